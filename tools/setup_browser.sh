#!/usr/bin/env bash
# Make sure headless Chromium (Debian's `chromium` package) is installed for the browser test
# (tests/docs/test_browser.py). Idempotent and instant when it is already there. Installs with apt-get when
# run as root (as CI is); otherwise says how. Never downloads a browser build of its own.
set -euo pipefail
if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then
    exit 0
fi
if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "setup_browser.sh: Chromium is not installed; the browser test will be skipped (failed under CI)." >&2
    echo "  Install it with: sudo apt-get update && sudo apt-get install -y chromium" >&2
    exit 0
fi
echo "Installing Debian's chromium for the browser test (first run only) ..." >&2
LOG="$(mktemp)"
if ! { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium; } >"$LOG" 2>&1; then
    echo "apt-get install chromium failed; its output:" >&2
    tail -n 40 "$LOG" >&2
    rm -f "$LOG"
    exit 1
fi
rm -f "$LOG"
