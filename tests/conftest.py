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
#: Session fixtures that cost seconds to build, each with its xdist group: every test that uses one runs on
#: the same worker (``--dist loadgroup``), so each is built once per run, not once per worker. One group per
#: build, so the docs site and the tiny main-job run are built on two workers at once rather than one after
#: the other on one. A test that uses both joins the group of the first (the other is then built on its
#: worker too: correct, only slower; no test does today).
_SHARED_BUILDS = {"docs_site": "docs-site", "tiny_paper_run": "tiny-paper-run"}


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):
    """Mark the tests of a shared build with its ``xdist_group``; then make every group take effect.

    A group takes effect through the suffix ``@group`` of the test's id, by which the controller's
    ``loadgroup`` scheduler sends the group to one worker. pytest-xdist's worker adds it itself by setting
    ``item._nodeid``, which pytest 9.2 no longer reads (a node's id is ``item._id``, a ``NodeId``): with
    pytest 9.2 and pytest-xdist 3.8 every group was spread over both workers, so the docs site and the tiny
    main-job run were each built twice, once per worker, and the fuzz module was split. Here the suffix is
    added (last, after xdist's own hook) through whichever attribute the installed pytest reads, and only
    where it is missing.
    """
    for item in items:
        names = getattr(item, "fixturenames", ())
        group = next((g for fixture, g in _SHARED_BUILDS.items() if fixture in names), None)
        if group is not None:
            item.add_marker(pytest.mark.xdist_group(group))
    if not getattr(config.option, "loadgroup", False):     # set by xdist's worker under --dist loadgroup
        return
    for item in items:
        groups = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                         for m in item.iter_markers("xdist_group")})
        if not groups or "@" in item.nodeid.rsplit("]", 1)[-1]:
            continue
        tagged = f"{item.nodeid}@{'_'.join(groups)}"
        if isinstance(getattr(item, "_id", None), str) or not hasattr(item, "_id"):
            item._nodeid = tagged
        else:
            from _pytest.nodeid import NodeId          # pytest >= 9.2
            item._id = NodeId.parse(tagged)
        assert item.nodeid == tagged, (item.nodeid, tagged)


# ------------------------------------------------------------------ where the suite's time goes (opt-in)
#: ``SUITE_PROFILE=FILE`` writes, per test, its wall and CPU time and the numba compile time it paid
#: (outermost compiles only, so a kernel that compiles its callees is counted once), one JSON line per test,
#: appended by every xdist worker; ``python tools/suite_profile.py FILE`` summarises it.
_PROFILE = os.environ.get("SUITE_PROFILE")
if _PROFILE:
    import json
    import time

    from numba.core import event as _numba_event

    class _CompileClock(_numba_event.Listener):
        depth = 0
        start = 0.0
        total = 0.0
        kernels: list = []

        def on_start(self, event):
            if self.depth == 0:
                self.start = time.perf_counter()
            self.depth += 1

        def on_end(self, event):
            self.depth -= 1
            if self.depth == 0:
                t = time.perf_counter() - self.start
                self.total += t
                f = getattr(event.data.get("dispatcher"), "py_func", None)
                self.kernels.append((f"{getattr(f, '__module__', '?')}.{getattr(f, '__qualname__', '?')}",
                                     str(event.data.get("args"))[:200], round(t, 3)))

    def _children_cpu():
        import resource
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    _CLOCK = _CompileClock()
    _numba_event.register("numba:compile", _CLOCK)

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(item, nextitem):
        _CLOCK.total, _CLOCK.kernels = 0.0, []
        w0, c0, k0 = time.perf_counter(), time.process_time(), _children_cpu()
        yield
        rec = dict(test=item.nodeid, worker=os.environ.get("PYTEST_XDIST_WORKER", "main"),
                   group=next((m.args[0] for m in item.iter_markers("xdist_group")), None),
                   start=w0, wall=time.perf_counter() - w0, cpu=time.process_time() - c0,
                   children_cpu=_children_cpu() - k0,
                   compile=_CLOCK.total, kernels=_CLOCK.kernels)
        with open(_PROFILE, "a") as fh:
            fh.write(json.dumps(rec) + "\n")
