"""Command line of the main job: reproduce the paper's figures and theorem checks.

``python -m mechanics`` (or the console script ``levy-area-paper``) runs every figure of the paper
and every theorem / proposition check, and writes PNGs, the ``.npz`` data behind them,
``report.md``, a self-contained ``report.html``, ``results.json`` and, last, ``manifest.json``
(every file with its size and SHA-256, the options, versions and timings) into an output folder.

The folder appears under its name only when complete (see :mod:`mechanics.paper.output`): the run
works in ``OUT.incomplete`` and renames it at the end, a lock keeps two runs out of one folder,
an interrupted run (SIGTERM, SIGINT, a kill, a full disk) can be continued with ``--resume`` and
gives the same bytes as an uninterrupted run.

The sizes of each figure and check (numbers of paths and steps, horizons, steps) are its presets
(``--tiny``, default, ``--full``: :data:`mechanics.paper.sizes.SIZES`), scaled by ``--paths-factor``
and ``--steps-factor`` and set one by one with ``--set NAME.SIZE=VALUE``. Before it starts, the run
prints its estimated CPU time and peak memory (:func:`mechanics.paper.cost.estimate_cost`) and
refuses a run beyond the library's memory or work budget.

Every user error (bad option value or size, options that contradict each other, an estimate beyond
the budget, an existing non-empty output folder, an unwritable folder, a full disk) is one line on
stderr and exit code 2, never a traceback. An exception inside one
figure or check is recorded in the report (with its traceback) and the run goes on; the exit code
is then 1.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import threading
import time
import traceback
from dataclasses import dataclass, field
from datetime import datetime, timezone

import importlib

import mechanics
import roughpaths

from roughpaths.validation import memory_budget, work_budget

from .cost import ESTIMATE_ACCURACY, CostEstimate, estimate_cost
from .output import PROGRESS, OutputError, RunFolder
from .report import (
    ERROR,
    FAIL,
    PASS,
    CheckResult,
    FigureResult,
    RunMetadata,
    format_value,
    result_from_json,
    result_to_json,
    versions,
    write_report,
)
from .sizes import SIZES, SizeError, check_size, plan_sizes
from .tasks import Context, Progress

__all__ = ["main", "build_parser", "parse_options", "Options", "UsageError", "run", "registries"]

PROG = "levy-area-paper"
SCALES = ("tiny", "default", "full")
CONVENTIONS = ("rp", "paper")
#: accepted values of --levy-area: the library's vocabulary (roughpaths.drivers.areas)
LEVY_AREA_METHODS = tuple(roughpaths.LEVY_AREA_METHODS)
DEFAULT_LEVY_AREA = "auto"
DEFAULT_OUTPUT = "paper-output"
#: environment variable overriding the default size scale (used by the tests: ``tiny``)
SCALE_ENV = "LEVY_AREA_PAPER_SCALE"


def registries() -> tuple[dict, dict]:
    """The registries ``(FIGURES, CHECKS)`` of :mod:`mechanics.paper.figures` and :mod:`~.checks`.

    Loaded on first use rather than when this module is imported: they bring in matplotlib and
    scipy's integrators (about a second), which ``--help`` and a mistyped option do not need.
    """
    return (importlib.import_module("mechanics.paper.figures").FIGURES,
            importlib.import_module("mechanics.paper.checks").CHECKS)


class UsageError(Exception):
    """A user error: reported as one line on stderr, exit code 2."""


class Terminated(KeyboardInterrupt):
    """Raised by the SIGTERM handler: the run stops like on Ctrl-C (exit code 143)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse would print usage + message and exit: we want one line
        raise UsageError(f"{message} (see --help)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``python -m mechanics`` / ``levy-area-paper``."""
    p = _Parser(
        prog=PROG,
        description="Reproduce the figures and theorem checks of 'Variational Principles on Geometric Rough "
        "Paths and the Lévy Area Correction': PNG figures with their .npz data, report.md, a self-contained "
        "report.html, results.json and manifest.json (checksums). The folder appears under its name only when "
        "complete; an interrupted run stays in DIR.incomplete and continues with --resume.",
        epilog="Example: levy-area-paper --output my-run --seed 1 --only fig1,gibbs_mean. Conventions: "
        "docs/conventions.md of the project.",
    )
    p.add_argument("--output", "-o", default=None, metavar="DIR",
                   help=f"output folder (default: {DEFAULT_OUTPUT}/); an existing non-empty folder is "
                   "refused unless --overwrite is given")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an existing output folder of an earlier run as a whole, when this run completes "
                   "(or discard an unfinished DIR.incomplete and start over)")
    p.add_argument("--resume", action="store_true",
                   help="continue the interrupted run in DIR.incomplete (same options): finished figures and "
                   "checks are verified against their checksums and reused")
    p.add_argument("--convention", default=None, metavar="{rp,paper}",
                   help="'rp' (default): rough-path-correct signs and factors (docs/conventions.md); 'paper': "
                   "the paper's printed equations, slips included, to reproduce its figures literally")
    p.add_argument("--seed", default=None, metavar="INT", help="seed of every random stream (default 0)")
    p.add_argument("--levy-area", default=None, metavar="METHOD",
                   help=f"sampler of the Brownian Lévy areas in the figures and checks, one of "
                   f"{', '.join(LEVY_AREA_METHODS)} (default {DEFAULT_LEVY_AREA}: the exact conditional law for "
                   "d = 2, Mrongowius-Rössler with per-step L² error h^1.5 for d = 3, strong order 1; davie and "
                   "foster are faster, strong order ½). 'exact' exists for d = 2 only: d = 3 drivers then use "
                   "auto's sampler. The Gibbs check's ensembles use increments only, whatever this option.")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--full", action="store_true",
                      help="paper-scale sizes, e.g. epsilon = 0.005 over T = 500 for Figures 4-5 (their cost: "
                      "--list --full, or docs/main-job.md)")
    size.add_argument("--tiny", action="store_true",
                      help="smoke-test sizes (seconds; numbers not meaningful, checks may fail)")
    p.add_argument("--only", action="append", default=None, metavar="NAMES",
                   help="comma-separated subset of figures/checks to run (names from --list; 'figures' "
                   "and 'checks' select a whole group); may be repeated")
    p.add_argument("--set", action="append", default=None, metavar="NAME.SIZE=VALUE", dest="settings",
                   help="set one size of one figure or check, e.g. --set fig2.T=5000 --set chen.n_paths=512 "
                   "(comma-separated or repeated; --list shows every figure's and check's sizes); wins over the "
                   "presets and the factors")
    p.add_argument("--paths-factor", default=None, metavar="F",
                   help="multiply every number of paths (n_paths, n_paths_wrong_models) of the presets by F "
                   "(rounded to a whole number)")
    p.add_argument("--steps-factor", default=None, metavar="F",
                   help="multiply every number of time steps of the presets by F: n_steps becomes round(F n_steps) "
                   "(a power of 2 for the convergence checks: the nearest one), dt becomes T/round(F T/dt); "
                   "horizons T and ε are left alone")
    p.add_argument("--list", action="store_true",
                   help="list the figures and checks with their sizes and estimated cost (for the chosen "
                   "--tiny/--full, --set, factors and --only) and exit")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output (errors still shown)")
    return p


