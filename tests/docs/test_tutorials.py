"""Every tutorial in ``docs/tutorials/*.py`` runs to completion (at reduced sizes).

Claim: the tutorials the documentation shows are executable as published: each file is run as a
script (``runpy``, ``__name__ == "__main__"``) with ``TUTORIAL_SMALL=1``; their internal ``assert``
statements check the numbers they print (closed forms, Chen, Lévy-area moments, ...).
"""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

TUTORIALS = sorted((Path(__file__).resolve().parents[2] / "docs" / "tutorials").glob("*.py"))


def test_there_are_tutorials():
    assert len(TUTORIALS) >= 1


@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_runs(path, monkeypatch, tmp_path, capsys):
    import matplotlib

    matplotlib.use("Agg", force=True)
    monkeypatch.setenv("TUTORIAL_SMALL", "1")
    monkeypatch.setenv("TUTORIAL_OUTPUT", str(tmp_path))  # where a tutorial may save a figure
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(path), run_name="__main__")
    assert capsys.readouterr().out.strip(), "a tutorial should print what it shows"
