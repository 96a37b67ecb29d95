"""Every tutorial in ``docs/tutorials/*.py`` runs to completion (at reduced sizes).

Claim: the tutorials the documentation shows are executable as published: each file is run as a
script (``runpy``, ``__name__ == "__main__"``) with ``TUTORIAL_SMALL=1``; their internal ``assert``
statements check the numbers they print (closed forms, Chen, Lévy-area moments, a classifier's accuracy
well above chance, ...). A tutorial that needs an optional extra (torch, jax) skips where it is missing,
and runs in a child process: torch and JAX start threads when imported, and later tests fork process
pools (a fork of a process with JAX's threads may deadlock), so this process never imports them.
"""

from __future__ import annotations

import importlib.util
import os
import runpy
import subprocess
import sys
from pathlib import Path

import pytest

TUTORIALS = sorted((Path(__file__).resolve().parents[2] / "docs" / "tutorials").glob("*.py"))
# tutorials that need an optional extra: skipped where it is missing, except under CI=true (./test.sh installs it)
NEEDS = {"signature_features_torch_jax": ("torch", "jax")}


def test_there_are_tutorials():
    assert len(TUTORIALS) >= 1


@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_runs(path, monkeypatch, tmp_path, capsys):
    missing = [m for m in NEEDS.get(path.stem, ()) if importlib.util.find_spec(m) is None]
    if missing and os.environ.get("CI"):
        pytest.fail(f"{path.name} needs {', '.join(missing)} (the extras ./test.sh installs)")
    if missing:
        pytest.skip(f"{path.name} needs {', '.join(missing)}: pip install -e '.[torch,jax]'")
    monkeypatch.setenv("TUTORIAL_SMALL", "1")
    monkeypatch.setenv("TUTORIAL_OUTPUT", str(tmp_path))  # where a tutorial may save a figure
    monkeypatch.chdir(tmp_path)
    if path.stem in NEEDS:
        env = dict(os.environ, MPLBACKEND="Agg",
                   PYTHONPATH=os.pathsep.join([str(path.parents[2])] + sys.path))
        run = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, env=env, timeout=600)
        assert run.returncode == 0, f"{path.name} failed:\n{run.stdout[-2000:]}\n{run.stderr[-4000:]}"
        assert run.stdout.strip(), "a tutorial should print what it shows"
        return
    import matplotlib

    matplotlib.use("Agg", force=True)
    runpy.run_path(str(path), run_name="__main__")
    assert capsys.readouterr().out.strip(), "a tutorial should print what it shows"