@dataclass
class Options:
    """Validated command-line options.

    ``settings`` holds the ``--set`` values (``{"TASK.WORD": value}``); ``sizes`` every size of every
    selected figure and check (:func:`~.sizes.plan_sizes`: presets of ``scale``, the two factors, then
    ``settings``), which the run records and ``--resume`` compares.
    """

    output: str
    overwrite: bool = False
    resume: bool = False
    convention: str = "rp"
    seed: int = 0
    levy_area: str = DEFAULT_LEVY_AREA
    scale: str = "default"
    only: list[str] | None = None
    list_only: bool = False
    quiet: bool = False
    settings: dict = field(default_factory=dict)
    paths_factor: float = 1.0
    steps_factor: float = 1.0
    sizes: dict = field(default_factory=dict)
    argv: list[str] = field(default_factory=list)

    def command(self) -> str:
        """The command that reproduces the results (without the output folder)."""
        parts = [PROG, "--convention", self.convention, "--seed", str(self.seed)]
        if self.levy_area != DEFAULT_LEVY_AREA:
            parts += ["--levy-area", self.levy_area]
        if self.scale != "default":
            parts.append(f"--{self.scale}")
        if self.paths_factor != 1.0:
            parts += ["--paths-factor", repr(self.paths_factor)]
        if self.steps_factor != 1.0:
            parts += ["--steps-factor", repr(self.steps_factor)]
        for key, value in self.settings.items():
            parts += ["--set", f"{key}={value!r}"]
        if self.only:
            parts += ["--only", ",".join(self.only)]
        return " ".join(parts)


