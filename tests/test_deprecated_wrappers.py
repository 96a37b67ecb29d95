"""The deprecated entry points are thin wrappers: each warns, names its replacement, and returns its numbers.

Claim, for every deprecated name (``mechanics.simulate``, ``simulate_brownian``, ``coadjoint_step``,
``integrate_rigid_body``, ``levy_torque``, ``path_generator``, ``RigidBody.levy_torque_vector``): calling it
emits one ``DeprecationWarning`` whose message names the replacement and which points at the caller's line
(not at library internals), and the result equals the replacement call's
(``roughpaths.solve`` + ``BrownianDriver`` / ``RoughPath``, ``solver.step``, ``rigid_body(..., s,
levy_in_dissipation)``, ``levy_velocity``, the documented generator) exactly, or to round-off where the
wrapper assembles the same model differently (``integrate_rigid_body``). The wrappers' own argument
validation (``orbit=``, ``save_every=``, ``levy_area=``, ``rng``, ``step_index``) is checked here too:
it is the only place those arguments exist.

This is the one test module allowed to call deprecated names; the rest of the suite and the tutorials
run clean under ``-W error::DeprecationWarning``.
"""

import warnings

import numpy as np
import pytest

import mechanics
from mechanics import (ImplicitMidpoint, LieEuler, LieHeun, LiePoissonSystem, check_on_orbit, heavy_top,
                       levy_velocity, rigid_body)
from mechanics.lie_algebra import so3
from roughpaths import BrownianDriver, RoughPath, solve

I3 = [1.0, 2.0, 3.0]
S = np.array([[0.0, 1.5, -2.0], [-1.5, 0.0, 0.7], [2.0, -0.7, 0.0]])


def _deprecated(fn, *args, match, **kwargs):
    """Call ``fn``; require exactly one DeprecationWarning matching ``match``, attributed to this file."""
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        out = fn(*args, **kwargs)
    dep = [w for w in rec if issubclass(w.category, DeprecationWarning)]
    assert len(dep) == 1, [str(w.message) for w in rec]
    assert match in str(dep[0].message), str(dep[0].message)
    assert dep[0].filename == __file__, dep[0].filename      # stacklevel: the user's line, not the library's
    return out


def _path(rng, batch=(3,), n=40, T=1.0):
    """A geometric level-2 path with non-zero step Lévy areas (Brownian-sized)."""
    h = T / n
    dw = np.sqrt(h) * rng.standard_normal(batch + (n, 3))
    lam = 0.5 * h * rng.standard_normal(batch + (n, 3, 3))
    areas = 0.5 * dw[..., :, None] * dw[..., None, :] + 0.5 * (lam - np.swapaxes(lam, -1, -2))
    return RoughPath.from_increments(dw, areas, times=np.linspace(0.0, T, n + 1))


