r"""Claim: the series sampler (the exact d = 2 sampler's fallback) draws its normals in the documented order,
``21 + 32 μ`` on average plus the tail.

:mod:`roughpaths.drivers.levy_area` derives the cost of the series sampler: per step ``1 + 2 + 2``
normals for ``Z, E₁, E₂`` (an exponential is ``(Z₁² + Z₂²)/2``), for each of the 8 exact terms
``2(N_k + 1)`` for the Poisson arrivals and ``2N_k`` for ``Γ_k``, i.e. ``21 + 32 μ`` on average given
``μ = |w|²/h`` (``N_k ~ Poisson(μ)``); the Gamma tail takes 3 per Marsaglia–Tsang attempt, plus 2 when its
shape ``α = 12.8 μ`` is below 1 (measured mean 3.1, only measurable: the acceptance rate has no simple
closed form). ``E[μ] = 2``, so about 88 area normals per step.

The test re-implements the documented draw order in numpy over the stream
``Generator(PCG64(SeedSequence(seed, spawn_key=(i, 1))))`` of path ``i``, checks that it reproduces the
kernel's series-only areas (so its counts are the kernel's), and checks the counts: the exact part's mean against
``21 + 32 μ`` within 4 standard errors, the tail's shape constant and its measured mean.

Peers: LevyArea.jl's ``runtests.jl`` pins its sampler's output against a fixed reference; here the
reference is a re-implementation of the stream instead of stored numbers.
"""

import math

import numpy as np
import pytest

import roughpaths.drivers.levy_area as levy_area
from roughpaths import BrownianDriver
from roughpaths.drivers._area_kernels import _exact_areas_d2
from roughpaths.drivers._random import PathStreams
from roughpaths.drivers.areas import _EXACT_T1, _EXACT_T2, _EXACT_TERMS


class _Stream:
    def __init__(self, z):
        self.z, self.pos = z, 0

    def normal(self):
        self.pos += 1
        return self.z[self.pos - 1]

    def exp1(self):
        a, b = self.normal(), self.normal()
        return 0.5 * (a * a + b * b)


def _exact_step(w, h, s):
    """One step of the documented draw order: (Lévy area, μ, normals of the exact part, of the tail)."""
    mu = (w[0] ** 2 + w[1] ** 2) / h
    start = s.pos
    z, e1, e2 = s.normal(), s.exp1(), s.exp1()
    V = 0.0
    for k in range(1, _EXACT_TERMS + 1):
        n, t = 0, s.exp1()
        while t <= mu:
            n += 1
            t += s.exp1()
        g = sum(s.normal() ** 2 for _ in range(2 * n))
        V += 0.5 * g / (2 * math.pi ** 2) / (k * k)
    exact_part = s.pos - start
    if mu > 0:
        alpha = mu * _EXACT_T1 ** 2 / (2 * _EXACT_T2)
        a = alpha + 1 if alpha < 1 else alpha
        dd = a - 1 / 3
        c = 1 / math.sqrt(9 * dd)
        while True:
            x = s.normal()
            v = 1 + c * x
            if v <= 0:
                continue
            v = v ** 3
            if -s.exp1() < 0.5 * x * x + dd - dd * v + dd * math.log(v):
                break
        gam = dd * v
        if alpha < 1:
            gam *= math.exp(-s.exp1() / alpha)
        V += 2 * _EXACT_T2 / _EXACT_T1 * gam
    area = h * (math.log(e1 / e2) / (2 * math.pi) + math.sqrt(V) * z)
    return area, mu, exact_part, s.pos - start - exact_part


def test_draw_order_reproduces_the_driver_and_the_counts_are_as_derived():
    P, N, h, seed = 4, 1500, 0.01, 7
    X = BrownianDriver(2, seed=seed, dt=h, n_steps=N, batch_shape=(P,), levy_area=None).rough_path()
    keys = np.stack([np.arange(P), np.ones(P, dtype=np.int64)], axis=1)
    out = np.empty((P, N, 2, 2))
    states = PathStreams(np.random.SeedSequence(seed), keys).states
    _exact_areas_d2(np.ascontiguousarray(X.increments), np.full(N, h), states, np.empty((2, 0, 0)), 0.05,
                    _EXACT_TERMS, _EXACT_T1, _EXACT_T2, False, out)                  # series only
    levy = 0.5 * (out[..., 0, 1] - out[..., 1, 0])
    mus, exact_part, tail = [], [], []
    for i in range(P):
        s = _Stream(np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(i, 1))))
                    .standard_normal(400 * N))
        for k in range(N):
            area, mu, c_exact, c_tail = _exact_step(X.increments[i, k], h, s)
            assert abs(area - levy[i, k]) <= 1e-14
            mus.append(mu)
            exact_part.append(c_exact)
            tail.append(c_tail)
    mus, exact_part, tail = np.array(mus), np.array(exact_part), np.array(tail)
    resid = exact_part - (21 + 32 * mus)
    assert abs(resid.mean()) <= 4 * resid.std() / math.sqrt(resid.size)
    assert _EXACT_T1 ** 2 / (2 * _EXACT_T2) == pytest.approx(12.8, rel=0.01)
    small = mus * _EXACT_T1 ** 2 / (2 * _EXACT_T2) < 1
    assert np.all(tail[~small] >= 3) and np.all(tail[small] >= 5)
    assert 3.0 <= tail.mean() <= 3.3                                    # "measured mean 3.1"
    assert 80 <= (exact_part + tail).mean() <= 96                        # "about 88" (E[μ] = 2)


def test_docstring_states_the_derived_cost():
    doc = levy_area.__doc__
    assert "21 + 32 μ" in doc and "about 88" in doc
    assert "24 + 32 μ" not in doc
