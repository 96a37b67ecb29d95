"""Numba kernels for signatures (private; called by :mod:`roughpaths.signature`).

Layout: a truncated signature of a path in ``R^d`` at depth ``m`` is a flat float64 vector of
length ``d + d**2 + ... + d**m`` (levels 1..m concatenated, each level in row-major word order,
no leading 1), exactly as ``iisignature.sig``. ``offsets[k]`` is the start of level ``k``
(``offsets[1] = 0``, ``offsets[m + 1] = sigdim``).

Kernels work on C-contiguous ``(B, n, d)`` batches and write ``(B, sigdim)``. A long path with
a small batch is cut into chunks signed separately and glued back with Chen's identity. The
public kernels below (no leading underscore) are serial, release the GIL and take a range of work
items (``lo, hi``): :mod:`roughpaths._signature_threads` runs ranges on a thread pool whose
calling thread works too, so a busy machine never makes a call wait for a thread that the OS
has not scheduled (numba's ``prange`` waits for every worker).

Precision: no ``fastmath`` (the results must agree with iisignature to 1e-12, and re-association
brings nothing measurable here: the loops are latency- or memory-bound).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# ---------------------------------------------------------------------------------- level 2
# The level-2 signature of a piecewise-linear path y (y_0 = 0) has symmetric part ½ X⊗X (X the
# total increment) and antisymmetric part ½ Σ_k y_{k-1} ∧ y_k (the Lévy area, shoelace formula).
# One pass over the points, d(d-1)/2 accumulators, no temporaries.


@njit(cache=True)
def _area_chunk_d2(x, b, lo, hi, out):
    x0, x1 = x[b, lo, 0], x[b, lo, 1]
    p0 = 0.0
    p1 = 0.0
    a01 = 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        a01 += p0 * y1 - p1 * y0
        p0, p1 = y0, y1
    out[0] = p0
    out[1] = p1
    out[2] = a01


@njit(cache=True)
def _area_chunk_d3(x, b, lo, hi, out):
    x0, x1, x2 = x[b, lo, 0], x[b, lo, 1], x[b, lo, 2]
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    a01 = 0.0
    a02 = 0.0
    a12 = 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        y2 = x[b, k, 2] - x2
        a01 += p0 * y1 - p1 * y0
        a02 += p0 * y2 - p2 * y0
        a12 += p1 * y2 - p2 * y1
        p0, p1, p2 = y0, y1, y2
    out[0] = p0
    out[1] = p1
    out[2] = p2
    out[3] = a01
    out[4] = a02
    out[5] = a12


@njit(cache=True)
def _area_chunk_generic(x, b, lo, hi, out):
    d = x.shape[2]
    prev = np.zeros(d)
    cur = np.empty(d)
    acc = np.zeros(d * (d - 1) // 2)
    for k in range(lo + 1, hi + 1):
        for i in range(d):
            cur[i] = x[b, k, i] - x[b, lo, i]
        q = 0
        for i in range(d):
            for j in range(i + 1, d):
                acc[q] += prev[i] * cur[j] - prev[j] * cur[i]
                q += 1
        for i in range(d):
            prev[i] = cur[i]
    for i in range(d):
        out[i] = prev[i]
    for q in range(acc.shape[0]):
        out[d + q] = acc[q]


@njit(cache=True)
def _area_chunk(x, b, lo, hi, out):
    """Write ``(X, twice the Lévy area over i<j)`` of points ``lo..hi`` of path ``b`` into ``out``."""
    d = x.shape[2]
    if d == 2:
        _area_chunk_d2(x, b, lo, hi, out)
    elif d == 3:
        _area_chunk_d3(x, b, lo, hi, out)
    else:
        _area_chunk_generic(x, b, lo, hi, out)


# ---------------------------------------------------------------------------------- depth >= 3
# Internally level k is stored in *reversed* word order: word (i_1..i_k) at sum_j i_j d^(j-1), so
# that a tensor product a_j ⊗ b_l is out[p + d^j q] = a[p] b[q] with a long, contiguous inner loop
# over p (vectorised). The Python wrapper permutes to iisignature's order at the end.


@njit(cache=True)
def mul_inplace(s, e, d, m, offsets):
    """In place Chen product ``s <- s ⊗ e`` of group-like elements (implicit 1, reversed layout)."""
    for k in range(m, 0, -1):
        ok = offsets[k]
        for r in range(d ** k):
            s[ok + r] += e[ok + r]
        for j in range(1, k):
            # s_k[p + d^j q] += s_j[p] e_{k-j}[q]
            oj = offsets[j]
            oe = offsets[k - j]
            nj = d ** j
            for q in range(d ** (k - j)):
                eq = e[oe + q]
                base = ok + q * nj
                for p in range(nj):
                    s[base + p] += s[oj + p] * eq


# ---------------------------------------------------------------------------------- rough paths
@njit(cache=True)
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


# ---------------------------------------------------------------------------------- log, Lyndon
# Row-major layout (iisignature's): (a_i ⊗ b_j)[p * d^j + q] = a_i[p] b_j[q].


@njit(cache=True)
def _log_one(a, d, m, offsets, r, t):
    """``r <- log(1 + a)`` (row-major, truncated at ``m``) by Horner, ``t`` scratch of the same size.

    ``log(1+a) = a (c_1 + a (c_2 + ... a (c_{m-1} + c_m a)))``, ``c_n = (-1)^(n+1)/n``, written
    with ``a`` on the right: ``r_m = c_m a``, ``r_n = (c_n + r_{n+1}) ⊗ a``. ``r_n`` is multiplied
    by ``a`` ``n - 1`` more times, so only its levels ``<= m - n + 1`` are formed.
    """
    for u in range(offsets[2]):
        r[u] = a[u] * ((-1.0) ** (m + 1) / m)
    for n in range(m - 1, 0, -1):
        c = (-1.0) ** (n + 1) / n
        kmax = m - n + 1
        for k in range(1, kmax + 1):
            ok = offsets[k]
            for u in range(d ** k):
                t[ok + u] = c * a[ok + u]
            for i in range(1, k):
                oi = offsets[i]
                oj = offsets[k - i]
                nj = d ** (k - i)
                for p in range(d ** i):
                    rp = r[oi + p]
                    base = ok + p * nj
                    for q in range(nj):
                        t[base + q] += rp * a[oj + q]
        for u in range(offsets[kmax + 1]):
            r[u] = t[u]


@njit(cache=True)
def _lyndon_one(z, lev_off, lidx, indptr, indices, data, out, out_off):
    for i in range(lidx.shape[0]):
        v = z[lev_off + lidx[i]]
        for t in range(indptr[i], indptr[i + 1]):
            v -= data[t] * out[out_off + indices[t]]
        out[out_off + i] = v


# ---------------------------------------------------------------------------------- lane kernel
# Depth >= 3 signatures across "lanes": LANES work units (a path, or a chunk of a long path)
# advance together, one segment per step; every array is (entries, LANES) flattened, so each
# innermost loop is LANES independent multiply-adds whatever d and the level size. This amortises
# the loop overhead of the short per-level loops (1.2-2.5x over one unit at a time for d = 3..5);
# LLVM does not turn these 8-wide loops into packed SIMD under numba (checked in the assembly:
# scalar vmulsd/vaddsd), which is where pysiglib's remaining 2-4x lead comes from.
# A unit that has run out of segments gets zero increments (exp(0) = 1 leaves it bitwise intact),
# so a unit's result depends only on its own data: the grouping and the number of threads never
# change a bit of the result.
LANES = 8


@njit(cache=True)
def _lane_group(x, ub, ulo, uhi, g, d, m, offsets, s, buf, delta, sc):
    """Signatures (reversed layout, lanes last) of units ``g*LANES ..`` into ``s`` (sigdim*LANES)."""
    L = LANES
    nunits = ub.shape[0]
    half = d ** (m - 1)
    for r in range(s.shape[0]):
        s[r] = 0.0
    steps = 0
    for l in range(L):
        u = g * L + l
        if u < nunits and uhi[u] - ulo[u] > steps:
            steps = uhi[u] - ulo[u]
    for t in range(steps):
        for l in range(L):
            u = g * L + l
            if u < nunits and ulo[u] + t < uhi[u]:
                b = ub[u]
                k = ulo[u] + t + 1
                for i in range(d):
                    delta[i * L + l] = x[b, k, i] - x[b, k - 1, i]
            else:
                for i in range(d):
                    delta[i * L + l] = 0.0
        for lev in range(m, 1, -1):
            inv = 1.0 / lev
            for i in range(d * L):
                buf[i] = delta[i] * inv
            size = d
            cur = 0
            nxt = half * L
            for j in range(1, lev - 1):
                f = 1.0 / (lev - j)
                o = offsets[j] * L
                for r in range(size * L):
                    buf[cur + r] += s[o + r]
                for q in range(d):
                    for l in range(L):
                        sc[l] = delta[q * L + l] * f
                    base = nxt + q * size * L
                    for p in range(size):
                        pl = p * L
                        for l in range(L):
                            buf[base + pl + l] = buf[cur + pl + l] * sc[l]
                size *= d
                cur, nxt = nxt, cur
            o = offsets[lev - 1] * L
            for r in range(size * L):
                buf[cur + r] += s[o + r]
            ok = offsets[lev] * L
            for q in range(d):
                base = ok + q * size * L
                for p in range(size):
                    pl = p * L
                    for l in range(L):
                        s[base + pl + l] += buf[cur + pl + l] * delta[q * L + l]
        for r in range(d * L):
            s[r] += delta[r]


@njit(cache=True)
def _lane_run(x, ub, ulo, uhi, g, d, m, offsets, part):
    L = LANES
    dim = offsets[m + 1]
    s = np.empty(dim * L)
    buf = np.empty(2 * d ** (m - 1) * L)
    delta = np.empty(d * L)
    sc = np.empty(L)
    _lane_group(x, ub, ulo, uhi, g, d, m, offsets, s, buf, delta, sc)
    for l in range(L):
        u = g * L + l
        if u < ub.shape[0]:
            for r in range(dim):
                part[u, r] = s[r * L + l]


@njit(cache=True)
def _glue(part, nchunks, b, m, offsets, out):
    d = offsets[2]
    dim = offsets[m + 1]
    for r in range(dim):
        out[b, r] = part[b * nchunks, r]
    for c in range(1, nchunks):
        mul_inplace(out[b], part[b * nchunks + c], d, m, offsets)


# ---------------------------------------------------------------------------------- gradients
# Vector-Jacobian products, reversed layout (word (i_1..i_k) at sum_j i_j d^(j-1)), so that a
# word u w splits as index(u) + d^|u| index(w). Pairing <G, S> = sum over words (levels 1..m).
# Backward through S = S_prev ⊗ exp(D) per segment (last to first):
#   S_prev = S ⊗ exp(-D)                       (same Horner step, no storage of the forward pass)
#   then backward through the Horner step itself (_step_vjp), which gives both the cotangent of
#   D and G_prev = G ◁ exp(D) for about three Horner steps' work.
# _lcon / _rcon (general contractions) serve the chunk cotangents and the log's backward pass.


@njit(cache=True)
def _horner_step(s, delta, d, m, offsets, buf):
    """``s <- s ⊗ exp(delta)`` in place (reversed layout); ``buf`` scratch of ``2 d^(m-1)``."""
    half = d ** (m - 1)
    for lev in range(m, 1, -1):
        inv = 1.0 / lev
        for i in range(d):
            buf[i] = delta[i] * inv
        size = d
        cur = 0
        nxt = half
        for j in range(1, lev - 1):
            f = 1.0 / (lev - j)
            o = offsets[j]
            for p in range(size):
                buf[cur + p] += s[o + p]
            for q in range(d):
                e = delta[q] * f
                base = nxt + q * size
                for p in range(size):
                    buf[base + p] = buf[cur + p] * e
            size *= d
            cur, nxt = nxt, cur
        o = offsets[lev - 1]
        ok = offsets[lev]
        for p in range(size):
            buf[cur + p] += s[o + p]
        for q in range(d):
            e = delta[q]
            base = ok + q * size
            for p in range(size):
                s[base + p] += buf[cur + p] * e
    for i in range(d):
        s[i] += delta[i]


@njit(cache=True)
def _lcon(x0, s, g, d, m, offsets, out):
    """``out <- (x0 + s) ▷ g``: ``out_j[w] = x0 g_j[w] + sum_{i>=1} sum_u s_i[u] g_{i+j}[u w]``."""
    for j in range(1, m + 1):
        oj = offsets[j]
        nj = d ** j
        for w in range(nj):
            out[oj + w] = x0 * g[oj + w]
        for i in range(1, m - j + 1):
            ni = d ** i
            oi = offsets[i]
            ok = offsets[i + j]
            for w in range(nj):
                base = ok + ni * w
                acc = 0.0
                for u in range(ni):
                    acc += s[oi + u] * g[base + u]
                out[oj + w] += acc


@njit(cache=True)
def _rcon(x0, g, e, d, m, offsets, out):
    """``out <- g ◁ (x0 + e)``: ``out_i[p] = x0 g_i[p] + sum_{j>=1} sum_q g_{i+j}[p q] e_j[q]``."""
    for i in range(1, m + 1):
        oi = offsets[i]
        ni = d ** i
        for p in range(ni):
            out[oi + p] = x0 * g[oi + p]
        for j in range(1, m - i + 1):
            oj = offsets[j]
            ok = offsets[i + j]
            for q in range(d ** j):
                eq = e[oj + q]
                base = ok + ni * q
                for p in range(ni):
                    out[oi + p] += g[base + p] * eq


@njit(cache=True)
def _step_vjp(s, g, delta, d, m, offsets, gprev, tb, ga, gb, gdelta):
    """Backward through one Horner step ``S_cur = S ⊗ exp(delta)`` (``s`` = S before the step).

    Level ``k`` of the step is ``S_k + B_k`` with ``B_1 = delta/k``, ``T_j = B_j + S_j``,
    ``B_{j+1} = T_j ⊗ delta / (k - j)``. Per level: recompute the ``T_j`` (kept in ``tb``, at
    the level offsets), then walk back ``gT_j = (gB_{j+1} ◁ delta)/(k-j)``,
    ``gdelta += (T_j ▷ gB_{j+1})/(k-j)``. ``gprev <- G ◁ exp(delta)`` (cotangent of S) and
    ``gdelta`` (cotangent of delta) are written; ``ga``, ``gb`` are scratch of ``d^m``.
    """
    dim = offsets[m + 1]
    for r in range(dim):
        gprev[r] = g[r]
    for q in range(d):
        gdelta[q] = g[q]
    for k in range(m, 1, -1):
        # forward: T_1 = delta/k + S_1, T_{j+1} = T_j ⊗ delta/(k-j) + S_{j+1}
        inv = 1.0 / k
        for q in range(d):
            tb[q] = delta[q] * inv + s[q]
        size = d
        for j in range(1, k - 1):
            f = 1.0 / (k - j)
            oj = offsets[j]
            on = offsets[j + 1]
            for q in range(d):
                e = delta[q] * f
                base = on + size * q
                for p in range(size):
                    tb[base + p] = tb[oj + p] * e + s[base + p]
            size *= d
        # backward: gB_k = G_k
        ok = offsets[k]
        nk = d ** k
        for r in range(nk):
            ga[r] = g[ok + r]
        for j in range(k - 1, 0, -1):
            f = 1.0 / (k - j)
            nj = d ** j
            oj = offsets[j]
            for p in range(nj):
                gb[p] = 0.0
            for q in range(d):
                e = delta[q] * f
                base = nj * q
                acc = 0.0
                for p in range(nj):
                    gb[p] += ga[base + p] * e
                    acc += ga[base + p] * tb[oj + p]
                gdelta[q] += acc * f
            for p in range(nj):
                gprev[oj + p] += gb[p]
                ga[p] = gb[p]
        for q in range(d):
            gdelta[q] += ga[q] * inv


@njit(cache=True)
def _unit_vjp(x, b, lo, hi, s, g, d, m, offsets, gd):
    """Backward over the segments ``lo..hi`` of path ``b``: ``s`` its signature, ``g`` its cotangent."""
    dim = offsets[m + 1]
    buf = np.empty(2 * d ** m)
    tb = np.empty(dim)
    ga = np.empty(d ** m)
    gb = np.empty(d ** m)
    gn = np.empty(dim)
    delta = np.empty(d)
    neg = np.empty(d)
    gdelta = np.empty(d)
    for k in range(hi, lo, -1):
        for i in range(d):
            delta[i] = x[b, k, i] - x[b, k - 1, i]
            neg[i] = -delta[i]
        _horner_step(s, neg, d, m, offsets, buf)
        _step_vjp(s, g, delta, d, m, offsets, gn, tb, ga, gb, gdelta)
        for i in range(d):
            gd[b, k - 1, i] = gdelta[i]
        for r in range(dim):
            g[r] = gn[r]


@njit(cache=True)
def _unit_cotangent(part, gtot, u, nchunks, d, m, offsets, g):
    """Cotangent of unit ``u``'s signature: ``P ▷ (G ◁ Q)``, P/Q the products of the units before/after."""
    dim = offsets[m + 1]
    b = u // nchunks
    c = u - b * nchunks
    q = np.zeros(dim)
    for cc in range(c + 1, nchunks):
        mul_inplace(q, part[b * nchunks + cc], d, m, offsets)
    tmp = np.empty(dim)
    _rcon(1.0, gtot[b], q, d, m, offsets, tmp)
    pre = np.zeros(dim)
    for cc in range(c):
        mul_inplace(pre, part[b * nchunks + cc], d, m, offsets)
    _lcon(1.0, pre, tmp, d, m, offsets, g)


