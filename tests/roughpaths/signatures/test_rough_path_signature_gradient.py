"""Claim: ``rough_path_signature_vjp`` is the vector–Jacobian product of ``rough_path_signature``.

``(g_inc, g_area) = d <G, S^{(m)}(X)> / d (X.increments, X.areas)``. Oracles: central finite
differences of ``rough_path_signature`` itself in every increment and area entry; for a
piecewise-linear lift the chain rule through ``inc_k = x_{k+1} - x_k`` must reproduce
``signature_vjp`` (an independent backward pass); the area cotangent is antisymmetric (only the
Lévy area enters the canonical extension).
"""

import numpy as np
import pytest

from roughpaths import rough_path_signature, rough_path_signature_vjp, RoughPath, signature_vjp


def _rough(rng, n, d, batch=()):
    inc = rng.standard_normal(batch + (n, d)) * 0.5
    b = rng.standard_normal(batch + (n, d, d)) * 0.3
    areas = 0.5 * inc[..., :, None] * inc[..., None, :] + 0.5 * (b - np.swapaxes(b, -1, -2))
    return inc, areas


@pytest.mark.parametrize("d,m", [(2, 3), (3, 4)])
def test_vjp_equals_finite_differences(rng, d, m):
    inc, areas = _rough(rng, 3, d)
    X = RoughPath(inc, areas, kind="geometric")
    g = rng.standard_normal(rough_path_signature(X, m).shape)
    gi, ga = rough_path_signature_vjp(X, m, g)

    def f(i, a):
        return g @ rough_path_signature(RoughPath(i, a, kind="geometric", check=False), m)

    h = 1e-6
    for idx in np.ndindex(inc.shape):
        e = np.zeros(inc.shape)
        e[idx] = h
        assert abs((f(inc + e, areas) - f(inc - e, areas)) / (2 * h) - gi[idx]) < 1e-7
    for idx in np.ndindex(areas.shape):
        e = np.zeros(areas.shape)
        e[idx] = h
        assert abs((f(inc, areas + e) - f(inc, areas - e)) / (2 * h) - ga[idx]) < 1e-7
    np.testing.assert_allclose(ga, -np.swapaxes(ga, -1, -2), atol=1e-15)


def test_piecewise_linear_lift_matches_signature_vjp(rng):
    x = np.cumsum(rng.standard_normal((2, 7, 3)), axis=-2) * 0.5
    g = rng.standard_normal((2, 39))
    gi, _ = rough_path_signature_vjp(RoughPath.from_path(x), 3, g)
    gx = np.zeros(x.shape)
    gx[..., 1:, :] += gi
    gx[..., :-1, :] -= gi
    np.testing.assert_allclose(gx, signature_vjp(x, 3, g), atol=1e-12)


def test_bad_input(rng):
    inc, areas = _rough(rng, 3, 2)
    X = RoughPath(inc, areas, kind="geometric")
    with pytest.raises(TypeError, match="RoughPath"):
        rough_path_signature_vjp(inc, 2, np.zeros(6))
    with pytest.raises(ValueError, match="grad_output"):
        rough_path_signature_vjp(X, 2, np.zeros(5))
