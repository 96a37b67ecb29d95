r"""Matrix Lie algebras: a Lie algebra given by a basis of ``N × N`` matrices, held and acted on as matrices.

:class:`MatrixLieAlgebra` is the representation for algebras of any size (so(n), su(N), u(N), sp(2n, R),
sl(n, R) and user bases): nothing of size ``n²`` or ``n³`` in the dimension ``n`` is formed by the
operations a solver uses, which cost matrix products (``O(N³)``) and sparse maps (``O(N²)`` for the
built-in bases). The structure-constant :class:`~mechanics.systems.lie_algebra.LieAlgebra` stays for small
and user algebras; both serve one :class:`~mechanics.systems.lie_poisson.LiePoissonSystem`.

Conventions (``docs/conventions.md``, "Matrix Lie algebras")
-------------------------------------------------------------
* The bracket is the commutator :math:`[A, C] = AC - CA`; coordinates ``x`` of an element are those in the
  basis ``E_i``: :math:`X = \sum_i x^i E_i` (:meth:`MatrixLieAlgebra.to_matrix`).
* The trace form :math:`B(A, C) = -\tfrac12\,\mathrm{Re}\,\mathrm{tr}(AC)` (:meth:`MatrixLieAlgebra.pairing`) is
  Ad-invariant, :math:`B([A, X], C) = B(A, [X, C])`, positive definite on the compact algebras (so(n), su(N),
  u(N)) and non-degenerate on the others built here. The built-in bases are orthonormal for it up to sign:
  the Gram matrix :math:`G_{ij} = B(E_i, E_j)` is ``diag(±1)`` (all ``+1`` for the compact ones).
* The dual: :math:`\mu\in\mathfrak g^*` (coordinates in the dual basis, :math:`\langle\mu, \eta\rangle =
  \mu_k\eta^k` as in every algebra of the library) is held as the matrix :math:`M\in\mathfrak g` with
  :math:`B(M, \eta) = \langle\mu, \eta\rangle`: :math:`M = \sum_i (G^{-1}\mu)_i E_i`
  (:meth:`MatrixLieAlgebra.dual_to_matrix`, inverse :meth:`MatrixLieAlgebra.matrix_to_dual`).
* Then, by invariance, the library's coadjoint operator
  :math:`\langle\mathrm{ad}^*_\xi\mu, \eta\rangle = \langle\mu, [\xi, \eta]\rangle` is :math:`[M, \xi]`, and its
  time-1 flow :math:`\exp(\mathrm{ad}^*_\sigma)\mu` is the conjugation :math:`M\mapsto e^{-\sigma} M e^{\sigma}`:
  the coadjoint orbits are the conjugacy classes in :math:`\mathfrak g`, and the Casimirs are the power traces
  (:meth:`MatrixLieAlgebra.casimirs`). On so(3) this is :math:`\Pi\times\xi` again.

What is exact and what is approximate: the maps between coordinates and matrices, the bracket and the
pairing are exact up to round-off (a fixed number of sums per entry); the user basis checks (closure under the
commutator, non-degenerate trace form) are exact except that closure is tested on two random pairs of
elements, which misses a defect with probability zero in exact arithmetic (:func:`_closure_defect`).
"""

from __future__ import annotations


import numpy as np

from roughpaths import expm_batched
from roughpaths.validation import as_float_array, check_memory, check_positive_int, check_rng

from ._matrix_exp import conjugate_members, one_norms

__all__ = ["MatrixLieAlgebra", "haar_matrices"]

#: Draws of the random closure check of a user basis, from a fixed seed (the verdict is reproducible).
_CLOSURE_DRAWS = 2
_CLOSURE_SEED = 0x5EC7A1


