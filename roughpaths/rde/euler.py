r"""Level-1 schemes: explicit Euler (Itô) and Stratonovich Heun.

They read only the increments :math:`X_{s,t}` of the driver (``increment_level = 1``), so they cannot
see the Lévy area: strong order ½ on Brownian motion with non-commuting fields."""

from __future__ import annotations

from .base import Solver, _drift_part

__all__ = ["Euler", "Heun"]


class Euler(Solver):
    r"""Explicit Euler, :math:`Y + V_0(Y)h + V_i(Y)X^i_{s,t}` (level 1).

    Order 1 on smooth drivers. On a Brownian driver it converges (strong order ½) to the **Itô**
    solution, whatever the area of the driver: it evaluates the fields at the left point only
    (time-dependent fields at the step's start time ``t``).
    """

    increment_level = 1
    member_times = True
    order = 0.5
    smooth_order = 1.0
    calculus = "ito"
    error_estimate = None        # order ½: a doubling difference measures the missing area, not the error

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
    member_times = True
    order = 0.5
    smooth_order = 2.0
    error_estimate = None        # order ½: a doubling difference measures the missing area, not the error

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
