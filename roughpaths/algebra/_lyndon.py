"""Lyndon words and the Lyndon basis of the free Lie algebra (private helpers).

Letters are ``0 .. d-1`` (printed 1-based in decimal, as ``iisignature`` prints letters 1..9; it
prints letters from 10 on as ``'?'``, we print the number, see :func:`roughpaths.lyndon_basis`). A Lyndon word ``w`` of length > 1
is bracketed by its *standard factorisation* ``w = u v`` with ``v`` the longest proper suffix
that is itself Lyndon (equivalently, the lexicographically smallest proper suffix):
``P(w) = [P(u), P(v)] = P(u)⊗P(v) - P(v)⊗P(u)``. This is the basis ``iisignature.basis`` lists,
in the same order (by length, then lexicographically).

``P(w) = w + (words lexicographically larger than w)``, so the coefficients ``l`` of the Lyndon
words in a Lie element ``L = sum_v c_v P(v)`` are ``l = M c`` with ``M[i, j] = <w_i, P(w_j)>``
unit lower-triangular (words of one length in lexicographic order). :func:`lyndon_projection`
returns ``M`` as a sparse matrix; the coordinates ``c`` are found by forward substitution. Nothing
dense of size ``n_k x d**k`` is ever formed:

* ``P(w)`` of a word of length ``k`` is a signed sum of exactly ``2**(k-1)`` words (with possible
  repeats), so the expansions of all Lyndon words of length ``k`` are two ``(n_k, 2**(k-1))``
  arrays (word indices, signs), built level by level from the factors' arrays;
* ``M`` keeps only the entries that land on Lyndon words.

Both are cached per ``(d, k)`` in a least-recently-used cache with a byte budget
(:data:`CACHE_BYTES`), so repeated calls are cheap and memory stays bounded.
"""

from __future__ import annotations

from collections import OrderedDict
from functools import lru_cache

import numpy as np

__all__ = ["lyndon_words", "standard_factorisation", "bracket_string", "level_expansion",
           "expansion_matrix",
           "lyndon_projection", "lyndon_levels", "count_lyndon_words", "lyndon_indices", "CACHE_BYTES", "cache_clear"]

#: Byte budget of the cache of expansions and projection matrices (least recently used evicted).
CACHE_BYTES = 256 * 2 ** 20


class _ByteLRU:
    """A dict-like LRU cache whose values are tuples of arrays, bounded by their total ``nbytes``."""

    def __init__(self, budget: int):
        self.budget = int(budget)
        self._data: OrderedDict = OrderedDict()
        self.nbytes = 0

    @staticmethod
    def _size(value) -> int:
        if isinstance(value, np.ndarray):
            return value.nbytes
        if _is_sparse(value):
            return value.data.nbytes + value.indices.nbytes + value.indptr.nbytes
        if isinstance(value, (tuple, list)):
            return sum(_ByteLRU._size(v) for v in value)
        return 64

    def get(self, key, build):
        if key in self._data:
            self._data.move_to_end(key)
            return self._data[key][0]
        value = build()
        size = self._size(value)
        self._data[key] = (value, size)
        self.nbytes += size
        while self.nbytes > self.budget and len(self._data) > 1:
            _, (_, s) = self._data.popitem(last=False)
            self.nbytes -= s
        return value

    def clear(self) -> None:
        self._data.clear()
        self.nbytes = 0


_CACHE = _ByteLRU(CACHE_BYTES)



def _sparse():
    """scipy.sparse, imported on first use (it costs ~0.1 s of ``import roughpaths`` otherwise)."""
    import scipy.sparse

    return scipy.sparse


def _is_sparse(value) -> bool:
    return "scipy.sparse" in type(value).__module__ and _sparse().issparse(value)


def cache_clear() -> None:
    """Drop every cached expansion / projection (and the word lists)."""
    _CACHE.clear()
    lyndon_words.cache_clear()
    _small_levels.cache_clear()


def _mobius(n: int) -> int:
    result, p = 1, 2
    while p * p <= n:
        if n % p == 0:
            n //= p
            if n % p == 0:
                return 0
            result = -result
        p += 1
    return -result if n > 1 else result


