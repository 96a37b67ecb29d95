r"""The one-step solver contract of :func:`roughpaths.solve` (:class:`Solver`) and the helpers the schemes share.

Each solver is a small class following the numbered contract of :class:`Solver` (what level of
increment a step consumes, its declared orders, its calculus, the invariants it preserves, and the
``step`` / ``integrate`` methods). The solvers below integrate
:class:`~roughpaths.VectorFields`; :mod:`mechanics` adds coadjoint solvers for
Lie–Poisson systems under the same contract, so that one :func:`roughpaths.solve` integrates both.

Conventions (``docs/conventions.md``): area :math:`\mathbb{X}^{ij} = \int (X^i - X^i_s)\,dX^j`, bracket
:math:`[V, W] = DW\cdot V - DV\cdot W`, Lévy area :math:`A = \tfrac12(\mathbb{X} - \mathbb{X}^T)`.

============  =====  ==============  ============  ==================================================
solver        level  order (BM, RP)  smooth order  note
============  =====  ==============  ============  ==================================================
``Euler``     1      1/2 (Itô)       1             on Brownian paths converges to the **Itô** solution
``Heun``      1      1/2             2             Stratonovich Heun; order 1 only for commuting fields
``Davie``     2      1               2             Milstein/Davie step with the area
``LogODE``    2      1               2             flow of the step's log-signature vector field
``Davie3``    3      1               3             third-order Taylor (Davie-type) step
``LogODE3``   3      1.5             3             flow of the level-3 log-signature field
============  =====  ==============  ============  ==================================================

One file per scheme family: :mod:`roughpaths.rde.euler` (``Euler``, ``Heun``),
:mod:`roughpaths.rde.davie` (``Davie``, ``Davie3``), :mod:`roughpaths.rde.logode` (``LogODE``,
``LogODE3``); the level-3 machinery they share is in ``roughpaths/rde/_level3.py``.
"""

from __future__ import annotations

import numpy as np


__all__ = ["Solver"]


