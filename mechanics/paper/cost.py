"""What a run of the main job costs: its estimated CPU time and peak memory.

Each figure and check costs ``s0 + s1 · work`` CPU seconds and ``b0 + b1 · held`` bytes above a
baseline, where ``work`` and ``held`` grow with its sizes (:data:`mechanics.paper.sizes.SIZES`) and the
coefficients were measured (``docs/main-job.md``, section Cost). :func:`estimate_cost` gives the
estimate the run prints before it starts, and that ``--list`` gives for each figure and check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["CostEstimate", "estimate_cost", "ESTIMATE_ACCURACY"]


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
    # beyond the rigid body (module matrix_algebras): su(3) and so(5); an orbit sample of the importance-sampling
    # oracle costs about four path-steps
    "matrix_prop21": (lambda s: s["n_paths"] * s["n_steps"], lambda s: s["n_paths"] * s["n_steps"]),
    "matrix_uniform": (lambda s: 240 * s["n_paths"], lambda s: s["n_paths"]),
    "matrix_gibbs": (lambda s: 2 * (s["n_paths"] * s["T"] / s["dt"] + 4 * s["n_samples"]), lambda s: s["n_samples"]),
    # beyond the paper: Euler on the sphere (O(N^3) per step; the stored states O(N^2) each)
    "sphere_euler": (lambda s: s["N"] ** 3 * s["n_steps"], lambda s: s["N"] ** 2),
    "sphere_casimirs": (lambda s: s["N"] ** 3 * s["n_steps"], lambda s: s["N"] ** 2 * s["n_steps"]),
    "sphere_friz_oberhauser": (lambda s: s["n_paths"], lambda s: s["n_paths"]),
    "sphere_convergence": (lambda s: s["n_ref"] ** 3, lambda s: s["n_ref"] ** 2),
    "sphere_strong_order": (lambda s: s["n_paths"], lambda s: s["n_paths"]),
    "sphere_levy_drift": (lambda s: s["n_paths"], lambda s: s["n_paths"]),
}

#: Measured cost coefficients ``{task: (s0, s1, b0, b1)}``: CPU seconds ``s0 + s1 · work`` and peak
#: memory above :data:`_BASE_BYTES`, ``b0 + b1 · held`` bytes (``work`` and ``held``: :data:`_GROWTH`).
#: Fitted through two in-process runs of every task, at ``--tiny`` and at ``--full`` (27 November 2026,
#: the project's 2-core machine at a load average of about 10; CPU time of the process, and ``VmHWM``
#: after resetting it before each task minus the resident memory before it); ``chaos`` through runs at
#: 300 x 40 and 1200 x 1000 (paths x steps); ``matrix_prop21``, ``matrix_uniform``, ``matrix_gibbs`` through
#: runs at ``--tiny`` and ``--full`` on 6 December 2026 (load 10-14; at the default sizes they took 2.1, 1.2 and
#: 2.2 s against estimates of 1.3, 1.3 and 2.1 s). At the default sizes, which the fit did not use, the
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
    "matrix_prop21": (0.531, 2.39e-04, 0.0, 1154.0),
    "matrix_uniform": (0.0724, 3.53e-06, 0.0, 3125.0),
    "matrix_gibbs": (0.05, 3.2e-06, 8.2e+06, 515.0),
    # beyond the paper: fitted through --tiny and --full runs of each (6 December 2026, load about 10, one BLAS
    # thread; sphere_strong_order's tiny point at 4 paths)
    "sphere_euler": (2.43, 1.08e-08, 7.16e+07, 8940.0),
    "sphere_casimirs": (0.094, 2.4e-08, 1.0e+06, 100.0),
    "sphere_friz_oberhauser": (0.084, 0.008, 0.0, 2.0e+05),
    "sphere_convergence": (0.19, 2.4e-07, 0.0, 1930.0),
    "sphere_strong_order": (0.44, 0.042, 5.0e+06, 0.0),
    "sphere_levy_drift": (0.0, 7.85e-05, 0.0, 4580.0),
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
    """Estimate CPU time and peak memory of running ``tasks`` with ``sizes`` (from :func:`~.sizes.plan_sizes`).

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
    >>> from mechanics.paper.sizes import plan_sizes
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
