r"""Compiled kernels of the signature kernel (private): the Goursat PDE swept row by row, and its adjoint.

The scheme (the second-order explicit scheme of Salvi et al. 2021, which pysiglib 4.0 and sigkernel use):
on the grid of the two piecewise-linear paths refined ``S = 2**order`` times in each direction,

    K[r, c] = (K[r, c-1] + K[r-1, c]) * A - K[r-1, c-1] * B,    K[0, :] = K[:, 0] = 1,
    A = 1 + g/2 + g²/12,   B = 1 - g²/12,   g = G[p, q] / 4**order,

where ``G[p, q]`` is the static kernel's inner product of the increments of the coarse cell
``(p, q) = ((r-1) >> order, (c-1) >> order)``: ``<x_{p+1} - x_p, y_{q+1} - y_q>`` (linear) or the double
difference ``κ(x_{p+1}, y_{q+1}) - κ(x_{p+1}, y_q) - κ(x_p, y_{q+1}) + κ(x_p, y_q)`` (RBF, ``κ(u, v) =
exp(-|u - v|²/2)`` on paths already divided by σ). The result is ``K`` at the last grid point.

Layout (measured design decision). A *lane group* of ``LANES`` pairs is solved together, the pair
index innermost in every buffer (``(…, LANES)``): the row sweep has a serial dependency along the row
(``K[r, c]`` needs ``K[r, c-1]``), so one pair at a time is latency-bound; ``LANES`` independent pairs
side by side fill packed SIMD registers and hide the latency. Every lane runs the same instructions, so
a pair's value does not depend on which lane, group or thread computed it (padding lanes repeat a
real pair and are discarded). The lane arithmetic uses the packed intrinsics of ``_simd`` (rounded per
operation, no fused multiply-add): with plain ``for l in range(LANES)`` loops numba emitted scalar
``vmulsd`` code, 67 ms for 32 pairs of 256 x 5 paths at order 2 on one thread, against 24 ms now
(pysiglib: 82 ms). ``B`` is stored negated (``NB = -B``) so that ``x - y * B`` is ``x + y * NB``, the same
rounding without a subtraction intrinsic.

Memory: the forward pass keeps two grid rows (``O(m 2**order)`` per pair). The adjoint keeps the grid
rows at the coarse rows (checkpoints, ``O(n m 2**order)``) and recomputes the ``2**order`` refined rows of
one coarse row at a time while it sweeps back, instead of storing the ``O(n m 4**order)`` grid.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

_OPTS = dict(cache=True, nogil=True, no_cfunc_wrapper=True, error_model="numpy", boundscheck=False)
L = LANES


@nb.njit(inline="always")
def _vsub(v, w):
    """``v - w`` exactly (``v + (-1 * w)``; the product is exact)."""
    return vadd(v, vmul(w, vsplat(-1.0)))


@nb.njit(**_OPTS)
def _prepare(X, Y, ia, ib, first, rbf, xg, yg, dx, dy, kap):
    """Gather a group: points ``xg``/``yg`` ``((t * d + c) * L + l)``, increments ``dx``/``dy`` likewise."""
    n, d, m = X.shape[1], X.shape[2], Y.shape[1]
    for l in range(L):
        i, j = ia[first + l], ib[first + l]
        for t in range(n):
            for c in range(d):
                xg[(t * d + c) * L + l] = X[i, t, c]
        for t in range(m):
            for c in range(d):
                yg[(t * d + c) * L + l] = Y[j, t, c]
    for k in range((n - 1) * d * L):
        dx[k] = xg[k + d * L] - xg[k]
    for k in range((m - 1) * d * L):
        dy[k] = yg[k + d * L] - yg[k]
    if rbf:
        _kappa_row(xg, yg, 0, d, kap[0])


@nb.njit(**_OPTS)
def _kappa_row(xg, yg, i, d, out):
    """RBF values ``exp(-|x_i - y_j|²/2)`` for every point ``y_j``, flat ``(m, L)``."""
    m = yg.shape[0] // (d * L)
    for j in range(m):
        for l in range(L):
            s = 0.0
            for c in range(d):
                u = xg[(i * d + c) * L + l] - yg[(j * d + c) * L + l]
                s += u * u
            out[j * L + l] = np.exp(-0.5 * s)


@nb.njit(**_OPTS)
def _coarse_row(dx, dy, kap, p, d, rbf, frac, G, A, NB):
    """``G``, ``A`` and ``NB = -B`` of coarse row ``p`` (columns ``0..m-2``; column ``m-1`` stays 0)."""
    m1 = G.shape[0] // L - 1
    if rbf:
        lo, hi = kap[p & 1], kap[(p + 1) & 1]
        for q in range(m1):
            up = _vsub(vload(hi, (q + 1) * L), vload(lo, (q + 1) * L))
            dn = _vsub(vload(hi, q * L), vload(lo, q * L))
            vstore(G, q * L, _vsub(up, dn))
    else:
        for q in range(m1):
            acc = vmul(vload(dx, p * d * L), vload(dy, q * d * L))
            for c in range(1, d):
                acc = vadd(acc, vmul(vload(dx, (p * d + c) * L), vload(dy, (q * d + c) * L)))
            vstore(G, q * L, acc)
    one, half, twelfth, f = vsplat(1.0), vsplat(0.5), vsplat(1.0 / 12.0), vsplat(frac)
    for q in range(m1):
        g = vmul(vload(G, q * L), f)
        g2 = vmul(vmul(g, g), twelfth)
        vstore(A, q * L, vadd(vadd(one, vmul(half, g)), g2))
        vstore(NB, q * L, vadd(g2, vsplat(-1.0)))          # -(1 - g2), exactly


@nb.njit(**_OPTS)
def _sweep(prev, cur, A, NB, m1, S):
    """One refined grid row ``cur`` from the row before, ``prev`` (flat ``(M, L)``)."""
    left = vsplat(1.0)
    vstore(cur, 0, left)
    c = L
    for q in range(m1):
        a = vload(A, q * L)
        nb_ = vload(NB, q * L)
        diag = vload(prev, c - L)
        for _ in range(S):
            up = vload(prev, c)
            left = vadd(vmul(vadd(left, up), a), vmul(diag, nb_))
            vstore(cur, c, left)
            diag = up
            c += L


@nb.njit(**_OPTS)
def kernel_groups(X, Y, ia, ib, rbf, order, g_lo, g_hi, out):
    """Signature kernels of the pairs ``(X[ia[k]], Y[ib[k]])`` of lane groups ``g_lo..g_hi-1`` into ``out[k]``.

    ``X`` ``(A, n, d)``, ``Y`` ``(B, m, d)`` with ``n, m >= 2``; ``ia``, ``ib`` padded to whole groups.
    """
    n, d, m = X.shape[1], X.shape[2], Y.shape[1]
    S = 1 << order
    frac = 1.0 / float(S * S)
    M = (m - 1) * S + 1
    xg, yg = np.empty(n * d * L), np.empty(m * d * L)
    dx, dy = np.empty(n * d * L), np.empty(m * d * L)
    kap = np.empty((2, m * L))
    G, A, NB = np.zeros(m * L), np.zeros(m * L), np.zeros(m * L)
    rows = np.empty((2, M * L))
    for g in range(g_lo, g_hi):
        first = g * L
        _prepare(X, Y, ia, ib, first, rbf, xg, yg, dx, dy, kap)
        rows[0, :] = 1.0
        cur = 0
        for p in range(n - 1):
            if rbf:
                _kappa_row(xg, yg, p + 1, d, kap[(p + 1) & 1])
            _coarse_row(dx, dy, kap, p, d, rbf, frac, G, A, NB)
            for _ in range(S):
                _sweep(rows[cur], rows[1 - cur], A, NB, m - 1, S)
                cur = 1 - cur
        for l in range(L):
            if first + l < out.shape[0]:
                out[first + l] = rows[cur, (M - 1) * L + l]


@nb.njit(**_OPTS)
def _adjoint_row(lc, ln, K1, K0, A, An, NBn, dA, NdB, order, S, m, seed, dG):
    """Adjoint ``lc`` of refined row ``r`` (grid rows ``K1 = K[r]``, ``K0 = K[r-1]``) from ``ln``, that of row
    ``r + 1`` (coefficients ``An``, ``NBn``); adds ``Λ[r, c] dK[r, c]/dG`` into ``dG``. ``seed``: the cotangent
    of the result, added at the last cell (zero except on the last row)."""
    M = (m - 1) * S + 1
    right = vsplat(0.0)            # Λ[r, c + 1]
    ln_right = vsplat(0.0)         # Λ[r + 1, c + 1]
    k0 = vload(K0, (M - 1) * L)    # K[r - 1, c]
    extra = seed
    zero = vsplat(0.0)
    c = M - 1
    for qc in range(m - 2, -1, -1):
        an_c, da_c, ndb_c = vload(An, qc * L), vload(dA, qc * L), vload(NdB, qc * L)
        acc = vload(dG, qc * L)
        for _ in range(S):
            qn = c >> order
            ln_c = vload(ln, c * L)
            v = vadd(vadd(vmul(right, vload(A, qn * L)), vmul(ln_c, an_c)), vmul(ln_right, vload(NBn, qn * L)))
            v = vadd(v, extra)
            extra = zero
            vstore(lc, c * L, v)
            k0l = vload(K0, (c - 1) * L)
            t = vadd(vmul(vadd(vload(K1, (c - 1) * L), k0), da_c), vmul(k0l, ndb_c))
            acc = vadd(acc, vmul(v, t))
            right, ln_right, k0 = v, ln_c, k0l
            c -= 1
        vstore(dG, qc * L, acc)


@nb.njit(**_OPTS)
def _scatter(xg, yg, dx, dy, kap, p, d, rbf, dG, gxs, gys):
    """Add coarse row ``p``'s cotangent ``dG`` of the static-kernel increments to the points' cotangents."""
    m = yg.shape[0] // (d * L)
    if not rbf:
        for q in range(m - 1):
            w = vload(dG, q * L)
            for c in range(d):
                t = vmul(w, vload(dy, (q * d + c) * L))
                i1, i0 = ((p + 1) * d + c) * L, (p * d + c) * L
                vstore(gxs, i1, vadd(vload(gxs, i1), t))
                vstore(gxs, i0, _vsub(vload(gxs, i0), t))
                u = vmul(w, vload(dx, (p * d + c) * L))
                j1, j0 = ((q + 1) * d + c) * L, (q * d + c) * L
                vstore(gys, j1, vadd(vload(gys, j1), u))
                vstore(gys, j0, _vsub(vload(gys, j0), u))
        return
    # κ(x_i, y_j) enters G[p, q] with sign +1 for (p+1, q+1), (p, q); -1 for (p+1, q), (p, q+1)
    for j in range(m):
        for l in range(L):
            w = 0.0
            if j >= 1:
                w += dG[(j - 1) * L + l]
            if j <= m - 2:
                w -= dG[j * L + l]
            for side in range(2):
                i = p + 1 - side
                wk = (w if side == 0 else -w) * kap[i & 1, j * L + l]
                for c in range(d):
                    u = wk * (xg[(i * d + c) * L + l] - yg[(j * d + c) * L + l])   # dκ/dx_i = -κ (x_i - y_j)
                    gxs[(i * d + c) * L + l] -= u
                    gys[(j * d + c) * L + l] += u


@nb.njit(**_OPTS)
def vjp_groups(X, Y, ia, ib, rbf, order, gout, g_lo, g_hi, gx, gy):
    """Exact gradients of the discretised kernels of lane groups ``g_lo..g_hi-1``.

    ``gout[k]`` is the cotangent of pair ``k``'s kernel; ``gx[k]`` ``(n, d)`` and ``gy[k]`` ``(m, d)`` receive
    the cotangents of its two paths' points (of the paths as passed: already scaled).
    """
    n, d, m = X.shape[1], X.shape[2], Y.shape[1]
    S = 1 << order
    frac = 1.0 / float(S * S)
    M = (m - 1) * S + 1
    P = gout.shape[0]
    xg, yg = np.empty(n * d * L), np.empty(m * d * L)
    dx, dy = np.empty(n * d * L), np.empty(m * d * L)
    kap = np.empty((2, m * L))
    G, dA, NdB = np.zeros(m * L), np.zeros(m * L), np.zeros(m * L)
    A2, NB2 = np.zeros((2, m * L)), np.zeros((2, m * L))      # coefficients of coarse row p in slot p & 1
    dG = np.empty(m * L)
    ck = np.empty((n - 1, M * L))
    blk = np.empty((S + 1, M * L))           # blk[0] unused: row p S is ck[p]
    tmp = np.empty((2, M * L))
    lam = np.empty((2, (M + 1) * L))
    go = np.empty(L)
    gxs, gys = np.empty(n * d * L), np.empty(m * d * L)
    sixth = vsplat(1.0 / 6.0)
    fv = vsplat(frac)
    for g in range(g_lo, g_hi):
        first = g * L
        for l in range(L):
            go[l] = gout[first + l] if first + l < P else 0.0
        _prepare(X, Y, ia, ib, first, rbf, xg, yg, dx, dy, kap)
        gxs[:] = 0.0
        gys[:] = 0.0
        # forward pass, keeping the grid rows at the coarse rows (checkpoints)
        ck[0, :] = 1.0
        for p in range(n - 2):
            if rbf:
                _kappa_row(xg, yg, p + 1, d, kap[(p + 1) & 1])
            A, NB = A2[0], NB2[0]
            _coarse_row(dx, dy, kap, p, d, rbf, frac, G, A, NB)
            for s in range(S):                   # ck[p] -> tmp[0] -> tmp[1] -> ... -> ck[p + 1], no copies
                src = ck[p] if s == 0 else tmp[(s - 1) & 1]
                dst = ck[p + 1] if s == S - 1 else tmp[s & 1]
                _sweep(src, dst, A, NB, m - 1, S)
        # backward pass, coarse row by coarse row, recomputing its refined rows from the checkpoint
        if rbf:
            _kappa_row(xg, yg, n - 1, d, kap[(n - 1) & 1])
        A2[(n - 1) & 1, :] = 0.0                 # "coarse row n - 1": below the grid, zero
        NB2[(n - 1) & 1, :] = 0.0
        lam[:, :] = 0.0
        nxt = 0
        for p in range(n - 2, -1, -1):
            if rbf:
                _kappa_row(xg, yg, p, d, kap[p & 1])
            A, NB, An, NBn = A2[p & 1], NB2[p & 1], A2[(p + 1) & 1], NB2[(p + 1) & 1]
            _coarse_row(dx, dy, kap, p, d, rbf, frac, G, A, NB)
            for q in range(m - 1):
                ndb = vmul(vmul(vmul(vload(G, q * L), fv), sixth), fv)     # -dB/dG
                vstore(NdB, q * L, ndb)
                vstore(dA, q * L, vadd(vmul(vsplat(0.5), fv), ndb))        # dA/dG
            _sweep(ck[p], blk[1], A, NB, m - 1, S)          # blk[s] = K[p S + s]; K[p S] is ck[p]
            for s in range(1, S):
                _sweep(blk[s], blk[s + 1], A, NB, m - 1, S)
            dG[:] = 0.0
            for s in range(S, 0, -1):
                cur = 1 - nxt
                last = s == S
                seed = vload(go, 0) if (last and p == n - 2) else vsplat(0.0)
                _adjoint_row(lam[cur], lam[nxt], blk[s], ck[p] if s == 1 else blk[s - 1], A, An if last else A,
                             NBn if last else NB, dA, NdB, order, S, m, seed, dG)
                nxt = cur
            _scatter(xg, yg, dx, dy, kap, p, d, rbf, dG, gxs, gys)
        for l in range(L):
            k = first + l
            if k < P:
                for t in range(n):
                    for c in range(d):
                        gx[k, t, c] = gxs[(t * d + c) * L + l]
                for t in range(m):
                    for c in range(d):
                        gy[k, t, c] = gys[(t * d + c) * L + l]
