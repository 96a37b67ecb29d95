"""Independent oracles for the tests of :mod:`mechanics.sphere`: continuous harmonics from scipy, quadrature
from numpy, spin matrices from their definition, and a naive isospectral midpoint rule.

Nothing here calls :mod:`mechanics.sphere` except where a test passes a library function in explicitly.
"""

import numpy as np
import scipy.special as sp


def random_su(rng, N, batch=()):
    """A random su(N) matrix (skew-Hermitian, trace-free), batch first."""
    A = rng.standard_normal(batch + (N, N)) + 1j * rng.standard_normal(batch + (N, N))
    A = A - np.conj(np.swapaxes(A, -1, -2))
    idx = np.arange(N)
    A[..., idx, idx] -= np.trace(A, axis1=-2, axis2=-1)[..., None] / N
    return A


def spin(N):
    """(S1, S2, S3) from the definition: S3 = diag(s, ..., -s), S+|mu> = sqrt(s(s+1) - mu(mu+1)) |mu+1>."""
    s = (N - 1) / 2
    mu = s - np.arange(N)
    splus = np.zeros((N, N), dtype=complex)
    for col in range(1, N):  # |mu_col> -> |mu_col + 1> = |mu_{col-1}>
        splus[col - 1, col] = np.sqrt(s * (s + 1) - mu[col] * (mu[col] + 1))
    sminus = splus.conj().T
    return (splus + sminus) / 2, (splus - sminus) / 2j, np.diag(mu).astype(complex)


def dense_laplacian(P, S):
    """-sum_a [S_a, [S_a, P]] with dense products."""
    out = np.zeros_like(P)
    for s in S:
        c = s @ P - P @ s
        out -= s @ c - c @ s
    return out


def Y(l, m, theta, phi):
    """scipy's orthonormal harmonic with the Condon–Shortley phase (theta colatitude)."""
    return sp.sph_harm_y(l, m, theta, phi)


def dtheta_Y(l, m, theta, phi):
    """d/dtheta Y_lm = m cot(theta) Y_lm + sqrt((l-m)(l+m+1)) e^{-i phi} Y_{l,m+1} (a textbook identity)."""
    up = Y(l, m + 1, theta, phi) if m + 1 <= l else 0.0
    return m / np.tan(theta) * Y(l, m, theta, phi) + np.sqrt((l - m) * (l + m + 1)) * np.exp(-1j * phi) * up


class Field:
    """A band-limited field sum c_lm Y_lm given by a dict {(l, m): c}, with its derivatives."""

    def __init__(self, coeffs):
        self.coeffs = dict(coeffs)

    def __call__(self, theta, phi):
        return sum(c * Y(l, m, theta, phi) for (l, m), c in self.coeffs.items())

    def d_theta(self, theta, phi):
        return sum(c * dtheta_Y(l, m, theta, phi) for (l, m), c in self.coeffs.items())

    def d_phi(self, theta, phi):
        return sum(1j * m * c * Y(l, m, theta, phi) for (l, m), c in self.coeffs.items())

    def laplacian_inverse(self):
        return Field({(l, m): -c / (l * (l + 1)) for (l, m), c in self.coeffs.items() if l > 0})


def bracket(f, g):
    """{f, g} = (f_theta g_phi - f_phi g_theta) / sin(theta), as a function of (theta, phi)."""
    return lambda th, ph: (f.d_theta(th, ph) * g.d_phi(th, ph) - f.d_phi(th, ph) * g.d_theta(th, ph)) / np.sin(th)


def quadrature(L):
    """A grid exact for fields of degree < L (and their products): Gauss–Legendre x uniform longitudes."""
    x, w = np.polynomial.legendre.leggauss(L + 1)
    n_phi = 2 * L + 1
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    th, ph = np.meshgrid(np.arccos(x), phi, indexing="ij")
    return th, ph, w[:, None] * (2 * np.pi / n_phi) * np.ones_like(ph)


def project(func, L, grid_degree=None):
    """Coefficients {(l, m): int func conj(Y_lm) dA} for l < L, on a grid exact for degree < grid_degree."""
    th, ph, wts = quadrature(grid_degree or 2 * L)
    vals = func(th, ph)
    return {(l, m): np.sum(wts * vals * np.conj(Y(l, m, th, ph))) for l in range(L) for m in range(-l, l + 1)}


def flat(coeffs, L):
    """A coefficient dict as the flat array omega[l*(l+1)+m], length L**2."""
    out = np.zeros(L * L, dtype=complex)
    for (l, m), c in coeffs.items():
        if l < L:
            out[l * (l + 1) + m] = c
    return out


def isospectral_midpoint(W, B, h, steps, tol=1e-14, max_iter=100):
    """Modin–Viviani's isospectral midpoint for dW/dt = [B(W), W] (plain numpy; fixed-point iteration).

    W~ = W_n + h/2 [B(W~), W~] + h^2/4 B(W~) W~ B(W~);  W_{n+1} = (I + hB/2) W~ (I - hB/2), B = B(W~).
    """
    eye = np.eye(W.shape[-1])
    for _ in range(steps):
        Wt = W.copy()
        for _ in range(max_iter):
            Bt = B(Wt)
            new = W + 0.5 * h * (Bt @ Wt - Wt @ Bt) + 0.25 * h * h * Bt @ Wt @ Bt
            done = np.max(np.abs(new - Wt)) <= tol * np.max(np.abs(W))
            Wt = new
            if done:
                break
        Bt = B(Wt)
        W = (eye + 0.5 * h * Bt) @ Wt @ (eye - 0.5 * h * Bt)
    return W


def rotation(axis, angle):
    """The rotation matrix about a unit axis by an angle (Rodrigues)."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def rotated(func, R):
    """(theta, phi) -> func at R^T x: the field rotated by R."""
    def out(theta, phi):
        x = np.stack(np.broadcast_arrays(np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)))
        y = np.einsum("ji,j...->i...", R, x)  # R^T x
        th = np.arccos(np.clip(y[2], -1, 1))
        ph = np.mod(np.arctan2(y[1], y[0]), 2 * np.pi)
        return func(th, ph)
    return out


def fitted_slope(ns, errors):
    """Least-squares slope of log(error) against log(n)."""
    return float(np.polyfit(np.log(ns), np.log(errors), 1)[0])