#: options that --list ignores (it runs nothing): given with --list they are refused
_NOT_WITH_LIST = (("resume", "--resume"), ("overwrite", "--overwrite"), ("output", "--output"), ("seed", "--seed"),
                  ("convention", "--convention"), ("levy_area", "--levy-area"), ("quiet", "--quiet"))


def _refuse_contradictions(ns) -> None:
    """Refuse options that contradict each other (--tiny with --full is refused by the parser)."""
    if ns.resume and ns.overwrite:
        raise UsageError("--resume (continue the unfinished run) and --overwrite (discard it and start over) "
                         "contradict each other; pass one of them")
    if ns.list:
        for attr, flag in _NOT_WITH_LIST:
            if getattr(ns, attr) not in (None, False):
                raise UsageError(f"--list only lists the figures and checks (it runs nothing), so {flag} has no "
                                 f"effect with it; drop {flag} or --list")


def _factor(text, flag: str) -> float:
    if text is None:
        return 1.0
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (math.isfinite(value) and value > 0):
        raise UsageError(f"{flag} must be a positive number (e.g. {flag} 2), got {text!r}")
    return value


def _settings(chunks, selected: list[str]) -> dict:
    """The ``--set`` values, ``{"TASK.WORD": number}``, checked against :data:`~.sizes.SIZES`."""
    figs, chks = (list(r) for r in registries())
    settings: dict = {}
    for chunk in chunks or ():
        for item in (c.strip() for c in chunk.split(",")):
            if not item:
                continue
            key, eq, text = (part.strip() for part in item.partition("="))
            if not eq or not key or not text:
                raise UsageError(f"--set takes NAME.SIZE=VALUE (e.g. --set fig2.T=5000), got {item!r}")
            task, dot, word = key.partition(".")
            if task not in figs + chks:
                raise UsageError(f"--set {item}: unknown figure or check {task!r}; valid names: "
                                 f"{', '.join(figs + chks)}")
            valid = ", ".join(f"{task}.{w}" for w in SIZES.get(task, {})) or "none: its numbers are fixed by its claim"
            if not dot or word not in SIZES.get(task, {}):
                raise UsageError(f"--set {item}: {task} has no size {word!r}; its sizes: {valid}")
            try:
                value = check_size(key, text)
            except ValueError as exc:
                raise UsageError(f"--set {item}: {exc}") from None
            if key in settings and settings[key] != value:
                raise UsageError(f"--set {key} is given twice with different values ({settings[key]!r} and "
                                 f"{value!r}); give it once")
            if task not in selected:
                raise UsageError(f"--set {item}: {task} is not run (--only selects {', '.join(selected)}); "
                                 f"add it to --only or drop this --set")
            settings[key] = value
    return settings


