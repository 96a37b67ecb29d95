"""The step-controller contract of ``solve``: a controller written here plugs in; fixed steps are one controller.

Claims: (1) a user-written controller that follows the numbered contract of ``StepController`` (here a step
schedule refined near t = 1/2, without error estimate) drives ``solve`` on a ``BrownianTree``, and its answer is
the fixed-step solve on the grid of its own accepted steps (an independent route: ``tree.rough_path``);
(2) ``FixedSteps(dt)`` on a tree is the fixed-step solve on the uniform grid; (3) adaptive steps are a declared
capability of the solver (``Solver.error_estimate``), not a type check; (4) objects outside the contract are
refused by name.
"""

import numpy as np
import pytest

import roughpaths as rp

M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))
Y0 = np.ones(3)


class Schedule(rp.StepController):
    """Steps of length ``h(t) = 1/64 + |t - 1/2| / 8``: short near t = 1/2, no error estimate."""

    def init(self, t0, t1, lanes, error_order):
        return {"h": np.full(lanes, self.h(t0))}

    @staticmethod
    def h(t):
        return 1 / 64 + np.abs(t - 0.5) / 8

    def adapt(self, state, t, h, r):
        assert r is None                                  # no error estimate is computed for it
        state["h"] = self.h(t + h)
        return np.ones(np.shape(h), dtype=bool)


def test_a_user_step_schedule_plugs_in_and_is_the_fixed_step_solve_on_its_steps():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=7, batch_shape=(4,))
    sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=Schedule(), shared_steps=True)
    t = sol.times
    assert t[0] == 0.0 and t[-1] == 1.0 and sol.stats["rejected"] == 0
    h, mid = np.diff(t), 0.5 * (t[:-1] + t[1:])
    assert np.all(h <= Schedule.h(t[:-1]) * (1 + 1 / 16) + 1e-12)       # ends snapped by at most 1/16
    assert h[np.abs(mid - 0.5) < 0.05].max() < 0.5 * h[np.abs(mid - 0.5) > 0.4].min()
    fixed = rp.solve(V, rp.BrownianTree(2, seed=7, batch_shape=(4,)).rough_path(t), Y0, rp.Davie())
    np.testing.assert_allclose(sol.states, fixed.states, rtol=0, atol=1e-13)
    # per member (the default), every member takes the schedule's steps: the same times for all
    own = rp.solve(V, tree, Y0, rp.Davie(), step_control=Schedule())
    assert own.times.shape == (4, t.size) and np.array_equal(own.times, np.broadcast_to(t, (4, t.size)))
    np.testing.assert_allclose(own.states, sol.states, rtol=0, atol=1e-13)


def test_fixed_steps_on_a_tree_is_the_uniform_grid_solve():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=2, batch_shape=(3,))
    sol = rp.solve(V, tree, Y0, rp.LogODE(), step_control=rp.FixedSteps(1 / 16), save_at="end")
    ref = rp.solve(V, tree.rough_path(np.linspace(0.0, 1.0, 17)), Y0, rp.LogODE(), save_at="end")
    np.testing.assert_allclose(sol.final, ref.final, rtol=0, atol=1e-13)
    assert sol.stats["accepted"].tolist() == [16, 16, 16]
    # on a grid driver FixedSteps() is the default controller: the grid's own steps, bitwise
    X = tree.rough_path(np.linspace(0.0, 1.0, 9))
    a = rp.solve(V, X, Y0, rp.Davie())
    b = rp.solve(V, X, Y0, rp.Davie(), step_control=rp.FixedSteps())
    assert np.array_equal(a.states, b.states)


