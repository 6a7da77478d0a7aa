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
``football-ros montecarlo``: release errors in, landing dispersion and wobble statistics out.

Each release quantity gets a Gaussian error (standard deviations from ``--spread``) around the
nominal release; samples are clipped to the accepted ranges. The flights run in batches through
:func:`football_ros.physics.batch.simulate_batch`. Writes one row per ball (:data:`COLUMNS`:
the sampled release in the units of its name, landing_x/landing_y [m], time_of_flight [s],
landed 0/1, max_alpha_deg/max_beta_deg/max_delta_deg [deg]) as CSV or .npz, a PNG figure, and
prints a summary table.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
import sys
import time
from typing import Mapping, TYPE_CHECKING

import numpy as np

from ..physics import Release
from ..physics.release import LIMITS

if TYPE_CHECKING:  # the batch module imports numba: only when flights are flown
    from ..physics.batch import BatchResult

SPREAD_DEFAULTS = {
    'speed': 0.5,
    'elevation_deg': 1.0,
    'azimuth_deg': 1.0,
    'spin_rpm': 30.0,
    'alpha0_deg': 1.0,
    'beta0_deg': 1.0,
    'alpha_rate_deg_s': 10.0,
    'beta_rate_deg_s': 10.0,
}
"""Default standard deviations of the release errors (units of each quantity)."""
CHUNK = 4096
COLUMNS = (
    *SPREAD_DEFAULTS,
    'landing_x',
    'landing_y',
    'time_of_flight',
    'landed',
    'max_alpha_deg',
    'max_beta_deg',
    'max_delta_deg',
)
"""Per-ball columns: release (units in the name; speed m/s), landing_x/y [m], time_of_flight [s],
landed (0/1), the largest |alpha|, |beta| and delta over the flight [deg]."""
FORMATS = ('.csv', '.npz')
SCATTER_MAX = 5000
"""Above this many landed balls the landing figure is a density image, not dots."""


def parse_spread(items: list[str]) -> dict[str, float]:
    """KEY=SIGMA items (comma-separated or repeated) over the defaults; raises ValueError."""
    spread = dict(SPREAD_DEFAULTS)
    for item in ','.join(items).split(','):
        if not item.strip():
            continue
        key, sep, value = item.partition('=')
        key = key.strip()
        if not sep or key not in spread:
            raise ValueError(
                f"--spread takes KEY=SIGMA with KEY one of {', '.join(spread)}; got '{item}'"
            )
        sigma = float(value)
        if not math.isfinite(sigma) or sigma < 0:
            raise ValueError(f'--spread {key}: sigma must be a finite number >= 0, got {value}')
        spread[key] = sigma
    return spread


def sample_releases(
    release: Release, spread: Mapping[str, float], n: int, rng: np.random.Generator
) -> dict[str, np.ndarray]:
    """N samples of each release quantity: nominal + N(0, sigma), clipped to LIMITS."""
    out = {}
    for key, sigma in spread.items():
        lo, hi = LIMITS[key]
        out[key] = np.clip(getattr(release, key) + sigma * rng.standard_normal(n), lo, hi)
    if release.position[2] <= 0.0:  # a release from the ground must go up
        out['elevation_deg'] = np.clip(out['elevation_deg'], 0.5, None)
    return out


def output_paths(out: str, figure: str = 'auto') -> tuple[Path, Path | None]:
    """
    Return the results file and the figure path.

    The results file's suffix picks the format: .csv or .npz; the figure: ``auto`` = beside it
    as .png, ``none`` = no figure; ValueError for an unknown format.
    """
    path = Path(out)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f'--out {out}: use a .csv or .npz file name')
    if figure == 'none':
        return path, None
    fig = path.with_suffix('.png') if figure == 'auto' else Path(figure)
    if fig.suffix.lower() != '.png':
        raise ValueError(f'--figure {figure}: use a .png file name (or auto, none)')
    return path, fig


