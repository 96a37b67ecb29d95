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


def laplacian_operator(N, S=None):
    """The Laplacian as an N² x N² matrix acting on flattened matrices, column by column from dense_laplacian."""
    S = spin(N) if S is None else S
    op = np.zeros((N * N, N * N), dtype=complex)
    for k in range(N * N):
        E = np.zeros(N * N, dtype=complex)
        E[k] = 1
        op[:, k] = dense_laplacian(E.reshape(N, N), S).ravel()
    return op


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


def smooth_coefficients(rng, lmax, decay=1.0):
    """Flat coefficients (length (lmax+1)**2) of a random real field of degrees 1..lmax, |omega_lm| ~ l^-decay."""
    L = lmax + 1
    omega = np.zeros(L * L, dtype=complex)
    for l in range(1, L):
        omega[l * (l + 1)] = rng.standard_normal() / l ** decay
        for m in range(1, l + 1):
            c = (rng.standard_normal() + 1j * rng.standard_normal()) / (np.sqrt(2.0) * l ** decay)
            omega[l * (l + 1) + m] = c
            omega[l * (l + 1) - m] = (-1) ** m * np.conj(c)
    return omega


def power_traces(W, orders=(2, 3, 4, 5, 6)):
    """tr((iW)^k) from the eigenvalues of the Hermitian iW (numpy's eigvalsh), and sum |lambda|^k."""
    lam = np.linalg.eigvalsh(1j * W)
    return (np.array([np.sum(lam ** k) for k in orders]), np.array([np.sum(np.abs(lam) ** k) for k in orders]))


class SpectralEuler:
    """A naive pseudo-spectral Galerkin solver of Euler on the sphere, omega_t = {omega, psi}, degrees < L.

    Coefficients omega[l*(l+1)+m]; the bracket (omega_theta psi_phi - omega_phi psi_theta)/sin(theta) is formed on a
    Gauss-Legendre x uniform grid fine enough that the projection of the (band-limited, degree < 2L) bracket
    back onto degrees < L is exact (no aliasing); classical RK4 in time. Harmonics and their theta-derivatives
    from scipy (the identity of dtheta_Y). Independent of mechanics.sphere.
    """
    def __init__(self, L):
        self.L = L
        n_lat = (3 * L) // 2 + 2
        self.n_lon = n_lon = 3 * L
        x, w = np.polynomial.legendre.leggauss(n_lat)
        th = np.arccos(x)
        ls = np.concatenate([[l] * (2 * l + 1) for l in range(L)])
        ms = np.concatenate([np.arange(-l, l + 1) for l in range(L)])
        self.ls, self.ms = ls, ms
        P = sp.sph_harm_y(ls[None, :], ms[None, :], th[:, None], 0.0)           # Pbar_lm(theta_i)
        up = np.where(ms + 1 <= ls, sp.sph_harm_y(ls[None, :], np.minimum(ms + 1, ls)[None, :], th[:, None], 0.0), 0.0)
        dP = ms / np.tan(th)[:, None] * P + np.sqrt(np.maximum((ls - ms) * (ls + ms + 1), 0))[None, :] * up
        self.P, self.dP, self.w, self.sin = P, dP, w, np.sin(th)
        self.col = np.mod(ms, n_lon)
        self.onehot = np.zeros((L * L, n_lon)); self.onehot[np.arange(L * L), self.col] = 1.0
        lap = -(ls * (ls + 1.0)); lap[0] = 1.0
        self.inv_lap = np.where(ls > 0, 1.0 / lap, 0.0)
    def synth(self, c, B):
        F = (B * c[None, :]) @ self.onehot
        return np.fft.ifft(F, axis=1).real * self.n_lon  # real fields
    def analyse(self, f):
        G = np.fft.fft(f, axis=1)[:, self.col] / self.n_lon
        return 2 * np.pi * np.einsum("i,il,il->l", self.w, np.conj(self.P), G)
    def rhs(self, om):
        psi = om * self.inv_lap
        om_t, om_p = self.synth(om, self.dP), self.synth(1j * self.ms * om, self.P)
        ps_t, ps_p = self.synth(psi, self.dP), self.synth(1j * self.ms * psi, self.P)
        return self.analyse((om_t * ps_p - om_p * ps_t) / self.sin[:, None])
    def solve(self, om0, T, n):
        om = np.zeros(self.L ** 2, complex); om[:om0.size] = om0
        h = T / n
        for _ in range(n):
            k1 = self.rhs(om); k2 = self.rhs(om + h / 2 * k1); k3 = self.rhs(om + h / 2 * k2); k4 = self.rhs(om + h * k3)
            om = om + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return om