def test_adaptive_steps_are_a_declared_capability():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0)
    ctrl = rp.PIController(1e-2, 1e-2)

    class NoEstimate(rp.Davie):
        error_estimate = None

    class Declared(rp.Solver):                           # a user's order-1 scheme: Davie's step, declared data
        increment_level, order = 2, 1.0
        step = rp.Davie.step
        _linear_step = staticmethod(rp.Davie._linear_step)

    for solver in (rp.Euler(), rp.Heun(), NoEstimate()):
        with pytest.raises(ValueError, match="error_estimate=None"):
            rp.solve(V, tree, Y0, solver, step_control=ctrl)
    assert rp.Heun().error_estimate is None and rp.Davie().error_estimate == "step_doubling"
    # without an estimate, a schedule still drives a level-1 solver
    heun = rp.solve(V, tree, Y0, rp.Heun(), step_control=rp.FixedSteps(0.25), save_at="end")
    assert heun.final.shape == (3,)
    a = rp.solve(V, tree, Y0, Declared(), step_control=ctrl, save_at="end")
    b = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, save_at="end")
    # the same scheme by two routes (Davie's own takes the members' times in one call): equal to round-off,
    # not bitwise (the routes' array products may run other vector kernels on another CPU)
    np.testing.assert_allclose(a.final, b.final, rtol=1e-12, atol=0)
    assert a.stats["accepted"] == b.stats["accepted"]


def test_objects_outside_the_contract_are_refused_by_name():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0)
    with pytest.raises(TypeError, match="StepController contract"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=object())
    with pytest.raises(ValueError, match="FixedSteps\\(dt=...\\)"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.FixedSteps())
    with pytest.raises(ValueError, match="dt must be"):
        rp.FixedSteps(-1.0)
    with pytest.raises(ValueError, match="no grid"):
        next(tree.blocks())


def test_a_controller_error_ratio_of_the_wrong_size_is_refused_by_name():
    """The loop keeps one error ratio per member (compiled, no bounds checks): a user's ``error_ratio`` returning
    another number of ratios is refused naming the controller; one ratio for all members is taken for each."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])

    class TwoRatios(rp.PIController):
        def error_ratio(self, y, y_new, y_err, h, span):
            return np.zeros(2)

    class OneRatio(rp.PIController):
        def error_ratio(self, y, y_new, y_err, h, span):
            return 0.5

    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    with pytest.raises(ValueError, match=r"TwoRatios\.error_ratio's result has 2 entries for 3 lane\(s\) or member"):
        rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=TwoRatios(1e-2, 1e-2))
    sol = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=OneRatio(1e-2, 1e-2),
                   save_at="end")
    assert np.isfinite(sol.final).all() and (sol.stats["rejected"] == 0).all()


def test_pi_adapt_refuses_arrays_that_do_not_match_its_state():
    """``PIController.adapt`` updates the state's arrays in place (compiled): a step or ratio array of another
    length than the state's lanes is refused, naming both sizes, instead of writing past the state."""
    ctl = rp.PIController(1e-2, 1e-2)
    state = ctl.init(0.0, 1.0, 3, 1.0)
    with pytest.raises(ValueError, match=r"one error ratio r per lane of the state \(3\), got 3 and 5"):
        ctl.adapt(state, np.zeros(3), np.full(3, 0.1), np.ones(5))
    accept = ctl.adapt(state, np.zeros(3), np.full(3, 0.1), np.array([0.5, 2.0, np.nan]))
    assert accept.tolist() == [True, False, False]
    assert state["h"][0] > 0.1 and state["h"][1] < 0.1 and state["h"][2] == 0.1 * ctl.factor_min


