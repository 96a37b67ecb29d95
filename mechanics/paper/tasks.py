"""What the figures and checks of the main job are made of: tasks, their context, a progress printer.

A :class:`Task` is a named function ``task(ctx) -> FigureResult | CheckResult``; the figures and the
checks register themselves in :data:`mechanics.paper.figures.FIGURES` and
:data:`mechanics.paper.checks.CHECKS` with :func:`registry_decorator`. Each task receives a
:class:`Context`: the options of the run, its sizes (:data:`~.sizes.SIZES`), a random stream of its own
(seeded by the run's seed and the task's name, so a task's numbers do not depend on which tasks ran
before it, or whether the run was resumed), and a way to save its files into the output folder.
"""

from __future__ import annotations

import io
import sys
import time
import zlib
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .sizes import SIZES, size_spec
from .output import npz_bytes

__all__ = ["Task", "registry_decorator", "Context", "Progress", "DPI"]

#: resolution of the saved figures
DPI = 130


@dataclass
class Task:
    """A registry entry: a figure or a check, its title and caption."""

    name: str
    title: str
    func: Callable
    caption: str = ""

    def run(self, ctx):
        """Run the task on ``ctx``, which it names (:attr:`Context.task`) and which records all its sizes."""
        if ctx.task is None:
            ctx.task = self.name
        if ctx.task != self.name:
            raise ValueError(f"a context of task {ctx.task!r} was given to task {self.name!r}; make one per task")
        for word in SIZES.get(self.name, {}):
            ctx.sizes[f"{self.name}.{word}"] = ctx.size_value(self.name, word)
        return self.func(ctx)


def registry_decorator(registry: dict):
    """A decorator ``register(name, title, caption="")`` adding functions to ``registry`` (in order)."""

    def register(name: str, title: str, caption: str = ""):
        def deco(func):
            registry[name] = Task(name=name, title=title, func=func, caption=caption)
            return func

        return deco

    return register


class Progress:
    """A dependency-free progress printer on stderr.

    On a terminal it redraws one line (``\\r``) at most every 0.1 s; otherwise it prints one line
    at the start and one at the end of each bar (logs stay readable). ``enabled=False`` silences it.
    """

    def __init__(self, enabled: bool = True, stream=None):
        self.enabled = enabled
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def bar(self, label: str, total: int | float):
        """A context manager with ``update(n=1)``: one bar of ``total`` units."""
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
    """What a figure or check receives.

    Attributes
    ----------
    folder : RunFolder or None
        Where :meth:`save_figure` writes (None: nothing is saved, e.g. in tests of a single check).
    task : str or None
        The name of the figure or check being run (set by :meth:`Task.run` if not given).
    convention, seed, scale : str, int, str
        The run's options.
    plan : dict or None
        The run's sizes, ``{"TASK.WORD": value}`` (:func:`~.sizes.plan_sizes`: presets of ``scale``,
        ``--paths-factor``, ``--steps-factor`` and ``--set``); None: the presets of ``scale``.
    levy_area : str
        The run's ``--levy-area``: the sampler of the Brownian Lévy areas (one of
        :data:`roughpaths.LEVY_AREA_METHODS`). Every Brownian driver a task creates with areas passes
        :meth:`levy_area_for` of its dimension (this value, but for ``"exact"`` at ``d > 2``).
    progress : Progress
    sizes : dict
        The sizes of the current task, ``{"TASK.WORD": value}``, recorded for the report (all of the
        task's sizes, whether or not it reads them on this run: a figure that reuses a cached run
        reads none).
    files : dict
        ``{file name: {"size", "sha256"}}`` written by the current task.
    cache : dict
        Results shared between tasks (e.g. one coloured-noise run behind Figures 4 and 5); a cached
        value must be a deterministic function of the seed and the task's sizes (the main job gives
        tasks whose sizes differ different caches).
    """

    folder: Any = None
    task: str | None = None
    convention: str = "rp"
    seed: int = 0
    levy_area: str = "auto"
    scale: str = "default"
    plan: dict | None = None
    progress: Progress = field(default_factory=lambda: Progress(enabled=False))
    sizes: dict = field(default_factory=dict)
    files: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict)

    def rng(self, name: str) -> np.random.Generator:
        """Generator seeded by ``(seed, name)``: a task's numbers do not depend on which others ran."""
        return np.random.default_rng([self.seed, zlib.crc32(name.encode())])

    def seed_for(self, name: str) -> int:
        """A non-negative integer seed derived from ``(seed, name)`` (for APIs taking a seed)."""
        return int(np.random.SeedSequence([self.seed, zlib.crc32(name.encode())]).generate_state(1, np.uint64)[0])

    def levy_area_for(self, dim: int) -> str:
        """The ``levy_area`` of a Brownian driver of dimension ``dim``: the run's ``--levy-area``.

        ``"exact"`` samples ``d <= 2`` only; a ``d > 2`` driver then uses ``"auto"`` (Mrongowius–Rößler,
        per-step L² error ``h^1.5``, strong order 1), as the report states (:func:`~.report.levy_area_text`).
        """
        return "auto" if self.levy_area == "exact" and dim > 2 else self.levy_area

    def size_value(self, task: str, word: str):
        """The value of size ``word`` of ``task`` in this run: :attr:`plan`'s, else the preset's."""
        key = f"{task}.{word}"
        if self.plan is not None and key in self.plan:
            return self.plan[key]
        return size_spec(key).preset(self.scale)

    def size(self, key: str, **presets):
        """The value of the current task's size ``key`` in this run, recorded for the report.

        Parameters
        ----------
        key : str
            ``"TASK.WORD"`` of :data:`~.sizes.SIZES`; a key whose ``TASK`` is not the current task
            (a helper shared by several tasks, e.g. ``"portrait.levels"``) means the current task's
            ``WORD``.
        **presets
            ``tiny=``, ``default=``, ``full=``: optional, the presets the caller expects; they must be
            those of :data:`~.sizes.SIZES` (``ValueError`` otherwise), so that they cannot drift apart.

        Returns
        -------
        int or float
        """
        prefix, _, word = key.rpartition(".")
        task = self.task if self.task is not None else prefix
        if task not in SIZES or word not in SIZES[task]:
            raise ValueError(f"size {key!r} of task {task!r} is not declared in mechanics.paper.sizes.SIZES; "
                             "declare it there (its presets, kind and meaning)")
        spec = SIZES[task][word]
        wrong = {k: v for k, v in presets.items() if spec.preset(k) != v}
        if wrong:
            raise ValueError(f"size {key!r} of task {task!r}: the presets given ({wrong}) differ from those in "
                             f"mechanics.paper.sizes.SIZES ({spec.tiny}, {spec.default}, {spec.full}); keep one")
        value = self.size_value(task, word)
        self.sizes[f"{task}.{word}"] = value
        return value

    def save_figure(self, name: str, fig, data: dict) -> tuple[str, str]:
        """Save ``fig`` as ``<name>.png`` and ``data`` as ``<name>.npz``; return the two file names.

        Both files are byte-for-byte reproducible (no time stamps), and written atomically.
        """
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=DPI, bbox_inches="tight")
        png, npz = f"{name}.png", f"{name}.npz"
        blobs = {png: buf.getvalue(), npz: npz_bytes({k: np.asarray(v) for k, v in data.items()})}
        for fname, blob in blobs.items():
            self.files[fname] = self.folder.write_bytes(fname, blob) if self.folder is not None else \
                {"size": len(blob), "sha256": None}
        return png, npz