def parse_options(argv: list[str] | None) -> Options:
    """Parse and validate ``argv``; raise :class:`UsageError` (one line) on a bad value."""
    argv = list(sys.argv[1:] if argv is None else argv)
    ns = build_parser().parse_args(argv)
    _refuse_contradictions(ns)
    conv = (ns.convention or "rp").strip().lower()
    if conv not in CONVENTIONS:
        raise UsageError(f"--convention must be 'rp' or 'paper', got {ns.convention!r}")
    try:
        seed = int(ns.seed or "0")
    except ValueError:
        raise UsageError(f"--seed must be a non-negative integer, got {ns.seed!r}") from None
    if seed < 0:
        raise UsageError(f"--seed must be a non-negative integer, got {seed}")
    levy_area = (ns.levy_area or DEFAULT_LEVY_AREA).strip().lower()
    if levy_area not in LEVY_AREA_METHODS:
        raise UsageError(f"--levy-area must be one of {', '.join(LEVY_AREA_METHODS)}, got {ns.levy_area!r}")
    scale = "full" if ns.full else "tiny" if ns.tiny else None
    if scale is None:
        env = os.environ.get(SCALE_ENV, "").strip().lower()
        if env and env not in SCALES:
            raise UsageError(f"environment variable {SCALE_ENV} must be one of {', '.join(SCALES)}, "
                             f"got {env!r}")
        scale = env or "default"
    output = DEFAULT_OUTPUT if ns.output is None else ns.output
    if not output or not str(output).strip():
        raise UsageError("--output must be a folder name, got an empty string")
    only = None
    if ns.only is not None:
        figs, chks = (list(r) for r in registries())
        known = figs + chks
        only = []
        for chunk in ns.only:
            for name in (n.strip() for n in chunk.split(",")):
                if not name:
                    continue
                if name == "figures":
                    only += figs
                elif name == "checks":
                    only += chks
                elif name in known:
                    only.append(name)
                else:
                    raise UsageError(f"--only: unknown name {name!r}; valid names: "
                                     f"{', '.join(known)} (or 'figures', 'checks')")
        if not only:
            raise UsageError("--only needs at least one name (see --list)")
        only = [n for n in known if n in set(only)]   # report order, whatever the order given
    paths_factor = _factor(ns.paths_factor, "--paths-factor")
    steps_factor = _factor(ns.steps_factor, "--steps-factor")
    selected = only if only is not None else [n for r in registries() for n in r]
    settings = _settings(ns.settings, selected)
    try:
        sizes = plan_sizes(scale, selected, settings=settings, paths_factor=paths_factor, steps_factor=steps_factor)
    except SizeError as exc:
        given = [f"--set {k}={v!r}" for k, v in settings.items() if k.partition(".")[0] == exc.task]
        raise UsageError((" ".join(given) + ": " if given else "") + str(exc)) from None
    return Options(output=str(output), overwrite=ns.overwrite, resume=ns.resume, convention=conv, seed=seed,
                   levy_area=levy_area, scale=scale, only=only, list_only=ns.list, quiet=ns.quiet,
                   settings=settings, paths_factor=paths_factor, steps_factor=steps_factor, sizes=sizes, argv=argv)


def _run_tasks(opts: Options, folder: RunFolder, prog: Progress):
    """Run (or reuse, when resuming) the selected figures and checks, recording each as it finishes."""
    selected = set(opts.only) if opts.only else None
    figures, checks, sizes, timings, reused = [], [], {}, {}, []
    caches: dict = {}   # tasks share a cache only if their sizes are equal (fig4 and fig5: one coloured run)
    figure_registry, check_registry = registries()
    for kind, registry in (("figure", figure_registry), ("check", check_registry)):
        for name, task in registry.items():
            if selected is not None and name not in selected:
                continue
            _stop_if_signalled()
            key = f"{kind} {name}"
            entry = folder.reused.get(key)
            if entry is not None and entry["result"].get("status") != ERROR:
                res = result_from_json(entry["result"])
                task_sizes, seconds = entry["sizes"], entry["seconds"]
                reused.append(key)
                prog.message(f"[{key}] finished before the interruption: reused ({res.status})")
            else:
                mine = tuple((k.partition(".")[2], v) for k, v in opts.sizes.items() if k.partition(".")[0] == name)
                ctx = Context(folder=folder, task=name, convention=opts.convention, seed=opts.seed,
                              levy_area=opts.levy_area, scale=opts.scale, plan=opts.sizes, progress=prog,
                              cache=caches.setdefault(tuple(sorted(mine)), {}))
                prog.message(f"[{key}] {task.title}")
                t0 = time.perf_counter()
                try:
                    res = task.run(ctx)
                except OutputError:
                    raise
                except Exception:
                    tb = traceback.format_exc()
                    prog.message(f"[{key}] error: {tb.strip().splitlines()[-1]}")
                    res = (FigureResult(name, task.title, task.caption, status=ERROR, details=tb)
                           if kind == "figure" else CheckResult(name, task.title, status=ERROR, details=tb))
                seconds = time.perf_counter() - t0
                task_sizes = ctx.sizes
                # the record makes the result and its files reusable by --resume; it is the task's last step
                res = result_from_json(result_to_json(res))   # the report is rendered from what is recorded
                folder.record(key, {"files": ctx.files, "result": result_to_json(res), "sizes": task_sizes,
                                    "seconds": seconds})
                if kind == "check" and res.status != ERROR:
                    prog.message(f"[{key}] {res.status}: predicted {_short(res.predicted)}, "
                                 f"measured {_short(res.measured)}")
            sizes.update(task_sizes)
            timings[key] = seconds
            (figures if kind == "figure" else checks).append(res)
    _stop_if_signalled()
    return figures, checks, sizes, timings, reused


