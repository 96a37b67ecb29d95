"""Sizes a user sets on the main job's command line, its estimate, and options that contradict each other.

Claims:

* ``--set TASK.SIZE=VALUE`` sets one size of one figure or check, ``--paths-factor`` and
  ``--steps-factor`` scale the presets exactly as documented (numbers of paths and of steps rounded,
  powers of 2 to the nearest power of 2, ``dt`` to ``T/round(F T/dt)``), and ``--set`` wins;
* the sizes reach the figures and checks (a check reports the number of paths it was given), and are
  recorded in ``manifest.json`` and ``results.json``; ``--resume`` refuses other sizes, naming them;
* unknown names and keys, values that are not positive finite numbers of the right kind, sizes that do
  not fit together, and an estimate beyond the memory or work budget are refused in one line, exit 2,
  naming the option and the valid values or the fix, before any folder is made;
* every pair of options that contradict each other is refused in one line, exit 2;
* the estimate is printed before the run starts; its coefficients are not tested against the clock
  (machine speed): what is tested is what it grows with.
"""

from __future__ import annotations

import errno
import json
import math
import os
from pathlib import Path

import pytest

from mechanics.paper import cli, cost, options, output
from mechanics.paper.checks import CHECKS
from mechanics.paper.cli import main
from mechanics.paper.cost import estimate_cost
from mechanics.paper.figures import FIGURES
from mechanics.paper.options import parse_options
from mechanics.paper.sizes import SIZES, check_size, check_task_sizes, plan_sizes
from mechanics.paper.tasks import Context, Task

ALL = list(FIGURES) + list(CHECKS)


def _one_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("levy-area-paper: error:") and "Traceback" not in err, err
    return err


# ------------------------------------------------------------------------------------------- the table
def test_every_task_is_in_the_size_table_and_presets_are_valid():
    """Every figure and check has an entry (maybe empty), in report order; each preset is a valid value."""
    assert list(SIZES) == [n for n in ALL if n in SIZES]
    assert set(ALL) - set(SIZES) == {"girsanov", "equilibria", "planar_constant"}
    for task, sizes in SIZES.items():
        for word, spec in sizes.items():
            for scale in ("tiny", "default", "full"):
                assert check_size(f"{task}.{word}", spec.preset(scale)) == spec.preset(scale)
            assert spec.kind in ("count", "power of 2", "positive") and spec.role in ("paths", "steps", "step", "other")
        check_task_sizes(task, {w: s.default for w, s in sizes.items()})


# ------------------------------------------------------------------------------------------- parsing
def test_set_and_factors_give_the_documented_sizes(monkeypatch):
    monkeypatch.delenv(options.SCALE_ENV, raising=False)
    o = parse_options(["--only", "chen,fig1,friz_oberhauser,fig4", "--paths-factor", "2.5", "--steps-factor", "3",
                       "--set", "chen.n_steps=777", "--set", "fig4.T=50,fig4.eps=0.02"])
    d = {k: SIZES[k.partition(".")[0]][k.partition(".")[2]].default for k in o.sizes}
    assert o.sizes["chen.n_steps"] == 777                                      # --set wins over the factor
    assert o.sizes["chen.n_paths"] == round(2.5 * d["chen.n_paths"]) == 160
    assert o.sizes["friz_oberhauser.n_paths"] == 160
    # 3 x 2048 = 6144 = 2^12.58: the nearest power of 2 (in log scale) is 2^13
    assert o.sizes["friz_oberhauser.n_steps"] == 8192
    T = d["fig1.T"]
    assert o.sizes["fig1.T"] == T and o.sizes["fig1.dt"] == T / round(3 * T / d["fig1.dt"])
    assert math.isclose(o.sizes["fig1.dt"], d["fig1.dt"] / 3, rel_tol=1e-12)
    assert (o.sizes["fig4.T"], o.sizes["fig4.eps"]) == (50.0, 0.02)          # ε and T: no factor
    assert list(o.sizes) == [f"{t}.{w}" for t in ("fig1", "fig4", "chen", "friz_oberhauser") for w in SIZES[t]]
    # the command reproduces the sizes
    again = parse_options(o.command().split()[1:])
    assert again.sizes == o.sizes and again.settings == o.settings


