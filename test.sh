#!/usr/bin/env bash
# Set up the environment (first run only; with the test, docs and dask extras, so the scale-out test runs,
# the torch and jax extras, so the framework front ends roughpaths.torch / roughpaths.jax are tested, and the
# progress extra, so the progress bar is tested with tqdm)
# and run the test suite. Extra arguments go to pytest,
# e.g. ./test.sh -m slow  (the long statistical runs), ./test.sh -x -q tests/roughpaths/paths/test_chen_identity.py
set -euo pipefail
cd "$(dirname "$0")"
PY="$(tools/setup_env.sh test,docs,dask,torch,jax,progress | tail -n 1)"
# KaTeX for the documentation site (npm package, pinned) and Debian's chromium for the browser test;
# both no-ops when present. Where they cannot be had (no npm, not root), the tests that need them skip,
# except under CI=true, where they fail.
tools/vendor_katex.sh || echo "test.sh: KaTeX could not be vendored; the docs typesetting checks will skip" >&2
tools/setup_browser.sh || echo "test.sh: chromium could not be installed; the browser test will skip" >&2
# Two workers (the CI machine has two cores); the tests that share a session-wide build (the docs site, the
# tiny main-job run) run on one of them (tests/conftest.py). PYTEST_WORKERS=0 runs in this process.
exec "$PY" -m pytest -n "${PYTEST_WORKERS:-2}" --dist loadgroup "$@"
