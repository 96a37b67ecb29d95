"""Adaptive steps on a Brownian tree: strong order 1 in the tolerance, no bias from rejections.

Theorem checked (numerically), with the steps shared by the batch (``shared_steps=True``; steps per member in
``test_adaptive_per_member_steps.py``): with ``PIController(rtol, atol)`` bounding the predicted global error
``sqrt(T/h)·|y_2 - y_1|`` (step doubling), an order-1 scheme on non-commuting noise has strong error
proportional to the tolerance. The reference is a fine *fixed-step* solve on the *same* tree (same Brownian
path), so the error measured is the scheme's, not a difference of paths. An error-per-step rule would give a
slope of 2/3; the fit must lie near 1.
"""

import numpy as np
import pytest

import roughpaths as rp

M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))       # non-commuting
Y0 = np.ones(3)


def _rms(a, b):
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


def _order_ladder(paths, rtols, ref_steps, seed):
    V = rp.LinearVectorFields(M)
    assert np.abs(M[0] @ M[1] - M[1] @ M[0]).max() > 0.05
    tree = rp.BrownianTree(2, seed=seed, batch_shape=(paths,))
    ref = rp.solve(V, tree.rough_path(np.linspace(0.0, 1.0, ref_steps + 1)), Y0, rp.Davie(), save_at="end").final
    errs, steps = [], []
    for rtol in rtols:
        sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(rtol, rtol), save_at="end",
                       shared_steps=True)
        errs.append(_rms(sol.final, ref))
        steps.append(int(np.max(sol.stats["accepted"])))
    slope = np.polyfit(np.log(rtols), np.log(errs), 1)[0]
    return slope, errs, steps


def test_strong_error_is_proportional_to_rtol():
    slope, errs, steps = _order_ladder(32, [1e-1, 3e-2, 1e-2], 2 ** 12, seed=11)
    assert max(steps) * 8 <= 2 ** 12, steps                   # the reference is much finer than any solve
    assert 0.8 <= slope <= 1.25, (slope, errs)
    assert errs[-1] < 5e-2 * 1.0


@pytest.mark.slow
def test_strong_error_is_proportional_to_rtol_full():
    slope, errs, steps = _order_ladder(128, [1e-1, 3e-2, 1e-2, 3e-3, 1e-3], 2 ** 15, seed=12)
    assert max(steps) * 8 <= 2 ** 15, steps
    assert 0.85 <= slope <= 1.15, (slope, errs)


def test_the_whole_step_is_the_trees_answer_on_the_whole_interval():
    """The error estimate's one-step attempt sees the same path as its two halves: the Chen product of the
    halves' increments and areas equals the tree's own answer on the whole interval (a transposed or missing
    cross term X_1 ⊗ X_2, or a lost ½ in the areas, would not)."""
    from roughpaths.rde._attempts import _doubling_nb

    tree = rp.BrownianTree(3, seed=6, batch_shape=(4,))
    a, b = 0.15625, 0.40625
    ts = np.array([a, 0.5 * (a + b), b])
    W, A = tree.increments_and_levy_areas(ts)
    halves = (W, A + 0.5 * W[..., :, None] * W[..., None, :])        # Stratonovich areas of the halves
    out = [np.empty(s) for s in ((8, 2), (8, 1), (8, 1), (8, 3), (8, 3, 3))]
    _doubling_nb(np.zeros((4, 2)), np.tile(ts, (4, 1)), *halves, *out)
    Ww, XXw = out[3][4:, None], out[4][4:, None]                      # rows n: are the whole steps
    W_ref, A_ref = tree.increments_and_levy_areas([a, b])
    XX_ref = A_ref + 0.5 * W_ref[..., :, None] * W_ref[..., None, :]          # Stratonovich: Lévy area + ½ W⊗W
    np.testing.assert_allclose(Ww, W_ref, rtol=0, atol=1e-14)
    np.testing.assert_allclose(XXw, XX_ref, rtol=0, atol=1e-14)
    assert np.abs(A_ref).max() > 1e-3                                    # a genuine area to get right


