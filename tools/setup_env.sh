#!/usr/bin/env bash
# Create (once) the project's virtual environment and install the package into it.
# Usage: tools/setup_env.sh [EXTRAS]   e.g. tools/setup_env.sh test
# Prints the path of the environment's python on its last line.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV="${VENV:-.venv}"
EXTRAS="${1:-}"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV" >&2
fi
PY="$VENV/bin/python"
"$PY" -m pip install -q --disable-pip-version-check --upgrade pip setuptools wheel numpy >&2
if [[ "$EXTRAS" == *test* || "$EXTRAS" == *bench* ]]; then
    # iisignature's setup.py imports numpy: build it against the numpy installed above.
    "$PY" -c "import iisignature" 2>/dev/null || \
        "$PY" -m pip install -q --disable-pip-version-check --no-build-isolation "iisignature>=0.24" >&2
fi
if [ -n "$EXTRAS" ]; then
    "$PY" -m pip install -q --disable-pip-version-check -e ".[$EXTRAS]" >&2
else
    "$PY" -m pip install -q --disable-pip-version-check -e . >&2
fi
echo "$PY"
