"""The tree's split kernel ``_refine_segments_nb`` gives, bit for bit, the outputs of its earlier loop nest.

``_refine_segments_nb`` (:mod:`roughpaths.drivers._tree_kernels`) was rewritten for speed (one workspace,
symmetric sums computed once, antisymmetric outputs mirrored, the pair solves written out for d = 2, 3)
with every product and the order of every sum kept, so the Brownian tree's nodes, and every answer and
adaptive solve built on them, keep their bits. Here the kernel is checked against a frozen copy of the
earlier version, :func:`_reference_refine` (with its ``_solve_pairs``): ``fine``, ``GL`` and ``GR`` equal
as arrays and as their ``uint64`` bit patterns, for random polygons ``w``, antisymmetric tails ``G`` and
normals ``z``, ``d`` in 1..5, ``n`` in {1, 2, 8, 16}, ``P`` in {1, 3}, ``delta`` in {1, 1e-3}, several
seeds; for inputs scaled far from 1 (d up to 6); and for degenerate finite inputs (zero polygons and
normals, entries of either zero sign, equal coordinates), where the mirrored entries' signs of zero
show. Finite inputs only: the tree never splits a node holding an inf or a NaN.

The frozen copy runs as plain Python (float arithmetic is IEEE double there as in numba, which contracts no
multiply-add), so the module compiles nothing but the kernel the tree compiles anyway.
"""

import math

import numpy as np
import pytest

from roughpaths.drivers._tree_kernels import _refine_segments_nb, split_width


def _reference_solve_pairs(N, a, y, iu, ju, C):
    """``_solve_pairs`` as it was when :func:`_reference_refine` was frozen (do not edit)."""
    p = iu.size
    for q in range(p):
        i, j = iu[q], ju[q]
        for t in range(p):
            k, l = iu[t], ju[t]
            v = a if q == t else 0.0
            if i == k:
                v += N[j, l]
            if j == l:
                v += N[i, k]
            if i == l:
                v -= N[j, k]
            if j == k:
                v -= N[i, l]
            C[q, t] = v
    for q in range(p):
        for t in range(q + 1):
            v = C[q, t]
            for u in range(t):
                v -= C[q, u] * C[t, u]
            C[q, t] = math.sqrt(v) if q == t else v / C[t, t]
    for q in range(p):
        v = y[q]
        for u in range(q):
            v -= C[q, u] * y[u]
        y[q] = v / C[q, q]
    for q in range(p - 1, -1, -1):
        v = y[q]
        for u in range(q + 1, p):
            v -= C[u, q] * y[u]
        y[q] = v / C[q, q]


def _reference_refine(w, G, delta, z, fine, GL, GR):
    """The split kernel as it was before its loops were reordered for speed (frozen copy; do not edit)."""
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
    iu = np.empty(p, dtype=np.int64)
    ju = np.empty(p, dtype=np.int64)
    q = 0
    for i in range(d):
        for j in range(i + 1, d):
            iu[q] = i
            ju[q] = j
            q += 1
    c = np.empty((n, d))
    x = np.empty((2 * n, d))
    NL = np.empty((d, d))
    NR = np.empty((d, d))
    N = np.empty((d, d))
    L0 = np.empty((d, d))
    R0 = np.empty((d, d))
    Y = np.empty((d, d))
    for a in range(d):            # zero diagonals (only the pairs a < b are written below); a loop, not np.zeros,
        for b in range(d):        # whose 2-D overload numba compiles on its own (about 0.3 s)
            L0[a, b] = 0.0
            R0[a, b] = 0.0
            Y[a, b] = 0.0
    C = np.empty((p, p))
    y = np.empty(p)
    o1, oa, ol = 2 * k, 2 * k + p, 4 * k + p
    for r in range(P):
        # 1. the midpoints given G
        for a in range(d):
            for b in range(d):
                v = 0.0
                for j in range(n):
                    v += w[r, j, a] * w[r, j, b]
                N[a, b] = (delta / 12.0) * v
        for q in range(p):
            a, b = iu[q], ju[q]
            t0 = 0.0
            kk = 0.0
            for j in range(n):
                t0 += w[r, j, a] * z[r, k + j * d + b] - z[r, k + j * d + a] * w[r, j, b]
                kk += z[r, j * d + a] * w[r, j, b] - w[r, j, a] * z[r, j * d + b]
            y[q] = G[r, a, b] - 0.5 * sc * kk - r1 * (r1z * z[r, o1 + q] + h2 * t0)
        _reference_solve_pairs(N, n * delta * delta / 12.0, y, iu, ju, C)
        for q in range(p):
            Y[iu[q], ju[q]] = y[q]
            Y[ju[q], iu[q]] = -y[q]
        for i in range(n):
            for a in range(d):
                v = 0.0
                for b in range(d):
                    v += Y[a, b] * w[r, i, b]
                c[i, a] = z[r, i * d + a] * sc + (delta / 8.0) * v
                x[2 * i, a] = 0.5 * w[r, i, a] + c[i, a]
                x[2 * i + 1, a] = 0.5 * w[r, i, a] - c[i, a]
        # 2. the rest of the tail split between the halves
        for a in range(d):
            for b in range(d):
                nl = 0.0
                nr = 0.0
                for j in range(n):
                    nl += x[j, a] * x[j, b]
                    nr += x[n + j, a] * x[n + j, b]
                NL[a, b] = nl
                NR[a, b] = nr
                N[a, b] = s * (nl + nr)
        for q in range(p):
            a, b = iu[q], ju[q]
            gl = 0.0
            gr = 0.0
            kk = 0.0
            for j in range(n):
                gl += x[j, a] * z[r, oa + j * d + b] - z[r, oa + j * d + a] * x[j, b]
                gr += x[n + j, a] * z[r, oa + (n + j) * d + b] - z[r, oa + (n + j) * d + a] * x[n + j, b]
                kk += c[j, a] * w[r, j, b] - w[r, j, a] * c[j, b]
            L0[a, b] = ra * z[r, ol + q] + rs * gl
            R0[a, b] = ra * z[r, ol + p + q] + rs * gr
            L0[b, a] = -L0[a, b]
            R0[b, a] = -R0[a, b]
            y[q] = G[r, a, b] - 0.5 * kk - L0[a, b] - R0[a, b]
        _reference_solve_pairs(N, 2.0 * a_half, y, iu, ju, C)
        for q in range(p):
            Y[iu[q], ju[q]] = y[q]
            Y[ju[q], iu[q]] = -y[q]
        for i in range(2 * n):
            for a in range(d):
                fine[r, i, a] = x[i, a]
        for a in range(d):
            for b in range(d):
                yl = 0.0
                yr = 0.0
                for e in range(d):
                    yl += Y[a, e] * NL[e, b] + NL[a, e] * Y[e, b]
                    yr += Y[a, e] * NR[e, b] + NR[a, e] * Y[e, b]
                GL[r, a, b] = L0[a, b] + a_half * Y[a, b] + s * yl
                GR[r, a, b] = R0[a, b] + a_half * Y[a, b] + s * yr