@njit(cache=True)
def _mul_rev(x0, xs, a, d, m, offsets, out):
    """``out <- (x0 + xs) ⊗ a`` (``a`` with no scalar), reversed layout, levels 1..m."""
    for k in range(1, m + 1):
        ok = offsets[k]
        for r in range(d ** k):
            out[ok + r] = x0 * a[ok + r]
        for i in range(1, k):
            oi = offsets[i]
            oj = offsets[k - i]
            ni = d ** i
            for q in range(d ** (k - i)):
                aq = a[oj + q]
                base = ok + ni * q
                for p in range(ni):
                    out[base + p] += xs[oi + p] * aq


@njit(cache=True)
def _log_vjp_one(a, g, d, m, offsets, ga):
    """``ga <- d/da <g, log(1 + a)>`` (reversed layout), backward through the Horner recursion."""
    dim = offsets[m + 1]
    r = np.zeros((m + 2, dim))
    for u in range(dim):
        r[m, u] = a[u] * ((-1.0) ** (m + 1) / m)
    for n in range(m - 1, 0, -1):
        c = (-1.0) ** (n + 1) / n
        _mul_rev(c, r[n + 1], a, d, m, offsets, r[n])
    gc = g.copy()
    tmp = np.empty(dim)
    for u in range(dim):
        ga[u] = 0.0
    for n in range(1, m):
        c = (-1.0) ** (n + 1) / n
        _lcon(c, r[n + 1], gc, d, m, offsets, tmp)
        for u in range(dim):
            ga[u] += tmp[u]
        _rcon(0.0, gc, a, d, m, offsets, tmp)
        for u in range(dim):
            gc[u] = tmp[u]
    cm = (-1.0) ** (m + 1) / m
    for u in range(dim):
        ga[u] += cm * gc[u]


