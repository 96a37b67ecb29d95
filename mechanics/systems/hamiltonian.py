r"""Hamiltonians on :math:`\mathfrak g^*` and the one inertia check.

:class:`Hamiltonian` (value, gradient, optional Hessian), :class:`QuadraticHamiltonian`
(:math:`\tfrac12\mu\cdot Q\mu + b\cdot\mu`; compiled kernels recognise it) and :func:`check_inertia`,
the only validation of inertia tensors and metrics in :mod:`mechanics`.
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array, check_memory

__all__ = ["Hamiltonian", "QuadraticHamiltonian", "MatrixHamiltonian", "check_inertia"]


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

    A vector ``q`` (shape ``(n,)``) means the diagonal :math:`Q = \mathrm{diag}(q)`, held as the vector: the
    gradient costs ``O(n)`` and nothing of size ``n²`` is formed (the large matrix algebras,
    :func:`mechanics.su`, need this). Use :meth:`from_inertia` for :math:`h = \tfrac12\mu\cdot\mathbb I^{-1}\mu`
    (symmetric positive definite inertia checked).
    """

    def __init__(self, q, linear=None):
        q = as_float_array(q, "q")
        if q.ndim == 1:
            self.q_diagonal = q
            n = q.shape[0]
        elif q.ndim == 2 and q.shape[0] == q.shape[1]:
            if float(np.max(np.abs(q - q.T))) > 1e-12 * max(1.0, float(np.max(np.abs(q)))):
                raise ValueError("q must be symmetric; pass 0.5 * (q + q.T).")
            self.q_diagonal = None
            n = q.shape[0]
        else:
            raise ValueError(f"q must be a square (n, n) matrix or a vector (n,) (the diagonal), got shape {q.shape}.")
        b = np.zeros(n) if linear is None else as_float_array(linear, "linear", ndim=1)
        if b.shape != (n,):
            raise ValueError(f"linear must have shape ({n},), got {b.shape}.")
        self._q = None if q.ndim == 1 else q
        self.linear = b
        super().__init__(self._val, self._grad, self._hess)

    @property
    def q(self) -> np.ndarray:
        """The matrix ``Q``, shape ``(n, n)`` (formed on first use when ``Q`` was given as its diagonal)."""
        if self._q is None:
            n = self.q_diagonal.shape[0]
            check_memory(8.0 * n * n, f"the {n}x{n} matrix of a diagonal quadratic Hamiltonian",
                         "use q_diagonal, or a solver that does not need the matrix")
            self._q = np.diag(self.q_diagonal)
        return self._q

    @classmethod
    def from_inertia(cls, inertia, linear=None) -> "QuadraticHamiltonian":
        """:math:`h = \\tfrac12\\mu\\cdot\\mathbb I^{-1}\\mu (+ b\\cdot\\mu)`; ``inertia`` symmetric positive definite."""
        i = check_inertia(inertia)
        return cls(np.linalg.inv(i), linear)

    def _val(self, mu):
        if self.q_diagonal is not None:
            return 0.5 * np.einsum("...i,i,...i->...", mu, self.q_diagonal, mu) + mu @ self.linear
        return 0.5 * np.einsum("...i,ij,...j->...", mu, self.q, mu) + mu @ self.linear

    def _grad(self, mu):
        if self.q_diagonal is not None:
            return self.q_diagonal * np.asarray(mu, dtype=np.float64) + self.linear
        # stacked mat-vec, not (B, n) @ (n, n): a batch member's gradient must not depend on the batch
        return (self.q.T @ np.asarray(mu, dtype=np.float64)[..., None])[..., 0] + self.linear

    def _hess(self, mu):
        return np.broadcast_to(self.q, np.shape(mu)[:-1] + self.q.shape)

    @property
    def is_quadratic(self) -> bool:
        return True


class MatrixHamiltonian(Hamiltonian):
    r"""A Hamiltonian on the dual of a :class:`~mechanics.systems.matrix_algebra.MatrixLieAlgebra`, given on matrices.

    Parameters
    ----------
    algebra : MatrixLieAlgebra
    value_matrix : callable
        ``M (..., N, N) -> (...)``: :math:`h` at the state held as the matrix ``M``.
    gradient_matrix : callable
        ``M (..., N, N) -> (..., N, N)``: :math:`\nabla h` as an element of the algebra (a matrix), defined by
        :math:`dh = B(dM, \nabla h)` for the trace form ``B``; the Lie–Poisson drift is then :math:`[M, \nabla h]`.

    Notes
    -----
    The isospectral solvers call :meth:`gradient_matrix` directly (no coordinates: e.g. the Zeitlin model's
    inverse Laplacian on su(N)); :meth:`value` and :meth:`gradient` in coordinates go through the algebra's
    ``O(N²)`` maps, for everything else (energies, the coordinate schemes, checks). The Hessian, where a
    coordinate method asks for it, is by central differences (:class:`Hamiltonian`).
    """

    def __init__(self, algebra, value_matrix, gradient_matrix):
        if not callable(value_matrix) or not callable(gradient_matrix):
            raise TypeError("MatrixHamiltonian needs callables value_matrix(M) and gradient_matrix(M).")
        if not hasattr(algebra, "dual_to_matrix"):
            raise TypeError(f"algebra must be a MatrixLieAlgebra (e.g. mechanics.su(8)), got {type(algebra).__name__}.")
        self.algebra = algebra
        self._value_matrix, self._gradient_matrix = value_matrix, gradient_matrix
        super().__init__(self._value_coords, self._gradient_coords)

    def value_matrix(self, M):
        """:math:`h` at matrices ``M (..., N, N)``, shape ``(...)``."""
        return np.asarray(self._value_matrix(M), dtype=np.float64)

    def gradient_matrix(self, M):
        """:math:`\nabla h` as matrices of the algebra, ``(..., N, N)``."""
        return np.asarray(self._gradient_matrix(M))

    def _value_coords(self, mu):
        return self.value_matrix(self.algebra.dual_to_matrix(mu))

    def _gradient_coords(self, mu):
        return self.algebra.from_matrix(self.gradient_matrix(self.algebra.dual_to_matrix(mu)))


def hamiltonian_from(h, gradient, hessian, n: int, *, diagonal_vector: bool = False) -> Hamiltonian:
    """The Hamiltonian a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` was given: a
    :class:`Hamiltonian`, a callable ``h(mu)`` (with ``gradient``), or an inertia tensor (checked). With
    ``diagonal_vector`` (matrix algebras of any size) a vector of principal moments stays a vector
    (:class:`QuadraticHamiltonian` with the diagonal ``1 / moments``), never an ``n x n`` matrix."""
    if isinstance(h, Hamiltonian):
        return h
    if callable(h):
        if gradient is None:
            raise TypeError("a callable hamiltonian needs hamiltonian_gradient=callable(mu) -> (..., n).")
        return Hamiltonian(h, gradient, hessian)
    if diagonal_vector and np.ndim(h) == 1:
        moments = as_float_array(h, "inertia", ndim=1)
        if moments.shape != (n,):
            raise ValueError(f"inertia must have shape ({n},) (one moment per basis element) or ({n}, {n}), "
                             f"got {moments.shape}.")
        if not np.all(moments > 0):
            raise ValueError(f"inertia must be positive; its smallest moment is {float(np.min(moments)):.6g}.")
        return QuadraticHamiltonian(1.0 / moments)
    return QuadraticHamiltonian.from_inertia(check_inertia(h, "inertia", dim=n))
