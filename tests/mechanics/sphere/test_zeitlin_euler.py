"""Zeitlin's model is the Lie–Poisson system of the energy on su(N)*, and it converges to Euler on the sphere.

Statements checked (mechanics.sphere.euler):

* with B(A, C) = -1/2 Re tr(AC), the gradient of h(W) = kappa/4 Re tr(W P) is -kappa P (dh = B(dW, grad h)),
  h >= 0, and the library's Lie–Poisson field [W, grad h] is kappa [P, W] (kappa = 1/hbar: physical time);
* the field of kappa [P, W] converges to the Euler field {omega, psi} (omega = Delta psi) like N^-2 (measured
  -2.01 over N = 16..128; relative error 2.8e-3 at N = 64), while
  Zeitlin's unscaled [P, W] (quantum time) is off by the factor 1/hbar and the opposite sign by 2;
* E = 2 pi/N Re tr(W P) is the kinetic energy 1/2 sum |omega_lm|^2 / (l(l+1)) (solid body: 4 pi Omega^2 / 3);
  the enstrophy and C_2 are exact, C_k -> (-1)^k N/(4 pi) int omega^k dA with relative errors falling like N^-2
  (measured slopes -2.0, k = 3..6, N = 16..128).
Oracles: dense Laplacian from spin matrices, scipy's harmonics and quadrature.
"""

import numpy as np
import pytest

from _sphere_oracles import (Field, bracket, fitted_slope, flat, laplacian_operator, project,
                             quadrature, random_su, spin)
from mechanics.sphere import (ZeitlinHamiltonian, casimirs, coefficients_to_matrix, energy, enstrophy, hbar,
                              matrix_to_coefficients)


def pairing(A, C):
    return -0.5 * np.trace(A @ C).real


def dense_inverse_laplacian(W):
    N = W.shape[-1]
    S = spin(N)
    op = laplacian_operator(N, S)
    P = np.linalg.lstsq(op, W.ravel(), rcond=None)[0].reshape(N, N)  # minimum norm: trace-free
    return P


@pytest.mark.parametrize("time_unit", ["physical", "quantum"])
def test_gradient_sign_and_scale(time_unit, rng):
    N = 7
    H = ZeitlinHamiltonian(N, time_unit=time_unit)
    kappa = 1 / hbar(N) if time_unit == "physical" else 1.0
    assert H.kappa == kappa
    W, V = random_su(rng, N), random_su(rng, N)
    P = dense_inverse_laplacian(W)
    np.testing.assert_allclose(H.stream_matrix(W), P, atol=1e-12)
    np.testing.assert_allclose(H.value_matrix(W), kappa / 4 * np.trace(W @ P).real, rtol=1e-12)
    assert H.value_matrix(W) > 0
    eps = 1e-6
    dh = (H.value_matrix(W + eps * V) - H.value_matrix(W - eps * V)) / (2 * eps)
    grad = H.gradient_matrix(W)
    np.testing.assert_allclose(dh, pairing(V, grad), rtol=1e-7)
    assert abs(dh - pairing(V, -grad)) > 0.5 * abs(dh)  # the other sign is rejected
    assert abs(dh - 0.5 * pairing(V, grad)) > 0.25 * abs(dh)  # and a missing 1/2 in the value
    np.testing.assert_allclose(grad, -kappa * P, atol=1e-12 * kappa)
    np.testing.assert_allclose(H.vector_field(W), W @ grad - grad @ W, atol=1e-12 * kappa)
    np.testing.assert_allclose(H.vector_field(W), kappa * (P @ W - W @ P), atol=1e-11 * kappa)


def test_batches(rng):
    N = 12
    H = ZeitlinHamiltonian(N)
    W = random_su(rng, N, (4,))
    v, g = H.value_matrix(W), H.gradient_matrix(W)
    assert v.shape == (4,) and g.shape == (4, N, N)
    for b in range(4):
        assert np.array_equal(H.value_matrix(W[b]), v[b])
        assert np.array_equal(H.gradient_matrix(W[b]), g[b])
        assert np.array_equal(energy(W[b]), energy(W)[b])
        assert np.array_equal(casimirs(W[b]), casimirs(W)[b])


