r"""Strong convergence rates of Davie, LogODE (level 2) and Davie3, LogODE3 (level 3) on fractional Brownian paths.

Claim: for an RDE with smooth non-commuting fields driven by the rough path of a fixed fBM sample, a
step-``N`` scheme fed the exact step signatures on a grid of step ``h`` converges to the solution at a
rate at least the pathwise rate ``(N + 1)H - 1`` (Friz–Victoir, Thm 10.30, ``p ↓ 1/H``); in mean square
over the fBM law the fitted rate is close to ``(N + 1)H - 1/2`` (for ``H = 1/2`` these are the classical
strong orders 1 of Milstein/Davie and 1.5 of the level-3 schemes).

Oracle: the driver is the polygon through an exact fBM sample on a fine grid (mesh ``δ``); the reference
solution is the ODE along that polygon, integrated leg by leg with RK4 written here (no signature, area or
bracket enters it). The schemes get the Chen products of the polygon's step signatures on coarse grids
``h ≫ δ`` (``piecewise_linear_lift``) and their RMS error at ``t = 1`` over the batch is fitted against
``h`` (slope of ``log error`` vs ``log h``). Asserted: each slope exceeds the pathwise rate by 0.1 and
is below ``(N+1)H - 1/2 + 0.35``; except for Davie3 it is also above ``(N+1)H - 1/2 - 0.35``; and
the level-3 log-ODE converges faster (slope at least 0.2 higher, error at the finest grid at most
half) than the level-2 one. Measured (reduced size, seed 7):
at ``H = 0.4`` Davie 0.77, LogODE 0.73, Davie3 0.88, LogODE3 1.26 (``(N+1)H - 1/2`` = 0.7, 0.7, 1.1, 1.1);
at ``H = 0.3`` Davie 0.45, LogODE 0.32, Davie3 0.62, LogODE3 0.70 (0.4, 0.4, 0.7, 0.7); full size
(256 paths, seed 8) LogODE 0.86, 0.74, 0.60, 0.45 at ``H = 0.45, 0.4, 0.35, 0.3``. The Taylor-type
Davie3 sits below ``4H - 1/2``, above the pathwise ``4H - 1`` (full size, 256 paths, seed 8: 0.94, 0.77,
0.62, 0.46 at ``H = 0.45, 0.4, 0.35, 0.3`` against ``4H - 1`` = 0.8, 0.6, 0.4, 0.2, while LogODE3 gives
1.26, 1.07, 0.89, 0.70): its local error is the level-4 signature, whose even words have non-zero mean
and add up coherently over the steps (asymptotic rate ``4H - 1``), while the log-ODE's is the level-4
log-signature, of mean zero because fBM is reversible in law (see :mod:`roughpaths.rde.logode`).
Its level-3 terms are right: on smooth drivers it has order 3 (``tests/roughpaths/rde/test_level3_solvers.py``).
"""

import numpy as np
from _oracles import trig_fields, trig_jacobians
import pytest

from roughpaths import Davie, Davie3, LogODE, LogODE3, VectorFields, fbm, piecewise_linear_lift, solve


FIELDS = VectorFields(trig_fields, trig_jacobians, dim_state=2, dim_noise=2)
Y0 = np.array([0.3, -0.2])


def _polygon_ode(values, y0, sub=2):
    """RK4 along each leg of the polygon through ``values`` (``sub`` RK4 steps per leg)."""
    y = np.broadcast_to(y0, values.shape[:-2] + y0.shape).copy()
    dx = np.diff(values, axis=-2)

    def f(z, d):
        return (trig_fields(z) @ d[..., None])[..., 0]

    for k in range(dx.shape[-2]):
        d = dx[..., k, :] / sub
        for _ in range(sub):
            k1 = f(y, d)
            k2 = f(y + 0.5 * k1, d)
            k3 = f(y + 0.5 * k2, d)
            k4 = f(y + k3, d)
            y = y + (k1 + 2 * k2 + 2 * k3 + k4) / 6.0
    return y


SCHEMES = {"Davie": (Davie(), 2), "LogODE": (LogODE(), 2), "Davie3": (Davie3(), 3), "LogODE3": (LogODE3(), 3)}


def fitted_rates(H, n_fine, batch, Ks, seed, names=tuple(SCHEMES)):
    """``{scheme: (slope, errors)}`` of the RMS error at t = 1 against the polygon reference."""
    values = fbm(n_fine, H, rng=seed, dim=2, batch_shape=(batch,))
    ref = _polygon_ode(values, Y0)
    out = {}
    for name in names:
        solver, level = SCHEMES[name]
        errs = []
        for K in Ks:
            X = piecewise_linear_lift(values, n_fine // K, level=level)
            yK = solve(FIELDS, X, Y0, solver, save_at="end").final
            errs.append(float(np.sqrt(np.mean(np.sum((yK - ref) ** 2, axis=-1)))))
        slope = float(np.polyfit(np.log(1.0 / np.asarray(Ks, dtype=float)), np.log(errs), 1)[0])
        out[name] = (slope, errs)
    return out


def _check(H, rates):
    for name, (slope, errs) in rates.items():
        N = SCHEMES[name][1]
        pathwise, gaussian = (N + 1) * H - 1.0, (N + 1) * H - 0.5
        assert slope > pathwise + 0.1, (name, slope, pathwise, errs)
        assert slope < gaussian + 0.35, (name, slope, gaussian, errs)
        if name != "Davie3":       # the Taylor step sits between the two rates (module docstring)
            assert slope > gaussian - 0.35, (name, slope, gaussian, errs)
    if "LogODE" in rates and "LogODE3" in rates:
        # the level-3 terms matter: a LogODE3 that dropped or mangled them would converge like LogODE
        assert rates["LogODE3"][0] > rates["LogODE"][0] + 0.2, rates
        assert rates["LogODE3"][1][-1] < 0.5 * rates["LogODE"][1][-1], rates


@pytest.mark.parametrize("H", [0.4, 0.3])
def test_strong_rates_reduced(H):
    _check(H, fitted_rates(H, 2048, 64, [16, 32, 64, 128], seed=7))


@pytest.mark.slow
@pytest.mark.parametrize("H", [0.45, 0.4, 0.35, 0.3])
def test_strong_rates_full(H):
    _check(H, fitted_rates(H, 8192, 256, [16, 32, 64, 128, 256], seed=8))


@pytest.mark.slow
def test_declared_brownian_orders():
    """At H = 1/2 (Brownian motion) the fitted rates match the declared ``order`` of every scheme.

    Measured (8192 fine steps, 128 paths, seed 8): Davie 0.99, LogODE 1.02, Davie3 1.10, LogODE3 1.43.
    """
    rates = fitted_rates(0.5, 8192, 128, [16, 32, 64, 128, 256], seed=8)
    for name, (slope, errs) in rates.items():
        assert abs(slope - SCHEMES[name][0].order) < 0.15, (name, slope, errs)