class Solver:
    r"""Base class of the one-step solvers that :func:`roughpaths.solve` drives: the solver contract.

    A solver is a small object. :func:`~roughpaths.solve` relies on exactly the following, in this
    order (subclasses override what they need; the defaults serve vector-field RDEs):

    1. ``increment_level`` (class attribute, 1, 2 or 3): what a step consumes, the increment
       :math:`X_{s,t}` alone (1), also the area :math:`\mathbb{X}_{s,t}` (2), or also the level-3 step
       signature (3, :mod:`roughpaths.rde.logode`, :mod:`roughpaths.rde.davie`). ``check_driver``
       decides which driver levels a solver accepts: the schemes here refuse a driver of lower level
       (Davie on increments alone is not Davie); a level-1 solver never sees the areas of a level-2
       driver; the level-1/2 solvers refuse a level-3 driver (:class:`~roughpaths.RoughPathN`) rather
       than drop its level 3 silently. A solver that accepts a lower-level driver (the coadjoint
       solvers of :mod:`mechanics`: a level-1 driver means zero area) gets what the driver has:
       ``solve`` passes ``min(increment_level, driver.level)``.
    2. ``order`` and ``smooth_order`` (class attributes): the declared strong order on Brownian rough
       paths (Stratonovich lift, non-commuting fields) and the order on smooth drivers with exact
       increments and areas. Convergence tests fit these.
    3. ``calculus`` (class attribute): ``"stratonovich"`` if the scheme solves the geometric
       (Stratonovich) RDE on a geometric driver, ``"ito"`` if it converges to the Itô solution on
       Brownian motion whatever the area it is given (left-point evaluation, :class:`Euler`).
    4. ``preserves`` (class attribute, tuple of str): invariants kept to round-off by construction,
       e.g. ``("casimirs",)`` for coadjoint schemes; empty for the generic schemes.
    5. ``check_fields(fields)``: return the object to integrate, or raise ``TypeError`` naming what
       this solver accepts. The default accepts :class:`~roughpaths.VectorFields`.
    6. ``check_driver(driver)``: raise ``ValueError`` if the driver (a ``RoughPath``, ``RoughPathN`` or a
       :class:`~roughpaths.Driver`) cannot drive this scheme. The default checks the level.
    7. ``step(fields, y, t, dt, dX, dXX)``: one step from ``y`` (``(..., e)``) over ``[t, t + dt]``
       with the increments ``dX`` (``(..., d)``) and areas ``dXX`` (``(..., d, d)``, ``None`` for a
       level-1 solver; for a level-3 solver the tuple ``(XX, XXX)`` of the step's level-2 and level-3
       components, shapes ``(..., d, d)`` and ``(..., d, d, d)``), vectorised over the leading
       (broadcast) batch axes. Each batch member's result must depend on that member's data only
       (no reductions or shared scalings over the batch).
    8. ``integrate(fields, y, times, dX, dXX, save, stop_on_failure)``: advance a block of steps
       (``times`` of shape ``(K + 1,)``, ``dX`` ``(..., K, d)``, ``dXX`` ``(..., K, d, d)`` or ``None``,
       or for ``increment_level = 3`` the tuple ``(XX (..., K, d, d), XXX (..., K, d, d, d))``,
       ``save`` a boolean mask ``(K,)`` of the steps after which the state is kept). Returns
       ``(y, saved, first_bad)``: the final state, the kept states ``(..., save.sum(), e)`` and, per
       batch member, the index of the first step after which the member was non-finite (``-1`` if
       never). With ``stop_on_failure`` it may return as soon as a member fails. The default loops
       :meth:`step`; compiled fast paths override this method and must return what stepping returns.
    9. ``error_estimate`` (class attribute, declared data for adaptive steps,
       :mod:`roughpaths.rde.step_control`): ``"step_doubling"`` (the default: an attempt is one step over
       ``[t, t + h]`` and two over its halves on the same path, the difference estimating the local error) or
       ``None`` (the scheme offers no estimate a controller can trust; adaptive steps refuse it).
       ``error_order`` (default ``None``: the declared ``order``) is the strong order the estimate's error ratio
       follows, ``r ∝ h ** error_order``; step doubling needs an order of at least 1 and the area
       (``increment_level >= 2``), or its difference is dominated by the missing area instead of the error.
    10. ``member_times`` (class attribute, default ``False``): ``integrate`` also accepts ``times`` of shape
        ``(..., K + 1)`` with the batch axes of ``y``, each member on its own steps (adaptive steps per member);
        :meth:`step` then gets ``t`` and ``dt`` of shape ``(..., 1)``. ``solve`` uses it for fields that do not
        depend on time; otherwise it calls ``integrate`` once per group of members on the same steps.
    11. ``step_nbytes(fields)``: bytes of one step's temporaries per batch member, for the memory check of
        :func:`~roughpaths.solve`; ``None`` (the default) means the generic estimate in the state dimension
        ``e`` (Jacobians and matrix exponentials of ``e × e``). A solver whose steps never form ``e × e``
        arrays (the isospectral steps of :mod:`mechanics` on ``N × N`` matrices, ``e = N² - 1``) states its own.
    """

    increment_level: int = 1
    order: float = 0.0
    smooth_order: float = 0.0
    calculus: str = "stratonovich"
    preserves: tuple = ()
    error_estimate: str | None = "step_doubling"
    error_order: float | None = None
    member_times: bool = False

    def check_fields(self, fields):
        """Return ``fields`` if this solver can integrate it (contract item 5)."""
        from .vector_fields import VectorFields

        if not isinstance(fields, VectorFields):
            raise TypeError(f"fields: {self!r} integrates VectorFields objects (LinearVectorFields(M) or "
                            f"VectorFields(callables, ...)), got {type(fields).__name__}; a Lie–Poisson "
                            f"system needs a coadjoint solver (mechanics.LieEuler(), LieHeun(), "
                            f"ImplicitMidpoint()).")
        return fields

    def check_driver(self, driver) -> None:
        """Raise ``ValueError`` if ``driver`` cannot drive this scheme (contract item 6)."""
        if self.increment_level >= 2 and driver.level < 2:
            raise ValueError(f"{self!r} is a level-2 solver and needs the driver's area, but the driver is "
                             f"level 1 (no area); pass a level-2 RoughPath (e.g. a Brownian rough path with "
                             f"its Lévy area), or choose a level-1 solver (Heun(), Euler()) if dropping the "
                             f"area is intended.")
        if driver.level > 2 and self.increment_level < 3:
            raise ValueError(f"{self!r} uses the driver up to level {self.increment_level}, but the driver is a "
                             f"level-{driver.level} rough path (p >= 3, e.g. fBM with H <= 1/3), whose level 3 "
                             f"this scheme would drop; use a level-3 solver (LogODE3(), Davie3() from "
                             f"roughpaths), or pass driver.to_rough_path() (its level-2 truncation) if the path "
                             f"is p-rough with p < 3 and dropping level 3 is intended.")

    def step_nbytes(self, fields):
        """Bytes of one step's temporaries per batch member, or ``None`` for the generic estimate (contract item 11)."""
        return None

    def step(self, fields, y, t, dt, dX, dXX):  # pragma: no cover - abstract
        """One step (contract item 7)."""
        raise NotImplementedError(f"{type(self).__name__} does not define step()")

    def integrate(self, fields, y, times, dX, dXX, save, stop_on_failure=True):
        """Advance ``y`` over a block of steps (contract item 8) by calling :meth:`step` per step."""
        saved = np.empty(y.shape[:-1] + (int(np.count_nonzero(save)), y.shape[-1]))
        first_bad = np.full(y.shape[:-1], -1, dtype=np.int64)
        dts = times[..., 1:] - times[..., :-1]          # np.diff's arithmetic, without its overhead
        per = times.ndim > 1                            # contract item 10: each member its own times
        slot = 0
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for k in range(times.shape[-1] - 1):
                if dXX is None:
                    dxx = None
                elif isinstance(dXX, tuple):
                    dxx = tuple(a[(Ellipsis, k) + (slice(None),) * (a.ndim - dX.ndim + 1)] for a in dXX)
                else:
                    dxx = dXX[..., k, :, :]
                t, dt = (times[..., k, None], dts[..., k, None]) if per else (times[k], dts[k])
                y = self.step(fields, y, t, dt, dX[..., k, :], dxx)
                bad = ~np.all(np.isfinite(y), axis=-1)
                if bad.any():
                    first_bad[bad & (first_bad < 0)] = k
                    if stop_on_failure:
                        break
                if save[k]:
                    saved[..., slot, :] = y
                    slot += 1
        return y, saved, first_bad

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and self.__dict__ == other.__dict__

    def __hash__(self) -> int:
        return hash(type(self))