def _human_bytes(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 2**10:.3g} KiB"


def _human_seconds(t: float) -> str:
    if t < 120:
        return f"{t:.0f} s"
    if t < 2 * 3600:
        return f"{t / 60:.1f} min"
    if t < 2 * 86400:
        return f"{t / 3600:.1f} h"
    return f"{t / 86400:.3g} days"


def _selected(opts: Options) -> list[str]:
    return list(opts.only) if opts.only else [n for r in registries() for n in r]


def _origin(opts: Options, task: str) -> str:
    """The options that chose ``task``'s sizes, for an error message."""
    given = [f"--set {k}={v!r}" for k, v in opts.settings.items() if k.partition(".")[0] == task]
    if not given:
        roles = {spec.role for spec in SIZES.get(task, {}).values()}
        given += [f"--paths-factor {opts.paths_factor:g}"] if opts.paths_factor != 1 and "paths" in roles else []
        given += ([f"--steps-factor {opts.steps_factor:g}"] if opts.steps_factor != 1 and roles & {"steps", "step"}
                  else [])
    if not given and opts.scale != "default":
        given.append(f"--{opts.scale}")
    return " ".join(given) or "the default sizes"


def _check_estimate(opts: Options, est: CostEstimate) -> None:
    """Refuse (:class:`UsageError`) a run whose estimate exceeds the library's memory or work budget."""
    budget = memory_budget()
    if est.peak_bytes > budget:
        task = max(est.tasks, key=lambda t: est.tasks[t][1])
        words = ", ".join(f"{task}.{w}" for w in SIZES.get(task, {}))
        base = est.peak_bytes - est.tasks[task][1]
        if base > budget or not words:       # not a matter of sizes
            raise UsageError(
                f"the main job needs about {_human_bytes(est.peak_bytes)} of memory, {_human_bytes(base)} before any "
                f"figure or check, more than the memory budget of {_human_bytes(budget)} "
                "(roughpaths.validation.memory_budget: three quarters of the available memory, or "
                "ROUGHPATHS_MAX_BYTES); free some memory or raise ROUGHPATHS_MAX_BYTES")
        raise UsageError(
            f"{_origin(opts, task)}: the run would need about {_human_bytes(est.peak_bytes)} of memory at its peak "
            f"({task}: {_human_bytes(est.tasks[task][1])}), more than the memory budget of {_human_bytes(budget)} "
            f"(roughpaths.validation.memory_budget: three quarters of the available memory, or ROUGHPATHS_MAX_BYTES); "
            f"lower {words or task} with --set (see --list for the estimate of each figure and check)")
    limit = work_budget()
    for task, units in est.work.items():
        if not units <= limit:
            raise UsageError(
                f"{_origin(opts, task)}: {task} would do about {units:.3g} path-steps, more than the work budget of "
                f"{limit:.3g} (roughpaths.validation.work_budget, ROUGHPATHS_MAX_WORK; about "
                f"{_human_seconds(est.tasks[task][0])} of CPU time); lower its sizes with --set")


def _estimate_line(est: CostEstimate) -> str:
    big = max(est.tasks, key=lambda t: est.tasks[t][0], default=None)
    return (f"{PROG}: estimate: about {_human_seconds(est.seconds)} of CPU time and {_human_bytes(est.peak_bytes)} of "
            f"memory at the peak" + (f" (longest: {big}, {_human_seconds(est.tasks[big][0])})" if big else "")
            + f"; {ESTIMATE_ACCURACY} (docs/main-job.md, Cost)")


