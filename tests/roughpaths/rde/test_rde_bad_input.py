"""Bad input to the RDE solvers raises a clear ValueError/TypeError, never a silent wrong answer.

Claims: mismatched dimensions between fields, driver and ``y0`` are reported with the sizes; a
level-2 solver refuses a level-1 driver (instead of dropping the area); a solver class instead of
an instance gets "did you mean Davie()?"; unknown solver names list the valid ones; a state that
becomes non-finite during the solve is reported with its step index and time; a non-antisymmetric
``s`` is rejected; malformed callables are caught at construction.
"""

import numpy as np
import pytest

from roughpaths import (Davie, Euler, Heun, LinearVectorFields, LogODE, rough_integral, RoughPath, solve,
                        VectorFields)


@pytest.fixture
def setup(rng):
    M = 0.5 * rng.standard_normal((2, 3, 3))
    W = np.cumsum(0.1 * rng.standard_normal((4, 9, 2)), axis=-2)
    return LinearVectorFields(M), RoughPath.from_path(W)


def test_dimension_mismatches(setup, rng):
    V, X = setup
    X3 = RoughPath.from_path(rng.standard_normal((4, 9, 3)))
    with pytest.raises(ValueError, match=r"d=3.*dim_noise=2"):
        solve(V, X3, np.ones(3))
    with pytest.raises(ValueError, match=r"y0 has last dimension 2.*R\^3"):
        solve(V, X, np.ones(2))
    with pytest.raises(ValueError, match="do not broadcast"):
        solve(V, X, np.ones((5, 3)))
    with pytest.raises(TypeError, match="RoughPath"):
        solve(V, np.zeros((8, 2)), np.ones(3))
    with pytest.raises(TypeError, match="VectorFields"):
        solve(lambda y: y, X, np.ones(3))


def test_level2_solver_refuses_level1_driver(setup):
    V, X = setup
    for solver in (Davie(), LogODE()):
        with pytest.raises(ValueError, match="level-2 solver.*level 1"):
            solve(V, X.to_level1(), np.ones(3), solver)
    # level-1 solvers accept it
    assert solve(V, X.to_level1(), np.ones(3), Heun()).states.shape == (4, 9, 3)


def test_solver_class_and_names(setup):
    V, X = setup
    with pytest.raises(TypeError, match=r"did you mean Davie\(\)\?"):
        solve(V, X, np.ones(3), Davie)
    with pytest.raises(TypeError, match=r"did you mean LogODE\(\)\?"):
        solve(V, X, np.ones(3), LogODE)
    with pytest.raises(ValueError, match=r"unknown solver name 'milstein'.*'davie'.*'euler'.*'heun'.*'logode'"):
        solve(V, X, np.ones(3), "milstein")
    with pytest.raises(TypeError, match="Solver instance"):
        solve(V, X, np.ones(3), 3.0)
    a = solve(V, X, np.ones(3), "davie").states
    np.testing.assert_array_equal(a, solve(V, X, np.ones(3), Davie()).states)
    with pytest.raises(ValueError, match="inner_steps"):
        LogODE(inner_steps=0)


def test_non_finite_state_reports_step_and_time():
    blow = VectorFields(lambda y: (y ** 2)[..., None], lambda y: (2 * y)[..., None, :, None] * np.eye(1),
                        dim_state=1, dim_noise=1)
    times = np.linspace(0.0, 2.0, 201)
    X = RoughPath.from_path(times[:, None], times=times)            # X(t) = t: dy = y² dt blows up at t = 1
    with pytest.raises(ValueError, match=r"non-finite at step \d+ \(t = 1\.\d+"):
        solve(blow, X, np.ones(1), Euler())
    nan_field = VectorFields(lambda y: np.where(y[..., :1] > 1.505, np.nan, 1.0)[..., None],
                             dim_state=1, dim_noise=1)
    with pytest.raises(ValueError, match=r"non-finite at step 50 \(t = 0\.51"):
        solve(nan_field, X, np.ones(1), Heun())


