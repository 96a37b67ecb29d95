r"""Linear vector fields :math:`V_i(y) = M_i y` with a linear (or general) drift: :class:`LinearVectorFields`.

A :class:`~roughpaths.VectorFields` family whose Jacobians and brackets are exact
(:math:`[V_i, V_j](y) = (M_j M_i - M_i M_j)\,y`, ``docs/conventions.md``) and whose step
generators the solvers use directly: :class:`~roughpaths.Davie` in closed form and
:class:`~roughpaths.LogODE` through an exact matrix exponential of
:math:`G = A_0 h + \sum_i x^i M_i + \sum_{ij} L^{ij} M_j M_i`.
"""

from __future__ import annotations

import numpy as np

from .._linalg import vecmat
from ..validation import as_float_array, check_antisymmetric
from .vector_fields import LinearDrift, VectorFields, _linear_part, _parse_drift

__all__ = ["LinearVectorFields"]


class LinearVectorFields(VectorFields):
    r"""Linear fields :math:`V_i(y) = M_i y` and an optional linear (or general) drift.

    Parameters
    ----------
    matrices : array_like, shape ``(d, e, e)``
        ``M_i`` (0-based ``i`` over the driving components).
    drift : array_like ``(e, e)``, LinearDrift, callable or None
        Drift matrix ``A`` (:math:`V_0(y) = A y`), or any drift accepted by :class:`VectorFields`
        (a non-linear drift makes the family non-linear: ``is_linear`` is then False).

    Notes
    -----
    Brackets are exact: :math:`[V_i, V_j](y) = (M_j M_i - M_i M_j) y`; the Friz–Oberhauser drift is
    the :class:`LinearDrift` with matrix :math:`\tfrac12\sum_{ij} s^{ij}(M_j M_i - M_i M_j)`.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import LinearVectorFields
    >>> M = np.array([[[0.0, 1.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]]])
    >>> V = LinearVectorFields(M)
    >>> V.bracket_matrices()[0, 1]          # M_1 M_0 - M_0 M_1
    array([[-1.,  0.],
           [ 0.,  1.]])
    >>> V.friz_oberhauser_drift(np.array([[0.0, 1.0], [-1.0, 0.0]])).matrix
    array([[-1.,  0.],
           [ 0.,  1.]])
    """

    def __init__(self, matrices, drift=None, *, drift_jacobian=None):
        M = as_float_array(matrices, "matrices", ndim=3)
        if M.shape[1] != M.shape[2] or M.size == 0:
            raise ValueError(f"matrices must have shape (d, e, e) with d, e >= 1, got {M.shape}; each M_i is square.")
        self.matrices = M
        self.dim_noise, self.dim_state = M.shape[0], M.shape[1]
        self._Mt = np.ascontiguousarray(np.transpose(M, (2, 0, 1)).reshape(M.shape[2], -1))  # (e, d*e)
        self._fields = self._linear_fields
        self._jac = self._linear_jac
        self._drift, self._drift_jac = _parse_drift(drift, drift_jacobian, self.dim_state)
        self._raw = (None, None, drift)
        self._check_shapes()

    @property
    def is_linear(self) -> bool:
        """True if the drift is absent or linear (then ``drift_matrix`` is the matrix)."""
        return self._drift is None or _linear_part(self._drift) is not None

    @property
    def drift_matrix(self) -> np.ndarray | None:
        """The drift matrix ``(e, e)`` (zeros if no drift), or None if the drift is not linear."""
        if self._drift is None:
            return np.zeros((self.dim_state, self.dim_state))
        lin = _linear_part(self._drift)
        return None if lin is None else lin.matrix

    def _linear_fields(self, t, y):
        y = np.asarray(y, dtype=np.float64)
        d, e = self.dim_noise, self.dim_state
        out = vecmat(y, self._Mt).reshape(y.shape[:-1] + (d, e))     # [..., i, a] = (M_i y)_a
        return np.swapaxes(out, -1, -2)

    def _linear_jac(self, t, y):
        y = np.asarray(y, dtype=np.float64)
        return np.broadcast_to(self.matrices, y.shape[:-1] + self.matrices.shape)

    def bracket_matrices(self) -> np.ndarray:
        r"""``C[i, j] = M_j M_i - M_i M_j`` (shape ``(d, d, e, e)``): :math:`[V_i, V_j](y) = C_{ij} y`."""
        M = self.matrices
        MjMi = np.einsum("jab,ibc->ijac", M, M)
        return MjMi - np.swapaxes(MjMi, 0, 1)

    def _linear_parts(self, dX, L):
        r"""``(Σ_i x^i M_i, Σ_ij L^{ij} M_j M_i)`` for a batch of steps, each of shape ``(..., e, e)``."""
        d, e = self.dim_noise, self.dim_state
        cache = getattr(self, "_gen_cache", None)
        if cache is None:
            M = self.matrices
            cache = (M.reshape(d, e * e), np.einsum("jab,ibc->ijac", M, M).reshape(d * d, e * e))
            self._gen_cache = cache
        Mflat, MMflat = cache
        Mx = vecmat(dX, Mflat).reshape(dX.shape[:-1] + (e, e))
        G2 = vecmat(L.reshape(L.shape[:-2] + (d * d,)), MMflat).reshape(L.shape[:-2] + (e, e))
        return Mx, G2

    def _logode_generator(self, dt, dX, L):
        r"""``G = A_0 h + Σ_i x^i M_i + Σ_ij L^{ij} M_j M_i`` for a batch of steps, shape ``(..., e, e)``."""
        Mx, G2 = self._linear_parts(dX, L)
        G = Mx + G2
        if self._drift is not None:
            G = G + np.asarray(dt)[..., None] * self.drift_matrix        # dt a scalar, or (..., 1) per member
        return G

    def friz_oberhauser_drift(self, s):
        s = check_antisymmetric(s, "s", dim=self.dim_noise)
        if s.ndim != 2:
            raise ValueError(f"s must have shape (d, d) = ({self.dim_noise}, {self.dim_noise}), got {s.shape}.")
        return LinearDrift(0.5 * np.einsum("ij,ijab->ab", s, self.bracket_matrices()))

    friz_oberhauser_drift.__doc__ = VectorFields.friz_oberhauser_drift.__doc__

    def with_drift(self, extra, jacobian=None) -> VectorFields:
        f, fj = _parse_drift(extra, jacobian, self.dim_state)
        if f is None:
            return self
        if _linear_part(f) is not None and self.is_linear:
            return LinearVectorFields(self.matrices, LinearDrift(self.drift_matrix + _linear_part(f).matrix))
        return self._add_drift_to(LinearVectorFields(self.matrices), f, fj)

    with_drift.__doc__ = VectorFields.with_drift.__doc__

    def __repr__(self) -> str:
        kind = "linear" if self.is_linear else "non-linear"
        return (f"LinearVectorFields(e={self.dim_state}, d={self.dim_noise}, "
                f"drift={'no' if self._drift is None else kind})")
