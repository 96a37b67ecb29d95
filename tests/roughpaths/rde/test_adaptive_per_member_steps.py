"""Adaptive steps per batch member: a member's result is bitwise the same alone or in any batch.

Claims: with ``shared_steps=False`` (the default for solvers that step members on their own times) each member's attempts, error ratios, controller state and
saved times are its own, so solving member ``i`` alone (``tree.select([i])``, its ``y0``) gives bitwise its
states, times and counts in the whole batch and in any other batch; rejected attempts leave no trace (a
member's answer is the fixed-step solve on its own accepted steps' halves); members take fewer steps than the
shared sequence, which follows the most demanding member.
"""

import numpy as np
import pytest

import roughpaths as rp

M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))


def _fields(kind):
    if kind == "linear":
        return rp.LinearVectorFields(M)
    return rp.VectorFields(lambda y: np.einsum("iab,...b->...ai", M, np.sin(y) + y),
                           dim_state=3, dim_noise=2)


def test_a_member_is_bitwise_the_same_alone_and_in_any_batch():
    y0 = 1.0 + 0.1 * np.arange(18.0).reshape(6, 3)
    for kind in ("linear", "general"):
        V, ctrl = _fields(kind), rp.PIController(1e-2, 1e-2)
        tree = rp.BrownianTree(2, seed=8, batch_shape=(6,))
        whole = rp.solve(V, tree, y0, rp.Davie(), step_control=ctrl, save_at=[0.0, 0.25, 0.5, 1.0])
        pair = rp.solve(V, tree.select([4, 2]), y0[[4, 2]], rp.Davie(), step_control=ctrl,
                        save_at=[0.0, 0.25, 0.5, 1.0])
        for i in (2, 4):
            alone = rp.solve(V, tree.select([i]), y0[i:i + 1], rp.Davie(), step_control=ctrl,
                             save_at=[0.0, 0.25, 0.5, 1.0])
            k = [4, 2].index(i)
            assert np.array_equal(alone.states[0], whole.states[i]) and np.array_equal(pair.states[k], whole.states[i])
            assert np.array_equal(alone.times, whole.times)
            for key in ("accepted", "rejected"):
                assert alone.stats[key][0] == whole.stats[key][i] == pair.stats[key][k]
        assert len(set(whole.stats["accepted"].tolist())) > 1                # the members' steps differ


def test_rejected_attempts_leave_no_trace_member_by_member():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=4, batch_shape=(3,))
    sol = rp.solve(V, tree, np.ones(3), rp.Davie(), step_control=rp.PIController(2e-2, 2e-2))
    assert sol.times.ndim == 2 and (sol.stats["rejected"] > 0).any()
    for i in range(3):
        t = np.unique(sol.times[i])                     # a shorter row repeats its last time
        assert t.size == sol.stats["accepted"][i] + 1
        grid = np.empty(2 * t.size - 1)
        grid[0::2], grid[1::2] = t, 0.5 * (t[:-1] + t[1:])
        fixed = rp.solve(V, tree.select([i]).rough_path(grid), np.ones(3), rp.Davie())
        np.testing.assert_allclose(sol.states[i, :t.size], fixed.states[0, 0::2], rtol=0, atol=1e-12)
        assert np.array_equal(sol.states[i, t.size:], np.broadcast_to(sol.states[i, t.size - 1],
                                                                      sol.states[i, t.size:].shape))


def test_members_take_fewer_steps_than_the_shared_sequence():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=5, batch_shape=(8,))
    ctrl = rp.PIController(1e-2, 1e-2)
    own = rp.solve(V, tree, np.ones(3), rp.Davie(), step_control=ctrl, save_at="end")
    shared = rp.solve(V, tree, np.ones(3), rp.Davie(), step_control=ctrl, save_at="end", shared_steps=True)
    assert own.stats["accepted"].max() <= shared.stats["accepted"]
    assert own.stats["accepted"].mean() < 0.8 * shared.stats["accepted"]


