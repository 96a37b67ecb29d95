"""Bad input to mechanics.sphere is refused with a ValueError/TypeError that names the argument and the fix."""

import numpy as np
import pytest

from mechanics.sphere import (RossbyHaurwitzWave, ZeitlinHamiltonian, casimirs, coefficients_to_grid,
                              coefficients_to_matrix, energy, function_to_matrix, grid_to_coefficients,
                              grid_to_matrix, harmonic_matrix, hbar, inverse_laplacian, laplacian, lm_index,
                              matrix_to_coefficients, matrix_to_grid, real_harmonic_matrix, salt_noise, sphere_grid,
                              zeitlin_system)

W8 = 1j * harmonic_matrix(8, 2, 0)

CASES = [
    (lambda: hbar(1), ValueError, "N must satisfy 2 <= N"),
    (lambda: hbar(2.5), TypeError, "N must be an integer"),
    (lambda: hbar(True), TypeError, "N must be an integer"),
    (lambda: harmonic_matrix(8, 8, 0), ValueError, "0 <= l < N"),
    (lambda: harmonic_matrix(8, 3, -4), ValueError, r"\|m\| <= l"),
    (lambda: harmonic_matrix(8, 2.0, 0), TypeError, "l must be an integer"),
    (lambda: lm_index(2, 3), ValueError, r"\|m\| <= l"),
    (lambda: lm_index(1.5, 0), TypeError, "l and m must be integers"),      # was the index 3.75
    (lambda: lm_index("a", 0), TypeError, "l and m must be integers"),      # was numpy's UFuncTypeError
    (lambda: lm_index(2, True), TypeError, "l and m must be integers"),
    (lambda: coefficients_to_matrix(np.ones(5)), ValueError, "L\\*\\*2"),
    (lambda: coefficients_to_matrix(np.ones(16), 3), ValueError, "truncation"),
    (lambda: coefficients_to_matrix("abc"), TypeError, "omega"),
    (lambda: coefficients_to_matrix(np.full(4, np.nan)), ValueError, "non-finite"),
    (lambda: matrix_to_coefficients(np.ones((3, 4))), ValueError, r"\(\.\.\., N, N\)"),
    (lambda: matrix_to_coefficients(W8, 9), ValueError, "exceeds the matrix size"),
    (lambda: matrix_to_coefficients(np.ones((2, 2), dtype=object)), TypeError, "numeric"),
    (lambda: laplacian(np.ones(4)), ValueError, "P must have shape"),
    (lambda: inverse_laplacian(np.full((4, 4), np.inf)), ValueError, "non-finite"),
    (lambda: inverse_laplacian(None), TypeError, "W must be"),
    (lambda: sphere_grid(0, 4), ValueError, "n_lat must be at least 1"),
    (lambda: sphere_grid(4, 2.0), TypeError, "n_lon must be an integer"),
    (lambda: coefficients_to_grid(np.ones(9), 4, 4), ValueError, "n_lon must be at least 5"),
    (lambda: grid_to_coefficients(np.ones((3, 8)), 4), ValueError, "n_lat"),
    (lambda: grid_to_coefficients(np.ones((4, 8)), 0), ValueError, "L .* positive integer"),
    (lambda: grid_to_matrix(np.ones((8, 8)), 8), ValueError, "n_lon"),
    (lambda: matrix_to_grid(W8, 8, 4), ValueError, "n_lon must be at least 15"),
    (lambda: function_to_matrix(3.0, 8), TypeError, "func must be a callable"),
    (lambda: function_to_matrix(lambda t, p: t, 8, oversample=0), ValueError, "oversample"),
    (lambda: function_to_matrix(lambda t, p: np.ones(3), 8), ValueError, "broadcastable to the grid"),
    # the grid values of func were refused as 'values has non-finite entries', an argument the caller never passed
    (lambda: function_to_matrix(lambda t, p: np.where(t > 1.0, np.nan, t) + 0 * p, 8), ValueError,
     r"func\(theta, phi\) returned .* non-finite"),
    (lambda: ZeitlinHamiltonian(8, time_unit="seconds"), ValueError, "time_unit must be"),
    (lambda: ZeitlinHamiltonian(8, time_unit=np.array(["physical"])), TypeError, "time_unit must be"),  # was kept
    (lambda: salt_noise(8, [(1, 0)], time_unit=["quantum"]), TypeError, "time_unit must be"),
    (lambda: ZeitlinHamiltonian(8).value_matrix(np.eye(6)), ValueError, "must be 8 x 8"),
    (lambda: ZeitlinHamiltonian(8).gradient_matrix("W"), TypeError, "W must be"),
    (lambda: casimirs(W8, (0, 2)), ValueError, "orders must be positive integers"),
    (lambda: casimirs(W8, (2.5,)), ValueError, "orders must be positive integers"),
    # were bare numpy/Python errors (int('ab'), int(nan), a 2-D array) or a bool taken as the order 1
    (lambda: casimirs(W8, "ab"), TypeError, "orders must be positive integers"),
    (lambda: casimirs(W8, (np.nan,)), ValueError, "orders must be positive integers"),
    (lambda: casimirs(W8, [[2, 3]]), ValueError, "orders must be positive integers"),
    (lambda: casimirs(W8, (True, 2)), TypeError, "orders must be positive integers"),
    # zeitlin_system(noise=...): were numpy's 'zero-size array to reduction operation maximum' (no matrix),
    # a bare ufunc error (text) and a message naming X instead of noise (object dtype)
    (lambda: zeitlin_system(8, noise=np.zeros((0, 8, 8))), ValueError, "noise must hold at least one"),
    (lambda: zeitlin_system(8, noise=[[["a"] * 8] * 8]), TypeError, "noise must be a numeric array"),
    (lambda: zeitlin_system(8, noise=np.zeros((2, 8, 8), dtype=object)), TypeError, "noise must be a numeric"),
    (lambda: casimirs(W8, (10**400,)), ValueError, "work budget.*ask for lower orders"),   # was a loop for ever
    (lambda: energy(np.ones((2, 3))), ValueError, r"\(\.\.\., N, N\)"),
    (lambda: real_harmonic_matrix(8, 0, 0), ValueError, "l = 0 is the identity"),
    (lambda: RossbyHaurwitzWave(0, {(0, 0): 1.0}, 1.0), ValueError, "degree must be"),
    (lambda: RossbyHaurwitzWave(3, {(2, 1): 1.0}, 1.0), ValueError, "l = degree = 3"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0, (3, -1): 1.0}, 1.0), ValueError, "real field"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, np.nan), ValueError, "rotation"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).coefficients(0.0, 3), ValueError, "L must exceed"),
    # were silent: a NaN or text coefficient, a float L truncated, a NaN time (NaN coefficients), a bool rotation;
    # or bare numpy errors: a fractional m (IndexError), a huge L or degree (MemoryError)
    (lambda: RossbyHaurwitzWave(3, {(3, 1): np.nan}, 1.0), ValueError, r"wave\[\(3, 1\)\] must be a finite"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): "0.5"}, 1.0), TypeError, r"wave\[\(3, 1\)\] must be a number"),
    (lambda: RossbyHaurwitzWave(3, {(3, 0.5): 1.0}, 1.0), ValueError, "wave keys must be"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, True), TypeError, "rotation must be a real number"),
    (lambda: RossbyHaurwitzWave(10**12, {(10**12, 1): 1.0}, 1.0), ValueError, "memory budget"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).coefficients(0.0, 4.7), TypeError, "L must be an integer"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).coefficients(np.nan, 4), ValueError, "t must be finite"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).coefficients(0.0, 10**7), ValueError, "memory budget"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).vorticity(0.1, 0.2, np.inf), ValueError, "t must be finite"),
    (lambda: RossbyHaurwitzWave(3, {(3, 1): 1.0}, 1.0).vorticity([0.1, np.nan], 0.2, 0.0), ValueError,
     "theta contains 1 non-finite"),
]


