"""Beyond the paper (issue 38): SALT Euler on the sphere keeps every Casimir tr((iW)^k) to round-off; the
energy is conserved only without noise, and then exactly by the isospectral midpoint.

Statements checked (mechanics.sphere.zeitlin_system solved by roughpaths.solve):

* Casimirs. dW = [W, w] dt + sum_i [W, xi_i] o dX^i with w = -kappa P + ell + ... is a coadjoint motion, so the
  spectrum of the Hermitian iW is constant and so is every C_k = tr((iW)^k). The isospectral schemes (LieEuler,
  LieHeun, ImplicitMidpoint: W_{n+1} = e^{-sigma} W_n e^{sigma}) keep them to round-off: relative to
  sum_j |lambda_j|^k, |C_k(t) - C_k(0)| <= 1e-12 at every step, k = 2..6, with SALT noise of three
  non-commuting modes, their Levy areas and a non-zero area perturbation s, at N = 32, 64 (and 128, slow), while
  W itself moves by tens of per cent. (Any coadjoint drift keeps them, the Levy correction with the wrong sign or
  without its 1/2 too: the Casimirs cannot tell those apart; the other tests of this folder do.)
  Oracle: the eigenvalues of iW from numpy's eigvalsh, not the library's Casimirs.
* Energy. E = 1/2 int |u|^2 dA is *not* conserved by SALT noise: dh = B(dW, grad h) = sum_i B([W, xi_i], -kappa P)
  o dX^i + B([W, ell], -kappa P) dt != 0 (transport by a velocity that is not the flow's own). Measured: it moves
  by far more than round-off. Without noise it is conserved by the flow, and by the implicit midpoint exactly:
  h is quadratic, so h(W') - h(W) = B(W' - W, grad h((W + W')/2)) = B(W' - W, sigma)/dt, and
  B(e^{-sigma} W e^{sigma}, sigma) = B(W, sigma) (sigma commutes with e^{sigma}), so the change is 0 up to the
  fixed-point tolerance. Lie-Heun (order 2) has an energy error that falls at least like dt^2 (measured: dt^3).
"""

import numpy as np
import pytest

from _sphere_oracles import power_traces, smooth_coefficients
import roughpaths as rp
from mechanics import ImplicitMidpoint, LieEuler, LieHeun
from mechanics.sphere import coefficients_to_matrix, energy, zeitlin_system

S = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.5], [0.0, -0.5, 0.0]])


def _run(N, method, n_steps, T=0.5, amplitudes=0.2, seed=2):
    system = zeitlin_system(N, amplitudes=amplitudes, s=S)
    g = system.algebra
    W0 = coefficients_to_matrix(smooth_coefficients(np.random.default_rng(1), 6), N)
    X = rp.brownian_rough_path(np.linspace(0.0, T, n_steps + 1), 3, np.random.default_rng(seed))
    states = rp.solve(system, X, g.matrix_to_dual(W0), method).states
    return W0, g.dual_to_matrix(states)


def _casimir_drift(W0, Ms):
    c0, scale = power_traces(W0)
    return max(float(np.max(np.abs(power_traces(M)[0] - c0) / scale)) for M in Ms)


@pytest.mark.parametrize("N, method", [(32, LieHeun()), (32, LieEuler()), (32, ImplicitMidpoint()), (64, LieHeun())],
                         ids=["32-LieHeun", "32-LieEuler", "32-ImplicitMidpoint", "64-LieHeun"])
def test_casimirs_kept_to_round_off_with_salt_noise_and_levy_area(N, method):
    W0, Ms = _run(N, method, 40)
    assert _casimir_drift(W0, Ms) <= 1e-12
    assert np.max(np.abs(Ms[-1] - W0)) > 0.1 * np.max(np.abs(W0))      # the state did move
    e = energy(Ms)
    assert np.max(np.abs(e - e[0])) > 1e-4 * e[0]                      # SALT noise does not keep the energy


@pytest.mark.slow
def test_casimirs_kept_to_round_off_at_N_128():
    W0, Ms = _run(128, LieHeun(), 60)
    assert _casimir_drift(W0, Ms) <= 1e-12
    assert np.max(np.abs(Ms[-1] - W0)) > 0.1 * np.max(np.abs(W0))


def _deterministic_energy_errors(method, ns, N=32):
    system = zeitlin_system(N, amplitudes=0.0)
    g = system.algebra
    W0 = g.matrix_to_dual(coefficients_to_matrix(smooth_coefficients(np.random.default_rng(1), 6), N))
    errs = []
    for n in ns:
        X = rp.RoughPath.from_path(np.zeros((n + 1, 3)), times=np.linspace(0.0, 1.0, n + 1))
        e = energy(g.dual_to_matrix(rp.solve(system, X, W0, method).states))
        errs.append(float(np.max(np.abs(e - e[0])) / e[0]))
    return np.array(errs)


def test_energy_conserved_without_noise_exactly_by_the_midpoint_and_to_order_by_heun():
    ns = [8, 16, 32, 64]
    mid = _deterministic_energy_errors(ImplicitMidpoint(tol=1e-14), ns)
    assert np.max(mid) <= 1e-12, mid
    heun = _deterministic_energy_errors(LieHeun(), ns)
    slope = -np.polyfit(np.log(ns), np.log(heun), 1)[0]
    assert slope >= 1.8 and heun[0] > 1e-8, (slope, heun)