def test_factor_one_and_no_options_keep_the_presets_bitwise(monkeypatch):
    monkeypatch.delenv(options.SCALE_ENV, raising=False)
    for argv, scale in (([], "default"), (["--full"], "full"), (["--tiny", "--paths-factor", "1"], "tiny")):
        o = parse_options(argv)
        assert o.sizes == {f"{t}.{w}": s.preset(scale) for t in ALL for w, s in SIZES.get(t, {}).items()}
        assert "--paths-factor" not in o.command() and "--set" not in o.command()


@pytest.mark.parametrize("argv, fragments", [
    (["--set", "fig2.n_paths=2000"], ["--set fig2.n_paths=2000", "fig2 has no size 'n_paths'", "fig2.T, fig2.dt"]),
    (["--set", "fig9.T=5"], ["unknown figure or check 'fig9'", "fig1, fig2, surf", "planar_constant"]),
    (["--set", "girsanov.T=5"], ["girsanov has no size 'T'", "fixed by its claim"]),
    (["--set", "chen.n_paths=0"], ["chen.n_paths", "whole number >= 1", "'0'"]),
    (["--set", "chen.n_paths=-4"], ["chen.n_paths", "'-4'"]),
    (["--set", "chen.n_paths=2.5"], ["chen.n_paths", "whole number"]),
    (["--set", "chen.n_paths=nan"], ["chen.n_paths", "'nan'"]),
    (["--set", "chen.n_paths=inf"], ["chen.n_paths", "'inf'"]),
    (["--set", "chen.n_paths=many"], ["chen.n_paths", "must be a number", "'many'"]),
    (["--set", "fig1.dt=0"], ["fig1.dt", "positive real number"]),
    (["--set", "fig1.dt=-0.01"], ["fig1.dt", "positive"]),
    (["--set", "fig1.T=NaN"], ["fig1.T", "positive"]),
    (["--set", "fig4.eps=-inf"], ["fig4.eps", "positive"]),
    (["--set", "friz_oberhauser.n_steps=1000"], ["friz_oberhauser.n_steps", "power of 2"]),
    (["--set", "fig1.dt=0.003"], ["--set fig1.dt=0.003", "not a whole number of steps", "divides T = 2000"]),
    (["--set", "gibbs_mean.T=20"], ["gibbs_mean.T", ">= 31"]),
    (["--set", "chen.n_paths"], ["--set takes NAME.SIZE=VALUE", "'chen.n_paths'"]),
    (["--set", "=3"], ["--set takes NAME.SIZE=VALUE"]),
    (["--paths-factor", "0"], ["--paths-factor must be a positive number", "'0'"]),
    (["--paths-factor", "-2"], ["--paths-factor", "'-2'"]),
    (["--steps-factor", "nan"], ["--steps-factor", "'nan'"]),
    (["--steps-factor", "inf"], ["--steps-factor", "'inf'"]),
    (["--steps-factor", "x2"], ["--steps-factor", "'x2'"]),
    (["--steps-factor", "0.0001"], ["--steps-factor 0.0001", "below its minimum", "--set"]),
    (["--paths-factor", "1e-9"], ["--paths-factor 1e-09", "below its minimum"]),
])
def test_bad_sizes_one_line_exit_2_naming_option_and_fix(argv, fragments, capsys, tmp_path, monkeypatch):
    monkeypatch.delenv(options.SCALE_ENV, raising=False)
    out = tmp_path / "o"
    assert main(argv + ["--output", str(out)]) == 2
    err = _one_line(capsys)
    for f in fragments:
        assert f in err, (f, err)
    assert not out.exists() and not Path(str(out) + ".incomplete").exists()


