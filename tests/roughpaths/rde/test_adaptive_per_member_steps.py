"""Adaptive steps per batch member: a member's result is bitwise the same alone or in any batch.

Claims: with ``shared_steps=False`` (the default) each member's attempts, error ratios, controller state and
saved times are its own, so solving member ``i`` alone (``tree.select([i])``, its ``y0``) gives bitwise its
states, times and counts in the whole batch and in any other batch; rejected attempts leave no trace (a
member's answer is the fixed-step solve on its own accepted steps' halves); members take fewer steps than the
shared sequence, which follows the most demanding member.
"""

import numpy as np

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
