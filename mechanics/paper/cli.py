"""Command line of the main job: reproduce the paper's figures and theorem checks.

``python -m mechanics`` (or the console script ``levy-area-paper``) runs every figure of the paper
and every theorem / proposition check, and writes PNGs, the ``.npz`` data behind them,
``report.md``, a self-contained ``report.html``, ``results.json`` and, last, ``manifest.json``
(every file with its size and SHA-256, the options, versions and timings) into an output folder.

The folder appears under its name only when complete (see :mod:`mechanics.paper.output`): the run
works in ``OUT.incomplete`` and renames it at the end, a lock keeps two runs out of one folder,
an interrupted run (SIGTERM, SIGINT, a kill, a full disk) can be continued with ``--resume`` and
gives the same bytes as an uninterrupted run.

The options are read and validated by :func:`mechanics.paper.options.parse_options`. The sizes of
each figure and check (numbers of paths and steps, horizons, steps) are its presets (``--tiny``,
default, ``--full``: :data:`mechanics.paper.sizes.SIZES`), scaled by ``--paths-factor`` and
``--steps-factor`` and set one by one with ``--set NAME.SIZE=VALUE``. Before it starts, the run
prints its estimated CPU time and peak memory (:func:`mechanics.paper.cost.estimate_cost`) and
refuses a run beyond the library's memory or work budget.

Every user error (bad option value or size, options that contradict each other, an estimate beyond
the budget, an existing non-empty output folder, an unwritable folder, a full disk) is one line on
stderr and exit code 2, never a traceback. An exception inside one
figure or check is recorded in the report (with its traceback) and the run goes on; the exit code
is then 1.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time
import traceback
from datetime import datetime, timezone

import mechanics

from roughpaths.validation import memory_budget, work_budget

from .cost import ESTIMATE_ACCURACY, CostEstimate, estimate_cost
from .options import PROG, Options, UsageError, parse_options, registries
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
from .sizes import SIZES
from .tasks import Context, Progress

__all__ = ["main", "run"]


class Terminated(KeyboardInterrupt):
    """Raised by the SIGTERM handler: the run stops like on Ctrl-C (exit code 143)."""


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
    """A ``sys.unraisablehook`` that, once a stop signal has come, drops what finalizers and callbacks from C
    cannot raise: the interruption itself (the run stops at the next piece boundary instead, with its usual
    one-line message) and the errors of objects the interruption left half-built (llvmlite's ``__del__``
    of an object whose constructor the signal cut short raises ``AttributeError``). Before any signal,
    everything is passed on."""
    def hook(unraisable):
        if _SIGNALLED:
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
