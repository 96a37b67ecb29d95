"""Numba kernel of the coloured-noise sampler (private; called by :mod:`roughpaths.drivers.coloured_noise`)."""

from __future__ import annotations

import numba
import numpy as np

from .coloured_noise_law import _K_UV, _K_XU, _K_XV


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc, area, ygrid, binc, barea):  # pragma: no cover
    """Advance ``y`` (P, n) over S coarse steps of ``msub`` sub-steps each (z: (P, S, msub, n+m))."""
    P, S, msub, k = z.shape
    n = y.shape[1]
    m = k - n
    w = np.empty(k)
    y1 = np.empty(n)
    x = np.empty(n)
    u = np.empty(n)
    v = np.empty(n)
    r = np.empty(n)
    X = np.empty(n)
    BX = np.empty(m)
    b = np.empty(m)
    for p in range(P):
        y0 = y[p].copy()
        for s in range(S):
            X[:] = 0.0
            BX[:] = 0.0
            for i in range(n):
                for j in range(n):
                    area[p, s, i, j] = 0.0
            for i in range(m):
                for j in range(m):
                    barea[p, s, i, j] = 0.0
            for q in range(msub):
                for i in range(k):
                    acc = 0.0
                    for j in range(k):
                        acc += L[i, j] * z[p, s, q, j]
                    w[i] = acc
                for i in range(n):
                    acc = w[i]
                    for j in range(n):
                        acc += Phi[i, j] * y0[j]
                    y1[i] = acc
                for i in range(m):
                    b[i] = w[n + i]
                for i in range(n):
                    acc = y0[i] - y1[i]
                    for j in range(m):
                        acc += D[i, j] * b[j]
                    r[i] = acc
                for i in range(n):
                    acc = 0.0
                    for j in range(n):
                        acc += Ainv[i, j] * r[j]
                    x[i] = eps * acc
                    u[i] = eps * delta * y0[i]
                    v[i] = eps * delta * y1[i]
                for i in range(n):
                    for j in range(n):
                        lev = (-0.1 * (x[i] * u[j] - u[i] * x[j]) + 0.1 * (x[i] * v[j] - v[i] * x[j])
                               - (1.0 / 60.0) * (u[i] * v[j] - v[i] * u[j]))
                        area[p, s, i, j] += 0.5 * x[i] * x[j] + lev + X[i] * x[j]
                for i in range(n):
                    X[i] += x[i]
                for i in range(m):
                    b[i] *= eps
                for i in range(m):
                    for j in range(m):
                        barea[p, s, i, j] += 0.5 * b[i] * b[j] + BX[i] * b[j]
                for i in range(m):
                    BX[i] += b[i]
                for i in range(n):
                    y0[i] = y1[i]
            for i in range(n):
                inc[p, s, i] = X[i]
                ygrid[p, s, i] = y0[i]
            for i in range(m):
                binc[p, s, i] = BX[i]
        for i in range(n):
            y[p, i] = y0[i]
