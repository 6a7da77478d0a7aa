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
Figures in the paper's style, headless (Agg), from a bag or a simulate CSV.

The ball, spin, model and wind come from the file (a CSV's sidecar, a bag's flight order);
without them ``--ball`` must say which ball it is, or :func:`plot_source` refuses.

wobble.png: the axis seen in the velocity frame (s3 horizontal, right > 0; s2 vertical, up > 0)
with the equilibrium s3p; angles.png: alpha and beta against time with the linear theory
(frozen and quasi-steady); trajectory.png: side view with the ground, top view;
precession.png: the paper's decomposition, about the equilibrium point: x_c = x - i s3p (the
complementary part), nutation |x_c| and precession arg(x_c), unwrapped.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .flightdata import FlightInfo, FlightRecord, load  # noqa: E402
from ..physics import frames, get_preset  # noqa: E402
from ..physics.linear_theory import local_modes  # noqa: E402
from ..physics.release import RPM  # noqa: E402

DEG = np.degrees
LEGEND = {'fontsize': 8, 'loc': 'upper left', 'bbox_to_anchor': (1.01, 1.0), 'borderaxespad': 0.0}
"""Legends beside the axes, never over the data."""


def flight_info(
    record: FlightRecord, ball: str | None = None, spin_rpm: float | None = None
) -> FlightInfo:
    """
    Describe what the flight is.

    The file's own description; else ``ball`` (and ``spin_rpm`` or the preset's) when the user
    names it; else ValueError. A ``ball`` that contradicts the file's is refused too.
    """
    info = record.info
    if info is not None:
        if ball is not None and ball != info.ball_name:
            raise ValueError(
                f"{record.source} is a '{info.ball_name}' flight ({info.origin}); "
                f'--ball {ball} contradicts it'
            )
        if spin_rpm is not None:
            return FlightInfo(
                info.ball,
                info.ball_name,
                spin_rpm * RPM,
                info.model,
                info.moment,
                info.aero,
                info.origin + ' (spin from --spin-rpm)',
            )
        return info
    if ball is None:
        raise ValueError(
            f'{record.source} does not say which ball it holds (no sidecar '
            f'<name>.csv.json, no football/flight/order in the bag): pass --ball '
            f"(and --spin-rpm), or re-run 'football-ros simulate'"
        )
    preset = get_preset(ball)
    spin = (spin_rpm if spin_rpm is not None else preset.spin_rpm) * RPM
    origin = '--ball' + (' and --spin-rpm' if spin_rpm is not None else ", preset's spin")
    return FlightInfo(preset, ball, spin, 'paper', 'linear', None, origin)


def spin_series(record: FlightRecord, info: FlightInfo) -> np.ndarray:
    """(N,) spin p [rad/s]: recorded when the source has it, else the release spin."""
    if record.spin is not None and np.all(np.isfinite(record.spin)):
        return record.spin
    return np.full(len(record.t), info.spin)


def equilibrium_sideslip(record: FlightRecord, info: FlightInfo) -> np.ndarray:
    """s3p(t) = g cos(Phi) h1 / (M_alpha(U) U) along the flight [rad] (air-relative U, Phi)."""
    h1 = info.ball.inertia_ratio * spin_series(record, info)
    return local_modes(info.ball.moment_coefficient(), record.velocity - info.wind, h1)[3]


def components(record: FlightRecord, info: FlightInfo) -> np.ndarray:
    """(N,) x = s2 + i s3 of the integrated axis in the air-relative velocity frame."""
    c = frames.to_velocity_frame(record.axis, record.velocity - info.wind)
    return c[:, 1] + 1j * c[:, 2]