def _per_member_ladder(paths, rtols, ref_steps, seed):
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=seed, batch_shape=(paths,))
    ref = rp.solve(V, tree.rough_path(np.linspace(0.0, 1.0, ref_steps + 1)), np.ones(3), rp.Davie(),
                   save_at="end").final
    errs, steps = [], []
    for rtol in rtols:
        sol = rp.solve(V, tree, np.ones(3), rp.Davie(), step_control=rp.PIController(rtol, rtol), save_at="end")
        errs.append(float(np.sqrt(np.mean(np.sum((sol.final - ref) ** 2, axis=-1)))))
        steps.append(int(sol.stats["accepted"].max()))
    return np.polyfit(np.log(rtols), np.log(errs), 1)[0], errs, steps


def test_strong_error_per_member_is_proportional_to_rtol():
    """Each member on its own steps: the RMS over members of the strong error at t = 1 against a fine fixed-step
    solve on the same tree falls in proportion to rtol (an error-per-step rule would give 2/3). At coarser
    tolerances (rtol 1e-2, about 20 steps per member) the fit is pre-asymptotic, about 1.3."""
    slope, errs, steps = _per_member_ladder(12, [3e-3, 1.5e-3, 7.5e-4], 2 ** 13, seed=11)
    assert max(steps) * 8 <= 2 ** 13, steps
    assert 0.8 <= slope <= 1.25, (slope, errs)


@pytest.mark.slow
def test_strong_error_per_member_is_proportional_to_rtol_full():
    slope, errs, steps = _per_member_ladder(64, [3e-3, 1e-3, 3e-4], 2 ** 15, seed=12)
    assert max(steps) * 8 <= 2 ** 15, steps
    assert 0.85 <= slope <= 1.15, (slope, errs)


def test_time_dependent_fields_with_batched_time_step_members_in_one_call():
    """``batched_time=True`` fields take every member's own times at once: the same answer (to round-off of the
    user's callable) as the same fields evaluated one time at a time, member by member; a member is bitwise the
    same alone and in the batch; a callable that does not broadcast ``t`` is refused at construction."""
    def sig(t):
        return 0.2 + 2.0 * np.exp(-((t - 0.5) / 0.05) ** 2)

    def make(batched):
        ex = (lambda t: t[..., None]) if batched else (lambda t: t)
        return rp.VectorFields(lambda t, y: ex(sig(t)) * np.einsum("iab,...b->...ai", M, y),
                               lambda t, y: ex(sig(t))[..., None] * np.broadcast_to(M, y.shape[:-1] + M.shape),
                               dim_state=3, dim_noise=2, time_dependent=True, batched_time=batched)

    tree = rp.BrownianTree(2, seed=3, batch_shape=(5,))
    ctrl = rp.PIController(1e-2, 1e-2, dt_max=1 / 16)
    fast = rp.solve(make(True), tree, np.ones(3), rp.Davie(), step_control=ctrl, save_at="end")
    slow = rp.solve(make(False), tree, np.ones(3), rp.Davie(), step_control=ctrl, save_at="end", shared_steps=False)
    assert not fast.stats["shared_steps"] and not slow.stats["shared_steps"]
    assert rp.solve(make(False), tree, np.ones(3), rp.Davie(), step_control=ctrl, save_at="end").stats["shared_steps"]
    assert np.array_equal(fast.stats["accepted"], slow.stats["accepted"])
    np.testing.assert_allclose(fast.final, slow.final, rtol=1e-12, atol=0)
    alone = rp.solve(make(True), tree.select([3]), np.ones(3), rp.Davie(), step_control=ctrl, save_at="end")
    assert np.array_equal(alone.final[0], fast.final[3])
    with pytest.raises(ValueError, match="batched_time=True but failed on t of shape"):
        rp.VectorFields(lambda t, y: sig(t) * np.einsum("iab,...b->...ai", M, y), dim_state=3, dim_noise=2,
                        time_dependent=True, batched_time=True)
    with pytest.raises(ValueError, match="needs time_dependent=True"):
        rp.VectorFields(lambda y: np.einsum("iab,...b->...ai", M, y), dim_state=3, dim_noise=2, batched_time=True)
