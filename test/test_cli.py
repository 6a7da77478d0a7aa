"""The ``football-ros`` command-line contract (keys, header, rows, exit codes)."""

import csv
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from football_ros.physics import CSV_HEADER

CLI = [sys.executable, "-m", "football_ros.cli"]


def run(*args, check=True):
    proc = subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=120)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def test_modes_json_has_the_contract_keys_and_paper_numbers():
    report = json.loads(run("modes", "--json").stdout)
    for key in ("m_alpha", "h1", "omega_fast", "omega_slow", "stable", "critical_spin_rpm",
                "equilibrium_sideslip", "c1", "c2"):
        assert key in report
    assert report["stable"] is True
    assert report["omega_fast"] == pytest.approx(32.01, rel=5e-3)
    assert report["omega_slow"] == pytest.approx(5.958, rel=5e-3)
    assert report["equilibrium_sideslip"] == pytest.approx(0.0617, rel=5e-3)
    assert len(report["c1"]) == 2 and len(report["c2"]) == 2


def test_modes_table_is_readable():
    out = run("modes", "--ball", "rugby").stdout
    assert "omega_fast" in out and "rugby" in out and "rpm" in out


def test_simulate_writes_the_contract_csv(tmp_path):
    out = tmp_path / "flight.csv"
    run("simulate", "--rate", "50", "--out", str(out))
    with open(out) as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == CSV_HEADER
    assert ",".join(rows[0][:18]) == ("t,x,y,z,vx,vy,vz,qx,qy,qz,qw,sx,sy,sz,alpha,beta,"
                                      "alpha_linear,beta_linear")
    data = np.array(rows[1:], dtype=float)
    t_land = 2 * 27.4 * math.sin(math.radians(30)) / 9.81
    assert data[-1, 0] == pytest.approx(t_land, abs=1e-9) and data[-1, 3] == 0.0
    assert np.allclose(data[:-1, 0], np.arange(len(data) - 1) / 50.0, atol=1e-12)
    assert np.all(data[:-1, 3] >= 0)
    # Unit quaternion with x axis = s; mean sideslip positive for a right-handed spiral.
    assert np.allclose(np.linalg.norm(data[:, 7:11], axis=1), 1.0, atol=1e-12)
    assert np.mean(data[:, 15]) > 0


def test_simulate_stops_at_duration(tmp_path):
    out = tmp_path / "short.csv"
    run("simulate", "--duration", "0.5", "--rate", "10", "--ball", "rugby", "--out", str(out))
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (6, len(CSV_HEADER)) and data[-1, 0] == pytest.approx(0.5)


@pytest.mark.parametrize("args", [
    ["modes", "--speed", "-3"], ["modes", "--speed", "nan"], ["modes", "--speed", "abc"],
    ["modes", "--ball", "soccer"], ["modes", "--ball-param", "mass"], ["modes", "--bogus"],
    ["simulate", "--out", "/nonexistent-dir/x.csv"], ["simulate"], [],
    ["simulate", "--rate", "0", "--out", "x.csv"],
])
def test_bad_options_exit_2_with_one_line(args):
    proc = run(*args, check=False)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("football-ros: error:"), proc.stderr
    assert "Traceback" not in proc.stderr


def test_physics_and_headless_commands_need_no_ros(tmp_path):
    """With rclpy and every ROS message package unimportable, the headless commands still run."""
    blocked = ["rclpy", "std_msgs", "geometry_msgs", "nav_msgs", "diagnostic_msgs", "visualization_msgs",
               "rosgraph_msgs", "std_srvs", "builtin_interfaces"]
    csv_path, figs = tmp_path / "f.csv", tmp_path / "figs"
    code = (f"import sys\nfor name in {blocked!r}: sys.modules[name] = None\n"
            "from football_ros.cli import main\n"
            f"assert main(['modes', '--json']) == 0\n"
            f"assert main(['simulate', '--out', {str(csv_path)!r}]) == 0\n"
            f"assert main(['plot', {str(csv_path)!r}, '--out', {str(figs)!r}]) == 0\n"
            f"assert main(['montecarlo', '--n', '50', '--quiet', '--out', {str(tmp_path / 'mc.csv')!r}]) == 0\n"
            "assert not any(m.split('.')[0] in {'rclpy'} for m in sys.modules if sys.modules[m] is not None)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert len(list(figs.glob("*.png"))) == 4
