"""``tools/setup_env.sh`` installs only when something changed, and warms the kernels after an install.

Claims: with a stamp matching ``pyproject.toml``, the environment's Python version and the requested
extras, the script prints the environment's python and runs nothing else (no pip, no index); a
missing extra, a changed ``pyproject.toml`` or Python version, or a missing stamp triggers one
install of the union of the extras, then the warm-up (``python -m mechanics --tiny`` and both parts of
``tools/warm_kernels.py``), then a new stamp. ``--warm-up=background`` (``./run.sh``, which runs the main job
next) returns before the warm-up, which compiles both parts in one background process and no ``--tiny``
run; a warm-up that did not finish is done by the next call. The environment is a fake: its ``python``
records its arguments instead of installing.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "tools" / "setup_env.sh"

FAKE_PYTHON = """#!/usr/bin/env bash
echo "$*" >> "$(dirname "$0")/../calls.log"
exit 0
"""


@pytest.fixture
def venv(tmp_path):
    if shutil.which("bash") is None:
        pytest.skip("bash not available")
    v = tmp_path / "venv"
    (v / "bin").mkdir(parents=True)
    for name in ("python", "levy-area-paper"):
        (v / "bin" / name).write_text(FAKE_PYTHON)
        (v / "bin" / name).chmod(0o755)
    (v / "pyvenv.cfg").write_text("home = /usr/bin\nversion = 3.11.7\n")
    return v


def _setup(venv: Path, extras: str = "", *options: str) -> list[str]:
    log = venv / "calls.log"
    if log.exists():
        log.unlink()
    proc = subprocess.run(["bash", str(SCRIPT), *options, extras], env={**os.environ, "VENV": str(venv)},
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == f"{venv}/bin/python"
    pid_file = venv / ".warm-up.pid"
    deadline = time.monotonic() + 30
    while pid_file.exists() and time.monotonic() < deadline:      # a background warm-up: let it end
        time.sleep(0.05)
    assert not pid_file.exists()
    return log.read_text().splitlines() if log.exists() else []


def test_install_once_then_skip_until_something_changes(venv):
    calls = _setup(venv, "test")                 # no stamp: install, warm up, stamp
    installs = [c for c in calls if c.startswith("-m pip install") and " -e " in f" {c} "]
    assert installs == ["-m pip install --disable-pip-version-check -e .[test]"], calls
    assert any(c.startswith("-m mechanics --tiny --quiet") for c in calls), calls
    assert {c for c in calls if c.startswith("tools/warm_kernels.py")} == {
        "tools/warm_kernels.py --part roughpaths --more", "tools/warm_kernels.py --part mechanics --more"}, calls
    assert not (venv / ".warm-up-pending").exists()
    assert (venv / ".setup-stamp").read_text().splitlines()[1] == "test"

    assert _setup(venv, "test") == []            # nothing changed: nothing runs
    assert _setup(venv, "") == []                # fewer extras than installed: nothing runs

    calls = _setup(venv, "docs")                 # a new extra: install the union
    assert "-m pip install --disable-pip-version-check -e .[docs,test]" in calls, calls
    assert _setup(venv, "test,docs") == [] and _setup(venv, "docs") == []

    (venv / "pyvenv.cfg").write_text("home = /usr/bin\nversion = 3.12.1\n")   # another Python
    assert "-m pip install --disable-pip-version-check -e .[docs,test]" in _setup(venv, "")
    assert _setup(venv, "") == []


def test_a_damaged_stamp_or_environment_reinstalls(venv):
    _setup(venv, "")
    (venv / ".setup-stamp").write_text("not a hash\n\n")
    assert "-m pip install --disable-pip-version-check -e ." in _setup(venv, "")
    (venv / "bin" / "levy-area-paper").unlink()     # the package was uninstalled by hand
    assert "-m pip install --disable-pip-version-check -e ." in _setup(venv, "")


def test_background_warm_up_skips_the_main_job_and_an_interrupted_one_is_redone(venv):
    calls = _setup(venv, "", "--warm-up=background")
    assert not any("--tiny" in c for c in calls), calls          # the caller runs the main job itself
    assert [c for c in calls if c.startswith("tools/warm_kernels.py")] == [
        "tools/warm_kernels.py --part roughpaths", "tools/warm_kernels.py --part mechanics"], calls
    assert "Compiled in" in (venv / "warm-up.log").read_text()
    assert not (venv / ".warm-up-pending").exists()
    assert _setup(venv, "", "--warm-up=background") == []        # done: nothing runs

    (venv / ".warm-up-pending").touch()                          # as if the warm-up had been killed
    calls = _setup(venv, "")
    assert not any(c.startswith("-m pip") for c in calls), calls   # no reinstall, only the warm-up
    assert any(c.startswith("-m mechanics --tiny") for c in calls), calls
    assert not (venv / ".warm-up-pending").exists()
    assert _setup(venv, "") == []


def test_an_unknown_warm_up_mode_is_refused(venv):
    proc = subprocess.run(["bash", str(SCRIPT), "--warm-up=later"], env={**os.environ, "VENV": str(venv)},
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "--warm-up=now or --warm-up=background" in proc.stderr
