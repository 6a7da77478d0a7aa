#!/usr/bin/env bash
# Set up (if needed) and run the demo: simulator + release node + recorder, one spiral pass.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/football-ros demo "$@"
