r"""The bisection of a Lévy-area tree node (private; see :mod:`roughpaths.drivers.tree`).

A node of length ``h`` holds, for each path of the batch, its *polygon* ``w (P, n, d)``: the increments
of the Brownian path over ``n = 2^m`` equal segments of length :math:`\delta = h/n`, and its *tail*
``G (P, d, d)``: the sum of the segments' own Lévy areas (antisymmetric, with the ½), so that Chen's
identity gives the node's increment and Lévy area as

.. math:: W = \sum_i w_i, \qquad A = \tfrac12\sum_{i<j} w_i\wedge w_j + G, \qquad u\wedge v = uv^T - vu^T.

:func:`refine_segments` halves every segment: the midpoint of the Brownian bridge on segment ``i`` is
:math:`w_i/2 + c_i`, :math:`c_i\sim N(0, \tfrac\delta4 I)` (the Lévy–Ciesielski tent), which turns
:math:`w_i` into :math:`x_i' = w_i/2 + c_i`, :math:`x_i'' = w_i/2 - c_i` and adds the Lévy area
:math:`\tfrac12 x_i'\wedge x_i'' = \tfrac12 c_i\wedge w_i` (linear in ``c``). The tail of the ``2n`` new
segments is split between the first ``n`` (``G_L``) and the last ``n`` (``G_R``), and the constraint

.. math:: \tfrac12\sum_i c_i\wedge w_i + G_L + G_R = G

is Chen's identity for the parent. Given the polygon, a segment's Lévy area has conditional mean 0 and
conditional covariance (Lévy; pair coordinates ``i < j``, ``k < l``)

.. math:: \Sigma(\delta, x)^{ij,kl} = \tfrac{\delta}{12}\bigl[\delta(\delta_{ik}\delta_{jl}-\delta_{il}\delta_{jk})
          + \delta_{ik}x_jx_l - \delta_{il}x_jx_k - \delta_{jk}x_ix_l + \delta_{jl}x_ix_k\bigr],

and the split is drawn in two exact Gaussian (Matheron) updates, each a prior draw corrected by
:math:`\mathrm{Cov}(\cdot, y)\mathrm{Cov}(y)^{-1}(\text{target} - y)`:

1. the midpoints ``c`` given the tail ``G``, with the tail of the new segments replaced by a Gaussian of
   its *expected* covariance :math:`\sum_i 2\,E\,\Sigma(\delta/2, w_i/2 \pm c_i)`; then the covariance
   of the constraint is exactly :math:`\sum_i\Sigma(\delta, w_i) = \mathrm{Var}(G\mid w)`, and ``c`` keeps
   its exact second moments :math:`\tfrac\delta4 I` whenever ``G`` has its exact conditional variance;
2. the remaining tail :math:`G - \tfrac12\sum_i c_i\wedge w_i` split between the halves, ``G_L`` and
   ``G_R`` Gaussian with the *realised* covariances :math:`\sum\Sigma(\delta/2, x)` of their new segments.

The constraint then holds to round-off, so Chen's identity holds exactly at every level. The Gaussian
tail and the Gaussian conditioning are the approximations; their measured effect is in the docstring of
:mod:`roughpaths.drivers.tree`. (One update with realised covariances throughout, measured first, gave
the child increments of the root split a variance 2.3 % too high at 10⁶ paths; this version 0.1 %.)
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit

from ._bridge import _pair_solve
from ._random import _fast_streams_ok, _pcg64_normals, _stream_states, stream_prefix

__all__ = ["split_width", "refine_segments", "refine_segments_fast", "polygon_area", "reduce_node",
           "antisym_from_normals", "seed_prefix", "split_seeded"]


def split_width(n: int, d: int) -> int:
    """Standard normals per path consumed by one :func:`refine_segments` of ``n`` segments in ``d`` dims."""
    return 4 * n * d + 3 * (d * (d - 1) // 2)


@lru_cache(maxsize=None)
def _upper(d: int):
    return np.triu_indices(d, 1)


def antisym_from_normals(z, d: int):
    """Antisymmetric ``(P, d, d)`` from ``z (P, d(d-1)/2)`` (entries above the diagonal, row-major)."""
    iu, ju = _upper(d)
    Y = np.zeros((z.shape[0], d, d))
    Y[:, iu, ju] = z
    return Y - np.swapaxes(Y, 1, 2)


def _wedge_sum(X, Y):
    """``Σ_k X_k ∧ Y_k`` over axis 1 of ``X, Y (P, n, d)``: ``(P, d, d)``."""
    Q = np.swapaxes(X, 1, 2) @ Y
    return Q - np.swapaxes(Q, 1, 2)


def polygon_area(w):
    """Lévy area ``(P, d, d)`` of the polygon with segment increments ``w (P, n, d)``: ``½ Σ_{i<j} w_i ∧ w_j``."""
    S = np.cumsum(w, axis=1) - w
    return 0.5 * _wedge_sum(S, w)


def _pair_cov_solve(N, a, R):
    """Antisymmetric ``Y`` with ``Y N + N Y + a Y = R`` (``N (P, d, d)`` symmetric, ``a`` scalar, ``R (P, d, d)``).

    ``Y ↦ Y N + N Y + a Y`` is, in pair coordinates, the covariance ``a I + M(N)`` of the constraint
    (``M(N)`` the covariance of ``Σ_k u_k ∧ α_k``, ``N = Σ u_k u_kᵀ``, ``α_k`` standard normal).
    """
    d = N.shape[-1]
    if d == 2:
        y = R[:, 0, 1] / (a + N[:, 0, 0] + N[:, 1, 1])
        Y = np.zeros_like(R)
        Y[:, 0, 1] = y
        Y[:, 1, 0] = -y
        return Y
    return _pair_solve(N, a, R)


def refine_segments(w, G, delta, z):
    """Halve every segment of the polygon ``w (P, n, d)`` (length ``delta`` each) given the tail ``G (P, d, d)``.

    ``z (P, split_width(n, d))`` are the standard normals of this split. Returns ``(fine, G_L, G_R)``:
    ``fine (P, 2n, d)`` the new polygon (segment ``i`` becomes ``2i, 2i+1``), ``G_L``, ``G_R (P, d, d)`` the
    tails of its first and last ``n`` segments; ``½ Σ c_i ∧ w_i + G_L + G_R = G`` to round-off. This
    numpy version is the readable reference; the tree uses :func:`refine_segments_fast`.
    """
    P, n, d = w.shape
    p = d * (d - 1) // 2
    dp = 0.5 * delta
    k = n * d
    c0 = z[:, :k].reshape(P, n, d) * np.sqrt(0.25 * delta)
    a1 = z[:, k:2 * k].reshape(P, n, d)
    z1 = antisym_from_normals(z[:, 2 * k:2 * k + p], d)
    alpha = z[:, 2 * k + p:4 * k + p].reshape(P, 2 * n, d)
    zl = antisym_from_normals(z[:, 4 * k + p:4 * k + 2 * p], d)
    zr = antisym_from_normals(z[:, 4 * k + 2 * p:4 * k + 3 * p], d)
    # 1. midpoints given G; the new segments' tail a Gaussian of covariance (δ'/12)[2nδ I + M(N_w)/2]
    T0 = np.sqrt(dp / 12.0) * (np.sqrt(2 * n * delta) * z1 + _wedge_sum(w * np.sqrt(0.5), a1))
    K0 = 0.5 * _wedge_sum(c0, w)
    Nw = np.swapaxes(w, 1, 2) @ w
    Y = _pair_cov_solve((delta / 12.0) * Nw, n * delta * delta / 12.0, G - K0 - T0)
    c = c0 + (delta / 8.0) * (w @ np.swapaxes(Y, 1, 2))         # Cov(c_i, <Y, ½ Σ c∧w>) = (δ/8) Y w_i
    fine = np.empty((P, 2 * n, d))
    fine[:, 0::2] = 0.5 * w + c
    fine[:, 1::2] = 0.5 * w - c
    # 2. the rest of the tail split between the halves, realised covariances (δ'/12)[nδ' I + M(Σ x xᵀ)]
    xl, xr = fine[:, :n], fine[:, n:]
    a_half = n * dp * dp / 12.0
    s = dp / 12.0
    GL0 = np.sqrt(a_half) * zl + np.sqrt(s) * _wedge_sum(xl, alpha[:, :n])
    GR0 = np.sqrt(a_half) * zr + np.sqrt(s) * _wedge_sum(xr, alpha[:, n:])
    NL = np.swapaxes(xl, 1, 2) @ xl
    NR = np.swapaxes(xr, 1, 2) @ xr
    Y = _pair_cov_solve(s * (NL + NR), 2.0 * a_half, G - 0.5 * _wedge_sum(c, w) - GL0 - GR0)
    GL = GL0 + a_half * Y + s * (Y @ NL + NL @ Y)
    GR = GR0 + a_half * Y + s * (Y @ NR + NR @ Y)
    return fine, GL, GR


@njit(cache=True, inline="always")
def _spread_pairs(S, d, oy, iY):
    """Rows ``iY .. iY + d - 1`` of ``S`` above the diagonal <- the pair coordinates ``S[oy, :p]`` (row-major
    pairs ``a < b``), below it their negatives: the antisymmetric ``d × d`` matrix (its diagonal is set once)."""
    q = 0
    for a in range(d):
        for b in range(a + 1, d):
            S[iY + a, b] = S[oy, q]
            S[iY + b, a] = -S[oy, q]
            q += 1


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _solve_pairs(S, d, a, oc, oy):
    """In place: ``y <- (a I + M(N))⁻¹ y`` in pair coordinates (Cholesky; the matrix is a covariance).

    ``N = S[:d, :d]``, ``y = S[oy, :p]``; rows ``oc .. oc + p - 1`` of ``S`` hold the factor's lower
    triangle (the only part read). Rows of the split kernel's workspace rather than slices of it: a slice
    is a view, whose reference counting costs about as much as this solve at ``d = 2``. ``p = 1`` and
    ``p = 3`` (``d = 2, 3``) are the loops below written out, the same operations in the same order: 11 and
    30 ns per call against 20 and 86 ns for the loops, for about 0.1 s more compile (about 0.3 s more CPU
    in a tree's first calls, whose kernels link this one). The loops walk the pairs ``i < j`` in row-major
    order by counters (index tables would cost an allocation per call, and numba's compile of it).
    """
    p = d * (d - 1) // 2
    if p == 1:
        L00 = math.sqrt((a + S[1, 1]) + S[0, 0])
        S[oy, 0] = (S[oy, 0] / L00) / L00
        return
    if p == 3:                    # pairs (0, 1), (0, 2), (1, 2); the factor's entries 0.0 + N or 0.0 - N as below
        L00 = math.sqrt((a + S[1, 1]) + S[0, 0])
        L10 = (0.0 + S[2, 1]) / L00
        L11 = math.sqrt(((a + S[2, 2]) + S[0, 0]) - L10 * L10)
        L20 = (0.0 - S[2, 0]) / L00
        L21 = ((0.0 + S[1, 0]) - L20 * L10) / L11
        L22 = math.sqrt((((a + S[2, 2]) + S[1, 1]) - L20 * L20) - L21 * L21)
        y0 = S[oy, 0] / L00
        y1 = (S[oy, 1] - L10 * y0) / L11
        y2 = ((S[oy, 2] - L20 * y0) - L21 * y1) / L22
        y2 = y2 / L22
        y1 = (y1 - L21 * y2) / L11
        S[oy, 0] = ((y0 - L10 * y1) - L20 * y2) / L00
        S[oy, 1] = y1
        S[oy, 2] = y2
        return
    i = 0
    j = 1
    for q in range(p):
        k = 0
        l = 1
        for t in range(p):
            v = a if q == t else 0.0
            if i == k:
                v += S[j, l]
            if j == l:
                v += S[i, k]
            if i == l:
                v -= S[j, k]
            if j == k:
                v -= S[i, l]
            S[oc + q, t] = v
            l += 1
            if l == d:
                k += 1
                l = k + 1
        j += 1
        if j == d:
            i += 1
            j = i + 1
    for q in range(p):
        for t in range(q + 1):
            v = S[oc + q, t]
            for u in range(t):
                v -= S[oc + q, u] * S[oc + t, u]
            S[oc + q, t] = math.sqrt(v) if q == t else v / S[oc + t, t]
    for q in range(p):
        v = S[oy, q]
        for u in range(q):
            v -= S[oc + q, u] * S[oy, u]
        S[oy, q] = v / S[oc + q, q]
    for q in range(p - 1, -1, -1):
        v = S[oy, q]
        for u in range(q + 1, p):
            v -= S[oc + u, q] * S[oy, u]
        S[oy, q] = v / S[oc + q, q]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _refine_segments_nb(w, G, delta, z, fine, GL, GR):
    """:func:`refine_segments` compiled, one path at a time (same formulas; writes ``fine``, ``GL``, ``GR``).

    The numpy version spends most of its time in tiny batched matrix products; this loop is about 10x
    faster at ``P = 2·10⁴``, ``n = 8``, ``d = 2``. The outputs must not overlap the inputs (``fine`` is
    written before ``w`` and ``z`` are read for the last time).

    Written for the adaptive steps' single-path splits (``P = 1``, ``n = 8``) with every product and the
    order of every sum of the earlier, plainer loop nest, so the same bits for finite inputs (the test
    ``test_tree_split_kernel_bits`` keeps that loop nest as its oracle): one workspace instead of twelve
    arrays; the symmetric ``N``, ``N_L``, ``N_R`` summed once per entry ``a <= b`` (``x y == y x``
    exactly) and, in the same pass over the segments, the pair ``a < b``'s other sums; ``G_L``, ``G_R``
    computed above the diagonal only (below it the same operations on negated operands, whose rounding is
    the negated rounding; on the diagonal, terms that cancel exactly); the pair solves written out for
    ``d = 2, 3`` (:func:`_solve_pairs`). Per call at ``P = 1``, ``n = 8`` (min of interleaved repeats of
    2·10⁵ calls, 2-core machine): ``d = 2`` 507 -> 264 ns, ``d = 3`` 863 -> 505 ns, ``d = 1`` 356 -> 144 ns,
    ``d = 4, 5, 6`` 16, 9, 5 % less. First calls of a ``BrownianTree(3)`` on an empty numba cache (shared
    times, then per-path times: the seeded split and the walk, both linking this kernel) take 0.3-0.6 s
    more CPU (10.0 -> 10.3 s, medians of six interleaved runs), about 0.3 s of it the written-out solves.
    Tried and not kept: ``d = 3`` written out whole (one pass per half, every sum in a register), 265 ns for
    about 1.1 s more compile; one pass per entry for all sums including the diagonal's (more work: slower);
    unsigned indices to skip numba's negative-index wrap (about 20 ns at ``d = 3``, a cast on every index).
    """
    P, n, d = w.shape
    p = d * (d - 1) // 2
    k = n * d
    dp = 0.5 * delta
    sc = math.sqrt(0.25 * delta)
    r1 = math.sqrt(dp / 12.0)
    r1z = math.sqrt(2 * n * delta)
    h2 = math.sqrt(0.5)
    a_half = n * dp * dp / 12.0
    ra = math.sqrt(a_half)
    s = dp / 12.0
    rs = math.sqrt(s)
    # the workspace's rows: N, N_L, N_R, Y (d each), c (n), the solve's factor (p), then y, L0, R0 (pair coordinates)
    iL, iR, iY, ic = d, 2 * d, 3 * d, 4 * d
    oc = ic + n
    oy = oc + p
    S = np.empty((oy + 3, max(d, p)))
    for a in range(d):
        S[iY + a, a] = 0.0
    o1, oa, ol = 2 * k, 2 * k + p, 4 * k + p
    for r in range(P):
        # 1. the midpoints given G. N[a, b] once for a <= b (x y == y x: N[b, a] is the same sum), and in the
        # same pass over the segments the pair a < b's sums: independent sums advancing together
        q = 0
        for a in range(d):
            for b in range(a, d):
                v = 0.0
                if a == b:
                    for j in range(n):
                        v += w[r, j, a] * w[r, j, b]
                else:
                    t0 = 0.0
                    kk = 0.0
                    for j in range(n):
                        v += w[r, j, a] * w[r, j, b]
                        t0 += w[r, j, a] * z[r, k + j * d + b] - z[r, k + j * d + a] * w[r, j, b]
                        kk += z[r, j * d + a] * w[r, j, b] - w[r, j, a] * z[r, j * d + b]
                    S[oy, q] = G[r, a, b] - 0.5 * sc * kk - r1 * (r1z * z[r, o1 + q] + h2 * t0)
                    q += 1
                v = (delta / 12.0) * v
                S[a, b] = v
                S[b, a] = v
        _solve_pairs(S, d, n * delta * delta / 12.0, oc, oy)
        _spread_pairs(S, d, oy, iY)
        for i in range(n):
            for a in range(d):
                v = 0.0
                for b in range(d):
                    v += S[iY + a, b] * w[r, i, b]
                ci = z[r, i * d + a] * sc + (delta / 8.0) * v
                S[ic + i, a] = ci
                fine[r, 2 * i, a] = 0.5 * w[r, i, a] + ci
                fine[r, 2 * i + 1, a] = 0.5 * w[r, i, a] - ci
        # 2. the rest of the tail split between the halves (its sums as in step 1)
        q = 0
        for a in range(d):
            for b in range(a, d):
                nl = 0.0
                nr = 0.0
                if a == b:
                    for j in range(n):
                        nl += fine[r, j, a] * fine[r, j, b]
                        nr += fine[r, n + j, a] * fine[r, n + j, b]
                else:
                    gl = 0.0
                    gr = 0.0
                    kk = 0.0
                    for j in range(n):
                        nl += fine[r, j, a] * fine[r, j, b]
                        nr += fine[r, n + j, a] * fine[r, n + j, b]
                        gl += fine[r, j, a] * z[r, oa + j * d + b] - z[r, oa + j * d + a] * fine[r, j, b]
                        gr += (fine[r, n + j, a] * z[r, oa + (n + j) * d + b]
                               - z[r, oa + (n + j) * d + a] * fine[r, n + j, b])
                        kk += S[ic + j, a] * w[r, j, b] - w[r, j, a] * S[ic + j, b]
                    l0 = ra * z[r, ol + q] + rs * gl
                    r0 = ra * z[r, ol + p + q] + rs * gr
                    S[oy + 1, q] = l0
                    S[oy + 2, q] = r0
                    S[oy, q] = G[r, a, b] - 0.5 * kk - l0 - r0
                    q += 1
                S[iL + a, b] = nl
                S[iL + b, a] = nl
                S[iR + a, b] = nr
                S[iR + b, a] = nr
                v = s * (nl + nr)
                S[a, b] = v
                S[b, a] = v
        _solve_pairs(S, d, 2.0 * a_half, oc, oy)
        _spread_pairs(S, d, oy, iY)
        # G_L = L0 + a_half Y + s (Y N_L + N_L Y), antisymmetric: for finite inputs the sum below the diagonal
        # is the negated sum (+0.0 where that is 0), the diagonal +0.0 (Y[a, e] N_L[e, a] - Y[a, e] N_L[a, e])
        q = 0
        for a in range(d):
            GL[r, a, a] = 0.0
            GR[r, a, a] = 0.0
            for b in range(a + 1, d):
                yl = 0.0
                yr = 0.0
                for e in range(d):
                    yl += S[iY + a, e] * S[iL + e, b] + S[iL + a, e] * S[iY + e, b]
                    yr += S[iY + a, e] * S[iR + e, b] + S[iR + a, e] * S[iY + e, b]
                ay = a_half * S[iY + a, b]
                l0 = S[oy + 1, q]
                r0 = S[oy + 2, q]
                GL[r, a, b] = l0 + ay + s * yl
                GR[r, a, b] = r0 + ay + s * yr
                GL[r, b, a] = -l0 - ay + s * (-yl if yl != 0.0 else yl)
                GR[r, b, a] = -r0 - ay + s * (-yr if yr != 0.0 else yr)
                q += 1


def refine_segments_fast(w, G, delta, z):
    """:func:`refine_segments` by the compiled kernel (same arguments and results, to round-off)."""
    P, n, d = w.shape
    fine = np.empty((P, 2 * n, d))
    GL = np.empty((P, d, d))
    GR = np.empty((P, d, d))
    _refine_segments_nb(np.ascontiguousarray(w), np.ascontiguousarray(G), float(delta), np.ascontiguousarray(z),
                        fine, GL, GR)
    return fine, GL, GR


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _reduce_nb(w, G, W, A):
    """``W = Σ_i w_i`` and ``A = ½ Σ_{i<j} w_i ∧ w_j + G`` per path (compiled :func:`polygon_area` plus ``G``)."""
    P, n, d = w.shape
    S = np.empty(d)
    for r in range(P):
        for a in range(d):
            S[a] = 0.0
        for a in range(d):
            for b in range(d):
                A[r, a, b] = G[r, a, b]
        for i in range(n):
            for a in range(d):
                for b in range(a + 1, d):
                    v = 0.5 * (S[a] * w[r, i, b] - S[b] * w[r, i, a])
                    A[r, a, b] += v
                    A[r, b, a] -= v
            for a in range(d):
                S[a] += w[r, i, a]
        for a in range(d):
            W[r, a] = S[a]


def reduce_node(w, G):
    """``(W (P, d), A (P, d, d))`` of a node state ``(w (P, n, d), G (P, d, d))``: Chen over its polygon."""
    P, n, d = w.shape
    W = np.empty((P, d))
    A = np.empty((P, d, d))
    _reduce_nb(w, G, W, A)
    return W, A


def seed_prefix(seed_seq):
    """The entropy words every stream of ``seed_seq`` starts with (uint32), or None off the fast path.

    A stream keyed by ``(tag, path, depth, index_hi, index_lo)`` hashes ``prefix + key`` (as
    :class:`~roughpaths.drivers._random.PathStreams` does for keys of 32-bit words).
    """
    if seed_seq.pool_size != 4 or not _fast_streams_ok():
        return None
    return stream_prefix(seed_seq)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _split_seeded_nb(prefix, paths, tag, depth, index, width, w, G, delta, fine, GL, GR):
    P = w.shape[0]
    m = prefix.size
    ent = np.empty((P, m + 5), dtype=np.uint32)
    for r in range(P):
        for q in range(m):
            ent[r, q] = prefix[q]
        ent[r, m] = tag
        ent[r, m + 1] = paths[r]
        ent[r, m + 2] = depth
        ent[r, m + 3] = index >> 32
        ent[r, m + 4] = index & 0xFFFFFFFF
    states = np.empty((P, 4), dtype=np.uint64)
    _stream_states(ent, states)
    z = np.empty((P, width))
    _pcg64_normals(states, z)
    _refine_segments_nb(w, G, delta, z, fine, GL, GR)


def split_seeded(prefix, paths, tag, depth, index, w, G, delta):
    """:func:`refine_segments_fast` with the normals of stream ``(tag, path, depth, index)`` of each path.

    One compiled call: the streams' seeding, their normals and the split (the same numbers as seeding
    :class:`~roughpaths.drivers._random.PathStreams` with those keys and filling ``split_width`` normals).
    """
    P, n, d = w.shape
    fine = np.empty((P, 2 * n, d))
    GL = np.empty((P, d, d))
    GR = np.empty((P, d, d))
    _split_seeded_nb(prefix, paths, np.int64(tag), np.int64(depth), np.int64(index), split_width(n, d),
                     np.ascontiguousarray(w), np.ascontiguousarray(G), float(delta), fine, GL, GR)
    return fine, GL, GR