def test_accepted_path_is_the_trees_path():
    """Rejected attempts leave no trace: the adaptive answer is a fixed-step solve on the accepted steps' halves."""
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=4, batch_shape=(5,))
    sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(2e-2, 2e-2), shared_steps=True)
    assert sol.stats["rejected"] > 0 and sol.stats["accepted"] == sol.times.size - 1
    t = sol.times
    grid = np.empty(2 * t.size - 1)
    grid[0::2] = t
    grid[1::2] = 0.5 * (t[:-1] + t[1:])
    fixed = rp.solve(V, rp.BrownianTree(2, seed=4, batch_shape=(5,)).rough_path(grid), Y0, rp.Davie())
    np.testing.assert_allclose(sol.states, fixed.states[:, 0::2], rtol=0, atol=1e-12)


def test_answers_do_not_depend_on_earlier_queries():
    V = rp.LinearVectorFields(M)
    ctrl = rp.PIController(3e-2, 3e-2)
    a = rp.solve(V, rp.BrownianTree(2, seed=9, batch_shape=(3,)), Y0, rp.Davie(), step_control=ctrl)
    tree = rp.BrownianTree(2, seed=9, batch_shape=(3,))
    tree.area(0.123, 0.777)
    tree.rough_path(np.linspace(0.0, 1.0, 7))
    b = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl)
    c = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl)
    assert np.array_equal(a.states, b.states) and np.array_equal(b.states, c.states)
    assert np.array_equal(a.times, b.times)


def test_save_at_times_are_hit_and_logode_runs():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=2, batch_shape=(4,))
    save = [0.0, 0.3, 0.71, 1.0]
    sol = rp.solve(V, tree, Y0, rp.LogODE(), step_control=rp.PIController(1e-2, 1e-2), save_at=save)
    np.testing.assert_allclose(sol.times, save, atol=1e-12)
    assert sol.states.shape == (4, 4, 3)
    np.testing.assert_array_equal(sol.states[:, 0], np.broadcast_to(Y0, (4, 3)))
    end = rp.solve(V, tree, Y0, rp.LogODE(), step_control=rp.PIController(1e-2, 1e-2), save_at="end")
    assert end.times.tolist() == [1.0] and end.states.shape == (4, 1, 3)


def test_time_dependent_burst_gets_small_steps():
    """Steps shrink where the noise bursts: the accepted steps inside the burst are much shorter than outside."""
    def sig(t):
        return 0.2 + 2.0 * np.exp(-((t - 0.5) / 0.03) ** 2)

    V = rp.VectorFields(lambda t, y: sig(t) * np.einsum("iab,...b->...ai", M, y),
                        lambda t, y: np.broadcast_to(sig(t) * M, y.shape[:-1] + M.shape),
                        dim_state=3, dim_noise=2, time_dependent=True)
    tree = rp.BrownianTree(2, seed=1, batch_shape=(8,))
    sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(1e-2, 1e-2, dt_max=1 / 32),
                   shared_steps=True)
    h = np.diff(sol.times)
    mid = 0.5 * (sol.times[:-1] + sol.times[1:])
    inside, outside = h[np.abs(mid - 0.5) < 0.03], h[np.abs(mid - 0.5) > 0.2]
    assert inside.size and outside.size
    assert np.median(inside) * 4 < np.median(outside)


def test_non_finite_members_are_reported_or_masked():
    V = rp.VectorFields(lambda y: np.stack([y ** 3, 0.0 * y], axis=-1),            # V_1 = y³, V_2 = 0
                        lambda y: np.stack([3 * y ** 2, 0.0 * y], axis=-2)[..., None],
                        dim_state=1, dim_noise=2)
    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    y0 = np.array([[0.1], [40.0], [0.2]])
    ctrl = rp.PIController(1e-1, 1e-1, dt_min=2.0 ** -12)
    # member 1 blows up; at dt_min its error exceeds the tolerance before it is non-finite: it fails either way
    with pytest.raises(ValueError, match=r"member.*\(1,\)") as info:
        rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl)
    assert getattr(info.value, "members", ((1,),)) == ((1,),)
    sol = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, on_failure="mask")
    assert sol.failed.tolist() == [False, True, False]
    assert np.all(np.isfinite(sol.final[[0, 2]])) and np.isnan(sol.final[1]).all()


