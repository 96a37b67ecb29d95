"""Claim: ``sig_mmd_test`` returns the unbiased signature-kernel MMD² and a valid permutation p-value.

Oracles: the statistic recomputed from a naive full-grid Gram matrix; with two paths per sample every
relabelling is one of the six partitions of the pooled sample, whose statistics are enumerated here;
the level (p uniform under the null: both samples Brownian; binomial bounds on P(p <= 0.05) and
P(p <= 0.2) and a KS distance over many seeds, a reduced run by default and a large one marked slow);
the power (Brownian motion against fBM with H = 0.4, lead-lag paths, rejected at 5%).
"""

import itertools

import numpy as np
import pytest

import roughpaths as rp
from _oracles import naive_signature_kernel


def _brownian(rng, shape):
    return np.concatenate([np.zeros(shape[:-2] + (1, shape[-1])),
                           rng.normal(size=shape[:-2] + (shape[-2] - 1, shape[-1])).cumsum(-2)], -2) / np.sqrt(
        shape[-2] - 1)


def _naive_stat(K, inx):
    a, n = int(inx.sum()), K.shape[0]
    b = n - a
    off = ~np.eye(n, dtype=bool)
    xx = K[np.ix_(inx, inx)][off[np.ix_(inx, inx)]].sum() / (a * (a - 1))
    yy = K[np.ix_(~inx, ~inx)][off[np.ix_(~inx, ~inx)]].sum() / (b * (b - 1))
    return xx + yy - 2 * K[np.ix_(inx, ~inx)].sum() / (a * b)


def test_statistic_and_every_null_value_from_a_naive_gram():
    rng = np.random.default_rng(0)
    X, Y = _brownian(rng, (2, 5, 2)), _brownian(rng, (2, 4, 2)) + 0.3
    # equal lengths are not required; pool with a naive kernel of every pair
    Z = list(X) + list(Y)
    K = np.array([[naive_signature_kernel(u, v, 1, 0.9) for v in Z] for u in Z])
    res = rp.sig_mmd_test(X, Y, seed=3, n_permutations=200, dyadic_order=1, static_kernel=rp.RBFKernel(0.9))
    inx = np.array([True, True, False, False])
    assert res.statistic == pytest.approx(_naive_stat(K, inx), rel=1e-12)
    parts = [np.isin(np.arange(4), c) for c in itertools.combinations(range(4), 2)]
    values = np.array([_naive_stat(K, p) for p in parts])
    assert all(np.min(np.abs(values - v)) < 1e-12 * max(1, abs(v)) for v in res.null_statistics)
    assert res.p_value == (1 + np.count_nonzero(res.null_statistics >= res.statistic)) / 201
    # partitions equal to the observed one tie with it exactly (counted as >=): about 2 in 6 of them
    assert 0.2 < np.mean(res.null_statistics == res.statistic) < 0.47


def test_reproducible_from_seed():
    rng = np.random.default_rng(1)
    X, Y = _brownian(rng, (6, 7, 2)), _brownian(rng, (5, 7, 2))
    a, b = rp.sig_mmd_test(X, Y, seed=5, n_permutations=50), rp.sig_mmd_test(X, Y, seed=5, n_permutations=50)
    c = rp.sig_mmd_test(X, Y, seed=6, n_permutations=50)
    np.testing.assert_array_equal(a.null_statistics, b.null_statistics)
    assert a.p_value == b.p_value and a.statistic == c.statistic
    assert not np.array_equal(a.null_statistics, c.null_statistics)


def _null_p_values(seeds, size, n_points, n_perm):
    ps = []
    for s in seeds:
        rng = np.random.default_rng(s)
        X, Y = _brownian(rng, (size, n_points, 2)), _brownian(rng, (size, n_points, 2))
        ps.append(rp.sig_mmd_test(X, Y, seed=s, n_permutations=n_perm).p_value)
    return np.array(ps)


def _check_uniform(ps):
    n = ps.size
    # binomial bounds at about 3.5 standard deviations (exact permutation test: P(p <= k/(N+1)) = k/(N+1))
    for alpha in (0.05, 0.2):
        hits = np.count_nonzero(ps <= alpha + 1e-12)
        sd = np.sqrt(n * alpha * (1 - alpha))
        assert abs(hits - n * alpha) < 3.5 * sd + 1, (alpha, hits)
    grid = np.sort(ps)
    ks = np.max(np.abs(np.arange(1, n + 1) / n - grid))
    assert ks < 1.63 / np.sqrt(n) + 0.02, ks          # 1% KS critical value, plus the p-value grid step


def test_level_under_the_null_reduced():
    _check_uniform(_null_p_values(range(100), 8, 6, 99))


@pytest.mark.slow
def test_level_under_the_null_large():
    _check_uniform(_null_p_values(range(1000), 15, 10, 199))


def _lead_lag(p):
    twice = np.repeat(p, 2, axis=-2)
    return np.concatenate([twice[..., 1:, :], twice[..., :-1, :]], axis=-1)


def test_power_brownian_against_fbm():
    rejected = 0
    for s in range(10):
        rng = np.random.default_rng(1000 + s)
        X = rp.fbm(32, 0.5, rng=rng, batch_shape=(10,))
        Y = rp.fbm(32, 0.4, rng=rng, batch_shape=(10,))
        res = rp.sig_mmd_test(_lead_lag(X), _lead_lag(Y), seed=s, n_permutations=99,
                              static_kernel=rp.LinearKernel(2.0))
        rejected += res.p_value <= 0.05
    assert rejected >= 7, rejected


@pytest.mark.parametrize("call,match", [
    (lambda: rp.sig_mmd_test(np.zeros((1, 4, 2)), np.zeros((3, 4, 2)), seed=0), "at least 2 paths"),
    (lambda: rp.sig_mmd_test(np.zeros((2, 3, 4, 2)), np.zeros((2, 3, 4, 2)), seed=0), "samples, points, d"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 2)), seed=None), "seed"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 2)), seed=1.5), "seed must be an int"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 2)), seed=-1), "seed must be a non-negative"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 2)), seed=np.random.default_rng(0)), "Generator"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 2)), seed=0, n_permutations=0), "n_permutations"),
    (lambda: rp.sig_mmd_test(np.zeros((3, 4, 2)), np.zeros((3, 4, 1)), seed=0), "d=2 coordinates"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
