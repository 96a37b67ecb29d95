"""Command line of the main job: reproduce the paper's figures and theorem checks.

``python -m mechanics`` (or the console script ``levy-area-paper``) runs every figure of the paper
and every theorem / proposition check, and writes PNGs, the ``.npz`` data behind them, ``report.md``
and a self-contained ``report.html`` into an output folder.

Every user error (bad option value, an existing non-empty output folder, an unwritable folder) is
one line on stderr and exit code 2, never a traceback. An exception inside one figure or check is
recorded in the report (with its traceback) and the run goes on; the exit code is then 1.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import traceback
import zlib
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

__all__ = ["main", "build_parser", "parse_options", "Options", "Context", "Progress", "UsageError"]

PROG = "levy-area-paper"
SCALES = ("tiny", "default", "full")
CONVENTIONS = ("rp", "paper")
DEFAULT_OUTPUT = "paper-output"
#: environment variable overriding the default size scale (used by the tests: ``tiny``)
SCALE_ENV = "LEVY_AREA_PAPER_SCALE"


class UsageError(Exception):
    """A user error: reported as one line on stderr, exit code 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse would print usage + message and exit: we want one line
        raise UsageError(f"{message} (see --help)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``python -m mechanics`` / ``levy-area-paper``."""
    p = _Parser(
        prog=PROG,
        description="Reproduce the figures and theorem checks of 'Variational Principles on Geometric "
        "Rough Paths and the Lévy Area Correction': PNG figures with their .npz data, report.md and a "
        "self-contained report.html.",
        epilog="Example: levy-area-paper --output my-run --seed 1 --only fig1,gibbs_mean",
    )
    p.add_argument("--output", "-o", default=DEFAULT_OUTPUT, metavar="DIR",
                   help=f"output folder (default: {DEFAULT_OUTPUT}/); an existing non-empty folder is "
                   "refused unless --overwrite is given")
    p.add_argument("--overwrite", action="store_true",
                   help="write into an existing non-empty output folder (replaces files of the same name)")
    p.add_argument("--convention", default="rp", metavar="{rp,paper}",
                   help="'rp' (default): rough-path-correct signs and factors (CONVENTIONS.md); 'paper': "
                   "the paper's printed equations, slips included, to reproduce its figures literally")
    p.add_argument("--seed", default="0", metavar="INT", help="seed of every random stream (default 0)")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--full", action="store_true", help="paper-scale sizes (about 4-6 minutes on 2 cores; epsilon = 0.005 over T = 500 for Figures 4-5)")
    size.add_argument("--tiny", action="store_true",
                      help="smoke-test sizes (seconds; numbers not meaningful, checks may fail)")
    p.add_argument("--only", action="append", default=None, metavar="NAMES",
                   help="comma-separated subset of figures/checks to run (names from --list; 'figures' "
                   "and 'checks' select a whole group); may be repeated")
    p.add_argument("--list", action="store_true", help="list the figures and checks and exit")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output (errors still shown)")
    return p


@dataclass
class Options:
    """Validated command-line options."""

    output: Path
    overwrite: bool = False
    convention: str = "rp"
    seed: int = 0
    scale: str = "default"
    only: list[str] | None = None
    list_only: bool = False
    quiet: bool = False
    argv: list[str] = field(default_factory=list)


def _registry():
    from . import checks, figures

    return figures.FIGURES, checks.CHECKS


def parse_options(argv: list[str] | None) -> Options:
    """Parse and validate ``argv``; raise :class:`UsageError` (one line) on a bad value."""
    argv = list(sys.argv[1:] if argv is None else argv)
    ns = build_parser().parse_args(argv)
    conv = ns.convention.strip().lower()
    if conv not in CONVENTIONS:
        raise UsageError(f"--convention must be 'rp' or 'paper', got {ns.convention!r}")
    try:
        seed = int(ns.seed)
    except ValueError:
        raise UsageError(f"--seed must be a non-negative integer, got {ns.seed!r}") from None
    if seed < 0:
        raise UsageError(f"--seed must be a non-negative integer, got {seed}")
    scale = "full" if ns.full else "tiny" if ns.tiny else None
    if scale is None:
        env = os.environ.get(SCALE_ENV, "").strip().lower()
        if env and env not in SCALES:
            raise UsageError(f"environment variable {SCALE_ENV} must be one of {', '.join(SCALES)}, "
                             f"got {env!r}")
        scale = env or "default"
    if not ns.output or not str(ns.output).strip():
        raise UsageError("--output must be a folder name, got an empty string")
    only = None
    if ns.only is not None:
        figs, chks = _registry()
        known = list(figs) + list(chks)
        only = []
        for chunk in ns.only:
            for name in (n.strip() for n in chunk.split(",")):
                if not name:
                    continue
                if name == "figures":
                    only += list(figs)
                elif name == "checks":
                    only += list(chks)
                elif name in known:
                    only.append(name)
                else:
                    raise UsageError(f"--only: unknown name {name!r}; valid names: "
                                     f"{', '.join(known)} (or 'figures', 'checks')")
        if not only:
            raise UsageError("--only needs at least one name (see --list)")
        only = list(dict.fromkeys(only))
    return Options(output=Path(ns.output), overwrite=ns.overwrite, convention=conv, seed=seed,
                   scale=scale, only=only, list_only=ns.list, quiet=ns.quiet, argv=argv)


def prepare_output(path: Path, overwrite: bool) -> Path:
    """Create / validate the output folder; raise :class:`UsageError` with one line if unusable."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise UsageError(f"output path '{path}' exists and is not a folder; choose another with --output")
    if path.is_dir():
        try:
            non_empty = any(path.iterdir())
        except OSError as exc:
            raise UsageError(f"cannot read output folder '{path}': {exc.strerror or exc}") from None
        if non_empty and not overwrite:
            raise UsageError(f"output folder '{path}' exists and is not empty; pass --overwrite to write "
                             "into it, or choose a new name with --output")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"cannot create output folder '{path}': {exc.strerror or exc}") from None
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".write-test-"):
            pass
    except OSError as exc:
        raise UsageError(f"output folder '{path}' is not writable: {exc.strerror or exc}") from None
    return path


class Progress:
    """A dependency-free progress printer on stderr.

    On a terminal it redraws one line (``\\r``) at most every 0.1 s; otherwise it prints one line
    at the start and one at the end of each task (logs stay readable). ``enabled=False`` silences it.
    """

    def __init__(self, enabled: bool = True, stream=None):
        self.enabled = enabled
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def bar(self, label: str, total: int | float):
        return _Bar(self, label, total)

    def message(self, text: str) -> None:
        if self.enabled:
            print(text, file=self.stream, flush=True)


class _Bar:
    def __init__(self, owner: Progress, label: str, total):
        self.owner, self.label, self.total = owner, label, max(float(total), 1e-300)
        self.done = 0.0
        self.t0 = time.perf_counter()
        self._last = 0.0
        if owner.enabled and not owner.tty:
            print(f"  {label} ...", file=owner.stream, flush=True)

    def update(self, n: float = 1) -> None:
        self.done = min(self.done + n, self.total)
        if not (self.owner.enabled and self.owner.tty):
            return
        now = time.perf_counter()
        if now - self._last < 0.1 and self.done < self.total:
            return
        self._last = now
        frac = self.done / self.total
        width = 24
        fill = int(round(frac * width))
        elapsed = now - self.t0
        eta = elapsed * (1 - frac) / frac if frac > 0 else float("nan")
        line = (f"\r  {self.label:<34.34} [{'#' * fill}{'.' * (width - fill)}] {100 * frac:5.1f}% "
                f"{elapsed:6.1f}s" + (f"  eta {eta:5.0f}s" if 0 < frac < 1 else "          "))
        print(line, end="", file=self.owner.stream, flush=True)

    def close(self) -> None:
        if not self.owner.enabled:
            return
        elapsed = time.perf_counter() - self.t0
        if self.owner.tty:
            print(f"\r  {self.label:<34.34} done in {elapsed:.1f}s" + " " * 40, file=self.owner.stream,
                  flush=True)
        else:
            print(f"  {self.label} done in {elapsed:.1f}s", file=self.owner.stream, flush=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


@dataclass
class Context:
    """What a figure or check receives: options, output folder, seeded streams, sizes, progress."""

    out_dir: Path
    convention: str = "rp"
    seed: int = 0
    scale: str = "default"
    progress: Progress = field(default_factory=lambda: Progress(enabled=False))
    sizes: dict = field(default_factory=dict)
    #: results shared between tasks (e.g. one coloured-noise run behind Figures 4 and 5)
    cache: dict = field(default_factory=dict)

    def rng(self, name: str) -> np.random.Generator:
        """Generator seeded by ``(seed, name)``: a task's numbers do not depend on which others ran."""
        return np.random.default_rng([self.seed, zlib.crc32(name.encode())])

    def size(self, key: str, *, tiny, default, full):
        """Pick a size for the current scale and record it for the report's metadata."""
        value = {"tiny": tiny, "default": default, "full": full}[self.scale]
        self.sizes[key] = value
        return value


def _run_tasks(opts: Options, ctx: Context):
    from .report import ERROR, SKIPPED, CheckResult, FigureResult

    figs, chks = _registry()
    selected = set(opts.only) if opts.only else None
    fig_results, check_results, timings = [], [], {}
    prog = ctx.progress
    for kind, registry in (("figure", figs), ("check", chks)):
        for name, task in registry.items():
            if selected is not None and name not in selected:
                continue
            missing = task.missing_modules()
            t0 = time.perf_counter()
            if missing:
                why = "needs " + ", ".join(missing) + " (not available yet)"
                prog.message(f"[{kind} {name}] skipped: {why}")
                res = (FigureResult(name, task.title, task.caption, status=SKIPPED, details=why)
                       if kind == "figure" else
                       CheckResult(name, task.title, status=SKIPPED, details=why))
            else:
                prog.message(f"[{kind} {name}] {task.title}")
                try:
                    res = task.run(ctx)
                except Exception:
                    tb = traceback.format_exc()
                    last = tb.strip().splitlines()[-1]
                    prog.message(f"[{kind} {name}] error: {last}")
                    res = (FigureResult(name, task.title, task.caption, status=ERROR, details=tb)
                           if kind == "figure" else
                           CheckResult(name, task.title, status=ERROR, details=tb))
            res.seconds = time.perf_counter() - t0
            timings[f"{kind} {name}"] = res.seconds
            if kind == "check" and res.status not in (SKIPPED, ERROR):
                prog.message(f"[check {name}] {res.status}: predicted {_short(res.predicted)}, "
                             f"measured {_short(res.measured)}")
            (fig_results if kind == "figure" else check_results).append(res)
    return fig_results, check_results, timings


def _short(v):
    from .report import format_value

    s = format_value(v, 3)
    return s if len(s) < 60 else s[:57] + "..."


def _list(opts: Options) -> int:
    figs, chks = _registry()
    print("figures:")
    for name, t in figs.items():
        miss = t.missing_modules()
        print(f"  {name:<14} {t.title}" + (f"   [needs {', '.join(miss)}]" if miss else ""))
    print("checks:")
    for name, t in chks.items():
        miss = t.missing_modules()
        print(f"  {name:<14} {t.title}" + (f"   [needs {', '.join(miss)}]" if miss else ""))
    return 0


def run(opts: Options) -> int:
    """Run the selected figures and checks and write the report; return the exit code."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    from .report import ERROR, FAIL, SKIPPED, RunMetadata, versions, write_report

    out = prepare_output(opts.output, opts.overwrite)
    prog = Progress(enabled=not opts.quiet)
    ctx = Context(out_dir=out, convention=opts.convention, seed=opts.seed, scale=opts.scale, progress=prog)
    started = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    prog.message(f"{PROG}: convention={opts.convention} seed={opts.seed} sizes={opts.scale} -> {out}/")
    t0 = time.perf_counter()
    figures, checks, timings = _run_tasks(opts, ctx)
    meta = RunMetadata(command=" ".join([PROG] + opts.argv), seed=opts.seed, convention=opts.convention,
                       scale=opts.scale, sizes=dict(ctx.sizes), versions=versions(), timings=timings,
                       started=started, total_seconds=time.perf_counter() - t0)
    md, page = write_report(out, meta, checks, figures)
    bad = [r for r in checks + figures if r.status in (FAIL, ERROR)]
    skipped = [r for r in checks + figures if r.status == SKIPPED]
    n_pass = sum(c.status == "pass" for c in checks)
    prog.message(f"{PROG}: {len(figures)} figures, checks {n_pass}/{len(checks)} passed"
                 + (f", {len(skipped)} skipped" if skipped else "")
                 + (f", {len(bad)} failed or errored: {', '.join(r.name for r in bad)}" if bad else "")
                 + f" in {meta.total_seconds:.1f}s")
    prog.message(f"{PROG}: report: {md} and {page}")
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m mechanics`` and ``levy-area-paper``; returns the exit code."""
    try:
        opts = parse_options(argv)
        if opts.list_only:
            return _list(opts)
        return run(opts)
    except UsageError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
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
    except OSError as exc:  # e.g. disk full or the folder removed while writing
        print(f"{PROG}: error: {exc.strerror or exc}"
              + (f": '{exc.filename}'" if getattr(exc, "filename", None) else ""), file=sys.stderr)
        return 2