# ------------------------------------------------------------------------------------------- contradictions
@pytest.mark.parametrize("argv, fragments", [
    (["--resume", "--overwrite"], ["--resume", "--overwrite", "contradict"]),
    (["--full", "--tiny"], ["--tiny", "not allowed with", "--full"]),
    (["--list", "--resume"], ["--list", "--resume"]),
    (["--list", "--overwrite"], ["--list", "--overwrite"]),
    (["--list", "--output", "somewhere"], ["--list", "--output"]),
    (["--list", "--seed", "3"], ["--list", "--seed"]),
    (["--list", "--convention", "paper"], ["--list", "--convention"]),
    (["--list", "--levy-area", "davie"], ["--list", "--levy-area"]),
    (["--list", "--quiet"], ["--list", "--quiet"]),
    (["--set", "chen.n_paths=3", "--set", "chen.n_paths=4"], ["chen.n_paths is given twice", "3 and 4"]),
    (["--only", "chen", "--set", "fig1.T=40"], ["--set fig1.T=40", "fig1 is not run", "--only"]),
])
def test_contradicting_options_one_line_exit_2(argv, fragments, capsys, tmp_path):
    with pytest.raises(options.UsageError):
        parse_options(argv)
    assert main(argv) == 2
    err = _one_line(capsys)
    for f in fragments:
        assert f in err, (f, err)


def test_same_value_twice_and_list_with_sizes_are_accepted(capsys, monkeypatch):
    monkeypatch.delenv(options.SCALE_ENV, raising=False)
    assert parse_options(["--set", "chen.n_paths=3", "--set", "chen.n_paths=3.0"]).sizes["chen.n_paths"] == 3
    assert main(["--list", "--full", "--only", "chen,fig1", "--set", "chen.n_paths=300", "--steps-factor", "2"]) == 0
    out = capsys.readouterr().out
    assert "chen.n_steps=200000, chen.n_paths=300" in out and "fig1.T=20000, fig1.dt=0.0005" in out
    assert "fig2" not in out and "levy_log" not in out
    assert out.splitlines()[-1].startswith("estimate: about ") and "memory at the peak" in out


# ------------------------------------------------------------------------------------------- Context.size
def test_context_size_reads_the_plan_and_refuses_drift():
    ctx = Context(task="chen", scale="tiny", plan={"chen.n_paths": 7})
    assert ctx.size("chen.n_paths") == 7 and ctx.size("chen.n_steps") == SIZES["chen"]["n_steps"].tiny
    assert ctx.sizes == {"chen.n_paths": 7, "chen.n_steps": SIZES["chen"]["n_steps"].tiny}
    # a helper shared by several tasks names its size by word: the current task's
    surf3 = Context(task="surf3", scale="full", plan={"surf3.levels": 5})
    assert surf3.size("portrait.levels", tiny=8, default=18, full=24) == 5
    with pytest.raises(ValueError, match="differ from those in mechanics.paper.sizes.SIZES"):
        Context(task="surf", scale="tiny").size("portrait.levels", tiny=9, default=18, full=24)
    with pytest.raises(ValueError, match="not declared"):
        Context(task="chen").size("chen.n_lanes")
    with pytest.raises(ValueError, match="was given to task"):
        CHECKS["chen"].run(Context(task="levy_log"))


def test_a_task_records_all_its_sizes_even_if_it_reads_none():
    """fig5 reading fig4's cached run reads no size; its record must still hold its sizes (resume = same bytes)."""
    task = Task("fig5", "t", lambda ctx: ctx.sizes.copy())
    got = task.run(Context(scale="tiny", plan={"fig5.T": 3.0}))
    assert got == {"fig5.eps": SIZES["fig5"]["eps"].tiny, "fig5.T": 3.0}


def test_tasks_with_different_sizes_get_different_caches(monkeypatch, tmp_path):
    """fig4 and fig5 share the coloured-noise run only when their sizes are equal."""
    seen = {}

    def fake(name):
        def run(ctx):
            seen[name] = ctx.cache
            return cli.FigureResult(name, name, "")
        return Task(name, name, run)

    fake_registries = {"fig4": fake("fig4"), "fig5": fake("fig5")}, {}
    for module in (options, cli):             # the options read the registries, the run loop runs them
        monkeypatch.setattr(module, "registries", lambda: fake_registries)
    for extra, shared in (([], True), (["--set", "fig5.T=20"], False)):
        seen.clear()
        out = tmp_path / f"o{len(extra)}"
        assert main(["--tiny", "--quiet", "--output", str(out)] + extra) == 0
        assert (seen["fig4"] is seen["fig5"]) == shared


