"""Naive reference implementations shared by several test modules (independent of the library)."""

import numpy as np


def naive_area(inc, areas, i, j):
    """XX over steps i..j-1 by the iterated-sum definition: Σ_k A_k + Σ_{k<l} ΔX_k ⊗ ΔX_l.

    ``inc`` has shape (N, d) and ``areas`` (N, d, d) (one path); a plain double loop, no Chen.
    """
    d = inc.shape[-1]
    out = np.zeros((d, d))
    for k in range(i, j):
        out += areas[k]
        for l in range(k + 1, j):
            out += np.outer(inc[k], inc[l])
    return out


def rk4_flow(f, y, t, n=40):
    """Classical RK4 for the autonomous ODE y' = f(y) over time t in n equal steps (batched y)."""
    h = t / n
    for _ in range(n):
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return y