@njit(cache=True)
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


# ---------------------------------------------------------------------------------- rough-path gradient
@njit(cache=True)
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


# ---------------------------------------------------------------------------------- entry points
# Serial, GIL-free kernels over a range [lo, hi) of work items; results do not depend on the split.
_NOGIL = dict(cache=True, nogil=True)


@njit(**_NOGIL)
def sig2_tasks(x, nchunks, lo, hi, part):
    """``(increment, twice the Lévy area)`` of chunks ``t = lo..hi-1`` (path ``t // nchunks``) into ``part``."""
    n = x.shape[1]
    seg = (n - 1 + nchunks - 1) // nchunks if n > 1 else 0
    for t in range(lo, hi):
        b = t // nchunks
        c = t - b * nchunks
        a = min(c * seg, n - 1)
        e = min(a + seg, n - 1)
        for r in range(part.shape[1]):
            part[t, r] = 0.0
        if e > a:
            _area_chunk(x, b, a, e, part[t])


@njit(**_NOGIL)
def sig2_glue(part, nb, nchunks, d):
    """Level-2 signatures ``(B, d + d*d)`` from the chunk data, glued by Chen: ``2A = 2A_1 + 2A_2 + X_1 ∧ X_2``."""
    width = part.shape[1]
    out = np.empty((nb, d + d * d))
    tot = np.empty(width)
    for b in range(nb):
        for r in range(width):
            tot[r] = 0.0
        for c in range(nchunks):
            p = part[b * nchunks + c]
            q = 0
            for i in range(d):
                for j in range(i + 1, d):
                    tot[d + q] += p[d + q] + tot[i] * p[j] - tot[j] * p[i]
                    q += 1
            for i in range(d):
                tot[i] += p[i]
        for i in range(d):
            out[b, i] = tot[i]
        q = 0
        for i in range(d):
            out[b, d + i * d + i] = 0.5 * tot[i] * tot[i]
            for j in range(i + 1, d):
                sym = 0.5 * tot[i] * tot[j]
                out[b, d + i * d + j] = sym + 0.5 * tot[d + q]
                out[b, d + j * d + i] = sym - 0.5 * tot[d + q]
                q += 1
    return out


