"""Coadjoint solvers on steps per member (``Solver.member_times``, contract item 10).

Claims:

* adaptive steps per member are the default for the coadjoint solvers (``Solution.stats["shared_steps"]`` is
  ``False``), and a member's states, times and counts are bitwise the same solved alone or in any batch, for
  LieEuler, LieHeun and ImplicitMidpoint on so(3), for the heavy top on se(3), for a forced system (the numpy
  path with ``force`` and ``noise_forces``), for su(2) and sl(2, R) (the generic compiled steps), for su(3) as a
  matrix algebra and from its matrix basis (both stepped on structure constants) and for su(4) from its matrix
  basis (stepped on its matrix twin);
* ``integrate`` with times of shape ``(members, K + 1)`` takes each member along its own grid: it agrees to
  round-off with solving each member alone on its grid by the fixed-step route (for so(3) and se(3) that is the
  compiled block kernels, another implementation of the same steps), and so does ``step`` with ``dt`` of
  shape ``(members, 1)``;
* without forces, where steps per member run compiled on structure constants (``so3_member_steps``,
  ``se3_member_steps``, ``generic_member_steps``: so(3), se(3), su(2), sl(2, R), a user's algebra of dimension 6,
  su(3) as a matrix algebra), or on matrices where the cost model says so (su(4) from its basis), a step with ``dt``
  per member equals the numpy path's step of each member alone with its ``dt`` as a float (the closed-form
  exponential, a dense ``expm`` or a conjugation of matrices: other implementations) to round-off, for small and
  large ``|sigma|`` (the Taylor and the trigonometric or scaling-and-squaring branch), and a non-finite member comes
  back NaN, failed, alone; split between numba's threads, a member's bits depend neither on their number nor on
  the members beside it.
"""

import numba
import numpy as np
import pytest

import roughpaths as rp
from mechanics import (ImplicitMidpoint, LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body, se3,
                       sl2r, so3, su, su2)
from mechanics.integrators._dispatch import member_system
from mechanics.integrators._generic_member import THETA_VECTOR

S = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.5], [0.0, -0.5, 0.0]])


def _forced():
    xi = 0.5 * np.eye(3) + 0.1 * np.random.default_rng(1).standard_normal((3, 3))
    return LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), xi, s=S, force=lambda mu: -0.2 * mu,
                            noise_forces=lambda mu: 0.1 * np.stack([np.sin(mu), np.cos(mu) - 1.0, mu ** 2], axis=-1))


def _su(N, basis=False):
    g = LieAlgebra.from_matrix_basis(su(N).basis) if basis else su(N)
    xi = 0.4 * np.random.default_rng(2).standard_normal((3, g.dim))
    return LiePoissonSystem(g, np.diag(1.0 + np.arange(g.dim) / g.dim), xi)


CASES = {
    "so3 LieEuler": (lambda: rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0), LieEuler(),
                     np.array([0.0, 0.6, 0.8])),
    "so3 LieHeun": (lambda: rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0), LieHeun(),
                    np.array([0.0, 0.6, 0.8])),
    "so3 ImplicitMidpoint": (lambda: rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5), ImplicitMidpoint(),
                             np.array([0.0, 0.6, 0.8])),
    "se3 LieHeun": (lambda: heavy_top(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0]), sigma=0.3, s=S),
                    LieHeun(), np.array([0.1, 0.2, 1.0, 0.0, 0.3, 0.9])),
    "se3 ImplicitMidpoint": (lambda: heavy_top(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0]), sigma=0.3),
                             ImplicitMidpoint(), np.array([0.1, 0.2, 1.0, 0.0, 0.3, 0.9])),
    "forced LieHeun": (_forced, LieHeun(), np.array([0.6, 0.0, 0.8])),
    "su2 LieHeun": (lambda: LiePoissonSystem(su2(), np.diag([1.0, 2.0, 3.0]), 0.5 * np.eye(3), theta=1.0), LieHeun(),
                    np.array([0.0, 0.6, 0.8])),
    "sl2r ImplicitMidpoint": (lambda: LiePoissonSystem(sl2r(), np.diag([1.0, 2.0, 3.0]), 0.3 * np.eye(3), s=S),
                              ImplicitMidpoint(), np.array([0.2, 0.6, 0.8])),
    "su3 LieHeun": (lambda: _su(3), LieHeun(), None),                  # stepped on structure constants
    "su3 basis LieHeun": (lambda: _su(3, basis=True), LieHeun(), None),
    "su4 basis LieHeun": (lambda: _su(4, basis=True), LieHeun(), None),   # stepped on its matrix twin
}