def test_vector_field_converges_to_euler():
    psi = Field({(1, 0): 0.4, (2, 1): 0.5, (2, -1): -0.5, (3, -2): 0.3j, (3, 2): 0.3j, (4, 0): 0.2})
    omega = Field({(l, m): -l * (l + 1) * c for (l, m), c in psi.coeffs.items()})
    L = 8
    exact = flat(project(bracket(omega, psi), L), L)  # omega_t = {omega, psi}
    ns = [8, 16, 32, 64]
    errs, unscaled, flipped = [], [], []
    for N in ns:
        W = coefficients_to_matrix(flat(omega.coeffs, L), N)
        got = matrix_to_coefficients(ZeitlinHamiltonian(N).vector_field(W), L)
        errs.append(np.linalg.norm(got - exact) / np.linalg.norm(exact))
        unscaled.append(np.linalg.norm(hbar(N) * got - exact) / np.linalg.norm(exact))
        flipped.append(np.linalg.norm(-got - exact) / np.linalg.norm(exact))
    assert -2.2 < fitted_slope(ns[1:], errs[1:]) < -1.8
    assert errs[-1] < 4e-3
    assert min(unscaled) > 0.5 and min(flipped) > 1.8


def test_energy_enstrophy_and_quadratic_casimir(rng):
    N, L = 10, 10
    coeffs = {}
    for l in range(1, L):
        coeffs[(l, 0)] = rng.standard_normal()
        for m in range(1, l + 1):
            c = complex(rng.standard_normal(), rng.standard_normal())
            coeffs[(l, m)], coeffs[(l, -m)] = c, (-1) ** m * np.conj(c)
    W = coefficients_to_matrix(flat(coeffs, L), N)
    e = 0.5 * sum(abs(c) ** 2 / (l * (l + 1)) for (l, m), c in coeffs.items())
    z = 0.5 * sum(abs(c) ** 2 for c in coeffs.values())
    np.testing.assert_allclose(energy(W), e, rtol=1e-12)
    np.testing.assert_allclose(enstrophy(W), z, rtol=1e-12)
    np.testing.assert_allclose(casimirs(W, [2])[0], N / (4 * np.pi) * 2 * z, rtol=1e-12)
    H = ZeitlinHamiltonian(N)
    np.testing.assert_allclose(H.value_matrix(W), H.kappa * N / (8 * np.pi) * e, rtol=1e-12)
    # solid-body rotation Omega about e3: omega = 2 Omega cos(theta), E = 4 pi Omega^2 / 3
    Omega = 0.7
    Wsb = coefficients_to_matrix(flat({(1, 0): 2 * Omega * np.sqrt(4 * np.pi / 3)}, 2), N)
    np.testing.assert_allclose(energy(Wsb), 4 * np.pi * Omega ** 2 / 3, rtol=1e-13)


def test_casimirs_approach_the_vorticity_moments():
    omega = Field({(1, 0): 1.0, (2, 0): 0.7, (2, 1): 0.6, (2, -1): -0.6, (3, 0): 0.8, (3, 3): 0.4j, (3, -3): 0.4j})
    th, ph, wts = quadrature(30)
    vals = omega(th, ph).real
    ns = [8, 16, 32, 64]
    errs = {k: [] for k in (3, 4, 6)}
    for N in ns:
        W = coefficients_to_matrix(flat(omega.coeffs, 4), N)
        c = casimirs(W, (3, 4, 6))
        for k, ck in zip((3, 4, 6), c):
            moment = (-1) ** k * N / (4 * np.pi) * np.sum(wts * vals ** k)
            errs[k].append(abs(ck - moment) / abs(moment))
    for k in (3, 4, 6):
        assert errs[k][-1] < errs[k][0] / 10
        assert fitted_slope(ns[1:], errs[k][1:]) < -1.8
    W = coefficients_to_matrix(flat(omega.coeffs, 4), 8)
    eig = np.linalg.eigvalsh(1j * W)
    np.testing.assert_allclose(casimirs(W, (2, 5)), [np.sum(eig ** 2), np.sum(eig ** 5)], rtol=1e-12)