# ------------------------------------------------------------------------------------------- the run
def test_sizes_reach_the_check_and_are_recorded(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["--tiny", "--only", "chen,levy_log", "--set", "chen.n_paths=3", "--set", "chen.n_steps=90",
                 "--output", str(out)]) == 0
    err = capsys.readouterr().err
    first = err.splitlines()[0]
    assert first.startswith("levy-area-paper: estimate: about ") and "memory at the peak" in first
    results = json.loads((out / "results.json").read_text())
    chen = next(c for c in results["checks"] if c["name"] == "chen")
    assert chen["details"].startswith("3 paths x 90 steps")           # what the check itself reports
    expect = {"chen.n_steps": 90, "chen.n_paths": 3, "levy_log.n_steps": SIZES["levy_log"]["n_steps"].tiny}
    assert results["metadata"]["sizes"] == expect
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["sizes"] == expect and manifest["settings"] == {"chen.n_paths": 3, "chen.n_steps": 90}
    assert "--set chen.n_paths=3 --set chen.n_steps=90" in manifest["command"]
    assert manifest["estimate"]["cpu_seconds"] > 0 and manifest["estimate"]["peak_bytes"] > 0
    md = (out / "report.md").read_text()
    assert "| chen.n_paths | 3 |" in md


def test_resume_refuses_other_sizes_and_accepts_the_same(tmp_path, capsys, monkeypatch):
    out = tmp_path / "run"
    real = output._write_file

    def fail_report(path, data):          # every piece finishes, the report cannot be written
        if Path(path).name.endswith("results.json"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        real(path, data)

    base = ["--tiny", "--quiet", "--only", "chen,girsanov", "--output", str(out)]
    monkeypatch.setattr(output, "_write_file", fail_report)
    assert main(base + ["--set", "chen.n_paths=6"]) == 2
    monkeypatch.undo()
    capsys.readouterr()
    assert main(base + ["--resume", "--set", "chen.n_paths=5"]) == 2
    err = _one_line(capsys)
    assert "used other sizes (chen.n_paths: 6 then, 5 now)" in err and "--overwrite" in err
    assert main(base + ["--resume"]) == 2                                   # the preset differs too
    assert f"chen.n_paths: 6 then, {SIZES['chen']['n_paths'].tiny} now" in _one_line(capsys)
    # the same sizes reached another way (a factor) are the same run: it resumes
    factor = 6 / SIZES["chen"]["n_paths"].tiny
    loud = [a for a in base if a != "--quiet"]
    assert main(loud + ["--resume", "--paths-factor", repr(factor)]) == 0
    assert "2 finished pieces verified and reused" in capsys.readouterr().err
    assert json.loads((out / "manifest.json").read_text())["sizes"]["chen.n_paths"] == 6
    # resuming the complete run with other sizes runs nothing and says so (not "complete, nothing to resume")
    before = (out / "manifest.json").read_bytes()
    assert main(base + ["--resume", "--set", "chen.n_paths=7"]) == 2
    err = _one_line(capsys)
    assert "is complete and used other sizes (chen.n_paths: 6 then, 7 now)" in err and "--overwrite" in err
    assert (out / "manifest.json").read_bytes() == before
    assert main(base + ["--resume", "--set", "chen.n_paths=6"]) == 0       # the same sizes: nothing to do


# ------------------------------------------------------------------------------------------- the estimate
def test_estimate_beyond_the_memory_budget_is_refused_before_any_folder(tmp_path, capsys, monkeypatch):
    plan = plan_sizes("tiny", ["chen"])
    need = estimate_cost(plan, ["chen"]).peak_bytes
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(int(2 * need)))
    out = tmp_path / "o"
    argv = ["--tiny", "--quiet", "--only", "chen", "--output", str(out)]
    big = estimate_cost(plan_sizes("tiny", ["chen"], settings={"chen.n_steps": 10**8}), ["chen"]).peak_bytes
    assert big > 2 * need                         # the size the test sets is beyond the budget it sets
    assert main(argv + ["--set", "chen.n_steps=1e8"]) == 2
    err = _one_line(capsys)
    assert err.startswith("levy-area-paper: error: --set chen.n_steps=100000000: ") and "memory budget" in err
    assert "ROUGHPATHS_MAX_BYTES" in err and "chen.n_steps, chen.n_paths" in err
    assert not out.exists() and not Path(str(out) + ".incomplete").exists()
    over = need - estimate_cost(plan, ["chen"]).tasks["chen"][1] / 2        # the preset of chen beyond the budget
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(int(over)))
    assert main(argv) == 2
    assert "error: --tiny: the run would need" in _one_line(capsys)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(int(0.5 * need)))           # not even the process fits
    assert main(argv) == 2
    err = _one_line(capsys)
    assert "before any figure or check, more than the memory budget" in err and "ROUGHPATHS_MAX_BYTES" in err


