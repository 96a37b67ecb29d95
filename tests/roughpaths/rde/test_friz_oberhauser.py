"""Friz–Oberhauser, pathwise: perturbing the area by ``s (t - s)`` equals adding the drift ``½ Σ s^{ij}[V_i, V_j]``.

Claim (``docs/conventions.md``, the paper's Theorem A.1 with its slips corrected): for a geometric rough
path ``X`` and antisymmetric ``s``, the solution of ``dY = V_i(Y) dX̃^i`` with
``X̃ = (X, XX + s (t - s))`` equals the solution of ``dY = ½ Σ_{i,j} s^{ij}[V_i, V_j](Y) dt + V_i(Y) dX^i``,
with the Jacobi–Lie bracket ``[V, W] = DW·V − DV·W``.

Independent oracle (no area, no ``s`` and no bracket enter it): the perturbed path is realised as
a genuine piecewise-linear path. On each step of a fine Brownian sample (mesh ``δ``) it follows the
increment and then, for every pair ``i < j``, a square loop of side ``sqrt(|s^{ij}| δ)`` in the
``(e_i, e_j)`` plane, oriented so that its area ``∫ X^i dX^j`` is ``s^{ij} δ`` (the loop construction
is checked against ``RoughPath.from_path``). The loops alternate between two mirror-image versions
so that their level-3 terms cancel. The ODE along this path is solved leg by leg with RK4.
As ``δ → 0`` its signature converges to the perturbed Brownian rough path, so the ODE solution must
approach the drift-corrected solution (``LogODE`` on the unperturbed piecewise-linear lift of the
same Brownian sample) at a fitted rate (about 1 here). With the opposite sign, without the ½
(``Σ s^{ij}[V_i, V_j]``) or with the paper's printed ``½ Σ_{i≤j}`` (half the drift), the
difference stays O(1): asserted. Linear and non-linear non-commuting fields, ``d = 2`` and ``3``.

A second module-level check works on the rough path directly: on Brownian rough paths with their
Lévy areas (Chen sums of a fine sample), ``solve(V, X.perturb(s))`` and ``solve(V, X, drift=FO)``
agree at a fitted rate ≈ 1 for ``Davie`` (the two schemes differ by ``O(h^{3/2})`` per step) and to
round-off for ``LogODE`` on linear fields (its step generator sees ``s`` and the drift identically).
"""

import numpy as np
from _oracles import rk4_flow
import pytest

from roughpaths import Davie, LinearVectorFields, LogODE, RoughPath, solve, VectorFields

S2 = np.array([[0.0, 1.4], [-1.4, 0.0]])
S3 = np.array([[0.0, 1.0, -0.6], [-1.0, 0.0, 0.8], [0.6, -0.8, 0.0]])


def _loop_legs(s, delta):
    """Legs ``(component, signed length)`` of the loops adding area ``s δ`` (pairs ``i < j``)."""
    legs = []
    d = s.shape[0]
    for i in range(d):
        for j in range(i + 1, d):
            if s[i, j] == 0:
                continue
            a = np.sqrt(abs(s[i, j]) * delta)
            p, q = (i, j) if s[i, j] > 0 else (j, i)
            legs += [(p, a), (q, a), (p, -a), (q, -a)]
    return legs


def _rk4(f, y, n):
    return rk4_flow(f, y, 1.0, n)


def _loop_oracle(V, W, s, T, y0, nsub=2):
    """Solve the ODE along the piecewise-linear path 'Brownian increment, then loops' (no area used)."""
    n = W.shape[-2] - 1
    legs = _loop_legs(s, T / n)
    y = np.broadcast_to(y0, W.shape[:-2] + y0.shape[-1:]).copy()
    dW = np.diff(W, axis=-2)
    for k in range(n):
        dx = dW[..., k, :]
        y = _rk4(lambda z: (V.fields(z) @ dx[..., None])[..., 0], y, nsub)
        sign = 1.0 if k % 2 == 0 else -1.0        # mirror-image loop every other step (same area)
        for i, c in legs:
            y = _rk4(lambda z: sign * c * V.fields(z)[..., i], y, nsub)
    return y


def test_loop_construction_has_area_s_delta():
    delta = 0.01
    for s in (S2, S3, -S3):
        for sign in (1.0, -1.0):
            pts = [np.zeros(s.shape[0])]
            for i, c in _loop_legs(s, delta):
                pts.append(pts[-1] + sign * c * np.eye(s.shape[0])[i])
            X = RoughPath.from_path(np.array(pts))
            np.testing.assert_allclose(X.increment(0.0, 1.0), 0.0, atol=1e-15)
            np.testing.assert_allclose(X.area(0.0, 1.0), s * delta, atol=1e-15)


def _linear(rng, d, e=3):
    return LinearVectorFields(0.5 * rng.standard_normal((d, e, e)))


def _nonlinear(rng, d, e=3, user_jacobian=True):
    M = 0.5 * rng.standard_normal((d, e, e))
    N = 0.8 * rng.standard_normal((d, e, e))

    def fields(y):
        return np.stack([y @ M[i].T + 0.5 * np.sin(y @ N[i].T) for i in range(d)], axis=-1)

    def jac(y):
        return np.stack([M[i] + 0.5 * np.cos(y @ N[i].T)[..., :, None] * N[i] for i in range(d)], axis=-3)

    return VectorFields(fields, jac if user_jacobian else None, dim_state=e, dim_noise=d)