class MatrixLieAlgebra:
    r"""A real Lie algebra of dimension ``n`` spanned by ``N × N`` matrices (real or complex), under the commutator.

    Parameters
    ----------
    basis : array_like, shape ``(n, N, N)``
        The basis matrices ``E_i``, real or complex (a complex basis spans a *real* algebra, e.g.
        skew-Hermitian matrices for su(N)). Checked: closed under the commutator, and the trace form
        :math:`B(A, C) = -\tfrac12\mathrm{Re}\,\mathrm{tr}(AC)` non-degenerate on the span (so the basis is
        independent and the dual can be held as a matrix). Algebras whose trace form is degenerate (se(3),
        nilpotent or solvable ones) have no such identification: use
        :meth:`~mechanics.systems.lie_algebra.LieAlgebra.from_matrix_basis` for them.
    name : str
        Label for ``repr`` and messages.
    compact : bool, optional
        Whether the trace form is positive definite (then :math:`e^{-\sigma}` is orthogonal or unitary and
        its inverse is its adjoint). Default: read from the Gram matrix.
    casimir_degrees : sequence of int, optional
        The powers ``k`` of the Casimirs :meth:`casimirs` (default ``2 .. min(N, 6)``).
    atol : float
        Tolerance of the checks, relative to the basis' scale.

    Notes
    -----
    Costs for a user basis with ``nnz`` non-zero entries: the checks take ``O(n · nnz)`` time and
    ``O(n² + nnz)`` memory (the Gram matrix), and the coordinate maps ``O(nnz)`` per member. The
    constructors :func:`so`, :func:`su`, :func:`u`, :func:`sp` and :func:`sl` build sparse bases directly
    (``nnz = O(N²)``) with a diagonal Gram matrix, in ``O(N²)`` time and memory.

    Examples
    --------
    >>> import numpy as np
    >>> from mechanics import su
    >>> g = su(3)
    >>> g.dim, g.matrix_size
    (8, 3)
    >>> x, y = np.eye(8)[0], np.eye(8)[3]
    >>> bool(np.allclose(g.to_matrix(g.bracket(x, y)), g.to_matrix(x) @ g.to_matrix(y) - g.to_matrix(y) @ g.to_matrix(x)))
    True
    """

    def __init__(self, basis, *, name: str = "g", compact=None, casimir_degrees=None, atol: float = 1e-10):
        b = np.asarray(basis)
        if b.dtype.kind not in "biufc":
            raise TypeError(f"basis must hold real or complex numbers, got dtype {b.dtype}.")
        if b.ndim != 3 or b.shape[1] != b.shape[2] or b.shape[0] < 1 or b.shape[1] < 1:
            raise ValueError(f"basis must have shape (n, N, N) (n matrices of size N x N), got {b.shape}.")
        if not np.all(np.isfinite(b)):
            raise ValueError("basis has non-finite entries; pass finite matrices.")
        n, N = b.shape[0], b.shape[1]
        check_memory(16.0 * (3 * b.size + 4 * n * n), f"the matrix Lie algebra of dimension n={n} on {N}x{N} "
                     f"matrices (its sparse basis and Gram matrix)", "use a smaller basis")
        dtype = np.complex128 if b.dtype.kind == "c" else np.float64
        b = b.astype(dtype)
        rows, idx = np.nonzero(b.reshape(n, N * N))
        vals = b.reshape(n, N * N)[rows, idx]
        self._setup(name, N, n, rows, idx, vals, dtype, gram=None, compact=compact,
                    casimir_degrees=casimir_degrees)
        scale = float(np.max(np.abs(b))) if b.size else 1.0
        defect = _closure_defect(self)
        if defect > atol * max(1.0, scale) ** 2:
            raise ValueError(f"the span of basis is not closed under the commutator (the bracket of two random "
                             f"elements leaves the span by {defect:.3g}); it is not a Lie algebra basis.")
        self._structure = _whole_algebra(b, scale)        # all of so(N), u(N) or su(N): project entrywise

    # ------------------------------------------------------------------ construction
    @classmethod
    def _from_entries(cls, name, N, rows, idx, vals, dtype, signs, compact, casimir_degrees=None):
        """A built-in algebra from its sparse basis (entries ``vals`` at ``(rows, idx = a N + b)``) and the
        diagonal ``signs`` of its Gram matrix (checked against the entries)."""
        self = object.__new__(cls)
        n = int(np.max(rows)) + 1 if len(rows) else 0
        self._setup(name, N, n, np.asarray(rows), np.asarray(idx), np.asarray(vals, dtype=dtype), dtype,
                    gram=np.asarray(signs, dtype=np.float64), compact=compact, casimir_degrees=casimir_degrees)
        return self

    def _setup(self, name, N, n, rows, idx, vals, dtype, *, gram, compact, casimir_degrees):
        import scipy.sparse as sparse

        self.name = str(name)
        self._N, self._n, self.dtype = int(N), int(n), np.dtype(dtype)
        a, b = np.divmod(idx, N)
        self._S = sparse.csr_matrix((vals, (rows, idx)), shape=(n, N * N))          # row i: vec(E_i)
        self._ST = sparse.csr_matrix((vals, (rows, b * N + a)), shape=(n, N * N))   # row i: vec(E_i^T)
        self._S_T = self._S.T.tocsr()                                               # (N², n) for x -> X
        full = (self._S @ self._ST.T).tocsr()                                       # -2 B(E_i, E_j)
        full.data = -0.5 * full.data.real
        full = full.astype(np.float64)
        diag = full.diagonal()
        off = full - sparse.diags(diag)
        off_max = float(abs(off).max()) if off.nnz else 0.0
        if gram is None and off_max == 0.0 and np.all(np.abs(np.abs(diag) - 1.0) < 1e-14):
            gram = np.sign(diag)                           # a user basis that is orthonormal up to sign
        if gram is None:
            self._signs = None
            check_memory(3 * 8.0 * n * n, f"the Gram matrix of {name} (n = {n})", "use a smaller basis")
            self._gram = full.toarray()
            w = np.linalg.eigvalsh(self._gram)
            small = float(np.min(np.abs(w))) if w.size else 0.0
            if not small > 1e-10 * max(1.0, float(np.max(np.abs(w)))):
                raise ValueError(f"the trace form B(A, C) = -1/2 Re tr(AC) is degenerate on the span of basis "
                                 f"(smallest |eigenvalue| of the Gram matrix {small:.3g}): the basis is linearly "
                                 f"dependent, or the algebra is not reductive (e.g. se(3)); use "
                                 f"LieAlgebra.from_matrix_basis(basis) for it.")
            self._ginv = np.linalg.inv(self._gram)
            is_pd = bool(np.all(w > 0))
        else:
            if off_max > 1e-13 or not np.allclose(diag, gram, rtol=0.0, atol=1e-13):   # the constructors' promise
                raise AssertionError(f"{name}: the basis is not orthonormal up to sign under the trace form")
            self._signs = np.asarray(gram, dtype=np.float64)
            self._gram = self._ginv = None
            is_pd = bool(np.all(self._signs > 0))
        self.compact = is_pd if compact is None else bool(compact)
        if casimir_degrees is None:
            casimir_degrees = tuple(range(2, min(self._N, 6) + 1)) or (2,)
        degrees = tuple(int(k) for k in casimir_degrees)
        if not degrees or any(k < 1 for k in degrees):
            raise ValueError(f"casimir_degrees must be positive integers, got {casimir_degrees!r}.")
        self._degrees = degrees
        self._structure = None            # set by the built-in constructors: how _project restores the algebra

    def __reduce__(self):
        return (_rebuild, (self.name, self._N, self._S.tocoo(), self.dtype.str, self._signs, self.compact,
                           self._degrees, self._structure))

    # ------------------------------------------------------------------ attributes
    @property
    def dim(self) -> int:
        """Dimension ``n`` of the algebra (the number of basis matrices)."""
        return self._n

    @property
    def matrix_size(self) -> int:
        """Size ``N`` of the matrices."""
        return self._N

    @property
    def gram(self) -> np.ndarray:
        r""":math:`G_{ij} = B(E_i, E_j)`, shape ``(n, n)`` (a copy; formed on request)."""
        check_memory(8.0 * self._n * self._n, f"the Gram matrix of {self.name}", "use casimirs/pairing instead")
        return np.diag(self._signs) if self._signs is not None else np.array(self._gram)

    @property
    def basis(self) -> np.ndarray:
        """The basis matrices ``E_i``, shape ``(n, N, N)`` (dense, formed on request)."""
        check_memory(float(self._n) * self._N ** 2 * self.dtype.itemsize, f"the dense basis of {self.name}",
                     "use to_matrix on coordinates instead")
        return self._S.toarray().reshape(self._n, self._N, self._N)

    @property
    def casimir_names(self) -> tuple:
        """Names of the Casimirs returned by :meth:`casimirs`."""
        form = "tr((iM)^{k})" if self.compact else "tr(M^{k})"
        return tuple(form.format(k=k) for k in self._degrees)

    @property
    def has_casimirs(self) -> bool:
        """Always ``True``: the power traces are Casimirs of every matrix algebra."""
        return True

    @property
    def structure_constants(self) -> np.ndarray:
        r"""``c[i, j, k]`` with :math:`[E_i, E_j] = c^k_{ij}E_k`, shape ``(n, n, n)``: formed on request, ``n``
        commutator batches; refused (memory budget) for large algebras, whose operations never need it."""
        n = self._n
        check_memory(8.0 * n ** 3 + 3.0 * n * self._N ** 2 * self.dtype.itemsize,
                     f"the structure constants of {self.name} (n = {n}: n³ floats)",
                     "use the matrix operations (bracket, ad_star) instead")
        eye = np.eye(n)
        return np.stack([self.bracket(eye[i], eye) for i in range(n)])

    def __repr__(self) -> str:
        return f"MatrixLieAlgebra(name={self.name!r}, dim={self._n}, N={self._N})"

    # ------------------------------------------------------------------ coordinates <-> matrices
    def _vec(self, x, name):
        return as_float_array(x, name, last_dims=(self._n,))

    def _mat(self, X, name):
        X = np.asarray(X)
        if X.dtype.kind not in "biufc":
            raise TypeError(f"{name} must hold numbers, got dtype {X.dtype}.")
        if X.ndim < 2 or X.shape[-2:] != (self._N, self._N):
            raise ValueError(f"{name} must have shape (..., {self._N}, {self._N}) (matrices of {self.name}), "
                             f"got {X.shape}.")
        return X

    def _to_matrix(self, x):
        """``Σ x^i E_i`` for ``x (..., n)`` real, unchecked: one sparse product over the flattened batch."""
        shape = x.shape[:-1]
        flat = np.ascontiguousarray(x.reshape(-1, self._n).T)
        out = (self._S_T @ flat).T
        return np.ascontiguousarray(out).reshape(shape + (self._N, self._N)).astype(self.dtype, copy=False)

    def _matrix_to_dual(self, M):
        """``μ_j = B(M, E_j)`` for ``M (..., N, N)``, unchecked."""
        shape = M.shape[:-2]
        flat = np.ascontiguousarray(np.swapaxes(M, -1, -2).reshape(-1, self._N * self._N).T)
        out = self._S @ flat
        return -0.5 * np.ascontiguousarray(out.real.T).reshape(shape + (self._n,))

    def _ginv_apply(self, v):
        if self._signs is not None:
            return v * self._signs
        return v @ self._ginv.T

    def to_matrix(self, x) -> np.ndarray:
        r"""The element :math:`X = \sum_i x^i E_i`, shape ``(..., n)`` → ``(..., N, N)``."""
        return self._to_matrix(self._vec(x, "x"))

    def from_matrix(self, X) -> np.ndarray:
        r"""Coordinates ``x`` of an element ``X`` of the algebra (``(..., N, N)`` → ``(..., n)``); for a matrix
        outside the algebra, the coordinates of its projection (orthogonal for the trace form)."""
        return self._ginv_apply(self._matrix_to_dual(self._mat(X, "X")))

    def dual_to_matrix(self, mu) -> np.ndarray:
        r"""The matrix :math:`M` that holds :math:`\mu\in\mathfrak g^*`: :math:`B(M, \eta) = \langle\mu, \eta\rangle`,
        :math:`M = \sum_i (G^{-1}\mu)_i E_i`. Shape ``(..., n)`` → ``(..., N, N)``."""
        return self._to_matrix(self._ginv_apply(self._vec(mu, "mu")))

    def matrix_to_dual(self, M) -> np.ndarray:
        r"""Inverse of :meth:`dual_to_matrix`: :math:`\mu_j = B(M, E_j)`, ``(..., N, N)`` → ``(..., n)``."""
        return self._matrix_to_dual(self._mat(M, "M"))

    def pairing(self, A, C) -> np.ndarray:
        r"""The trace form :math:`B(A, C) = -\tfrac12\mathrm{Re}\,\mathrm{tr}(AC)` of matrices ``(..., N, N)``."""
        A, C = self._mat(A, "A"), self._mat(C, "C")
        return -0.5 * np.einsum("...ab,...ba->...", A, C).real

    # ------------------------------------------------------------------ operations (coordinates)
    def bracket(self, x, y) -> np.ndarray:
        r""":math:`[x, y]` in coordinates (the commutator of the matrices), shapes ``(..., n)`` broadcast."""
        X, Y = self.to_matrix(x), self.to_matrix(y)
        return self._ginv_apply(self._matrix_to_dual(X @ Y - Y @ X))

    def ad_star(self, xi, mu) -> np.ndarray:
        r""":math:`\mathrm{ad}^*_\xi\mu` (the library's sign: :math:`\langle\mathrm{ad}^*_\xi\mu,\eta\rangle =
        \langle\mu,[\xi,\eta]\rangle`), computed as :math:`[M, \xi]`; shapes ``(..., n)`` broadcast."""
        X, M = self.to_matrix(xi), self.dual_to_matrix(mu)
        return self._matrix_to_dual(M @ X - X @ M)

    def _ad_star_unchecked(self, xi, mu):
        X, M = self._to_matrix(xi), self._to_matrix(self._ginv_apply(mu))
        return self._matrix_to_dual(M @ X - X @ M)

    def _dense_operator(self, batch, what):
        """The unit vectors an ``n × n`` operator is applied to, after checking its memory: the ``n`` basis matrices,
        three ``n × N × N`` products per member, and the ``n × n`` result (with its copy) per member."""
        n, b = self._n, float(np.prod(batch, dtype=np.int64))
        check_memory(float(n) * self._N ** 2 * self.dtype.itemsize * (1.0 + 3.0 * b) + 16.0 * b * n * n,
                     f"{what} of {self.name} (n x n matrices, n = {n})",
                     "use the matrix operations (bracket, ad_star) instead")
        return np.eye(n)

    def ad(self, x) -> np.ndarray:
        r"""Matrix of :math:`\mathrm{ad}_x` (``ad(x) @ y == bracket(x, y)``), shape ``(..., n, n)``."""
        x = self._vec(x, "x")
        eye = self._dense_operator(x.shape[:-1], "ad(x)")
        X = self._to_matrix(x)[..., None, :, :]
        E = self._to_matrix(eye)
        return np.swapaxes(self._ginv_apply(self._matrix_to_dual(X @ E - E @ X)), -1, -2)

    def ad_star_matrix(self, xi) -> np.ndarray:
        r"""Matrix of :math:`\mu\mapsto\mathrm{ad}^*_\xi\mu`, shape ``(..., n, n)``."""
        xi = self._vec(xi, "xi")
        eye = self._dense_operator(xi.shape[:-1], "ad_star_matrix(xi)")
        X = self._to_matrix(xi)[..., None, :, :]
        M = self._to_matrix(self._ginv_apply(eye))
        return np.swapaxes(self._matrix_to_dual(M @ X - X @ M), -1, -2)

    def coadjoint_orbit_tangent(self, mu) -> np.ndarray:
        r"""Matrix of :math:`\delta\mapsto\mathrm{ad}^*_\delta\mu` (``L[..., j, i] = (ad*_{e_i} mu)_j``), shape
        ``(..., n, n)``."""
        mu = self._vec(mu, "mu")
        eye = self._dense_operator(mu.shape[:-1], "the orbit tangent")
        M = self._to_matrix(self._ginv_apply(mu))[..., None, :, :]
        E = self._to_matrix(eye)
        return np.swapaxes(self._matrix_to_dual(M @ E - E @ M), -1, -2)

    def exp(self, x) -> np.ndarray:
        """Group exponential ``expm(Σ x^i E_i)``, batched, shape ``(..., N, N)``."""
        return expm_batched(self.to_matrix(x))

    def Ad_star_exp(self, sigma, mu) -> np.ndarray:  # noqa: N802 (mathematical name)
        r""":math:`\exp(\mathrm{ad}^*_\sigma)\mu`: the conjugation :math:`M\mapsto e^{-\sigma}Me^{\sigma}` of the
        matrix of ``mu``, back in coordinates. Shapes ``(..., n)`` broadcast."""
        sigma, mu = self._vec(sigma, "sigma"), self._vec(mu, "mu")
        shape = np.broadcast_shapes(sigma.shape, mu.shape)
        S = self._to_matrix(np.broadcast_to(sigma, shape))
        M = self._to_matrix(self._ginv_apply(np.broadcast_to(mu, shape)))
        return self._matrix_to_dual(self.conjugate(S, M))

    def conjugate(self, sigma_matrix, M) -> np.ndarray:
        r""":math:`e^{-\sigma} M e^{\sigma}` for matrices ``(..., N, N)`` (the coadjoint flow on matrices):
        ``Q M Q^H`` with ``Q = expm(-σ)`` on compact algebras (``Q`` unitary), ``Q M Q^{-1}`` otherwise, each member
        on its own (:mod:`mechanics.systems._matrix_exp`); the result is projected back onto the algebra (the
        round-off that leaves it). A member with a non-finite ``σ`` gives NaN."""
        S, M = np.broadcast_arrays(np.asarray(sigma_matrix), np.asarray(M))
        shape = S.shape
        S, M = S.reshape((-1,) + shape[-2:]), M.reshape((-1,) + shape[-2:])
        with np.errstate(over="ignore", invalid="ignore"):
            norms = one_norms(S)
        ok = np.isfinite(norms)
        if np.all(ok):
            out = conjugate_members(S, M, self.compact, norms)
        else:
            out = np.full(S.shape, np.nan, dtype=np.result_type(S, M))
            out[ok] = conjugate_members(S[ok], M[ok], self.compact, norms[ok])
        return self._project(out).reshape(shape)

    def _project(self, X):
        """A projection onto the algebra (the identity on its elements): for the built-in algebras the defining
        conditions restored entrywise (skew-(Hermitian) part, trace removed, ``½(X + J Xᵀ J)`` on sp), which
        round in no preferred direction; for a user basis the trace-form projection through the coordinates.

        Measured on su(8), 5000 random conjugations (relative eigenvalue drift): the entrywise projection
        5e-15, none 9e-15, the projection through the coordinates 8e-14 (the Gell-Mann diagonals' irrational
        weights round with a bias that accumulates linearly)."""
        kind = self._structure
        if kind is None:
            return self._to_matrix(self._ginv_apply(self._matrix_to_dual(X)))
        N = self._N
        if kind in ("skew", "skew_traceless"):
            X = 0.5 * (X - np.conj(np.swapaxes(X, -1, -2)))
        elif kind == "hamiltonian":                          # J X^T J with J = [[0, I], [-I, 0]]
            h = N // 2
            Xt = np.swapaxes(X, -1, -2)
            JXtJ = np.concatenate([np.concatenate([-Xt[..., h:, h:], Xt[..., h:, :h]], -1),
                                   np.concatenate([Xt[..., :h, h:], -Xt[..., :h, :h]], -1)], -2)
            X = 0.5 * (X + JXtJ)
        if kind in ("skew_traceless", "traceless"):
            if kind == "traceless":
                X = np.array(X, dtype=np.result_type(X, np.float64))      # a fresh copy, updated in place
            flat = X.reshape(-1, N * N)                                   # a view of the fresh array
            flat[:, :: N + 1] -= (np.trace(X, axis1=-2, axis2=-1) / N).reshape(-1, 1)
        return X

    # ------------------------------------------------------------------ invariants
    def casimirs(self, mu) -> np.ndarray:
        r"""The power traces of the matrix of ``mu``: :math:`\mathrm{tr}((iM)^k)` on compact algebras (real, the
        power sums of the eigenvalues of the Hermitian :math:`iM`), :math:`\mathrm{tr}(M^k)` otherwise, for
        ``k`` in ``casimir_degrees``; shape ``(..., n)`` → ``(..., len(casimir_degrees))``."""
        return self.matrix_casimirs(self.dual_to_matrix(mu))

    def matrix_casimirs(self, M) -> np.ndarray:
        """:meth:`casimirs` of matrices ``(..., N, N)`` held as matrices."""
        M = self._mat(M, "M")
        A = 1j * M if self.compact else M
        out, P, k = [], A, 1
        for deg in self._degrees:
            while k < deg:
                P, k = P @ A, k + 1
            out.append(np.trace(P, axis1=-2, axis2=-1).real)
        return np.stack(out, axis=-1)

    def casimir_scale(self, M) -> np.ndarray:
        r""":math:`\sum_j|\lambda_j|^k` for the eigenvalues of ``M`` (``(..., N, N)`` → ``(..., len(degrees))``):
        the scale a Casimir's drift is relative to (``tr(M^k)`` may vanish, e.g. odd ``k`` on so(n))."""
        M = self._mat(M, "M")
        lam = np.abs(np.linalg.eigvals(M))
        return np.stack([np.sum(lam ** k, axis=-1) for k in self._degrees], axis=-1)

    def sample_orbit(self, mu, size, rng) -> np.ndarray:
        r"""Independent draws from the invariant (uniform) measure on the coadjoint orbit of ``mu``: :math:`U M U^{-1}`
        with ``U`` Haar-distributed on the compact group (``SO(N)`` for a real algebra, ``U(N)`` for a complex
        one). Compact algebras only. Returns ``(size, n)`` dual coordinates.

        The uniform measure on an orbit is the push-forward of the Haar measure by :math:`U\mapsto UMU^{-1}`
        (the orbit is a homogeneous space), so these are exact samples of Proposition 3.1's measure.
        """
        if not self.compact:
            raise ValueError(f"sample_orbit needs a compact algebra (so, su, u); {self.name} is not compact, its "
                             f"orbits carry no finite invariant measure.")
        rng = check_rng(rng)
        size = check_positive_int(size, "size")
        mu = self._vec(mu, "mu")
        if mu.ndim != 1:
            raise ValueError(f"mu must be one point of shape ({self._n},), got {mu.shape}.")
        M = self.dual_to_matrix(mu)
        U = haar_matrices(self._N, size, rng, complex_=self.dtype.kind == "c")
        return self._matrix_to_dual(U @ M @ np.conj(np.swapaxes(U, -1, -2)))