def _refuse_other_sizes(folder: RunFolder, opts: Options, *, complete: bool = False) -> None:
    """``--resume``: refuse, naming the differences, a run whose sizes differ from this run's.

    The unfinished run in ``OUT.incomplete`` (its record), or with ``complete=True`` the completed run in
    ``OUT`` (its manifest), which ``--resume`` would otherwise report as done. (The folder's own check
    compares every option of an unfinished run too; this one names only the sizes that differ.)
    """
    where = folder.final if complete else folder.staging
    try:
        text = (where / ("manifest.json" if complete else PROGRESS)).read_text(encoding="utf-8")
        old = dict(json.loads(text)["sizes"] if complete else json.loads(text)["run"]["sizes"])
    except (OSError, ValueError, KeyError, TypeError):
        return
    diffs = [f"{k}: {old[k]!r} then, {v!r} now" for k, v in opts.sizes.items() if k in old and old[k] != v]
    if diffs and complete:
        raise UsageError(f"--resume: the run in '{folder.show(where)}' is complete and used other sizes "
                         f"({'; '.join(diffs)}); nothing was run: to run these sizes, pass --overwrite (replaces it) "
                         "or another --output")
    if diffs:
        raise UsageError(f"--resume: the unfinished run in '{folder.show(where)}' used other sizes "
                         f"({'; '.join(diffs)}); resume it with its sizes, or start over with --overwrite")


def _short(v):
    s = format_value(v, 3)
    return s if len(s) < 60 else s[:57] + "..."


def _list(opts: Options) -> int:
    """Print the selected figures and checks, each with its sizes in this run and its estimated cost."""
    selected = _selected(opts)
    est = estimate_cost(opts.sizes, selected)
    for group, registry in zip(("figures", "checks"), registries()):
        names = [n for n in registry if n in selected]
        if names:
            print(f"{group}:")
        for name in names:
            print(f"  {name:<22} {registry[name].title}")
            sizes = ", ".join(f"{k}={v:g}" for k, v in opts.sizes.items() if k.partition(".")[0] == name)
            seconds, nbytes = est.tasks[name]
            print(f"  {'':<22} {sizes or 'no sizes'}; about {_human_seconds(seconds)} CPU, "
                  f"{_human_bytes(nbytes)}")
    print(_estimate_line(est).partition(": ")[2])
    return 0


#: The stop signals received by this run, kept after their exception is raised: a handler that runs
#: inside a callback from C code (numba's compiler calls back into Python while it caches a kernel)
#: raises into a frame that prints and drops the exception, and the run would go on as if no signal
#: had come. :func:`_stop_if_signalled` raises it again at the next piece boundary.
_SIGNALLED: list = []


def _interruption(signum):
    return Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def _on_stop_signal(signum, frame):
    _SIGNALLED.append(signum)
    raise _interruption(signum)


def _quiet_unraisable(previous):
    """A ``sys.unraisablehook`` that drops the interruptions of our stop signals (the run stops at the next
    piece boundary instead, with its usual one-line message) and passes everything else on."""
    def hook(unraisable):
        if _SIGNALLED and isinstance(unraisable.exc_value, KeyboardInterrupt):
            return
        previous(unraisable)
    return hook


def _stop_if_signalled() -> None:
    """Raise the interruption of a stop signal whose exception was swallowed (see :data:`_SIGNALLED`)."""
    if _SIGNALLED:
        raise _interruption(_SIGNALLED[-1])


