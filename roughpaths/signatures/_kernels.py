"""Numba kernels of the signature of a level-2 rough path (private).

The exponential of a level-2 Lie element and the product of the step exponentials, for
:func:`roughpaths.rough_path_signature` (the truncated logarithm and the Lyndon coordinates are the
tensor algebra's: :mod:`roughpaths.algebra.flat`).
The signature kernels themselves live in :mod:`roughpaths.signatures._level2` (level 2),
:mod:`roughpaths.signatures._lanes` (depth >= 3, the lane kernel) and :mod:`roughpaths.signatures._vjp`
(gradients).

Layout: a truncated signature of a path in ``R^d`` at depth ``m`` is a flat float64 vector of
length ``d + d**2 + ... + d**m`` (levels 1..m concatenated, no leading 1). ``offsets[k]`` is the
start of level ``k`` (``offsets[1] = 0``, ``offsets[m + 1] = sigdim``). Row-major (iisignature's)
word order: ``(a_i ⊗ b_j)[p * d^j + q] = a_i[p] b_j[q]``; *reversed* order (the kernels'
internal one): word ``(i_1..i_k)`` at ``sum_j i_j d^(j-1)``.

Kernels named without a leading underscore are serial, release the GIL and take a range of rows
``lo..hi-1``; :mod:`roughpaths._threads` shares the ranges between threads.
Precision: no ``fastmath``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._lanes import mul_inplace

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _exp_lie2(x, a, d, m, offsets, out, p, q):
    """``out <- exp(x + a) - 1`` truncated at depth ``m`` (reversed layout).

    ``x`` is level 1 (d,), ``a`` level 2 (d, d) with ``a[i, j]`` the coefficient of word (i, j).
    """
    dim = offsets[m + 1]
    for r in range(dim):
        p[r] = 0.0
    for i in range(d):
        p[i] = x[i]
    if m >= 2:
        o2 = offsets[2]
        for i in range(d):
            for j in range(d):
                p[o2 + i + d * j] = a[i, j]
    for r in range(dim):
        out[r] = p[r]
    for n in range(2, m + 1):
        # q <- p ⊗ z / n, where p = z^(n-1)/(n-1)! lives in levels n-1 .. m
        inv = 1.0 / n
        for r in range(dim):
            q[r] = 0.0
        for k in range(n, m + 1):
            ok = offsets[k]
            o1 = offsets[k - 1]
            n1 = d ** (k - 1)
            for i in range(d):
                xi = x[i] * inv
                base = ok + n1 * i
                for u in range(n1):
                    q[base + u] += p[o1 + u] * xi
            if k - 2 >= n - 1:
                o2 = offsets[k - 2]
                n2 = d ** (k - 2)
                for i in range(d):
                    for j in range(d):
                        aij = a[i, j] * inv
                        base = ok + n2 * (i + d * j)
                        for u in range(n2):
                            q[base + u] += p[o2 + u] * aij
        for r in range(dim):
            p[r] = q[r]
            out[r] += q[r]


@njit(**_NOGIL)
def rough_sig_rows(inc, lev, m, offsets, lo, hi, out):
    """``prod_k exp(inc_k + lev_k)`` (reversed layout) for paths ``lo..hi-1`` into ``out`` (B, sigdim)."""
    d = inc.shape[2]
    dim = offsets[m + 1]
    e = np.empty(dim)
    p = np.empty(dim)
    q = np.empty(dim)
    for b in range(lo, hi):
        for r in range(dim):
            out[b, r] = 0.0
        for k in range(inc.shape[1]):
            _exp_lie2(inc[b, k], lev[b, k], d, m, offsets, e, p, q)
            mul_inplace(out[b], e, d, m, offsets)
