"""Fields on the sphere: grid values, coefficients and vorticity matrices against scipy's harmonics.

Statement checked (mechanics.sphere.grid): on the Gauss–Legendre grid with n_lat >= L, n_lon >= 2L-1 the synthesis
sum omega_lm Y_lm and the analysis int f conj(Y_lm) dA are exact for degree < L; matrix -> grid -> matrix is the
identity on su(N); a zonal field is a diagonal matrix; the truncation error of a field that is not band-limited
falls with N at the rate of its smoothness (|cos theta|^3: measured L2 slope -3.6, the Legendre tail's N^-3.5).
Oracle: scipy.special.sph_harm_y evaluated pointwise.
"""

import numpy as np
import pytest

from _sphere_oracles import Y, fitted_slope, flat
from mechanics.sphere import (coefficients_to_grid, function_to_matrix, grid_to_coefficients, grid_to_matrix,
                              harmonic_matrix, hbar, matrix_to_coefficients, matrix_to_grid, real_harmonic_matrix,
                              sphere_grid, spin_matrices)


def random_coeffs(rng, L):
    return {(l, m): complex(rng.standard_normal(), rng.standard_normal()) for l in range(L) for m in range(-l, l + 1)}


def test_grid_and_weights():
    theta, phi, w = sphere_grid(7, 13)
    assert np.all(np.diff(theta) > 0) and 0 < theta[0] and theta[-1] < np.pi
    np.testing.assert_allclose(phi, 2 * np.pi * np.arange(13) / 13)
    np.testing.assert_allclose(np.sum(w) * 2 * np.pi, 4 * np.pi)
    np.testing.assert_allclose(np.sum(w * np.cos(theta) ** 12), 2 / 13)  # exact up to degree 13


@pytest.mark.parametrize("L, n_lat, n_lon", [(1, 1, 1), (4, 4, 7), (7, 9, 16)])
def test_synthesis_matches_scipy(L, n_lat, n_lon, rng):
    coeffs = random_coeffs(rng, L)
    theta, phi, _ = sphere_grid(n_lat, n_lon)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    expected = sum(c * Y(l, m, th, ph) for (l, m), c in coeffs.items())
    np.testing.assert_allclose(coefficients_to_grid(flat(coeffs, L), n_lat, n_lon), expected, atol=1e-12)


@pytest.mark.parametrize("L, n_lat, n_lon", [(1, 1, 1), (5, 5, 9), (8, 11, 20)])
def test_analysis_is_exact_for_band_limited_fields(L, n_lat, n_lon, rng):
    coeffs = random_coeffs(rng, L)
    theta, phi, _ = sphere_grid(n_lat, n_lon)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    values = sum(c * Y(l, m, th, ph) for (l, m), c in coeffs.items())
    np.testing.assert_allclose(grid_to_coefficients(values, L), flat(coeffs, L), atol=1e-12)


@pytest.mark.parametrize("N", [2, 6, 17])
def test_matrix_grid_round_trip_and_batches(N, rng):
    A = rng.standard_normal((3, N, N)) + 1j * rng.standard_normal((3, N, N))
    W = A - np.conj(np.swapaxes(A, -1, -2))
    values = matrix_to_grid(W)
    assert values.shape == (3, N, 2 * N) and values.dtype == np.float64
    np.testing.assert_allclose(grid_to_matrix(values, N), W, atol=1e-12 * N)
    for b in range(3):
        assert np.array_equal(matrix_to_grid(W[b]), values[b])
        assert np.array_equal(grid_to_matrix(values[b], N), grid_to_matrix(values, N)[b])
    # a non-skew-Hermitian matrix: the field of its skew-Hermitian part
    np.testing.assert_allclose(matrix_to_grid(A), matrix_to_grid(0.5 * (A - np.conj(np.swapaxes(A, -1, -2)))),
                               atol=1e-12 * N)


def test_fields_of_known_matrices():
    N = 12
    theta, phi, _ = sphere_grid(N, 2 * N)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    # the vorticity matrix of x_3 is i hbar S_3
    np.testing.assert_allclose(function_to_matrix(lambda t, p: np.cos(t) + 0 * p, N),
                               1j * hbar(N) * spin_matrices(N)[2], atol=1e-13)
    np.testing.assert_allclose(matrix_to_grid(1j * harmonic_matrix(N, 3, 0)), Y(3, 0, th, ph).real, atol=1e-12)
    real_21 = np.sqrt(2) * (-1) * Y(2, 1, th, ph).real
    np.testing.assert_allclose(matrix_to_grid(real_harmonic_matrix(N, 2, 1)), real_21, atol=1e-12)
    real_3m2 = np.sqrt(2) * Y(3, 2, th, ph).imag
    np.testing.assert_allclose(matrix_to_grid(real_harmonic_matrix(N, 3, -2)), real_3m2, atol=1e-12)
    # real harmonic matrices of degree 1 are the coordinates: Y^R_11 ~ x_1, Y^R_1-1 ~ x_2
    c = np.sqrt(3 / (4 * np.pi))
    np.testing.assert_allclose(real_harmonic_matrix(N, 1, 1), 1j * c * hbar(N) * spin_matrices(N)[0], atol=1e-13)
    np.testing.assert_allclose(real_harmonic_matrix(N, 1, -1), 1j * c * hbar(N) * spin_matrices(N)[1], atol=1e-13)


def test_zonal_fields_are_diagonal_and_truncation_converges():
    profile = lambda t, p: np.abs(np.cos(t)) ** 3 + 0 * p  # C^2: Legendre tail ~ N^-3.5 in L2
    ns = [8, 16, 32, 64]
    errs = []
    for N in ns:
        W = function_to_matrix(profile, N)
        off = W - np.diag(np.diag(W))
        assert np.abs(off).max() < 1e-13 * np.abs(W).max()
        theta, phi, w = sphere_grid(2 * N, 4 * N)
        diff = matrix_to_grid(W, 2 * N, 4 * N) - profile(theta[:, None], phi[None, :])
        errs.append(np.sqrt(np.sum(w[:, None] * 2 * np.pi / (4 * N) * diff ** 2)))
    assert -3.9 < fitted_slope(ns[1:], errs[1:]) < -3.3
    assert errs[-1] < 5e-6


def test_coefficients_keep_requested_degrees(rng):
    N = 9
    A = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    np.testing.assert_array_equal(matrix_to_coefficients(A, 4), matrix_to_coefficients(A)[:16])
