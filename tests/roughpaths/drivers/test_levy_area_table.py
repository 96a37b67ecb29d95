r"""The quantile table of the exact d = 2 Lévy-area sampler: its values, its law error, its file.

Claim (:mod:`roughpaths.drivers._levy_table`): the table holds the quantile ``g(s, z)`` of
``a = A/h`` given ``μ = s²`` at the normal quantile ``z`` (``F_μ(g) = Φ(z)``) and ``∂g/∂z``; the
sampler ``a = g̃(√μ, |z|) sign(z)`` (cubic Hermite in ``z``, 4-point Lagrange in ``s``) is within
Kolmogorov distance 6·10⁻⁸ of the exact conditional law; the driver draws one normal per step and
applies exactly this map; a damaged table file is refused.

Oracles: the CDF from the characteristic function by adaptive quadrature (scipy ``quad``, a
different rule from the table's trapezoid sums), the closed-form logistic law at ``μ = 0``, and a
naive numpy re-implementation of the interpolation.
"""

import numpy as np
import pytest
from scipy import integrate
from scipy.special import ndtr

import roughpaths.drivers._levy_table as levy_table
from roughpaths import BrownianDriver
from roughpaths.drivers._area_kernels import _table_quantile


def _cf(lam, mu):
    x = lam / 2
    return x / np.sinh(x) * np.exp(-mu / 2 * (x / np.tanh(x) - 1))


def _cdf(a, mu):
    """Gil-Pelaez by adaptive quadrature: F(a) = 1/2 + (1/π) ∫_0^∞ sin(λa) φ(λ)/λ dλ."""
    top = 2 * 40.0 / (1 + mu / 2) + 20
    return np.array([0.5 + integrate.quad(lambda l: np.sin(l * x) * _cf(l, mu) / l, 1e-12, top, limit=800,
                                          epsabs=1e-14, epsrel=1e-13)[0] / np.pi for x in np.atleast_1d(a)])


def _naive_quantile(table, step, s, z):
    """The documented interpolation, written out in numpy (rows mirrored at s = 0)."""
    i = min(int(s / step), table.shape[1] - 3)
    u = s / step - i
    j = min(int(z / step), table.shape[2] - 2)
    v = z / step - j
    herm = [2 * v ** 3 - 3 * v ** 2 + 1, (v ** 3 - 2 * v ** 2 + v) * step, -2 * v ** 3 + 3 * v ** 2, (v ** 3 - v ** 2) * step]
    nodes = [-1.0, 0.0, 1.0, 2.0]
    total = 0.0
    for q, x in enumerate(nodes):
        lag = np.prod([(u - y) / (x - y) for y in nodes if y != x])
        r = abs(i - 1 + q)
        total += lag * (herm[0] * table[0, r, j] + herm[1] * table[1, r, j] + herm[2] * table[0, r, j + 1]
                        + herm[3] * table[1, r, j + 1])
    return total


def test_gil_pelaez_of_the_table_matches_the_logistic_law_and_quadrature():
    a = np.linspace(-3.0, 3.0, 25)
    F, f = levy_table.conditional_cdf_pdf(a, 0.0)
    e = np.exp(-2 * np.pi * a)
    np.testing.assert_allclose(F, 1 / (1 + e), atol=1e-15)
    np.testing.assert_allclose(f, 2 * np.pi * e / (1 + e) ** 2, atol=1e-14)
    for mu in (0.7, 9.0, 40.0):
        a = np.linspace(-3, 3, 7) * np.sqrt((1 + mu) / 12)
        np.testing.assert_allclose(levy_table.conditional_cdf_pdf(a, mu)[0], _cdf(a, mu), atol=1e-12)


def _summation_scales(mu):
    """``(S_F, S_f)``: the sums of absolute terms of the Gil-Pelaez sums for ``F`` and ``f``.

    A CPU whose vector units sum in another order changes ``F`` and ``f`` by a few ulps of these (not of
    ``F`` or ``f`` themselves), so they set the tolerance of any comparison of rebuilt values.
    """
    lam = levy_table._lambda_grid(mu)
    x = 0.5 * lam
    phi = np.abs(x / np.sinh(x) * np.exp(-0.5 * mu * (x / np.tanh(x) - 1.0)))
    c = levy_table._D_LAMBDA / np.pi
    return c * (phi / lam).sum() + 0.5, c * (phi.sum() + 0.5)


