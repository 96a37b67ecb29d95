r"""What the level-3 solvers share (private): step signatures of rough paths with :math:`p\in[3, 4)`.

They follow the contract of :class:`roughpaths.Solver` with ``increment_level = 3``:
:func:`roughpaths.solve` passes each step's level-2 and level-3 components as the tuple
``dXX = (XX, XXX)``, of shapes ``(..., d, d)`` and ``(..., d, d, d)`` (word ``(i, j, k)`` at
``XXX[..., i, j, k]``), from a :class:`~roughpaths.RoughPathN` driver of level >= 3.

The differential operators of words (``docs/conventions.md``): a word :math:`w = (i_1,\dots,i_k)` acts
on the identity as :math:`V_w = V_{i_1}(V_{i_2}(\cdots V_{i_k}))` with :math:`V_i f = Df\cdot V_i`, i.e.

.. math::
    V_{(i,j)} = DV_j\cdot V_i, \qquad
    V_{(i,j,k)} = D^2V_k[V_j, V_i] + DV_k\cdot DV_j\cdot V_i ,

and the Taylor expansion of the flow over a step is :math:`Y + \sum_{|w|\le 3}\mathbf{X}^w V_w(Y)`.

Second derivatives :math:`D^2V_k` come from ``hessians`` if given (``y -> (..., d, e, e, e)`` with
``[..., k, a, b, c] =`` :math:`\partial_b\partial_c V_k^a`), else from central differences of the
Jacobians along the fields, :math:`D(DV_k)[V_i] \approx (J_k(y + \varepsilon V_i) - J_k(y - \varepsilon V_i))/2\varepsilon`
(``2d`` extra Jacobian evaluations per step, relative accuracy about ``1e-10`` for smooth fields);
they vanish for :class:`~roughpaths.LinearVectorFields`, where every term is a matrix product.

============  =====  ========================  ============  ======================================
solver        level  order (BM; fBM H<1/2)     smooth order  note
============  =====  ========================  ============  ======================================
``LogODE3``   3      1.5; 4H - 1/2 (measured)  3             flow of the level-3 log-signature field
``Davie3``    3      1; 4H - 1                 3             third-order Taylor (Davie-type) step
============  =====  ========================  ============  ======================================

Why the two differ on random drivers: a step's error is, to leading order, the level-4 part the scheme
leaves out. For the log-ODE method that is the level-4 **log**-signature, whose mean vanishes for
Brownian and fractional Brownian motion (their increments are reversible in law, and reversal maps the
log-signature ``ℓ`` to ``−ℓ``), so the step errors cancel like a sum of centred terms: rate
``(N+1)H − 1/2``, i.e. 1.5 for Brownian motion. For the Taylor step it is the level-4 **signature**, whose
even words have non-zero mean (``E[X^4]/24`` for ``d = 1``: the scalar ``dY = Y∘dW`` already loses
``h²/8`` per step in ``log Y``), which adds up coherently: rate ``4H − 1``, i.e. 1 for Brownian motion.
That is the pathwise rate ``(N+1)/p − 1`` of a step-``N`` scheme with exact step signatures
(Friz–Victoir, Thm 10.30, ``N = 3``, ``p`` just above ``1/H``), which both schemes satisfy. Measured
rates are in ``tests/roughpaths/rde/test_rough_strong_rates.py`` (pre-asymptotically Davie3 fits 0.15–0.25 above
``4H − 1``). With a drift the space–time iterated integrals are approximated (as in
:class:`~roughpaths.Davie`), which limits the smooth order to 2.
"""

from __future__ import annotations

import numpy as np

from .._linalg import vecmat
from .base import Solver, _second_order
from .vector_fields import FD_STEP

def _split_levels(dXX, name):
    if not (isinstance(dXX, tuple) and len(dXX) == 2):
        raise TypeError(f"{name} is a level-3 solver: dXX must be the tuple (XX, XXX) of the step's level-2 "
                        f"and level-3 components (roughpaths.solve passes it from a RoughPathN of level >= 3), "
                        f"got {type(dXX).__name__}.")
    return dXX


def _log3(x, XX, XXX):
    r"""Levels 2 and 3 of :math:`\log(1 + x + XX + XXX)`."""
    xx = x[..., :, None] * x[..., None, :]
    l2 = XX - 0.5 * xx
    l3 = (XXX - 0.5 * (x[..., :, None, None] * XX[..., None, :, :] + XX[..., :, :, None] * x[..., None, None, :])
          + (1.0 / 3.0) * xx[..., :, :, None] * x[..., None, None, :])
    return l2, l3


