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

Each release quantity gets an error around the nominal release (Gaussian by default, uniform or
log-normal on request: :func:`parse_spread`); samples outside the accepted ranges are clipped
into them and counted. The chunks of balls (:mod:`football_ros.tools.mc_engine`: seeding,
in-process or Dask execution) are flown by :func:`football_ros.physics.batch.simulate_batch`.
Writes one row per ball (:data:`COLUMNS`) as CSV or .npz (gathered in memory: small runs), or
as Parquet partitions written by the workers (any size; loads lazily), a PNG figure, and prints
a summary: landing, time of flight and wobble statistics, clipped and gyroscopically unstable
balls, 50/95 % dispersion ellipses, the probability of landing in a zone with its Wilson
interval, and the inputs' shares of the landing dispersion.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import os
from pathlib import Path
import sys
import time
from typing import Mapping

import numpy as np

from .mc_engine import (  # noqa: F401  (COLUMNS and CHUNK: this module's public names too)
    CHUNK,
    COLUMNS,
    concat,
    drain,
    ellipse,
    Engine,
    fit_r2,
    INPUT_KEYS,
    inside_ellipse,
    MOMENT_KEYS,
    Plan,
    remove_partitions,
    sensitivity,
    Spread,
    Stats,
    SUBSAMPLE_TOTAL,
    SUMMARY_KEYS,
    wilson,
)
from ..physics import Release
from ..physics.release import ERROR_SIGMAS, LIMITS

SPREAD_DEFAULTS = ERROR_SIGMAS
"""Default standard deviations of the (Gaussian) release errors (units of each quantity)."""
UNITS = {
    'speed': 'm/s',
    'elevation_deg': 'deg',
    'azimuth_deg': 'deg',
    'spin_rpm': 'rpm',
    'alpha0_deg': 'deg',
    'beta0_deg': 'deg',
    'alpha_rate_deg_s': 'deg/s',
    'beta_rate_deg_s': 'deg/s',
}
FORMATS = ('.csv', '.npz', '.parquet')
GATHERED_MAX = 10_000_000
"""Most balls of a CSV/.npz run (its rows are held in memory); Parquet takes up to BALLS_MAX."""
BALLS_MAX = 10**11
SCATTER_MAX = 5000
"""Above this many landed balls the landing figure is a density image, not dots."""
LEVELS = (0.5, 0.95)
"""Probability levels of the dispersion ellipses."""


def parse_spread(items: list[str]) -> dict[str, Spread]:
    """
    KEY=WIDTH items (comma-separated or repeated) over the defaults; raises ValueError.

    WIDTH is a Gaussian sigma, ``normal:SIGMA`` the same, ``uniform:HALF`` a uniform error in
    [-HALF, HALF], ``lognormal:SIGMA`` a factor exp(SIGMA z) (sigma of the logarithm, the
    nominal the median; not for a nominal 0).
    """
    spread = {k: Spread('normal', v) for k, v in SPREAD_DEFAULTS.items()}
    for item in ','.join(items).split(','):
        if not item.strip():
            continue
        key, sep, value = item.partition('=')
        key = key.strip()
        if not sep or key not in spread:
            raise ValueError(
                f"--spread takes KEY=SIGMA with KEY one of {', '.join(spread)}; got '{item}'"
            )
        dist, colon, width = value.strip().rpartition(':')
        dist = dist.strip() if colon else 'normal'
        if dist not in ('normal', 'uniform', 'lognormal'):
            raise ValueError(
                f"--spread {key}: distribution must be normal, uniform or lognormal, got '{dist}'"
            )
        try:
            sigma = float(width)
        except ValueError:
            raise ValueError(f"--spread {key}: '{width}' is not a number") from None
        if not math.isfinite(sigma) or sigma < 0:
            raise ValueError(f'--spread {key}: width must be a finite number >= 0, got {width}')
        spread[key] = Spread(dist, sigma)
    return spread


