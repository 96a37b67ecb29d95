"""The options of the main job's command line: the parser and the validation of every value.

:func:`parse_options` reads ``argv`` into validated :class:`Options`: the output folder, seed,
convention and Lévy-area sampler, the figures and checks selected with ``--only`` (names from
:func:`registries`), and the sizes of each (:func:`~.sizes.plan_sizes`: the presets of ``--tiny``,
default or ``--full``, ``--paths-factor``, ``--steps-factor`` and ``--set``). A bad value, an unknown
name or options that contradict each other raise :class:`UsageError`, which
:func:`mechanics.paper.cli.main` reports as one line on stderr with exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import sys
from dataclasses import dataclass, field

import roughpaths

from .sizes import SIZES, SizeError, check_size, plan_sizes

__all__ = ["build_parser", "parse_options", "Options", "UsageError", "registries"]

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