def test_a_member_non_finite_on_an_accepted_step_is_reported_at_that_step():
    """Fixed steps on the tree accept every attempt, so a member that overflows is accepted non-finite: the error
    names the member, its step and the step's times (those of the attempt, not of the next one); masked, its
    states are NaN from that step on and the other members are what they are alone, bitwise."""
    V = rp.VectorFields(lambda y: np.stack([y ** 3, 0.0 * y], axis=-1),
                        lambda y: np.stack([3 * y ** 2, 0.0 * y], axis=-2)[..., None], dim_state=1, dim_noise=2)
    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    y0 = np.array([[0.1], [40.0], [0.2]])
    ctrl = rp.FixedSteps(1 / 64)
    with pytest.raises(rp.NonFiniteStateError, match=r"step 3 \(t = 0\.0625, step from t = 0\.046875\) for batch "
                                                     r"member \(1,\)"):
        rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl)
    sol = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, on_failure="mask")
    assert sol.failed_step.tolist() == [-1, 3, -1] and sol.stats["accepted"].tolist() == [64, 4, 64]
    assert np.isfinite(sol.states[1, :4]).all() and np.isnan(sol.states[1, 4:]).all()
    assert sol.times[1, 4] == 0.0625 and np.all(sol.times[1, 5:] == 1.0)     # stopped: NaN at t1, no more steps
    for k in (0, 2):
        alone = rp.solve(V, tree.select([k]), y0[k], rp.Davie(), step_control=ctrl)
        np.testing.assert_array_equal(sol.states[k], alone.states[0])


def test_a_masked_member_stops_at_its_failure_and_is_nan_at_the_save_times_left():
    """With steps per member, a member masked at its failure takes no more steps: its accepted steps end with the
    failing one, its states are NaN at the save times after it (t1 with save_at='all'), and the other members are
    what they are alone, bitwise (before, it went on stepping NaN states to t1, counted as accepted steps)."""
    V = rp.VectorFields(lambda y: np.stack([y ** 2, 0.1 * y], axis=-1),               # V_1 = y², V_2 = y / 10
                        lambda y: np.stack([2 * y, np.full_like(y, 0.1)], axis=-2)[..., None], dim_state=1, dim_noise=2)
    tree = rp.BrownianTree(2, seed=3, batch_shape=(3,))
    y0 = np.array([[0.1], [30.0], [0.2]])
    ctrl = rp.PIController(1e-2, 1e-2)
    sol = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, on_failure="mask")
    k = int(sol.failed_step[1])
    assert k > 0 and sol.failed_step[[0, 2]].tolist() == [-1, -1]
    assert sol.stats["accepted"][1] == k + 1
    assert np.isfinite(sol.states[1, :k + 1]).all() and np.isnan(sol.states[1, k + 1:]).all()
    assert sol.times[1, k + 1] < 0.01 and np.all(sol.times[1, k + 2:] == 1.0)
    for j in (0, 2):
        alone = rp.solve(V, tree.select([j]), y0[j], rp.Davie(), step_control=ctrl)
        K = alone.times.shape[-1]
        assert np.array_equal(sol.times[j, :K], alone.times[0]) and np.array_equal(sol.states[j, :K], alone.states[0])
    at = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, on_failure="mask", save_at=[0.0, 0.5, 1.0])
    assert at.stats["accepted"][1] == k + 1
    np.testing.assert_array_equal(at.times, [0.0, 0.5, 1.0])
    assert at.states[1, 0, 0] == 30.0 and np.isnan(at.states[1, 1:]).all() and np.isfinite(at.states[[0, 2]]).all()


def test_bad_input_names_the_fix():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0)
    ctrl = rp.PIController(1e-2, 1e-2)
    with pytest.raises(ValueError, match="step_control=PIController"):
        rp.solve(V, tree, Y0, rp.Davie())
    X = tree.rough_path([0.0, 0.5, 1.0])
    with pytest.raises(ValueError, match="BrownianTree"):
        rp.solve(V, X, Y0, rp.Davie(), step_control=ctrl)
    with pytest.raises(ValueError, match="order-1"):
        rp.solve(V, tree, Y0, rp.Euler(), step_control=ctrl)
    with pytest.raises(TypeError, match="PIController"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=1e-3)
    with pytest.raises(ValueError, match="max_steps"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(1e-6, 0.0, max_steps=20))
    with pytest.raises(ValueError, match="lie in the tree"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, save_at=[0.5, 1.5])
    with pytest.raises(ValueError, match="executor"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, executor=object())
    with pytest.raises(ValueError, match="both 0"):
        rp.PIController(0.0, 0.0)
    with pytest.raises(ValueError, match="factor_min"):
        rp.PIController(1e-3, 1e-3, factor_min=2.0)
    with pytest.raises(ValueError, match="dt_min"):
        rp.PIController(1e-3, 1e-3, dt_min=0.5, dt_max=0.1)