def check_spread(release: Release, spread: Mapping[str, Spread]) -> None:
    """Refuse a log-normal error of a nominal 0 (ValueError): it scales the nominal."""
    for key, s in spread.items():
        if s.dist == 'lognormal' and s.width > 0 and getattr(release, key) == 0:
            raise ValueError(
                f'--spread {key}=lognormal: the nominal {key} is 0 (a log-normal error '
                'scales it); use normal or uniform'
            )


def as_spread(spread: Mapping[str, Spread | float]) -> dict[str, Spread]:
    """Spreads from Spread values or plain Gaussian sigmas (missing keys: no error)."""
    return {
        k: (v if isinstance(v, Spread) else Spread('normal', float(v)))
        for k, v in ((k, spread.get(k, 0.0)) for k in INPUT_KEYS)
    }


def sample_releases(
    release: Release, spread: Mapping[str, Spread | float], n: int, seed: int = 0
) -> dict[str, np.ndarray]:
    """N samples of each release quantity, chunk by chunk as a run draws them (clipped)."""
    from .mc_engine import sample_chunk

    spread = as_spread(spread)
    parts = [
        sample_chunk(release, spread, seed, i, min(CHUNK, n - i * CHUNK))[0]
        for i in range((n + CHUNK - 1) // CHUNK)
    ]
    return {k: np.concatenate([p[k] for p in parts]) for k in INPUT_KEYS}


def output_paths(out: str, figure: str = 'auto') -> tuple[Path | None, Path | None]:
    """
    Return the results path and the figure path.

    The results path's suffix picks the format: .csv, .npz, or .parquet (a folder of
    partitions); ``none`` = no rows (statistics only). The figure: ``auto`` = beside the
    results as .png (none without results), ``none`` = no figure; ValueError for an unknown
    format or a results folder that cannot be used.
    """
    if out == 'none':
        return None, (None if figure in ('none', 'auto') else output_paths('x.csv', figure)[1])
    path = Path(out)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f'--out {out}: use a .csv, .npz or .parquet (folder) name')
    if path.suffix.lower() == '.parquet':
        parent = path.resolve().parent
        if path.exists() and not path.is_dir():
            raise ValueError(f'--out {out}: exists and is not a folder')
        if not parent.is_dir():
            raise ValueError(f'--out {out}: folder {parent} does not exist')
        if not os.access(path if path.exists() else parent, os.W_OK | os.X_OK):
            raise ValueError(f'--out {out}: not writable')
    if figure == 'none':
        return path, None
    fig = path.with_suffix('.png') if figure == 'auto' else Path(figure)
    if fig.suffix.lower() != '.png':
        raise ValueError(f'--figure {figure}: use a .png file name (or auto, none)')
    return path, fig


def check_zone(zone, until_halfwidth: float | None) -> tuple[float, float, float] | None:
    """Validate ``--zone X Y R`` [m] and ``--until-halfwidth H``; raises ValueError."""
    if zone is not None:
        x, y, r = (float(v) for v in zone)
        lo, hi = LIMITS['position_xy']
        if not (lo <= x <= hi and lo <= y <= hi and 0 < r <= hi - lo):
            raise ValueError(
                f'--zone X Y R: X and Y in [{lo:g}, {hi:g}], 0 < R <= {hi - lo:g} [m], '
                f"got {' '.join(f'{v:g}' for v in zone)}"
            )
        zone = (x, y, r)
    if until_halfwidth is not None:
        if zone is None:
            raise ValueError('--until-halfwidth needs --zone (the probability it narrows)')
        if not (math.isfinite(until_halfwidth) and 0 < until_halfwidth <= 0.5):
            raise ValueError(f'--until-halfwidth must be in (0, 0.5], got {until_halfwidth}')
    return zone


@dataclass
class Outcome:
    """A run's result: statistics, the rows (None when streamed), times, where it ran."""

    n: int
    stats: Stats
    rows: dict[str, np.ndarray] | None
    seconds: float
    """Kernel seconds (summed over the workers)."""
    ball_seconds: float
    wall: float
    workers: int
    distributed: bool
    start_seconds: float
    stopped: str = ''
    """Why a --until-halfwidth run stopped."""
    zone: tuple[float, float, float] | None = None


