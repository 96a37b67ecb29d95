r"""Friz–Oberhauser, pathwise, on fractional Brownian rough paths (``H = 0.4`` at level 2, ``H = 0.3`` at level 3).

Claim (``docs/conventions.md``): for a geometric rough path ``X`` and antisymmetric ``s``, the solution of
``dY = V_i(Y) dX̃^i`` with the perturbed path ``X̃`` (area ``XX + s (t - s)``; at level 3 the translation of
``X`` by ``t ↦ s t`` in the area direction) equals the solution of
``dY = ½ Σ_{ij} s^{ij}[V_i, V_j](Y) dt + V_i(Y) dX^i``, bracket ``[V, W] = DW·V − DV·W``. It is a pathwise
statement: it holds for fBM paths, where no Itô/Stratonovich calculus is available (``H = 0.3`` needs the
level-3 lift, ``p > 3``).

Three checks:

1. *Independent oracle (no area, level 3, ``s`` or library bracket enters it).* On each step of an exact
   fBM sample of mesh ``δ`` the path follows the increment and then a square loop of area ``s^{12} δ``
   (mirror-image loops on alternate steps, so that their level-3 terms cancel); the ODE along this
   polygon is integrated leg by leg with RK4. As ``δ → 0`` this path converges to the perturbed fBM rough
   path, so its solution must approach the ODE along the plain polygon with the drift
   ``s^{12}[V_1, V_2]`` (bracket from the Jacobians written here). The gap is fitted (rate > 0.2) and the
   printed slips (opposite sign, no ½) stay O(1).
2. *Rough-path side.* ``solve`` on ``X.perturb(s)`` (Davie at level 2 for ``H = 0.4``; Davie3 on the
   level-3 lift for ``H = 0.3``) against the log-ODE scheme of the same level with the drift, on coarse grids
   of the same fBM lift: the gap shrinks with the step at a fitted rate.
3. *Exactness.* The log-ODE schemes see ``s h`` in the step log-signature and the drift as the same term
   of their vector field: perturbed and drift-corrected solutions agree to round-off (linear fields, exact
   exponential; non-linear fields, RK4).
"""

import numpy as np
from _oracles import trig_fields, trig_jacobians
import pytest

from roughpaths import (Davie, Davie3, LinearVectorFields, LogODE, LogODE3, VectorFields, fbm,
                        piecewise_linear_lift, solve)

SIG = 0.8                                     # s^{12}
S = np.array([[0.0, SIG], [-SIG, 0.0]])


FIELDS = VectorFields(trig_fields, trig_jacobians, dim_state=2, dim_noise=2)
Y0 = np.array([0.3, -0.2])


def _bracket12(y):
    """[V_1, V_2] = DV_2·V_1 − DV_1·V_2 from the closed-form Jacobians."""
    V, J = trig_fields(y), trig_jacobians(y)
    return (J[..., 1, :, :] @ V[..., :, 0, None])[..., 0] - (J[..., 0, :, :] @ V[..., :, 1, None])[..., 0]


def _rk4(f, y, n=1):
    u = 1.0 / n
    for _ in range(n):
        k1 = f(y)
        k2 = f(y + 0.5 * u * k1)
        k3 = f(y + 0.5 * u * k2)
        k4 = f(y + u * k3)
        y = y + (u / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)
    return y


def _loop_solution(values, sig, T=1.0):
    """ODE along 'increment, then a square loop of area sig·δ' on every step (mirror loops alternate)."""
    n = values.shape[-2] - 1
    delta = T / n
    a = np.sqrt(abs(sig) * delta)
    p, q = (0, 1) if sig > 0 else (1, 0)
    legs = [(p, a), (q, a), (p, -a), (q, -a)]
    dx = np.diff(values, axis=-2)
    y = np.broadcast_to(Y0, values.shape[:-2] + (2,)).copy()
    for k in range(n):
        y = _rk4(lambda z: (trig_fields(z) @ dx[..., k, :, None])[..., 0], y)
        sign = 1.0 if k % 2 == 0 else -1.0
        for i, c in legs:
            y = _rk4(lambda z: sign * c * trig_fields(z)[..., :, i], y)
    return y


def _drift_solution(values, coef, T=1.0):
    """ODE along the polygon with the drift coef·[V_1, V_2] (coef = s^{12} for Friz–Oberhauser)."""
    n = values.shape[-2] - 1
    delta = T / n
    dx = np.diff(values, axis=-2)
    y = np.broadcast_to(Y0, values.shape[:-2] + (2,)).copy()
    for k in range(n):
        y = _rk4(lambda z: (trig_fields(z) @ dx[..., k, :, None])[..., 0] + coef * delta * _bracket12(z), y)
    return y


