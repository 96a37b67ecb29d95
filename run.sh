#!/usr/bin/env bash
# Set up the environment (first run only) and run the main job: reproduce the paper's figures and
# theorem checks on default sizes. Extra arguments go to the command (see: ./run.sh --help).
set -euo pipefail
cd "$(dirname "$0")"
PY="$(tools/setup_env.sh | tail -n 1)"
exec "$PY" -m mechanics "$@"