def _inputs(rng, P, n, d, delta, scale=1.0):
    w = rng.standard_normal((P, n, d)) * math.sqrt(delta) * scale
    G = rng.standard_normal((P, d, d)) * delta * scale * scale
    G = G - np.swapaxes(G, 1, 2)
    z = rng.standard_normal((P, split_width(n, d)))
    return w, G, z


def _both(w, G, delta, z):
    P, n, d = w.shape
    out = []
    for kernel in (_reference_refine, _refine_segments_nb):
        fine, GL, GR = np.empty((P, 2 * n, d)), np.empty((P, d, d)), np.empty((P, d, d))
        kernel(w, G, delta, z, fine, GL, GR)
        out.append((fine, GL, GR))
    return out


def _assert_same_bits(old, new):
    for a, b in zip(old, new):
        assert np.array_equal(a, b)
        np.testing.assert_array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize("d", [1, 2, 3, 4, 5])
def test_split_kernel_keeps_the_bits_of_the_reference(d):
    for seed in range(3):
        rng = np.random.default_rng(1000 * d + seed)
        for n in (1, 2, 8, 16):
            for P in (1, 3):
                for delta in (1.0, 1e-3):
                    w, G, z = _inputs(rng, P, n, d, delta)
                    _assert_same_bits(*_both(w, G, delta, z))


@pytest.mark.parametrize("d", [2, 3, 6])
def test_split_kernel_keeps_the_bits_far_from_unit_scale(d):
    """Large and tiny polygons (a node's G far from its variance): every sum rounds, orders would show."""
    rng = np.random.default_rng(77 + d)
    for scale in (1e-6, 3.7, 1e5):
        for n in (2, 8):
            w, G, z = _inputs(rng, 2, n, d, 0.25, scale)
            _assert_same_bits(*_both(w, G, 0.25, z))


@pytest.mark.parametrize("d", [1, 2, 3, 4])
def test_split_kernel_keeps_the_bits_on_degenerate_inputs(d):
    rng = np.random.default_rng(500 + d)
    for n in (1, 2, 8):
        w, G, z = _inputs(rng, 2, n, d, 0.5)
        w[:, ::2, :] = 0.0
        w[:, :, 0] = w[:, :, -1]                 # equal coordinates: sums that cancel exactly
        z[:, ::3] = 0.0
        z[:, 1::5] = -0.0
        for ww in (w, np.zeros_like(w), -np.zeros_like(w)):
            for zz in (z, np.zeros_like(z), -np.zeros_like(z)):
                for GG in (G, np.zeros_like(G), -np.zeros_like(G)):
                    _assert_same_bits(*_both(ww, GG, 0.5, zz))