def _y0(system, mu, members):
    mu = np.linspace(0.5, 1.0, system.dim) if mu is None else mu
    return mu * (1.0 + 0.1 * np.arange(members))[:, None]


@pytest.mark.parametrize("name", sorted(CASES))
def test_adaptive_member_is_bitwise_the_same_alone_and_in_any_batch(name):
    make, solver, mu = CASES[name]
    system = make()
    y0 = _y0(system, mu, 4)
    tree = rp.BrownianTree(3, seed=7, batch_shape=(4,))
    ctrl = rp.PIController(3e-2, 3e-2)
    whole = rp.solve(system, tree, y0, solver, step_control=ctrl, save_at=[0.0, 0.5, 1.0])
    assert whole.stats["shared_steps"] is False and np.all(np.isfinite(whole.states))
    pair = rp.solve(system, tree.select([3, 1]), y0[[3, 1]], solver, step_control=ctrl, save_at=[0.0, 0.5, 1.0])
    for i, k in ((1, 1), (3, 0)):
        alone = rp.solve(system, tree.select([i]), y0[i:i + 1], solver, step_control=ctrl, save_at=[0.0, 0.5, 1.0])
        assert np.array_equal(alone.states[0], whole.states[i]) and np.array_equal(pair.states[k], whole.states[i])
        for key in ("accepted", "rejected"):
            assert alone.stats[key][0] == whole.stats[key][i] == pair.stats[key][k]


@pytest.mark.parametrize("name", sorted(CASES))
def test_integrate_on_member_times_follows_each_members_grid(name):
    make, solver, mu = CASES[name]
    system = make()
    y0 = _y0(system, mu, 3)
    rng = np.random.default_rng(4)
    times = np.sort(np.concatenate([np.zeros((3, 1)), rng.uniform(0.0, 0.4, (3, 5)),
                                    np.full((3, 1), 0.4)], axis=1), axis=1)            # (members, K + 1)
    tree = rp.BrownianTree(3, seed=3, batch_shape=(3,))
    X = [tree.select([i]).rough_path(times[i]) for i in range(3)]
    dX = np.stack([x.increments[0] for x in X])
    dXX = np.stack([x.areas[0] for x in X])
    save = np.array([False, True, False, False, True, True])
    y, saved, first_bad = solver.integrate(system, y0, times, dX, dXX, save, stop_on_failure=True)
    assert np.all(first_bad == -1) and saved.shape == (3, 3, y0.shape[-1])
    stepped = y0
    for k in range(times.shape[1] - 1):
        stepped = solver.step(system, stepped, times[:, k:k + 1], np.diff(times, axis=1)[:, k:k + 1], dX[:, k],
                              dXX[:, k])
    for i in range(3):
        alone = rp.solve(system, X[i], y0[i], solver)          # the fixed-step route on this member's grid
        np.testing.assert_allclose(y[i], alone.final[0], rtol=0, atol=1e-12)
        np.testing.assert_allclose(saved[i], alone.states[0, 1:][save], rtol=0, atol=1e-12)
        np.testing.assert_allclose(stepped[i], alone.final[0], rtol=0, atol=1e-12)


