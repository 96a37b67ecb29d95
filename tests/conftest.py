"""Shared test configuration: hypothesis profile and seeded generators."""

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

# Numba compiles on first call and the CI machine is shared: no per-example deadline.
settings.register_profile("default", deadline=None, max_examples=40,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", deadline=None, max_examples=400,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


@pytest.fixture
def rng():
    """A fresh, seeded generator per test (results reproducible from the seed)."""
    return np.random.default_rng(20261121)


# ------------------------------------------------------------------ built once per session, shared
ROOT = Path(__file__).resolve().parents[1]
DOCS_TOOLCHAIN = ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")


def _missing_modules(names):
    missing = []
    for name in names:
        try:
            found = importlib.util.find_spec(name) is not None
        except ModuleNotFoundError:
            found = False
        if not found:
            missing.append(name)
    return missing


@pytest.fixture(scope="session")
def docs_site(tmp_path_factory):
    """The documentation site, built once per session by ``mkdocs build --strict``.

    Returns the finished ``subprocess.CompletedProcess`` with ``site`` (the output folder) attached.
    Skipped when the docs toolchain is not installed (it is in the ``docs`` extra), failed under
    ``CI=true``. KaTeX is vendored first (``tools/vendor_katex.sh``, a no-op when present); where that
    fails outside CI, ``katex_missing`` says why and the tests that need KaTeX skip.
    """
    missing = _missing_modules(DOCS_TOOLCHAIN)
    if missing and os.environ.get("CI"):
        pytest.fail(f"docs toolchain not installed in CI ({', '.join(missing)}); ./test.sh installs the "
                    f"docs extra, so the strict build must run there.")
    if missing:
        pytest.skip(f"docs toolchain not installed ({', '.join(missing)}); install the docs extra: "
                    f"pip install -e '.[docs]'")
    vendor = subprocess.run(["bash", str(ROOT / "tools" / "vendor_katex.sh")], capture_output=True, text=True,
                            timeout=300)
    if vendor.returncode != 0 and os.environ.get("CI"):
        pytest.fail(f"tools/vendor_katex.sh failed (KaTeX is needed to typeset the site):\n{vendor.stderr}")
    site = tmp_path_factory.mktemp("docs") / "site"
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                          cwd=ROOT, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"}, capture_output=True,
                          text=True, timeout=300)
    proc.site = site
    # Without KaTeX (no npm here, outside CI) the site still builds; the tests that typeset skip.
    proc.katex_missing = None if vendor.returncode == 0 else vendor.stderr.strip() or "vendor_katex.sh failed"
    return proc


@pytest.fixture(scope="session")
def tiny_paper_run(tmp_path_factory):
    """``python -m mechanics --tiny --output DIR --seed 3`` run once per session, as a user runs it.

    Returns the finished ``subprocess.CompletedProcess`` with ``out`` (the output folder) attached.
    """
    out = tmp_path_factory.mktemp("paper") / "paper"
    proc = subprocess.run([sys.executable, "-m", "mechanics", "--tiny", "--output", str(out), "--seed", "3"],
                          capture_output=True, text=True, timeout=600)
    proc.out = out
    return proc


# ------------------------------------------------------------------ two workers (pytest-xdist)
#: Session fixtures that cost seconds to build: every test that uses one runs on the same worker
#: (``--dist loadgroup``), so each is built once per run, not once per worker (a test may use both).
_SHARED_BUILDS = ("docs_site", "tiny_paper_run")


def pytest_collection_modifyitems(config, items):
    for item in items:
        if any(name in getattr(item, "fixturenames", ()) for name in _SHARED_BUILDS):
            item.add_marker(pytest.mark.xdist_group("shared-builds"))
