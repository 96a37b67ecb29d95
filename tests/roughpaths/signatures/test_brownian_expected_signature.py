"""The expected Stratonovich signature of Brownian motion, ``exp(t/2 Σ eᵢ⊗eᵢ)``.

Claims:

* exact (1e-14) against an independent construction: the exponential series summed with a naive
  tensor product of dense ``(d,)*k`` arrays (``np.multiply.outer``), flattened at the end;
* against a Monte Carlo estimate (piecewise-linear signatures of sampled Brownian paths, whose
  expectation converges to the Stratonovich one), within 5 standard errors entrywise, on a grid fine
  enough that the grid's bias is below the standard error: on ``N`` steps of size ``h`` the
  piecewise-linear signature's expectation is ``E[exp(ΔB)]^{⊗N}``, exact at levels 1-3 and off at
  level 4 by ``t h / 24 (δ₁₃δ₂₄ + δ₁₄δ₂₃ − 2 δ₁₂δ₃₄)``, at most ``t h / 12`` in any entry;
* bad arguments are refused with the argument named.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import roughpaths as rp


def _naive_exp_pairs(d: int, depth: int, t: float) -> np.ndarray:
    """Σ_k A^{⊗k}/k! truncated at ``depth`` with A = (t/2) I at level 2, by dense tensor products."""
    A = [np.zeros((d,) * k) for k in range(depth + 1)]      # A[k] is level k; no scalar part
    if depth >= 2:
        A[2] = 0.5 * t * np.eye(d)

    def mul(a, b):
        c = [np.zeros((d,) * k) for k in range(depth + 1)]
        for i in range(depth + 1):
            for j in range(depth + 1 - i):
                c[i + j] = c[i + j] + np.multiply.outer(a[i], b[j])
        return c

    total = [np.zeros((d,) * k) for k in range(depth + 1)]
    total[0] = np.array(1.0)
    power = [x.copy() for x in total]                        # A^{⊗0} = 1
    for k in range(1, depth + 1):
        power = mul(power, A)
        total = [s + p / math.factorial(k) for s, p in zip(total, power)]
    return np.concatenate([total[k].reshape(-1) for k in range(1, depth + 1)])


@pytest.mark.parametrize("d, depth, t", [(1, 6, 1.0), (2, 5, 0.7), (3, 4, 2.5), (4, 4, 1.0), (2, 8, 3.0)])
def test_exact_against_a_naive_tensor_series(d, depth, t):
    got = rp.brownian_expected_signature(d, depth, t=t)
    want = _naive_exp_pairs(d, depth, t)
    assert got.shape == (rp.sigdim(d, depth),)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-14)
    assert np.count_nonzero(got) == sum(d ** k for k in range(1, depth // 2 + 1))   # the pair words only


def test_zero_time_and_scaling():
    assert not np.any(rp.brownian_expected_signature(3, 4, t=0.0))
    e1, e2 = rp.brownian_expected_signature(2, 6, t=1.0), rp.brownian_expected_signature(2, 6, t=2.0)
    level = np.concatenate([np.full(2 ** k, k) for k in range(1, 7)])
    np.testing.assert_allclose(e2, e1 * 2.0 ** (level / 2), rtol=1e-15)          # Brownian scaling


def _monte_carlo(d, depth, n_steps, n_paths, seed, t=1.0, chunk=8000):
    """Mean and standard error of the piecewise-linear signatures of ``n_paths`` Brownian samples."""
    rng = np.random.default_rng(seed)
    s1 = s2 = 0.0
    for lo in range(0, n_paths, chunk):
        k = min(chunk, n_paths - lo)
        dB = rng.standard_normal((k, n_steps, d)) * math.sqrt(t / n_steps)
        S = rp.signature(np.concatenate([np.zeros((k, 1, d)), dB.cumsum(axis=1)], axis=1), depth)
        s1, s2 = s1 + S.sum(axis=0), s2 + (S ** 2).sum(axis=0)
    mean = s1 / n_paths
    return mean, np.sqrt((s2 / n_paths - mean ** 2) / (n_paths - 1))


def _check_monte_carlo(d, depth, n_steps, n_paths, seed):
    mean, se = _monte_carlo(d, depth, n_steps, n_paths, seed)
    exact = rp.brownian_expected_signature(d, depth)
    bias = 1.0 / (12 * n_steps)                 # t h / 12, t = 1: the grid's largest bias (level 4)
    level = np.concatenate([np.full(d ** k, k) for k in range(1, depth + 1)])
    assert np.all(bias < se[level == 4]), (bias, se[level == 4].min())          # bias below the noise
    z = (mean - exact) / se
    assert np.abs(z).max() < 5.0, np.abs(z).max()


def test_monte_carlo_depth4_reduced():
    """d = 2, depth 4: 4000 paths of 128 steps; SE of level 4 ≥ 3.1e-3, bias ≤ 1/(12·128) ≈ 6.5e-4."""
    _check_monte_carlo(2, 4, 128, 4000, seed=11)


@pytest.mark.slow
def test_monte_carlo_depth4_full():
    """d = 3, depth 4: 100000 paths of 512 steps; SE of level 4 ≈ 6e-4, bias ≤ 1/(12·512) ≈ 1.6e-4."""
    _check_monte_carlo(3, 4, 512, 100_000, seed=12)


@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(dim=0, depth=2), ValueError, ["dim"]),
    (dict(dim=2, depth=0), ValueError, ["depth"]),
    (dict(dim=2, depth=2, t=-1.0), ValueError, ["t"]),
    (dict(dim=2, depth=2.5), TypeError, ["depth"]),
    (dict(dim=1000, depth=12), ValueError, ["memory budget", "lower depth"]),
])
def test_bad_arguments(kwargs, exc, words):
    with pytest.raises(exc) as info:
        rp.brownian_expected_signature(**kwargs)
    for w in words:
        assert w in str(info.value)