def test_a_user_controller_may_answer_with_one_step_and_one_verdict_for_all_lanes():
    """A controller whose state holds one step (a float) and whose ``adapt`` returns one ``True`` for all lanes plugs in
    as numpy broadcasting took it (the compiled bookkeeping gets them repeated per lane); a state step of another
    count than the lanes is refused naming the controller."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])

    class Eighths(rp.StepController):
        def init(self, t0, t1, lanes, error_order):
            return {"h": 0.125}

        def adapt(self, state, t, h, r):
            return True

    class FiveSteps(Eighths):
        def init(self, t0, t1, lanes, error_order):
            return {"h": np.full(lanes + 2, 0.125)}

    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    sol = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=Eighths())
    assert sol.stats["accepted"].tolist() == [8, 8, 8] and (sol.times == np.arange(9) / 8).all()
    fixed = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=rp.FixedSteps(0.125))
    np.testing.assert_array_equal(sol.states, fixed.states)
    with pytest.raises(ValueError, match=r'state\["h"\] \(FiveSteps\) has 5 entries for 3 lane'):
        rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=FiveSteps())


@pytest.mark.parametrize("step", [0.0, -0.125, np.nan, np.inf])
@pytest.mark.parametrize("when", ["init", "adapt"])
def test_a_step_that_is_not_a_positive_finite_number_is_refused_by_name(step, when):
    """A controller's ``state["h"]`` must hold finite steps > 0 (contract item 2 and 4): a step of 0 divided by
    zero, and a negative, NaN or infinite step passed through the snapping as one step straight to t1
    (``accepted == 1``, a silent answer on a step the controller never proposed)."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])

    class Broken(rp.StepController):
        def init(self, t0, t1, lanes, error_order):
            return {"h": np.full(lanes, step if when == "init" else 0.125)}

        def adapt(self, state, t, h, r):
            state["h"] = np.where(t + h >= 0.5, step, 0.125)      # goes wrong from t = 1/2 on
            return np.ones(np.shape(h), dtype=bool)

    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    for shared in (False, True):
        with pytest.raises(ValueError, match=r'state\["h"\] \(Broken\) holds the step .* finite number > 0'):
            rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=Broken(),
                     shared_steps=shared, save_at="end")


@pytest.mark.parametrize("attr, value", [("dt_min", np.nan), ("dt_min", np.inf), ("dt_min", -1.0), ("dt_min", "0.1"),
                                         ("max_steps", None), ("max_steps", 2.5), ("max_steps", 0), ("max_steps", -1)])
def test_a_controllers_dt_min_and_max_steps_outside_the_contract_are_refused_by_name(attr, value):
    """Contract item 5: ``dt_min(span)`` a finite step >= 0, ``max_steps`` an integer >= 1. A NaN or infinite
    dt_min raised numpy's 'cannot convert float NaN to integer'; max_steps=None a bare TypeError, and 0, -1 or
    2.5 stopped the solve with 'took 0 attempts' (or 2.5) instead of naming the bad value."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])

    class Odd(rp.StepController):
        max_steps = value if attr == "max_steps" else 100

        def init(self, t0, t1, lanes, error_order):
            return {"h": np.full(lanes, 0.125)}

        def adapt(self, state, t, h, r):
            return np.ones(np.shape(h), dtype=bool)

        def dt_min(self, span):
            return value if attr == "dt_min" else 0.0

    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    with pytest.raises(ValueError, match=rf"Odd\.{attr}.*{attr}|Odd\.{attr}.*contract item 5"):
        rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=Odd(), save_at="end")
    ok = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=rp.FixedSteps(0.125),
                  save_at="end")                           # the same schedule within the contract runs
    assert ok.stats["accepted"].tolist() == [8, 8, 8]


def test_fixed_steps_finer_than_a_coarse_trees_grid_are_refused_not_rounded():
    """FixedSteps(dt) on a tree of resolution L steps ``dt`` (docs: step ends move by at most 1/16); on a coarse
    tree (L = 4, cells of 1/16) dt = 0.1 came out as steps of 0.125 and dt = 0.05 as steps of 2 cells, silently.
    Such steps are refused naming the resolution that resolves them; that resolution then gives steps of dt."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    V = rp.LinearVectorFields(M)
    for dt in (0.1, 0.05):
        with pytest.raises(ValueError, match=r"shorter than 8 cells.*resolution=\d+"):
            rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,), resolution=4), np.ones(2), rp.Davie(),
                     step_control=rp.FixedSteps(dt))
    sol = rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,), resolution=8), np.ones(2), rp.Davie(),
                   step_control=rp.FixedSteps(0.1), shared_steps=True)
    h = np.diff(sol.times)
    assert sol.times[-1] == 1.0 and np.all(np.abs(h[:-1] - 0.1) <= 0.1 / 16) and h.size == 10


