"""The quantised spherical harmonics T_lm: weights, spins, normalisation, orthogonality and phases.

Statement checked (mechanics.sphere.quantisation): T_lm lies on the m-th diagonal with [S3, T_lm] = m T_lm,
-sum_a [S_a, [S_a, T_lm]] = -l(l+1) T_lm, tr(T_lm T_l'm'^*) = N/(4 pi) delta delta, T_{l,-m} = (-1)^m T_lm^*,
T_ll = (-1)^l c S_+^l with c > 0, T_{l,m-1} = [S_-, T_lm] / sqrt((l+m)(l-m+1)) (the Condon–Shortley phases of
Y_lm), T(x_a) = hbar S_a exactly. Oracles: spin matrices from their definition and dense commutators.
"""

import numpy as np
import pytest

from _sphere_oracles import dense_laplacian, spin
from mechanics.sphere import (coefficients_to_matrix, harmonic_matrix, hbar, lm_index, matrix_to_coefficients,
                              spin_matrices)


def all_T(N):
    return {(l, m): harmonic_matrix(N, l, m) for l in range(N) for m in range(-l, l + 1)}


@pytest.mark.parametrize("N", [2, 3, 6, 9])
def test_weights_spins_and_orthonormality(N):
    S = spin(N)
    Ts = all_T(N)
    keys = list(Ts)
    gram = np.array([[np.trace(Ts[a] @ Ts[b].conj().T) for b in keys] for a in keys])
    np.testing.assert_allclose(gram, N / (4 * np.pi) * np.eye(len(keys)), atol=1e-13)
    for (l, m), T in Ts.items():
        np.testing.assert_allclose(S[2] @ T - T @ S[2], m * T, atol=1e-12)
        np.testing.assert_allclose(dense_laplacian(T, S), -l * (l + 1) * T, atol=1e-11 * max(1, l * l))
        assert np.all(np.isreal(T))


def test_spin_matrices_match_definition():
    for N in (2, 5, 8):
        np.testing.assert_allclose(spin_matrices(N), np.array(spin(N)), atol=1e-15)
        S1, S2, S3 = spin_matrices(N)
        np.testing.assert_allclose(S1 @ S2 - S2 @ S1, 1j * S3, atol=1e-13)
        np.testing.assert_allclose(hbar(N) ** 2 * (S1 @ S1 + S2 @ S2 + S3 @ S3), np.eye(N), atol=1e-13)


@pytest.mark.parametrize("N", [3, 7, 16])
def test_degree_one_is_the_coordinate_quantisation(N):
    S1, S2, S3 = spin(N)
    h = hbar(N)
    splus = S1 + 1j * S2
    np.testing.assert_allclose(harmonic_matrix(N, 0, 0), np.eye(N) / np.sqrt(4 * np.pi), atol=1e-14)
    np.testing.assert_allclose(harmonic_matrix(N, 1, 0), np.sqrt(3 / (4 * np.pi)) * h * S3, atol=1e-13)
    np.testing.assert_allclose(harmonic_matrix(N, 1, 1), -np.sqrt(3 / (8 * np.pi)) * h * splus, atol=1e-13)
    np.testing.assert_allclose(harmonic_matrix(N, 1, -1), np.sqrt(3 / (8 * np.pi)) * h * splus.conj().T,
                               atol=1e-13)


@pytest.mark.parametrize("N", [5, 12, 40])
def test_condon_shortley_phases(N):
    S1, S2, _ = spin(N)
    splus, sminus = S1 + 1j * S2, S1 - 1j * S2
    for l in range(N):
        top = harmonic_matrix(N, l, l)
        power = np.linalg.matrix_power(splus, l)
        c = np.sum(top * power) / np.sum(power * power)
        assert (-1) ** l * c.real > 0 and abs(c.imag) < 1e-12 * abs(c)
        np.testing.assert_allclose(top, c * power, atol=1e-10 * np.abs(top).max())
        for m in range(l, -l, -1):
            lowered = (sminus @ harmonic_matrix(N, l, m) - harmonic_matrix(N, l, m) @ sminus)
            np.testing.assert_allclose(lowered / np.sqrt((l + m) * (l - m + 1)), harmonic_matrix(N, l, m - 1),
                                       atol=1e-9 * np.sqrt(N))
        for m in range(1, l + 1):
            np.testing.assert_allclose(harmonic_matrix(N, l, -m), (-1) ** m * harmonic_matrix(N, l, m).T, atol=0)


def test_north_pole_entries_have_the_sign_of_the_legendre_functions():
    """Near the north pole P_l^m(cos theta) has the sign (-1)^m (Condon–Shortley): so has T_lm's first entry."""
    N = 12
    for l in range(N):
        for m in range(0, l + 1):
            assert np.sign(harmonic_matrix(N, l, m)[0, m].real) == (-1) ** m


def test_wrong_phase_would_break_the_lowering_rule():
    """The phase check above can fail: flipping one T_lm's sign breaks it."""
    N = 8
    S1, S2, _ = spin(N)
    sminus = S1 - 1j * S2
    T = -harmonic_matrix(N, 4, 2)
    lowered = (sminus @ T - T @ sminus) / np.sqrt(6 * 3)
    assert np.abs(lowered - harmonic_matrix(N, 4, 1)).max() > 0.1


@pytest.mark.parametrize("N", [2, 5, 17])
def test_coefficient_maps_are_inverse_on_gl_n(N, rng):
    A = rng.standard_normal((3, N, N)) + 1j * rng.standard_normal((3, N, N))
    omega = matrix_to_coefficients(A)
    assert omega.shape == (3, N * N)
    np.testing.assert_allclose(coefficients_to_matrix(omega), A, atol=1e-12)
    single = harmonic_matrix(N, N - 1, 1 - N)
    got = matrix_to_coefficients(1j * single)
    expected = np.zeros(N * N, dtype=complex)
    expected[lm_index(N - 1, 1 - N)] = 1
    np.testing.assert_allclose(got, expected, atol=1e-13)
    for b in range(3):
        assert np.array_equal(matrix_to_coefficients(A[b]), omega[b])
        assert np.array_equal(coefficients_to_matrix(omega[b]), coefficients_to_matrix(omega)[b])


def test_real_fields_give_skew_hermitian_matrices(rng):
    N, L = 10, 7
    omega = rng.standard_normal(L * L) + 1j * rng.standard_normal(L * L)
    for l in range(L):  # impose omega_{l,-m} = (-1)^m conj(omega_lm)
        omega[lm_index(l, 0)] = omega[lm_index(l, 0)].real
        for m in range(1, l + 1):
            omega[lm_index(l, -m)] = (-1) ** m * np.conj(omega[lm_index(l, m)])
    W = coefficients_to_matrix(omega, N)
    np.testing.assert_allclose(W, -W.conj().T, atol=1e-13)
    np.testing.assert_allclose(np.trace(W), 1j * omega[0] * N / np.sqrt(4 * np.pi), atol=1e-12)
    back = matrix_to_coefficients(W, L)
    np.testing.assert_allclose(back, omega, atol=1e-12)


def test_larger_sizes_keep_the_spectrum_and_norms():
    N = 96
    S = spin(N)
    for l, m in [(0, 0), (1, -1), (40, 17), (95, -95), (95, 3), (60, 0)]:
        T = harmonic_matrix(N, l, m)
        np.testing.assert_allclose(np.linalg.norm(T) ** 2, N / (4 * np.pi), rtol=1e-12)
        np.testing.assert_allclose(dense_laplacian(T, S), -l * (l + 1) * T, atol=1e-9 * l * l + 1e-15 * N * N)
