"""Convergence orders of the RDE solvers match their declared orders (fitted slopes of log-error vs log-step).

Claims:

* **smooth driver** with exact increments and exact areas (Gauss–Legendre quadrature of
  ``∫ (x^i − x^i_s) dx^j``), non-linear non-commuting fields with a drift, against ``scipy``'s
  ``solve_ivp`` (DOP853, tolerance 1e-12) of ``y' = V_0(y) + V_i(y) ẋ^i(t)``: ``Davie`` and ``LogODE``
  have order 2 (``smooth_order``), ``Heun`` 2, ``Euler`` 1;
* **Brownian rough path** (Chen sums of a fine Brownian sample: genuine Lévy areas on the coarse
  grids, reference = ``LogODE`` on the fine grid, same path), linear non-commuting fields in
  ``R^3`` driven by ``d = 3`` noises: ``Davie`` and ``LogODE`` with the Lévy area converge with
  strong order 1 (``order``); dropping the area (``Davie`` on the piecewise-linear lift of the
  coarse samples, or the Stratonovich ``Heun``) gives order ½; ``Euler`` converges with order ½ to
  the **Itô** solution (reference: the Stratonovich equation with drift ``−½ Σ M_i² y``, written here).
  A non-linear case checks order 1 for ``Davie`` with a central-difference Jacobian.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from roughpaths import Davie, Euler, Heun, LinearVectorFields, LogODE, RoughPath, solve, VectorFields


# ---------------------------------------------------------------------------- smooth driver
def _x(t):
    t = np.asarray(t, dtype=float)
    return np.stack([np.sin(2 * t) + 0.3 * t, np.cos(3 * t) - 1.0, t ** 2], axis=-1)


def _xdot(t):
    t = np.asarray(t, dtype=float)
    return np.stack([2 * np.cos(2 * t) + 0.3, -3 * np.sin(3 * t), 2 * t], axis=-1)


def _smooth_rough_path(n, T=1.0):
    """Exact increments and areas ``∫_s^t (x^i_r − x^i_s) ẋ^j_r dr`` (12-point Gauss–Legendre per step)."""
    times = np.linspace(0.0, T, n + 1)
    g, w = np.polynomial.legendre.leggauss(12)
    s, t = times[:-1, None], times[1:, None]
    r = 0.5 * (s + t) + 0.5 * (t - s) * g                          # (n, 12)
    rel = _x(r) - _x(times[:-1])[:, None, :]                       # (n, 12, d)
    areas = 0.5 * (t - s)[..., None] * np.einsum("kq,kqi,kqj->kij", np.broadcast_to(w, r.shape), rel, _xdot(r))
    inc = np.diff(_x(times), axis=0)
    return RoughPath(inc, areas, times=times)


def _smooth_fields():
    rng = np.random.default_rng(11)
    M = 0.6 * rng.standard_normal((3, 3, 3))
    N = 0.8 * rng.standard_normal((3, 3, 3))

    def fields(y):
        return np.stack([y @ M[i].T + 0.5 * np.sin(y @ N[i].T) for i in range(3)], axis=-1)

    def jac(y):
        return np.stack([M[i] + 0.5 * np.cos(y @ N[i].T)[..., :, None] * N[i] for i in range(3)], axis=-3)

    drift = lambda y: -0.3 * y + 0.2 * np.roll(y, 1, axis=-1) ** 2
    return VectorFields(fields, jac, drift=drift, dim_state=3, dim_noise=3)


def _slope(h, err):
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])


@pytest.mark.parametrize("solver", [Davie(), LogODE(), Heun(), Euler()], ids=repr)
def test_smooth_driver_orders(solver):
    V = _smooth_fields()
    y0 = np.array([0.4, -0.2, 0.3])
    T = 1.0
    ref = solve_ivp(lambda t, y: V.drift(y) + V.fields(y) @ _xdot(t), (0, T), y0, method="DOP853",
                    rtol=1e-12, atol=1e-12).y[:, -1]
    ns = np.array([16, 32, 64, 128])
    errs = [np.linalg.norm(solve(V, _smooth_rough_path(n, T), y0, solver, save_at="end").final - ref) for n in ns]
    slope = _slope(T / ns, errs)
    assert abs(slope - solver.smooth_order) < 0.25, (slope, errs)


# ---------------------------------------------------------------------------- Brownian rough paths
def _fine_brownian(rng, paths, d, n_fine, T=1.0):
    dW = rng.standard_normal((paths, n_fine, d)) * np.sqrt(T / n_fine)
    W = np.concatenate([np.zeros((paths, 1, d)), np.cumsum(dW, axis=1)], axis=1)
    return W, RoughPath.from_path(W, times=np.linspace(0.0, T, n_fine + 1))


def _brownian_errors(V, solvers, rng, paths, n_fine, ns, ito_drift=None):
    y0 = np.array([1.0, 0.5, -0.3])
    W, Xf = _fine_brownian(rng, paths, V.dim_noise, n_fine)
    ref = solve(V, Xf, y0, LogODE(), save_at="end").final
    ref_ito = None if ito_drift is None else solve(V, Xf, y0, LogODE(), drift=ito_drift, save_at="end").final
    out = {}
    for name, solver in solvers.items():
        errs = []
        for n in ns:
            step = n_fine // n
            if name == "davie-no-area":          # piecewise-linear lift of the coarse samples
                X = RoughPath.from_path(W[:, ::step], times=Xf.times[::step])
            else:
                X = Xf.restrict(Xf.times[::step])
            target = ref_ito if name == "euler" else ref
            y = solve(V, X, y0, solver, save_at="end").final
            errs.append(np.sqrt(np.mean(np.sum((y - target) ** 2, axis=-1))))
        out[name] = (_slope(1.0 / np.asarray(ns), errs), errs)
    return out


def _linear_noncommuting(rng):
    M = 0.35 * rng.standard_normal((3, 3, 3))
    C = M[1] @ M[0] - M[0] @ M[1]
    assert np.linalg.norm(C) > 0.1 * np.linalg.norm(M[0]) ** 2    # really non-commuting
    return M, LinearVectorFields(M, drift=0.2 * rng.standard_normal((3, 3)))


def _expected(solvers):
    return {"davie": 1.0, "logode": 1.0, "heun": 0.5, "davie-no-area": 0.5, "euler": 0.5}


def _check(out, solvers, tol):
    for name, (slope, errs) in out.items():
        declared = solvers[name].order if name != "davie-no-area" else 0.5
        assert declared == _expected(solvers)[name]
        assert abs(slope - declared) < tol, (name, slope, errs)


SOLVERS = {"davie": Davie(), "logode": LogODE(), "heun": Heun(), "davie-no-area": Davie(), "euler": Euler()}


def test_brownian_strong_orders(rng):
    M, V = _linear_noncommuting(rng)
    ito = -0.5 * sum(m @ m for m in M)                     # Itô dY = M_i Y dW^i  ⇔  Stratonovich drift −½ΣM_i²
    out = _brownian_errors(V, SOLVERS, rng, paths=96, n_fine=2 ** 11, ns=[8, 16, 32, 64], ito_drift=ito)
    _check(out, SOLVERS, tol=0.2)
    # with the area, at the finest step, the order-1 solvers beat the area-blind ones clearly
    assert out["davie"][1][-1] < 0.5 * out["heun"][1][-1]


@pytest.mark.slow
def test_brownian_strong_orders_full(rng):
    M, V = _linear_noncommuting(rng)
    ito = -0.5 * sum(m @ m for m in M)
    out = _brownian_errors(V, SOLVERS, rng, paths=500, n_fine=2 ** 14, ns=[16, 32, 64, 128, 256, 512],
                           ito_drift=ito)
    _check(out, SOLVERS, tol=0.1)


def test_brownian_nonlinear_davie_order_one(rng):
    M = 0.5 * rng.standard_normal((2, 3, 3))
    V = VectorFields(lambda y: np.stack([np.sin(y @ M[i].T) for i in range(2)], axis=-1),
                     drift=lambda y: -0.2 * y ** 3, dim_state=3, dim_noise=2)      # central-difference Jacobian
    out = _brownian_errors(V, {"davie": Davie(), "heun": Heun()}, rng, paths=64, n_fine=2 ** 10, ns=[8, 16, 32, 64])
    assert abs(out["davie"][0] - 1.0) < 0.2, out["davie"]
    assert abs(out["heun"][0] - 0.5) < 0.2, out["heun"]
