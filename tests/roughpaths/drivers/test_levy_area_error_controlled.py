"""Error-controlled Lévy-area samplers reproduce the law of the Brownian Lévy area.

Statement: for Brownian motion in R^d over a step h with increment w, the Lévy area A (with the ½)
has E[A_ij] = 0, Var(A_ij) = h²/4, E[A_ij⁴] = 5h⁴/16 (each pair is the planar Lévy area, whose
characteristic function is 1/cosh(λh/2)), and conditionally on w
Var(A_ij | w) = h²/12 + h(w_i² + w_j²)/12, Cov(A_ij, A_il | w) = h w_j w_l / 12 (j ≠ l).
The Mrongowius–Rößler and Wiktorsson samplers reproduce every conditional second moment exactly
for any number of terms n; the plain Fourier series lacks h² s_n/(2π²) of each conditional variance
(s_n = Σ_{k>n} k⁻²), which the test also detects.
"""

import math

import numpy as np
import pytest
from scipy.special import polygamma

from roughpaths import (choose_levy_area_method, levy_area_normals,
                                  levy_area_terms, levy_areas_from_normals, sample_levy_areas)

#: the error-controlled methods (LEVY_AREA_METHODS also lists davie, foster, exact and auto)
FOURIER_METHODS = ("fourier", "mrongowius-rossler", "wiktorsson")


def _z(x, mean, exact):
    return abs(np.mean(x) - exact) / (np.std(x, ddof=1) / math.sqrt(x.size))


@pytest.mark.parametrize("method", ["mrongowius-rossler", "wiktorsson", "auto"])
def test_unconditional_second_and_fourth_moments(method):
    rng = np.random.default_rng(11)
    d, h, N = 3, 0.05, 200_000
    w = rng.normal(0.0, math.sqrt(h), size=(N, d))
    # error h^1.5 / 4: the tail's law error (O(1/n) in the fourth moment) below what 2e5 samples resolve
    A = sample_levy_areas(w, h, rng, levy_area=method, levy_area_error=h**1.5 / 4)
    np.testing.assert_array_equal(A, -np.swapaxes(A, -1, -2))
    for i, j in [(0, 1), (0, 2), (1, 2)]:
        a = A[:, i, j]
        assert _z(a, 0, 0.0) < 4
        assert _z(a * a, 0, h * h / 4) < 4, (i, j)
        assert _z(a**4, 0, 5 * h**4 / 16) < 4, (i, j)
    assert _z(A[:, 0, 1] * A[:, 0, 2], 0, 0.0) < 4


@pytest.mark.parametrize("method,n", [("mrongowius-rossler", 1), ("mrongowius-rossler", 4),
                                      ("wiktorsson", 1), ("wiktorsson", 3)])
def test_conditional_covariance_is_exact_for_any_number_of_terms(method, n):
    rng = np.random.default_rng(12)
    d, h, N = 3, 0.2, 200_000
    w = np.array([0.7, -0.4, 0.25])                    # a fixed (large) increment
    z = rng.standard_normal((N, levy_area_normals(method, d, n)))
    A = levy_areas_from_normals(w, h, z, method, n)
    for i, j in [(0, 1), (0, 2), (1, 2)]:
        assert _z(A[:, i, j] ** 2, 0, h * h / 12 + h * (w[i] ** 2 + w[j] ** 2) / 12) < 4, (i, j)
    assert _z(A[:, 0, 1] * A[:, 0, 2], 0, h * w[1] * w[2] / 12) < 4      # Cov(A_01, A_02 | w)
    assert _z(A[:, 0, 1] * A[:, 1, 2], 0, -h * w[0] * w[2] / 12) < 4     # Cov(A_01, A_12 | w)


