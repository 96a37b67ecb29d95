"""Naive reference implementations shared by several test modules (independent of the library)."""

import re

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


# A non-commuting pair of smooth fields on R^2 with their exact Jacobians, shared by the rough-driver
# tests (Friz–Oberhauser on fBM, strong rates): V_1 = (sin y2, cos y1), V_2 = (cos(y1 + y2)/2, sin y1).
def trig_fields(y):
    y1, y2 = y[..., 0], y[..., 1]
    V1 = np.stack([np.sin(y2), np.cos(y1)], -1)
    V2 = np.stack([0.5 * np.cos(y1 + y2), np.sin(y1)], -1)
    return np.stack([V1, V2], -1)


def trig_jacobians(y):
    y1, y2 = y[..., 0], y[..., 1]
    z = np.zeros(y.shape[:-1])
    J1 = np.stack([np.stack([z, np.cos(y2)], -1), np.stack([-np.sin(y1), z], -1)], -2)
    s = -0.5 * np.sin(y1 + y2)
    J2 = np.stack([np.stack([s, s], -1), np.stack([np.cos(y1), z], -1)], -2)
    return np.stack([J1, J2], -3)


# Polynomial fields on R^3 with exact Jacobians (elementwise-exact arithmetic, so a batch member's
# values cannot depend on the batch), shared by the batch-independence tests.
def poly_fields(y):
    return np.stack([0.3 * y * y - y[..., ::-1], 0.2 * y[..., [1, 2, 0]] * y], axis=-1)


def poly_jacobians(y):
    e = y.shape[-1]
    J = np.zeros(y.shape[:-1] + (2, e, e))
    idx = np.arange(e)
    J[..., 0, idx, idx] += 0.6 * y
    J[..., 0, idx, idx[::-1]] -= 1.0
    J[..., 1, idx, [1, 2, 0]] += 0.2 * y
    J[..., 1, idx, idx] += 0.2 * y[..., [1, 2, 0]]
    return J


def parse_bracket(label, first_letter=1):
    """Nested pairs of letters from a bracket label such as ``'[1,[1,2]]'`` (iisignature's and esig's
    notation; multi-digit letters allowed), numbered from 0: letter ``first_letter`` becomes 0.
    Raises ``AssertionError`` unless the whole label is one well-formed bracket expression."""
    tokens = re.findall(r"\[|\]|,|\d+|.", label)
    pos = 0

    def tree():
        nonlocal pos
        tok = tokens[pos]
        pos += 1
        if tok != "[":
            return int(tok) - first_letter
        left = tree()
        assert tokens[pos] == ","
        pos += 1
        right = tree()
        assert tokens[pos] == "]"
        pos += 1
        return (left, right)

    out = tree()
    assert pos == len(tokens), label
    return out


def naive_signature_kernel(x, y, order, sigma=None):
    """Signature kernel of one pair by a full-grid solve of the Goursat scheme of pysiglib/sigkernel
    (``K = (K_left + K_below) A - K_diag B``), plain Python loops; ``sigma``: RBF static kernel."""
    if sigma is None:
        G = np.diff(x, axis=0) @ np.diff(y, axis=0).T
    else:
        kap = np.exp(-((x[:, None, :] - y[None, :, :]) ** 2).sum(-1) / (2 * sigma ** 2))
        G = kap[1:, 1:] - kap[1:, :-1] - kap[:-1, 1:] + kap[:-1, :-1]
    S = 2 ** order
    N, M = (x.shape[0] - 1) * S, (y.shape[0] - 1) * S
    K = np.ones((N + 1, M + 1))
    for r in range(1, N + 1):
        for c in range(1, M + 1):
            g = G[(r - 1) // S, (c - 1) // S] / S ** 2
            K[r, c] = (K[r, c - 1] + K[r - 1, c]) * (1 + g / 2 + g * g / 12) - K[r - 1, c - 1] * (1 - g * g / 12)
    return K[N, M]
