"""The main job's command line (``python -m mechanics`` / ``levy-area-paper``).

Claims: options parse to the documented values; every user error (bad option value, unknown name,
existing non-empty output folder, unwritable folder) is exactly one line on stderr and exit code 2,
never a traceback, and leaves an existing folder untouched; a tiny end-to-end run writes the
figures (PNG + npz), ``report.md``, a self-contained ``report.html``, ``results.json`` and a
``manifest.json`` listing every file. The output folder's safety (atomic writes, lock, resume) is
tested in ``tests/mechanics/paper/test_main_job_output.py``.
"""

from __future__ import annotations

import io
import json
import subprocess
import sys

import pytest

import roughpaths
from mechanics.paper.checks import CHECKS
from mechanics.paper.cli import main
from mechanics.paper.figures import FIGURES
from mechanics.paper.options import SCALE_ENV, UsageError, parse_options
from mechanics.paper.tasks import Context, Progress


# ------------------------------------------------------------------------------------ option parsing
def test_defaults(monkeypatch):
    monkeypatch.delenv(SCALE_ENV, raising=False)
    o = parse_options([])
    assert str(o.output) == "paper-output"
    assert (o.convention, o.seed, o.scale, o.only, o.quiet, o.overwrite, o.resume) == (
        "rp", 0, "default", None, False, False, False)
    assert o.levy_area == "auto" and "--levy-area" not in o.command()


def test_values(monkeypatch):
    monkeypatch.delenv(SCALE_ENV, raising=False)
    o = parse_options(["--output", "x", "--convention", "paper", "--seed", "7", "--full", "--quiet"])
    assert (str(o.output), o.convention, o.seed, o.scale, o.quiet) == ("x", "paper", 7, "full", True)
    assert parse_options(["--tiny"]).scale == "tiny"
    monkeypatch.setenv(SCALE_ENV, "tiny")
    assert parse_options([]).scale == "tiny"
    assert parse_options(["--full"]).scale == "full"  # the option beats the environment


@pytest.mark.parametrize("method", roughpaths.LEVY_AREA_METHODS)
def test_levy_area_values(method):
    """Every method of the library is accepted (case-insensitively); command() names it unless default."""
    o = parse_options(["--levy-area", method.upper()])
    assert o.levy_area == method
    assert ("--levy-area" in o.command()) == (method != "auto")
    if method != "auto":
        assert f"--levy-area {method}" in o.command()
        assert parse_options(o.command().split()[1:]).levy_area == method   # the command reproduces it


