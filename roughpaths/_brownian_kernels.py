r"""Numba kernel for the Brownian step areas (private; called by :mod:`roughpaths.brownian`).

One call turns pre-drawn standard normals into the level-2 step areas of a chunk of rows
(steps), fusing what :mod:`roughpaths.brownian` used to do with batched numpy products:

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

Conventions as in :mod:`roughpaths.brownian`: ``XX[i, j] = ∫ (W^i - W^i_s) ∘dW^j``, Lévy area
with the ½. The random numbers are drawn by the caller from its ``numpy.random.Generator`` (so
results reproduce from the seed, in the same order as the former numpy implementation); the
kernel is deterministic. No temporary larger than ``O(d)``.

Serial on purpose: the cost is dominated by the normals the caller draws (one thread, the
Generator is sequential); the kernel is ~15 % of the total (d = 3, m = 8), and a ``prange``
version measured slower end to end on the shared 2-core machine (idle OpenMP threads spin
while the Generator draws the next chunk). ``nogil=True`` lets callers overlap it with other
work. No ``fastmath``: round-off matches the numpy reference to ~1e-16 relative.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _step_areas(dW, h, z, zeta, lam, m, davie, ito, out):
    """Level-2 step areas of ``R`` rows from pre-drawn standard normals, written into ``out``.

    Parameters
    ----------
    dW : (R, d) float64
        Step increments ``W``.
    h : (R,) float64
        Step sizes.
    z : (R, m, d) float64
        Standard normals for the bridge (ignored, may be ``(0, 1, d)``, when ``m == 1``).
    zeta : (R, m, d) float64
        Standard normals for the space-time Lévy areas.
    lam : (R, P) float64
        Standard normals for Davie's term, ``P = d(d-1)/2`` (ignored unless ``davie``).
    m : int
        Substeps per step.
    davie, ito : bool
        Add Davie's independent Gaussian; subtract ``½ h I`` (Itô areas).
    out : (R, d, d) float64
        Receives ``A + ½ W⊗W (- ½ h I)``.
    """
    R, d = dW.shape
    P = d * (d - 1) // 2
    inv_m = 1.0 / m
    inv_s12 = 1.0 / np.sqrt(12.0)
    lam_scale = 1.0 / np.sqrt(12.0 * m)
    shift = np.zeros(d)      # √δ z̄ - W/m, so that w_k = √δ z_k - shift
    s = np.empty(d)          # S_k = Σ_{l<k} w_l
    w = np.empty(d)
    a = np.empty(d)          # H_k + ½ S_k
    A = np.empty(P)          # Lévy area, pairs i < j in triu order
    for r in range(R):
        hr = h[r]
        sq = np.sqrt(hr * inv_m)
        sH = sq * inv_s12
        if m > 1:
            for j in range(d):
                acc = 0.0
                for k in range(m):
                    acc += z[r, k, j]
                shift[j] = sq * acc * inv_m - dW[r, j] * inv_m
        for j in range(d):
            s[j] = 0.0
        for p in range(P):
            A[p] = 0.0
        for k in range(m):
            if m > 1:
                for j in range(d):
                    w[j] = sq * z[r, k, j] - shift[j]
            else:
                for j in range(d):
                    w[j] = dW[r, j]
            for j in range(d):
                a[j] = sH * zeta[r, k, j] + 0.5 * s[j]
                s[j] += w[j]
            p = 0
            for i in range(d):         # (g - gᵀ)_{ij}, g = Σ_k a_k ⊗ w_k
                for j in range(i + 1, d):
                    A[p] += a[i] * w[j] - a[j] * w[i]
                    p += 1
        c = hr * lam_scale
        p = 0
        for i in range(d):
            Wi = dW[r, i]
            out[r, i, i] = 0.5 * Wi * Wi - (0.5 * hr if ito else 0.0)
            for j in range(i + 1, d):
                v = A[p] + (lam[r, p] * c if davie else 0.0)
                sym = 0.5 * Wi * dW[r, j]
                out[r, i, j] = sym + v
                out[r, j, i] = sym - v
                p += 1
