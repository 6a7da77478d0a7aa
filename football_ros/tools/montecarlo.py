"""``football-ros montecarlo``: release errors in, landing dispersion and wobble statistics out.

Each release quantity gets a Gaussian error (standard deviations from ``--spread``) around the
nominal release; samples are clipped to the accepted ranges. The flights run in batches through
:func:`football_ros.physics.batch.simulate_batch`. Writes one CSV row per ball, a PNG figure
next to it, and prints a summary table.
"""

from __future__ import annotations

import csv
import math
import sys
import time
from pathlib import Path
from typing import Mapping

import numpy as np

from ..physics import Release
from ..physics.batch import BatchResult, simulate_batch
from ..physics.release import LIMITS, release_states

SPREAD_DEFAULTS = {"speed": 0.5, "elevation_deg": 1.0, "azimuth_deg": 1.0, "spin_rpm": 30.0,
                   "alpha0_deg": 1.0, "beta0_deg": 1.0, "alpha_rate_deg_s": 10.0, "beta_rate_deg_s": 10.0}
"""Default standard deviations of the release errors (units of each quantity)."""
CHUNK = 4096
DENSITY_ABOVE = 5000
"""Landing points above this count are drawn as a density (hexbin), not a scatter."""
COLUMNS = (*SPREAD_DEFAULTS, "landing_x", "landing_y", "time_of_flight", "landed", "max_alpha",
           "max_beta", "max_delta")


def parse_spread(items: list[str]) -> dict[str, float]:
    """KEY=SIGMA items (comma-separated or repeated) over the defaults; raises ValueError."""
    spread = dict(SPREAD_DEFAULTS)
    for item in ",".join(items).split(","):
        if not item.strip():
            continue
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or key not in spread:
            raise ValueError(f"--spread takes KEY=SIGMA with KEY one of {', '.join(spread)}; got '{item}'")
        sigma = float(value)
        if not math.isfinite(sigma) or sigma < 0:
            raise ValueError(f"--spread {key}: sigma must be a finite number >= 0, got {value}")
        spread[key] = sigma
    return spread


def sample_releases(release: Release, spread: Mapping[str, float], n: int,
                    rng: np.random.Generator) -> dict[str, np.ndarray]:
    """n samples of each release quantity: nominal + N(0, sigma), clipped to LIMITS."""
    out = {}
    for key, sigma in spread.items():
        lo, hi = LIMITS[key]
        out[key] = np.clip(getattr(release, key) + sigma * rng.standard_normal(n), lo, hi)
    if release.position[2] <= 0.0:  # a release from the ground must go up
        out["elevation_deg"] = np.clip(out["elevation_deg"], 0.5, None)
    return out


def run(release: Release, n: int, spread: Mapping[str, float], seed: int, progress=True) -> tuple[dict, BatchResult]:
    """Sample and fly ``n`` releases; returns the samples and the concatenated results."""
    rng = np.random.default_rng(seed)
    samples = sample_releases(release, spread, n, rng)
    ball = release.preset()
    parts = []
    start = time.perf_counter()
    for first in range(0, n, CHUNK):
        part = {k: v[first:first + CHUNK] for k, v in samples.items()}
        states = release_states(part["speed"], part["elevation_deg"], part["azimuth_deg"], part["spin_rpm"],
                                part["alpha0_deg"], part["beta0_deg"], part["alpha_rate_deg_s"],
                                part["beta_rate_deg_s"], np.array(release.position))
        parts.append(simulate_batch(ball, states, release.model, release.moment, release.aero_model()))
        if progress:
            done = min(n, first + CHUNK)
            bar = "#" * int(30 * done / n)
            print(f"\r[{bar:<30}] {done}/{n} balls, {time.perf_counter() - start:.1f} s", end="",
                  file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    fields = ("landing_x", "landing_y", "time_of_flight", "landed", "max_alpha", "max_beta", "max_delta")
    result = BatchResult(*(np.concatenate([getattr(p, f) for p in parts]) for f in fields), None, parts[0].sample_period)
    return samples, result


def summary_rows(result: BatchResult) -> list[tuple[str, np.ndarray, str]]:
    landed = result.landed
    return [("landing x (downfield)", result.landing_x[landed], "m"),
            ("landing y (left > 0)", result.landing_y[landed], "m"),
            ("time of flight", result.time_of_flight[landed], "s"),
            ("wobble: max |alpha|", np.degrees(result.max_alpha), "deg"),
            ("max |beta|", np.degrees(result.max_beta), "deg"),
            ("max total angle delta", np.degrees(result.max_delta), "deg")]


def write_csv(path: Path, samples: dict, result: BatchResult) -> None:
    data = [*(samples[k] for k in SPREAD_DEFAULTS), result.landing_x, result.landing_y, result.time_of_flight,
            result.landed.astype(int), result.max_alpha, result.max_beta, result.max_delta]
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        writer.writerows(np.column_stack(data).tolist())


def plot(path: Path, result: BatchResult, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    landed = result.landed
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.5))
    x, y = result.landing_x[landed], result.landing_y[landed]
    if x.size > DENSITY_ABOVE:  # a scatter of this many points is a solid blob: plot the density
        cells = axes[0].hexbin(x, y, gridsize=60, bins="log", mincnt=1, cmap="viridis")
        fig.colorbar(cells, ax=axes[0], label="balls per cell")
    else:
        axes[0].scatter(x, y, s=2, alpha=0.3)
    axes[0].set_aspect("equal", adjustable="datalim")  # metres are metres both ways
    axes[0].plot(np.mean(x), np.mean(y), "r+", ms=14, label="mean")
    axes[0].set_xlabel("landing x, downfield [m]")
    axes[0].set_ylabel("landing y, left > 0 [m]")
    axes[0].set_title("Landing points")
    axes[0].legend(loc="upper left", bbox_to_anchor=(0.0, -0.15), fontsize=8)
    axes[0].grid(alpha=0.3)
    axes[1].hist(result.time_of_flight[landed], bins=50)
    axes[1].set_xlabel("time of flight [s]")
    axes[1].set_ylabel("balls")
    axes[1].set_title("Time of flight")
    axes[2].hist(np.degrees(result.max_alpha), bins=50, alpha=0.7, label="max |alpha|")
    axes[2].hist(np.degrees(result.max_beta), bins=50, alpha=0.7, label="max |beta|")
    axes[2].set_xlabel("angle [deg]")
    axes[2].set_title("Wobble amplitude")
    axes[2].legend(fontsize=8, loc="upper right")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def print_summary(result: BatchResult, n: int, seconds: float) -> None:
    print(f"{n} balls, {int(result.landed.sum())} landed, {seconds:.2f} s "
          f"({result.time_of_flight.sum() / seconds:.3g} ball-seconds per second)")
    print(f"{'quantity':<24}{'mean':>10}{'std':>10}{'p5':>10}{'p50':>10}{'p95':>10}  unit")
    for name, values, unit in summary_rows(result):
        if values.size == 0:
            print(f"{name:<24}{'(none)':>10}")
            continue
        p5, p50, p95 = np.percentile(values, [5, 50, 95])
        print(f"{name:<24}{values.mean():>10.3f}{values.std():>10.3f}{p5:>10.3f}{p50:>10.3f}{p95:>10.3f}  {unit}")