def components_from_angles(alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """X = s2 + i s3 of the axis with angles alpha, beta [rad]: s2 = sin a cos b, s3 = sin b."""
    return np.sin(alpha) * np.cos(beta) + 1j * np.sin(beta)


def describe(info: FlightInfo) -> str:
    """One line: ball, spin, model, where it came from."""
    return f'{info.ball_name}, {info.spin / RPM:.0f} rpm, {info.model} model ({info.origin})'


def plot_source(
    source: str | Path, out_dir: str | Path, ball: str | None = None, spin_rpm: float | None = None
) -> list[Path]:
    """
    Write the four PNG figures for the flight in ``source``; returns their paths.

    Raises ValueError when the file does not say which ball it holds and ``ball`` is None.
    """
    record = load(source)
    info = flight_info(record, ball, spin_rpm)
    return plot_record(record, info, out_dir, f'{Path(record.source).name}: {describe(info)}')


def plot_record(
    record: FlightRecord, info: FlightInfo, out_dir: str | Path, subtitle: str, prefix: str = ''
) -> list[Path]:
    """Draw the four figures of one record into ``out_dir`` (names prefixed by ``prefix``)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    fig, ax = plt.subplots(figsize=(8.5, 6))
    wobble_axes(ax, record, info)
    ax.set_title(f'Wobble in the velocity frame\n{subtitle}', fontsize=9)
    paths.append(_save(fig, out / f'{prefix}wobble.png'))
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    angle_axes(axes, record, info)
    axes[0].set_title(f'Angle of attack and sideslip\n{subtitle}', fontsize=9)
    paths.append(_save(fig, out / f'{prefix}angles.png'))
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    trajectory_axes(axes, record)
    axes[0].set_title(
        f'Trajectory (field frame: x downfield, y left, z up)\n{subtitle}', fontsize=9
    )
    paths.append(_save(fig, out / f'{prefix}trajectory.png'))
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    precession_axes(axes, record, info)
    axes[0].set_title(
        f'Nutation and precession about the equilibrium point\n{subtitle}', fontsize=9
    )
    paths.append(_save(fig, out / f'{prefix}precession.png'))
    return paths


def angles_deg(x) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the angles [deg] of the axis whose velocity-frame components are x = s2 + i s3.

    (nose above the velocity atan2(s2, s1), nose right of it atan2(s3, s1)), with the unit
    axis' s1 = sqrt(1 - s2^2 - s3^2): the angles themselves, not 180/pi times s2 and s3.
    """
    x = np.asarray(x, dtype=complex)
    s1 = np.sqrt(np.clip(1.0 - np.abs(x) ** 2, 0.0, None))
    return np.degrees(np.arctan2(x.real, s1)), np.degrees(np.arctan2(x.imag, s1))


def _angle_between_deg(x, y) -> np.ndarray:
    """Angle [deg] between the unit axes of velocity-frame components x and y (s2 + i s3)."""
    x, y = np.asarray(x, dtype=complex), np.asarray(y, dtype=complex)
    s1x = np.sqrt(np.clip(1.0 - np.abs(x) ** 2, 0.0, None))
    s1y = np.sqrt(np.clip(1.0 - np.abs(y) ** 2, 0.0, None))
    chord = np.sqrt((s1x - s1y) ** 2 + np.abs(x - y) ** 2)
    return np.degrees(2.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0)))


def wobble_axes(ax, record: FlightRecord, info: FlightInfo) -> None:
    """Nose up against nose right [deg] (:func:`angles_deg`): flight, theories, equilibrium."""
    x = components(record, info)
    s3p = equilibrium_sideslip(record, info)
    up, right = angles_deg(x)
    ax.plot(right, up, lw=1.0, label='spin axis (integrated)')
    lin_up, lin_right = angles_deg(components_from_angles(record.alpha_linear,
                                                          record.beta_linear))
    ax.plot(
        lin_right,
        lin_up,
        lw=0.8,
        ls='--',
        color='gray',
        label='linear theory, V and $\\Phi$ frozen at release',
    )
    if record.alpha_quasi_steady is not None:
        qs_up, qs_right = angles_deg(
            components_from_angles(record.alpha_quasi_steady, record.beta_quasi_steady))
        ax.plot(
            qs_right,
            qs_up,
            lw=0.8,
            ls=':',
            color='tab:green',
            label='linear theory, quasi-steady',
        )
    s3p_right = angles_deg(1j * s3p)[1]
    ax.plot(
        s3p_right,
        np.zeros_like(s3p),
        color='tab:red',
        lw=1.0,
        alpha=0.6,
        label='equilibrium $s_{3p}$ along the flight',
    )
    ax.plot(
        s3p_right[0],
        0.0,
        marker='*',
        ms=14,
        color='tab:red',
        ls='none',
        label='equilibrium at release',
    )
    ax.plot(right[0], up[0], marker='o', color='k', ls='none', label='release')
    ax.axhline(0, color='k', lw=0.5)
    ax.axvline(0, color='k', lw=0.5)
    ax.set_xlabel('nose right of the velocity, atan2($s_3$, $s_1$) [deg]')
    ax.set_ylabel('nose above the velocity, atan2($s_2$, $s_1$) [deg]')
    ax.set_aspect('equal', adjustable='datalim')
    ax.legend(**LEGEND)