def run(
    release: Release,
    n: int,
    spread: Mapping[str, Spread | float],
    seed: int,
    progress: bool = True,
    *,
    parquet: str | Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    zone: tuple[float, float, float] | None = None,
    until_halfwidth: float | None = None,
    task_chunks: int = 1,
    gather: bool = True,
) -> Outcome:
    """
    Sample and fly ``n`` releases (at most ``n`` with ``until_halfwidth``).

    ``parquet``: folder for the partitions (the rows are then not gathered), else the rows come
    back in ``Outcome.rows`` (unless ``gather`` is False: statistics only). ``workers``: a
    local Dask cluster of that many processes; ``scheduler``: an existing cluster's address;
    neither = in this process.
    ``until_halfwidth``: stop after the first chunk whose zone probability's Wilson 95 %
    interval is at most that half-width (chunks of one task each, so the stop is the same
    whatever the workers).
    """
    if n < 1:
        raise ValueError(f'n must be >= 1, got {n}')
    spread = as_spread(spread)
    check_spread(release, spread)
    n_chunks = (n + CHUNK - 1) // CHUNK
    gather = parquet is None and gather
    # Gathered rows give the table and the figure themselves: the chunks keep no subsample.
    keep = 0 if gather else max(1, min(CHUNK, SUBSAMPLE_TOTAL // n_chunks))
    if parquet is not None:
        Path(parquet).mkdir(exist_ok=True)
        remove_partitions(parquet)
    plan = Plan(
        release,
        spread,
        int(seed),
        int(n),
        zone,
        None if parquet is None else str(parquet),
        keep,
        gather=gather,
    )
    if until_halfwidth is not None:
        task_chunks = 1
    bar = None
    if progress:
        try:
            from tqdm import tqdm
        except ImportError:  # a ROS install without tqdm: a plain bar
            tqdm = _Bar
        bar = tqdm(
            total=n, unit='ball', unit_scale=True, file=sys.stderr, mininterval=0.5, smoothing=0.1
        )
    stopped = ''

    def on_chunk(r, stats: Stats) -> bool:
        nonlocal stopped
        if bar is not None:
            bar.update(r.stats.n)
        if until_halfwidth is None:
            return False
        _, lo, hi = wilson(stats.in_zone, stats.n)
        if (hi - lo) / 2.0 <= until_halfwidth:
            stopped = f'Wilson 95 % half-width {(hi - lo) / 2:.4g} <= {until_halfwidth:g}'
            return True
        return False

    begin = time.perf_counter()
    try:
        with Engine(workers, scheduler, parquet is not None) as engine:
            stats, rows, seconds, ball_seconds, used = drain(engine, plan, task_chunks, on_chunk)
            n_workers = engine.n_workers()
            start = engine.start_seconds
    finally:
        if bar is not None:
            bar.close()
    if until_halfwidth is not None and not stopped:
        _, lo, hi = wilson(stats.in_zone, stats.n)
        stopped = (
            f'reached --n {n} with the Wilson 95 % half-width {(hi - lo) / 2:.4g} > '
            f'{until_halfwidth:g}'
        )
    return Outcome(
        stats.n,
        stats,
        concat(rows) if gather else None,
        seconds,
        ball_seconds,
        time.perf_counter() - begin,
        n_workers,
        engine.distributed,
        start,
        stopped,
        zone,
    )


class _Bar:
    """Progress line with rate and time left, for want of tqdm (same calls as its bar)."""

    def __init__(self, total: int, file, mininterval: float = 0.5, **_) -> None:
        self.total, self.file, self.every = total, file, mininterval
        self.done, self.start, self.shown = 0, time.perf_counter(), 0.0

    def update(self, count: int) -> None:
        self.done += count
        now = time.perf_counter()
        if now - self.shown < self.every and self.done < self.total:
            return
        self.shown = now
        rate = self.done / max(now - self.start, 1e-9)
        left = (self.total - self.done) / rate if rate > 0 else math.inf
        bar = '#' * int(30 * self.done / self.total)
        print(
            f'\r[{bar:<30}] {self.done}/{self.total} balls, {rate:.3g} ball/s, '
            f'{now - self.start:.0f} s<{left:.0f} s left',
            end='',
            file=self.file,
            flush=True,
        )

    def close(self) -> None:
        print(file=self.file)


def write(path: Path, rows: Mapping[str, np.ndarray]) -> None:
    """
    Write the per-ball table.

    .npz (one array per column, full precision) or CSV (header :data:`COLUMNS`, 6 decimals,
    landed, stable and clipped as 0/1; :mod:`football_ros.tools.fastcsv`).
    """
    data = {k: rows[k] for k in COLUMNS}
    if path.suffix.lower() == '.npz':
        with open(path, 'wb') as handle:  # keeps the name as given (savez would add .npz)
            np.savez(handle, **data)
    else:
        from .fastcsv import write_csv

        write_csv(path, data, decimals=6)


def summary_rows(sample: Mapping[str, np.ndarray]) -> list[tuple[str, np.ndarray, str]]:
    """Return the table's quantities: landing and time of flight of landed balls, wobble of all."""
    landed = sample['landed'].astype(bool)
    return [
        ('landing x (downfield)', sample['landing_x'][landed], 'm'),
        ('landing y (left > 0)', sample['landing_y'][landed], 'm'),
        ('time of flight', sample['time_of_flight'][landed], 's'),
        ('wobble: max |alpha|', sample['max_alpha_deg'], 'deg'),
        ('max |beta|', sample['max_beta_deg'], 'deg'),
        ('max total angle delta', sample['max_delta_deg'], 'deg'),
    ]


def ellipses(stats: Stats) -> list[tuple[float, float, float, float, float, float]]:
    """(level, centre x, centre y [m], major, minor semi-axis [m], angle [rad]) per LEVELS."""
    if stats.count < 3:
        return []
    i, j = MOMENT_KEYS.index('landing_x'), MOMENT_KEYS.index('landing_y')
    cov = stats.covariance()[np.ix_([i, j], [i, j])]
    cx, cy = stats.mean[i], stats.mean[j]
    return [(level, cx, cy, *ellipse(cov, level)) for level in LEVELS]


def summary(outcome: Outcome, release: Release, spread: Mapping[str, Spread]) -> list[str]:
    """Return the printed summary, line by line."""
    stats = outcome.stats
    sample = _sample(outcome)
    n = outcome.n
    rate = outcome.ball_seconds / outcome.seconds if outcome.seconds > 0 else math.nan
    where = (
        f' of worker time on {outcome.workers} Dask worker(s) (wall {outcome.wall:.2f} s, '
        f'cluster start {outcome.start_seconds:.2f} s)'
        if outcome.distributed
        else ''
    )
    lines = [
        f'{n} balls, {stats.landed} landed, integrated in {outcome.seconds:.2f} s{where} '
        f'({rate:.3g} ball-seconds per second)'
    ]
    if outcome.stopped:
        lines.append(f'stopped: {outcome.stopped}')
    shown = sample['landed'].size
    if shown < n:
        lines.append(
            f'(table: mean, std and percentiles of a subsample of {shown} balls, the first of '
            'each chunk; counts, ellipses, zone and sensitivity: all balls)'
        )
    lines.append(f'{"quantity":<24}{"mean":>10}{"std":>10}{"p5":>10}{"p50":>10}{"p95":>10}  unit')
    for name, values, unit in summary_rows(sample):
        if values.size == 0:
            lines.append(f'{name:<24}{"(none)":>10}')
            continue
        p5, p50, p95 = np.percentile(values, [5, 50, 95])
        lines.append(
            f'{name:<24}{values.mean():>10.3f}{values.std():>10.3f}'
            f'{p5:>10.3f}{p50:>10.3f}{p95:>10.3f}  {unit}'
        )
    lines.append(
        f'clipped into the accepted ranges: {stats.any_clipped} balls '
        f'({100.0 * stats.any_clipped / n:.1f} %)'
        + ''.join(
            f'; {k} {c} ({100.0 * c / n:.1f} %, into [{_lo(release, k):g}, {LIMITS[k][1]:g}] '
            f'{UNITS[k]})'
            for k, c in zip(INPUT_KEYS, stats.clipped)
            if c
        )
    )
    lines.append(
        f'gyroscopically unstable at release (spin below the critical spin): {stats.unstable} '
        f'balls ({100.0 * stats.unstable / n:.1f} %)'
    )
    found = ellipses(stats)
    if found:
        x, y = sample['landing_x'], sample['landing_y']
        landed = sample['landed'].astype(bool)
        i, j = MOMENT_KEYS.index('landing_x'), MOMENT_KEYS.index('landing_y')
        cov = stats.covariance()[np.ix_([i, j], [i, j])]
        lines.append(
            'landing dispersion ellipses (Gaussian fit of the landed balls; holds = share of '
            'the landed balls inside):'
        )
        lines.append(
            f'{"level":>7}{"centre x":>10}{"centre y":>10}{"major":>9}{"minor":>9}'
            f'{"angle":>8}{"holds":>8}'
        )
        for level, cx, cy, major, minor, angle in found:
            holds = inside_ellipse(x[landed], y[landed], (cx, cy), cov, level).mean()
            lines.append(
                f'{100 * level:>5.0f} %{cx:>10.3f}{cy:>10.3f}{major:>9.3f}{minor:>9.3f}'
                f'{math.degrees(angle):>8.1f}{100 * holds:>7.1f}%'
            )
        lines.append('  (m; semi-axes; angle of the major axis from +x toward +y, deg)')
    zone = outcome.zone
    if zone is not None:
        p, lo, hi = wilson(stats.in_zone, n)
        lines.append(
            f'P(landing within {zone[2]:g} m of ({zone[0]:g}, {zone[1]:g})) = {p:.4f}, '
            f'Wilson 95 %: [{lo:.4f}, {hi:.4f}] (half-width {(hi - lo) / 2:.4f}; '
            f'{stats.in_zone} of {n} balls)'
        )
    rows_x = {k: (b, s) for k, b, s in sensitivity(stats, 'landing_x')}
    rows_y = {k: (b, s) for k, b, s in sensitivity(stats, 'landing_y')}
    if rows_x or rows_y:
        lines.append(
            'sensitivity of the landing point (least-squares slopes over the landed balls; '
            'share = slope^2 var(input) / var(landing)):'
        )
        lines.append(
            f'{"input":<18}{"error":<26}{"dx/dinput":>11}{"share x":>9}'
            f'{"dy/dinput":>11}{"share y":>9}'
        )
        for key in INPUT_KEYS:
            if key not in rows_x and key not in rows_y:
                continue
            bx, sx = rows_x.get(key, (math.nan, math.nan))
            by, sy = rows_y.get(key, (math.nan, math.nan))
            lines.append(
                f'{key:<18}{spread[key].describe(UNITS[key]):<26}{bx:>11.4g}'
                f'{100 * sx:>8.1f}%{by:>11.4g}{100 * sy:>8.1f}%'
            )
        lines.append(
            f'{"sum of the shares":<44}{"":>11}'
            f'{100 * sum(s for _, s in rows_x.values()):>8.1f}%'
            f'{"":>11}{100 * sum(s for _, s in rows_y.values()):>8.1f}%'
        )
        lines.append(
            f'{"R^2 of the linear fit":<44}{"":>11}{100 * fit_r2(stats, "landing_x"):>8.1f}%'
            f'{"":>11}{100 * fit_r2(stats, "landing_y"):>8.1f}%'
        )
        lines.append(
            '  (slopes in m per unit of the input; the shares add up to about R^2 when the '
            'inputs are independent)'
        )
    return lines


def _lo(release: Release, key: str) -> float:
    if key == 'elevation_deg' and release.position[2] <= 0.0:
        return 0.5
    return LIMITS[key][0]


def warnings(outcome: Outcome, release: Release) -> list[str]:
    """Lines for stderr: clipped inputs, gyroscopically unstable balls."""
    stats, n, out = outcome.stats, outcome.n, []
    for key, count in zip(INPUT_KEYS, stats.clipped):
        if count:
            out.append(
                f'{100.0 * count / n:.1f} % of the {key} samples ({count} of {n}) fell '
                f'outside [{_lo(release, key):g}, {LIMITS[key][1]:g}] {UNITS[key]} and were '
                'clipped into it'
            )
    if stats.unstable:
        out.append(
            f'{stats.unstable} of {n} balls ({100.0 * stats.unstable / n:.1f} %) were released '
            'below the critical spin (gyroscopically unstable)'
        )
    return out


def _sample(outcome: Outcome) -> dict[str, np.ndarray]:
    """Return the balls the table and figure use: all gathered rows, else the chunks' subsample."""
    if outcome.rows is not None:
        return {k: outcome.rows[k] for k in SUMMARY_KEYS}
    return outcome.stats.sample()


def figure_data(outcome: Outcome) -> dict:
    """Return what the figure draws: the subsample's columns, the ellipses, the counts."""
    data = _sample(outcome)
    data['ellipses'] = ellipses(outcome.stats)
    data['landed_total'] = outcome.stats.landed
    return data


def plot(path: Path, data: Mapping, title: str) -> None:
    """
    Draw landing points with the dispersion ellipses, time of flight and wobble histograms.

    ``data``: :func:`figure_data`. Landing points as dots, or a density image above
    SCATTER_MAX balls; equal aspect. One PNG at ``path``.
    """
    import matplotlib.pyplot as plt

    fig = figure(data, title)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def figure(data: Mapping, title: str):
    """Return the matplotlib Figure of :func:`plot` (constrained layout: no label is cut)."""
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib.patches import Ellipse
    import matplotlib.pyplot as plt

    landed = np.asarray(data['landed']).astype(bool)
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8), layout='constrained')
    x, y = data['landing_x'][landed], data['landing_y'][landed]
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
    for (level, cx, cy, major, minor, angle), color in zip(
        data.get('ellipses', []), ('tab:red', 'tab:orange')
    ):
        ax.add_patch(
            Ellipse(
                (cx, cy),
                2 * major,
                2 * minor,
                angle=math.degrees(angle),
                fill=False,
                color=color,
                lw=1.5,
                label=f'{100 * level:.0f} % ellipse',
            )
        )
    if x.size:
        ax.plot(np.mean(x), np.mean(y), 'r+', ms=14, mew=2, label='mean')
        ax.legend(loc='upper right', framealpha=0.8, fontsize='small')
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('landing x, downfield [m]')
    ax.set_ylabel('landing y, left > 0 [m]')
    total = int(data.get('landed_total', x.size))
    shown = f'{x.size} landed' if total == x.size else f'{x.size} of {total} landed'
    ax.set_title(f'Landing points ({shown})')
    ax.grid(alpha=0.3)
    _histogram(axes[1], [(data['time_of_flight'][landed], None)])
    axes[1].set_xlabel('time of flight [s]')
    axes[1].set_ylabel('balls')
    axes[1].set_title('Time of flight')
    _histogram(
        axes[2], [(data['max_alpha_deg'], 'max |alpha|'), (data['max_beta_deg'], 'max |beta|')]
    )
    axes[2].set_xlabel('angle [deg]')
    axes[2].set_ylabel('balls')
    axes[2].set_title('Wobble amplitude')
    axes[2].legend(loc='upper right', framealpha=0.8)
    fig.suptitle(title)
    return fig


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

                    plot(path, pickle.loads(payload), title)
                code = 0
            except BaseException as exc:  # reported by the parent's exit code
                print(f'football-ros: error: figure {path}: {exc}', file=sys.stderr, flush=True)
            finally:
                os._exit(code)
        os.close(read)
        self.pid, self._pipe = pid, write

    def draw(self, data: Mapping) -> None:
        """Hand :func:`figure_data` over (or draw it here when there is no child)."""
        if self.pid is None:
            plot(self.path, data, self.title)
            return
        import pickle

        payload = pickle.dumps(dict(data), protocol=5)
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


def _histogram(ax, series) -> None:
    """Step histograms from np.histogram (one artist each, cheap at any n)."""
    for values, label in series:
        values = values[np.isfinite(values)]
        if values.size == 0:
            continue
        counts, edges = np.histogram(values, bins=50)
        ax.stairs(counts, edges, fill=True, alpha=0.6, label=label)
