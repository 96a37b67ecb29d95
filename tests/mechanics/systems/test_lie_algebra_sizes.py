"""Claim: ``LieAlgebra`` checks its structure constants in ``O(n⁴)`` flops and ``O(n²)`` extra memory (so(16),
``n = 120``, constructs within 100 MB; the full Jacobi tensor took 4.7 GB and 88 s), still finds violations of
the Jacobi identity (planted, of size 100 x the tolerance, at random places), accepts dense constants of a
genuine algebra, and refuses an algebra too large for the memory budget before it allocates.

Oracles: so(N) constants written from the closed form ``[L_ab, L_cd] = δ_bc L_ad - δ_ac L_bd - δ_bd L_ac +
δ_ad L_bc``; a random orthogonal change of basis (still a Lie algebra, dense constants); the Killing form of
so(N), ``K = -2 (N - 2) I`` in this basis; tracemalloc for the peak.
"""

import time
import tracemalloc

import numpy as np
import pytest

from mechanics.systems.lie_algebra import LieAlgebra


def _so_constants(N):
    pairs = [(a, b) for a in range(N) for b in range(a + 1, N)]
    index = {p: k for k, p in enumerate(pairs)}

    def L(a, b):                       # L_ab as (sign, index); L_aa = 0
        if a == b:
            return 0.0, 0
        return (1.0, index[(a, b)]) if a < b else (-1.0, index[(b, a)])

    n = len(pairs)
    c = np.zeros((n, n, n))
    for i, (a, b) in enumerate(pairs):
        for j, (p, q) in enumerate(pairs):
            for coef, (x, y) in (((b == p), (a, q)), (-(a == p), (b, q)), (-(b == q), (a, p)), ((a == q), (b, p))):
                if coef:
                    s, k = L(x, y)
                    c[i, j, k] += coef * s
    return c


def test_so16_constructs_in_little_memory_and_time():
    c = _so_constants(16)
    assert c.shape == (120, 120, 120)
    tracemalloc.start()
    t = time.perf_counter()
    try:
        g = LieAlgebra(c, name="so16")
        elapsed = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100 * 2 ** 20, peak / 2 ** 20           # measured 13 MB (one n³ temporary)
    assert elapsed < 10.0, elapsed                         # 0.1-0.5 s measured; the n⁴ tensor took 88 s
    np.testing.assert_allclose(g.killing_form(), -2 * (16 - 2) * np.eye(120), atol=1e-12)
    assert g.is_semisimple


def test_dense_constants_of_a_genuine_algebra_are_accepted():
    c = _so_constants(6)
    Q, _ = np.linalg.qr(np.random.default_rng(0).normal(size=(15, 15)))
    dense = np.einsum("ia,jb,abc,kc->ijk", Q, Q, c, Q)     # the same algebra in an orthonormal basis
    assert np.count_nonzero(np.abs(dense) > 1e-3) > 0.5 * dense.size
    g = LieAlgebra(dense)
    x, y, z = np.random.default_rng(1).normal(size=(3, 15))
    jac = g.bracket(g.bracket(x, y), z) + g.bracket(g.bracket(y, z), x) + g.bracket(g.bracket(z, x), y)
    assert np.max(np.abs(jac)) < 1e-12


@pytest.mark.parametrize("seed", range(5))
def test_planted_jacobi_violations_are_found(seed):
    rng = np.random.default_rng(seed)
    c = _so_constants(5)
    n = c.shape[0]
    for _ in range(4):
        i, j, k = rng.choice(n, size=3, replace=False)
        bad = c.copy()
        D = 100 * 1e-10                                   # 100 x the tolerance atol * max|c|**2
        bad[i, j, k] += D
        bad[j, i, k] -= D                                 # still antisymmetric: only Jacobi is broken
        with pytest.raises(ValueError, match="Jacobi identity"):
            LieAlgebra(bad)


def test_an_algebra_beyond_the_memory_budget_is_refused_first(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(2 ** 20))
    with pytest.raises(ValueError, match=r"Lie algebra of dimension n=60 .* would take \d.* MiB"):
        LieAlgebra(np.zeros((60, 60, 60)))


def test_semisimplicity_of_a_killing_form_whose_determinant_overflows():
    # so(3)^6 with constants scaled by 1e10: K = -2e20 I (18 x 18), det K = 2.6e365 overflows float64
    # (so(25), n = 300, raised OverflowError in the constructor for the same reason)
    eps = np.zeros((3, 3, 3))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        eps[i, j, k], eps[j, i, k] = 1.0, -1.0
    c = np.zeros((18, 18, 18))
    for b in range(6):
        c[3 * b:3 * b + 3, 3 * b:3 * b + 3, 3 * b:3 * b + 3] = 1e10 * eps
    g = LieAlgebra(c)
    assert c.flags.writeable                  # the caller's array is not frozen (a copy is kept)
    np.testing.assert_allclose(g.killing_form(), -2e20 * np.eye(18), rtol=1e-15)
    assert g.is_semisimple and g.has_casimirs
    c[:3] = 0.0                               # an abelian summand: degenerate, not semisimple
    c[:, :3] = 0.0
    assert not LieAlgebra(c).is_semisimple
