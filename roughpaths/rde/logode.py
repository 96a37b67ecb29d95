r"""Log-ODE schemes: the flow of the step's log-signature vector field, at level 2 (:class:`LogODE`) and 3 (:class:`LogODE3`).

Linear fields take the exact flow (a batched matrix exponential); non-linear ones ``inner_steps`` RK4
steps of the autonomous ODE on ``[0, 1]``."""

from __future__ import annotations

import numbers

from .._linalg import expm_batched, matvec
from ..algebra.level2 import outer
from ._level3 import _Level3, _log3, _split_levels
from .base import Solver, _second_order, _unit_time_flow

__all__ = ["LogODE", "LogODE3"]


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
    member_times = True
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

        return _unit_time_flow(W, y, self.inner_steps)


class LogODE3(_Level3):
    r"""The log-ODE method at depth 3: the flow of the step's level-3 log-signature vector field.

    With :math:`\ell = \log \mathbf{X}_{s,t} = x + \ell_2 + \ell_3` (truncated at level 3), one step
    follows for unit time the flow of

    .. math:: W = V_0 h + \sum_i x^i V_i + \sum_{ij}\ell_2^{ij} V_{(i,j)} + \sum_{ijk}\ell_3^{ijk} V_{(i,j,k)},

    Since :math:`\ell` is a Lie element this is a bracket expansion: the level-2 part is
    :math:`\tfrac12\sum A^{ij}[V_i, V_j]` and the level-3 part a combination of the brackets of brackets
    :math:`[V_i, [V_j, V_k]]` (the Lyndon coordinates of :math:`\ell_3` times the brackets of their
    words); the :math:`D^2V` parts of the word operators cancel in that sum. They are still computed, so
    that a slightly non-geometric input is integrated consistently.

    * :class:`~roughpaths.LinearVectorFields` with a linear drift: exact flow
      :math:`Y' = \exp(G)Y`, :math:`G = A_0h + \sum x^iM_i + \sum\ell_2^{ij}M_jM_i + \sum\ell_3^{ijk}M_kM_jM_i`.
    * otherwise ``inner_steps`` RK4 steps of :math:`z' = W(z)` on ``[0, 1]``.

    Parameters
    ----------
    inner_steps : int
        RK4 sub-steps per step for non-linear fields (default 1).
    hessians : callable, optional
        ``y -> (..., d, e, e, e)``, :math:`\partial_b\partial_c V_k^a` at ``[..., k, a, b, c]``; central
        differences of the Jacobians if omitted.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import LinearVectorFields, LogODE3, fbm_rough_path, solve
    >>> V = LinearVectorFields(0.5 * np.random.default_rng(0).standard_normal((2, 3, 3)))
    >>> X = fbm_rough_path(32, 0.3, rng=1, substeps=16, level=3, batch_shape=(4,))
    >>> solve(V, X, np.ones(3), LogODE3()).final.shape
    (4, 3)
    """

    order = 1.5
    smooth_order = 3.0

    def __init__(self, inner_steps: int = 1, hessians=None):
        super().__init__(hessians)
        if isinstance(inner_steps, bool) or not isinstance(inner_steps, numbers.Integral) or inner_steps < 1:
            raise ValueError(f"inner_steps must be a positive integer, got {inner_steps!r}.")
        self.inner_steps = int(inner_steps)

    def __repr__(self) -> str:
        h = "" if self.hessians is None else ", hessians=..."
        return f"LogODE3(inner_steps={self.inner_steps}{h})"

    def step(self, fields, y, t, dt, dX, dXX):
        XX, XXX = _split_levels(dXX, "LogODE3")
        l2, l3 = _log3(dX, XX, XXX)
        if getattr(fields, "is_linear", False):
            G = self._linear_generator(fields, dX, l2, l3)
            if fields.has_drift:
                G = G + dt * fields.drift_matrix
            return matvec(expm_batched(G), y)

        def W(z):
            V = fields.fields(z)
            J = fields.jacobians(z)
            w = (V @ dX[..., None])[..., 0] + _second_order(J, V, l2) + self._third(fields, z, V, J, l3)
            if fields.has_drift:
                w = w + fields.drift(z) * dt
            return w

        return _unit_time_flow(W, y, self.inner_steps)