@njit(**_NOGIL)
def lane_groups(x, ub, ulo, uhi, m, offsets, lo, hi, part):
    """Signatures (reversed layout) of the units of lane groups ``lo..hi-1`` into ``part`` (units, sigdim)."""
    d = x.shape[2]
    for g in range(lo, hi):
        _lane_run(x, ub, ulo, uhi, g, d, m, offsets, part)


@njit(**_NOGIL)
def lane_glue(part, nb, nchunks, m, offsets):
    """Per path, the Chen product of its units' signatures, in order (reversed layout)."""
    out = np.empty((nb, offsets[m + 1]))
    for b in range(nb):
        _glue(part, nchunks, b, m, offsets, out)
    return out


@njit(**_NOGIL)
def sig_vjp_units(x, ub, ulo, uhi, nchunks, m, offsets, part, gtot, lo, hi, gd):
    """Cotangents of the segment increments of units ``lo..hi-1`` into ``gd`` (B, n-1, d)."""
    d = x.shape[2]
    g = np.empty(offsets[m + 1])
    for u in range(lo, hi):
        _unit_cotangent(part, gtot, u, nchunks, d, m, offsets, g)
        s = part[u].copy()
        _unit_vjp(x, ub[u], ulo[u], uhi[u], s, g, d, m, offsets, gd)


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


