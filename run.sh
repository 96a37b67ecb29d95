#!/usr/bin/env bash
# Set up the environment (first run only) and run the main job: reproduce the paper's figures and
# theorem checks on default sizes. Extra arguments go to the command (see: ./run.sh --help).
# On the first run the main job compiles its own numba kernels while one background process compiles the
# library's other kernels (tools/setup_env.sh --warm-up=background); this script waits for it at the end.
set -euo pipefail
cd "$(dirname "$0")"
VENV="${VENV:-.venv}"
PY="$(tools/setup_env.sh --warm-up=background | tail -n 1)"
rc=0
"$PY" -m mechanics "$@" || rc=$?
PID_FILE="$VENV/.warm-up.pid"
if [ -f "$PID_FILE" ] && kill -0 "$(cat "$PID_FILE" 2>/dev/null)" 2>/dev/null; then
    echo "Waiting for the background compilation of the library's other kernels (first run only; log: $VENV/warm-up.log) ..." >&2
    while [ -f "$PID_FILE" ] && kill -0 "$(cat "$PID_FILE" 2>/dev/null)" 2>/dev/null; do sleep 1; done
fi
if [ -f "$VENV/warm-up.log" ] && [ ! -f "$PID_FILE" ]; then      # say how the background compilation ended
    grep -h "^warning\|^Compiled in" "$VENV/warm-up.log" | sed 's/^/warm-up: /' >&2 || true
    rm -f "$VENV/warm-up.log"
fi
exit "$rc"