def test_bad_levy_area_names_the_accepted_values(capsys, tmp_path):
    assert main(["--levy-area", "levy", "--output", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--levy-area" in err and "'levy'" in err
    assert all(m in err for m in roughpaths.LEVY_AREA_METHODS), err
    assert not (tmp_path / "o").exists()


def test_levy_area_reaches_the_drivers(monkeypatch):
    """The run's method is what the checks' Brownian drivers receive ('exact' at d = 3: 'auto')."""
    import mechanics.paper.checks as checks
    seen = []
    real = roughpaths.brownian_rough_path

    def spy(*args, **kwargs):
        seen.append((args[1], kwargs.get("levy_area", "<default>")))
        return real(*args, **kwargs)

    monkeypatch.setattr(checks.roughpaths, "brownian_rough_path", spy)
    for method in ("davie", "exact"):
        seen.clear()
        for name in ("levy_log", "brownian_levy_area"):
            assert CHECKS[name].run(Context(levy_area=method, scale="tiny")).passed
        assert seen == [(3, "auto" if method == "exact" else method)] + [(2, method)] * 2, seen


def test_help_names_levy_area(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "--levy-area" in out and all(m in out for m in roughpaths.LEVY_AREA_METHODS)


def test_only_names_and_groups():
    names = list(CHECKS)
    o = parse_options(["--only", f"{names[0]}, {names[-1]}", "--only", names[0]])
    assert o.only == list(dict.fromkeys([names[0], names[-1]]))
    assert parse_options(["--only", "checks"]).only == names
    assert parse_options(["--only", "figures,checks"]).only == list(FIGURES) + names
    # report order whatever the order given, so a resumed run compares equal
    assert parse_options(["--only", f"{names[-1]},{names[0]}"]).only == [names[0], names[-1]]


@pytest.mark.parametrize("argv, fragment", [
    (["--seed", "x"], "--seed"),
    (["--seed", "-3"], "--seed"),
    (["--convention", "ito"], "--convention"),
    (["--levy-area", "exakt"], "--levy-area must be one of davie, foster, exact"),
    (["--levy-area", "none"], "--levy-area"),
    (["--only", "no_such_figure"], "unknown name 'no_such_figure'"),
    (["--only", ","], "--only"),
    (["--bogus"], "unrecognized arguments"),
    (["--full", "--tiny"], "not allowed with"),
    (["--output", ""], "--output"),
    (["--resume", "--list"], "--resume"),
])
def test_bad_options_one_line_exit_2(argv, fragment, capsys, tmp_path):
    with pytest.raises(UsageError):
        parse_options(argv)
    assert main(argv + (["--output", str(tmp_path / "o")] if "--output" not in argv else [])) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("levy-area-paper: error:"), err
    assert fragment in err
    assert "Traceback" not in err


def test_bad_scale_env(monkeypatch, capsys, tmp_path):
    monkeypatch.setenv(SCALE_ENV, "huge")
    assert main(["--output", str(tmp_path / "o")]) == 2
    assert SCALE_ENV in capsys.readouterr().err


# ------------------------------------------------------------------------------------ output folder
def test_existing_non_empty_folder_refused_and_untouched(tmp_path, capsys):
    out = tmp_path / "run"
    out.mkdir()
    (out / "report.md").write_text("precious")
    assert main(["--output", str(out), "--tiny", "--quiet", "--only", "chen"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--overwrite" in err and "not empty" in err
    assert (out / "report.md").read_text() == "precious"
    assert sorted(p.name for p in out.iterdir()) == ["report.md"]


def test_overwrite_and_empty_folder(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    assert main(["--output", str(out), "--tiny", "--quiet", "--only", "chen"]) == 0  # empty: fine
    assert main(["--output", str(out), "--tiny", "--quiet", "--only", "chen", "--overwrite"]) == 0
    assert "chen" in (out / "report.md").read_text()


@pytest.mark.parametrize("make", ["under_a_file", "is_a_file"])
def test_unwritable_output_one_line(tmp_path, capsys, make):
    f = tmp_path / "plain-file"
    f.write_text("x")
    target = f / "sub" if make == "under_a_file" else f
    assert main(["--output", str(target), "--tiny", "--quiet", "--only", "chen"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("levy-area-paper: error:") and "Traceback" not in err
    assert str(target) in err


def test_read_only_folder(tmp_path, capsys):
    import os

    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        if os.access(ro, os.W_OK):  # root ignores permissions
            pytest.skip("running with privileges that ignore folder permissions")
        assert main(["--output", str(ro / "out"), "--tiny", "--quiet", "--only", "chen"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err
    finally:
        ro.chmod(0o700)


# ------------------------------------------------------------------------------------ progress, help
def test_progress_printer_non_tty_and_quiet():
    buf = io.StringIO()
    p = Progress(enabled=True, stream=buf)
    with p.bar("work", 10) as b:
        for _ in range(10):
            b.update()
    lines = buf.getvalue().splitlines()
    assert lines[0].strip() == "work ..." and "done in" in lines[-1]
    quiet = io.StringIO()
    with Progress(enabled=False, stream=quiet).bar("work", 3) as b:
        b.update(3)
    assert quiet.getvalue() == ""


def test_help_and_list(capsys):
    assert main(["--help"]) == 0
    assert "--convention" in capsys.readouterr().out
    assert main(["--list"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in list(FIGURES) + list(CHECKS))


# ------------------------------------------------------------------------------------ end to end
def test_tiny_end_to_end_run(tiny_paper_run):
    """The whole job at tiny sizes, in a subprocess, as a user runs it (``--tiny --seed 3``; the run is
    shared with the browser test, see ``conftest.tiny_paper_run``)."""
    proc, out = tiny_paper_run, tiny_paper_run.out
    assert proc.returncode in (0, 1), proc.stderr  # 1: a check failed at tiny sizes (numbers not meaningful)
    assert "Traceback" not in proc.stderr
    md = (out / "report.md").read_text()
    page = (out / "report.html").read_text()
    for name in list(CHECKS):
        assert f"`{name}`" in md
    assert "seed **3**" in md
    assert "Lévy areas: **auto** (exact conditional law for d = 2; Mrongowius–Rößler, per-step L² error h^1.5 " \
           "for d = 3)" in md
    assert "Lévy areas: <b>auto</b>" in page
    assert "http://" not in page and "https://" not in page  # self-contained
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["complete"] and manifest["seed"] == 3 and manifest["scale"] == "tiny"
    assert manifest["levy_area"] == "auto"
    assert sorted(f["name"] for f in manifest["files"]) == sorted(p.name for p in out.iterdir()
                                                                   if p.name != "manifest.json")
    results = json.loads((out / "results.json").read_text())
    assert results["metadata"]["levy_area"] == "auto"
    assert [c["name"] for c in results["checks"]] == list(CHECKS)
    for name in FIGURES:
        assert (out / f"{name}.png").stat().st_size > 10_000, name
        assert (out / f"{name}.npz").exists(), name
        assert f"id='{name}'" in page and "data:image/png;base64," in page
    # no figure or check raised
    assert "**error**" not in md, md