def test_estimate_beyond_the_work_budget_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", "1e6")
    out = tmp_path / "o"
    assert main(["--tiny", "--quiet", "--only", "wong_zakai", "--set", "wong_zakai.eps=0.001",
                 "--output", str(out)]) == 2
    err = _one_line(capsys)
    assert "--set wong_zakai.eps=0.001: wong_zakai would do about" in err and "work budget" in err
    assert not out.exists()


def test_estimate_grows_with_what_the_task_does():
    """Not the coefficients (machine speed) but the structure: linear in the work, fig5 reuses fig4's run."""
    def estimate(task, **sets):
        plan = plan_sizes("default", [task], settings={f"{task}.{k}": v for k, v in sets.items()})
        return estimate_cost(plan, [task])

    a, b = estimate("chen", n_paths=64), estimate("chen", n_paths=128)
    c = estimate("chen", n_paths=192)
    assert b.work["chen"] == 2 * a.work["chen"] > 0
    assert math.isclose(c.tasks["chen"][0] - b.tasks["chen"][0], b.tasks["chen"][0] - a.tasks["chen"][0],
                        rel_tol=1e-9)
    assert b.tasks["chen"][0] > a.tasks["chen"][0]
    both = plan_sizes("default", ["fig4", "fig5"])
    shared = estimate_cost(both, ["fig4", "fig5"])
    alone = estimate_cost(both, ["fig5"])
    other = estimate_cost({**both, "fig5.T": 400.0}, ["fig4", "fig5"])
    assert shared.work["fig5"] == 0 < alone.work["fig5"] == other.work["fig5"] / 2
    assert shared.tasks["fig5"][0] < alone.tasks["fig5"][0] < other.tasks["fig5"][0]
    assert shared.seconds == pytest.approx(sum(t for t, _ in shared.tasks.values()) + cost._BASE_SECONDS)


# ------------------------------------------------------------------------------------------- every size is read
def _read_sizes(names, monkeypatch):
    read = {}
    real = Context.size

    def spy(self, key, **presets):
        value = real(self, key, **presets)
        read.setdefault(self.task, set()).add(key.rpartition(".")[2])
        return value

    monkeypatch.setattr(Context, "size", spy)
    registry = {**FIGURES, **CHECKS}
    for name in names:
        registry[name].run(Context(scale="tiny"))
        assert read.get(name, set()) == set(SIZES.get(name, {})), name
    return read


CHEAP = ["surf", "chen", "levy_log", "brownian_levy_area", "prop21", "casimir", "coloured_area_rate", "girsanov"]


def test_cheap_tasks_read_exactly_their_declared_sizes(monkeypatch):
    _read_sizes(CHEAP, monkeypatch)


@pytest.mark.slow
def test_every_task_reads_exactly_its_declared_sizes(monkeypatch):
    _read_sizes([n for n in ALL if n not in CHEAP], monkeypatch)


def test_the_documented_sizes_are_the_table():
    """docs/main-job.md, section Sizes, lists every size with its three presets (it cannot drift)."""
    doc = (Path(__file__).resolve().parents[3] / "docs" / "main-job.md").read_text(encoding="utf-8")
    rows = {}
    for line in doc.split("## Sizes", 1)[1].split("\n## ", 1)[0].splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 6 and cells[0].startswith("`"):
            rows[cells[0].strip("`")] = tuple(float(c) for c in cells[2:5])
    assert rows == {f"{t}.{w}": (s.tiny, s.default, s.full) for t, d in SIZES.items() for w, s in d.items()}