def count_lyndon_words(dim: int, k: int) -> int:
    """Number of Lyndon words of length exactly ``k`` over ``dim`` letters (Witt's formula).

    ``(1/k) sum_{e | k} mu(e) dim**(k/e)``, exact integer arithmetic, no enumeration.
    """
    total = sum(_mobius(e) * dim ** (k // e) for e in range(1, k + 1) if k % e == 0)
    return total // k


def _is_lyndon(w: tuple) -> bool:
    return all(w < w[i:] for i in range(1, len(w)))


@lru_cache(maxsize=8)
def lyndon_words(dim: int, depth: int) -> tuple:
    """Lyndon words over ``0..dim-1`` of length ``1..depth``, sorted by length then lexicographically.

    Duval's algorithm generates all Lyndon words of length ``<= depth`` in lexicographic order.
    """
    words = []
    w = [-1]
    while w:
        w[-1] += 1
        words.append(tuple(w))
        m = len(w)
        while len(w) < depth:
            w.append(w[len(w) - m])
        while w and w[-1] == dim - 1:
            w.pop()
    return tuple(sorted(words, key=lambda u: (len(u), u)))


@lru_cache(maxsize=64)
def _words_of_length(dim: int, k: int) -> tuple:
    return tuple(w for w in lyndon_words(dim, k) if len(w) == k)


@lru_cache(maxsize=64)
def _positions(dim: int, k: int) -> dict:
    return {w: i for i, w in enumerate(_words_of_length(dim, k))}


def standard_factorisation(w: tuple) -> tuple:
    """``(u, v)`` with ``w = u v`` and ``v`` the longest proper Lyndon suffix of ``w``."""
    if len(w) < 2 or not _is_lyndon(w):
        raise ValueError(f"{w!r} has no proper Lyndon suffix (it has length 1 or is not Lyndon).")
    i = min(range(1, len(w)), key=lambda j: w[j:])     # smallest proper suffix = longest Lyndon one
    return w[:i], w[i:]


def bracket_string(w: tuple) -> str:
    """The bracketing of ``w`` in ``iisignature.basis`` notation (1-based decimal letters, no spaces).

    Letters from 10 on are printed as numbers (iisignature prints ``'?'``), e.g. ``'[1,10]'``.
    """
    if len(w) == 1:
        return str(w[0] + 1)
    u, v = standard_factorisation(w)
    return f"[{bracket_string(u)},{bracket_string(v)}]"


def _word_index(w: tuple, dim: int) -> int:
    idx = 0
    for letter in w:
        idx = idx * dim + letter
    return idx


def lyndon_indices(dim: int, k: int) -> np.ndarray:
    """Row-major positions (inside level ``k``) of the Lyndon words of length ``k``, increasing."""
    def build():
        return np.array([_word_index(w, dim) for w in _words_of_length(dim, k)], dtype=np.int64)
    return _CACHE.get(("idx", dim, k), build)


def _factor_table(dim: int, k: int) -> tuple:
    """Per Lyndon word of length ``k``: length of ``u`` and positions of ``u``, ``v`` in their levels."""
    def build():
        words = _words_of_length(dim, k)
        pos = [None] + [_positions(dim, length) for length in range(1, k)]
        a_len = np.empty(len(words), dtype=np.int64)
        pu = np.empty(len(words), dtype=np.int64)
        pv = np.empty(len(words), dtype=np.int64)
        for j, w in enumerate(words):
            for i in range(1, k):                  # longest proper Lyndon suffix first
                pv_j = pos[k - i].get(w[i:])
                if pv_j is not None:
                    break
            a_len[j], pu[j], pv[j] = i, pos[i][w[:i]], pv_j
        return a_len, pu, pv
    return _CACHE.get(("fac", dim, k), build)


def _expand_rows(dim: int, k: int, rows: np.ndarray) -> tuple:
    """``(idx, sgn)`` of the expansions of the Lyndon words ``rows`` (positions in level ``k``)."""
    if k == 1:
        return rows.astype(np.int64)[:, None], np.ones((rows.shape[0], 1), dtype=np.int8)
    a_len, pu_all, pv_all = _factor_table(dim, k)
    width = 2 ** (k - 1)
    idx = np.empty((rows.shape[0], width), dtype=np.int64)
    sgn = np.empty((rows.shape[0], width), dtype=np.int8)
    for a in np.unique(a_len[rows]):
        a = int(a)
        b = k - a
        sel = np.flatnonzero(a_len[rows] == a)
        iu, su = level_expansion(dim, a)
        iv, sv = level_expansion(dim, b)
        pu, pv = pu_all[rows[sel]], pv_all[rows[sel]]
        iu, su, iv, sv = iu[pu], su[pu], iv[pv], sv[pv]
        g = sel.shape[0]
        s1 = (su[:, :, None] * sv[:, None, :]).reshape(g, -1)
        idx[sel] = np.concatenate([(iu[:, :, None] * dim ** b + iv[:, None, :]).reshape(g, -1),
                                   (iv[:, :, None] * dim ** a + iu[:, None, :]).reshape(g, -1)], axis=1)
        sgn[sel] = np.concatenate([s1, -s1], axis=1)
    return idx, sgn


def _row_blocks(n_rows: int, width: int, max_entries: int = 2 ** 21):
    step = max(1, max_entries // max(width, 1))
    for start in range(0, n_rows, step):
        yield np.arange(start, min(start + step, n_rows), dtype=np.int64)


def level_expansion(dim: int, k: int) -> tuple:
    """``(idx, sgn)``, each ``(n_k, 2**(k-1))``: ``P(w_j) = sum_t sgn[j, t] * word(idx[j, t])``.

    ``idx`` are row-major positions inside level ``k`` (int64), ``sgn`` is ``+-1`` (int8).
    """
    return _CACHE.get(("exp", dim, k),
                      lambda: _expand_rows(dim, k, np.arange(count_lyndon_words(dim, k), dtype=np.int64)))


def expansion_matrix(dim: int, k: int):
    """Sparse ``(n_k, dim**k)`` matrix whose row ``j`` is the tensor expansion of ``P(w_j)``."""
    def build():
        n_k, width = count_lyndon_words(dim, k), 2 ** (k - 1)
        blocks = []
        for rows in _row_blocks(n_k, width):
            idx, sgn = _expand_rows(dim, k, rows)
            r = np.repeat(np.arange(rows.shape[0], dtype=np.int64), width)
            blk = _sparse().csr_matrix((sgn.reshape(-1).astype(np.float64), (r, idx.reshape(-1))),
                                shape=(rows.shape[0], dim ** k))
            blk.sum_duplicates()
            blk.eliminate_zeros()
            blocks.append(blk)
        if not blocks:                                      # no Lyndon word of length k (dim = 1, k > 1)
            return _sparse().csr_matrix((0, dim ** k))
        return _sparse().vstack(blocks, format="csr")
    return _CACHE.get(("E", dim, k), build)


def lyndon_projection(dim: int, k: int) -> tuple:
    """``(idx, indptr, indices, data)``: Lyndon positions and the strictly lower part of ``M`` (CSR).

    ``M[i, j] = <w_i, P(w_j)>`` for Lyndon words of length ``k`` (unit diagonal, checked). The
    coordinates of a Lie element ``L`` are ``c = M^{-1} L[idx]`` (forward substitution).
    """
    def build():
        lidx = lyndon_indices(dim, k)
        n_k = lidx.shape[0]
        if k == 1 or n_k == 0:                               # n_k = 0: dim = 1, k > 1
            m = _sparse().csr_matrix((n_k, n_k))
        else:
            ri, ci, vi = [], [], []
            table = None
            if dim ** k <= 2 ** 24:                          # direct lookup word -> Lyndon position
                table = np.full(dim ** k, -1, dtype=np.int64)
                table[lidx] = np.arange(n_k)
            for rows in _row_blocks(n_k, 2 ** (k - 1)):      # bounded temporaries
                terms, sgn = _expand_rows(dim, k, rows)
                if table is not None:
                    p = table[terms]
                    hit = p >= 0
                else:
                    p = np.searchsorted(lidx, terms)
                    p[p >= n_k] = 0
                    hit = lidx[p] == terms
                ri.append(p[hit])
                ci.append(np.broadcast_to(rows[:, None], terms.shape)[hit])
                vi.append(sgn[hit].astype(np.float64))
            m = _sparse().csr_matrix((np.concatenate(vi), (np.concatenate(ri), np.concatenate(ci))),
                              shape=(n_k, n_k))
            m.sum_duplicates()
            if not np.array_equal(m.diagonal(), np.ones(n_k)):
                raise AssertionError("Lyndon projection: M is not unit triangular")
            m = _sparse().tril(m, k=-1, format="csr")
            m.eliminate_zeros()
            if m.nnz and np.any(m.indices >= np.repeat(np.arange(n_k), np.diff(m.indptr))):
                raise AssertionError("Lyndon projection: M is not lower triangular")
        return (lidx, m.indptr.astype(np.int64), m.indices.astype(np.int64),
                np.ascontiguousarray(m.data, dtype=np.float64))
    return _CACHE.get(("proj", dim, k), build)


#: Alphabets and depths with ``dim**depth`` at most this keep their per-level projections together
#: (:func:`lyndon_levels`): a few hundred kB at most, 32 of them at most.
_SMALL_LEVELS = 4096


def lyndon_levels(dim: int, depth: int) -> tuple:
    """``(projections, starts, work)``: :func:`lyndon_projection` of levels ``1..depth``, where each level's
    coordinates start in the concatenated Lyndon coordinates (``starts[depth]``: their number), and the
    work of one row (coordinates plus map entries).

    For small ``dim**depth`` kept together (one look-up instead of one per level, which costs more than the
    coordinates of a small batch); otherwise assembled from the byte-bounded cache on each call.
    """
    if dim ** depth <= _SMALL_LEVELS:
        return _small_levels(dim, depth)
    return _levels(dim, depth)


def _levels(dim: int, depth: int) -> tuple:
    projections = tuple(lyndon_projection(dim, k) for k in range(1, depth + 1))
    starts = [0]
    for p in projections:
        starts.append(starts[-1] + p[0].shape[0])
    return projections, tuple(starts), float(sum(p[0].shape[0] + p[2].shape[0] for p in projections))


@lru_cache(maxsize=32)
def _small_levels(dim: int, depth: int) -> tuple:
    return _levels(dim, depth)
