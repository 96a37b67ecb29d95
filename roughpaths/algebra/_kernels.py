"""Numba kernels of the truncated tensor algebra (private to :mod:`roughpaths.algebra`).

The truncated logarithm and the Lyndon coordinates (with the transpose of their projection), on
flat float64 rows in the layout of :mod:`roughpaths.algebra.flat`: levels ``1..m`` concatenated, no
leading 1, row-major words; ``offsets[k]`` is the start of level ``k`` (``offsets[1] = 0``).

Kernels named without a leading underscore are serial, release the GIL and take a range of rows
``lo..hi-1``; :mod:`roughpaths._threads` shares the ranges between threads. Precision: no ``fastmath``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)

@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _log_one(a, d, m, offsets, r, t):
    """``r <- log(1 + a)`` (row-major, truncated at ``m``) by Horner, ``t`` scratch of the same size.

    ``log(1+a) = a (c_1 + a (c_2 + ... a (c_{m-1} + c_m a)))``, ``c_n = (-1)^(n+1)/n``, written
    with ``a`` on the right: ``r_m = c_m a``, ``r_n = (c_n + r_{n+1}) ⊗ a``. ``r_n`` is multiplied
    by ``a`` ``n - 1`` more times, so only its levels ``<= m - n + 1`` are formed.

    Indices are unsigned (no negative-index wrap-around), so LLVM vectorises the loops over the last
    letters (each entry gets the same operations in the same order: the same bits): 64 rows at d = 8,
    depth 3, 0.04 ms against 0.21 with signed indices, d = 3 at depth 4 0.06 against 0.08.
    """
    for u in range(offsets[2]):
        r[u] = a[u] * ((-1.0) ** (m + 1) / m)
    for n in range(m - 1, 0, -1):
        c = (-1.0) ** (n + 1) / n
        kmax = m - n + 1
        for k in range(1, kmax + 1):
            ok = np.uint64(offsets[k])
            for u in range(np.uint64(d ** k)):
                t[ok + u] = c * a[ok + u]
            for i in range(1, k):
                oi = np.uint64(offsets[i])
                oj = np.uint64(offsets[k - i])
                nj = np.uint64(d ** (k - i))
                for p in range(np.uint64(d ** i)):
                    rp = r[oi + p]
                    base = ok + p * nj
                    for q in range(nj):
                        t[base + q] += rp * a[oj + q]
        for u in range(np.uint64(offsets[kmax + 1])):
            r[u] = t[u]
@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _lyndon_one(z, lev_off, lidx, indptr, indices, data, out, out_off):
    for i in range(lidx.shape[0]):
        v = z[lev_off + lidx[i]]
        for t in range(indptr[i], indptr[i + 1]):
            v -= data[t] * out[out_off + indices[t]]
        out[out_off + i] = v
@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def lyndon_vjp(gc, out_off, lidx, indptr, indices, data, gz, lev_off):
    """Transpose of one level of the Lyndon projection: ``gz[lidx] = M^{-T} gc`` (back substitution)."""
    n = lidx.shape[0]
    y = np.empty(n)
    for b in range(gc.shape[0]):
        for i in range(n):
            y[i] = gc[b, out_off + i]
        for r in range(n - 1, -1, -1):
            yr = y[r]
            for t in range(indptr[r], indptr[r + 1]):
                y[indices[t]] -= data[t] * yr
        for i in range(n):
            gz[b, lev_off + lidx[i]] = y[i]
@njit(**_NOGIL)
def log_rows(a, d, m, offsets, lo, hi, out):
    """Row-major ``log(1 + a)`` of rows ``lo..hi-1`` of ``a`` (B, sigdim) into ``out``."""
    t = np.empty(a.shape[1])
    for b in range(lo, hi):
        _log_one(a[b], d, m, offsets, out[b], t)
@njit(**_NOGIL)
def lyndon_rows(z, lev_off, lidx, indptr, indices, data, out, out_off, lo, hi):
    """Lyndon coordinates of one level (forward substitution with the sparse ``M``), rows ``lo..hi-1``."""
    for b in range(lo, hi):
        _lyndon_one(z[b], lev_off, lidx, indptr, indices, data, out[b], out_off)
