r"""One-step RDE solvers for :func:`roughpaths.solve`.

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
============  =====  ==============  ============  ==================================================
"""

from __future__ import annotations

import numbers

import numpy as np

from .._linalg import expm_batched, matvec
from ..algebra.level2 import outer

__all__ = ["Solver", "Euler", "Heun", "Davie", "LogODE", "SOLVERS"]


class Solver:
    r"""Base class of the one-step solvers that :func:`roughpaths.solve` drives: the solver contract.

    A solver is a small object. :func:`~roughpaths.solve` relies on exactly the following, in this
    order (subclasses override what they need; the defaults serve vector-field RDEs):

    1. ``increment_level`` (class attribute, 1, 2 or 3): what a step consumes, the increment
       :math:`X_{s,t}` alone (1), also the area :math:`\mathbb{X}_{s,t}` (2), or also the level-3 step
       signature (3, :mod:`roughpaths.rde.solvers_level3`). ``solve`` refuses a driver of lower level; a
       level-1 solver never sees the areas of a level-2 driver; the level-1/2 solvers here refuse a
       level-3 driver (:class:`~roughpaths.RoughPathN`) rather than drop its level 3 silently.
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
    """

    increment_level: int = 1
    order: float = 0.0
    smooth_order: float = 0.0
    calculus: str = "stratonovich"
    preserves: tuple = ()

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

    def step(self, fields, y, t, dt, dX, dXX):  # pragma: no cover - abstract
        """One step (contract item 7)."""
        raise NotImplementedError(f"{type(self).__name__} does not define step()")

    def integrate(self, fields, y, times, dX, dXX, save, stop_on_failure=True):
        """Advance ``y`` over a block of steps (contract item 8) by calling :meth:`step` per step."""
        n = times.shape[0] - 1
        saved = np.empty(y.shape[:-1] + (int(np.count_nonzero(save)), y.shape[-1]))
        first_bad = np.full(y.shape[:-1], -1, dtype=np.int64)
        dts = np.diff(times)
        slot = 0
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for k in range(n):
                if dXX is None:
                    dxx = None
                elif isinstance(dXX, tuple):
                    dxx = tuple(a[(Ellipsis, k) + (slice(None),) * (a.ndim - dX.ndim + 1)] for a in dXX)
                else:
                    dxx = dXX[..., k, :, :]
                y = self.step(fields, y, times[k], dts[k], dX[..., k, :], dxx)
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


class Euler(Solver):
    r"""Explicit Euler, :math:`Y + V_0(Y)h + V_i(Y)X^i_{s,t}` (level 1).

    Order 1 on smooth drivers. On a Brownian driver it converges (strong order ½) to the **Itô**
    solution, whatever the area of the driver: it evaluates the fields at the left point only
    (time-dependent fields at the step's start time ``t``).
    """

    increment_level = 1
    order = 0.5
    smooth_order = 1.0
    calculus = "ito"

    def step(self, fields, y, t, dt, dX, dXX):
        V = fields.fields(y, t)
        return y + _drift_part(fields, y, t, dt) + (V @ dX[..., None])[..., 0]


class Heun(Solver):
    r"""Stratonovich Heun (trapezoidal predictor–corrector, level 1).

    :math:`\tilde Y = Y + V_0(Y)h + V(Y)X_{s,t}`,
    :math:`Y' = Y + \tfrac12(V_0(Y) + V_0(\tilde Y))h + \tfrac12(V(Y) + V(\tilde Y))X_{s,t}`.
    Order 2 on smooth drivers; strong order ½ towards the Stratonovich solution for non-commuting
    fields (it cannot see the Lévy area), order 1 for commuting fields. Time-dependent fields are
    evaluated at ``t`` in the predictor and at ``t + h`` at the predicted point.
    """

    increment_level = 1
    order = 0.5
    smooth_order = 2.0

    def step(self, fields, y, t, dt, dX, dXX):
        V = fields.fields(y, t)
        dx = dX[..., None]
        f0 = fields.drift(y, t) if fields.has_drift else None
        pred = y + (V @ dx)[..., 0]
        if f0 is not None:
            pred = pred + f0 * dt
        V2 = fields.fields(pred, t + dt)
        out = y + 0.5 * ((V + V2) @ dx)[..., 0]
        if f0 is not None:
            out = out + 0.5 * dt * (f0 + fields.drift(pred, t + dt))
        return out


