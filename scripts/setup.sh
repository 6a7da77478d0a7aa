#!/usr/bin/env bash
# Create ./.venv with football_ros, ROS 2 Jazzy from PyPI wheels and the test tools, build the
# interface packages that have no wheel, and compile the numba kernels ahead (so the nodes are
# ready at once and the first throw answers). Prints a line at least every 20 s.
# Idempotent: a second run only checks that everything is installed and the kernels cached.
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
SETUP_START=$SECONDS

# heartbeat LABEL: a line every 20 s until killed (for the steps that are silent for long).
heartbeat() {
  local start=$SECONDS
  while sleep 20 > /dev/null 2>&1; do
    echo "[setup]   ... still $1 ($((SECONDS - start)) s)"
  done
}
stop() { kill "$1" 2> /dev/null; wait "$1" 2> /dev/null || true; }

if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv with $($PYTHON --version) (first time: about 5-10 min in all)"
  "$PYTHON" -m venv .venv
  .venv/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip setuptools wheel \
    > .venv/pip-upgrade.log 2>&1 || { cat .venv/pip-upgrade.log; exit 1; }
fi
echo "[setup] installing football_ros[ros,test] into .venv"
# Progress: each package pip fetches, one line (the whole output: .venv/pip-install.log).
heartbeat "installing with pip" &
BEAT=$!
if ! .venv/bin/python -m pip install --disable-pip-version-check -e ".[ros,test]" 2>&1 \
    | tee .venv/pip-install.log \
    | { grep --line-buffered -E '^(Collecting|Installing collected)' \
        | sed -u -E 's/^(.{0,90}).*/[setup]   pip: \1/'; true; }; then
  stop "$BEAT"
  grep -v "is ignored: it is neither a file nor a directory" .venv/pip-install.log | tail -40
  echo "[setup] pip install failed; full log: .venv/pip-install.log" >&2
  exit 1
fi
stop "$BEAT"
# The kernels need no ROS: they compile (or load, when cached) while colcon builds.
.venv/bin/football-ros compile > .venv/compile.log 2>&1 &
COMPILE=$!
# tf2_msgs and simulation_interfaces have no wheel: build pip_ros/* with colcon into .venv
# (each skipped once built).
if ! AMENT_PREFIX_PATH= .venv/bin/python pip_ros/build_into_venv.py; then
  stop "$COMPILE"
  echo "[setup] building the pip_ros interface packages failed (needs cmake and a C compiler)" >&2
  exit 1
fi
.venv/bin/python -c "import rclpy, football_ros; print('[setup] ok: rclpy and football_ros', football_ros.__version__)"
echo "[setup] numba kernels (compiled ahead once after an install or a source change, then loaded)"
heartbeat "compiling the numba kernels" &
BEAT=$!
if ! wait "$COMPILE"; then
  stop "$BEAT"
  cat .venv/compile.log
  echo "[setup] football-ros compile failed; log: .venv/compile.log" >&2
  exit 1
fi
stop "$BEAT"
sed 's/^/[setup]   /' .venv/compile.log
echo "[setup] done in $((SECONDS - SETUP_START)) s"
