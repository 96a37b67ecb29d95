r"""Numba kernel for the Brownian step areas (private; called by :mod:`roughpaths.brownian`).

One call turns pre-drawn standard normals into the level-2 step areas of a chunk of rows
(steps), fusing what :mod:`roughpaths.brownian` used to do with batched numpy products:

* substep increments ``w_k`` (a Brownian bridge pinned to the step increment ``W``:
  ``w_k = √δ (z_k - z̄) + W/m``, ``δ = h/m``; for ``m = 1`` simply ``w_1 = W``);
* space-time Lévy areas ``H_k = √(δ/12) ζ_k``;
* the Chen sum of the conditional means,
  ``A = Σ_k (H_k⊗w_k - w_k⊗H_k) + Alt Σ_{k<l} w_k⊗w_l = g - gᵀ`` with
  ``g = Σ_k (H_k + ½ S_k) ⊗ w_k``, ``S_k = Σ_{l<k} w_l`` (the exclusive running sum);
* for Davie's method, the independent antisymmetric Gaussian ``λ_{ij} h/√(12 m)`` (``i < j``,
  in ``numpy.triu_indices`` order);
* the symmetric part ``½ W⊗W`` and, for Itô, ``-½ h I``.

Conventions as in :mod:`roughpaths.brownian`: ``XX[i, j] = ∫ (W^i - W^i_s) ∘dW^j``, Lévy area
with the ½. The random numbers are drawn by the caller from its ``numpy.random.Generator`` (so
results reproduce from the seed, in the same order as the former numpy implementation); the
kernel is deterministic and its output does not depend on the number of threads. No temporary
larger than ``O(d²)`` per block of rows. No ``fastmath``: round-off matches the numpy reference
to ~1e-16 relative.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# Rows per parallel block (scratch arrays are allocated once per block, not per row).
_BLOCK = 2048


@njit(cache=True, parallel=True)
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
    nblk = (R + _BLOCK - 1) // _BLOCK
    inv_m = 1.0 / m
    inv_s12 = 1.0 / np.sqrt(12.0)
    lam_scale = 1.0 / np.sqrt(12.0 * m)
    for blk in prange(nblk):
        lo = blk * _BLOCK
        hi = min(R, lo + _BLOCK)
        zbar = np.empty(d)
        s = np.empty(d)
        w = np.empty(d)
        a = np.empty(d)
        g = np.empty((d, d))
        for r in range(lo, hi):
            hr = h[r]
            sq = np.sqrt(hr * inv_m)
            sH = sq * inv_s12
            if m > 1:
                for j in range(d):
                    acc = 0.0
                    for k in range(m):
                        acc += z[r, k, j]
                    zbar[j] = acc * inv_m
            for i in range(d):
                s[i] = 0.0
                for j in range(d):
                    g[i, j] = 0.0
            for k in range(m):
                for j in range(d):
                    if m > 1:
                        w[j] = sq * (z[r, k, j] - zbar[j]) + dW[r, j] * inv_m
                    else:
                        w[j] = dW[r, j]
                    a[j] = sH * zeta[r, k, j] + 0.5 * s[j]
                for i in range(d):
                    ai = a[i]
                    for j in range(d):
                        g[i, j] += ai * w[j]
                for j in range(d):
                    s[j] += w[j]
            for i in range(d):
                Wi = dW[r, i]
                for j in range(d):
                    out[r, i, j] = (g[i, j] - g[j, i]) + 0.5 * Wi * dW[r, j]
            if davie:
                c = hr * lam_scale
                p = 0
                for i in range(d):
                    for j in range(i + 1, d):
                        v = lam[r, p] * c
                        out[r, i, j] += v
                        out[r, j, i] -= v
                        p += 1
            if ito:
                for i in range(d):
                    out[r, i, i] -= 0.5 * hr