def haar_matrices(N: int, size: int, rng, *, complex_: bool) -> np.ndarray:
    """``size`` Haar-distributed matrices of ``SO(N)`` (real) or ``U(N)`` (complex), shape ``(size, N, N)``:
    the QR factor of a Gaussian matrix with the signs of ``R``'s diagonal moved into ``Q`` (Mezzadri 2007)."""
    if complex_:
        Z = (rng.standard_normal((size, N, N)) + 1j * rng.standard_normal((size, N, N))) / np.sqrt(2.0)
    else:
        Z = rng.standard_normal((size, N, N))
    Q, R = np.linalg.qr(Z)
    d = np.diagonal(R, axis1=-2, axis2=-1)
    Q = Q * (d / np.abs(d))[..., None, :]
    if not complex_:                                  # O(N) -> SO(N): flip one column where det = -1
        neg = np.linalg.det(Q) < 0
        Q[neg, :, 0] *= -1.0
    return Q


def _built(alg, structure):
    """Record how :meth:`MatrixLieAlgebra._project` restores a built-in algebra (``None``: through coordinates)."""
    alg._structure = structure
    return alg


def _rebuild(name, N, coo, dtype, signs, compact, degrees, structure):
    if signs is not None:
        return _built(MatrixLieAlgebra._from_entries(name, N, coo.row, coo.col, coo.data, np.dtype(dtype), signs,
                                                     compact, degrees), structure)
    basis = np.zeros((int(coo.row.max()) + 1, N * N), dtype=np.dtype(dtype))
    basis[coo.row, coo.col] = coo.data
    return MatrixLieAlgebra(basis.reshape(-1, N, N), name=name, compact=compact, casimir_degrees=degrees)


