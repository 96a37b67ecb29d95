r"""The classical matrix Lie algebras so(n), su(N), u(N), sl(n, R) and sp(2n, R) as :class:`MatrixLieAlgebra`.

Each is built from a sparse basis written down directly (``O(N²)`` entries, no dense ``n × N × N`` array), that
is orthonormal up to sign for the trace form :math:`B(A, C) = -\tfrac12\mathrm{Re}\,\mathrm{tr}(AC)` (checked
at construction), and each restores its defining conditions entrywise after an update
(:meth:`MatrixLieAlgebra._project`). su(64) (dimension 4095) builds in about 0.03 s.
"""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths.validation import check_memory

from .matrix_algebra import MatrixLieAlgebra, _built

__all__ = ["so", "su", "u", "sp", "sl"]


class _Entries:
    """Collects the sparse basis of a built-in algebra: entries, and each element's Gram sign."""

    def __init__(self, N):
        self.N, self.rows, self.idx, self.vals, self.signs = N, [], [], [], []

    def add(self, entries, sign):
        row = len(self.signs)
        for a, b, v in entries:
            self.rows.append(row)
            self.idx.append(a * self.N + b)
            self.vals.append(v)
        self.signs.append(sign)


def _check_size(value, name, minimum):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}.")
    if value > 4096:
        raise ValueError(f"{name} = {value} is beyond the matrix sizes this library builds (<= 4096).")
    return int(value)


#: Bytes per non-zero entry of a built-in basis at the peak of its construction: the three Python lists of
#: :class:`_Entries` (an int row, an int index and a float or complex value: about 110 bytes), their arrays and the
#: sparse matrices of :class:`MatrixLieAlgebra` (measured with tracemalloc, N = 64 to 700: 192-214 bytes for the real
#: algebras, 245-248 for the complex ones; su(4096) would take 10 GiB and three minutes).
_BYTES_PER_ENTRY = 260.0


def _check_basis_memory(name: str, arg: str, value: int, nnz: int) -> None:
    """Refuse, before the lists are built, a basis of ``nnz`` non-zero entries above the memory budget."""
    check_memory(_BYTES_PER_ENTRY * nnz, f"the basis of {name} at {arg} = {value} ({nnz:.3g} non-zero entries, built "
                 f"as Python lists and then sparse matrices)", f"use a smaller {arg}")


def _skew_pairs(e, N, scale=1.0, sign=1.0, offset=(0, 0)):
    """``E_ab - E_ba`` (a < b) on the block at ``offset``, times ``scale``."""
    r, c = offset
    for a in range(N):
        for b in range(a + 1, N):
            e.add([(r + a, c + b, scale), (r + b, c + a, -scale)], sign)


def _gell_mann_diagonals(N):
    """The traceless diagonals ``D_k = sqrt(2/(k(k+1))) diag(1, .., 1, -k, 0, ..)``, ``tr(D_k²) = 2``."""
    for k in range(1, N):
        f = np.sqrt(2.0 / (k * (k + 1)))
        yield [(a, a, f) for a in range(k)] + [(k, k, -k * f)]


def so(n: int) -> MatrixLieAlgebra:
    r"""so(n): real skew-symmetric ``n × n`` matrices, dimension ``n(n-1)/2``.

    Basis :math:`E_{ab} = e_ae_b^T - e_be_a^T` (``a < b``, lexicographic), orthonormal for the trace form
    (compact); coordinates ``x_ab = X[a, b]``. Casimirs :math:`\mathrm{tr}((iM)^k)` (zero for odd ``k``).

    >>> so(4).dim
    6
    """
    n = _check_size(n, "n", 2)
    _check_basis_memory("so(n)", "n", n, n * (n - 1))
    e = _Entries(n)
    _skew_pairs(e, n)
    return _built(MatrixLieAlgebra._from_entries(f"so({n})", n, e.rows, e.idx, e.vals, np.float64, e.signs, True),
                  "skew")


def _su_nnz(N: int) -> int:
    """Non-zero entries of the basis of su(N): two per off-diagonal pair and kind, k + 1 per diagonal D_k."""
    return 2 * N * (N - 1) + (N - 1) * (N + 2) // 2


def _su_entries(N):
    e = _Entries(N)
    _skew_pairs(e, N)                                                  # E_ab - E_ba
    for a in range(N):
        for b in range(a + 1, N):
            e.add([(a, b, 1j), (b, a, 1j)], 1.0)                       # i (E_ab + E_ba)
    for diag in _gell_mann_diagonals(N):
        e.add([(a, b, 1j * v) for a, b, v in diag], 1.0)               # i D_k
    return e


def su(N: int) -> MatrixLieAlgebra:
    r"""su(N): complex skew-Hermitian trace-free ``N × N`` matrices, a real algebra of dimension ``N² - 1``.

    Basis (orthonormal for the trace form, compact): :math:`E_{ab} - E_{ba}`, :math:`i(E_{ab} + E_{ba})`
    (``a < b``) and :math:`iD_k` with the Gell-Mann diagonals :math:`D_k`, i.e. :math:`i\lambda_a` for the
    generalised Gell-Mann matrices. Casimirs :math:`\mathrm{tr}((iM)^k)`.

    >>> su(2).dim, su(4).dim
    (3, 15)
    """
    N = _check_size(N, "N", 2)
    _check_basis_memory("su(N)", "N", N, _su_nnz(N))
    e = _su_entries(N)
    return _built(MatrixLieAlgebra._from_entries(f"su({N})", N, e.rows, e.idx, e.vals, np.complex128, e.signs,
                                                 True), "skew_traceless")