def run(
    release: Release, n: int, spread: Mapping[str, float], seed: int, progress: bool = True
) -> tuple[dict, BatchResult, float]:
    """
    Sample and fly ``n`` releases.

    Returns the samples, the concatenated results and the seconds spent integrating (inside
    simulate_batch).
    """
    from ..physics.batch import BatchResult, simulate_batch
    from ..physics.release import release_states

    rng = np.random.default_rng(seed)
    samples = sample_releases(release, spread, n, rng)
    ball = release.preset()
    parts = []
    start = time.perf_counter()
    seconds = 0.0
    aero = release.aero_model()
    for first in range(0, n, CHUNK):
        part = {k: v[first:first + CHUNK] for k, v in samples.items()}
        states = release_states(
            part['speed'],
            part['elevation_deg'],
            part['azimuth_deg'],
            part['spin_rpm'],
            part['alpha0_deg'],
            part['beta0_deg'],
            part['alpha_rate_deg_s'],
            part['beta_rate_deg_s'],
            np.array(release.position),
        )
        begin = time.perf_counter()
        parts.append(simulate_batch(ball, states, release.model, release.moment, aero))
        seconds += time.perf_counter() - begin
        if progress:
            done = min(n, first + CHUNK)
            bar = '#' * int(30 * done / n)
            print(
                f'\r[{bar:<30}] {done}/{n} balls, {time.perf_counter() - start:.1f} s',
                end='',
                file=sys.stderr,
                flush=True,
            )
    if progress:
        print(file=sys.stderr)
    fields = (
        'landing_x',
        'landing_y',
        'time_of_flight',
        'landed',
        'max_alpha',
        'max_beta',
        'max_delta',
    )
    result = BatchResult(
        *(np.concatenate([getattr(p, f) for p in parts]) for f in fields),
        None,
        parts[0].sample_period,
    )
    return samples, result, seconds


def summary_rows(result) -> list[tuple[str, np.ndarray, str]]:
    landed = result.landed
    return [
        ('landing x (downfield)', result.landing_x[landed], 'm'),
        ('landing y (left > 0)', result.landing_y[landed], 'm'),
        ('time of flight', result.time_of_flight[landed], 's'),
        ('wobble: max |alpha|', np.degrees(result.max_alpha), 'deg'),
        ('max |beta|', np.degrees(result.max_beta), 'deg'),
        ('max total angle delta', np.degrees(result.max_delta), 'deg'),
    ]


def columns(samples: Mapping[str, np.ndarray], result) -> dict[str, np.ndarray]:
    """Return the per-ball table as named columns in the order and units of :data:`COLUMNS`."""
    data = {k: samples[k] for k in SPREAD_DEFAULTS}
    data.update(
        landing_x=result.landing_x,
        landing_y=result.landing_y,
        time_of_flight=result.time_of_flight,
        landed=result.landed.astype(np.int8),
        max_alpha_deg=np.degrees(result.max_alpha),
        max_beta_deg=np.degrees(result.max_beta),
        max_delta_deg=np.degrees(result.max_delta),
    )
    return data


def write(path: Path, samples: Mapping[str, np.ndarray], result) -> None:
    """
    Write the per-ball table.

    .npz (one array per column, full precision) or CSV (header :data:`COLUMNS`, 6 decimals,
    landed as 0/1; :mod:`football_ros.tools.fastcsv`).
    """
    data = columns(samples, result)
    if path.suffix.lower() == '.npz':
        with open(path, 'wb') as handle:  # keeps the name as given (savez would add .npz)
            np.savez(handle, **data)
    else:
        from .fastcsv import write_csv

        write_csv(path, data, decimals=6)


