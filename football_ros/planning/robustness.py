# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Hit probability of a plan under release noise, from the batch kernel.

A hit: the ball, moving down, crosses the horizontal plane of the target (z = z_T) within
``catch_radius`` of the target (the batch kernel's landing on a "ground" at z_T). Release errors
are Gaussian with the sigmas given (defaults: those of ``football-ros montecarlo``), clipped to
the release limits. The 95 % interval is Wilson's score interval of the binomial count.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Mapping

import numpy as np

from .planner import Plan, plan, PlanError
from ..physics.release import ERROR_SIGMAS, LIMITS, release_states

DEFAULT_SIGMAS = ERROR_SIGMAS
"""Default release-error sigmas (units of each key; the montecarlo command's defaults)."""
DEFAULT_CATCH_RADIUS = 0.5
"""Catch radius [m] unless told."""


@dataclass(frozen=True)
class HitEstimate:
    """probability of a hit with its Wilson 95 % interval [low, high], from ``hits`` of ``n``."""

    probability: float
    low: float
    high: float
    hits: int
    n: int
    catch_radius: float

    def to_mapping(self) -> dict:
        return {
            'hit_probability': self.probability,
            'hit_probability_low': self.low,
            'hit_probability_high': self.high,
            'hit_n': self.n,
            'catch_radius_m': self.catch_radius,
        }


def wilson(hits: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """Wilson score interval (95 % by default) of a binomial proportion ``hits`` / ``n``."""
    if n <= 0:
        return 0.0, 1.0
    p = hits / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2.0 * n)) / denom
    half = z * math.sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def _check_sigmas(sigmas: Mapping[str, float] | None) -> dict[str, float]:
    out = dict(DEFAULT_SIGMAS)
    for key, value in (sigmas or {}).items():
        if key not in out:
            raise PlanError(f"unknown sigma '{key}' (known: {', '.join(out)})", 'sigmas')
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise PlanError(f"sigma '{key}' must be a number", 'sigmas')
        if not (math.isfinite(value) and 0.0 <= value <= 0.5 * (LIMITS[key][1] - LIMITS[key][0])):
            raise PlanError(f"sigma '{key}' = {value!r} must be finite and >= 0", 'sigmas')
        out[key] = float(value)
    return out


def arcs_summary(comparison: dict) -> dict:
    """Return :func:`compare_arcs` as flat plain data (hit probabilities, or why refused)."""
    out: dict = {'more_robust': comparison['more_robust']}
    for arc in ('flat', 'lofted'):
        v = comparison[arc]
        if isinstance(v, tuple):
            p, est = v
            out.update({
                f'{arc}_elevation_deg': p.release.elevation_deg,
                f'{arc}_arrival_time': p.arrival_time,
                f'{arc}_hit_probability': est.probability,
                f'{arc}_hit_probability_low': est.low,
                f'{arc}_hit_probability_high': est.high,
            })
        else:
            out[f'{arc}_refused'] = str(v)
    return out


def miss_distances(
    the_plan: Plan,
    sigmas: Mapping[str, float] | None = None,
    n: int = 4000,
    seed: int = 0,
) -> np.ndarray:
    """
    Horizontal miss [m] in the target's plane of ``n`` noisy copies of the plan (inf: never there).

    Flown with :func:`football_ros.physics.batch.simulate_batch` (its default step rule).
    """
    from ..physics.batch import simulate_batch

    sig = _check_sigmas(sigmas)
    if not 1 <= n <= 10_000_000:
        raise PlanError(f"'n' = {n} must be in [1, 1e7]", 'n')
    rel = the_plan.release
    rng = np.random.default_rng(seed)
    draws = {}
    for key, sigma in sig.items():
        lo, hi = LIMITS[key]
        draws[key] = np.clip(getattr(rel, key) + sigma * rng.standard_normal(n), lo, hi)
    if rel.position[2] <= 0.0:
        draws['elevation_deg'] = np.clip(draws['elevation_deg'], 0.5, None)
    states = release_states(
        draws['speed'],
        draws['elevation_deg'],
        draws['azimuth_deg'],
        draws['spin_rpm'],
        draws['alpha0_deg'],
        draws['beta0_deg'],
        draws['alpha_rate_deg_s'],
        draws['beta_rate_deg_s'],
        np.array(rel.position, dtype=float),
    )
    target = the_plan.target
    result = simulate_batch(
        rel.preset(),
        states,
        rel.model,
        rel.moment,
        rel.aero_model(),
        max_time=the_plan.arrival_time * 3.0 + 2.0,
        ground=float(target[2]),
    )
    miss = np.hypot(result.landing_x - target[0], result.landing_y - target[1])
    return np.where(result.landed, miss, np.inf)


def hit_probability(
    the_plan: Plan,
    sigmas: Mapping[str, float] | None = None,
    catch_radius: float = DEFAULT_CATCH_RADIUS,
    n: int = 4000,
    seed: int = 0,
) -> HitEstimate:
    """
    Probability that a noisy copy of the plan is a hit (module docstring), Wilson 95 %.

    Needs a plan that arrives moving down (the plane crossing is the descending one); raises
    :class:`PlanError` otherwise.
    """
    if not (isinstance(catch_radius, (int, float)) and math.isfinite(catch_radius)
            and 0.0 < catch_radius <= 100.0):
        raise PlanError(f"'catch_radius' = {catch_radius!r} must be in (0, 100] m",
                        'catch_radius')
    vz = np.diff(the_plan.path_positions[-2:, 2])
    if vz.size and vz[0] > 0.0:
        raise PlanError('the plan arrives moving up: the hit probability is measured on the '
                        'descending crossing of the target height', 'arrival')
    miss = miss_distances(the_plan, sigmas, n, seed)
    hits = int(np.count_nonzero(miss <= catch_radius))
    low, high = wilson(hits, n)
    return HitEstimate(hits / n, low, high, hits, n, float(catch_radius))


def compare_arcs(target, base, sigmas=None, catch_radius: float = DEFAULT_CATCH_RADIUS,
                 n: int = 4000, seed: int = 0, **plan_options) -> dict:
    """
    Plan the flat and the lofted arc at the base release's speed and estimate both hits.

    Returns {'flat': (Plan, HitEstimate) or PlanError, 'lofted': ..., 'more_robust': name or
    None}; 'more_robust' is the arc with the higher hit probability when the two intervals
    do not overlap, 'either' when they do.
    """
    out: dict = {}
    for arc in ('flat', 'lofted'):
        try:
            p = plan(target, base, objective=arc, **plan_options)
            out[arc] = (p, hit_probability(p, sigmas, catch_radius, n, seed))
        except PlanError as exc:
            out[arc] = exc
    flat, lofted = out['flat'], out['lofted']
    if isinstance(flat, tuple) and isinstance(lofted, tuple):
        a, b = flat[1], lofted[1]
        if a.low > b.high:
            out['more_robust'] = 'flat'
        elif b.low > a.high:
            out['more_robust'] = 'lofted'
        else:
            out['more_robust'] = 'either'
    else:
        out['more_robust'] = 'flat' if isinstance(flat, tuple) else (
            'lofted' if isinstance(lofted, tuple) else None)
    return out
