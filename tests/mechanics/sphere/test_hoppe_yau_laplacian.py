"""The Hoppe–Yau quantised Laplacian and its inverse.

Statement checked (mechanics.sphere.laplacian): Delta_N = -sum_a ad_{S_a}^2 has the eigenvalues -l(l+1),
l = 0..N-1, each with multiplicity 2l+1 (the Laplace–Beltrami spectrum truncated at l < N); the inverse
solves Delta_N P = W - tr(W) I / N with tr P = 0, is skew-Hermitian to the last bit on skew-Hermitian W,
and sends the identity (l = 0) to zero. Oracles: the dense N^2 x N^2 operator built from spin matrices.
"""

import numpy as np
import pytest

from _sphere_oracles import dense_laplacian, laplacian_operator, random_su, spin
from mechanics.sphere import inverse_laplacian, laplacian


@pytest.mark.parametrize("N", [2, 3, 4, 7])
def test_spectrum_is_the_truncated_sphere_spectrum(N):
    S = spin(N)
    op = laplacian_operator(N, S)
    eig = np.sort(np.linalg.eigvalsh(0.5 * (op + op.conj().T)))
    expected = np.sort(np.concatenate([[-l * (l + 1)] * (2 * l + 1) for l in range(N)]).astype(float))
    np.testing.assert_allclose(eig, expected, atol=1e-10)
    np.testing.assert_allclose(op, op.conj().T, atol=1e-12)  # self-adjoint for the Frobenius product


@pytest.mark.parametrize("N", [2, 5, 16, 31])
def test_fast_laplacian_matches_dense(N, rng):
    P = rng.standard_normal((2, N, N)) + 1j * rng.standard_normal((2, N, N))
    S = spin(N)
    got = laplacian(P)
    for b in range(2):
        np.testing.assert_allclose(got[b], dense_laplacian(P[b], S), atol=1e-12 * N * N)


@pytest.mark.parametrize("N", [2, 3, 8, 33])
def test_inverse_solves_the_poisson_equation(N, rng):
    W = random_su(rng, N, (3,))
    P = inverse_laplacian(W)
    S = spin(N)
    for b in range(3):
        np.testing.assert_allclose(dense_laplacian(P[b], S), W[b], atol=1e-12 * N)
        assert np.array_equal(P[b], -P[b].conj().T)  # skew-Hermitian to the last bit
        assert abs(np.trace(P[b])) < 1e-13 * np.abs(P[b]).max() * N
        assert np.array_equal(inverse_laplacian(W[b]), P[b])  # batch independence


def test_inverse_drops_the_trace_and_works_on_gl_n(rng):
    N = 9
    A = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    P = inverse_laplacian(A)
    S = spin(N)
    np.testing.assert_allclose(dense_laplacian(P, S), A - np.trace(A) / N * np.eye(N), atol=1e-12)
    np.testing.assert_allclose(np.trace(P), 0, atol=1e-13)
    np.testing.assert_allclose(inverse_laplacian(np.eye(N)), 0, atol=1e-15)


def test_inverse_is_diagonal_on_the_basis():
    from mechanics.sphere import harmonic_matrix
    N = 20
    for l, m in [(1, 0), (5, -3), (19, 19), (12, 0)]:
        T = 1j * harmonic_matrix(N, l, m)
        np.testing.assert_allclose(inverse_laplacian(T), -T / (l * (l + 1)), atol=1e-13)


@pytest.mark.slow
def test_inverse_at_large_n(rng):
    for N in (128, 256):
        W = random_su(rng, N)
        P = inverse_laplacian(W)
        np.testing.assert_allclose(laplacian(P), W, atol=1e-10)
        assert np.array_equal(P, -P.conj().T)