class Davie(Solver):
    r"""Davie's scheme (level 2): :math:`Y + V_0 h + V_i X^i_{s,t} + (DV_j\cdot V_i)\,\mathbb{X}^{ij}_{s,t}`.

    With a drift, the time direction is treated as a path component so that the scheme stays of
    order 2 on smooth drivers: the drift is integrated by the trapezoidal rule at the Euler predictor
    :math:`\tilde Y = Y + V_0 h + V_i X^i` (this adds :math:`\tfrac12 h\,DV_0\cdot(V_0 h + V_i X^i)`),
    and the cross term :math:`\tfrac12 h\,X^i\,DV_i\cdot V_0` is added (the space–time area
    :math:`\int (r - s)\,dX^i` approximated by :math:`\tfrac12 h X^i`, exact to :math:`O(h^3)` on
    smooth paths and to a mean-zero :math:`O(h^{3/2})` on Brownian ones).

    Time-dependent fields: the driving fields and their Jacobians are evaluated at the midpoint
    time :math:`t + h/2` (this contributes the :math:`\tfrac12 h\,\partial_t V_i\,X^i` term that keeps
    order 2 on smooth drivers), the drift at ``t`` and, at the predictor, at ``t + h``.

    Declared orders: strong order 1 on Brownian rough paths (Stratonovich lift with the Lévy area;
    with an Itô lift it solves the Itô equation), order 2 on smooth drivers with exact areas.
    """

    increment_level = 2
    order = 1.0
    smooth_order = 2.0

    def step(self, fields, y, t, dt, dX, dXX):
        if getattr(fields, "is_linear", False):
            return self._linear_step(fields, y, dt, dX, dXX)
        tm = t + 0.5 * dt
        V = fields.fields(y, tm)
        J = fields.jacobians(y, tm)
        noise = (V @ dX[..., None])[..., 0]
        second = _second_order(J, V, dXX)                          # Σ_ij DV_j·V_i XX^{ij}
        if not fields.has_drift:
            return y + noise + second
        f0 = fields.drift(y, t)
        f1 = fields.drift(y + f0 * dt + noise, t + dt)
        cross = _second_order(J, f0[..., None], dX[..., None, :])  # Σ_i X^i DV_i·V_0
        return y + 0.5 * dt * (f0 + f1) + noise + second + 0.5 * dt * cross

    @staticmethod
    def _linear_step(fields, y, dt, dX, dXX):
        # same formula for V_i(y) = M_i y, V_0(y) = A y: DV_j·V_i = M_j M_i y, DV_i·V_0 = M_i A y
        Mx, G2 = fields._linear_parts(dX, dXX)                     # Σ x^i M_i, Σ XX^{ij} M_j M_i
        noise = (Mx @ y[..., None])[..., 0]
        out = y + noise + (G2 @ y[..., None])[..., 0]
        A = fields.drift_matrix
        if fields.has_drift:
            f0 = matvec(A, y)
            f1 = matvec(A, y + f0 * dt + noise)
            out = out + 0.5 * dt * (f0 + f1) + 0.5 * dt * (Mx @ f0[..., None])[..., 0]
        return out


class LogODE(Solver):
    r"""The log-ODE method (level 2).

    Each step replaces the driver by its step log-signature :math:`(h, x, L)` with
    :math:`x = X_{s,t}` and :math:`L = \mathbb{X}_{s,t} - \tfrac12 x\otimes x` (for a geometric driver
    :math:`L = A`, the Lévy area with its ½), and follows for unit time the flow of the vector field

    .. math:: W = V_0 h + V_i x^i + \sum_{i,j} L^{ij}\,DV_j\cdot V_i
              \;\overset{L = A}{=}\; V_0 h + V_i x^i + \tfrac12\sum_{i,j} A^{ij}[V_i, V_j],

    with :math:`[V, W] = DW\cdot V - DV\cdot W`. (The symmetric part of ``L``, non-zero for an Itô lift,
    :math:`-\tfrac12 h I`, gives the Itô–Stratonovich correction.)

    * :class:`~roughpaths.LinearVectorFields` with a linear drift: the flow is exact,
      :math:`Y' = \exp(G) Y` with :math:`G = A_0 h + M_i x^i + \sum_{ij} L^{ij} M_j M_i`, computed by a
      batched scaling-and-squaring Padé exponential (:func:`expm_batched`).
    * otherwise: ``inner_steps`` classical RK4 steps of the autonomous ODE :math:`z' = W(z)` on ``[0, 1]``;
      time-dependent fields are frozen at the midpoint time :math:`t + h/2` of the step.

    Declared orders: strong order 1 on Brownian rough paths, order 2 on smooth drivers with exact
    areas (the level-3 terms of the step signature are :math:`O(h^3)` there).

    Parameters
    ----------
    inner_steps : int
        RK4 sub-steps per step for non-linear fields (default 1).
    """

    increment_level = 2
    order = 1.0
    smooth_order = 2.0

    def __init__(self, inner_steps: int = 1):
        if isinstance(inner_steps, bool) or not isinstance(inner_steps, numbers.Integral) or inner_steps < 1:
            raise ValueError(f"inner_steps must be a positive integer, got {inner_steps!r}.")
        self.inner_steps = int(inner_steps)

    def __repr__(self) -> str:
        return f"LogODE(inner_steps={self.inner_steps})"

    def step(self, fields, y, t, dt, dX, dXX):
        L = dXX - 0.5 * outer(dX, dX)
        if getattr(fields, "is_linear", False):
            G = fields._logode_generator(dt, dX, L)
            return (expm_batched(G) @ y[..., None])[..., 0]

        tm = t + 0.5 * dt

        def W(z):
            V = fields.fields(z, tm)
            J = fields.jacobians(z, tm)
            w = (V @ dX[..., None])[..., 0] + _second_order(J, V, L)
            if fields.has_drift:
                w = w + fields.drift(z, tm) * dt
            return w

        n = self.inner_steps
        u = 1.0 / n
        z = y
        for _ in range(n):
            k1 = W(z)
            k2 = W(z + 0.5 * u * k1)
            k3 = W(z + 0.5 * u * k2)
            k4 = W(z + u * k3)
            z = z + (u / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        return z


#: Solver names accepted by :func:`~roughpaths.solve` as strings (default instances).
SOLVERS = {"euler": Euler, "heun": Heun, "davie": Davie, "logode": LogODE}
