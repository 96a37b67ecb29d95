"""Registry of the paper's theorem / proposition checks run by the main job.

Each check is a function ``check(ctx) -> CheckResult`` (see :class:`mechanics.report.CheckResult`)
that computes a *predicted* number from the theory (closed form, quadrature) and a *measured* one
from a simulation or an independent computation with the library, compares them with a stated
tolerance, and says pass or fail. Sizes come from ``ctx.size(...)`` (``tiny`` / ``default`` /
``full``); at default sizes all checks and figures finish in under 5 minutes on 2 cores.

The mathematics lives in :mod:`roughpaths` and :mod:`mechanics`; this module only calls it.
Conventions: ``CONVENTIONS.md`` (area ``XX[i,j] = ∫(X^i - X^i_s) dX^j``, Lévy area ``½(XX - XXᵀ)``,
bracket ``[V,W] = DW·V - DV·W``, Friz–Oberhauser drift ``½ Σ s^{ij}[V_i,V_j]``).
"""

from __future__ import annotations

import numpy as np

from .report import CheckResult, Task

__all__ = ["CHECKS", "register"]

#: name -> Task, in report order
CHECKS: dict[str, Task] = {}


def register(name: str, title: str, requires: tuple = ()):
    """Decorator adding a check to :data:`CHECKS`."""

    def deco(func):
        CHECKS[name] = Task(name=name, title=title, func=func, requires=tuple(requires))
        return func

    return deco


# --------------------------------------------------------------------------------------------- rough paths
@register("chen", "Chen's identity for level-2 rough paths", requires=("roughpaths.rough_path",))
def check_chen(ctx) -> CheckResult:
    """Chen: XX_{0,T} = XX_{0,u} + XX_{u,T} + X_{0,u}⊗X_{u,T}, and = the naive sum over the steps."""
    rng = ctx.rng("chen")
    n = ctx.size("chen.steps", tiny=200, default=10_000, full=100_000)
    batch = ctx.size("chen.paths", tiny=4, default=64, full=256)
    X = _brownian(rng, batch, n, 3)
    t = X.times
    T0, u, T = t[0], t[n // 3], t[-1]
    whole = X.area(T0, T)
    split = X.area(T0, u) + X.area(u, T) + np.einsum("...i,...j->...ij", X.increment(T0, u), X.increment(u, T))
    # independent oracle: the iterated sum over the per-step (increment, area) pairs
    inc, steps = X.increments, X.areas
    before = np.cumsum(inc, axis=-2) - inc                       # X_{t_0, t_k}
    naive = steps.sum(axis=-3) + np.einsum("...ki,...kj->...ij", before, inc)
    e_split = float(np.max(np.abs(whole - split)))
    e_naive = float(np.max(np.abs(whole - naive)))
    # the classic slip: the cross term transposed (X_{u,T} ⊗ X_{0,u}) must be detected
    wrong = X.area(T0, u) + X.area(u, T) + np.einsum("...i,...j->...ij", X.increment(u, T), X.increment(T0, u))
    e_wrong = float(np.max(np.abs(whole - wrong)))
    measured = max(e_split, e_naive)
    tol = 1e-10
    return CheckResult(
        "chen",
        "Chen's identity XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t} on Brownian rough paths, and "
        "XX_{0,T} = the iterated sum over the grid steps (CONVENTIONS.md ordering XX[i,j] = ∫(X^i-X^i_s)dX^j).",
        predicted=0.0, measured=measured,
        tolerance=f"max abs defect <= {tol:g}; transposed cross term differs by O(1)",
        passed=measured <= tol and e_wrong > 1e-3,
        details=f"{batch} paths x {n} steps, d = 3; split defect {e_split:.3g}, naive-sum defect "
                f"{e_naive:.3g}; with the cross term transposed: {e_wrong:.3g}",
    )


@register("levy_log", "Level-2 log of a geometric path is its Lévy area ½(XX − XXᵀ)",
          requires=("roughpaths.rough_path", "roughpaths.level2"))
def check_levy_log(ctx) -> CheckResult:
    """log(X, XX) at level 2 is XX − ½ X⊗X = Alt(XX) for geometric paths (CONVENTIONS.md)."""
    from roughpaths.level2 import level2_log

    rng = ctx.rng("levy_log")
    n = ctx.size("levy_log.steps", tiny=100, default=2_000, full=20_000)
    X = _brownian(rng, 32, n, 3)
    x, xx = X.increment(X.times[0], X.times[-1]), X.area(X.times[0], X.times[-1])
    out = level2_log(x, xx)
    log2 = out[1] if isinstance(out, tuple) else out
    levy = X.levy_area(X.times[0], X.times[-1])
    err = float(np.max(np.abs(log2 - levy)))
    wrong = float(np.max(np.abs(log2 - 2.0 * levy)))  # the paper's (LevyArea) without the ½
    tol = 1e-12
    return CheckResult(
        "levy_log",
        "For a geometric level-2 path, the level-2 log-signature XX − ½X⊗X equals the Lévy area "
        "½(XX − XXᵀ) (the paper's eq. (LevyArea) omits the ½; the variant without it must differ).",
        predicted=0.0, measured=err, tolerance=f"max abs difference <= {tol:g}; without ½: differs by O(1)",
        passed=err <= tol and wrong > 1e-3,
        details=f"without the ½ the difference is {wrong:.3g}",
    )


# --------------------------------------------------------------------------------------------- helpers
def _brownian(rng, batch: int, n: int, d: int, T: float = 1.0):
    """A batch of Stratonovich Brownian rough paths on [0, T] (library sampler if present)."""
    times = np.linspace(0.0, T, n + 1)
    try:
        from roughpaths.brownian import brownian_rough_path
    except ImportError:
        brownian_rough_path = None
    if brownian_rough_path is not None:
        return _call_brownian(brownian_rough_path, times, d, batch, rng)
    from roughpaths.rough_path import RoughPath

    dw = rng.standard_normal((batch, n, d)) * np.sqrt(T / n)
    w = np.concatenate([np.zeros((batch, 1, d)), np.cumsum(dw, axis=1)], axis=1)
    return RoughPath.from_path(w, times=times)


def _call_brownian(func, times, d, batch, rng):
    return func(times, d, batch=(batch,), rng=rng)
