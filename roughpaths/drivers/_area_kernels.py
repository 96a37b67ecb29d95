r"""Numba kernel for the Brownian step areas (private; called by :mod:`roughpaths.drivers.brownian`).

One call turns pre-drawn standard normals into the level-2 step areas of a block of
path-steps:

* substep increments ``w_k`` (a Brownian bridge pinned to the step increment ``W``:
  ``w_k = √δ (z_k - z̄) + W/m``, ``δ = h/m``; for ``m = 1`` simply ``w_1 = W``);
* space-time Lévy areas ``H_k = √(δ/12) ζ_k``;
* the Chen sum of the conditional means,
  ``A = Σ_k (H_k⊗w_k - w_k⊗H_k) + Alt Σ_{k<l} w_k⊗w_l = g - gᵀ`` with
  ``g = Σ_k (H_k + ½ S_k) ⊗ w_k``, ``S_k = Σ_{l<k} w_l`` (the exclusive running sum),
  accumulated for the pairs ``i < j`` only;
* for Davie's method, the independent antisymmetric Gaussian ``λ_{ij} h/√(12 m)`` (``i < j``,
  in ``numpy.triu_indices`` order);
* the symmetric part ``½ W⊗W`` and, for Itô, ``-½ h I``.

Conventions as in :mod:`roughpaths.drivers.brownian`: ``XX[i, j] = ∫ (W^i - W^i_s) ∘dW^j``, Lévy area
with the ½. The random numbers are drawn by the caller (the driver's per-path streams); the
kernel is deterministic. No temporary larger than ``O(d)``.

Serial on purpose: the cost is dominated by drawing the normals (d = 3, m = 1: the six area normals
take about 40 ns per path-step, the arithmetic and the d × d write about 12 ns in the written-out
:func:`_areas_m1_d3`), and the machine is shared. ``nogil=True`` lets callers
overlap it with other work. No ``fastmath``: round-off matches a naive per-step numpy
reimplementation to ~1e-16 relative (``tests/roughpaths/drivers/test_brownian_driver_stream.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._random import _pcg64_fill, _pcg64_fill2, _pcg64_normal


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _scale_accumulate(dW, sqh, x):
    """``dW[p, k] *= sqh[k]`` and ``x[p] += Σ_k dW[p, k]`` in one pass (numpy's middle-axis sum
    measured ~4x the cost of the scaling)."""
    P, K, d = dW.shape
    for p in range(P):
        for k in range(K):
            for j in range(d):
                v = dW[p, k, j] * sqh[k]
                dW[p, k, j] = v
                x[p, j] += v


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _path_normals(states, p, zrows, words):
    """Path ``p``'s normals for the whole block (a row of ``zrows (2, n)``), in stream order.

    Called for ``p = 0, 1, 2, ...`` in turn: at even ``p`` the streams of ``p`` and ``p + 1`` are
    drawn together (:func:`roughpaths.drivers._random._pcg64_fill2`) into the two rows.
    """
    if p % 2 == 0:
        if p + 1 < states.shape[0]:
            _pcg64_fill2(states, p, p + 1, zrows[0], zrows[1], words[0], words[1])
        else:
            _pcg64_fill(states, p, zrows[0], words[0])
    return zrows[p % 2]


@njit(cache=True, inline="always")
def _m1_scratch(h, buf, states):
    """What the ``m = 1`` kernels share: per step ``sqrt(h/12)`` (the space-time area's scale) and
    ``h/sqrt(12)`` (Davie's), whether the normals are drawn in the kernel, their count per step, and the
    scratch rows and words of :func:`_path_normals`."""
    K = h.shape[0]
    draw = states.shape[0] > 0
    na = buf.shape[2]
    zrows = np.empty((2, K * na if draw else 0))
    words = np.empty((2, K * na + 64 if draw else 0), dtype=np.uint64)
    return np.sqrt(h / 12.0), h / np.sqrt(12.0), draw, na, zrows, words


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _areas_m1(dW, h, buf, states, davie, ito, out):
    """:func:`_block_areas` for ``m = 1`` (Davie's own method, ``A = H ∧ W + λ``, no substeps).

    A separate loop nest: inside the general one it measured ~1.5x slower.
    """
    P, K, d = dW.shape
    sHs, cs, draw, na, zrows, words = _m1_scratch(h, buf, states)
    zb = buf
    for p in range(P):
        if draw:
            zb = _path_normals(states, p, zrows, words).reshape((1, K, na))
        for r in range(K):
            hr = h[r]
            sH = sHs[r]
            c = cs[r]
            bp, br = (0, r) if draw else (p, r)
            q = 0
            for i in range(d):
                Wi = dW[p, r, i]
                Hi = sH * zb[bp, br, i]
                out[p, r, i, i] = 0.5 * Wi * Wi - (0.5 * hr if ito else 0.0)
                for j in range(i + 1, d):
                    Wj = dW[p, r, j]
                    v = Hi * Wj - sH * zb[bp, br, j] * Wi
                    if davie:
                        v += zb[bp, br, d + q] * c
                    sym = 0.5 * Wi * Wj
                    out[p, r, i, j] = sym + v
                    out[p, r, j, i] = sym - v
                    q += 1


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _areas_m1_d3(dW, h, buf, states, davie, ito, out):
    """:func:`_areas_m1` for ``d = 3``, the loops over the pairs written out (same operations in the same
    order, so the same bits): the general loop nest measured 27 ns per path-step here, this one 12 ns
    (the rigid body and the heavy top are driven in three dimensions)."""
    P, K, _ = dW.shape
    sHs, cs, draw, na, zrows, words = _m1_scratch(h, buf, states)
    zb = buf
    for p in range(P):
        if draw:
            zb = _path_normals(states, p, zrows, words).reshape((1, K, na))
        bp = 0 if draw else p
        for r in range(K):
            sH = sHs[r]
            c = cs[r]
            diag = 0.5 * h[r] if ito else 0.0
            W0 = dW[p, r, 0]
            W1 = dW[p, r, 1]
            W2 = dW[p, r, 2]
            H0 = sH * zb[bp, r, 0]
            H1 = sH * zb[bp, r, 1]
            H2 = sH * zb[bp, r, 2]
            v01 = H0 * W1 - H1 * W0
            v02 = H0 * W2 - H2 * W0
            v12 = H1 * W2 - H2 * W1
            if davie:
                v01 += zb[bp, r, 3] * c
                v02 += zb[bp, r, 4] * c
                v12 += zb[bp, r, 5] * c
            s01 = 0.5 * W0 * W1
            s02 = 0.5 * W0 * W2
            s12 = 0.5 * W1 * W2
            out[p, r, 0, 0] = 0.5 * W0 * W0 - diag
            out[p, r, 0, 1] = s01 + v01
            out[p, r, 0, 2] = s02 + v02
            out[p, r, 1, 0] = s01 - v01
            out[p, r, 1, 1] = 0.5 * W1 * W1 - diag
            out[p, r, 1, 2] = s12 + v12
            out[p, r, 2, 0] = s02 - v02
            out[p, r, 2, 1] = s12 - v12
            out[p, r, 2, 2] = 0.5 * W2 * W2 - diag


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _block_areas(dW, h, buf, states, m, davie, ito, out):
    """Level-2 step areas of a block ``(P, K)`` of path-steps from the per-step packed normals.

    With the layout of :class:`roughpaths.BrownianDriver`'s
    area stream: ``buf[p, k]`` holds, in this order, the bridge normals ``z`` (``m d``,
    substep-major, only if ``m > 1``), the space-time normals ``ζ`` (``m d``) and, for Davie's
    method, the ``d(d-1)/2`` normals ``λ`` (``numpy.triu_indices`` order).

    Written as loop nests (a per-step helper function taking the arrays measured 3-5x slower:
    array reference counting per call); ``m = 1`` has its own, :func:`_areas_m1`.

    Parameters
    ----------
    dW : (P, K, d) float64
        Step increments.
    h : (K,) float64
        Step sizes.
    buf : (P, K, n_area) or (1, 1, n_area) float64
        Standard normals, ``n_area = (m d if m > 1 else 0) + m d + (d(d-1)/2 if davie else 0)``;
        ignored (any shape ``(1, 1, n_area)``) with ``states``.
    states : (P, 4) uint64 or (0, 4)
        If not empty, the PCG64 states of the paths' area streams (:mod:`roughpaths.drivers._random`):
        each path's ``K n_area`` normals of the block are drawn into a scratch row of the kernel,
        in stream order, instead of read from ``buf`` (same numbers as drawing the block first,
        without a ``(P, K, n_area)`` buffer). The states advance in place.
    m : int
        Substeps per step.
    davie, ito : bool
        Add Davie's independent Gaussian; subtract ``½ h I`` (Itô areas).
    out : (P, K, d, d) float64
        Receives ``A + ½ W⊗W (- ½ h I)``.
    """
    if m == 1:
        if dW.shape[2] == 3:
            _areas_m1_d3(dW, h, buf, states, davie, ito, out)
        else:
            _areas_m1(dW, h, buf, states, davie, ito, out)
        return
    P, K, d = dW.shape
    npair = d * (d - 1) // 2
    inv_m = 1.0 / m
    o_zeta = m * d if m > 1 else 0
    o_lam = o_zeta + m * d
    shift, s, w, a = np.zeros(d), np.empty(d), np.empty(d), np.empty(d)
    A = np.empty(max(npair, 1))
    sHs = np.sqrt(h * (inv_m / 12.0))            # √(δ/12), δ = h/m
    cs = h / np.sqrt(12.0 * m)                   # Davie's scale h/√(12 m)
    draw = states.shape[0] > 0
    na = buf.shape[2]
    zrows = np.empty((2, K * na if draw else 0))
    words = np.empty((2, K * na + 64 if draw else 0), dtype=np.uint64)
    zb = buf
    for p in range(P):
        if draw:
            zb = _path_normals(states, p, zrows, words).reshape((1, K, na))
        for r in range(K):
            hr = h[r]
            sH = sHs[r]
            c = cs[r]
            bp, br = (0, r) if draw else (p, r)
            sq = np.sqrt(hr * inv_m)
            for j in range(d):
                acc = 0.0
                for k in range(m):
                    acc += zb[bp, br, k * d + j]
                shift[j] = sq * acc * inv_m - dW[p, r, j] * inv_m
                s[j] = 0.0
            for q in range(npair):
                A[q] = 0.0
            for k in range(m):
                for j in range(d):
                    w[j] = sq * zb[bp, br, k * d + j] - shift[j]
                    a[j] = sH * zb[bp, br, o_zeta + k * d + j] + 0.5 * s[j]
                    s[j] += w[j]
                q = 0
                for i in range(d):         # (g - gᵀ)_{ij}, g = Σ_k a_k ⊗ w_k
                    for j in range(i + 1, d):
                        A[q] += a[i] * w[j] - a[j] * w[i]
                        q += 1
            q = 0
            for i in range(d):
                Wi = dW[p, r, i]
                out[p, r, i, i] = 0.5 * Wi * Wi - (0.5 * hr if ito else 0.0)
                for j in range(i + 1, d):
                    v = A[q] + (zb[bp, br, o_lam + q] * c if davie else 0.0)
                    sym = 0.5 * Wi * dW[p, r, j]
                    out[p, r, i, j] = sym + v
                    out[p, r, j, i] = sym - v
                    q += 1


# ----------------------------------------------------------------------------- exact d = 2 area
@njit(cache=True, inline="always")
def _exp1(sh, sl, ih, il):
    """An Exp(1) variable from two standard normals, ``(Z1² + Z2²)/2`` (exact: χ²₂/2)."""
    z1, sh, sl = _pcg64_normal(sh, sl, ih, il)
    z2, sh, sl = _pcg64_normal(sh, sl, ih, il)
    return 0.5 * (z1 * z1 + z2 * z2), sh, sl


@njit(cache=True, inline="always")
def _series_area(mu, n_terms, t1, t2, sh, sl, ih, il):
    r"""``a = A/h`` from the series ``a = L + √V Z`` given ``μ = |w|²/h`` (the fallback of the table).

    ``L`` logistic of scale ``1/(2π)`` (``L = log(E₁/E₂)/(2π)``), ``Z ~ N(0, 1)`` and
    ``V = Σ_{k≥1} Γ_k/(2π²k²)``, ``Γ_k ~ Gamma(N_k)`` (0 if ``N_k = 0``), ``N_k ~ Poisson(μ)``
    (derivation in :mod:`roughpaths.drivers.levy_area`). The first ``n_terms`` terms are drawn
    exactly (``N_k`` by exponential arrivals, ``Γ_k`` as ``½ χ²_{2N_k}``), the tail ``Σ_{k>n_terms}``
    by a Gamma variable with its exact mean ``μ t1`` and variance ``2 μ t2`` (Marsaglia–Tsang).
    Draw order: ``Z``; ``E₁, E₂`` (2 normals each); for each ``k``: the arrivals (2 normals each,
    the one past ``μ`` included) then the ``2 N_k`` normals of ``Γ_k``; the tail's normals.
    """
    inv2pi2 = 1.0 / (2.0 * np.pi * np.pi)
    z, sh, sl = _pcg64_normal(sh, sl, ih, il)
    e1, sh, sl = _exp1(sh, sl, ih, il)
    e2, sh, sl = _exp1(sh, sl, ih, il)
    V = 0.0
    for k in range(1, n_terms + 1):
        n = 0                                    # N_k ~ Poisson(mu): unit-rate arrivals in [0, mu]
        tarr, sh, sl = _exp1(sh, sl, ih, il)
        while tarr <= mu:
            n += 1
            e, sh, sl = _exp1(sh, sl, ih, il)
            tarr += e
        g = 0.0
        for _ in range(2 * n):
            x, sh, sl = _pcg64_normal(sh, sl, ih, il)
            g += x * x
        V += 0.5 * g * inv2pi2 / (k * k)
    if mu > 0.0:
        alpha = mu * t1 * t1 / (2.0 * t2)
        theta = 2.0 * t2 / t1
        a = alpha + 1.0 if alpha < 1.0 else alpha
        dd = a - 1.0 / 3.0
        c = 1.0 / np.sqrt(9.0 * dd)
        while True:
            x, sh, sl = _pcg64_normal(sh, sl, ih, il)
            v = 1.0 + c * x
            if v <= 0.0:
                continue
            v = v * v * v
            e, sh, sl = _exp1(sh, sl, ih, il)
            if -e < 0.5 * x * x + dd - dd * v + dd * np.log(v):
                break
        gam = dd * v
        if alpha < 1.0:
            e, sh, sl = _exp1(sh, sl, ih, il)
            gam *= np.exp(-e / alpha)
        V += theta * gam
    return np.log(e1 / e2) / (2.0 * np.pi) + np.sqrt(V) * z, sh, sl


@njit(cache=True, inline="always")
def _table_quantile(table, step, s, z):
    """``g(s, z)`` (``z >= 0``, inside the table): cubic Hermite in ``z``, 4-point Lagrange in ``s``."""
    ns = table.shape[1]
    x = s / step
    i = min(int(x), ns - 3)
    u = x - i
    y = z / step
    j = min(int(y), table.shape[2] - 2)
    v = y - j
    v2 = v * v
    h00 = (2.0 * v - 3.0) * v2 + 1.0
    h10 = (v2 * v - 2.0 * v2 + v) * step
    h01 = (3.0 - 2.0 * v) * v2
    h11 = (v2 * v - v2) * step
    um, u1, u2 = u + 1.0, u - 1.0, u - 2.0
    lw0 = -u * u1 * u2 / 6.0
    lw1 = um * u1 * u2 / 2.0
    lw2 = -um * u * u2 / 2.0
    lw3 = um * u * u1 / 6.0
    g = 0.0
    for q in range(4):
        r = abs(i - 1 + q)                       # g is even in s: row -1 is row 1
        row = h00 * table[0, r, j] + h10 * table[1, r, j] + h01 * table[0, r, j + 1] + h11 * table[1, r, j + 1]
        g += (lw0 if q == 0 else lw1 if q == 1 else lw2 if q == 2 else lw3) * row
    return g


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _exact_areas_d2(dW, h, states, table, step, n_terms, t1, t2, ito, out):
    r"""Exact-in-law d = 2 Lévy areas given the increments, from the per-path area streams.

    For a step of size ``h`` with increment ``w`` and ``μ = |w|²/h``: one normal ``z``, and
    ``A = h g(√μ, |z|) sign(z)`` from the quantile ``table`` (``(2, n, n)``, grid ``step``; see
    :mod:`roughpaths.drivers._levy_table`); outside the table (``√μ`` or ``|z|`` beyond its last node)
    ``A = h a`` with ``a`` from :func:`_series_area` drawn next from the same stream. An empty
    table (``n = 0``) draws every area from the series, without ``z``. ``states`` ``(P, 4)`` advance
    in place; ``out`` ``(P, K, 2, 2)`` receives ``A J + ½ w⊗w (- ½ h I)``.
    """
    P, K, d = dW.shape
    top = step * (table.shape[1] - 1)
    for p in range(P):
        sh, sl, ih, il = states[p, 0], states[p, 1], states[p, 2], states[p, 3]
        for r in range(K):
            hr = h[r]
            w0 = dW[p, r, 0]
            w1 = dW[p, r, 1]
            mu = (w0 * w0 + w1 * w1) / hr
            a = 0.0
            series = table.shape[1] == 0
            if not series:
                z, sh, sl = _pcg64_normal(sh, sl, ih, il)
                s = np.sqrt(mu)
                if s <= top and abs(z) <= top:
                    a = _table_quantile(table, step, s, abs(z))
                    if z < 0.0:
                        a = -a
                else:
                    series = True
            if series:          # one call site: _series_area is inlined once, not twice (compile time)
                a, sh, sl = _series_area(mu, n_terms, t1, t2, sh, sl, ih, il)
            A = hr * a
            sym = 0.5 * w0 * w1
            out[p, r, 0, 0] = 0.5 * w0 * w0 - (0.5 * hr if ito else 0.0)
            out[p, r, 1, 1] = 0.5 * w1 * w1 - (0.5 * hr if ito else 0.0)
            out[p, r, 0, 1] = sym + A
            out[p, r, 1, 0] = sym - A
        states[p, 0] = sh
        states[p, 1] = sl
