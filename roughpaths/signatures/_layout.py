"""The signature's layout permutation (private): the kernels' reversed word order to the row-major one.

Called by :mod:`roughpaths.signatures._engine` where a path has at least as many floats as its signature (for
shorter paths the engine runs the kernels on the path reversed in time and negated, whose reversed-layout signature
is the row-major one, and permutes nothing).
"""

from __future__ import annotations

import numpy as np
from numba import njit

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


#: Levels with more entries than this are permuted in tiles (:func:`to_rowmajor`).
_TILED = 16384


@njit(**_NOGIL)
def to_rowmajor(src, perm, offsets, m, lo, hi, out):
    """``out[b] = src[b, perm]`` for rows ``lo..hi-1``: the reversed layout to the row-major one.

    A word of level ``k`` is ``(a, w)``, ``a`` its first ``h = k // 2`` letters: its reversed index is
    ``rev(a) + d^h rev(w)``, its row-major one ``a d^(k-h) + w``; the level is copied in 8 x 8 tiles
    of ``(rev(a), w)`` so that reads and writes both stay within a few cache lines (a gather in
    row-major order measured 5x slower on a 4^8-entry level).
    """
    d = offsets[2]
    kt = 1                                          # levels below kt fit in cache: a plain gather
    while kt <= m and offsets[kt + 1] - offsets[kt] <= _TILED:
        kt += 1
    for b in range(lo, hi):
        for i in range(offsets[kt]):
            out[b, i] = src[b, perm[i]]
    for k in range(kt, m + 1):
        ok = offsets[k]
        h = k // 2
        na = d ** h
        nw = d ** (k - h)
        ra = (perm[offsets[h]:offsets[h] + na] - offsets[h]) * nw + ok
        rw = (perm[offsets[k - h]:offsets[k - h] + nw] - offsets[k - h]) * na + ok
        ua = np.uint64(na - na % 8)
        uw = np.uint64(nw - nw % 8)
        e = np.uint64(8)
        for b in range(lo, hi):
            sb = src[b]
            ob = out[b]
            for r0 in range(np.uint64(0), ua, e):           # 8 x 8 tiles
                for w0 in range(np.uint64(0), uw, e):
                    for r in range(r0, r0 + e):
                        dst = np.uint64(ra[r]) + w0
                        for w in range(e):
                            ob[dst + w] = sb[np.uint64(rw[w0 + w]) + r]
            for r in range(np.uint64(0), np.uint64(na)):       # the edges
                for w in range(uw if r < ua else np.uint64(0), np.uint64(nw)):
                    ob[np.uint64(ra[r]) + w] = sb[np.uint64(rw[w]) + r]