def test_shipped_rows_are_the_regenerated_rows():
    """Rebuilt rows equal the shipped ones within the conditioning of the quantile, on any CPU.

    In the far tail (``z`` near 7) the density is ~4e-12, so a change of 1e-15 in the CDF, which another
    summation order can make, moves the quantile by ~3e-4: the rows are compared in the CDF domain
    (both solve ``F(g) = Φ(z)`` to the summation accuracy) and then entry by entry with the tolerance that
    the condition number ``1/f`` gives, never bit for bit.
    """
    table = levy_table.load_table()
    rows = [0, 1, 37, 140]
    rebuilt = levy_table.build_table(rows)
    z = levy_table.TABLE_STEP * np.arange(table.shape[2])
    eps = np.finfo(float).eps
    for r, i in enumerate(rows):
        mu = (levy_table.TABLE_STEP * i) ** 2
        S_F, S_f = _summation_scales(mu)
        tol_F = 1e-15 + 32 * eps * S_F                    # Newton's stop (1e-15) plus summation error
        F_shipped, f = levy_table.conditional_cdf_pdf(table[0, i], mu)
        F_rebuilt, _ = levy_table.conditional_cdf_pdf(rebuilt[0, r], mu)
        assert np.abs(F_shipped - ndtr(z)).max() <= tol_F, f"row {i}: shipped quantiles off in the CDF domain"
        assert np.abs(F_rebuilt - ndtr(z)).max() <= tol_F, f"row {i}: rebuilt quantiles off in the CDF domain"
        dg = 2 * tol_F / f + 1e-14 * np.abs(table[0, i])   # the quantile's condition number is 1/f
        np.testing.assert_array_less(np.abs(rebuilt[0, r] - table[0, i]), dg)
        # ∂g/∂z = φ_N(z)/f(g): the relative error of f (summation error over f) plus f's change over dg,
        # |f'/f| <= max(2π, 7 sqrt(12/(1+μ))) < 8π on the table (logistic tail at μ = 0, Gaussian-like beyond)
        rel_f = 32 * eps * S_f / f + 8 * np.pi * dg
        np.testing.assert_array_less(np.abs(rebuilt[1, r] - table[1, i]), (rel_f + 1e-13) * np.abs(table[1, i]))
        # and a loose absolute check that would catch a different table (a wrong row or a wrong law)
        np.testing.assert_allclose(rebuilt[:, r], table[:, i], rtol=5e-3, atol=1e-12)


@pytest.mark.parametrize("mu", [0.0006, 0.05, 1.3, 10.0, 48.0])
def test_interpolated_quantiles_are_within_the_stated_kolmogorov_distance(mu):
    table, step = levy_table.load_table(), levy_table.TABLE_STEP
    s = np.sqrt(mu)
    z = np.concatenate([np.arange(0.5, 140) * step, [0.013, 3.333, 6.99]])
    g = np.array([_table_quantile(table, step, s, x) for x in z])
    assert np.all(np.diff(g[:139]) > 0)                               # increasing in z
    err = np.abs(_cdf(g, mu) - ndtr(z))
    assert err.max() < 6.5e-8, (mu, err.max(), z[err.argmax()])
    # the naive re-implementation agrees; the area without the ½ (twice a) is far off
    np.testing.assert_allclose(g[::10], [_naive_quantile(table, step, s, x) for x in z[::10]], rtol=1e-13, atol=1e-15)
    assert np.abs(_cdf(2 * g[::10], mu) - ndtr(z[::10])).max() > 0.05


def test_driver_draws_one_normal_per_step_and_applies_the_table():
    P, N, h, seed = 3, 200, 0.02, 5
    X = BrownianDriver(2, seed=seed, dt=h, n_steps=N, batch_shape=(P,), levy_area="exact").rough_path()
    table, step = levy_table.load_table(), levy_table.TABLE_STEP
    for i in range(P):
        z = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(i, 1)))).standard_normal(N)
        w = X.increments[i]
        mu = (w ** 2).sum(-1) / h
        assert np.all(np.sqrt(mu) < 7) and np.all(np.abs(z) < 7)      # no fallback in this sample
        want = h * np.sign(z) * np.array([_naive_quantile(table, step, np.sqrt(m), abs(x)) for m, x in zip(mu, z)])
        np.testing.assert_allclose(X.step_levy_areas[i, :, 0, 1], want, rtol=1e-12, atol=1e-16)


def test_fallback_beyond_the_table_is_finite_and_has_the_conditional_variance():
    """|w|²/h = 64 > 49: every area comes from the series sampler (its law is tested in
    test_levy_area_exact_d2); here: through the driver's kernel, the variance h²(1 + μ)/12."""
    from roughpaths.drivers._area_kernels import _exact_areas_d2
    from roughpaths.drivers._random import PathStreams
    from roughpaths.drivers.areas import _EXACT_T1, _EXACT_T2, _EXACT_TERMS

    n, h = 20_000, 0.25
    dW = np.broadcast_to(np.array([8.0, 0.0]) * np.sqrt(h), (n, 1, 2)).copy()
    keys = np.stack([np.arange(n), np.ones(n, dtype=np.int64)], axis=1)
    out = np.empty((n, 1, 2, 2))
    _exact_areas_d2(dW, np.array([h]), PathStreams(np.random.SeedSequence(2), keys).states, levy_table.load_table(),
                    levy_table.TABLE_STEP, _EXACT_TERMS, _EXACT_T1, _EXACT_T2, False, out)
    a = 0.5 * (out[:, 0, 0, 1] - out[:, 0, 1, 0]) / h
    assert np.all(np.isfinite(a))
    assert abs(a.var() / (65 / 12) - 1) < 5 * np.sqrt(2.4 / n)


def test_a_damaged_table_is_refused(tmp_path, monkeypatch):
    raw = bytearray(open(levy_table._PATH, "rb").read())
    raw[-8] ^= 1
    bad = tmp_path / "levy_area_d2.npy"
    bad.write_bytes(bytes(raw))
    monkeypatch.setattr(levy_table, "_PATH", str(bad))
    monkeypatch.setattr(levy_table, "_CACHE", [])
    with pytest.raises(RuntimeError, match="damaged"):
        levy_table.load_table()
    monkeypatch.setattr(levy_table, "_PATH", str(tmp_path / "missing.npy"))
    with pytest.raises(RuntimeError, match="missing"):
        levy_table.load_table()