def _whole_algebra(b, scale):
    """``"skew"`` / ``"skew_traceless"`` when a user basis ``b (n, N, N)`` spans all of so(N) (a real basis), u(N) or
    su(N): there the entrywise projection of :meth:`MatrixLieAlgebra._project` is the trace-form one (the
    complement is the (Hermitian) symmetric matrices, and ``iℝ·I`` for su(N)); otherwise ``None``."""
    n, N = b.shape[0], b.shape[1]
    if np.max(np.abs(b + np.conj(np.swapaxes(b, 1, 2)))) > 1e-14 * scale:
        return None
    if b.dtype.kind != "c":
        return "skew" if n == N * (N - 1) // 2 else None
    if n == N * N:
        return "skew"
    traceless = np.max(np.abs(np.trace(b, axis1=1, axis2=2))) <= 1e-14 * scale * N
    return "skew_traceless" if traceless and n == N * N - 1 else None


def _closure_defect(alg: MatrixLieAlgebra) -> float:
    r"""How far the commutator of random elements ``Y, Z`` of the span leaves it (largest entry of the residual
    after the trace-form projection), over ``_CLOSURE_DRAWS`` draws from a fixed seed.

    The residual :math:`R(Y, Z) = [Y, Z] - P[Y, Z]` is bilinear; it vanishes for all pairs iff the span is
    closed, and a non-zero bilinear map vanishes at a random Gaussian pair with probability zero. Cost: two
    matrix products and two sparse maps per draw.
    """
    rng = np.random.default_rng(_CLOSURE_SEED)
    worst = 0.0
    for _ in range(_CLOSURE_DRAWS):
        y, z = rng.standard_normal((2, alg.dim))
        Y, Z = alg._to_matrix(y), alg._to_matrix(z)
        C = Y @ Z - Z @ Y
        worst = max(worst, float(np.max(np.abs(C - alg._project(C)))))
    return worst