def run(opts: Options) -> int:
    """Run the selected figures and checks and write the report; return the exit code.

    Raises :class:`~mechanics.paper.output.OutputError` when the output folder cannot be used or
    written, and ``KeyboardInterrupt`` (:class:`Terminated` for SIGTERM) when interrupted; the
    unfinished run is then left in ``OUT.incomplete``, marked so, for ``--resume``.
    """
    prog = Progress(enabled=not opts.quiet)
    est = estimate_cost(opts.sizes, _selected(opts))
    _check_estimate(opts, est)
    prog.message(_estimate_line(est))
    folder = RunFolder(opts.output)
    run_info = {"seed": opts.seed, "convention": opts.convention, "levy_area": opts.levy_area,
                "scale": opts.scale, "only": opts.only, "sizes": opts.sizes, "versions": versions()}
    in_main_thread = threading.current_thread() is threading.main_thread()   # signals: main thread only
    _SIGNALLED.clear()
    previous = ({sig: signal.signal(sig, _on_stop_signal) for sig in (signal.SIGTERM, signal.SIGINT)}
                if in_main_thread else {})
    previous_hook = sys.unraisablehook
    if in_main_thread:
        sys.unraisablehook = _quiet_unraisable(previous_hook)
    try:
        with folder:
            if opts.resume and folder.staging.is_dir():
                _refuse_other_sizes(folder, opts)
            folder.open(run_info, overwrite=opts.overwrite, resume=opts.resume, notify=prog.message)
            if folder.already_complete:
                _refuse_other_sizes(folder, opts, complete=True)
                prog.message(f"{PROG}: '{folder.shown}' is complete (manifest.json verified); nothing to resume")
                return 0
            started = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
            changed = [f"--paths-factor {opts.paths_factor:g}"] if opts.paths_factor != 1 else []
            changed += [f"--steps-factor {opts.steps_factor:g}"] if opts.steps_factor != 1 else []
            changed += [f"{k}={v!r}" for k, v in opts.settings.items()]
            prog.message(f"{PROG}: convention={opts.convention} seed={opts.seed} levy-area={opts.levy_area} "
                         f"sizes={opts.scale}{' ' + ' '.join(changed) if changed else ''} -> "
                         f"{folder.show(folder.staging)}/ (renamed to {folder.shown}/ when complete)")
            t0 = time.perf_counter()
            figures, checks, sizes, timings, reused = _run_tasks(opts, folder, prog)
            meta = RunMetadata(command=opts.command(), seed=opts.seed, convention=opts.convention,
                               scale=opts.scale, sizes=opts.sizes, versions=run_info["versions"],
                               levy_area=opts.levy_area)
            write_report(folder, meta, checks, figures)
            manifest = {
                "package": "roughpaths-mechanics", "version": mechanics.__version__, "seed": opts.seed,
                "convention": opts.convention, "levy_area": opts.levy_area, "scale": opts.scale, "only": opts.only,
                "command": opts.command(),
                "argv": opts.argv, "versions": run_info["versions"], "sizes": opts.sizes, "settings": opts.settings,
                "paths_factor": opts.paths_factor, "steps_factor": opts.steps_factor,
                "estimate": {"cpu_seconds": est.seconds, "peak_bytes": est.peak_bytes}, "started": started,
                "finished": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC"),
                "seconds_this_process": time.perf_counter() - t0, "task_seconds": timings,
                "resumed": bool(opts.resume and reused), "reused": reused,
            }
            # no signal between the manifest and the rename (a kill -9 there is handled by --resume)
            blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
            try:
                final = folder.finish(manifest)
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    except KeyboardInterrupt:
        if folder.staging.exists():
            prog.enabled = True
            prog.message(f"{PROG}: interrupted; the unfinished run is in '{folder.show(folder.staging)}' (marked "
                         "INCOMPLETE): continue it with the same options and --resume")
        raise
    finally:
        for sig, handler in previous.items():
            if handler is not None:                  # None: a handler not set from Python, left alone
                signal.signal(sig, handler)
        sys.unraisablehook = previous_hook
    bad = [r for r in checks + figures if r.status in (FAIL, ERROR)]
    n_pass = sum(c.status == PASS for c in checks)
    prog.message(f"{PROG}: {len(figures)} figures, checks {n_pass}/{len(checks)} passed"
                 + (f", {len(bad)} failed or errored: {', '.join(r.name for r in bad)}" if bad else "")
                 + (f", {len(reused)} reused from the interrupted run" if reused else "")
                 + f" in {time.perf_counter() - t0:.1f}s")
    prog.message(f"{PROG}: report: {final / 'report.md'} and {final / 'report.html'}")
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m mechanics`` and ``levy-area-paper``; returns the exit code."""
    try:
        opts = parse_options(argv)
        if opts.list_only:
            return _list(opts)
        return run(opts)
    except (UsageError, OutputError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        print(f"{PROG}: terminated", file=sys.stderr)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `levy-area-paper --list | head`: not an error of the user's
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return 0
    except SystemExit as exc:  # --help / --version from argparse
        return int(exc.code or 0)
    except OSError as exc:  # an OS error outside the writes (those name their file already)
        print(f"{PROG}: error: {exc.strerror or exc}"
              + (f": '{exc.filename}'" if getattr(exc, "filename", None) else ""), file=sys.stderr)
        return 2
