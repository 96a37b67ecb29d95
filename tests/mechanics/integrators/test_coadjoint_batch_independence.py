"""Batch members of the coadjoint solvers do not affect each other (issue "Batch members must not affect each other").

Claim: for every coadjoint solver (Lie–Euler, Lie–Heun, implicit midpoint) on so(3) (compiled
kernels), se(3) (heavy top), su(2), sl(2, R) and a user-defined algebra (so(3) in a skewed basis,
no closed-form exponential), ``roughpaths.solve`` on a batch gives each healthy member bit for bit
the result of solving it alone, also when other members are scaled by up to 1e12 or driven by a path
with a NaN increment (drawn by hypothesis); with ``on_failure="mask"`` exactly that member is marked failed, at the right step, and
with ``on_failure="raise"`` the error names it.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from mechanics import ImplicitMidpoint, LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body
from mechanics.systems.lie_algebra import sl2r, so3, su2
from roughpaths import BrownianDriver, NonFiniteStateError, RoughPath, solve


def _skewed_so3():
    b = np.array([[1.0, 0.2, 0.0], [0.0, 1.0, 0.3], [0.1, 0.0, 1.0]])        # new basis f_i = b_ij e_j
    c = so3().structure_constants
    binv = np.linalg.inv(b)
    cc = np.einsum("ia,jb,abk,kl->ijl", b, b, c, binv)
    return LieAlgebra(cc, name="skewed so3")


def _system(name):
    if name == "so3":
        return rigid_body([1.0, 2.0, 3.0], sigma=0.3, s=np.array([[0, 1.0, 0], [-1.0, 0, 0], [0, 0, 0]]), theta=0.5)
    if name == "se3":
        return heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.3)
    alg = {"su2": su2, "sl2r": sl2r, "user": _skewed_so3}[name]()
    return LiePoissonSystem(alg, np.diag([1.0, 2.0, 3.0]), 0.3 * np.eye(3), theta=0.2)


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=repr)
@pytest.mark.parametrize("name", ["so3", "se3", "su2", "sl2r", "user"])
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), scale_exp=st.floats(0.0, 12.0), bad_step=st.integers(0, 11))
@example(seed=1412910009, scale_exp=10.5, bad_step=0)     # a singular chord Jacobian once failed the whole batch
def test_each_member_equals_itself_alone(name, solver, seed, scale_exp, bad_step):
    system = _system(name)
    n = system.dim
    rng = np.random.default_rng(seed)
    mu0 = rng.standard_normal((6, n))
    mu0[2] *= 10.0 ** scale_exp                                              # a wild member (may fail alone)
    Y = BrownianDriver(system.n_noise, seed=seed, dt=0.01, n_steps=12, batch_shape=(6,)).rough_path()
    inc = np.array(Y.increments)
    inc[4, bad_step, 0] = np.nan                                             # a broken member
    X = RoughPath(inc, Y.areas, times=Y.times, kind="geometric", check=False)
    with np.errstate(all="ignore"):
        sol = solve(system, X, mu0, solver, on_failure="mask")
    assert sol.failed[4] and sol.failed_step[4] == bad_step
    for i in range(6):
        with np.errstate(all="ignore"):
            alone = solve(system, RoughPath(inc[i], Y.areas[i], times=Y.times, kind="geometric", check=False),
                          mu0[i], solver, on_failure="mask")
        np.testing.assert_array_equal(sol.states[i], alone.states)        # NaN where (and only where) alone
        assert sol.failed_step[i] == alone.failed_step
    mu0[2] /= 10.0 ** scale_exp
    with pytest.raises(NonFiniteStateError, match=r"member \(4,\)"):
        solve(system, X, mu0, solver)
