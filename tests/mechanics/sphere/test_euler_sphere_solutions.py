"""Closed-form solutions of Euler on the sphere and what Zeitlin's model does with them.

Statements checked:

* the Rossby–Haurwitz wave (solid-body rotation Omega plus a degree-l wave) solves omega_t = {omega, psi} exactly
  when the wave pattern turns at lambda = Omega (1 - 2/(l(l+1))) (continuous check with scipy's harmonics; the
  speeds Omega, -lambda and 0 fail);
* Zeitlin's model (ZeitlinHamiltonian, physical time) reproduces it for every N > l: evolved with classical RK4
  the error is RK4's O(h^4) and the same at every N; the same for the wave turned about a tilted axis (all
  orders m mixed). A naive isospectral midpoint rule (written here) keeps the Casimirs to round-off and has
  order 2, with a constant growing like N^2 in physical time (its Cayley map of the solid-body part);
* zonal flows, also about a tilted axis, are steady: [P, W] = 0 to round-off (a wrong phase on one order
  breaks it); for a profile that is not band-limited (|n.x|^3) the model's steady field differs from the
  continuous one by the truncation, falling like N^-3.5 (measured -3.6), and the evolution keeps it;
* the isospectral rule keeps the Casimirs tr((iW)^k), k = 2..6, to round-off.
"""

import numpy as np
import pytest

from _oracles import rk4_flow
from _sphere_oracles import Field, bracket, fitted_slope, isospectral_midpoint, rotated, rotation
from mechanics.sphere import (RossbyHaurwitzWave, ZeitlinHamiltonian, casimirs, function_to_matrix, matrix_to_grid,
                              sphere_grid)

WAVE = {(4, 1): 0.3 + 0.2j, (4, 3): -0.25j, (4, 0): 0.4}


def drift(N):
    """dW/dt = [B(W), W] with B = -grad h = kappa P."""
    H = ZeitlinHamiltonian(N)
    return lambda W: -H.gradient_matrix(W)


def psi_field(wave, t):
    L = wave.degree + 1
    c = wave.coefficients(t, L)
    coeffs = {}
    for l in range(1, L):
        for m in range(-l, l + 1):
            if abs(c[l * (l + 1) + m]) > 0:
                coeffs[(l, m)] = -c[l * (l + 1) + m] / (l * (l + 1))
    return Field(coeffs), Field({k: -k[0] * (k[0] + 1) * v for k, v in coeffs.items()})


@pytest.mark.parametrize("degree, rotation_rate", [(2, 1.0), (4, 0.7), (5, -1.3)])
def test_rossby_haurwitz_speed_solves_euler(degree, rotation_rate, rng):
    wave = RossbyHaurwitzWave(degree, {(degree, 1): 0.3 + 0.1j, (degree, 2): -0.2}, rotation=rotation_rate)
    assert wave.speed == pytest.approx(rotation_rate * (1 - 2 / (degree * (degree + 1))))
    theta = rng.uniform(0.2, np.pi - 0.2, 50)
    phi = rng.uniform(0, 2 * np.pi, 50)
    t, dt = 0.37, 1e-5
    psi, omega = psi_field(wave, t)
    rhs = bracket(omega, psi)(theta, phi).real
    lhs = (wave.vorticity(theta, phi, t + dt) - wave.vorticity(theta, phi, t - dt)) / (2 * dt)
    np.testing.assert_allclose(lhs, rhs, atol=1e-7 * np.abs(rhs).max())
    np.testing.assert_allclose(omega(theta, phi).real, wave.vorticity(theta, phi, t), atol=1e-12)
    for wrong in (rotation_rate, -wave.speed, 0.0):  # the background speed, the opposite sign, a steady wave
        other = RossbyHaurwitzWave(degree, {(degree, 1): 0.3 + 0.1j, (degree, 2): -0.2}, rotation=rotation_rate)
        other.speed = wrong
        lhs_w = (other.vorticity(theta, phi, t + dt) - other.vorticity(theta, phi, t - dt)) / (2 * dt)
        assert np.abs(lhs_w - rhs).max() > 0.05 * np.abs(rhs).max()


def test_model_reproduces_the_wave_for_every_n():
    """Classical RK4 on dW/dt = kappa [P, W]: the error is RK4's alone, the same at every N (exactness in N)."""
    wave = RossbyHaurwitzWave(4, WAVE, rotation=0.5)
    T = 1.0
    errs = {}
    for N in (6, 12, 24):
        H = ZeitlinHamiltonian(N)
        for steps in (50, 100):
            W = rk4_flow(H.vector_field, wave.matrix(0.0, N), T, steps)
            exact = wave.matrix(T, N)
            errs[(N, steps)] = np.linalg.norm(W - exact) / np.linalg.norm(exact)
    for N in (6, 12, 24):
        assert 12 < errs[(N, 50)] / errs[(N, 100)] < 20  # RK4's h^4, nothing else
        np.testing.assert_allclose(errs[(N, 100)], errs[(6, 100)], rtol=1e-3)  # no error from N
    assert errs[(24, 100)] < 1e-9
    # the speed without the 2/(l(l+1)) correction is far off
    wrong = RossbyHaurwitzWave(4, WAVE, rotation=0.5)
    wrong.speed = 0.5
    W = rk4_flow(ZeitlinHamiltonian(12).vector_field, wave.matrix(0.0, 12), T, 50)
    assert np.linalg.norm(W - wrong.matrix(T, 12)) / np.linalg.norm(W) > 1e-2


