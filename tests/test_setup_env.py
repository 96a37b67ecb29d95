"""``tools/setup_env.sh`` installs only when something changed, and warms the kernels after an install.

Claims: with a stamp matching ``pyproject.toml``, the environment's Python version and the requested
extras, the script prints the environment's python and runs nothing else (no pip, no index); a
missing extra, a changed ``pyproject.toml`` or Python version, or a missing stamp triggers one
install of the union of the extras, then the warm-up run (``python -m mechanics --tiny``), then a new
stamp. The environment is a fake: its ``python`` records its arguments instead of installing.
"""

from __future__ import annotations

import os
import shutil
import subprocess
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


def _setup(venv: Path, extras: str = "") -> list[str]:
    log = venv / "calls.log"
    if log.exists():
        log.unlink()
    proc = subprocess.run(["bash", str(SCRIPT), extras], env={**os.environ, "VENV": str(venv)},
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == f"{venv}/bin/python"
    return log.read_text().splitlines() if log.exists() else []


def test_install_once_then_skip_until_something_changes(venv):
    calls = _setup(venv, "test")                 # no stamp: install, warm up, stamp
    installs = [c for c in calls if c.startswith("-m pip install") and " -e " in f" {c} "]
    assert installs == ["-m pip install --disable-pip-version-check -e .[test]"], calls
    assert any(c.startswith("-m mechanics --tiny --quiet") for c in calls), calls
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
