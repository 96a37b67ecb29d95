r"""One-step RDE solvers for :func:`roughpaths.solve.solve`.

Each solver is a small class with two class attributes and one method:

* ``increment_level`` -- 1 if a step uses only the increment :math:`X_{s,t}`, 2 if it also uses the
  area :math:`\mathbb{X}_{s,t}` (a level-2 solver refuses a level-1 driver);
* ``order`` -- the declared **strong order on Brownian rough paths** (Stratonovich lift, non-commuting
  fields, mesh ``h``: the error is :math:`O(h^{\text{order}})` in :math:`L^2`);
  ``smooth_order`` -- the order on **smooth drivers** with exact increments (and areas);
* ``step(fields, y, t, dt, dX, dXX)`` -- one step from ``y`` (``(..., e)``) over ``[t, t + dt]`` with the
  increments ``dX`` (``(..., d)``) and areas ``dXX`` (``(..., d, d)``, ``None`` at level 1), vectorised
  over the batch (leading axes broadcast).

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
from math import factorial

import numpy as np

from .level2 import outer

__all__ = ["Solver", "Euler", "Heun", "Davie", "LogODE", "SOLVERS", "expm_batched"]


class Solver:
    """Base class: subclasses set ``increment_level``, ``order``, ``smooth_order`` and define ``step``."""

    increment_level: int = 1
    order: float = 0.0
    smooth_order: float = 0.0

    def step(self, fields, y, t, dt, dX, dXX):  # pragma: no cover - abstract
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and self.__dict__ == other.__dict__

    def __hash__(self) -> int:
        return hash(type(self))


def _drift_part(fields, y, dt):
    return fields.drift(y) * dt if fields.has_drift else 0.0


class Euler(Solver):
    r"""Explicit Euler, :math:`Y + V_0(Y)h + V_i(Y)X^i_{s,t}` (level 1).

    Order 1 on smooth drivers. On a Brownian driver it converges (strong order ½) to the **Itô**
    solution, whatever the area of the driver: it evaluates the fields at the left point only.
    """

    increment_level = 1
    order = 0.5
    smooth_order = 1.0

    def step(self, fields, y, t, dt, dX, dXX):
        V = fields.fields(y)
        return y + _drift_part(fields, y, dt) + (V @ dX[..., None])[..., 0]


class Heun(Solver):
    r"""Stratonovich Heun (trapezoidal predictor–corrector, level 1).

    :math:`\tilde Y = Y + V_0(Y)h + V(Y)X_{s,t}`,
    :math:`Y' = Y + \tfrac12(V_0(Y) + V_0(\tilde Y))h + \tfrac12(V(Y) + V(\tilde Y))X_{s,t}`.
    Order 2 on smooth drivers; strong order ½ towards the Stratonovich solution for non-commuting
    fields (it cannot see the Lévy area), order 1 for commuting fields.
    """

    increment_level = 1
    order = 0.5
    smooth_order = 2.0

    def step(self, fields, y, t, dt, dX, dXX):
        V = fields.fields(y)
        dx = dX[..., None]
        f0 = fields.drift(y) if fields.has_drift else None
        pred = y + (V @ dx)[..., 0]
        if f0 is not None:
            pred = pred + f0 * dt
        V2 = fields.fields(pred)
        out = y + 0.5 * ((V + V2) @ dx)[..., 0]
        if f0 is not None:
            out = out + 0.5 * dt * (f0 + fields.drift(pred))
        return out


class Davie(Solver):
    r"""Davie's scheme (level 2): :math:`Y + V_0 h + V_i X^i_{s,t} + (DV_j\cdot V_i)\,\mathbb{X}^{ij}_{s,t}`.

    With a drift, the time direction is treated as a path component so that the scheme stays of
    order 2 on smooth drivers: the drift is integrated by the trapezoidal rule at the Euler predictor
    :math:`\tilde Y = Y + V_0 h + V_i X^i` (this adds :math:`\tfrac12 h\,DV_0\cdot(V_0 h + V_i X^i)`),
    and the cross term :math:`\tfrac12 h\,X^i\,DV_i\cdot V_0` is added (the space–time area
    :math:`\int (r - s)\,dX^i` approximated by :math:`\tfrac12 h X^i`, exact to :math:`O(h^3)` on
    smooth paths and to a mean-zero :math:`O(h^{3/2})` on Brownian ones).

    Declared orders: strong order 1 on Brownian rough paths (Stratonovich lift with the Lévy area;
    with an Itô lift it solves the Itô equation), order 2 on smooth drivers with exact areas.
    """

    increment_level = 2
    order = 1.0
    smooth_order = 2.0

    def step(self, fields, y, t, dt, dX, dXX):
        if getattr(fields, "is_linear", False):
            return self._linear_step(fields, y, dt, dX, dXX)
        V = fields.fields(y)
        J = fields.jacobians(y)
        noise = (V @ dX[..., None])[..., 0]
        second = np.einsum("...jab,...bj->...a", J, V @ dXX)      # Σ_ij DV_j·V_i XX^{ij}
        if not fields.has_drift:
            return y + noise + second
        f0 = fields.drift(y)
        f1 = fields.drift(y + f0 * dt + noise)
        cross = np.einsum("...iab,...b,...i->...a", J, f0, dX)     # Σ_i X^i DV_i·V_0
        return y + 0.5 * dt * (f0 + f1) + noise + second + 0.5 * dt * cross

    @staticmethod
    def _linear_step(fields, y, dt, dX, dXX):
        # same formula for V_i(y) = M_i y, V_0(y) = A y: DV_j·V_i = M_j M_i y, DV_i·V_0 = M_i A y
        Mx, G2 = fields._linear_parts(dX, dXX)                     # Σ x^i M_i, Σ XX^{ij} M_j M_i
        noise = (Mx @ y[..., None])[..., 0]
        out = y + noise + (G2 @ y[..., None])[..., 0]
        A = fields.drift_matrix
        if fields.has_drift:
            f0 = y @ A.T
            f1 = (y + f0 * dt + noise) @ A.T
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

    * :class:`~roughpaths.vector_fields.LinearVectorFields` with a linear drift: the flow is exact,
      :math:`Y' = \exp(G) Y` with :math:`G = A_0 h + M_i x^i + \sum_{ij} L^{ij} M_j M_i`, computed by a
      batched scaling-and-squaring Padé exponential (:func:`expm_batched`).
    * otherwise: ``inner_steps`` classical RK4 steps of the autonomous ODE :math:`z' = W(z)` on ``[0, 1]``.

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

        def W(z):
            V = fields.fields(z)
            J = fields.jacobians(z)
            w = (V @ dX[..., None])[..., 0] + np.einsum("...jab,...bj->...a", J, V @ L)
            if fields.has_drift:
                w = w + fields.drift(z) * dt
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


#: Solver names accepted by :func:`~roughpaths.solve.solve` as strings (default instances).
SOLVERS = {"euler": Euler, "heun": Heun, "davie": Davie, "logode": LogODE}


# ---------------------------------------------------------------------- batched matrix exponential
_THETA = ((3, 1.495585217958292e-2), (5, 2.539398330063230e-1), (7, 9.504178996162932e-1),
          (9, 2.097847961257068e0), (13, 5.371920351148152e0))


def _pade_coefficients(m):
    return [factorial(2 * m - k) * factorial(m) / (factorial(2 * m) * factorial(k) * factorial(m - k))
            for k in range(m + 1)]


_PADE = {m: _pade_coefficients(m) for m, _ in _THETA}


def expm_batched(A) -> np.ndarray:
    r"""Matrix exponential of a batch ``A`` (shape ``(..., n, n)``), vectorised.

    Scaling and squaring with the diagonal Padé approximant of degree ``m ∈ {3, 5, 7, 9, 13}`` chosen
    from the largest 1-norm in the batch (Higham 2005 thresholds, backward error below the float64
    unit roundoff). One degree and one number of squarings serve the whole batch, so a batch of
    small matrices costs a handful of batched ``matmul`` calls and one batched ``solve``.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths.solvers import expm_batched
    >>> R = expm_batched(np.array([[0.0, -np.pi / 2], [np.pi / 2, 0.0]]))   # rotation by 90°
    >>> np.round(R, 12) + 0.0
    array([[ 0., -1.],
           [ 1.,  0.]])
    """
    A = np.asarray(A, dtype=np.float64)
    n = A.shape[-1]
    if A.size == 0:
        return np.broadcast_to(np.eye(n), A.shape).copy()
    norm = float(np.max(np.sum(np.abs(A), axis=-2)))
    if not np.isfinite(norm):
        return np.full(A.shape, np.nan)
    s = 0
    for m, theta in _THETA:
        if norm <= theta:
            break
    else:
        m = 13
        s = max(0, int(np.ceil(np.log2(norm / _THETA[-1][1]))))
        A = A / (2.0 ** s)
    b = _PADE[m]
    eye = np.broadcast_to(np.eye(n), A.shape)
    A2 = A @ A
    powers = [eye, A2]                                 # A^0, A^2, A^4, ...
    for _ in range(2, m // 2 + 1):
        powers.append(powers[-1] @ A2)
    Uin = sum(b[2 * k + 1] * powers[k] for k in range(m // 2 + 1))
    U = A @ Uin
    V = sum(b[2 * k] * powers[k] for k in range(m // 2 + 1))
    R = np.linalg.solve(V - U, V + U)
    for _ in range(s):
        R = R @ R
    return R
