r"""Strong order 1 against Brownian motion with error-controlled Lévy areas; order ½ with Davie's areas.

Claim: for the linear Stratonovich SDE :math:`dY = AY\,dt + \sum_{i=1}^3 \sigma M_i Y\circ dW^i` with
non-commuting :math:`M_i` (rotations plus a random shear), the order-1 schemes ``Davie`` and ``LogODE``
driven by ``BrownianDriver(levy_area="mrongowius-rossler")`` (per-step area error :math:`h^{3/2}`, the
default) converge with strong order 1.0 ± 0.1 at ``T = 1``, measured against a reference solved (``LogODE``,
exact exponential per step) on ``driver.refine(F)``: the same Brownian path, ``F`` times finer, whose
areas restrict exactly (Chen) to the driver's. With ``levy_area="davie"`` the coarse area is not the
area of the refined path (``roughpaths.drivers.refinement``), and the order against the same kind of
reference falls to about ½ (asserted: below 0.7).

Strong error: root mean square over paths of :math:`|Y_T - Y_T^{\text{ref}}|`; order: slope of
``log error`` against ``log h`` (least squares). Reduced run (default suite): ``h = 1/8 … 1/64``, 160 paths, ``F = 4``, order within 0.15 (seeds
3, 4, 5 gave 0.99/0.99, 1.02/1.03, 0.99/0.97 for Davie/LogODE and 0.54, 0.55, 0.53 with Davie's areas);
full run (``slow``): ``h = 1/4 … 1/4096``, three decades, 64 paths, ``F = 16``: measured Davie 0.98,
LogODE 1.00, Davie's areas 0.52 (about 20 minutes on the shared machine).

The default driver (no ``levy_area`` argument: ``"auto"``, exact areas for ``d = 2``, Mrongowius–Rößler at
:math:`h^{3/2}` for ``d = 3``) gives fitted order at least 0.9 over ``h = 1/8 … 1/64`` for ``d = 2`` (the
first two noises) and ``d = 3``, with Davie's areas below 0.7 in the same measurement (issue "Right by
default"; measured 0.95/0.98 and 0.99/0.99 for Davie/LogODE, 0.63 and 0.54 with Davie's areas).
"""

import numpy as np
import pytest

from roughpaths import BrownianDriver, Davie, LinearVectorFields, LogODE, solve

Y0 = np.array([1.0, 0.5, -0.3])


def _fields(d=3, sigma=0.3):
    rng = np.random.default_rng(1234)
    so3 = np.array([[[0, 0, 0], [0, 0, -1], [0, 1, 0]],
                    [[0, 0, 1], [0, 0, 0], [-1, 0, 0]],
                    [[0, -1, 0], [1, 0, 0], [0, 0, 0]]], dtype=float)
    M = sigma * (so3[:d] + 0.3 * rng.standard_normal((d, 3, 3)))
    return LinearVectorFields(M, drift=-0.2 * np.eye(3) + 0.1 * rng.standard_normal((3, 3)))


def strong_orders(levy_area, solvers, levels, paths, factor, seed=3, d=3):
    """``{name: (order, errors)}`` over ``h = 2**-j``, ``j in levels``; ``levy_area=None``: the driver's default."""
    V = _fields(d)
    errs = {name: [] for name in solvers}
    kw = {} if levy_area is None else {"levy_area": levy_area}
    for j in levels:
        drv = BrownianDriver(d, seed=seed, dt=2.0 ** -j, n_steps=2 ** j, batch_shape=(paths,), **kw)
        ref = solve(V, drv.refine(factor), Y0, LogODE(), save_at="end").final
        for name, solver in solvers.items():
            y = solve(V, drv, Y0, solver, save_at="end").final
            errs[name].append(float(np.sqrt(np.mean(np.sum((y - ref) ** 2, axis=-1)))))
    h = 2.0 ** -np.asarray(levels, dtype=float)
    return {name: (float(np.polyfit(np.log(h), np.log(e), 1)[0]), e) for name, e in errs.items()}


def _check(levels, paths, factor, tol):
    good = strong_orders("mrongowius-rossler", {"Davie": Davie(), "LogODE": LogODE()}, levels, paths, factor)
    for name, (order, errs) in good.items():
        assert abs(order - 1.0) < tol, (name, order, errs)
    (order, errs), = strong_orders("davie", {"Davie": Davie()}, levels, paths, factor).values()
    assert order < 0.7, (order, errs)
    return good


def test_strong_order_one_reduced():
    _check(range(3, 7), 160, 4, 0.15)


@pytest.mark.slow
def test_strong_order_one_three_decades():
    _check(range(2, 13), 64, 16, 0.1)


@pytest.mark.parametrize("d", [2, 3])
def test_default_driver_has_strong_order_one(d):
    assert BrownianDriver(d, seed=0, dt=0.1, n_steps=2).levy_area == "auto"
    for name, (order, errs) in strong_orders(None, {"Davie": Davie(), "LogODE": LogODE()}, range(3, 7), 160, 4,
                                             d=d).items():
        assert order >= 0.9, (d, name, order, errs)
    (order, errs), = strong_orders("davie", {"Davie": Davie()}, range(3, 7), 160, 4, d=d).values()
    assert order < 0.7, (d, order, errs)