def test_an_unmet_tolerance_on_a_coarse_tree_names_the_resolution_not_dt_min():
    """On a coarse tree the shortest step is 2 cells of its grid, far above dt_min; the failure said 'at
    dt_min = 0.0312' (the step, not dt_min) and advised lowering dt_min, which changes nothing. It now names the
    tree's resolution; with the default resolution the message still points at dt_min."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    V = rp.LinearVectorFields(M)
    control = rp.PIController(1e-4, 1e-4)
    with pytest.raises(ValueError, match=r"2 cells of \(t1 - t0\)·2\^-6.*higher resolution \(now 6") as info:
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,), resolution=6), np.ones(2), rp.Davie(),
                 step_control=control)
    assert "lower dt_min" not in str(info.value)
    with pytest.raises(ValueError, match=r"at dt_min = .*lower dt_min"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), np.ones(2), rp.Davie(),
                 step_control=rp.PIController(1e-14, 1e-14))


def test_dt_max_below_the_default_dt_min_is_honoured_and_dt_min_above_dt_max_refused():
    """On a long interval the default dt_min, (t1 - t0)·2^-30, exceeds a small dt_max: the steps were held at
    dt_min (9.3e-5 for t1 - t0 = 1e5), silently ten times the dt_max=1e-5 asked for. The default dt_min is now
    at most dt_max, and the steps follow dt_max (within the snapping's 1/16 with shared steps); a dt_min above
    dt_max on the tree's interval (e.g. above t1 - t0) is refused by name."""
    ctrl = rp.PIController(1e-1, 1e-1, dt_max=1e-5)
    assert ctrl.dt_min(1e5) <= ctrl.dt_max(1e5) == 1e-5
    M = 1e-3 * np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0, batch_shape=(2,), t1=2.0 ** -10, resolution=50)
    sol = rp.solve(V, tree, np.ones(2), rp.Davie(), shared_steps=True,
                   step_control=rp.PIController(1e-1, 1e-1, dt_max=2.0 ** -17, dt_min=2.0 ** -40))
    assert np.diff(sol.times).max() <= 2.0 ** -17 * (1 + 1 / 16) and sol.stats["accepted"] >= 2 ** 7
    with pytest.raises(ValueError, match=r"dt_min\(1\.0\) = 2\.0 exceeds dt_max\(1\.0\) = 1\.0"):
        rp.solve(V, rp.BrownianTree(2, seed=0), np.ones(2), rp.Davie(),
                 step_control=rp.PIController(1e-2, 1e-2, dt_min=2.0))


def test_steps_that_cannot_reach_t1_within_max_steps_are_refused_at_once():
    """A dt_max (or a FixedSteps dt) that needs more than max_steps steps to reach t1 crawled through all
    max_steps attempts (8 s for dt_max=1e-14 or FixedSteps(1e-9) on [0, 1]) and then blamed the tolerance ('loosen
    rtol/atol'); a dt_max below the tree's shortest step (2 cells of its grid) was exceeded silently. All three are
    refused before the first step, naming the argument and the fix."""
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0, batch_shape=(2,), t1=1e5)
    with pytest.raises(ValueError, match=r"dt_max\(100000\.0\) = 1e-05 needs at least 1e\+10 steps .* more than "
                                         r"max_steps = 20 .* raise dt_max or max_steps"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(1e-1, 1e-1, dt_max=1e-5, max_steps=20))
    with pytest.raises(ValueError, match=r"FixedSteps\(dt=1e-09\) needs 1e\+09 steps .* driver=tree\.rough_path"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(), step_control=rp.FixedSteps(1e-9))
    with pytest.raises(ValueError, match=r"dt_max\(1\.0\) = 1e-13 is shorter than the shortest step of the tree's "
                                         r"grid.*resolution=45 or more"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(),
                 step_control=rp.PIController(1e-1, 1e-1, dt_max=1e-13, dt_min=1e-14, max_steps=10 ** 14))