def _second_order(J, V, A):
    r""":math:`\sum_{i,j} A^{ij}\,DV_j\cdot V_i` from ``J`` (``(..., d, e, e)``), ``V`` (``(..., e, d)``), ``A`` (``(..., d, d)``).

    Summed over ``j`` in a fixed order with stacked mat-vec products, so every batch member gets the
    arithmetic it gets alone (an ``einsum`` over the batch may reorder its reduction by memory layout).
    """
    W = V @ A                                                       # [..., b, j] = Σ_i V_i^b A^{ij}
    acc = (J[..., 0, :, :] @ W[..., :, 0, None])[..., 0]
    for j in range(1, J.shape[-3]):
        acc = acc + (J[..., j, :, :] @ W[..., :, j, None])[..., 0]
    return acc


def _drift_part(fields, y, t, dt):
    return fields.drift(y, t) * dt if fields.has_drift else 0.0


def _unit_time_flow(W, y, n_steps):
    """``n_steps`` classical RK4 steps of the autonomous ODE ``z' = W(z)`` on ``[0, 1]`` from ``z = y``.

    The inner integrator of the log-ODE schemes (:class:`~roughpaths.LogODE`,
    :class:`~roughpaths.LogODE3`) for non-linear fields.
    """
    u = 1.0 / n_steps
    z = y
    for _ in range(n_steps):
        k1 = W(z)
        k2 = W(z + 0.5 * u * k1)
        k3 = W(z + 0.5 * u * k2)
        k4 = W(z + u * k3)
        z = z + (u / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return z
