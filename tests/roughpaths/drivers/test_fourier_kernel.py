"""The numba kernel of the error-controlled Lévy areas (``roughpaths.drivers._fourier_kernels``) in the driver.

Statement: for ``levy_area`` in ``"fourier"``, ``"mrongowius-rossler"``, ``"wiktorsson"`` and ``"auto"``,
``BrownianDriver``'s areas are the truncated Fourier series of ``levy_areas_from_normals`` evaluated on
the path's own area-stream normals, consumed step by step in the documented order (ξ, η, ψ, one per
pair), with each step's ``(method, n)`` from ``step_plan``: checked against a naive per-step numpy
reimplementation written here (rtol 1e-12, atol 1e-15 h), on uniform and non-uniform grids, ``d`` in
(2, 3, 5). Also: the kernel agrees with the numpy fallback used when the numba streams are unavailable;
the areas are bitwise invariant under the block size and ``select``; Itô = Stratonovich - ½ h I exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import polygamma

import roughpaths.drivers.brownian as brownian_module
from roughpaths import BrownianDriver
from roughpaths.drivers._fourier_kernels import _CHUNK
from roughpaths.drivers._random import PathStreams
from roughpaths.drivers.levy_area import levy_area_normals, step_plan

METHODS = ["fourier", "mrongowius-rossler", "wiktorsson", "auto"]
NONUNIFORM = np.concatenate([[0.0], np.cumsum(np.tile([1e-3, 4e-2, 2.5e-3, 1e-1, 1e-2], 3))])
# "long": more normals per path than the kernel draws at once (its chunk of whole steps ends inside a block)
GRIDS = {"uniform": dict(dt=0.01, n_steps=12), "nonuniform": dict(times=NONUNIFORM),
         "long": dict(dt=0.003, n_steps=150)}
STEPS = {"uniform": np.full(12, 0.01), "nonuniform": np.diff(NONUNIFORM), "long": np.full(150, 0.003)}


def _oracle_step(w, h, z, method, n):
    """Stratonovich area of one step (d x d) from its increment ``w`` and its normals ``z``, plainly."""
    d = w.size
    wt = w / math.sqrt(h)
    xi = z[:d * n].reshape(d, n)
    eta = z[d * n:2 * d * n].reshape(d, n)
    pos = 2 * d * n
    k = np.arange(1, n + 1)
    P = np.array([[np.sum(xi[i] * (eta[j] + math.sqrt(2.0) * wt[j]) / k) for j in range(d)] for i in range(d)])
    a = math.sqrt(2.0 * float(polygamma(1, n + 1)))
    if method != "wiktorsson":
        psi = z[pos:pos + d]
        pos += d
        P = P + a * np.outer(psi, wt)
    A = P - P.T
    if method != "fourier":
        G = np.zeros((d, d))
        q = 0
        for i in range(d):
            for j in range(i + 1, d):
                G[i, j], G[j, i] = a * z[pos + q], -a * z[pos + q]
                q += 1
        pos += q
        if method == "wiktorsson":
            kappa = 1.0 / (1.0 + math.sqrt(1.0 + wt @ wt))
            C = kappa * np.outer(G @ wt, wt)
            G = G + C - C.T
        A = A + G
    assert pos == z.size
    return h / (2.0 * math.pi) * A + 0.5 * np.outer(w, w)


def _oracle(drv, method, h):
    """The driver's Stratonovich areas, recomputed from its increments and its area streams' normals."""
    X = drv.rough_path()
    P, d = drv.n_paths, drv.dim
    plan = step_plan(method, d, h)
    widths = [levy_area_normals(plan[float(hk)][0], d, plan[float(hk)][1]) for hk in h]
    keys = np.zeros((P, 2), dtype=np.int64)
    keys[:, 0] = drv.path_indices
    keys[:, 1] = 1
    z = np.empty((P, sum(widths)))
    PathStreams(drv.seed_sequence, keys).fill(z)
    W = X.increments.reshape(P, -1, d)
    out = np.empty((P, h.size, d, d))
    for p in range(P):
        off = 0
        for r, hk in enumerate(h):
            m, n, _ = plan[float(hk)]
            out[p, r] = _oracle_step(W[p, r], float(hk), z[p, off:off + widths[r]], m, n)
            off += widths[r]
    return X.areas.reshape(P, -1, d, d), out, plan


@pytest.mark.parametrize("grid", list(GRIDS))
@pytest.mark.parametrize("method, d", [(m, d) for m in METHODS for d in (2, 3, 5) if (m, d) != ("auto", 2)])
def test_areas_equal_the_naive_per_step_series(method, d, grid):
    """(``"auto"`` at ``d = 2`` is the exact sampler, tested in test_levy_area_table.)"""
    drv = BrownianDriver(d, seed=np.random.SeedSequence(11, spawn_key=(2,)), batch_shape=(5,),
                         levy_area=method, **GRIDS[grid])
    h = STEPS[grid]
    got, want, plan = _oracle(drv, method, h)
    if grid == "nonuniform":
        assert len({v[:2] for v in plan.values()}) > 1       # steps of different (method, n)
    if grid == "long":
        assert sum(plan[0.003][2] for _ in h) > 2 * _CHUNK
    err = np.abs(got - want)
    tol = 1e-12 * np.abs(want) + 1e-15 * h[None, :, None, None]
    assert np.all(err <= tol), float(np.max(err / tol))


def test_auto_mixes_term_counts_on_the_nonuniform_grid():
    plan = step_plan("auto", 3, np.diff(NONUNIFORM))
    assert len({n for _, n, _ in plan.values()}) >= 3


@pytest.mark.parametrize("method", METHODS)
def test_kernel_agrees_with_the_numpy_fallback(method, monkeypatch):
    drv = BrownianDriver(3, seed=5, times=NONUNIFORM, batch_shape=(3,), levy_area=method)
    fast = drv.rough_path().areas
    monkeypatch.setattr(brownian_module, "PathStreams",
                        lambda ss, keys: PathStreams(ss, keys, _force_numpy=True))
    slow = drv.rough_path().areas
    np.testing.assert_allclose(fast, slow, rtol=1e-13, atol=1e-15 * NONUNIFORM[-1])


def test_areas_bitwise_invariant_under_blocks_and_select():
    drv = BrownianDriver(3, seed=9, times=NONUNIFORM, batch_shape=(7,), levy_area="mrongowius-rossler")
    X = drv.rough_path()
    for K in (1, 2, 4, 15):
        blocks = list(drv.blocks(max_steps=K))
        np.testing.assert_array_equal(np.concatenate([b.areas for b in blocks], axis=1), X.areas)
    for idx in ([6], [1, 4], [5, 0, 3], [2, 3, 4, 5, 6]):     # odd and even counts: paths drawn in pairs
        np.testing.assert_array_equal(drv.select(idx).rough_path().areas, X.areas[idx])


@pytest.mark.parametrize("method", METHODS)
def test_ito_is_stratonovich_minus_half_h(method):
    kw = dict(seed=4, times=NONUNIFORM, batch_shape=(3,), levy_area=method)
    S = BrownianDriver(3, kind="stratonovich", **kw).rough_path().areas
    I = BrownianDriver(3, kind="ito", **kw).rough_path().areas
    h = np.diff(NONUNIFORM)
    expect = S - 0.5 * h[None, :, None, None] * np.eye(3)
    np.testing.assert_array_equal(I, expect)