# ------------------------------------------------------------------------------------------ simulate
@pytest.mark.parametrize("method", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_simulate(method, rng):
    rb = rigid_body(I3, sigma=0.5, s=S, theta=0.7)
    X = _path(rng)
    mu0 = [0.0, 0.6, 0.8]
    t, a = _deprecated(mechanics.simulate, rb, mu0, X, method, save_every=4, match="roughpaths.solve")
    sol = solve(rb, X, mu0, method, save_at=X.times[::4])
    np.testing.assert_array_equal(t, sol.times)
    np.testing.assert_array_equal(a, sol.states)
    assert a.shape == (3, 11, 3)
    # levy_area=False: the Method(levy_area=False) solver on the level-1 path
    _, b = _deprecated(mechanics.simulate, rb, mu0, X.to_level1(), method, levy_area=False, match="roughpaths.solve")
    np.testing.assert_array_equal(b, solve(rb, X.to_level1(), mu0, type(method)(levy_area=False)).states)
    assert np.max(np.abs(b[:, -1] - a[:, -1])) > 1e-6                # the areas mattered


def test_simulate_own_validation(rng):
    """orbit=, save_every=, levy_area= and the method/driver types exist only on the wrapper."""
    rb = rigid_body(I3, sigma=0.1, theta=1.0)
    X = _path(rng, batch=())
    top = heavy_top(I3, [0, 0, 1.0], sigma=0.1)
    with pytest.warns(DeprecationWarning, match="roughpaths.solve"):
        with pytest.raises(ValueError, match=r"off the coadjoint orbit: \|mu\|\^2 = 4.0"):
            mechanics.simulate(rb, [0.0, 0.0, 2.0], X, orbit=[1.0])
        with pytest.raises(ValueError, match="Pi.Gamma"):
            mechanics.simulate(top, [1.0, 0, 0, 1.0, 0, 0], X, orbit=[1.0, 0.0])
        _, on = mechanics.simulate(top, [0.0, 1.0, 0, 1.0, 0, 0], X, orbit=[1.0, 0.0])   # on the orbit: accepted
        with pytest.raises(ValueError, match="save_every"):
            mechanics.simulate(rb, [0, 0, 1.0], X, save_every=0)
        with pytest.raises(TypeError, match="method"):
            mechanics.simulate(rb, [0, 0, 1.0], X, method="heun")
        with pytest.raises(TypeError, match=r"did you mean LieHeun\(\)"):
            mechanics.simulate(rb, [0, 0, 1.0], X, LieHeun)
        with pytest.raises(TypeError, match="RoughPath"):
            mechanics.simulate(rb, [0, 0, 1.0], np.zeros((11, 3)))
        with pytest.raises(ValueError, match="levy_area=False"):
            mechanics.simulate(rb, [0, 0, 1.0], X.to_level1())
        with pytest.raises(ValueError, match="to_level1"):
            mechanics.simulate(rb, [0, 0, 1.0], X, levy_area=False)
        with pytest.raises(TypeError, match="levy_area"):
            mechanics.simulate(rb, [0, 0, 1.0], X, levy_area="yes")
    check_on_orbit(top, on, [1.0, 0.0])                                # the run stayed on it


# --------------------------------------------------------------------------------- simulate_brownian
@pytest.mark.parametrize("levy_area, driver_area", [(True, "davie"), ("foster", "foster"), (False, None)])
def test_simulate_brownian(levy_area, driver_area):
    """Same numbers as ``solve(system, BrownianDriver(m, seed=int(rng.integers(2**63)), ...), mu0, method)``."""
    top = heavy_top(I3, [0.1, -0.2, 1.0], sigma=0.3, s=S, theta=0.5)
    mu0 = np.array([0.4, -0.3, 1.1, 0.3, 0.5, 0.81])
    t, a = _deprecated(mechanics.simulate_brownian, top, mu0, 0.01, 60, np.random.default_rng(3), n_paths=5,
                       levy_area=levy_area, area_substeps=2, save_every=6, chunk_steps=7,
                       match="roughpaths.BrownianDriver")
    seed = int(np.random.default_rng(3).integers(2 ** 63))            # the wrapper's documented seed
    X = BrownianDriver(3, seed=seed, dt=0.01, n_steps=60, batch_shape=(5,), levy_area=driver_area, substeps=2)
    sol = solve(top, X, mu0, LieHeun(levy_area=driver_area is not None), save_at=X.times[::6])
    np.testing.assert_array_equal(t, sol.times)
    np.testing.assert_array_equal(a, sol.states)
    assert a.shape == (5, 11, 6)


def test_simulate_brownian_own_validation(rng):
    rb = rigid_body(I3, sigma=0.1, theta=1.0)
    with pytest.warns(DeprecationWarning, match="BrownianDriver"):
        with pytest.raises(ValueError, match=r"batch index \(1,\)"):
            mechanics.simulate_brownian(rb, [[0.0, 0.0, 1.0], [0.0, 0.0, 1.1]], 0.01, 10, rng, orbit=1.0)
        with pytest.raises(TypeError, match="Generator"):
            mechanics.simulate_brownian(rb, [0, 0, 1.0], 0.01, 10, 42)
        with pytest.raises(ValueError, match="dt"):
            mechanics.simulate_brownian(rb, [0, 0, 1.0], -0.01, 10, rng)
        with pytest.raises(ValueError, match="n_steps"):
            mechanics.simulate_brownian(rb, [0, 0, 1.0], 0.01, 0, rng)
        with pytest.raises(ValueError, match="levy_area"):
            mechanics.simulate_brownian(rb, [0, 0, 1.0], 0.01, 10, rng, levy_area="exact")
        with pytest.raises(ValueError, match="non-finite"):
            mechanics.simulate_brownian(rb, [0, np.nan, 1.0], 0.01, 10, rng)
        with pytest.raises(ValueError, match="save_every"):
            mechanics.simulate_brownian(rb, [0, 0, 1.0], 0.01, 10, rng, save_every=0)


# ------------------------------------------------------------------------------------ coadjoint_step
@pytest.mark.parametrize("method", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_coadjoint_step(method, rng):
    """``coadjoint_step(system, mu, dt, eta)`` with ``eta`` the step's stochastic velocity == ``solver.step``."""
    rb = rigid_body(I3, sigma=0.5, s=S, theta=0.7)
    mu = rng.standard_normal((4, 3))
    dX = 0.1 * rng.standard_normal((4, 3))
    lam = 0.01 * rng.standard_normal((4, 3, 3))
    dXX = 0.5 * dX[:, :, None] * dX[:, None, :] + (lam - np.swapaxes(lam, -1, -2))
    eta = rb.stochastic_velocity(dX, 0.5 * (dXX - np.swapaxes(dXX, -1, -2)))
    a = _deprecated(mechanics.coadjoint_step, rb, mu, 0.05, eta, method, match="solver.step")
    np.testing.assert_array_equal(a, method.step(rb, mu, 0.0, 0.05, dX, dXX))
    assert np.max(np.abs(a - mu)) > 1e-3


def test_coadjoint_step_names_the_given_step():
    """``step_index`` / ``t`` only label the wrapper's chord-failure message."""
    generic = LiePoissonSystem(so3(), lambda m: 0.5 * np.sum(m * m / I3, -1), 0.5 * np.eye(3), theta=50.0,
                               hamiltonian_gradient=lambda m: m / np.asarray(I3))
    with pytest.warns(DeprecationWarning, match="solver.step"):
        with pytest.raises(mechanics.ChordConvergenceError, match=r"step 7 \(t = 0.35"):
            mechanics.coadjoint_step(generic, np.array([0.0, 0.6, 0.8]), 0.05, np.zeros(3),
                                     ImplicitMidpoint(tol=1e-15, max_iter=1), step_index=7, t=0.35)


# ------------------------------------------------------------------------------ integrate_rigid_body
def test_integrate_rigid_body(rng):
    """== ``solve(rigid_body(I, xi, s, theta, levy_in_dissipation=...), X, Pi0, LieHeun())`` with
    ``c = ½ s^{ij} ξ_i×ξ_j``: ``torque=c`` alone is ``levy_in_dissipation=False``, ``torque =
    dissipation_shift = c`` is ``levy_in_dissipation=True`` (the wrapper puts ``c·Π`` into ``h`` instead
    of into the Lévy velocity, so the two agree to round-off rather than bitwise)."""
    X = _path(rng, batch=(4,), n=50)
    xi = 0.5 * np.eye(3)
    Pi0 = [0.0, 0.6, 0.8]
    c = levy_velocity(S, xi)
    t, plain = _deprecated(mechanics.integrate_rigid_body, X, Pi0, I3, xi, 1.0, save_every=5, match="roughpaths.solve")
    ref = solve(rigid_body(I3, xi=xi, theta=1.0), X, Pi0, LieHeun(), save_at=X.times[::5])
    np.testing.assert_array_equal(t, ref.times)
    np.testing.assert_allclose(plain, ref.states, rtol=0, atol=1e-13)
    for cd, in_diss in ((None, False), (c, True)):
        _, a = _deprecated(mechanics.integrate_rigid_body, X, Pi0, I3, xi, 1.0, torque=c, dissipation_shift=cd,
                           match="levy_in_dissipation=False")
        b = solve(rigid_body(I3, xi=xi, s=S, theta=1.0, levy_in_dissipation=in_diss), X, Pi0, LieHeun()).states
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)
        assert np.max(np.abs(a[:, -1] - plain[:, -1])) > 1e-3            # the torque mattered
    with pytest.warns(DeprecationWarning), pytest.raises(TypeError, match="level-2"):
        mechanics.integrate_rigid_body(X.to_level1(), Pi0, I3, xi, 1.0)


# ------------------------------------------------------------------- levy_torque, levy_torque_vector
def test_levy_torque(rng):
    xi = rng.standard_normal((3, 3))
    a = _deprecated(mechanics.levy_torque, S, xi, match="levy_velocity")
    np.testing.assert_array_equal(a, levy_velocity(S, xi))
    # an independent closed form: ½ Σ s^{ij} ξ_i × ξ_j
    np.testing.assert_allclose(a, 0.5 * sum(S[i, j] * np.cross(xi[i], xi[j]) for i in range(3) for j in range(3)),
                               atol=1e-14)


def test_rigid_body_levy_torque_vector():
    rb = rigid_body(I3, sigma=0.05, s=S, theta=1.0)
    a = _deprecated(lambda: rb.levy_torque_vector, match=".levy_velocity")
    np.testing.assert_array_equal(a, rb.levy_velocity)
    np.testing.assert_allclose(a, 0.05 ** 2 * np.array([S[1, 2], -S[0, 2], S[0, 1]]), atol=1e-15)


# ------------------------------------------------------------------------------------ path_generator
def test_path_generator():
    """No longer the ensemble's stream (that is ``BrownianDriver(..., seed=seed).select([i])``, named in the
    warning); its numbers are still the documented ``PCG64(SeedSequence(seed, spawn_key=(index,)))``."""
    g = _deprecated(mechanics.path_generator, 11, 3, match="BrownianDriver")
    ref = np.random.Generator(np.random.PCG64(np.random.SeedSequence(11, spawn_key=(3,))))
    np.testing.assert_array_equal(g.standard_normal(20), ref.standard_normal(20))