def test_isospectral_midpoint_keeps_casimirs_and_has_order_two():
    """The naive isospectral midpoint: Casimirs to round-off, error O(h^2); its constant grows like N^2 in
    physical time (the Cayley map of the solid-body part kappa P ~ Omega S_3 turns weight mu by
    2 arctan(h Omega mu / 2), not h Omega mu), which the exact exponential of that part would not have."""
    wave = RossbyHaurwitzWave(4, WAVE, rotation=0.5)
    T = 1.0
    errs = {}
    for N in (6, 12):
        W0 = wave.matrix(0.0, N)
        exact = wave.matrix(T, N)
        for steps in (25, 50):
            W = isospectral_midpoint(W0, drift(N), T / steps, steps)
            errs[(N, steps)] = np.linalg.norm(W - exact) / np.linalg.norm(exact)
        c0, c1 = casimirs(W0), casimirs(W)
        np.testing.assert_allclose(c1, c0, rtol=1e-12, atol=1e-12 * np.abs(c0).max())
        assert 3.6 < errs[(N, 25)] / errs[(N, 50)] < 4.4
    assert 3 < errs[(12, 50)] / errs[(6, 50)] < 6.5
    assert errs[(12, 50)] < 3e-4


def test_tilted_wave_mixes_all_orders_and_is_reproduced():
    wave = RossbyHaurwitzWave(3, {(3, 2): 0.5, (3, 1): 0.2j}, rotation=0.4)
    R = rotation([1.0, 1.0, 0.3], 0.8)
    N, T, steps = 10, 1.0, 100
    W0 = function_to_matrix(rotated(lambda th, ph: wave.vorticity(th, ph, 0.0), R), N)
    assert np.count_nonzero(np.abs(np.diag(W0, 3)) > 1e-8) > 0  # the tilt fills other diagonals
    W = rk4_flow(ZeitlinHamiltonian(N).vector_field, W0, T, steps)
    theta, phi, _ = sphere_grid(N, 2 * N)
    exact = rotated(lambda th, ph: wave.vorticity(th, ph, T), R)(theta[:, None], phi[None, :])
    err = np.abs(matrix_to_grid(W) - exact).max() / np.abs(exact).max()
    assert err < 1e-9
    frozen = rotated(lambda th, ph: wave.vorticity(th, ph, 0.0), R)(theta[:, None], phi[None, :])
    assert np.abs(matrix_to_grid(W) - frozen).max() / np.abs(exact).max() > 100 * err


def jet(th, ph):
    return np.exp(-((np.cos(th) - 0.3) / 0.3) ** 2) + 0 * ph


def test_zonal_flows_are_steady_also_when_tilted():
    N = 16
    H = ZeitlinHamiltonian(N)
    for R in (np.eye(3), rotation([0.3, 1.0, 0.2], 1.1)):
        W = function_to_matrix(rotated(jet, R), N)
        idx = np.arange(N)
        W[idx, idx] -= np.trace(W) / N
        P = H.stream_matrix(W)
        com = P @ W - W @ P
        assert np.abs(com).max() < 1e-13 * np.abs(P).max() * np.abs(W).max() * N
    # a wrong phase on the orders m = +-2 breaks the commutation: the check can fail
    from mechanics.sphere import coefficients_to_matrix, matrix_to_coefficients
    om = matrix_to_coefficients(W)
    for l in range(2, N):
        om[l * (l + 1) + 2] *= -1
        om[l * (l + 1) - 2] *= -1
    bad = coefficients_to_matrix(om)
    Pb = H.stream_matrix(bad)
    assert np.abs(Pb @ bad - bad @ Pb).max() > 1e-3 * np.abs(Pb).max() * np.abs(bad).max()


def test_steady_field_error_is_the_truncation_and_falls_with_n():
    R = rotation([1.0, 0.0, 0.5], 0.9)
    profile = rotated(lambda th, ph: np.abs(np.cos(th)) ** 3 - 0.5 + 0 * ph, R)  # mean 1/4 - 1/2: not 0
    ns = [8, 16, 32]
    errs = []
    for N in ns:
        W0 = function_to_matrix(profile, N)
        idx = np.arange(N)
        mean = np.trace(W0).imag / N  # the l = 0 part, kept aside (it does not move)
        W0[idx, idx] -= np.trace(W0) / N
        W = isospectral_midpoint(W0, drift(N), 0.05, 4)
        # steady up to the aliasing of the quadrature (the field is not band-limited)
        assert np.abs(W - W0).max() < 1e-4 * np.abs(W0).max()
        theta, phi, w = sphere_grid(2 * N, 4 * N)
        diff = matrix_to_grid(W, 2 * N, 4 * N) + mean - profile(theta[:, None], phi[None, :])
        errs.append(np.sqrt(np.sum(w[:, None] * 2 * np.pi / (4 * N) * diff ** 2)))
    assert -3.9 < fitted_slope(ns, errs) < -3.2
    assert errs[-1] < 1e-4


@pytest.mark.slow
def test_wave_and_casimirs_at_n_64_and_128():
    wave = RossbyHaurwitzWave(5, {(5, 2): 0.4, (5, 5): 0.1j, (5, 0): -0.3}, rotation=0.3)
    for N in (64, 128):
        H = ZeitlinHamiltonian(N)
        W = rk4_flow(H.vector_field, wave.matrix(0.0, N), 1.0, 50)
        exact = wave.matrix(1.0, N)
        assert np.linalg.norm(W - exact) / np.linalg.norm(exact) < 5e-9
        W0 = wave.matrix(0.0, N)
        Wm = isospectral_midpoint(W0, drift(N), 0.01, 8)
        c0, c1 = casimirs(W0), casimirs(Wm)
        np.testing.assert_allclose(c1, c0, rtol=1e-12, atol=1e-12 * np.abs(c0).max())