def test_running_out_of_attempts_names_the_member_that_did_not_reach_t1():
    """Per member, member 0 reaches t1 in exactly max_steps = 8 steps of 1/8 (allowed) and member 1, on steps
    of 1/16, runs out at t = 1/2. The message named the lane with the most attempts, member 0: 'reached t = 1 of
    [0.0, 1.0]'; it now names member 1 and t = 0.5."""
    M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])

    class TwoPaces(rp.StepController):
        max_steps = 8

        def init(self, t0, t1, lanes, error_order):
            return {"h": np.array([1 / 8, 1 / 16])}

        def adapt(self, state, t, h, r):
            return np.ones(np.shape(h), dtype=bool)

    with pytest.raises(ValueError, match=r"took 8 attempts and reached t = 0\.5 of \[0\.0, 1\.0\] for batch member \(1,\)"):
        rp.solve(rp.LinearVectorFields(M), rp.BrownianTree(2, seed=0, batch_shape=(2,)), np.ones(2), rp.Davie(),
                 step_control=TwoPaces(), shared_steps=False)


@pytest.mark.parametrize("value", ["no", "False", 0, 2, [True]])
def test_shared_steps_other_than_a_bool_or_none_is_refused(value):
    """shared_steps was read as bool(shared_steps): "no" and "False" gave shared steps, 0 per-member steps,
    silently. It must be True, False or None."""
    V = rp.LinearVectorFields(M)
    with pytest.raises(TypeError, match=r"shared_steps must be True, False or None .*, got"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(),
                 step_control=rp.PIController(1e-2, 1e-2), shared_steps=value, save_at="end")
    for ok in (True, False, np.bool_(True)):
        sol = rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(),
                       step_control=rp.PIController(1e-2, 1e-2), shared_steps=ok, save_at="end")
        assert sol.stats["shared_steps"] is bool(ok)


def test_an_adaptive_controller_whose_error_ratio_returns_none_is_refused():
    """An adaptive controller's error_ratio that returns None (a missing return) was taken for 'no estimate':
    every attempt was accepted at zero error and the steps grew by factor_max to t1 (4 steps), silently."""
    class Forgetful(rp.PIController):
        def error_ratio(self, y, y_new, y_err, h, span):
            super().error_ratio(y, y_new, y_err, h, span)          # computed, not returned

    V = rp.LinearVectorFields(M)
    for shared in (False, True):
        with pytest.raises(TypeError, match=r"Forgetful\.error_ratio returned None"):
            rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(),
                     step_control=Forgetful(1e-2, 1e-2), shared_steps=shared)


def test_a_controller_whose_adapt_returns_none_is_refused():
    """adapt returning None (a missing return) became np.asarray(None, bool) == False: every attempt rejected until
    max_steps, then 'took 1000 attempts ... loosen rtol/atol', which misnames the fault."""
    class NoVerdict(rp.StepController):
        max_steps = 1000

        def init(self, t0, t1, lanes, error_order):
            return {"h": np.full(lanes, 0.125)}

        def adapt(self, state, t, h, r):
            state["h"] = h

    V = rp.LinearVectorFields(M)
    with pytest.raises(TypeError, match=r"NoVerdict\.adapt returned None"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(), step_control=NoVerdict())


@pytest.mark.parametrize("state", [None, {"step": 0.125}, [0.125]])
def test_a_controller_whose_init_returns_no_state_with_h_is_refused(state):
    """init must return a dict holding 'h' (contract item 2); None or a dict without 'h' raised a bare TypeError
    ('NoneType' object is not subscriptable) or KeyError: 'h' from inside the loop."""
    class NoState(rp.StepController):
        def init(self, t0, t1, lanes, error_order):
            return state

        def adapt(self, state, t, h, r):
            return np.ones(np.shape(h), dtype=bool)

    V = rp.LinearVectorFields(M)
    with pytest.raises(TypeError, match=r"NoState\.init returned .*contract item 2"):
        rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(), step_control=NoState())
