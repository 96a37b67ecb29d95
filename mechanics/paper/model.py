"""The paper's Section 4 set-up shared by its figures and checks, and the sizes they run at.

The stochastic rigid body with inertia ``𝕀 = diag(1, 2, 3)``, isotropic noise ``σ = 0.05``,
dissipation ``θ = 1`` and ``Π(0) = e₃``; antisymmetric Lévy-area perturbations ``s`` written by
their upper entries; the Gibbs mean conditioned on a hemisphere (a trajectory started at ``e₃``
with ``σ = 0.05`` never crosses the equator, so it samples the Gibbs law of its basin).
Conventions: ``docs/conventions.md``.

The sizes (:data:`SIZES`): every number of paths, number of steps, horizon and step each figure and
check reads, its presets (``--tiny``, default, ``--full``) and the values it accepts;
:func:`plan_sizes` resolves a run's sizes from the presets, the factors and ``--set``, and
:func:`estimate_cost` predicts the run's CPU time and peak memory from measured costs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import mechanics

__all__ = ["INERTIA", "SIGMA", "THETA", "PI0", "s_matrix", "s_label", "paper_body", "hemisphere_mean",
           "standard_error", "Size", "SizeError", "SIZES", "size_spec", "check_size", "check_task_sizes", "plan_sizes",
           "CostEstimate", "estimate_cost", "ESTIMATE_ACCURACY"]

#: the paper's inertia 𝕀 = diag(1, 2, 3)
INERTIA = (1.0, 2.0, 3.0)
#: noise amplitude σ of the isotropic noise ξ_i = σ e_i
SIGMA = 0.05
#: dissipation strength θ
THETA = 1.0
#: the initial state Π(0) = e3
PI0 = np.array([0.0, 0.0, 1.0])


def s_matrix(s12: float = 0.0, s13: float = 0.0, s23: float = 0.0) -> np.ndarray:
    """The antisymmetric 3×3 Lévy-area perturbation ``s`` with the given upper entries.

    Examples
    --------
    >>> s_matrix(s13=25.0)[2, 0]
    np.float64(-25.0)
    """
    return np.array([[0.0, s12, s13], [-s12, 0.0, s23], [-s13, -s23, 0.0]])


def s_label(s) -> str:
    """Matplotlib label of the non-zero entries of ``s``, e.g. ``s$^{13}$=25``."""
    parts = [f"s$^{{{i + 1}{j + 1}}}$={s[i, j]:g}" for i, j in ((0, 1), (0, 2), (1, 2)) if s[i, j] != 0]
    return ", ".join(parts) if parts else "s = 0"


def paper_body(s=None, *, sigma=SIGMA, theta=THETA, convention="rp"):
    """The paper's rigid body with Lévy-area perturbation ``s`` (``mechanics.rigid_body``)."""
    return mechanics.rigid_body(INERTIA, sigma=sigma, s=s, theta=theta, convention=convention)


def hemisphere_mean(gibbs, sign: float = 1.0) -> np.ndarray:
    """Mean of a Gibbs measure on the sphere conditioned on ``sign(Π₃) = sign``.

    Parameters
    ----------
    gibbs : mechanics.GibbsMeasure
    sign : {1.0, -1.0}

    Returns
    -------
    ndarray, shape ``(3,)``
    """

    def feats(P):
        ind = (np.sign(P[..., 2:3]) == sign).astype(np.float64)
        return np.concatenate([P * ind, ind], axis=-1)

    e = gibbs.expectation(feats)
    return e[:3] / e[3]


def standard_error(x, axis: int = 0) -> np.ndarray:
    """Standard error of the mean of independent samples along ``axis`` (``ddof = 1``)."""
    x = np.asarray(x, dtype=np.float64)
    return np.std(x, axis=axis, ddof=1) / np.sqrt(x.shape[axis])


# ------------------------------------------------------------------------------------------------ sizes
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


_LEVELS = Size(8, 18, 24, "count", "other", "level sets drawn")
_FINEST = "steps of the finest grid on [0, 1]; the check halves the step down to 1/n_steps"

#: The sizes of every figure and check: ``{task name: {word: Size}}``, in report order. A size is set on
#: the command line as ``--set TASK.WORD=VALUE``; the words are ``n_paths`` (number of independent paths),
#: ``n_steps`` (number of time steps), ``T`` (horizon), ``dt`` (step), ``eps`` (ε of the coloured noise),
#: ``levels`` (level sets of a phase portrait) and ``n_paths_wrong_models``. A task absent here has no
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
    mechanics.paper.model.SizeError: fig1: T/dt = 1/0.3 = 3.333 is not a whole number of steps; choose a dt ...
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


