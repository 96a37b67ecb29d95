"""Coadjoint solvers on steps per member (``Solver.member_times``, contract item 10).

Claims:

* adaptive steps per member are the default for the coadjoint solvers (``Solution.stats["shared_steps"]`` is
  ``False``), and a member's states, times and counts are bitwise the same solved alone or in any batch, for
  LieEuler, LieHeun and ImplicitMidpoint on so(3), for the heavy top on se(3), for a forced system (the numpy
  path with ``force`` and ``noise_forces``), for su(3) as a matrix algebra and for su(3) from its matrix basis (a
  structure-constant algebra, whose members are stepped on its matrix twin);
* ``integrate`` with times of shape ``(members, K + 1)`` takes each member along its own grid: it agrees to
  round-off with solving each member alone on its grid by the fixed-step route (for so(3) and se(3) that is the
  compiled block kernels, another implementation of the same steps), and so does ``step`` with ``dt`` of
  shape ``(members, 1)``;
* on so(3) and se(3) without forces, where steps per member run compiled (``so3_member_steps``,
  ``se3_member_steps``), a step with ``dt`` per member equals the numpy path's step of each member alone with its ``dt`` as a float (the closed-form
  exponential, another implementation) to round-off, for small and large ``|sigma|`` (the Taylor and the
  trigonometric branch), and a non-finite member comes back NaN, failed, alone.
"""

import numpy as np
import pytest

import roughpaths as rp
from mechanics import (ImplicitMidpoint, LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body, so3,
                       su)

S = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.5], [0.0, -0.5, 0.0]])


def _forced():
    xi = 0.5 * np.eye(3) + 0.1 * np.random.default_rng(1).standard_normal((3, 3))
    return LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), xi, s=S, force=lambda mu: -0.2 * mu,
                            noise_forces=lambda mu: 0.1 * np.stack([np.sin(mu), np.cos(mu) - 1.0, mu ** 2], axis=-1))


def _su3(basis=False):
    g = LieAlgebra.from_matrix_basis(su(3).basis) if basis else su(3)
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
    "su3 LieHeun": (_su3, LieHeun(), None),
    "su3 basis LieHeun": (lambda: _su3(basis=True), LieHeun(), None),       # stepped on its matrix twin
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


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=repr)
@pytest.mark.parametrize("algebra", ["so3", "se3"])
def test_steps_per_member_agree_with_the_numpy_step_of_each_member(solver, algebra):
    system = (rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0) if algebra == "so3" else
              heavy_top(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0]), sigma=0.3, s=S, theta=0.5))
    rng = np.random.default_rng(11)
    n = 6
    mu = rng.standard_normal((n, system.dim))
    dt = np.array([1e-4, 1e-3, 0.01, 0.05, 0.2, 0.4])[:, None]
    dX = rng.standard_normal((n, 3)) * np.sqrt(dt) * np.array([1, 1, 1, 1, 8, 8])[:, None]   # past the Taylor branch
    dXX = 0.5 * dX[:, :, None] * dX[:, None, :] + 0.3 * dt[:, :, None] * np.array([[0, 1, 0], [-1, 0, 2], [0, -2, 0]])
    eta = solver._eta(system, dX, dXX)
    assert np.any(np.sum(eta[-2:, :3] ** 2, -1) > 1e-2)             # the trigonometric branch is taken
    new, ok, _ = solver._advance(system, mu, dt, eta)                # dt per member: the compiled steps
    assert ok.all()
    for p in range(n):
        ref, ref_ok, _ = solver._advance(system, mu[p], float(dt[p, 0]), eta[p])     # a float: the numpy path
        assert ref_ok
        np.testing.assert_allclose(new[p], ref, rtol=0, atol=1e-13 * (1 + np.abs(ref).max()))
    bad = mu.copy()
    bad[2, 1] = np.nan
    new2, ok2, _ = solver._advance(system, bad, dt, eta)
    assert not ok2[2] and np.isnan(new2[2]).all() and ok2[[0, 1, 3, 4, 5]].all()
    assert np.array_equal(new2[[0, 1, 3, 4, 5]], new[[0, 1, 3, 4, 5]])        # the others' bits are their own
