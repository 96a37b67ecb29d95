r"""Davie (Taylor) schemes: the level-2 step :class:`Davie` and the level-3 step :class:`Davie3`.

A step is the truncated Taylor expansion of the flow in the step signature,
:math:`Y + \sum_{|w|\le N}\mathbf{X}^w_{s,t}V_w(Y)` with ``N = 2`` or ``3`` (``docs/conventions.md``)."""

from __future__ import annotations

from .._linalg import matvec, vecmat
from ._level3 import _Level3, _split_levels
from .base import Solver, _second_order

__all__ = ["Davie", "Davie3"]


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
    member_times = True
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


class Davie3(_Level3):
    r"""Third-order Davie-type (Taylor) step: :math:`Y + \sum_{1\le|w|\le3}\mathbf{X}^w_{s,t}V_w(Y)`.

    .. math:: Y' = Y + V_i x^i + (DV_j\cdot V_i)\,\mathbb{X}^{ij}
              + \big(D^2V_k[V_j, V_i] + DV_k\cdot DV_j\cdot V_i\big)\,\mathbb{X}^{ijk}

    with the full (not log) step signature. A drift is treated as in :class:`~roughpaths.Davie`
    (trapezoidal rule at the Euler predictor and the cross term :math:`\tfrac12 h x^i DV_i\cdot V_0`).

    Parameters
    ----------
    hessians : callable, optional
        As for :class:`LogODE3`.
    """

    order = 1.0
    smooth_order = 3.0

    def step(self, fields, y, t, dt, dX, dXX):
        XX, XXX = _split_levels(dXX, "Davie3")
        if getattr(fields, "is_linear", False):
            G = self._linear_generator(fields, dX, XX, XXX)
            noise_and_more = matvec(G, y)
            out = y + noise_and_more
            if fields.has_drift:
                A = fields.drift_matrix
                M1 = self._linear_products(fields)[0]
                e = fields.dim_state
                Mx = vecmat(dX, M1).reshape(dX.shape[:-1] + (e, e))
                f0 = matvec(A, y)
                f1 = matvec(A, y + f0 * dt + matvec(Mx, y))
                out = out + 0.5 * dt * (f0 + f1) + 0.5 * dt * matvec(Mx, f0)
            return out
        V = fields.fields(y)
        J = fields.jacobians(y)
        noise = (V @ dX[..., None])[..., 0]
        out = y + noise + _second_order(J, V, XX) + self._third(fields, y, V, J, XXX)
        if not fields.has_drift:
            return out
        f0 = fields.drift(y)
        f1 = fields.drift(y + f0 * dt + noise)
        cross = _second_order(J, f0[..., None], dX[..., None, :])
        return out + 0.5 * dt * (f0 + f1) + 0.5 * dt * cross