# ------------------------------------------------------------------------------------------------ costs
def _coloured_steps(T: float, eps: float) -> float:
    """Steps of the paper's coloured-noise runs (k = 0.05): ``T / h``, ``h = ε²/(2‖A‖)``,
    ``‖A‖ = √(1 + k²)``."""
    return T * 2.0 * math.hypot(1.0, 0.05) / eps**2


#: What each task's CPU time and memory grow with, ``{task: (work(s), held(s))}`` for its sizes
#: ``s = {word: value}``: ``work`` counts path-steps (or level sets), ``held`` what the task holds at
#: once (path-steps of one chunk, paths, ...). Tasks absent here cost a fixed amount.
_GROWTH = {
    "fig1": (lambda s: s["T"] / s["dt"], lambda s: s["T"] / s["dt"]),
    "fig2": (lambda s: 4 * s["T"] / s["dt"], lambda s: s["T"] / s["dt"]),
    **{name: (lambda s: s["levels"], lambda s: s["levels"]) for name in ("surf", "surf2", "surf3", "surf4", "surf5")},
    "fig4": (lambda s: _coloured_steps(s["T"], s["eps"]), lambda s: _coloured_steps(s["T"], s["eps"])),
    "fig5": (lambda s: _coloured_steps(s["T"], s["eps"]), lambda s: _coloured_steps(s["T"], s["eps"])),
    "chen": (lambda s: s["n_paths"] * s["n_steps"], lambda s: min(s["n_paths"], 16) * s["n_steps"]),
    "levy_log": (lambda s: 32 * s["n_steps"], lambda s: 32 * s["n_steps"]),
    "brownian_levy_area": (lambda s: s["n_paths"], lambda s: s["n_paths"]),
    "friz_oberhauser": (lambda s: s["n_paths"] * s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
    "prop21": (lambda s: s["n_paths"] * s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
    # the reference ODE (an RK4 per step and per loop) and the LogODE levels: a Python loop over the steps
    "forced_euler_poincare": (lambda s: s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
    "hamiltonian_reduction": (lambda s: s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
    "casimir": (lambda s: s["n_paths"] * s["n_steps"], lambda s: s["n_paths"]),
    "gibbs_mean": (lambda s: (2 * s["n_paths"] + 4 * s["n_paths_wrong_models"]) * s["T"] / s["dt"],
                   lambda s: max(s["n_paths"], s["n_paths_wrong_models"])),
    "uniform_no_dissipation": (lambda s: 1500 * s["n_paths"], lambda s: s["n_paths"]),
    "coloured_area_rate": (lambda s: 500 * s["n_paths"], lambda s: 500 * s["n_paths"]),
    "wong_zakai": (lambda s: s["n_paths"] * _coloured_steps(2.0, s["eps"]), lambda s: s["n_paths"]),
    "chaos": (lambda s: s["n_paths"] * s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
}

#: Measured cost coefficients ``{task: (s0, s1, b0, b1)}``: CPU seconds ``s0 + s1 · work`` and peak
#: memory above :data:`_BASE_BYTES`, ``b0 + b1 · held`` bytes (``work`` and ``held``: :data:`_GROWTH`).
#: Fitted through two in-process runs of every task, at ``--tiny`` and at ``--full`` (27 November 2026,
#: the project's 2-core machine at a load average of about 10; CPU time of the process, and ``VmHWM``
#: after resetting it before each task minus the resident memory before it); ``chaos`` through runs at
#: 300 x 40 and 1200 x 1000 (paths x steps). At the default sizes, which the fit did not use, the
#: total came out 7 % low in CPU time and 14 % low in peak memory (docs/main-job.md, section Cost).
_COST: dict = {
    "fig1": (1.87, 1.26e-06, 8.97e+07, 2.76),
    "fig2": (3.89, 1.09e-06, 2.46e+07, 3.74),
    "surf": (0.853, 0.0, 2.96e+07, 0.0),
    "surf2": (0.713, 0.0, 3.75e+07, 0.0),
    "surf3": (0.807, 0.0, 3.93e+07, 0.0),
    "surf4": (0.78, 0.0, 4.21e+07, 0.0),
    "surf5": (0.513, 0.0174, 4.08e+07, 0.0),
    "fig4": (1.41, 2.1e-06, 1.88e+07, 2.55),
    "fig5": (2.79, 0.0, 1.03e+07, 0.0),      # drawing only; its own coloured run costs fig4's s1, b1
    "chen": (0.00303, 4.13e-06, 0.0, 367.0),
    "levy_log": (0.014, 2.81e-06, 0.0, 336.0),
    "brownian_levy_area": (0.0191, 7.35e-06, 0.0, 1170.0),
    "friz_oberhauser": (0.169, 1.02e-05, 0.0, 417.0),
    "prop21": (0.0116, 1.46e-06, 0.0, 257.0),
    "forced_euler_poincare": (0.47, 0.0188, 5.33e+04, 15.9),
    "hamiltonian_reduction": (0.171, 0.00886, 0.0, 0.0),
    "casimir": (0.0033, 4.76e-07, 1.23e+04, 0.0),
    "gibbs_mean": (0.807, 7.17e-08, 7.55e+06, 0.0),
    "uniform_no_dissipation": (0.00605, 4.28e-07, 1.35e+06, 6590.0),
    "girsanov": (0.001, 0.0, 0.0, 0.0),
    "equilibria": (0.0979, 0.0, 1.05e+05, 0.0),
    "coloured_area_rate": (0.0101, 1.59e-06, 0.0, 451.0),
    "wong_zakai": (3.52, 5.96e-07, 8.0e+07, 3.57e+04),
    "planar_constant": (0.000496, 0.0, 0.0, 0.0),
    "chaos": (1.51, 8.17e-06, 4.45e+07, 146.0),
}
#: Resident memory of the process once every kind of figure and check has run (bytes: the end of a
#: ``--tiny`` run, 364 MiB), and the CPU time to start, import and write the report (seconds: a run of
#: ``planar_constant`` alone took 2.77 s), both measured with the coefficients.
_BASE_BYTES = 364.0 * 2**20
_BASE_SECONDS = 2.77
#: How well :func:`estimate_cost` predicted a run it was not fitted to (stated with every estimate).
ESTIMATE_ACCURACY = ("from costs measured at --tiny and --full on a busy 2-core machine; at the default sizes, "
                     "not used to fit them, it came out 7 % below the measured CPU time (single figures and checks "
                     "within a factor 2) and 14 % below the measured peak memory")


@dataclass(frozen=True)
class CostEstimate:
    """The estimated cost of a run (:func:`estimate_cost`).

    Attributes
    ----------
    seconds : float
        CPU time of the whole run (on one core of the machine the coefficients were measured on).
    peak_bytes : float
        Peak resident memory of the process.
    tasks : dict
        ``{task: (seconds, bytes)}``: each task's CPU time and its memory above the baseline.
    work : dict
        ``{task: units}``: each task's path-steps (the growth of its time).
    """

    seconds: float
    peak_bytes: float
    tasks: dict
    work: dict


def estimate_cost(sizes: dict, tasks) -> CostEstimate:
    """Estimate CPU time and peak memory of running ``tasks`` with ``sizes`` (from :func:`plan_sizes`).

    Each task costs ``s0 + s1 · work`` CPU seconds and ``b0 + b1 · held`` bytes above the baseline,
    with coefficients measured at ``--tiny`` and ``--full`` (:data:`_COST`); the peak is the baseline
    plus the largest task. ``fig5`` reuses ``fig4``'s coloured-noise run when both run with the same
    sizes.

    Parameters
    ----------
    sizes : dict
        ``{"TASK.WORD": value}`` covering every size of ``tasks``.
    tasks : iterable of str

    Returns
    -------
    CostEstimate

    Examples
    --------
    >>> small = estimate_cost(plan_sizes("default", ["chen"]), ["chen"])
    >>> big = estimate_cost(plan_sizes("default", ["chen"], settings={"chen.n_steps": 10**7}), ["chen"])
    >>> big.tasks["chen"][1] > 100 * small.tasks["chen"][1] > 0
    True
    """
    tasks = list(tasks)
    per, work = {}, {}
    for task in tasks:
        mine = {k.partition(".")[2]: v for k, v in sizes.items() if k.partition(".")[0] == task}
        s0, s1, b0, b1 = _COST.get(task, (0.0, 0.0, 0.0, 0.0))
        grows, held = _GROWTH.get(task, (lambda s: 0.0, lambda s: 0.0))
        w, h = float(grows(mine)), float(held(mine))
        if task == "fig5" and "fig4" in tasks and all(sizes[f"fig4.{k}"] == v for k, v in mine.items()):
            w = h = 0.0                          # the coloured run of fig4 is reused
        if task == "fig5" and w:                 # a run of its own: fig4's cost of the run
            s1, b1 = _COST["fig4"][1], _COST["fig4"][3]
        per[task] = (s0 + s1 * w, b0 + b1 * h)
        work[task] = w
    seconds = _BASE_SECONDS + sum(t for t, _ in per.values())
    peak = _BASE_BYTES + max((b for _, b in per.values()), default=0.0)
    return CostEstimate(seconds=seconds, peak_bytes=peak, tasks=per, work=work)
