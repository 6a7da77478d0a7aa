#!/usr/bin/env bash
# Create ./.venv with football_ros, ROS 2 Jazzy from PyPI wheels and the test tools, then
# compile the numba kernels ahead (so the nodes are ready at once and the first throw answers).
# Idempotent: a second run only checks that everything is installed and the kernels cached.
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
FIRST_TIME=""
if [ ! -x .venv/bin/python ]; then
  FIRST_TIME=" (first time: a few minutes, with the interface builds after it)"
  echo "[setup] creating .venv with $($PYTHON --version)"
  "$PYTHON" -m venv .venv
  .venv/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip setuptools wheel \
    > .venv/pip-upgrade.log 2>&1 || { cat .venv/pip-upgrade.log; exit 1; }
fi
echo "[setup] installing football_ros[ros,test] into .venv$FIRST_TIME"
# Progress: each package pip fetches, one line (the whole output: .venv/pip-install.log).
if ! .venv/bin/python -m pip install --disable-pip-version-check -e ".[ros,test]" 2>&1 \
    | tee .venv/pip-install.log \
    | { grep --line-buffered -E '^(Collecting|Installing collected)' \
        | sed -u -E 's/^(.{0,90}).*/[setup]   pip: \1/'; true; }; then
  grep -v "is ignored: it is neither a file nor a directory" .venv/pip-install.log | tail -40
  echo "[setup] pip install failed; full log: .venv/pip-install.log" >&2
  exit 1
fi
# tf2_msgs and simulation_interfaces have no wheel: build pip_ros/* with colcon into .venv
# (each skipped once built; simulation_interfaces takes a few minutes the first time).
if ! AMENT_PREFIX_PATH= .venv/bin/python pip_ros/build_into_venv.py; then
  echo "[setup] building tf2_msgs / simulation_interfaces failed (needs cmake and a C/C++ compiler)" >&2
  exit 1
fi
.venv/bin/python -c "import rclpy, football_ros; print('[setup] ok: rclpy and football_ros', football_ros.__version__)"
echo "[setup] compiling the numba kernels ahead" \
  "(about 30 s after an install or a source change, < 1 s when cached)"
.venv/bin/football-ros compile
