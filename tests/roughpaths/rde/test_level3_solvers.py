r"""The level-3 solvers have order 3 on smooth drivers, and their building blocks are consistent.

Claim: fed the exact level-3 step signatures of a smooth path, :class:`roughpaths.Davie3` (third-order
Taylor step) and :class:`roughpaths.LogODE3` (log-ODE at depth 3) converge with order 3 to the solution of
the ODE driven by the path (Davie and LogODE, level 2, have order 2); the Hessian terms by central
differences equal those from supplied Hessians; on linear fields the matrix formulas equal the generic
non-linear code path; ``solve`` refuses mismatched levels with a clear message.

Oracle: the ODE along the finely sampled smooth path, integrated leg by leg with RK4 written here; closed
form Hessians of the test fields.
"""

import numpy as np
from _oracles import poly_fields, poly_jacobians, trig_fields, trig_jacobians
import pytest

from roughpaths import (Davie, Davie3, Heun, LinearVectorFields, LogODE, LogODE3, RoughPathN, VectorFields,
                        piecewise_linear_lift, solve)


_fields, _jac = trig_fields, trig_jacobians   # the shared trigonometric test fields


def _hess(y):
    """[..., k, a, b, c] = ∂_b ∂_c V_k^a, closed form."""
    y1, y2 = y[..., 0], y[..., 1]
    H = np.zeros(y.shape[:-1] + (2, 2, 2, 2))
    H[..., 0, 0, 1, 1] = -np.sin(y2)
    H[..., 0, 1, 0, 0] = -np.cos(y1)
    c = -0.5 * np.cos(y1 + y2)
    H[..., 1, 0, :, :] = c[..., None, None]
    H[..., 1, 1, 0, 0] = -np.sin(y1)
    return H


FIELDS = VectorFields(_fields, _jac, dim_state=2, dim_noise=2)
Y0 = np.array([0.3, -0.2])


def _ode(values, y0):
    y = y0.copy()
    for dx in np.diff(values, axis=-2):
        f = lambda z: (_fields(z) @ dx[:, None])[:, 0]
        k1 = f(y)
        k2 = f(y + 0.5 * k1)
        k3 = f(y + 0.5 * k2)
        k4 = f(y + k3)
        y = y + (k1 + 2 * k2 + 2 * k3 + k4) / 6.0
    return y


def test_smooth_order_three():
    n = 2 ** 13
    t = np.linspace(0.0, 1.0, n + 1)
    vals = 1.5 * np.stack([np.sin(3 * t) + 0.5 * t ** 2, np.cos(2 * t) - t], -1)
    ref = _ode(vals, Y0)
    Ks = np.array([8, 16, 32, 64])
    for solver, level, lo in [(Davie3(), 3, 2.7), (LogODE3(), 3, 2.7), (Davie3(hessians=_hess), 3, 2.7),
                              (Davie(), 2, 1.5)]:
        errs = [np.abs(solve(FIELDS, piecewise_linear_lift(vals, n // K, level=level), Y0, solver,
                             save_at="end").final - ref).max() for K in Ks]
        slope = np.polyfit(np.log(1.0 / Ks), np.log(errs), 1)[0]
        assert slope > lo, (solver, slope, errs)
        if level == 2:
            assert slope < 2.7, (solver, slope)   # level 2 cannot reach order 3: the check discriminates


def test_finite_difference_hessians_match_closed_form():
    X = RoughPathN.from_path(np.cumsum(np.random.default_rng(1).normal(0, 0.2, (4, 33, 2)), axis=-2), 3)
    for cls in (Davie3, LogODE3):
        a = solve(FIELDS, X, Y0, cls()).states
        b = solve(FIELDS, X, Y0, cls(hessians=_hess)).states
        np.testing.assert_allclose(a, b, atol=1e-8)


def test_linear_formula_equals_generic_path():
    M = 0.5 * np.random.default_rng(3).standard_normal((2, 3, 3))
    L = LinearVectorFields(M, drift=0.2 * np.eye(3))
    G = VectorFields(lambda y: np.einsum("iab,...b->...ai", M, y),
                     lambda y: np.broadcast_to(M, y.shape[:-1] + M.shape), drift=0.2 * np.eye(3),
                     dim_state=3, dim_noise=2)
    X = RoughPathN.from_path(np.cumsum(np.random.default_rng(4).normal(0, 0.2, (3, 17, 2)), axis=-2), 3)
    np.testing.assert_allclose(solve(L, X, np.ones(3), Davie3()).states,
                               solve(G, X, np.ones(3), Davie3()).states, atol=1e-12)
    np.testing.assert_allclose(solve(L, X, np.ones(3), LogODE3()).states,
                               solve(G, X, np.ones(3), LogODE3(inner_steps=32)).states, atol=1e-8)


def test_levels_are_checked():
    X3 = RoughPathN.from_path(np.cumsum(np.random.default_rng(5).normal(0, 0.2, (17, 2)), axis=0), 3)
    for solver in (Davie(), LogODE(), Heun()):
        with pytest.raises(ValueError, match="level-3 solver"):
            solve(FIELDS, X3, Y0, solver)
    with pytest.raises(ValueError, match="needs the driver's level-3"):
        solve(FIELDS, X3.to_rough_path(), Y0, Davie3())
    # the level-2 truncation is accepted when asked for explicitly
    assert solve(FIELDS, X3.to_rough_path(), Y0, Davie()).final.shape == (2,)
    with pytest.raises(TypeError, match="tuple"):
        Davie3().step(FIELDS, Y0, 0.0, 0.1, np.zeros(2), np.zeros((2, 2)))
    with pytest.raises(TypeError, match="hessians"):
        LogODE3(hessians=np.zeros(3))


def _poly_fields():
    return VectorFields(poly_fields, poly_jacobians, dim_state=3, dim_noise=2, drift=lambda y: -0.1 * y)


@pytest.mark.parametrize("kind", ["linear", "polynomial"])
@pytest.mark.parametrize("solver", [Davie3(), LogODE3()], ids=repr)
@pytest.mark.parametrize("seed", [0, 1])
def test_batch_members_independent(kind, solver, seed):
    """Each member's result is, bit for bit, its result alone (one member far out of scale, one NaN)."""
    rng = np.random.default_rng(seed)
    V = (LinearVectorFields(0.5 * rng.standard_normal((2, 3, 3)), drift=0.3 * rng.standard_normal((3, 3)))
         if kind == "linear" else _poly_fields())
    X = RoughPathN.from_path(np.cumsum(rng.normal(0, 0.1, (4, 17, 2)), axis=-2), 3)
    sig = X.step_signatures.copy()
    sig[1] *= 1e3                                                  # out of scale (not group-like: fine)
    sig[3, 5, 0] = np.nan
    with np.errstate(all="ignore"):
        Y = RoughPathN(sig, 2, times=X.times, check=False)
        sol = solve(V, Y, np.ones(3), solver, on_failure="mask")
        for i in range(4):
            alone = solve(V, RoughPathN(sig[i], 2, times=X.times, check=False), np.ones(3), solver,
                          on_failure="mask")
            assert np.array_equal(sol.states[i], alone.states, equal_nan=True), i
    assert sol.failed_step[3] == 5 and sol.failed_step[0] == -1
