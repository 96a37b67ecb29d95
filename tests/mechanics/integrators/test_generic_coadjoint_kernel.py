"""The compiled coadjoint kernel built from structure constants (every algebra without a hand-written kernel).

Claims, on so(3) in a skewed basis, se(3) rebuilt from its own structure constants, su(2), sl(2, R)
and so(4) (6-dimensional, two Casimirs), for Lie–Euler, Lie–Heun and the chord implicit midpoint:

* ``roughpaths.solve`` takes the compiled path (checked by counting its calls) and agrees with the
  numpy scheme (the library's path for forced systems: ``expm_batched`` of the ``ad*`` matrices, numpy
  chord) to ~1e-12, also on steps that need Taylor degrees up to 23 or the scaling-and-squaring branch;
* every Casimir is kept to 1e-12 over 2,000 steps;
* a member gives bit for bit its result alone, also beside a member scaled by 1e9 and one with a NaN
  increment (which fails alone, at its step), and the result is the same with one or two threads
  (several blocks).
"""

import numba
import numpy as np
import pytest

from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun, _generic_kernels
from mechanics.systems.lie_algebra import LieAlgebra, se3, sl2r, so3, su2
from mechanics.systems.lie_poisson import LiePoissonSystem
from roughpaths import BrownianDriver, RoughPath, Solver, solve

SOLVERS = [LieEuler(), LieHeun(), ImplicitMidpoint()]


def _skewed_so3():
    b = np.array([[1.0, 0.2, 0.0], [0.0, 1.0, 0.3], [0.1, 0.0, 1.0]])
    c = np.einsum("ia,jb,abk,kl->ijl", b, b, so3().structure_constants, np.linalg.inv(b))
    binv = np.linalg.inv(b)                     # mu_f = b mu_e: |b^-1 mu|^2 is the Casimir
    return LieAlgebra(c, name="skewed so3", casimirs=lambda mu: np.sum((mu @ binv.T) ** 2, -1)[..., None])


def _se3_from_constants():
    def cas(mu):
        p, g = mu[..., :3], mu[..., 3:]
        return np.stack([np.sum(g * g, -1), np.sum(p * g, -1)], -1)
    return LieAlgebra(se3().structure_constants, name="se3 (constants)", casimirs=cas)


def _so4():
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    basis = np.zeros((6, 4, 4))
    for r, (a, b) in enumerate(pairs):
        basis[r, a, b], basis[r, b, a] = 1.0, -1.0

    def cas(mu):                                # |M|^2 and the Pfaffian of M = Σ mu_ab E_ab
        m01, m02, m03, m12, m13, m23 = np.moveaxis(mu, -1, 0)
        return np.stack([np.sum(mu * mu, -1), m01 * m23 - m02 * m13 + m03 * m12], -1)
    return LieAlgebra.from_matrix_basis(basis, name="so4", casimirs=cas)


ALGEBRAS = {"skewed_so3": _skewed_so3, "se3_constants": _se3_from_constants, "su2": su2, "sl2r": sl2r,
            "so4": _so4}


def _system(name):
    alg = ALGEBRAS[name]()
    n = alg.dim
    rng = np.random.default_rng(7)
    inertia = np.diag(1.0 + np.arange(n) / 2.0)
    m = 3
    xi = 0.3 * rng.standard_normal((m, n))
    s = np.array([[0.0, 1.0, 0.5], [-1.0, 0.0, -0.2], [-0.5, 0.2, 0.0]])
    return LiePoissonSystem(alg, inertia, xi, s=s, theta=0.3)


def _numpy_path(solver, system, mu0, X):
    save = np.ones(X.n_steps, dtype=bool)
    _, saved, _ = Solver.integrate(solver, system, mu0.copy(), X.times, X.increments, X.areas, save)
    return saved


@pytest.mark.parametrize("solver", SOLVERS, ids=repr)
@pytest.mark.parametrize("name", list(ALGEBRAS))
@pytest.mark.parametrize("dt, n_steps", [(0.02, 30), (0.6, 3), (1.5, 2)],
                         ids=["taylor", "large_steps", "past_vector"])
def test_agrees_with_numpy_path(name, solver, dt, n_steps, monkeypatch):
    """dt = 0.6: θ ~ 0.7 .. 4, the high Taylor degrees (θ > 1.1) and some scaling-and-squaring steps; dt = 1.5:
    θ ~ 1.7 .. 9, nearly every member past the vector path (few steps: the large-step map amplifies round-off
    quickly)."""
    system = _system(name)
    calls = []
    real = _generic_kernels.integrate_generic
    monkeypatch.setattr(_generic_kernels, "integrate_generic", lambda *a: calls.append(1) or real(*a))
    mu0 = np.random.default_rng(1).standard_normal((5, system.dim))
    X = BrownianDriver(3, seed=3, dt=dt, n_steps=n_steps, batch_shape=(5,)).rough_path()
    with np.errstate(all="ignore"):
        ours = solve(system, X, mu0, solver, on_failure="mask").states[:, 1:]
        ref = _numpy_path(solver, system, mu0, X)
    assert calls
    scale = np.maximum(1.0, np.abs(ref))
    assert np.array_equal(np.isnan(ours), np.isnan(ref))
    assert np.nanmax(np.abs(ours - ref) / scale) < 1e-11


@pytest.mark.parametrize("solver", SOLVERS, ids=repr)
@pytest.mark.parametrize("name", list(ALGEBRAS))
def test_casimirs_kept(name, solver):
    system = _system(name)
    mu0 = np.random.default_rng(2).standard_normal((4, system.dim))
    X = BrownianDriver(3, seed=4, dt=0.01, n_steps=2000, batch_shape=(4,))
    mu = solve(system, X, mu0, solver, save_at=X.times[::250]).states
    c0 = system.casimirs(mu0)[:, None, :]
    err = np.max(np.abs(system.casimirs(mu) - c0) / np.maximum(1.0, np.abs(c0)))
    assert err <= 1e-12, err
    assert np.max(np.abs(mu[:, -1] - mu0)) > 1e-2          # the state really moved


@pytest.mark.parametrize("solver", SOLVERS, ids=repr)
@pytest.mark.parametrize("name", list(ALGEBRAS))
def test_member_alone_equals_member_in_batch(name, solver):
    system = _system(name)
    n = system.dim
    nb = 2 * _generic_kernels.BLOCK + 3                      # three blocks
    rng = np.random.default_rng(5)
    mu0 = rng.standard_normal((nb, n))
    mu0[1] *= 1e9                                            # a wild member (may fail alone)
    Y = BrownianDriver(3, seed=6, dt=0.01, n_steps=12, batch_shape=(nb,)).rough_path()
    inc = np.array(Y.increments)
    inc[200, 5, 0] = np.nan                                  # a broken member, in the second block
    X = RoughPath(inc, Y.areas, times=Y.times, kind="geometric", check=False)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        with np.errstate(all="ignore"):
            one = solve(system, X, mu0, solver, on_failure="mask")
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        with np.errstate(all="ignore"):
            many = solve(system, X, mu0, solver, on_failure="mask")
    finally:
        numba.set_num_threads(threads)
    np.testing.assert_array_equal(one.states, many.states)
    assert one.failed[200] and one.failed_step[200] == 5
    for i in (0, 1, 2, 127, 128, 200, nb - 1):
        with np.errstate(all="ignore"):
            alone = solve(system, RoughPath(inc[i], Y.areas[i], times=Y.times, kind="geometric", check=False),
                          mu0[i], solver, on_failure="mask")
        np.testing.assert_array_equal(one.states[i], alone.states)