def _member_case(algebra):
    """A system for the steps-per-member checks: so(3), se(3) (hand-written kernels), su(2), sl(2, R) and se(3) given
    by its constants alone (a user's algebra, dimension 6: the midpoint rule's compiled variant; the Lévy torque
    outside the double bracket), su(3) as a matrix algebra (whose members are stepped on its structure constants)
    and su(4) from its matrix basis (on its matrix twin)."""
    if algebra == "so3":
        return rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0)
    if algebra == "se3":
        return heavy_top(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0]), sigma=0.3, s=S, theta=0.5)
    g = {"su2": su2, "sl2r": sl2r, "user6": lambda: LieAlgebra(se3().structure_constants, name="user"),
         "su3 matrix": lambda: su(3), "su4 basis": lambda: LieAlgebra.from_matrix_basis(su(4).basis)}[algebra]()
    xi = 0.4 * np.random.default_rng(5).standard_normal((3, g.dim))
    # the user's algebra with the Lévy torque kept out of the double bracket: the velocity's f term is not zero
    return LiePoissonSystem(g, np.diag(1.0 + np.arange(g.dim) / g.dim), xi, s=S, theta=0.0 if "su" in algebra else 0.7,
                            levy_in_dissipation=algebra != "user6")


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=repr)
@pytest.mark.parametrize("algebra", ["so3", "se3", "su2", "sl2r", "user6", "su3 matrix", "su4 basis"])
def test_steps_per_member_agree_with_the_numpy_step_of_each_member(solver, algebra):
    system = _member_case(algebra)
    compiled = algebra != "su4 basis"
    stepped_on = member_system(system)
    assert isinstance(stepped_on.algebra, LieAlgebra) == compiled        # the cost model's choice (_dispatch)
    rng = np.random.default_rng(11)
    n = 6
    mu = rng.standard_normal((n, system.dim))
    dt = np.array([1e-4, 1e-3, 0.01, 0.05, 0.2, 0.4])[:, None]
    dX = rng.standard_normal((n, 3)) * np.sqrt(dt) * np.array([1, 1, 1, 1, 8, 16])[:, None]  # past the Taylor branch
    dXX = 0.5 * dX[:, :, None] * dX[:, None, :] + 0.3 * dt[:, :, None] * np.array([[0, 1, 0], [-1, 0, 2], [0, -2, 0]])
    if algebra == "so3":
        eta = solver._eta(system, dX, dXX)
        assert np.any(np.sum(eta[-2:, :3] ** 2, -1) > 1e-2)         # the trigonometric branch is taken
    if compiled and algebra not in ("so3", "se3"):
        # the generic kernel's exponential: Taylor on the vector for small steps, scaling and squaring for the last
        c = np.abs(stepped_on.algebra.structure_constants)
        theta = np.abs(solver._eta(stepped_on, dX, dXX)) @ np.max(np.sum(c, axis=2), axis=1)
        assert theta[0] < THETA_VECTOR < theta[-1]
    t = np.zeros((n, 1))
    new = solver.step(system, mu, t, dt, dX, dXX)                    # dt per member: the compiled steps
    fin = np.all(np.isfinite(new), axis=-1)
    # the explicit schemes take every step; the midpoint rule's chord iteration may fail on the largest two (sl(2, R),
    # su(4)), in both paths alike
    assert fin.all() if solver._code != 2 else fin[:4].all()
    for p in range(n):
        ref = solver.step(system, mu[p], 0.0, float(dt[p, 0]), dX[p], dXX[p])   # a float: the numpy path
        assert np.all(np.isfinite(ref)) == fin[p] and np.isnan(new[p]).all() != fin[p]
        if fin[p]:
            np.testing.assert_allclose(new[p], ref, rtol=0, atol=1e-12 * (1 + np.abs(ref).max()))
    bad = mu.copy()
    bad[2, 1] = np.nan
    new2 = solver.step(system, bad, t, dt, dX, dXX)
    others = [0, 1, 3, 4, 5]
    assert np.isnan(new2[2]).all() and np.array_equal(np.all(np.isfinite(new2[others]), axis=-1), fin[others])
    if compiled:
        np.testing.assert_array_equal(new2[others], new[others])        # the others' bits are their own


def test_compiled_steps_per_member_do_not_depend_on_threads_or_neighbours():
    # su(3) as a matrix algebra, stepped on its structure constants: 200 members are split into ranges between
    # numba's threads (about 80 members a range); every member's bits are its own whatever the split
    system = _member_case("su3 matrix")
    rng = np.random.default_rng(3)
    B = 200
    mu = rng.standard_normal((B, system.dim))
    dt = rng.uniform(1e-3, 5e-2, (B, 1))
    dX = rng.standard_normal((B, 3)) * np.sqrt(dt)
    dXX = 0.5 * dX[:, :, None] * dX[:, None, :] + 0.1 * dt[:, :, None] * np.array([[0, 1, 0], [-1, 0, 2], [0, -2, 0]])
    solver = LieHeun()
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = solver.step(system, mu, np.zeros((B, 1)), dt, dX, dXX)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = solver.step(system, mu, np.zeros((B, 1)), dt, dX, dXX)
    finally:
        numba.set_num_threads(before)
    assert np.all(np.isfinite(one))
    np.testing.assert_array_equal(one, many)
    for lo in (0, 57, 199):                                  # a member alone, and a slice of its neighbours
        np.testing.assert_array_equal(solver.step(system, mu[lo:lo + 1], np.zeros((1, 1)), dt[lo:lo + 1], dX[lo:lo + 1],
                                                  dXX[lo:lo + 1]), one[lo:lo + 1])
    np.testing.assert_array_equal(solver.step(system, mu[50:130], np.zeros((80, 1)), dt[50:130], dX[50:130],
                                              dXX[50:130]), one[50:130])
