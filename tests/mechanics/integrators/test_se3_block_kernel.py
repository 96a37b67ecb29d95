"""The heavy top's Lie–Euler and Lie–Heun kernel (``_se3_block``): bit for bit the generic kernel's numbers.

Claims:

* Lie–Euler and Lie–Heun on se(3)* with three noise fields take the se(3) block kernel (se(3) as
  :class:`~mechanics.systems.lie_algebra.SE3Algebra` or given by its structure constants alike), and their
  states are bitwise those of the generic kernel (forced by hiding the table match), across heavy tops with and
  without dissipation, with the Lévy shift inside and outside the double bracket (``f ≠ 0``), a full inertia,
  noise in all of se(3), the ``"paper"`` convention, Davie areas and none; on several blocks, with a wild member
  (the scaling-and-squaring path) and a NaN increment (failing alone at its step), on one thread and two.
* The table match is exact: se(3) with its structure constants negated (a Lie algebra too, the opposite
  bracket) or scaled, and other six-dimensional algebras, run the generic kernel, and still agree with the
  numpy scheme; two or four noise fields run the generic kernel too.
"""

import numba
import numpy as np
import pytest

from mechanics import LieAlgebra, LiePoissonSystem, heavy_top
from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun, _generic_kernels, _se3_block, _soa_rows
from mechanics.systems.lie_algebra import se3
from roughpaths import BrownianDriver, RoughPath, Solver, solve

S3 = np.array([[0.0, 1.0, -0.5], [-1.0, 0.0, 0.3], [0.5, -0.3, 0.0]])
FULL_INERTIA = np.array([[2.0, 0.3, 0.1], [0.3, 1.5, -0.2], [0.1, -0.2, 1.0]])


def _tops():
    rng = np.random.default_rng(3)
    return {
        "theta": heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.3),
        "no_theta": heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2),
        "shift_outside": heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, s=S3, theta=0.4,
                                   levy_in_dissipation=False),
        "full": heavy_top(FULL_INERTIA, chi=[0.3, 0.2, 1.0], xi=0.2 * rng.standard_normal((3, 6)), s=S3, theta=0.3),
        "paper": heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.2, convention="paper"),
    }


TOPS = _tops()


def _solve(system, X, mu0, solver, generic, monkeypatch):
    with monkeypatch.context() as m:
        if generic:
            m.setattr(_se3_block, "has_se3_table", lambda *a: False)
        with np.errstate(all="ignore"):
            return solve(system, X, mu0, solver, on_failure="mask")


def _path(n_noise, nb, area, seed=5, dt=0.05, n_steps=37):
    Y = BrownianDriver(n_noise, seed=seed, dt=dt, n_steps=n_steps, batch_shape=(nb,), levy_area=area).rough_path()
    inc = np.array(Y.increments)
    inc[70, 9, 0] = np.nan                                   # a broken member, in the second block
    return RoughPath(inc, Y.areas, times=Y.times, kind="geometric", check=False)


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun()], ids=repr)
@pytest.mark.parametrize("area", ["davie", None])
@pytest.mark.parametrize("name", list(TOPS))
def test_bitwise_the_generic_kernel(name, area, solver, monkeypatch):
    top = TOPS[name]
    nb = 2 * _se3_block.B + 3                                  # three blocks, the last one short
    mu0 = np.random.default_rng(1).standard_normal((nb, 6))
    mu0[2] *= 1e8                                            # a wild member: large θ, the scalar path
    X = _path(3, nb, area)
    kernels = []
    # which variant a solve starts with is process state (_soa_rows.starts_full): an earlier test's se(3) solve
    # without a wild member would make the first solve here start without the exact step (one call more)
    monkeypatch.setattr(_soa_rows, "_STARTS", {})
    real, real_full = _se3_block.run_block, _se3_block.run_block_full    # the wild member: the variant with the
    monkeypatch.setattr(_se3_block, "run_block", lambda *a: kernels.append(a[8]) or real(*a))   # exact exponential
    monkeypatch.setattr(_se3_block, "run_block_full", lambda *a: kernels.append(a[8]) or real_full(*a))
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        ours = _solve(top, X, mu0, solver, False, monkeypatch)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        ours2 = _solve(top, X, mu0, solver, False, monkeypatch)
    finally:
        numba.set_num_threads(threads)
    assert kernels == [solver._code] * 6                     # three blocks, twice
    ref = _solve(top, X, mu0, solver, True, monkeypatch)
    assert len(kernels) == 6                                 # the reference did not take it
    for got in (ours, ours2):
        np.testing.assert_array_equal(got.states.view(np.uint64), ref.states.view(np.uint64))
        np.testing.assert_array_equal(got.failed_step, ref.failed_step)
    assert ours.failed[70] and ours.failed_step[70] == 9
    assert np.isfinite(ours.states[0]).all()


def _plain(system, c):
    return LiePoissonSystem(LieAlgebra(c, name="constants", check=False), system.hamiltonian, system.xi,
                            theta=system.theta)


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun()], ids=repr)
def test_table_match_is_exact(solver, monkeypatch):
    top = TOPS["theta"]
    c = se3().structure_constants
    taken = []
    real, real_full = _se3_block.run_block, _se3_block.run_block_full    # either variant (the process may have
    monkeypatch.setattr(_se3_block, "run_block", lambda *a: taken.append(a[8]) or real(*a))   # needed the exact
    monkeypatch.setattr(_se3_block, "run_block_full", lambda *a: taken.append(a[8]) or real_full(*a))   # step)
    mu0 = np.random.default_rng(2).standard_normal((5, 6))
    X = BrownianDriver(3, seed=3, dt=0.02, n_steps=30, batch_shape=(5,)).rough_path()
    save = np.ones(30, dtype=bool)
    for system, fast in ((_plain(top, c), True), (_plain(top, -c), False), (_plain(top, 2.0 * c), False)):
        taken.clear()
        ours = solve(system, X, mu0, solver).states[:, 1:]
        assert taken == ([solver._code] if fast else [])
        _, ref, _ = Solver.integrate(solver, system, mu0.copy(), X.times, X.increments, X.areas, save)
        assert np.max(np.abs(ours - ref) / np.maximum(1.0, np.abs(ref))) < 1e-11
    # the table itself: se(3)'s, and not a negated or permuted one
    ti, tj, tk, tv, _, _ = _generic_kernels.algebra_tables(c)
    assert _se3_block.has_se3_table(ti, tj, tk, tv)
    assert not _se3_block.has_se3_table(ti, tj, tk, -tv)
    assert not _se3_block.has_se3_table(tk, tj, ti, tv)


@pytest.mark.parametrize("m", [2, 4])
def test_other_noise_counts_run_the_generic_kernel(m, monkeypatch):
    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], xi=0.3 * np.eye(m, 6), theta=0.2)
    taken = []
    monkeypatch.setattr(_se3_block, "run_block", lambda *a: taken.append(a[8]))
    X = BrownianDriver(m, seed=1, dt=0.02, n_steps=10, batch_shape=(3,)).rough_path()
    solve(top, X, np.ones((3, 6)), LieHeun())
    solve(top, X, np.ones((3, 6)), ImplicitMidpoint())
    assert taken == []
