#!/usr/bin/env bash
# Create (once) the project's virtual environment and install the package into it.
# Usage: tools/setup_env.sh [EXTRAS]   e.g. tools/setup_env.sh test
# Prints the path of the environment's python on its last line; pip's output goes to
# $VENV/setup.log and is shown only if a step fails.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${VENV:-.venv}"
EXTRAS="${1:-}"
if [ ! -x "$VENV/bin/python" ]; then
    echo "Creating the virtual environment $VENV (first run only) ..." >&2
    python3 -m venv "$VENV" >&2
fi
PY="$VENV/bin/python"
LOG="$VENV/setup.log"
: > "$LOG"
pipi() {
    if ! "$PY" -m pip install --disable-pip-version-check "$@" >>"$LOG" 2>&1; then
        echo "pip install $* failed; its output:" >&2
        tail -n 40 "$LOG" >&2
        exit 1
    fi
}
echo "Installing the package${EXTRAS:+ with extras [$EXTRAS]} into $VENV ..." >&2
pipi --upgrade pip setuptools wheel numpy
if [[ "$EXTRAS" == *test* || "$EXTRAS" == *bench* ]]; then
    # iisignature's setup.py imports numpy at build time: build it against the numpy above.
    "$PY" -c "import iisignature" 2>/dev/null || pipi --no-build-isolation "iisignature>=0.24"
fi
if [ -n "$EXTRAS" ]; then
    pipi -e ".[$EXTRAS]"
else
    pipi -e .
fi
echo "$PY"