def test_an_unreachable_tolerance_fails_fast_and_names_the_fix():
    """At dt_min a step whose error exceeds the tolerance is a failure, never accepted: PIController(1e-300, 0)
    raises after a bounded number of attempts (the steps shrink by factor_min down to dt_min), naming the fix;
    with on_failure='mask' every member is marked failed and its states are NaN from that step on."""
    import time

    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0, batch_shape=(3,))
    ctrl = rp.PIController(1e-300, 0.0)
    t0 = time.process_time()
    with pytest.raises(ValueError, match=r"cannot be met.*loosen rtol/atol.*dt_min.*on_failure='mask'"):
        rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl)
    sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, on_failure="mask", save_at=[0.0, 0.5, 1.0])
    assert time.process_time() - t0 < 1.0
    assert sol.failed.all() and np.sum(sol.stats["at_dt_min"]) == 3
    assert np.max(sol.stats["accepted"] + sol.stats["rejected"]) < 200
    np.testing.assert_array_equal(sol.times, [0.0, 0.5, 1.0])
    assert np.array_equal(sol.states[:, 0], np.ones((3, 3))) and np.isnan(sol.states[:, 1:]).all()


def test_a_member_that_misses_the_tolerance_at_dt_min_is_masked_alone():
    """Only the member whose error exceeds the tolerance at dt_min fails; the others finish (with rtol = 0 the error of a member of size 10⁶ is 10⁶ times that of a member of size 1)."""
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=1, batch_shape=(3,))
    y0 = np.array([[1.0] * 3, [1e6] * 3, [1.0] * 3])
    ctrl = rp.PIController(0.0, 1e-2, dt_min=2.0 ** -12)
    with pytest.raises(ValueError, match=r"1 batch member\(s\) \(first \(1,\)\)"):
        rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, save_at="end")
    sol = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, save_at="end", on_failure="mask")
    assert sol.failed.tolist() == [False, True, False] and sol.stats["at_dt_min"].tolist() == [0, 1, 0]
    assert np.all(np.isfinite(sol.final[[0, 2]])) and np.isnan(sol.final[1]).all()


@pytest.mark.parametrize("batch", [(0,), (2, 0)])
@pytest.mark.parametrize("shared", [None, True, False])
@pytest.mark.parametrize("control", [rp.PIController(1e-2, 1e-2), rp.FixedSteps(0.125)])
def test_an_empty_batch_axis_solves_to_empty_states(batch, shared, control):
    """A tree (or y0) with an empty batch axis is a batch of no members: empty states at the times asked, as the
    grid solve of the same tree gives them (the first attempt indexed the missing member: IndexError)."""
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=0, batch_shape=batch, t0=1.0, t1=3.0)
    for save_at, times in (("end", [3.0]), ([1.5, 2.0, 3.0], [1.5, 2.0, 3.0]), ("all", [1.0, 3.0])):
        sol = rp.solve(V, tree, np.ones(3), rp.Davie(), step_control=control, shared_steps=shared, save_at=save_at)
        grid = rp.solve(V, tree.rough_path(np.array(times if len(times) > 1 else [1.0, 3.0])), np.ones(3), rp.Davie(),
                        save_at=save_at if save_at != "all" else "all")
        assert sol.times.tolist() == times and grid.states.shape[-2] == len(times)
        assert sol.states.shape == grid.states.shape == batch + (len(times), 3)
        assert sol.failed_step.shape == batch
    sol = rp.solve(V, rp.BrownianTree(2, seed=0), np.ones(batch + (3,)), rp.Davie(), step_control=control,
                   save_at="end")                                   # the empty axis from y0
    assert sol.states.shape == batch + (1, 3) and sol.times.tolist() == [1.0]
