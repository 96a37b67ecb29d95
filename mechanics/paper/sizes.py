"""The sizes the main job's figures and checks run at.

:data:`SIZES`: every number of paths, number of steps, horizon and step each figure and check reads,
its presets (``--tiny``, default, ``--full``) and the values it accepts (``docs/main-job.md``, section
Sizes); :func:`plan_sizes` resolves a run's sizes from the presets, the factors and ``--set``. What a
run at these sizes costs is estimated by :mod:`mechanics.paper.cost`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Size", "SizeError", "SIZES", "size_spec", "check_size", "check_task_sizes", "plan_sizes"]


@dataclass(frozen=True)
class Size:
    """One size a figure or check reads: its value at each preset and the values it accepts.

    Attributes
    ----------
    tiny, default, full : int or float
        The value at ``--tiny``, by default and at ``--full``.
    kind : {"count", "power of 2", "positive"}
        A whole number ``>= minimum``, a power of 2 ``>= minimum``, or a finite real number
        ``>= minimum`` and ``> 0``.
    role : {"paths", "steps", "step", "other"}
        What ``--paths-factor`` and ``--steps-factor`` do to it: ``"paths"`` (a number of paths) is
        multiplied by the paths factor; ``"steps"`` (a number of steps) is multiplied by the steps
        factor (a power of 2 is rounded to the nearest power of 2); ``"step"`` (a step ``dt`` over a
        horizon ``T``) becomes ``T / round(factor · T / dt)``; ``"other"`` is left alone.
    meaning : str
        What it is, for ``--list`` and the error messages.
    minimum : float
        The smallest accepted value.
    """

    tiny: float
    default: float
    full: float
    kind: str
    role: str
    meaning: str
    minimum: float = 1

    def preset(self, scale: str):
        """The value at the preset ``scale`` (``"tiny"``, ``"default"`` or ``"full"``)."""
        return {"tiny": self.tiny, "default": self.default, "full": self.full}[scale]


def _paths(tiny, default, full, meaning="independent paths", minimum=1):
    return Size(tiny, default, full, "count", "paths", meaning, minimum)


def _steps(tiny, default, full, meaning, minimum=1, kind="count"):
    return Size(tiny, default, full, kind, "steps", meaning, minimum)


def _horizon(tiny, default, full, minimum):
    return Size(tiny, default, full, "positive", "other", "time horizon T", minimum)


def _dt(tiny, default, full):
    return Size(tiny, default, full, "positive", "step", "time step dt (T/dt steps)", 1e-5)


def _eps(tiny, default, full):
    return Size(tiny, default, full, "positive", "other", "correlation time ε of the coloured noise (its step is "
                "ε²/(2‖A‖))", 0.0)


def _matrix(tiny, default, full, meaning, minimum):
    return Size(tiny, default, full, "count", "other", meaning, minimum)


_LEVELS = Size(8, 18, 24, "count", "other", "level sets drawn")
_FINEST = "steps of the finest grid on [0, 1]; the check halves the step down to 1/n_steps"

#: The sizes of every figure and check: ``{task name: {word: Size}}``, in report order. A size is set on
#: the command line as ``--set TASK.WORD=VALUE``; the words are ``n_paths`` (number of independent paths),
#: ``n_steps`` (number of time steps), ``T`` (horizon), ``dt`` (step), ``eps`` (ε of the coloured noise),
#: ``levels`` (level sets of a phase portrait), ``n_paths_wrong_models``, and beyond the paper ``N`` and ``n_ref``
#: (matrix sizes of Zeitlin's model of Euler on the sphere). A task absent here has no
#: sizes (its numbers are fixed by the claim it checks).
SIZES: dict = {
    "fig1": {"T": _horizon(20.0, 2_000.0, 20_000.0, 0.1), "dt": _dt(0.01, 0.005, 0.001)},
    "fig2": {"T": _horizon(20.0, 1_000.0, 20_000.0, 0.1), "dt": _dt(0.01, 0.005, 0.001)},
    "surf": {"levels": _LEVELS},
    "surf2": {"levels": _LEVELS},
    "surf3": {"levels": _LEVELS},
    "surf4": {"levels": _LEVELS},
    "surf5": {"levels": _LEVELS},
    "fig4": {"eps": _eps(0.05, 0.01, 0.005), "T": _horizon(10.0, 200.0, 500.0, 0.1)},
    "fig5": {"eps": _eps(0.05, 0.01, 0.005), "T": _horizon(10.0, 200.0, 500.0, 0.1)},
    # beyond the paper: Euler on the sphere (mechanics.paper.sphere_figure)
    "sphere_euler": {"N": _matrix(32, 64, 128, "matrix size N of Zeitlin's model (degrees l < N)", 8),
                     "n_steps": _steps(50, 100, 400, "LieHeun steps on [0, 2]", minimum=10)},
    "chen": {"n_steps": _steps(200, 10_000, 100_000, "steps on [0, 1]", minimum=3),
             "n_paths": _paths(4, 64, 256)},
    "levy_log": {"n_steps": _steps(100, 2_000, 20_000, "steps on [0, 1] (32 paths)")},
    "brownian_levy_area": {"n_paths": _paths(2_000, 40_000, 400_000, minimum=2)},
    "friz_oberhauser": {"n_paths": _paths(8, 64, 256),
                        "n_steps": _steps(2**8, 2**11, 2**13, _FINEST, minimum=16, kind="power of 2")},
    "prop21": {"n_paths": _paths(4, 32, 128), "n_steps": _steps(200, 4_000, 20_000, "steps on [0, 10]")},
    "forced_euler_poincare": {"n_paths": _paths(4, 12, 32),
                              "n_steps": _steps(2**6, 2**8, 2**9, _FINEST, minimum=8, kind="power of 2")},
    "hamiltonian_reduction": {"n_paths": _paths(2, 4, 8),
                              "n_steps": _steps(2**7, 2**8, 2**10, _FINEST, minimum=16, kind="power of 2")},
    "casimir": {"n_steps": _steps(1_000, 10_000, 100_000, "steps of dt = 0.01"), "n_paths": _paths(16, 64, 1_000)},
    "gibbs_mean": {"n_paths": _paths(8, 64, 512, "paths of each corrected model", minimum=2),
                   "T": _horizon(40.0, 300.0, 1_000.0, 31.0), "dt": _dt(0.01, 0.005, 0.002),
                   "n_paths_wrong_models": _paths(8, 16, 32, "paths of each rejected model", minimum=2)},
    "uniform_no_dissipation": {"n_paths": _paths(200, 2_000, 10_000, "paths (T = 30, dt = 0.02)", minimum=2)},
    "coloured_area_rate": {"n_paths": _paths(50, 400, 2_000, "paths (500 steps)", minimum=2)},
    "wong_zakai": {"n_paths": _paths(600, 1_000, 4_000, "paired paths (T = 2)", minimum=2),
                   "eps": _eps(0.02, 0.02, 0.01)},
    "chaos": {"n_paths": _paths(300, 6_000, 20_000, "cat-map orbits (Lorenz: a third, at least 200)", minimum=2),
              "n_steps": _steps(40, 200, 1_000, "fast steps per unit time (Lorenz: twice as many)")},
    "matrix_prop21": {"n_paths": _paths(2, 8, 32, "paths per algebra (su(3), so(5))"),
                      "n_steps": _steps(100, 400, 4_000, "steps on [0, 1]")},
    "matrix_uniform": {"n_paths": _paths(200, 1_500, 20_000, "paths and fresh orbit samples per algebra (T = 1.5, "
                                         "dt = 0.025)", minimum=2)},
    "matrix_gibbs": {"n_paths": _paths(100, 600, 6_000, "paths per algebra (su(3), so(5))", minimum=2),
                     "n_samples": Size(10_000, 50_000, 400_000, "count", "other", "exact orbit samples of the "
                                       "importance-sampling oracle, per algebra", 2),
                     "T": _horizon(3.0, 4.0, 12.0, 2.0), "dt": _dt(0.02, 0.02, 0.01)},
    # beyond the paper: Euler on the sphere (mechanics.paper.sphere_checks)
    "sphere_casimirs": {"N": _matrix(32, 64, 128, "matrix size N of Zeitlin's model", 4),
                        "n_steps": _steps(20, 40, 200, "LieHeun steps on [0, 0.5]", minimum=2)},
    "sphere_friz_oberhauser": {"n_paths": _paths(2, 8, 32)},
    "sphere_convergence": {"n_ref": _matrix(64, 128, 256, "N of the reference (compared: N = 8, 16, ... <= n_ref/4)",
                                            64)},
    "sphere_strong_order": {"n_paths": _paths(8, 16, 64, "paths (N = 16, 2⁹ fine steps)", minimum=2)},
    "sphere_levy_drift": {"n_paths": _paths(1_000, 4_000, 100_000, "paths from one W₀ (su(4), h = 0.1)",
                                            minimum=2)},
}


class SizeError(ValueError):
    """Sizes of a figure or check that cannot be used; :attr:`task` names it (None: not one task's)."""

    def __init__(self, message: str, task: str | None = None):
        super().__init__(message)
        self.task = task


def size_spec(key: str) -> Size:
    """The :class:`Size` of ``key`` (``"TASK.WORD"``); ``ValueError`` listing the valid keys if unknown.

    Examples
    --------
    >>> size_spec("chen.n_paths").full
    256
    """
    task, _, word = str(key).partition(".")
    if task not in SIZES:
        raise ValueError(f"unknown figure or check {task!r} in {key!r}; the ones with sizes are "
                         f"{', '.join(SIZES)}")
    if word not in SIZES[task]:
        raise ValueError(f"{task} has no size {word!r}; its sizes are {', '.join(SIZES[task])}")
    return SIZES[task][word]


def check_size(key: str, value) -> int | float:
    """``value`` as the number the size ``key`` takes (int for counts), or ``ValueError`` saying why not.

    Parameters
    ----------
    key : str
        ``"TASK.WORD"``, a key of :data:`SIZES`.
    value : int or float

    Returns
    -------
    int or float

    Examples
    --------
    >>> check_size("chen.n_paths", 2e3)
    2000
    >>> check_size("fig1.dt", 0.0)
    Traceback (most recent call last):
    ...
    ValueError: fig1.dt (time step dt (T/dt steps)) must be a positive real number >= 1e-05, got 0.0
    """
    spec = size_spec(key)
    what = f"{key} ({spec.meaning})"
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a number, got {value!r}") from None
    if spec.kind == "positive":
        if not (math.isfinite(x) and x > 0 and x >= spec.minimum):
            floor = f" >= {spec.minimum:g}" if spec.minimum else ""
            raise ValueError(f"{what} must be a positive real number{floor}, got {value!r}")
        return x
    whole = math.isfinite(x) and x == math.floor(x) and x >= spec.minimum
    if spec.kind == "power of 2":
        if not (whole and int(x) & (int(x) - 1) == 0):
            raise ValueError(f"{what} must be a power of 2 >= {spec.minimum:g}, got {value!r}")
    elif not whole:
        raise ValueError(f"{what} must be a whole number >= {spec.minimum:g}, got {value!r}")
    return int(x)


def check_task_sizes(task: str, sizes: dict) -> None:
    """Refuse sizes of one task that are valid alone but not together (:class:`SizeError`).

    A horizon ``T`` with a step ``dt`` must make a whole number of steps (``T/dt`` within ``1e-9`` of
    an integer), at least one.

    Examples
    --------
    >>> check_task_sizes("fig1", {"T": 1.0, "dt": 0.3})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechanics.paper.sizes.SizeError: fig1: T/dt = 1/0.3 = 3.333 is not a whole number of steps; choose a dt ...
    """
    if "T" in sizes and "dt" in sizes:
        T, dt = sizes["T"], sizes["dt"]
        n = T / dt
        if not (n >= 1 and abs(n - round(n)) <= 1e-9 * n):
            raise SizeError(f"{task}: T/dt = {T:g}/{dt:g} = {n:.4g} is not a whole number of steps; choose a dt that "
                             f"divides T = {T:g} (or a T that is a multiple of dt)", task)


def _scaled(spec: Size, value, factor: float, T=None):
    """A preset ``value`` of ``spec`` under a paths or steps ``factor`` (see :class:`Size`)."""
    if spec.role in ("paths", "steps") and spec.kind == "power of 2":
        return int(2 ** round(math.log2(value * factor)))
    if spec.role in ("paths", "steps"):
        return int(round(value * factor))
    if spec.role == "step":
        return T / round(factor * T / value)
    return value


def plan_sizes(scale: str, tasks, *, settings: dict | None = None, paths_factor: float = 1.0,
               steps_factor: float = 1.0) -> dict:
    """The sizes of ``tasks`` for a run: presets of ``scale``, then the factors, then ``settings``.

    Parameters
    ----------
    scale : {"tiny", "default", "full"}
    tasks : iterable of str
        Names of figures and checks (those without sizes contribute nothing).
    settings : dict, optional
        ``{"TASK.WORD": value}``: explicit values, which win over the factors.
    paths_factor, steps_factor : float
        Multiply every number of paths, every number of steps (and divide every step ``dt``) of the
        presets, as :class:`Size` says; 1 leaves the presets exactly as they are.

    Returns
    -------
    dict
        ``{"TASK.WORD": value}`` in report order, every size of every task given.

    Raises
    ------
    SizeError
        An unknown key, a value :func:`check_size` refuses, a factor that takes a size below its
        minimum (the message names the factor), or sizes :func:`check_task_sizes` refuses.

    Examples
    --------
    >>> plan_sizes("default", ["chen"], paths_factor=2, settings={"chen.n_steps": 500})
    {'chen.n_steps': 500, 'chen.n_paths': 128}
    """
    settings = dict(settings or {})
    tasks = list(tasks)
    for key, value in settings.items():
        try:
            settings[key] = check_size(key, value)
        except ValueError as exc:
            raise SizeError(str(exc), key.partition(".")[0]) from None
        if key.partition(".")[0] not in tasks:
            raise SizeError(f"{key} is set, but {key.partition('.')[0]} is not run (not selected by --only)",
                            key.partition(".")[0])
    plan = {}
    for task in tasks:
        mine = {}
        for word, spec in SIZES.get(task, {}).items():
            key = f"{task}.{word}"
            if key in settings:
                mine[word] = settings[key]
                continue
            value = spec.preset(scale)
            factor, option = ((paths_factor, "--paths-factor") if spec.role == "paths"
                              else (steps_factor, "--steps-factor"))
            if spec.role != "other" and factor != 1.0:
                count = factor * (mine["T"] / value if spec.role == "step" else value)   # paths or steps
                if not math.isfinite(count):
                    raise SizeError(f"{option} {factor:g} makes {key} ({spec.meaning}) overflow; use a smaller factor",
                                    task)
                value = _scaled(spec, value, factor, T=mine.get("T"))
                if not value >= spec.minimum:
                    raise SizeError(f"{option} {factor:g} takes {key} ({spec.meaning}) from "
                                     f"{spec.preset(scale):g} to {value:g}, below its minimum {spec.minimum:g}; use a "
                                     f"larger factor or set it with --set {key}=VALUE", task)
            mine[word] = value
        check_task_sizes(task, mine)
        plan.update({f"{task}.{word}": v for word, v in mine.items()})
    return plan