@pytest.mark.parametrize("call, error, message", CASES)
def test_bad_input_is_refused_clearly(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_requests_above_the_memory_budget_are_refused_before_allocating(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**6))
    small = np.zeros((100, 100), dtype=complex)
    with pytest.raises(ValueError, match="Poisson solve .* memory budget"):
        inverse_laplacian(small)
    with pytest.raises(ValueError, match="grid values .* memory budget"):
        coefficients_to_grid(np.zeros(4), 200, 400)
    with pytest.raises(ValueError, match="oversampled grid .* memory budget"):
        function_to_matrix(lambda t, p: t + 0 * p, 64, oversample=4)
    with pytest.raises(ValueError, match="quantised basis .* memory budget"):
        harmonic_matrix(200, 1, 0)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**8))
    assert inverse_laplacian(small).shape == (100, 100)


def test_a_huge_grid_is_refused_before_the_node_computation_allocates():
    # the Gauss–Legendre nodes are the eigenvalues of an n_lat x n_lat companion matrix: sphere_grid(10**6, 1)
    # raised numpy's bare MemoryError (7.28 TiB), and grid_to_coefficients of a tall grid the same
    with pytest.raises(ValueError, match="n_lat x n_lat .* memory budget.*fewer colatitudes"):
        sphere_grid(10**6, 1)
    with pytest.raises(ValueError, match="n_lat x n_lat .* memory budget"):
        grid_to_coefficients(np.broadcast_to(np.zeros(1), (10**6, 1)), 1)
    with pytest.raises(ValueError, match="memory budget"):
        sphere_grid(4, 10**15)


@pytest.mark.parametrize("n, order, budget", [
    (2, 10**4, 1e5),       # 10**4 steps of 2 us each (the call of a product): was counted as 4 entries a step, 4e4
    (1024, 3, 4.5e6),      # 2 products of N^3 multiply-adds (0.3 s each): was counted as N^2 entries each, 3.1e6
])
def test_casimirs_work_estimate_counts_what_the_products_cost(monkeypatch, n, order, budget):
    # the old count (max order x matrices x N^2) was below these budgets: the calls ran instead
    W = 1j * np.random.default_rng(0).normal(size=(n, n)) / n
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", str(budget))
    with pytest.raises(ValueError, match=rf"orders up to k = {order}: .* s of one core.* work budget .* ask for lower "
                                         rf"orders \(for {n} x {n} matrices the C_k with k > {n} follow"):
        casimirs(W, (2, order))
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", str(budget * 100))
    assert casimirs(W, (2, order)).shape == (2,)


def test_casimirs_refuses_powers_above_the_memory_budget(monkeypatch):
    # iW, the current power and the next: three stacks of the input's size; they were allocated unchecked
    W = np.zeros((100, 32, 32), dtype=complex)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(3 * W.nbytes - 1))
    with pytest.raises(ValueError, match="powers .* of 100 matrices of size 32 would take .* memory budget.*fewer "
                                         "matrices"):
        casimirs(W)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(4 * W.nbytes))
    assert casimirs(W).shape == (100, 5)


def test_zeitlin_system_refuses_a_large_N_before_building_su_N(monkeypatch):
    # su(N) was built first, unchecked (153 MiB and 2 s at N = 512, 10 GiB at N = 4096), and only then were the
    # noise matrices refused; now su(N) refuses itself before its lists exist
    import tracemalloc

    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(2**25))
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match=r"basis of su\(N\) at N = 512 .* memory budget .*; use a smaller N\."):
            zeitlin_system(512)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**20, peak
