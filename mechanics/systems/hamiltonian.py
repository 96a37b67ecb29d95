r"""Hamiltonians on :math:`\mathfrak g^*` and the one inertia check.

:class:`Hamiltonian` (value, gradient, optional Hessian), :class:`QuadraticHamiltonian`
(:math:`\tfrac12\mu\cdot Q\mu + b\cdot\mu`; compiled kernels recognise it) and :func:`check_inertia`,
the only validation of inertia tensors and metrics in :mod:`mechanics`.
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array

__all__ = ["Hamiltonian", "QuadraticHamiltonian", "check_inertia"]


def check_inertia(inertia, name: str = "inertia", *, dim: int | None = None) -> np.ndarray:
    """Check a symmetric positive-definite ``(n, n)`` inertia tensor (a vector means ``diag``)."""
    arr = as_float_array(inertia, name)
    if arr.ndim == 1:
        arr = np.diag(arr)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        raise ValueError(f"{name} must be a square (n, n) matrix or a vector of principal moments, "
                         f"got shape {arr.shape}.")
    if dim is not None and arr.shape[0] != dim:
        raise ValueError(f"{name} must be {dim}x{dim} for this Lie algebra, got shape {arr.shape}.")
    scale = max(1.0, float(np.max(np.abs(arr))))
    asym = float(np.max(np.abs(arr - arr.T)))
    if asym > 1e-12 * scale:
        raise ValueError(f"{name} must be symmetric; {name} - {name}.T has entries up to {asym:.3g}. "
                         f"Pass 0.5 * ({name} + {name}.T) if the asymmetry is round-off.")
    eig = np.linalg.eigvalsh(0.5 * (arr + arr.T))
    if eig[0] <= 0:
        raise ValueError(f"{name} must be positive definite, but its smallest eigenvalue is "
                         f"{eig[0]:.6g} (eigenvalues {np.array2string(eig, precision=4)}); principal "
                         f"moments of inertia are strictly positive.")
    if not eig[0] > 1e-12 * eig[-1]:
        raise ValueError(f"{name} is too ill-conditioned to invert in float64 (eigenvalues "
                         f"{np.array2string(eig, precision=4)}, smallest/largest < 1e-12); rescale the moments "
                         f"(e.g. to units where the largest is 1) or drop the degenerate axis.")
    return 0.5 * (arr + arr.T)


class Hamiltonian:
    r"""A Hamiltonian :math:`h:\mathfrak g^*\to\mathbb R` with its gradient (and optionally Hessian).

    Parameters
    ----------
    value : callable
        ``mu (..., n) -> (...)``.
    gradient : callable
        ``mu (..., n) -> (..., n)``: :math:`\partial h/\partial\mu\in\mathfrak g`.
    hessian : callable, optional
        ``mu (..., n) -> (..., n, n)``. Default: central finite differences of ``gradient`` (only
        used by the implicit midpoint's chord Jacobian and by :meth:`LiePoissonSystem.drift_jacobian`).
    """

    def __init__(self, value, gradient, hessian=None):
        if not callable(value) or not callable(gradient):
            raise TypeError("Hamiltonian needs callables value(mu) and gradient(mu); got "
                            f"{type(value).__name__} and {type(gradient).__name__}.")
        if hessian is not None and not callable(hessian):
            raise TypeError(f"hessian must be callable or None, got {type(hessian).__name__}.")
        self._value, self._gradient, self._hessian = value, gradient, hessian

    def value(self, mu):
        """:math:`h(\\mu)`, shape ``(...)``."""
        return np.asarray(self._value(mu), dtype=np.float64)

    def gradient(self, mu):
        """:math:`\\partial h/\\partial\\mu`, shape ``(..., n)``."""
        return np.asarray(self._gradient(mu), dtype=np.float64)

    def hessian(self, mu):
        """:math:`\\partial^2 h/\\partial\\mu^2`, shape ``(..., n, n)``."""
        if self._hessian is not None:
            return np.asarray(self._hessian(mu), dtype=np.float64)
        mu = np.asarray(mu, dtype=np.float64)
        n = mu.shape[-1]
        eps = 1e-6 * np.maximum(1.0, np.abs(mu))
        cols = []
        for k in range(n):
            e = np.zeros(n)
            e[k] = 1.0
            step = eps[..., k:k + 1] * e
            cols.append((self.gradient(mu + step) - self.gradient(mu - step)) / (2.0 * eps[..., k:k + 1]))
        return np.stack(cols, axis=-1)

    @property
    def is_quadratic(self) -> bool:
        return False


class QuadraticHamiltonian(Hamiltonian):
    r""":math:`h(\mu) = \tfrac12\mu\cdot Q\mu + b\cdot\mu` with symmetric ``Q`` (``(n, n)``) and ``b`` (``(n,)``).

    Use :meth:`from_inertia` for :math:`h = \tfrac12\mu\cdot\mathbb I^{-1}\mu` (symmetric positive
    definite inertia checked).
    """

    def __init__(self, q, linear=None):
        q = as_float_array(q, "q", ndim=2)
        if q.shape[0] != q.shape[1]:
            raise ValueError(f"q must be square, got shape {q.shape}.")
        if float(np.max(np.abs(q - q.T))) > 1e-12 * max(1.0, float(np.max(np.abs(q)))):
            raise ValueError("q must be symmetric; pass 0.5 * (q + q.T).")
        n = q.shape[0]
        b = np.zeros(n) if linear is None else as_float_array(linear, "linear", ndim=1)
        if b.shape != (n,):
            raise ValueError(f"linear must have shape ({n},), got {b.shape}.")
        self.q, self.linear = q, b
        super().__init__(self._val, self._grad, self._hess)

    @classmethod
    def from_inertia(cls, inertia, linear=None) -> "QuadraticHamiltonian":
        """:math:`h = \\tfrac12\\mu\\cdot\\mathbb I^{-1}\\mu (+ b\\cdot\\mu)`; ``inertia`` symmetric positive definite."""
        i = check_inertia(inertia)
        return cls(np.linalg.inv(i), linear)

    def _val(self, mu):
        return 0.5 * np.einsum("...i,ij,...j->...", mu, self.q, mu) + mu @ self.linear

    def _grad(self, mu):
        # stacked mat-vec, not (B, n) @ (n, n): a batch member's gradient must not depend on the batch
        return (self.q.T @ np.asarray(mu, dtype=np.float64)[..., None])[..., 0] + self.linear

    def _hess(self, mu):
        return np.broadcast_to(self.q, np.shape(mu)[:-1] + self.q.shape)

    @property
    def is_quadratic(self) -> bool:
        return True