def u(N: int) -> MatrixLieAlgebra:
    r"""u(N): complex skew-Hermitian ``N × N`` matrices, dimension ``N²``: the basis of :func:`su` and
    :math:`i\sqrt{2/N}\,I` (orthonormal, compact; reductive, not semisimple: ``tr(iM)`` is a Casimir too).

    >>> u(3).dim
    9
    """
    N = _check_size(N, "N", 1)
    _check_basis_memory("u(N)", "N", N, _su_nnz(N) + N)
    e = _su_entries(N)
    f = np.sqrt(2.0 / N)
    e.add([(a, a, 1j * f) for a in range(N)], 1.0)
    return _built(MatrixLieAlgebra._from_entries(f"u({N})", N, e.rows, e.idx, e.vals, np.complex128, e.signs, True,
                                                 casimir_degrees=tuple(range(1, min(N, 6) + 1))), "skew")


def sl(n: int) -> MatrixLieAlgebra:
    r"""sl(n, R): real trace-free ``n × n`` matrices, dimension ``n² - 1`` (non-compact).

    Basis orthogonal for the trace form: :math:`E_{ab} - E_{ba}` (``+1``), :math:`E_{ab} + E_{ba}` (``a < b``)
    and the Gell-Mann diagonals :math:`D_k` (``-1``). Casimirs :math:`\mathrm{tr}(M^k)`.

    >>> sl(3).dim
    8
    """
    n = _check_size(n, "n", 2)
    _check_basis_memory("sl(n, R)", "n", n, _su_nnz(n))
    e = _Entries(n)
    _skew_pairs(e, n)
    for a in range(n):
        for b in range(a + 1, n):
            e.add([(a, b, 1.0), (b, a, 1.0)], -1.0)
    for diag in _gell_mann_diagonals(n):
        e.add(diag, -1.0)
    return _built(MatrixLieAlgebra._from_entries(f"sl({n})", n, e.rows, e.idx, e.vals, np.float64, e.signs, False),
                  "traceless")


def sp(n: int) -> MatrixLieAlgebra:
    r"""sp(2n, R): real Hamiltonian ``2n × 2n`` matrices :math:`X^TJ + JX = 0`, :math:`J = [[0, I], [-I, 0]]`,
    i.e. :math:`X = [[A, B], [C, -A^T]]` with ``B``, ``C`` symmetric; dimension ``n(2n + 1)`` (non-compact).

    Basis orthogonal for the trace form (``+1`` on the compact part u(n), ``-1`` on the rest):
    :math:`\mathrm{diag}(A, -A^T)` for ``A`` skew (:math:`E_{ab}-E_{ba}`, scaled :math:`1/\sqrt2`), symmetric
    (:math:`E_{ab}+E_{ba}`, scaled :math:`1/\sqrt2`) and diagonal (:math:`E_{aa}`); :math:`[[0, S], [\mp S, 0]]`
    for ``S`` the symmetric units (:math:`E_{aa}`, and :math:`(E_{ab}+E_{ba})/\sqrt2`). Casimirs
    :math:`\mathrm{tr}(M^k)` (zero for odd ``k``).

    >>> sp(2).dim, sp(2).matrix_size
    (10, 4)
    """
    n = _check_size(n, "n", 1)
    _check_basis_memory("sp(2n, R)", "n", n, 8 * n * (n - 1) + 6 * n)
    N = 2 * n
    e = _Entries(N)
    h = 1.0 / np.sqrt(2.0)
    for a in range(n):                                   # diag(K, K) with K skew: -A^T = K
        for b in range(a + 1, n):
            e.add([(a, b, h), (b, a, -h), (n + a, n + b, h), (n + b, n + a, -h)], 1.0)
    for a in range(n):                                   # diag(S, -S) with S symmetric
        for b in range(a + 1, n):
            e.add([(a, b, h), (b, a, h), (n + a, n + b, -h), (n + b, n + a, -h)], -1.0)
        e.add([(a, a, 1.0), (n + a, n + a, -1.0)], -1.0)
    units = [[(a, a, 1.0)] for a in range(n)] + [[(a, b, h), (b, a, h)] for a in range(n) for b in range(a + 1, n)]
    for S in units:                                      # [[0, S], [-S, 0]] (compact) and [[0, S], [S, 0]]
        e.add([(a, n + b, v) for a, b, v in S] + [(n + a, b, -v) for a, b, v in S], 1.0)
        e.add([(a, n + b, v) for a, b, v in S] + [(n + a, b, v) for a, b, v in S], -1.0)
    return _built(MatrixLieAlgebra._from_entries(f"sp({N})", N, e.rows, e.idx, e.vals, np.float64, e.signs, False),
                  "hamiltonian")