@njit(**_NOGIL)
def log_vjp_rows(a, g, d, m, offsets, lo, hi, out):
    """Row-wise :func:`_log_vjp_one` (reversed layout) for rows ``lo..hi-1``."""
    for b in range(lo, hi):
        _log_vjp_one(a[b], g[b], d, m, offsets, out[b])


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


@njit(**_NOGIL)
def rough_vjp_rows(inc, lev, s, g, m, offsets, lo, hi, ginc, glev):
    """Cotangents of the step increments / Lévy areas of paths ``lo..hi-1``."""
    d = inc.shape[2]
    for b in range(lo, hi):
        _rough_vjp_one(inc[b], lev[b], s[b].copy(), g[b].copy(), d, m, offsets, ginc[b], glev[b])


@njit(**_NOGIL)
def scalar_units(x, ub, ulo, uhi, m, offsets, lo, hi, part):
    """Signatures (reversed layout) of units ``lo..hi-1`` one at a time (few units: no idle lanes).

    Same arithmetic, operation for operation, as the lane kernel (bitwise the same result).
    """
    d = x.shape[2]
    buf = np.empty(2 * d ** (m - 1))
    delta = np.empty(d)
    for u in range(lo, hi):
        s = part[u]
        for r in range(s.shape[0]):
            s[r] = 0.0
        b = ub[u]
        for k in range(ulo[u] + 1, uhi[u] + 1):
            for i in range(d):
                delta[i] = x[b, k, i] - x[b, k - 1, i]
            _horner_step(s, delta, d, m, offsets, buf)