class _Level3(Solver):
    increment_level = 3

    def __init__(self, hessians=None):
        if hessians is not None and not callable(hessians):
            raise TypeError(f"hessians must be a callable y (..., e) -> (..., d, e, e, e) with [..., k, a, b, c] = "
                            f"d_b d_c V_k^a, or None for central differences; got {type(hessians).__name__}.")
        self.hessians = hessians

    def __repr__(self) -> str:
        return f"{type(self).__name__}()" if self.hessians is None else f"{type(self).__name__}(hessians=...)"

    def check_driver(self, driver) -> None:
        """Require a driver of level >= 3 (contract item 6)."""
        if driver.level < 3:
            raise ValueError(f"{self!r} is a level-3 solver and needs the driver's level-3 step signatures, but "
                             f"the driver is level {driver.level}. Lift a fine sample with "
                             f"roughpaths.piecewise_linear_lift(values, m, level=3) or fbm_rough_path(..., level=3), "
                             f"or extend a geometric level-2 path with RoughPathN.from_rough_path(X, 3) (exact only "
                             f"when p < 3); or use a level-2 solver (Davie(), LogODE()) on a level-2 path.")

    # ---------------------------------------------------------------- word operators
    def _third(self, fields, y, V, J, c):
        r""":math:`\sum_{ijk} c^{ijk} V_{(i,j,k)}(y)` for non-linear fields, shape ``(..., e)``."""
        d = J.shape[-3]
        # DV_k · (Σ_ij c^{ijk} DV_j·V_i), summed over k in a fixed order
        acc = None
        for k in range(d):
            u = _second_order(J, V, c[..., :, :, k])
            term = (J[..., k, :, :] @ u[..., None])[..., 0]
            acc = term if acc is None else acc + term
        # Σ_k Σ_ij c^{ijk} D²V_k[V_j, V_i]
        if self.hessians is not None:
            Hs = np.asarray(self.hessians(y), dtype=np.float64)             # [..., k, a, b, c]
            e = y.shape[-1]
            if Hs.shape[-4:] != (d, e, e, e) or Hs.shape[:-4] not in ((), y.shape[:-1]):
                raise ValueError(f"hessians(y) must return shape (..., d, e, e, e) = {y.shape[:-1] + (d, e, e, e)} "
                                 f"with [..., k, a, b, c] = d_b d_c V_k^a, got {Hs.shape}; fix the callable "
                                 f"or pass hessians=None for central differences.")
            for i in range(d):
                for k in range(d):
                    w = (V @ c[..., i, :, k, None])[..., 0]                   # Σ_j c^{ijk} V_j
                    acc = acc + np.einsum("...abc,...b,...c->...a", Hs[..., k, :, :, :], w, V[..., :, i])
            return acc
        scale = 1.0 + np.max(np.abs(y), axis=-1, keepdims=True)
        for i in range(d):
            vi = V[..., :, i]
            size = np.max(np.abs(vi), axis=-1, keepdims=True)
            eps = FD_STEP * scale / np.where(size > 0, size, 1.0)
            Jp = fields.jacobians(y + eps * vi)
            Jm = fields.jacobians(y - eps * vi)
            for k in range(d):
                G = (Jp[..., k, :, :] - Jm[..., k, :, :]) / (2.0 * eps[..., None])   # D(DV_k)[V_i]
                w = (V @ c[..., i, :, k, None])[..., 0]
                acc = acc + (G @ w[..., None])[..., 0]
        return acc

    @staticmethod
    def _linear_products(fields):
        cache = getattr(fields, "_level3_products", None)
        if cache is None:
            M = fields.matrices
            d, e = M.shape[0], M.shape[1]
            M1 = M.reshape(d, e * e)
            M2 = np.einsum("jab,ibc->ijac", M, M)                              # [i, j] = M_j M_i
            M3 = np.einsum("kab,ijbc->ijkac", M, M2)                           # [i, j, k] = M_k M_j M_i
            cache = (M1, M2.reshape(d * d, e * e), M3.reshape(d ** 3, e * e))
            try:
                fields._level3_products = cache
            except AttributeError:  # pragma: no cover - slotted fields
                pass
        return cache

    @classmethod
    def _linear_generator(cls, fields, x, c2, c3):
        r""":math:`\sum_i x^i M_i + \sum c_2^{ij} M_jM_i + \sum c_3^{ijk} M_kM_jM_i`, shape ``(..., e, e)``."""
        M1, M2, M3 = cls._linear_products(fields)
        e = fields.dim_state
        d = x.shape[-1]
        G = vecmat(x, M1) + vecmat(c2.reshape(c2.shape[:-2] + (d * d,)), M2) \
            + vecmat(c3.reshape(c3.shape[:-3] + (d ** 3,)), M3)
        return G.reshape(G.shape[:-1] + (e, e))