def angle_axes(axes, record: FlightRecord, info: FlightInfo) -> None:
    """Alpha and beta against time: integrated, frozen and quasi-steady linear theory."""
    s3p = equilibrium_sideslip(record, info)
    qs = (record.alpha_quasi_steady, record.beta_quasi_steady)
    rows = (
        (axes[0], 'angle of attack $\\alpha$', record.alpha, record.alpha_linear),
        (axes[1], 'sideslip $\\beta$', record.beta, record.beta_linear),
    )
    for k, (ax, name, value, lin) in enumerate(rows):
        ax.plot(record.t, DEG(value), label='nonlinear (integrated)')
        ax.plot(record.t, DEG(lin), ls='--', label='linear theory, frozen')
        if qs[k] is not None:
            ax.plot(record.t, DEG(qs[k]), ls=':', label='linear theory, quasi-steady')
        if k == 1:
            ax.plot(
                record.t,
                angles_deg(1j * s3p)[1],
                color='tab:red',
                lw=0.8,
                alpha=0.7,
                label='equilibrium $s_{3p}$',
            )
        ax.set_ylabel(f'{name} [deg]')
        ax.grid(alpha=0.3)
        ax.legend(**LEGEND)
    axes[1].set_xlabel('time since release [s]')


def trajectory_axes(axes, record: FlightRecord) -> None:
    """Side view (x, z) with the ground z = 0, top view (x, y)."""
    axes[0].plot(record.position[:, 0], record.position[:, 2], label='ball')
    axes[0].axhline(0.0, color='saddlebrown', lw=1.5, label='ground z = 0')
    top = max(1.0, float(np.max(record.position[:, 2])))
    axes[0].set_ylim(-0.06 * top, 1.12 * top)  # the arc fills the panel (heights not to scale)
    axes[0].set_ylabel('height z [m]')
    axes[0].legend(**LEGEND)
    axes[1].plot(record.position[:, 0], record.position[:, 1])
    lateral = max(1.0, 1.2 * float(np.max(np.abs(record.position[:, 1]))))
    axes[1].set_ylim(-lateral, lateral)
    axes[1].set_ylabel('lateral y, left > 0 [m]')
    axes[1].set_xlabel('downfield x [m]')
    for ax in axes:
        ax.grid(alpha=0.3)


def complementary(record: FlightRecord, info: FlightInfo) -> dict[str, np.ndarray]:
    """
    Return the complementary part x_c = x - i s3p(t) of the flight and the theories.

    Of the integrated flight and of the linear theories (frozen: its own s3p at release), keyed
    "nonlinear", "frozen", "quasi_steady".
    """
    s3p = equilibrium_sideslip(record, info)
    out = {
        'nonlinear': components(record, info) - 1j * s3p,
        'frozen': components_from_angles(record.alpha_linear, record.beta_linear) - 1j * s3p[0],
    }
    if record.alpha_quasi_steady is not None:
        quasi = components_from_angles(record.alpha_quasi_steady, record.beta_quasi_steady)
        out['quasi_steady'] = quasi - 1j * s3p
    return out


def precession_axes(axes, record: FlightRecord, info: FlightInfo) -> None:
    """
    Nutation and precession (unwrapped arg x_c) about the equilibrium point.

    Nutation: the angle between the axis and the equilibrium axis (s3p and its own s1).
    """
    styles = {
        'nonlinear': {'label': 'nonlinear (integrated)'},
        'frozen': {'ls': '--', 'label': 'linear theory, frozen'},
        'quasi_steady': {'ls': ':', 'label': 'linear theory, quasi-steady'},
    }
    s3p = equilibrium_sideslip(record, info)
    for key, xc in complementary(record, info).items():
        centre = 1j * (s3p[0] if key == 'frozen' else s3p)
        axes[0].plot(record.t, _angle_between_deg(xc + centre, centre), **styles[key])
        axes[1].plot(record.t, DEG(np.unwrap(np.angle(xc))), **styles[key])
    axes[0].set_ylabel('nutation: angle from\nthe equilibrium axis [deg]')
    axes[1].set_ylabel('precession: angle about the\nequilibrium arg $x_c$ [deg]')
    axes[1].set_xlabel('time since release [s]')
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(**LEGEND)


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
