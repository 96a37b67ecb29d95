#!/usr/bin/env bash
# Set up the environment (first run only) and run the test suite. Extra arguments go to pytest,
# e.g. ./test.sh -m slow  (the long statistical runs), ./test.sh -x -q tests/test_chen_identity.py
set -euo pipefail
cd "$(dirname "$0")"
PY="$(tools/setup_env.sh test,docs | tail -n 1)"
tools/vendor_katex.sh     # KaTeX for the documentation site (npm package, pinned; no-op when present)
tools/setup_browser.sh    # Debian's chromium for tests/test_browser.py (no-op when installed)
exec "$PY" -m pytest "$@"
