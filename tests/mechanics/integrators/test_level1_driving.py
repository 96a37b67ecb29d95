"""A coadjoint solver takes its driving level from the driver: a level-1 driver means zero step Lévy area.

Claim: ``solve(system, X1, mu0, Method())`` on a level-1 path equals the run of the same solver on the
level-2 path with the same increments and zero step Lévy areas (the piecewise-linear lift), to
round-off, and differs from the run with the true (non-zero) areas, which therefore always enter when
the driver has them. No solver holds a flag for it (``LieHeun(levy_area=...)`` does not exist), and a
level-3 driver is refused rather than truncated silently.
"""

import numpy as np
import pytest

from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun
from mechanics.systems.lie_algebra import sl2r
from mechanics.systems.lie_poisson import LiePoissonSystem
from mechanics.systems.rigid_body import rigid_body
from roughpaths import RoughPath, piecewise_linear_lift, solve
from roughpaths.algebra.level2 import outer

SYSTEMS = {
    "rigid body (numba kernel)": lambda: rigid_body([1.0, 2.0, 3.0], sigma=0.5, theta=1.0),
    "sl2r (numpy path)": lambda: LiePoissonSystem(sl2r(), np.diag([1.0, 2.0, 0.5]), 0.4 * np.eye(3), theta=0.3),
}


@pytest.mark.parametrize("method", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("name", list(SYSTEMS))
def test_level1_equals_zero_area_lift(name, method, rng):
    system = SYSTEMS[name]()
    n = 200
    dw = rng.standard_normal((3, n, 3)) * 0.05
    times = np.linspace(0.0, 1.0, n + 1)
    x1 = RoughPath.from_increments(dw, times=times)
    lift = RoughPath.from_increments(dw, 0.5 * outer(dw, dw), times=times)           # zero Lévy area
    lam = rng.standard_normal((3, n, 3, 3)) * 0.05 ** 2
    true = RoughPath.from_increments(dw, 0.5 * outer(dw, dw) + (lam - np.swapaxes(lam, -1, -2)), times=times)
    mu0 = [0.0, 0.6, 0.8]
    a = solve(system, x1, mu0, method).states
    b = solve(system, lift, mu0, method).states
    c = solve(system, true, mu0, method).states
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-14)
    assert np.max(np.abs(a - c)) > 1e-4                   # the areas do enter when given


def test_no_flag_and_higher_levels_refused(rng):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.5)
    dw = rng.standard_normal((10, 3)) * 0.1
    path = np.cumsum(np.vstack([np.zeros(3), dw]), axis=0)
    x2 = RoughPath.from_path(path, times=np.linspace(0, 1, 11))
    with pytest.raises(TypeError, match="takes no arguments"):
        LieHeun(levy_area=False)
    a = solve(rb, x2.to_level1(), [0.0, 0.0, 1.0], LieHeun()).states     # dropping the areas is explicit
    b = solve(rb, x2, [0.0, 0.0, 1.0], LieHeun()).states                # the lift's own areas: zero Lévy area
    assert a.shape == (11, 3)
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-14)
    x3 = piecewise_linear_lift(path, 1, level=3)
    with pytest.raises(ValueError, match="level-3"):
        solve(rb, x3, [0.0, 0.0, 1.0], LieHeun())
