r"""``roughpaths.ColouredNoiseDriver``: per-path seeded coloured noise, its stream and its law.

Claims tested:

* invariance: the same bits whatever the block size, the paths generated together (``select``)
  or the process; the blocks chain (``x0`` of a block is the end of the previous one);
* stream definition: path ``i``'s stationary start is ``L z`` with ``z`` the first ``n`` normals of
  ``Generator(PCG64(SeedSequence(seed, spawn_key=(i,))))``, ``LLᵀ = Σ``;
* law after one step from the stationary start, against the exact Van Loan law
  (:func:`roughpaths.ou_step_law`): ``Cov(y_h) = Σ``, ``Cov(ΔB^ε) = (T_J Σ T_Jᵀ + Q_JJ)/ε²``,
  ``Cov(ΔB) = h I`` (within 5 standard errors; the wrong ``ε`` scaling fails);
* bad arguments raise naming the argument.
"""

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from roughpaths import ColouredNoiseDriver, coloured_noise_limit, ou_step_law

A = np.array([[1.0, 2.0], [-0.5, 1.5]])
D = np.array([[1.0, 0.0], [0.3, 0.8]])


def _areas(drv, K=None):
    return np.concatenate([b.areas for b in drv.blocks(K)], axis=-3)


def test_bitwise_invariance_blocks_select_processes():
    drv = ColouredNoiseDriver(A, D, 0.2, seed=8, times=np.r_[0.0, 0.01, 0.05, 0.07, np.linspace(0.1, 0.3, 9)],
                              batch_shape=(2, 3))
    full = drv.rough_path()
    for K in (1, 4, 100):
        np.testing.assert_array_equal(_areas(drv, K), full.areas)
        blocks = list(drv.blocks(K))
        for b0, b1 in zip(blocks, blocks[1:]):
            np.testing.assert_allclose(b1.x0, b0.x0 + b0.increments.sum(axis=-2), atol=1e-14)
    flat = full.areas.reshape((6,) + full.areas.shape[2:])
    np.testing.assert_array_equal(_areas(drv.select([4, 1])), flat[[4, 1]])
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(_areas, [drv.select(range(0, 3)), drv.select(range(3, 6))]))
    np.testing.assert_array_equal(np.concatenate(parts), flat)
    # a given start is carried by select
    drv2 = ColouredNoiseDriver(A, D, 0.2, seed=8, dt=0.02, n_steps=5, batch_shape=(3,), y0=[[0.0, 1.0], [2, 3], [4, 5]])
    np.testing.assert_array_equal(_areas(drv2.select([2])), _areas(drv2)[[2]])


def test_stationary_start_is_the_first_normals_of_the_path_stream():
    Ls = np.linalg.cholesky(coloured_noise_limit(A, D).Sigma)
    drv = ColouredNoiseDriver(A, D, 0.3, seed=21, dt=0.01, n_steps=1, batch_shape=(3,))
    y0 = drv.initial_state()
    for i in range(3):
        g = np.random.Generator(np.random.PCG64(np.random.SeedSequence(21, spawn_key=(i,))))
        np.testing.assert_allclose(y0[i], Ls @ g.standard_normal(2), rtol=1e-14)
    np.testing.assert_array_equal(drv.select([2, 0]).initial_state(), y0[[2, 0]])
    given = ColouredNoiseDriver(A, D, 0.3, seed=21, dt=0.01, n_steps=1, y0=[1.0, -2.0])
    np.testing.assert_array_equal(given.initial_state(), [1.0, -2.0])


@pytest.mark.parametrize("eps", [0.3, 1.0])
def test_one_step_law_matches_van_loan(eps):
    h, P = 0.2, 20000
    n, m = D.shape
    drv = ColouredNoiseDriver(A, D, eps, seed=5, dt=h, n_steps=1, batch_shape=(P,))
    path, bro, y = next(drv.blocks_with_brownian())
    T, Q = ou_step_law(A, D, eps, h)
    Sigma = coloured_noise_limit(A, D).Sigma
    covJ = T[n:2 * n] @ Sigma @ T[n:2 * n].T + Q[n:2 * n, n:2 * n]
    for sample, target in ((y[:, 0], Sigma), (path.increments[:, 0], covJ / eps ** 2), (bro.increments[:, 0], h * np.eye(m))):
        emp = sample.T @ sample / P
        se = np.sqrt((np.diag(target)[:, None] * np.diag(target)[None, :] + target ** 2) / P)
        assert np.all(np.abs(emp - target) <= 5 * se), (emp, target)
    wrong = covJ / eps ** 4 if eps != 1.0 else 2 * covJ
    assert not np.all(np.abs(path.increments[:, 0].T @ path.increments[:, 0] / P - wrong) <= 5 * se)


@pytest.mark.parametrize("kw, exc, word", [
    (dict(seed=1), ValueError, "times"),
    (dict(seed=np.random.default_rng(), dt=0.1, n_steps=2), TypeError, "seed"),
    (dict(seed=1, dt=0.1, n_steps=2, y0="zero"), ValueError, "y0"),
    (dict(seed=1, dt=0.1, n_steps=2, y0=np.zeros(3)), ValueError, "y0"),
    (dict(seed=1, dt=0.1, n_steps=2, batch_shape=(2,), y0=np.zeros((3, 2))), ValueError, "y0"),
])
def test_bad_arguments(kw, exc, word):
    with pytest.raises(exc, match=word):
        ColouredNoiseDriver(A, D, 0.1, **kw)