def _fit(hs, gaps):
    return float(np.polyfit(np.log(hs), np.log(gaps), 1)[0])


def oracle_gaps(H, n_fine, batch, ns, seed):
    values = fbm(n_fine, H, rng=seed, dim=2, batch_shape=(batch,))
    gaps = []
    for n in ns:
        v = values[..., ::n_fine // n, :]
        gaps.append(float(np.sqrt(np.mean(np.sum((_loop_solution(v, SIG) - _drift_solution(v, SIG)) ** 2, -1)))))
    v = values[..., ::n_fine // ns[-1], :]
    loop = _loop_solution(v, SIG)
    wrong = {name: float(np.sqrt(np.mean(np.sum((loop - _drift_solution(v, c)) ** 2, -1))))
             for name, c in (("sign", -SIG), ("no half", 2 * SIG))}
    return gaps, _fit(1.0 / np.asarray(ns, float), gaps), wrong


@pytest.mark.parametrize("H", [0.4, 0.3])
def test_loop_oracle_reduced(H):
    gaps, rate, wrong = oracle_gaps(H, 256, 32, [32, 64, 128, 256], seed=3)
    assert rate > 0.2, (gaps, rate)
    assert gaps[-1] < 0.6 * gaps[0], gaps
    for name, g in wrong.items():
        assert g > 5 * gaps[-1], (name, g, gaps)


def rough_path_gaps(H, n_fine, batch, Ks, seed):
    values = fbm(n_fine, H, rng=seed, dim=2, batch_shape=(batch,))
    level = 2 if H > 1 / 3 else 3
    taylor, logode = (Davie(), LogODE()) if level == 2 else (Davie3(), LogODE3())
    gaps = []
    for K in Ks:
        X = piecewise_linear_lift(values, n_fine // K, level=level)
        a = solve(FIELDS, X.perturb(S), Y0, taylor, save_at="end").final
        b = solve(FIELDS, X, Y0, logode, drift=FIELDS.friz_oberhauser_drift(S), save_at="end").final
        gaps.append(float(np.sqrt(np.mean(np.sum((a - b) ** 2, -1)))))
    return gaps, _fit(1.0 / np.asarray(Ks, float), gaps)


@pytest.mark.parametrize("H", [0.4, 0.3])
def test_rough_path_side_reduced(H):
    gaps, rate = rough_path_gaps(H, 2048, 32, [16, 32, 64, 128], seed=4)
    assert rate > 0.2, (gaps, rate)
    assert gaps[-1] < 0.6 * gaps[0], gaps


@pytest.mark.parametrize("H, level", [(0.4, 2), (0.3, 3)])
def test_logode_perturbation_is_the_drift_exactly(H, level):
    values = fbm(256, H, rng=6, dim=2, batch_shape=(8,))
    X = piecewise_linear_lift(values, 8, level=level)
    solver = LogODE() if level == 2 else LogODE3()
    M = 0.6 * np.random.default_rng(2).standard_normal((2, 3, 3))
    L = LinearVectorFields(M)
    a = solve(L, X.perturb(S), np.ones(3), solver).states
    b = solve(L, X, np.ones(3), solver, drift=L.friz_oberhauser_drift(S)).states
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * (1 + np.abs(a).max()))
    c = solve(FIELDS, X.perturb(S), Y0, solver).states
    e = solve(FIELDS, X, Y0, solver, drift=FIELDS.friz_oberhauser_drift(S)).states
    np.testing.assert_allclose(c, e, rtol=0, atol=1e-10)
    # and the drift is not zero: the perturbation changes the solution at O(1)
    assert np.abs(c - solve(FIELDS, X, Y0, solver).states).max() > 0.05


@pytest.mark.slow
@pytest.mark.parametrize("H", [0.4, 0.3])
def test_loop_oracle_full(H):
    gaps, rate, wrong = oracle_gaps(H, 4096, 128, [128, 256, 512, 1024, 2048, 4096], seed=13)
    assert rate > 0.3, (gaps, rate)
    for name, g in wrong.items():
        assert g > 10 * gaps[-1], (name, g, gaps)


@pytest.mark.slow
@pytest.mark.parametrize("H", [0.4, 0.3])
def test_rough_path_side_full(H):
    gaps, rate = rough_path_gaps(H, 8192, 128, [16, 32, 64, 128, 256], seed=14)
    assert rate > 0.25, (gaps, rate)
