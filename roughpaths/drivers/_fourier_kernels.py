r"""Numba kernel for the error-controlled Lévy areas of the Brownian driver (private; called by
:class:`roughpaths.drivers.brownian.BrownianDriver` for ``levy_area`` in ``"fourier"``,
``"mrongowius-rossler"``, ``"wiktorsson"`` and ``"auto"``).

Per path and step, with ``w̃ = w/√h``, ``n`` the step's number of Fourier terms and
``a = √(2 s_n)``, ``s_n = Σ_{k>n} 1/k² = ψ'(n + 1)``, it computes the truncated series of
:func:`roughpaths.levy_areas_from_normals` (its docstring and :mod:`roughpaths.drivers.levy_area`
derive it):

* ``P[i, j] = Σ_{k≤n} ξ_ik (η_jk + √2 w̃_j) / k``; ``"fourier"`` and ``"mrongowius-rossler"`` add
  ``a ψ_i w̃_j`` (the ``w``-dependent part of the tail); ``A = P - Pᵀ``;
* ``"mrongowius-rossler"`` and ``"wiktorsson"`` add the antisymmetric ``G``, ``G_ij = a ζ_q``
  (``i < j``, pair ``q`` in ``numpy.triu_indices`` order); ``"wiktorsson"`` also adds
  ``κ Alt((G w̃) ⊗ w̃)``, ``κ = 1/(1 + √(1 + |w̃|²))`` (Wiktorsson's square root of the tail covariance);
* writes ``(h/2π) A + ½ w⊗w`` (``- ½ h I`` for Itô), the full ``d × d`` step area.

Draw order, the area stream of :class:`~roughpaths.BrownianDriver` (unchanged from drawing the
block with ``PathStreams.fill`` and calling :func:`roughpaths.drivers.levy_area.block_areas`): each
path's steps in order; per step ``ξ`` (``d × n``, row ``i`` = component ``i``), ``η`` (``d × n``),
``ψ`` (``d``; fourier and MR), one ``ζ`` per pair ``i < j`` (MR and Wiktorsson). Two paths are
processed together: the normals of their next whole steps, up to ``_CHUNK`` (at least one step) per
path, are drawn at once (:func:`roughpaths.drivers._random._pcg64_fill2`) into a scratch of two rows,
``O(d n)``, then turned into areas step by step; no ``(P, K, width)`` buffer; the states advance in
place (chunking a stream does not change its numbers). Drawing the normals takes ~80% of the time
(d = 5, fourier).
The sums run in a different order than numpy's matrix product, so the areas agree with the numpy
version to round-off (~1e-16 relative), not bitwise. No ``fastmath``; serial (drawing the normals
dominates, and the machine is shared); ``nogil=True``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._random import _pcg64_fill, _pcg64_fill2
from .levy_area import _tail_zeta2

#: Method codes of the kernel.
_CODES = {"fourier": 0, "mrongowius-rossler": 1, "wiktorsson": 2}
#: Normals per path drawn at once (whole steps; at least the widest step): amortises the draw's call
#: (one call per step measured ~2x slower at d = 2 with Mrongowius-Rößler, 23 normals per step).
_CHUNK = 1024


def step_tables(plan: dict, h) -> tuple:
    """Per-step ``(codes, n, widths, a)`` arrays for the step lengths ``h`` from the driver's ``step_plan``
    ``{h: (method, n, width)}``: method code, number of terms, normals per step, tail scale ``√(2 s_n)``."""
    h = np.asarray(h, dtype=np.float64)
    u, inv = np.unique(h, return_inverse=True)
    rows = [plan[float(hv)] for hv in u]
    codes = np.array([_CODES[m] for m, _, _ in rows], dtype=np.int64)
    ns = np.array([n for _, n, _ in rows], dtype=np.int64)
    widths = np.array([w for _, _, w in rows], dtype=np.int64)
    tails = np.array([math.sqrt(2.0 * _tail_zeta2(n)) for _, n, _ in rows])
    inv = inv.reshape(-1)
    return codes[inv], ns[inv], widths[inv], tails[inv]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _fourier_areas(dW, h, codes, ns, widths, tails, states, ito, out):
    """Step areas ``out (P, K, d, d)`` of a block from its increments ``dW (P, K, d)``, step lengths
    ``h (K,)``, the per-step tables of :func:`step_tables` and the paths' area-stream states
    ``(P, 4)`` (advanced in place), as in the module docstring."""
    P, K, d = dW.shape
    wmax = 1
    nmax = 1
    for r in range(K):
        wmax = max(wmax, widths[r])
        nmax = max(nmax, ns[r])
    cap = max(wmax, _CHUNK)
    zrows = np.empty((2, cap))
    words = np.empty((2, cap + 64), dtype=np.uint64)
    inv_k = np.empty(nmax)
    for k in range(nmax):
        inv_k[k] = 1.0 / (k + 1)
    wt = np.empty(d)
    G = np.zeros((d, d))
    Gw = np.empty(d)
    sqrt2 = math.sqrt(2.0)
    kappa = 0.0
    for p in range(0, P, 2):
        lanes = 2 if p + 1 < P else 1
        end = 0                                   # steps [r, end) have their normals in zrows
        off = 0
        for r in range(K):
            if r == end:                          # draw the next steps that fit in the scratch
                tot = 0
                while end < K and tot + widths[end] <= cap:
                    tot += widths[end]
                    end += 1
                if lanes == 2:
                    _pcg64_fill2(states, p, p + 1, zrows[0, :tot], zrows[1, :tot], words[0], words[1])
                else:
                    _pcg64_fill(states, p, zrows[0, :tot], words[0])
                off = 0
            hr = h[r]
            code = codes[r]
            n = ns[r]
            a = tails[r]
            sqh = math.sqrt(hr)
            scale = hr / (2.0 * math.pi)
            half_h = 0.5 * hr if ito else 0.0
            o_xi = off
            o_eta = off + d * n
            o_psi = off + 2 * d * n
            o_pair = o_psi + (d if code != 2 else 0)
            for lane in range(lanes):
                pp = p + lane
                for i in range(d):
                    wt[i] = dW[pp, r, i] / sqh
                if code != 0:                     # G: the Gaussian tail (MR, Wiktorsson)
                    q = 0
                    for i in range(d):
                        for j in range(i + 1, d):
                            g = a * zrows[lane, o_pair + q]
                            G[i, j] = g
                            G[j, i] = -g
                            q += 1
                if code == 2:
                    nw = 0.0
                    for i in range(d):
                        nw += wt[i] * wt[i]
                        acc = 0.0
                        for j in range(d):
                            acc += G[i, j] * wt[j]
                        Gw[i] = acc
                    kappa = 1.0 / (1.0 + math.sqrt(1.0 + nw))
                for i in range(d):
                    Wi = dW[pp, r, i]
                    out[pp, r, i, i] = 0.5 * Wi * Wi - half_h
                    for j in range(i + 1, d):
                        pij = 0.0
                        pji = 0.0
                        wj = sqrt2 * wt[j]
                        wi = sqrt2 * wt[i]
                        for k in range(n):
                            pij += zrows[lane, o_xi + i * n + k] * inv_k[k] * (zrows[lane, o_eta + j * n + k] + wj)
                            pji += zrows[lane, o_xi + j * n + k] * inv_k[k] * (zrows[lane, o_eta + i * n + k] + wi)
                        if code != 2:             # the w-part of the tail (fourier, MR)
                            pij += a * zrows[lane, o_psi + i] * wt[j]
                            pji += a * zrows[lane, o_psi + j] * wt[i]
                        v = pij - pji
                        if code != 0:
                            gij = G[i, j]
                            if code == 2:
                                gij += kappa * Gw[i] * wt[j] - kappa * Gw[j] * wt[i]
                            v += gij
                        v *= scale
                        sym = 0.5 * Wi * dW[pp, r, j]
                        out[pp, r, i, j] = sym + v
                        out[pp, r, j, i] = sym - v
            off += widths[r]
