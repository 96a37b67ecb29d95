"""SALT noise matrices for Zeitlin's model.

Statement checked (mechanics.sphere.salt_noise): xi_i = -kappa i T(a_i zeta_i) is in su(N), built alike from a
mode (l, m), a callable field or grid values; the library's noise term [W, xi_i] converges to the stochastic
transport {omega, zeta_i} like N^-2 (and the opposite sign does not); the mean of a field transports nothing.
Oracles: scipy's harmonics and quadrature.
"""

import numpy as np
import pytest

from _sphere_oracles import Field, Y, bracket, fitted_slope, flat, project
from mechanics.sphere import (coefficients_to_matrix, hbar, matrix_to_coefficients, real_harmonic_matrix,
                              salt_noise, sphere_grid)


def test_modes_are_scaled_real_harmonics():
    N = 9
    xi = salt_noise(N, [(1, 0), (2, 1), (3, -2)], amplitudes=[1.0, 0.5, -2.0])
    assert xi.shape == (3, N, N)
    for k, ((l, m), a) in enumerate(zip([(1, 0), (2, 1), (3, -2)], [1.0, 0.5, -2.0])):
        np.testing.assert_allclose(xi[k], -a / hbar(N) * real_harmonic_matrix(N, l, m), atol=1e-13)
        np.testing.assert_allclose(xi[k], -xi[k].conj().T, atol=0)
        assert abs(np.trace(xi[k])) < 1e-13
    quantum = salt_noise(N, [(2, 1)], amplitudes=0.5, time_unit="quantum")
    np.testing.assert_allclose(quantum[0], -0.5 * real_harmonic_matrix(N, 2, 1), atol=1e-14)


def test_fields_callables_and_grids_agree_with_modes():
    N = 8
    zeta = lambda th, ph: -np.sqrt(2) * Y(2, 1, th, ph).real + 3.0  # Y^R_21 plus a constant
    from_mode = salt_noise(N, [(2, 1)])
    np.testing.assert_allclose(salt_noise(N, fields=[zeta]), from_mode, atol=1e-12)
    theta, phi, _ = sphere_grid(N, 2 * N)
    grid = zeta(theta[:, None], phi[None, :])
    np.testing.assert_allclose(salt_noise(N, fields=grid[None]), from_mode, atol=1e-12)
    np.testing.assert_allclose(salt_noise(N, fields=[grid]), from_mode, atol=1e-12)
    both = salt_noise(N, [(1, 0)], fields=[zeta], amplitudes=[2.0, 1.0])
    np.testing.assert_allclose(both[1], from_mode[0], atol=1e-12)


def test_noise_term_converges_to_stochastic_transport():
    omega = Field({(1, 0): 0.5, (2, 1): 0.4, (2, -1): -0.4, (3, 0): -0.6, (4, 2): 0.3j, (4, -2): 0.3j})
    zeta = Field({(2, 1): -1 / np.sqrt(2), (2, -1): 1 / np.sqrt(2)})  # Y^R_21
    L = 8
    exact = flat(project(bracket(omega, zeta), L), L)  # d omega = {omega, zeta} o dX
    ns = [8, 16, 32, 64]
    errs, flipped = [], []
    for N in ns:
        W = coefficients_to_matrix(flat(omega.coeffs, L), N)
        xi = salt_noise(N, [(2, 1)])[0]
        got = matrix_to_coefficients(W @ xi - xi @ W, L)  # ad*_xi W = [W, xi]
        errs.append(np.linalg.norm(got - exact) / np.linalg.norm(exact))
        flipped.append(np.linalg.norm(-got - exact) / np.linalg.norm(exact))
    assert -2.2 < fitted_slope(ns[1:], errs[1:]) < -1.8
    assert errs[-1] < 5e-3 and min(flipped) > 1.8


def test_bad_noise_arguments():
    with pytest.raises(ValueError, match="modes=.*fields="):
        salt_noise(8)
    with pytest.raises(ValueError, match="amplitudes"):
        salt_noise(8, [(1, 0), (2, 0)], amplitudes=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="l = 0"):
        salt_noise(8, [(0, 0)])
    with pytest.raises(ValueError, match=r"\(l, m\) pairs"):
        salt_noise(8, [1, 0])
    with pytest.raises(ValueError, match="time_unit"):
        salt_noise(8, [(1, 0)], time_unit="seconds")


def test_amplitudes_of_the_wrong_kind_and_too_many_modes_are_refused(monkeypatch):
    # were: a bool taken as 1.0, a text raised numpy's bare "could not convert string to float", a complex
    # float()'s bare TypeError; the matrices of the modes were allocated before any estimate
    with pytest.raises(TypeError, match="amplitudes must be real"):
        salt_noise(8, [(1, 0)], amplitudes=True)
    with pytest.raises(TypeError, match="amplitudes must be real"):
        salt_noise(8, [(1, 0)], amplitudes="x")
    with pytest.raises(TypeError, match="amplitudes must be real"):
        salt_noise(8, [(1, 0)], amplitudes=1j)
    with pytest.raises(TypeError, match="amplitudes must be real"):
        salt_noise(8, [(1, 0), (1, 1)], amplitudes=[1.0, True])
    with pytest.raises(TypeError, match="modes must be a sequence of"):          # was 'int' object is not iterable
        salt_noise(8, 5)
    with pytest.raises(TypeError, match="fields must be callables"):             # was 'float' object is not iterable
        salt_noise(8, fields=3.0)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**6))
    with pytest.raises(ValueError, match="noise matrices .* memory budget"):
        salt_noise(64, [(1, 0)] * 20)


def test_many_modes_above_the_cached_sizes_cost_one_pass_over_the_basis(monkeypatch):
    """Above N = 256 the quantised basis is not kept: each pass over it builds it anew (O(N^3): 2.5 s at N = 512).
    SALT noise of several modes takes one pass for all of them (it took two per mode with m != 0: zeitlin_system at
    N = 512 12 s, at N = 2048 minutes), with the values of the modes built one at a time."""
    from mechanics.sphere import quantisation

    passes = []
    real = quantisation._bands_descending

    def counted(n):
        passes.append(n)
        return real(n)

    monkeypatch.setattr(quantisation, "_bands_descending", counted)
    N = 260
    modes = [(1, 0), (2, 1), (3, -2)]
    xi = salt_noise(N, modes, amplitudes=[1.0, 0.5, -2.0])
    assert passes == [N]
    one = salt_noise(N, [(3, -2)], amplitudes=-2.0)                       # one more pass, for one mode alone
    assert len(passes) == 2
    assert xi[2].tobytes() == one[0].tobytes()
