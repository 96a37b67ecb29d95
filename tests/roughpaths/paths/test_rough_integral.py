"""The rough integral (compensated Riemann sums) against closed forms.

Claims, with the area ``XX^{ij} = ∫ (X^i − X^i_s) dX^j`` and ``Y'[..., a, j, i] = ∂Y^a_j/∂X^i``:

* Stratonovich ``∫ W∘dW = ½ W²`` and Itô ``∫ W dW = ½(W² − t)`` (Itô lift ``XX − ½(t−s) I``), exactly
  (the compensated sums telescope), at every grid time;
* ``∫ X^1 dX^2 = XX^{12}_{0,T}`` for a 2-d path: pins the index order of ``Y'`` (the transposed
  reading gives ``XX^{21}``, asserted different);
* ``∫ W²∘dW = W³/3`` (Stratonovich) and ``∫ W² dW = W³/3 − ∫ W dt`` (Itô) on Brownian paths, converging
  as the mesh is refined; dropping the compensation term converges to the wrong (Itô) value;
* polynomial 1-forms on a smooth 2-d path against ``scipy.integrate.quad``: fitted order 2 for the
  compensated sums against order 1 for plain left-point Riemann sums.
"""

import numpy as np
from scipy.integrate import quad

from roughpaths import rough_integral, RoughPath


def _bm(rng, paths, n, d=1, T=1.0):
    dW = rng.standard_normal((paths, n, d)) * np.sqrt(T / n)
    return np.concatenate([np.zeros((paths, 1, d)), np.cumsum(dW, axis=1)], axis=1)


def _ito(X):
    eye = np.eye(X.dim)
    return RoughPath(X.increments, X.areas - 0.5 * X.dt[:, None, None] * eye, times=X.times, kind="ito")


def test_w_dw_stratonovich_and_ito(rng):
    W = _bm(rng, 20, 300)                                           # (20, 301, 1)
    X = RoughPath.from_path(W)
    t = X.times
    ones = np.ones(W.shape + (1,))
    strat = rough_integral(W, ones, X, cumulative=True)
    np.testing.assert_allclose(strat, 0.5 * W[..., 0] ** 2, atol=1e-12)
    ito = rough_integral(W, ones, _ito(X), cumulative=True)
    np.testing.assert_allclose(ito, 0.5 * (W[..., 0] ** 2 - t), atol=1e-12)
    np.testing.assert_allclose(rough_integral(W, ones, X), 0.5 * W[:, -1, 0] ** 2, atol=1e-12)


def test_index_order_of_gubinelli_derivative(rng):
    W = _bm(rng, 5, 200, d=2)
    X = RoughPath.from_path(W)
    n = X.n_steps + 1
    Y = np.zeros((5, n, 2))
    Y[..., 1] = W[..., 0]                                           # Y = X^1 dX^2
    Yp = np.zeros((5, n, 2, 2))
    Yp[..., 1, 0] = 1.0                                              # ∂Y_2/∂X^1
    I = rough_integral(Y, Yp, X)
    A = X.area(0.0, 1.0)
    np.testing.assert_allclose(I, A[:, 0, 1], atol=1e-12)
    assert np.max(np.abs(I - A[:, 1, 0])) > 0.05                    # the transposed reading differs
    # matrix layout (m = 2): both ∫X^1 dX^2 and ∫X^2 dX^1 at once
    Y2 = np.zeros((5, n, 2, 2))
    Y2[..., 0, 1], Y2[..., 1, 0] = W[..., 0], W[..., 1]
    Yp2 = np.zeros((5, n, 2, 2, 2))
    Yp2[..., 0, 1, 0], Yp2[..., 1, 0, 1] = 1.0, 1.0
    np.testing.assert_allclose(rough_integral(Y2, Yp2, X), np.stack([A[:, 0, 1], A[:, 1, 0]], -1), atol=1e-12)


def test_w_squared_converges_to_closed_forms(rng):
    n_fine = 2 ** 12
    W = _bm(rng, 200, n_fine)
    Xf = RoughPath.from_path(W)
    WT = W[:, -1, 0]
    errs_s, errs_i, errs_plain = [], [], []
    ns = [16, 64, 256, 1024]
    for n in ns:
        step = n_fine // n
        X = Xf.restrict(Xf.times[::step])
        w = W[:, ::step]
        Y, Yp = w ** 2, (2 * w)[..., None]
        errs_s.append(np.sqrt(np.mean((rough_integral(Y, Yp, X) - WT ** 3 / 3) ** 2)))
        ito_exact = WT ** 3 / 3 - np.sum(0.5 * (w[:, 1:, 0] + w[:, :-1, 0]) / n, axis=1)   # ∫W dt, trapezoid
        errs_i.append(np.sqrt(np.mean((rough_integral(Y, Yp, _ito(X)) - ito_exact) ** 2)))
        errs_plain.append(np.sqrt(np.mean((rough_integral(Y, 0 * Yp, X) - WT ** 3 / 3) ** 2)))
    for errs in (errs_s, errs_i):
        slope = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
        assert slope > 0.35 and errs[-1] < 0.05, (slope, errs)
    # without the compensation the Riemann sums converge to the Itô integral, not W³/3
    assert errs_plain[-1] > 0.3 and errs_plain[-1] > 10 * errs_s[-1]


def _xy(t):
    return np.stack([np.sin(2 * t) + t, np.cos(t) * t], axis=-1)


def _dxy(t):
    return np.stack([2 * np.cos(2 * t) + 1, np.cos(t) - t * np.sin(t)], axis=-1)


def test_polynomial_one_form_on_smooth_path():
    # F(x) dx = x1² x2 dx1 + (x1 + x2³) dx2; DF rows: ∂F_j/∂x_i
    F = lambda x: np.stack([x[..., 0] ** 2 * x[..., 1], x[..., 0] + x[..., 1] ** 3], -1)

    def DF(x):
        out = np.zeros(x.shape + (2,))
        out[..., 0, 0] = 2 * x[..., 0] * x[..., 1]
        out[..., 0, 1] = x[..., 0] ** 2
        out[..., 1, 0] = 1.0
        out[..., 1, 1] = 3 * x[..., 1] ** 2
        return out

    T = 1.5
    exact = quad(lambda t: F(_xy(t)) @ _dxy(t), 0, T, epsabs=1e-13, epsrel=1e-13)[0]
    ns = np.array([16, 32, 64, 128])
    comp, plain = [], []
    g, w = np.polynomial.legendre.leggauss(12)
    for n in ns:
        times = np.linspace(0, T, n + 1)
        x = _xy(times)
        s, t = times[:-1, None], times[1:, None]
        r = 0.5 * (s + t) + 0.5 * (t - s) * g
        rel = _xy(r) - x[:-1, None, :]
        areas = 0.5 * (t - s)[..., None] * np.einsum("q,kqi,kqj->kij", w, rel, _dxy(r))
        X = RoughPath(np.diff(x, axis=0), areas, times=times)
        comp.append(abs(rough_integral(F(x), DF(x), X) - exact))
        plain.append(abs(rough_integral(F(x), 0 * DF(x), X) - exact))
    s_comp = -np.polyfit(np.log(ns), np.log(comp), 1)[0]
    s_plain = -np.polyfit(np.log(ns), np.log(plain), 1)[0]
    assert abs(s_comp - 2.0) < 0.2, (s_comp, comp)
    assert abs(s_plain - 1.0) < 0.2, (s_plain, plain)
