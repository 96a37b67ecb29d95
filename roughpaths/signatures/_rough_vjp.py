"""Vector–Jacobian product of the signature of a level-2 rough path (private).

Called by :func:`roughpaths.signatures.gradients.rough_path_signature_vjp`. Reversed layout and the
contractions :func:`~roughpaths.signatures._vjp._lcon` / :func:`~roughpaths.signatures._vjp._rcon`
of :mod:`roughpaths.signatures._vjp`; the step exponentials of :mod:`roughpaths.signatures._kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._kernels import _exp_lie2
from ._lanes import mul_inplace
from ._vjp import _lcon, _mul_rev, _rcon

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _rough_vjp_one(inc, lev, s, g, d, m, offsets, ginc, glev):
    """Backward through ``S = prod_k exp(inc_k + lev_k)`` for one path (reversed layout).

    ``s`` is the final signature (overwritten), ``g`` its cotangent (overwritten). Per step, last
    to first: ``S_prev = S ⊗ exp(-z)``, cotangent of ``E = exp(z)`` is ``S_prev ▷ G``,
    ``G <- G ◁ E``, and the cotangent of ``z`` comes from the powers ``P_n = P_{n-1} ⊗ z / n``.
    """
    dim = offsets[m + 1]
    nsteps = inc.shape[0]
    e = np.empty(dim)
    en = np.empty(dim)
    p = np.empty(dim)
    q = np.empty(dim)
    ge = np.empty(dim)
    gn = np.empty(dim)
    z = np.zeros(dim)
    pw = np.zeros((m + 1, dim))
    gp = np.empty(dim)
    gz = np.empty(dim)
    tmp = np.empty(dim)
    neg_x = np.empty(d)
    neg_a = np.empty((d, d))
    o2 = offsets[2] if m >= 2 else 0
    for k in range(nsteps - 1, -1, -1):
        for i in range(d):
            neg_x[i] = -inc[k, i]
            for j in range(d):
                neg_a[i, j] = -lev[k, i, j]
        _exp_lie2(neg_x, neg_a, d, m, offsets, en, p, q)
        mul_inplace(s, en, d, m, offsets)                     # s = S_prev
        _exp_lie2(inc[k], lev[k], d, m, offsets, e, p, q)
        _lcon(1.0, s, g, d, m, offsets, ge)                   # cotangent of E
        _rcon(1.0, g, e, d, m, offsets, gn)
        # powers of z (levels 1 and 2 only)
        for r in range(dim):
            z[r] = 0.0
        for i in range(d):
            z[i] = inc[k, i]
        if m >= 2:
            for i in range(d):
                for j in range(d):
                    z[o2 + i + d * j] = lev[k, i, j]
        for r in range(dim):
            pw[1, r] = z[r]
        for n in range(2, m + 1):
            _mul_rev(0.0, pw[n - 1], z, d, m, offsets, pw[n])
            for r in range(dim):
                pw[n, r] /= n
        # backward: E = sum_n P_n, P_n = P_{n-1} ⊗ z / n
        for r in range(dim):
            gp[r] = ge[r]
            gz[r] = 0.0
        for n in range(m, 1, -1):
            _lcon(0.0, pw[n - 1], gp, d, m, offsets, tmp)      # P_{n-1} ▷ gP_n
            for r in range(dim):
                gz[r] += tmp[r] / n
            _rcon(0.0, gp, z, d, m, offsets, tmp)              # gP_n ◁ z
            for r in range(dim):
                gp[r] = ge[r] + tmp[r] / n
        for r in range(dim):
            gz[r] += gp[r]
        for i in range(d):
            ginc[k, i] = gz[i]
        if m >= 2:
            for i in range(d):
                for j in range(d):
                    glev[k, i, j] = gz[o2 + i + d * j]
        for r in range(dim):
            g[r] = gn[r]


@njit(**_NOGIL)
def rough_vjp_rows(inc, lev, s, g, m, offsets, lo, hi, ginc, glev):
    """Cotangents of the step increments / Lévy areas of paths ``lo..hi-1``."""
    d = inc.shape[2]
    for b in range(lo, hi):
        _rough_vjp_one(inc[b], lev[b], s[b].copy(), g[b].copy(), d, m, offsets, ginc[b], glev[b])
