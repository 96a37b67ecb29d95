r"""The Lie–Poisson system's drift and noise as matrices, for states held as matrices of a :class:`MatrixLieAlgebra`.

A mixin of :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` (the coordinate formulas live there): the
isospectral solvers (:mod:`mechanics.integrators`) step the matrix :math:`M` of :math:`\mu` and ask the system
for the drift velocity :math:`w` and the stochastic velocity :math:`\eta` as matrices of the algebra. With the
trace form's identification (:mod:`mechanics.systems.matrix_algebra`) :math:`\mathrm{ad}^*_\xi\mu = [M, \xi]`,
so the double bracket is :math:`\vartheta[M, ([M, \nabla\tilde h])^\sharp]` and ``♯`` is the identity for an
orthonormal basis and the coordinate metric.
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import check_memory

__all__ = ["MatrixStatesMixin"]


class _MatrixData:
    """The cached matrices of :meth:`MatrixStatesMixin._matrix_data` (plain attributes)."""

    def __init__(self, **fields):
        self.__dict__.update(fields)


class MatrixStatesMixin:
    """Matrix forms of :meth:`drift_velocity` and :meth:`stochastic_velocity` (systems on a matrix algebra)."""

    def drift_velocity_matrix(self, M) -> np.ndarray:
        r"""The drift velocity :math:`w(\mu)` as a matrix of the algebra, for states held as matrices ``M``
        (``(..., N, N)``, :meth:`MatrixLieAlgebra.dual_to_matrix`): the drift is :math:`[M, w]`. Matrix
        algebras only. A Hamiltonian with a ``gradient_matrix(M)`` method (e.g. the Zeitlin model's) gives
        :math:`\nabla h` as a matrix directly; any other goes through the coordinates (``O(N²)`` maps)."""
        alg = self._matrix_algebra("drift_velocity_matrix")
        data = self._matrix_data()
        h = self.hamiltonian
        grad_matrix = getattr(h, "gradient_matrix", None)
        if grad_matrix is not None:
            W = np.asarray(grad_matrix(M)) + data.shift
        else:
            W = alg._to_matrix(h.gradient(alg._matrix_to_dual(M))) + data.shift
        if self.theta == 0.0:
            return W
        Wd = W if data.dissipation_change is None else W + data.dissipation_change
        D = M @ Wd - Wd @ M                                   # ad*_{grad} mu, a dual element held as a matrix
        if data.sharp_is_identity:
            X = D                                             # orthonormal basis, coordinate metric: ♯ = identity
        else:
            X = alg._to_matrix(self._sharp(alg._matrix_to_dual(D)))
        X *= self.theta
        X += W
        return X

    def stochastic_velocity_matrix(self, increments, levy_areas=None) -> np.ndarray:
        r""":meth:`stochastic_velocity` as a matrix of the algebra, ``(..., m)`` (and ``(..., m, m)``) →
        ``(..., N, N)``: :math:`\sum_i\xi_iX^i + \sum_{i<j}A^{ij}[\xi_i, \xi_j]`, one product per member with
        the stacked matrices of the :math:`\xi_i` and their brackets (each member's sum in one fixed order; a
        complex algebra's matrices are multiplied as their real and imaginary parts)."""
        alg = self._matrix_algebra("stochastic_velocity_matrix")
        data = self._matrix_data()
        m = self.n_noise
        inc = np.asarray(increments, dtype=np.float64)
        if levy_areas is None:
            coef, Z = inc, data.noise[:m]
        else:
            a = np.asarray(levy_areas, dtype=np.float64)
            coef, Z = np.concatenate([inc, a[..., data.iu, data.ju]], axis=-1), data.noise
        N = alg.matrix_size
        out = np.matmul(coef[..., None, :], Z)[..., 0, :]
        return out.view(alg.dtype).reshape(coef.shape[:-1] + (N, N))

    def _matrix_data(self):
        """What the matrix forms reuse, formed on first use (``with_s`` drops it): the ``ξ_i`` and the brackets
        ``[ξ_i, ξ_j]`` (``i < j``) as flattened real matrices ``(m + m(m-1)/2, N²)`` (``2N²`` for a complex
        algebra: real and imaginary parts interleaved), the velocity shift and the change of the gradient inside
        the double bracket as matrices, and whether ``♯`` is the identity on matrices."""
        data = getattr(self, "_stack", None)
        if data is None:
            alg, m = self.algebra, self.n_noise
            iu, ju = np.triu_indices(m, 1)
            N = alg.matrix_size
            check_memory((m + iu.size) * N * N * alg.dtype.itemsize, f"the {m} noise matrices of {alg.name} and "
                         f"their {iu.size} brackets", "use fewer noise vectors")
            coords = np.concatenate([self.xi, self._xi_brackets[iu, ju]])
            noise = np.ascontiguousarray(alg._to_matrix(coords)).view(np.float64).reshape(coords.shape[0], -1)
            change = self._shift_dissipation - self._shift
            data = self._stack = _MatrixData(
                noise=noise, iu=iu, ju=ju, shift=alg._to_matrix(self._shift),
                dissipation_change=None if self.levy_in_dissipation or not np.any(change) else alg._to_matrix(change),
                sharp_is_identity=bool(self._metric_inv is None and alg._signs is not None and np.all(alg._signs > 0)))
        return data

    def _matrix_algebra(self, what):
        if not self._matrix:
            raise TypeError(f"{what} needs a system on a MatrixLieAlgebra (e.g. mechanics.su(4)); this one is on "
                            f"{self.algebra!r}: use the coordinate methods.")
        return self.algebra