def _rms(a):
    return float(np.sqrt(np.mean(np.sum(a * a, axis=-1))))


def _fo_versus_loops(V, s, rng, levels, paths=12, T=1.0):
    kmax = max(levels)
    d = s.shape[0]
    dW = rng.standard_normal((paths, 2 ** kmax, d)) * np.sqrt(T / 2 ** kmax)
    Wf = np.concatenate([np.zeros((paths, 1, d)), np.cumsum(dW, axis=1)], axis=1)
    y0 = np.array([1.0, 0.5, -0.3])
    fo = V.friz_oberhauser_drift(s)
    variants = {"opposite sign": lambda y: -fo(y), "without the ½": lambda y: 2.0 * fo(y),
                "paper's ½Σ_{i≤j}": lambda y: 0.5 * fo(y)}
    diffs, wrong = [], {k: [] for k in variants}
    for k in levels:
        W = Wf[:, :: 2 ** (kmax - k)]
        X = RoughPath.from_path(W, times=np.linspace(0.0, T, 2 ** k + 1))
        y_loop = _loop_oracle(V, W, s, T, y0)
        diffs.append(_rms(y_loop - solve(V, X, y0, LogODE(), drift=fo, save_at="end").final))
        for name, f in variants.items():
            wrong[name].append(_rms(y_loop - solve(V, X, y0, LogODE(), drift=f, save_at="end").final))
    h = T / 2.0 ** np.array(levels)
    rate = np.polyfit(np.log(h), np.log(diffs), 1)[0]
    return np.array(diffs), rate, {k: np.array(v) for k, v in wrong.items()}


CASES = [("linear", 2), ("linear", 3), ("nonlinear", 2), ("nonlinear", 3)]


@pytest.mark.parametrize("kind,d", CASES)
def test_friz_oberhauser_against_loop_oracle(kind, d, rng):
    V = _linear(rng, d) if kind == "linear" else _nonlinear(rng, d)
    s = S2 if d == 2 else S3
    diffs, rate, wrong = _fo_versus_loops(V, s, rng, levels=[4, 5, 6, 7])
    assert rate > 0.75, (rate, diffs)                    # fitted rate ≈ 1
    assert diffs[-1] < 0.25 * diffs[0], diffs
    for name, w in wrong.items():
        # a wrong drift does not converge: O(1) and far above the correct difference
        assert w[-1] > 0.1, (name, w)
        assert w[-1] > 5 * diffs[-1], (name, w, diffs)
        assert w[-1] > 0.5 * w[0], (name, w)


@pytest.mark.slow
@pytest.mark.parametrize("kind,d", CASES)
def test_friz_oberhauser_against_loop_oracle_full(kind, d, rng):
    V = _linear(rng, d) if kind == "linear" else _nonlinear(rng, d, user_jacobian=False)
    s = S2 if d == 2 else S3
    diffs, rate, wrong = _fo_versus_loops(V, s, rng, levels=[4, 5, 6, 7, 8, 9, 10], paths=32)
    assert abs(rate - 1.0) < 0.2, (rate, diffs)
    for name, w in wrong.items():
        assert w[-1] > 50 * diffs[-1], (name, w, diffs)


def _brownian_rough_path(rng, paths, d, n_fine, T=1.0):
    dW = rng.standard_normal((paths, n_fine, d)) * np.sqrt(T / n_fine)
    W = np.concatenate([np.zeros((paths, 1, d)), np.cumsum(dW, axis=1)], axis=1)
    return RoughPath.from_path(W, times=np.linspace(0.0, T, n_fine + 1))


@pytest.mark.parametrize("kind,d", CASES)
def test_perturbed_path_versus_drift_on_brownian_rough_paths(kind, d, rng):
    V = _linear(rng, d) if kind == "linear" else _nonlinear(rng, d)
    s = S2 if d == 2 else S3
    Xf = _brownian_rough_path(rng, 16, d, 2 ** 10)
    fo = V.friz_oberhauser_drift(s)
    y0 = np.array([1.0, 0.5, -0.3])
    ns = [16, 32, 64, 128]
    diffs, wrong = [], []
    for n in ns:
        X = Xf.restrict(Xf.times[:: 2 ** 10 // n])
        y_pert = solve(V, X.perturb(s), y0, Davie(), save_at="end").final
        diffs.append(_rms(y_pert - solve(V, X, y0, Davie(), drift=fo, save_at="end").final))
        wrong.append(_rms(y_pert - solve(V, X, y0, Davie(), drift=lambda y: -fo(y), save_at="end").final))
    rate = -np.polyfit(np.log(ns), np.log(diffs), 1)[0]
    assert rate > 0.8, (rate, diffs)
    assert min(wrong) > 0.1 and min(wrong) > 20 * diffs[-1], (wrong, diffs)
    if kind == "linear":   # LogODE's exact step sees s (t - s) and the linear drift identically
        X = Xf.restrict(Xf.times[::16])
        a = solve(V, X.perturb(s), y0, LogODE(), save_at="end").final
        b = solve(V, X, y0, LogODE(), drift=fo, save_at="end").final
        np.testing.assert_allclose(a, b, rtol=1e-11, atol=1e-11)
