"""Figures in the paper's style, headless (Agg), from a bag or a simulate CSV.

wobble.png: the axis seen in the velocity frame (s3 horizontal, right > 0; s2 vertical, up > 0)
with the equilibrium s3p marked; angles.png: alpha and beta against time with the linear theory;
trajectory.png: side and top views; precession.png: the total angle delta (nutation) and the
precession angle atan2(s3, s2) of the axis around the velocity.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..physics import frames, get_preset  # noqa: E402
from ..physics.release import RPM  # noqa: E402
from .flightdata import FlightRecord, load  # noqa: E402


def equilibrium_sideslip(record: FlightRecord, ball_name: str, spin_rpm: float | None) -> tuple[np.ndarray, float]:
    """s3p(t) = g cos(Phi) h1 / (M_alpha(V) V) along the flight [rad], and the spin used [rpm]
    (the recorded spin when the source has it, else ``spin_rpm`` or the preset's)."""
    ball = get_preset(ball_name)
    if spin_rpm is None:
        spin_rpm = float(np.median(record.spin)) / RPM if record.spin is not None else ball.spin_rpm
    speed = np.linalg.norm(record.velocity, axis=1)
    phi = frames.flight_path_angle(record.velocity)
    h1 = ball.inertia_ratio * spin_rpm * RPM
    return frames.GRAVITY * np.cos(phi) * h1 / (ball.moment_coefficient() * speed ** 3), spin_rpm


def plot_source(source: str | Path, out_dir: str | Path, ball: str = "american",
                spin_rpm: float | None = None) -> list[Path]:
    """Write the four PNG figures for the flight in ``source``; returns their paths."""
    record = load(source)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    s_vf = frames.to_velocity_frame(record.axis, record.velocity)
    s3p, spin_used = equilibrium_sideslip(record, ball, spin_rpm)
    subtitle = f"{Path(record.source).name} ({ball}, {spin_used:.0f} rpm)"
    paths = []

    fig, ax = plt.subplots(figsize=(6.5, 6))
    deg = np.degrees
    ax.plot(deg(s_vf[:, 2]), deg(s_vf[:, 1]), lw=1.0, label="spin axis (integrated)")
    ax.plot(deg(record.beta_linear), deg(record.alpha_linear), lw=0.8, ls="--", color="gray",
            label="linear theory (V, $\\Phi$ frozen at release)")
    ax.plot(deg(s3p), np.zeros_like(s3p), color="tab:red", lw=1.0, alpha=0.6,
            label="equilibrium $s_{3p}$ along the flight")
    ax.plot(deg(s3p[0]), 0.0, marker="*", ms=14, color="tab:red", ls="none", label="equilibrium at release")
    ax.plot(deg(s_vf[0, 2]), deg(s_vf[0, 1]), marker="o", color="k", ls="none", label="release")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("$s_3$: nose right of the velocity [deg]")
    ax.set_ylabel("$s_2$: nose above the velocity [deg]")
    ax.set_title(f"Wobble in the velocity frame\n{subtitle}")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8, loc="best")
    paths.append(_save(fig, out / "wobble.png"))

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for ax, name, value, lin in ((axes[0], "angle of attack $\\alpha$", record.alpha, record.alpha_linear),
                                 (axes[1], "sideslip $\\beta$", record.beta, record.beta_linear)):
        ax.plot(record.t, deg(value), label="nonlinear (integrated)")
        ax.plot(record.t, deg(lin), ls="--", label="linear theory")
        ax.set_ylabel(f"{name} [deg]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[1].plot(record.t, deg(s3p), color="tab:red", lw=0.8, alpha=0.7, label="equilibrium $s_{3p}$")
    axes[1].legend(fontsize=8)
    axes[1].set_xlabel("time since release [s]")
    axes[0].set_title(f"Angle of attack and sideslip\n{subtitle}")
    paths.append(_save(fig, out / "angles.png"))

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    axes[0].plot(record.position[:, 0], record.position[:, 2])
    axes[0].set_ylabel("height z [m]")
    axes[0].set_title(f"Trajectory (field frame: x downfield, y left, z up)\n{subtitle}")
    axes[1].plot(record.position[:, 0], record.position[:, 1])
    lateral = max(1.0, 1.2 * float(np.max(np.abs(record.position[:, 1]))))
    axes[1].set_ylim(-lateral, lateral)
    axes[1].set_ylabel("lateral y, left > 0 [m]")
    axes[1].set_xlabel("downfield x [m]")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].set_aspect("equal", adjustable="datalim")
    paths.append(_save(fig, out / "trajectory.png"))

    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    delta = np.arccos(np.clip(s_vf[:, 0], -1.0, 1.0))
    precession = np.unwrap(np.arctan2(s_vf[:, 2], s_vf[:, 1]))
    axes[0].plot(record.t, deg(delta))
    axes[0].set_ylabel("total angle $\\delta$ [deg]")
    axes[0].set_title(f"Nutation and precession of the axis about the velocity\n{subtitle}")
    axes[1].plot(record.t, deg(precession))
    axes[1].set_ylabel("precession angle\natan2($s_3$, $s_2$) [deg]")
    axes[1].set_xlabel("time since release [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    paths.append(_save(fig, out / "precession.png"))
    return paths


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