def test_plain_fourier_lacks_the_tail_variance():
    rng = np.random.default_rng(13)
    d, h, N, n = 2, 0.2, 200_000, 2
    w = np.array([0.5, -0.3])
    z = rng.standard_normal((N, levy_area_normals("fourier", d, n)))
    a = levy_areas_from_normals(w, h, z, "fourier", n)[:, 0, 1]
    exact = h * h / 12 + h * (w @ w) / 12
    deficit = h * h * float(polygamma(1, n + 1)) / (2 * math.pi**2)
    assert _z(a * a, 0, exact - deficit) < 4
    assert _z(a * a, 0, exact) > 8                                          # the exact value is rejected


def test_terms_and_choice_follow_the_documented_error_formulas():
    h = 1 / 256
    for d in (2, 3, 5):
        for m in FOURIER_METHODS:
            n = levy_area_terms(m, d, h)
            coef = {"fourier": h / (math.sqrt(2) * math.pi),
                    "mrongowius-rossler": math.sqrt(d) * h / (math.sqrt(12) * math.pi),
                    "wiktorsson": math.sqrt(5 * d) * h / (math.sqrt(12) * math.pi)}[m]
            order = 0.5 if m == "fourier" else 1.0
            assert coef * n ** -order <= h**1.5 < coef * max(n - 1, 0.5) ** -order
        method, n = choose_levy_area_method(d, h)
        cost = levy_area_normals(method, d, n)
        assert all(cost <= levy_area_normals(m, d, levy_area_terms(m, d, h)) for m in FOURIER_METHODS)


def test_members_do_not_affect_each_other():
    rng = np.random.default_rng(14)
    w = rng.normal(size=(6, 3)) * 10.0 ** rng.uniform(-6, 6, size=(6, 1))
    z = rng.standard_normal((6, levy_area_normals("wiktorsson", 3, 4)))
    A = levy_areas_from_normals(w, 0.1, z, "wiktorsson", 4)
    for i in range(6):
        np.testing.assert_array_equal(A[i], levy_areas_from_normals(w[i], 0.1, z[i], "wiktorsson", 4))


def test_bad_arguments_are_refused_clearly():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="levy_area must be one of"):
        sample_levy_areas(np.zeros(2), 0.1, rng, levy_area="exact-ish")
    with pytest.raises(ValueError, match="h must be a positive finite number"):
        levy_area_terms("fourier", 2, -1.0)
    with pytest.raises(ValueError, match="error must be a positive finite number"):
        levy_area_terms("fourier", 2, 0.1, error=float("nan"))
    with pytest.raises(ValueError, match="needs .* terms per step"):
        levy_area_terms("fourier", 2, 1.0, error=1e-9)
    with pytest.raises(ValueError, match="normals must have last dimension"):
        levy_areas_from_normals(np.zeros(2), 0.1, np.zeros(3), "fourier", 1)


@pytest.mark.parametrize("method", ["mrongowius-rossler", "wiktorsson", "fourier", "auto"])
def test_brownian_driver_uses_the_error_controlled_samplers_on_its_streams(method):
    """The driver's areas are levy_areas_from_normals of the documented per-path area stream, any blocks."""
    from roughpaths import BrownianDriver

    d, h, N, P = 3, 1 / 64, 10, 4
    drv = BrownianDriver(d, seed=5, dt=h, n_steps=N, batch_shape=(P,), levy_area=method)
    X = drv.rough_path()
    m, n = choose_levy_area_method(d, h) if method == "auto" else (method, levy_area_terms(method, d, h))
    w = levy_area_normals(m, d, n)
    ss = np.random.SeedSequence(5)
    for i in range(P):
        g = np.random.Generator(np.random.PCG64(np.random.SeedSequence(ss.entropy, spawn_key=(i, 1))))
        z = g.standard_normal(N * w).reshape(N, w)
        A = levy_areas_from_normals(X.increments[i], h, z, m, n)
        np.testing.assert_allclose(X.areas[i], A + 0.5 * X.increments[i][:, :, None] * X.increments[i][:, None, :],
                                   rtol=0, atol=1e-15)
    blocks = list(drv.blocks(max_steps=3))
    np.testing.assert_array_equal(np.concatenate([b.areas for b in blocks], axis=1), X.areas)
    np.testing.assert_array_equal(drv.select([2]).rough_path().areas[0], X.areas[2])