def plot(path: Path, result, title: str) -> None:
    """
    Draw landing points, time of flight and wobble histograms into one PNG.

    Landing points as dots, or a density image above SCATTER_MAX balls; equal aspect.
    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    landed = result.landed
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.5))
    x, y = result.landing_x[landed], result.landing_y[landed]
    ax = axes[0]
    if x.size > SCATTER_MAX:  # density: a 2-D histogram drawn as one image
        counts, xe, ye = np.histogram2d(x, y, bins=(120, 120))
        counts[counts == 0] = np.nan
        image = ax.imshow(
            counts.T,
            origin='lower',
            extent=(xe[0], xe[-1], ye[0], ye[-1]),
            cmap='viridis',
            norm=matplotlib.colors.LogNorm(),
            aspect='auto',
            interpolation='nearest',
        )
        fig.colorbar(image, ax=ax, label='balls per cell')
    elif x.size:
        ax.scatter(x, y, s=4, alpha=0.4, linewidths=0)
    if x.size:
        ax.plot(np.mean(x), np.mean(y), 'r+', ms=14, mew=2, label='mean')
        ax.legend(loc='upper right', framealpha=0.8)
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('landing x, downfield [m]')
    ax.set_ylabel('landing y, left > 0 [m]')
    ax.set_title(f'Landing points ({x.size} landed)')
    ax.grid(alpha=0.3)
    _histogram(axes[1], [(result.time_of_flight[landed], None)])
    axes[1].set_xlabel('time of flight [s]')
    axes[1].set_ylabel('balls')
    axes[1].set_title('Time of flight')
    _histogram(
        axes[2],
        [
            (np.degrees(result.max_alpha), 'max |alpha|'),
            (np.degrees(result.max_beta), 'max |beta|'),
        ],
    )
    axes[2].set_xlabel('angle [deg]')
    axes[2].set_title('Wobble amplitude')
    axes[2].legend(loc='upper right', framealpha=0.8)
    fig.suptitle(title)
    fig.subplots_adjust(left=0.05, right=0.98, bottom=0.12, top=0.86, wspace=0.3)
    fig.savefig(path, dpi=100)
    plt.close(fig)


FIGURE_FIELDS = ('landing_x', 'landing_y', 'time_of_flight', 'landed', 'max_alpha', 'max_beta')


class FigureProcess:
    """
    Figure drawn by a forked child, off the critical path.

    The child imports matplotlib while this process integrates and draws while it writes the
    table (start-up and drawing leave the critical path). Without ``os.fork``, or once numba
    (and its threads) is loaded, it draws in-process.
    """

    def __init__(self, path: Path, title: str) -> None:
        self.path, self.title, self.pid, self._pipe = path, title, None, None
        if not hasattr(os, 'fork') or 'numba' in sys.modules:
            return
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            os.close(write)
            code = 1
            try:
                import matplotlib

                matplotlib.use('Agg')
                import matplotlib.pyplot  # noqa: F401

                with os.fdopen(read, 'rb') as pipe:
                    payload = pipe.read()
                if payload:
                    import pickle

                    plot(path, _Fields(pickle.loads(payload)), title)
                code = 0
            except BaseException as exc:  # reported by the parent's exit code
                print(f'football-ros: error: figure {path}: {exc}', file=sys.stderr, flush=True)
            finally:
                os._exit(code)
        os.close(read)
        self.pid, self._pipe = pid, write

    def draw(self, result) -> None:
        """Hand the results over (or draw them here when there is no child)."""
        if self.pid is None:
            plot(self.path, result, self.title)
            return
        import pickle

        payload = pickle.dumps({f: getattr(result, f) for f in FIGURE_FIELDS}, protocol=5)
        with os.fdopen(self._pipe, 'wb') as pipe:
            self._pipe = None
            pipe.write(payload)

    def finish(self) -> bool:
        """Wait for the child (after cancelling it if it got nothing); True if it drew."""
        if self.pid is None:
            return True
        if self._pipe is not None:  # nothing sent: the child exits without drawing
            os.close(self._pipe)
            self._pipe = None
        _, status = os.waitpid(self.pid, 0)
        self.pid = None
        return os.waitstatus_to_exitcode(status) == 0


class _Fields:

    def __init__(self, data: dict) -> None:
        self.__dict__.update(data)


def _histogram(ax, series) -> None:
    """Step histograms from np.histogram (one artist each, cheap at any n)."""
    for values, label in series:
        values = values[np.isfinite(values)]
        if values.size == 0:
            continue
        counts, edges = np.histogram(values, bins=50)
        ax.stairs(counts, edges, fill=True, alpha=0.6, label=label)


def print_summary(result, n: int, seconds: float) -> None:
    print(
        f'{n} balls, {int(result.landed.sum())} landed, integrated in {seconds:.2f} s '
        f'({result.time_of_flight.sum() / seconds:.3g} ball-seconds per second)'
    )
    print(f'{"quantity":<24}{"mean":>10}{"std":>10}{"p5":>10}{"p50":>10}{"p95":>10}  unit')
    for name, values, unit in summary_rows(result):
        if values.size == 0:
            print(f'{name:<24}{"(none)":>10}')
            continue
        p5, p50, p95 = np.percentile(values, [5, 50, 95])
        print(
            f'{name:<24}{values.mean():>10.3f}{values.std():>10.3f}'
            f'{p5:>10.3f}{p50:>10.3f}{p95:>10.3f}  {unit}'
        )