def test_s_not_antisymmetric(setup):
    V, X = setup
    s = np.array([[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match="antisymmetric"):
        V.friz_oberhauser_drift(s)
    with pytest.raises(ValueError, match="antisymmetric"):
        VectorFields(V.fields, dim_state=3, dim_noise=2).friz_oberhauser_drift(s)
    with pytest.raises(ValueError, match=r"\(d, d\)|2x2"):
        V.friz_oberhauser_drift(np.zeros((3, 3)))


def test_malformed_fields(rng):
    with pytest.raises(TypeError, match="dim_state"):
        VectorFields(lambda y: y[..., None])
    with pytest.raises(ValueError, match=r"must return shape \(e, d\) = \(3, 2\)"):
        VectorFields(lambda y: y[..., None], dim_state=3, dim_noise=2)
    with pytest.raises(ValueError, match="batched"):
        VectorFields(lambda y: np.stack([y, y], axis=-1) if y.ndim == 1 else np.zeros(3),
                     dim_state=3, dim_noise=2)
    with pytest.raises(ValueError, match=r"jacobians\(y\)"):
        VectorFields(lambda y: np.stack([y, y], -1), lambda y: np.zeros(y.shape + (3,)),
                     dim_state=3, dim_noise=2)
    with pytest.raises(ValueError, match="list of 1 callables but dim_noise=2"):
        VectorFields([lambda y: y], dim_state=3, dim_noise=2)
    with pytest.raises(TypeError, match="callable"):
        VectorFields([lambda y: y, 3.0], dim_state=3, dim_noise=2)
    with pytest.raises(ValueError, match=r"shape \(d, e, e\)"):
        LinearVectorFields(np.zeros((2, 3, 4)))
    with pytest.raises(ValueError, match=r"drift matrix must have shape \(e, e\) = \(3, 3\)"):
        LinearVectorFields(np.zeros((2, 3, 3)), drift=np.zeros((2, 2)))
    with pytest.raises(ValueError, match="non-finite"):
        LinearVectorFields(np.full((2, 3, 3), np.nan))
    with pytest.raises(ValueError, match="field index"):
        LinearVectorFields(np.zeros((2, 3, 3))).bracket(0, 2)


def test_bad_save_at_and_y0(setup):
    V, X = setup
    with pytest.raises(ValueError, match="not a grid time"):
        solve(V, X, np.ones(3), save_at=[0.3333])
    with pytest.raises(ValueError, match="save_at"):
        solve(V, X, np.ones(3), save_at="middle")
    with pytest.raises(ValueError, match="non-finite"):
        solve(V, X, np.array([1.0, np.nan, 0.0]))
    sol = solve(V, X, np.ones(3), save_at=[0.0, 0.5, 1.0])
    assert sol.states.shape == (4, 3, 3) and np.allclose(sol.times, [0, 0.5, 1])


def test_rough_integral_bad_input(setup):
    _, X = setup
    Y = np.zeros((4, 9, 2))
    with pytest.raises(ValueError, match="level-2"):
        rough_integral(Y, np.zeros((4, 9, 2, 2)), X.to_level1())
    with pytest.raises(ValueError, match="one more axis"):
        rough_integral(Y, np.zeros((4, 9, 2)), X)
    with pytest.raises(ValueError, match="N \\+ 1 = 9"):
        rough_integral(np.zeros((4, 8, 2)), np.zeros((4, 8, 2, 2)), X)
    with pytest.raises(ValueError, match="d=2"):
        rough_integral(np.zeros((4, 9, 3)), np.zeros((4, 9, 3, 3)), X)


def test_solve_refuses_a_state_array_above_the_memory_budget(monkeypatch):
    V = LinearVectorFields(np.zeros((1, 2, 2)))
    X = RoughPath.from_increments(np.zeros((1000, 1)))
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", "10000")
    with pytest.raises(ValueError, match=r"saved states .* 1001 time\(s\) .* memory budget .*save_at='end'"):
        solve(V, X, np.ones(2), Heun())
    assert solve(V, X, np.ones(2), Heun(), save_at="end").states.shape == (1, 2)
