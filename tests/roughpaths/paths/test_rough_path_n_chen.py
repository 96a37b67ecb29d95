r"""Level-N rough paths obey Chen's identity and match the iterated integrals of the polygon (iisignature).

Claim: a :class:`roughpaths.RoughPathN` built from data (``from_path``, ``piecewise_linear_lift``)
returns, for grid times ``s < t``, the truncated signature of the polygon between them (Chen); its
restriction, reversal and concatenation are those of the polygon; ``perturb(s)`` keeps the steps
group-like and agrees at level 2 with :meth:`RoughPath.perturb`; the level-2 conversion round-trips; the
homogeneous Hölder and p-variation norms equal their definitions evaluated by brute force.

Oracles: ``iisignature.sig`` of the polygon pieces; for the norms, enumeration of all partitions of a
short grid with the same signatures from ``iisignature``.
"""

import itertools

import iisignature
import numpy as np
import pytest

from roughpaths import RoughPath, RoughPathN, piecewise_linear_lift

rng = np.random.default_rng(31)
V = np.cumsum(rng.standard_normal((2, 17, 3)), axis=-2)
T = np.linspace(0.0, 2.0, 17)


@pytest.mark.parametrize("level", [1, 2, 3, 4])
def test_chen_queries_match_iisignature(level):
    X = RoughPathN.from_path(V, level, times=T)
    for i, j in [(0, 16), (3, 9), (5, 6), (0, 1)]:
        ref = iisignature.sig(V[:, i:j + 1], level)
        np.testing.assert_allclose(X.signature(T[i], T[j]), ref, atol=1e-13 * (1 + np.abs(ref).max()))
    np.testing.assert_allclose(X.signature(T[4], T[4]), 0.0, atol=1e-14)


def test_restrict_reverse_concatenate():
    X = RoughPathN.from_path(V, 3, times=T)
    R = X.restrict(T[::4])
    for k in range(4):
        np.testing.assert_allclose(R.step_signatures[:, k], iisignature.sig(V[:, 4 * k:4 * k + 5], 3), atol=1e-12)
    np.testing.assert_allclose(R.path, V[:, ::4], atol=1e-12)
    Rv = X.reverse()
    np.testing.assert_allclose(Rv.signature(0.0, 2.0), iisignature.sig(V[:, ::-1], 3), atol=1e-11)
    np.testing.assert_allclose(Rv.x0, V[:, -1])
    C = X.restrict(T[:9]).concatenate(X.restrict(T[8:]))
    np.testing.assert_allclose(C.signature(0.0, 2.0), iisignature.sig(V, 3), atol=1e-11)
    L = piecewise_linear_lift(V, 4, level=3, times=T)
    np.testing.assert_allclose(L.step_signatures, R.step_signatures, atol=1e-12)


def test_level2_conversion_and_perturb():
    X2 = RoughPath.from_path(V, times=T)
    X = RoughPathN.from_rough_path(X2, 3)
    np.testing.assert_allclose(X.to_rough_path().areas, X2.areas, atol=1e-14)
    np.testing.assert_allclose(X.signature(0.0, 2.0), iisignature.sig(V, 3), atol=1e-11)  # linear steps
    s = np.array([[0.0, 0.4, -0.2], [-0.4, 0.0, 0.7], [0.2, -0.7, 0.0]])
    P = X.perturb(s)
    np.testing.assert_allclose(P.to_rough_path().areas, X2.perturb(s).areas, atol=1e-13)
    np.testing.assert_allclose(P.area(0.0, 2.0), X2.perturb(s).area(0.0, 2.0), atol=1e-12)
    RoughPathN(P.step_signatures, 3, times=T)                    # still group-like: the check passes
    with pytest.raises(ValueError, match="group-like"):
        bad = P.step_signatures.copy()
        bad[..., 3 + 9 + 5] += 0.1                               # a level-3 entry off the Lie algebra
        RoughPathN(bad, 3, times=T)
    with pytest.raises(ValueError, match="antisymmetric"):
        X.perturb(np.eye(3))


def _hom(g, d, level):
    out, start = 0.0, 0
    for k in range(1, level + 1):
        out = max(out, np.linalg.norm(g[..., start:start + d ** k]) ** (1.0 / k))
        start += d ** k
    return out


def test_norms_by_brute_force():
    v = V[0, :8]
    t = T[:8]
    X = RoughPathN.from_path(v, 3, times=t)
    n = 7
    p = 3.5
    best = 0.0
    for cuts in itertools.product([False, True], repeat=n - 1):
        pts = [0] + [k + 1 for k, c in enumerate(cuts) if c] + [n]
        best = max(best, sum(_hom(iisignature.sig(v[a:b + 1], 3), 3, 3) ** p for a, b in zip(pts, pts[1:])))
    np.testing.assert_allclose(X.p_variation(p), best ** (1 / p), rtol=1e-10)
    alpha = 0.4
    hol = max(_hom(iisignature.sig(v[a:b + 1], 3), 3, 3) / (t[b] - t[a]) ** alpha
              for a in range(n) for b in range(a + 1, n + 1))
    np.testing.assert_allclose(X.holder_norm(alpha), hol, rtol=1e-10)
    with pytest.raises(ValueError, match="max_points"):
        X.p_variation(p, max_points=4)


def test_batch_axes_and_indexing():
    X = RoughPathN.from_path(V, 2, times=T)
    assert X.batch_shape == (2,) and X.n_steps == 16 and X.dim == 3 and X.level == 2
    np.testing.assert_allclose(X[1].signature(0.0, 2.0), iisignature.sig(V[1], 2), atol=1e-12)
    assert X.areas.shape == (2, 16, 3, 3) and X.increments.shape == (2, 16, 3)


def test_group_roundtrips():
    """perturb(s) then perturb(-s), and reversing twice, give the path back (to round-off)."""
    X = RoughPathN.from_path(V, 3, times=T)
    s = np.array([[0.0, 0.4, -0.2], [-0.4, 0.0, 0.7], [0.2, -0.7, 0.0]])
    np.testing.assert_allclose(X.perturb(s).perturb(-s).step_signatures, X.step_signatures, atol=1e-12)
    np.testing.assert_allclose(X.reverse().reverse().step_signatures, X.step_signatures, atol=1e-12)
    np.testing.assert_allclose(X.reverse().reverse().times, T)
    # the perturbation changes level 3 by ½(x⊗s h + s h⊗x) per step (exp(ℓ + s h) with level-1 x)
    h = T[1] - T[0]
    x = X.increments
    d3 = X.perturb(s).step_level(3) - X.step_level(3)
    expect = 0.5 * (x[..., :, None, None] * (s * h)[None, None, None] + (s * h)[None, None, :, :, None]
                    * x[..., None, None, :])
    np.testing.assert_allclose(d3, expect, atol=1e-12)
