"""Numba kernels for :mod:`roughpaths.norms` (private).

Every kernel loops over the flattened batch and over grid pairs ``i < j`` without materialising
an ``n × n`` array: memory is ``O(n d + d²)`` per path, time ``O(n² d)`` (level 1) or ``O(n² d²)``
(level 2). Two-parameter quantities over ``[t_i, t_j]`` are accumulated step by step with Chen's
identity (never as differences of long cumulative sums), so round-off does not grow with the
distance of ``[t_i, t_j]`` from ``t_0``.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def holder_sups(incx, areax, incy, areay, times, alpha, level2, diff, lagw):
    r"""Squared Hölder quotients of a batch (or of a difference of two batches).

    Parameters
    ----------
    incx, incy : (B, N, d) per-step increments (``incy`` ignored unless ``diff``).
    areax, areay : (B, N, d, d) per-step areas (ignored unless ``level2``).
    times : (N + 1,) grid.
    alpha : exponent.
    level2, diff : flags.
    lagw : (N + 1,) or (0,)
        For a uniform grid, ``lagw[k] = (k h)^{2 alpha}`` (saves a ``pow`` per pair); empty for a
        general grid.

    Returns
    -------
    sup1, sup2 : (B,) arrays
        :math:`\sup_{i<j} |Z_{t_i t_j}|^2 / (t_j - t_i)^{2\alpha}` and
        :math:`\sup_{i<j} |\mathbb{Z}_{t_i t_j}|_F^2 / (t_j - t_i)^{4\alpha}` where ``Z = X`` or
        ``X - Y`` (and ``𝕑 = XX`` or ``XX - YY``).
    """
    nb, n, d = incx.shape
    sup1 = np.zeros(nb)
    sup2 = np.zeros(nb)
    x = np.zeros(d)
    y = np.zeros(d)
    a = np.zeros((d, d))
    two_alpha = 2.0 * alpha
    uniform = lagw.shape[0] == n + 1
    for b in range(nb):
        m1 = 0.0
        m2 = 0.0
        for i in range(n):
            for p in range(d):
                x[p] = 0.0
                y[p] = 0.0
                for q in range(d):
                    a[p, q] = 0.0
            for j in range(i + 1, n + 1):
                k = j - 1
                n2 = 0.0
                if level2:
                    # Chen: Z_{i,j} = Z_{i,j-1} + A_k + X_{i,j-1} ⊗ ΔX_k  (minus the same for Y)
                    for p in range(d):
                        for q in range(d):
                            v = areax[b, k, p, q] + x[p] * incx[b, k, q]
                            if diff:
                                v -= areay[b, k, p, q] + y[p] * incy[b, k, q]
                            a[p, q] += v
                            n2 += a[p, q] * a[p, q]
                n1 = 0.0
                for p in range(d):
                    x[p] += incx[b, k, p]
                    if diff:
                        y[p] += incy[b, k, p]
                        z = x[p] - y[p]
                    else:
                        z = x[p]
                    n1 += z * z
                if uniform:
                    w = lagw[j - i]
                else:
                    w = (times[j] - times[i]) ** two_alpha
                r1 = n1 / w
                if r1 > m1:
                    m1 = r1
                if level2:
                    r2 = n2 / (w * w)
                    if r2 > m2:
                        m2 = r2
        sup1[b] = m1
        sup2[b] = m2
    return sup1, sup2


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _box_reach(pj, lo, hi, d):
    """Largest Euclidean distance from ``pj`` to a point of the box ``[lo, hi]``."""
    s = 0.0
    for c in range(d):
        u = abs(pj[c] - lo[c])
        v = abs(pj[c] - hi[c])
        m = u if u > v else v
        s += m * m
    return np.sqrt(s)


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def pvar_level1(paths, p, prune, block):
    r"""Exact p-variation (to the power p) of each path over all partitions by grid points.

    Dynamic programming ``V[j] = max_{i<j} V[i] + |P_j - P_i|^p`` with ``V[0] = 0``; the answer
    is ``V[n]``. With ``prune``, candidates ``i`` are skipped in blocks of ``block`` consecutive
    indices using the upper bound ``V[e] + reach(P_j, box)^p`` where ``e`` is the block's last
    index (``V`` is nondecreasing) and ``box`` the bounding box of the block's points (resp. of
    all points ``P_0..P_e`` for an early exit). The bound never underestimates a candidate, so
    the maximum is unchanged.

    Returns ``(value, prev)``: ``value`` shape (B,), ``prev`` shape (B, n + 1), the optimal
    predecessor of each index (``prev[:, 0] = -1``).
    """
    nb, npts, d = paths.shape
    out = np.zeros(nb)
    prev_all = np.full((nb, npts), -1, dtype=np.int64)
    V = np.zeros(npts)
    nblk = (npts + block - 1) // block
    blo = np.empty((nblk, d))
    bhi = np.empty((nblk, d))
    plo = np.empty((npts, d))
    phi = np.empty((npts, d))
    for b in range(nb):
        P = paths[b]
        if prune:
            for m in range(nblk):
                for c in range(d):
                    blo[m, c] = np.inf
                    bhi[m, c] = -np.inf
            for i in range(npts):
                m = i // block
                for c in range(d):
                    v = P[i, c]
                    if v < blo[m, c]:
                        blo[m, c] = v
                    if v > bhi[m, c]:
                        bhi[m, c] = v
                    if i == 0:
                        plo[i, c] = v
                        phi[i, c] = v
                    else:
                        plo[i, c] = v if v < plo[i - 1, c] else plo[i - 1, c]
                        phi[i, c] = v if v > phi[i - 1, c] else phi[i - 1, c]
        V[0] = 0.0
        for j in range(1, npts):
            best = -1.0
            arg = -1
            top = j - 1
            while top >= 0:
                m = top // block
                start = m * block
                if prune and best >= 0.0:
                    if V[top] + _box_reach(P[j], plo[top], phi[top], d) ** p <= best:
                        break
                    if V[top] + _box_reach(P[j], blo[m], bhi[m], d) ** p <= best:
                        top = start - 1
                        continue
                for i in range(top, start - 1, -1):
                    s = 0.0
                    for c in range(d):
                        z = P[j, c] - P[i, c]
                        s += z * z
                    cand = V[i] + s ** (0.5 * p)
                    if cand > best:
                        best = cand
                        arg = i
                top = start - 1
            V[j] = best
            prev_all[b, j] = arg
        out[b] = V[npts - 1]
    return out, prev_all


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def pvar_level2(inc, areas, q):
    r"""Exact ``sup Σ |XX_{t_i t_{i+1}}|_F^q`` over partitions by grid points (``q = p / 2``).

    Dynamic programming ``W[j] = max_{i<j} W[i] + |XX_{i,j}|^q``; for fixed ``j`` the areas
    ``XX_{i,j}`` are accumulated backwards by Chen,
    ``XX_{i,j} = A_i + XX_{i+1,j} + ΔX_i ⊗ X_{i+1,j}``. Returns ``(value, prev)`` as
    :func:`pvar_level1`.
    """
    nb, n, d = inc.shape
    out = np.zeros(nb)
    prev_all = np.full((nb, n + 1), -1, dtype=np.int64)
    W = np.zeros(n + 1)
    x = np.zeros(d)
    a = np.zeros((d, d))
    half_q = 0.5 * q
    for b in range(nb):
        W[0] = 0.0
        for j in range(1, n + 1):
            for r in range(d):
                x[r] = 0.0
                for c in range(d):
                    a[r, c] = 0.0
            best = -1.0
            arg = -1
            for i in range(j - 1, -1, -1):
                s = 0.0
                for r in range(d):
                    for c in range(d):
                        a[r, c] += areas[b, i, r, c] + inc[b, i, r] * x[c]
                        s += a[r, c] * a[r, c]
                for r in range(d):
                    x[r] += inc[b, i, r]
                cand = W[i] + s ** half_q
                if cand > best:
                    best = cand
                    arg = i
            W[j] = best
            prev_all[b, j] = arg
        out[b] = W[n]
    return out, prev_all


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def holder_level1_pruned(paths, times, alpha, block):
    r"""``sup_{i<j} |P_j - P_i|^2 / (t_j - t_i)^{2α}`` per path, with branch-and-bound.

    For a start ``i``, end points ``j`` are visited in blocks of ``block`` consecutive indices.
    A block (resp. every later point) is skipped when
    ``reach(P_i, box)^2 / (t_j0 - t_i)^{2α} <= best``, where ``box`` is the bounding box of the
    block (resp. of all points from ``j0`` on) and ``j0`` the first index visited in it: every
    skipped quotient has a numerator at most ``reach^2`` and a denominator at least
    ``(t_j0 - t_i)^{2α}``, so the supremum is unchanged.
    """
    nb, npts, d = paths.shape
    out = np.zeros(nb)
    two_alpha = 2.0 * alpha
    nblk = (npts + block - 1) // block
    blo = np.empty((nblk, d))
    bhi = np.empty((nblk, d))
    slo = np.empty((npts, d))
    shi = np.empty((npts, d))
    for b in range(nb):
        P = paths[b]
        for m in range(nblk):
            for c in range(d):
                blo[m, c] = np.inf
                bhi[m, c] = -np.inf
        for i in range(npts - 1, -1, -1):
            m = i // block
            for c in range(d):
                v = P[i, c]
                if v < blo[m, c]:
                    blo[m, c] = v
                if v > bhi[m, c]:
                    bhi[m, c] = v
                if i == npts - 1:
                    slo[i, c] = v
                    shi[i, c] = v
                else:
                    slo[i, c] = v if v < slo[i + 1, c] else slo[i + 1, c]
                    shi[i, c] = v if v > shi[i + 1, c] else shi[i + 1, c]
        best = 0.0
        for i in range(npts - 1):
            j = i + 1
            while j < npts:
                m = j // block
                end = (m + 1) * block
                if end > npts:
                    end = npts
                w = (times[j] - times[i]) ** two_alpha
                if best > 0.0:
                    r = _box_reach(P[i], slo[j], shi[j], d)
                    if r * r / w <= best:
                        break
                    r = _box_reach(P[i], blo[m], bhi[m], d)
                    if r * r / w <= best:
                        j = end
                        continue
                for jj in range(j, end):
                    s = 0.0
                    for c in range(d):
                        z = P[jj, c] - P[i, c]
                        s += z * z
                    q = s / (times[jj] - times[i]) ** two_alpha
                    if q > best:
                        best = q
                j = end
        out[b] = best
    return out
