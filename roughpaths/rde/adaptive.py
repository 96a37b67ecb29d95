r"""Steps on a driver that answers on any times (a :class:`~roughpaths.BrownianTree`): the attempts of :func:`~roughpaths.solve`.

``solve(fields, tree, y0, solver, step_control=PIController(rtol, atol))`` integrates on ``[tree.t0,
tree.t1]`` with steps chosen by the controller (:mod:`roughpaths.rde.step_control`). The tree answers the
increment and area on any interval, so a rejected step asks the same tree again on a shorter interval: the
Brownian path is fixed by the seed, and rejection introduces no bias (no resampling, no conditioning on the
rejection).

Lanes
-----
With ``shared_steps=False`` every batch member is a *lane* with steps of its own (its attempts, error ratio,
controller state and saved times are its own), so a member's result is bitwise the same alone or in any
batch. With ``shared_steps=True`` the batch is one lane: the error ratio is the maximum over its healthy
members and all take the same steps (``Solution.times`` then has one axis). The default is per member when
the solver takes every member on its own times in one call (``Solver.member_times``, fields autonomous or
``batched_time``), shared otherwise. Per member, the tree answers all lanes in one compiled walk
(:mod:`roughpaths.drivers._tree_members`); a solver without ``member_times`` is called once per group of
lanes on the same interval. The loop's own work per iteration (snapping the step ends, stacking step doubling's
inputs, reducing error ratios over lanes, advancing the lanes) is compiled elementwise over lanes and members
(:mod:`roughpaths.rde._attempts`), so it costs a few kernel calls, not some seventy numpy calls.

The error estimate (step doubling)
----------------------------------
For ``Solver.error_estimate == "step_doubling"`` an attempt on ``[t, t + h]`` takes one step of the solver
over the whole interval, ``y_1``, and two over its halves, ``y_2``, with the increments and areas of the
same tree (the whole step's are the Chen product of the halves', so both see the same path). The local
error of an order-1 scheme on non-commuting noise is its missing level-3 term, of size :math:`h^{3/2}`;
``y_2 - y_1`` is of that size and estimates it. The two-step value ``y_2`` is kept. The controller turns it
into an error ratio (:meth:`~roughpaths.PIController.error_ratio`: an RMS over the ``e`` components, times
:math:`\sqrt{T/h}`, the predicted global error, since random local errors add in mean square), so the
strong error of an order-1 scheme is proportional to ``rtol`` (an error-per-step rule would give
``rtol^(2/3)``). A controller without estimate (``adaptive = False``) gets one solver step per attempt.

The step ends
-------------
Step ends are snapped to a dyadic grid of spacing at most ``h/8`` (a relative change of at most 1/16), so a
query walks only about :math:`\log_2(T/h) + 4` levels of the tree; adaptive steps per member use the grid of
spacing in :math:`(h/4, h/2]` (a relative change of the proposed step of at most 1/4, which the error estimate
then judges). Each member walks the tree on its own there, and a new step end on the coarser grid needs about
two new tree nodes instead of seven (the splits are most of a per-member query's cost; with shared steps one
split serves the whole batch, which keeps the finer grid unless it has one member). Save times and ``t1`` are never
stepped over. A step at ``dt_min`` whose error ratio exceeds 1 fails its members (``on_failure``).

What is exact and what is approximate
-------------------------------------
Exact: the increments and areas of every attempt come from the tree (Chen's identity between a step and
its halves to round-off); the answer depends only on the tree's seed, ``y0`` and the controller. The step
sizes depend on the path (they are not stopping times of the Brownian filtration); this is the usual
setting of pathwise adaptive schemes and, with a fixed path, costs no bias. Approximate: the law of the
tree itself (see :mod:`roughpaths.drivers.tree`); the error estimate (of the right size, not a bound).
"""

from __future__ import annotations

import math

import numpy as np

from ._attempts import _advance_nb, _doubling_nb, _judge_nb, _ratios_nb, _snap_nb
from .step_control import _checked_init, _checked_ratios, _checked_steps, _checked_verdict

__all__ = []


def _step_doubling(solver, fields, y, a):
    """``(y_2, y_1)`` of an attempt ``a`` from ``y``: two solver steps over its halves and one over the whole.

    With each member on its own times (``a.times (members, 3)``) the first half and the whole step are one
    step of the solver on the members stacked twice (a member's arithmetic is its own in any batch), the
    second half another: two calls instead of three, the same numbers. They call ``solver.step`` (the
    contract's ``integrate`` returns what stepping returns) with the arguments ``integrate`` passes it.
    The whole step's increment and area are the Chen product of the halves' (:func:`_doubling_nb`)."""
    n, e, d = y.shape[0], y.shape[-1], a.dX.shape[-1]
    Y2, T2, DT2, DX2, DXX2 = np.empty((2 * n, e)), np.empty((2 * n, 1)), np.empty((2 * n, 1)), \
        np.empty((2 * n, d)), np.empty((2 * n, d, d))
    ts = a.times if a.times.ndim == 2 else np.tile(a.times, (n, 1))     # contiguous: one compiled layout
    _doubling_nb(y, ts, a.dX, a.dXX, Y2, T2, DT2, DX2, DXX2)
    if a.times.ndim == 2 and isinstance(a.dXX, np.ndarray):
        both = solver.step(fields, Y2, T2, DT2, DX2, DXX2)                # first half; whole step
        return solver.step(fields, both[:n], ts[:, 1:2], ts[:, 2:] - ts[:, 1:2], a.dX[:, 1], a.dXX[:, 1]), both[n:]
    y2 = solver.integrate(fields, y, a.times, a.dX, a.dXX, a.save, stop_on_failure=a.stop)[0]
    return y2, solver.integrate(fields, y, a.times[..., [0, -1]], DX2[n:, None], DXX2[n:, None], a.save[:1],
                                stop_on_failure=False)[0]


class _Attempt:
    """One call of the solver: flat ``members``, ``times``, ``dX``, ``dXX``, ``save`` mask, the step ``h`` if adaptive."""

    def __init__(self, members, times, dX, dXX, save, h=None):
        self.members, self.times, self.dX, self.dXX, self.save, self.h = members, times, dX, dXX, save, h
        self.stop = False


class _TreeSteps:
    """The proposer of :func:`~roughpaths.solve`'s loop on an ``any_times`` driver: lanes, snapping, targets."""

    def __init__(self, run, tree, control, solver, save_at, shared, fields):
        L = getattr(tree, "resolution", 40)
        t0, t1 = float(tree.t0), float(tree.t1)
        self.run, self.tree, self.control, self.t0, self.t1, self.L = run, tree, control, t0, t1, L
        self.span = T = t1 - t0
        self.end, self.cell = end, cell = 1 << L, T / (1 << L)
        if isinstance(save_at, str):
            if save_at not in ("all", "end"):
                raise ValueError(f"save_at must be 'all', 'end' or an array of times in [t0, t1], got {save_at!r}.")
            self.targets, self.save_idx = np.array([end]), ({end} if save_at == "end" else set())
        else:
            st = np.asarray(save_at, dtype=np.float64).ravel()
            if st.size == 0 or not np.all(np.isfinite(st)) or st.min() < t0 or st.max() > t1:
                raise ValueError(f"save_at times must be finite and lie in the tree's [t0, t1] = [{t0}, {t1}], got "
                                 f"{save_at!r}.")
            self.save_idx = snapped = {min(int(round((v - t0) / T * end)), end) for v in st}
            if np.any(np.diff(np.array(sorted(snapped | {0, end}))) < 2):
                raise ValueError(f"save_at has times closer than two cells of the tree's grid ((t1 - t0)·2^-{L - 1}) "
                                 f"to each other or to t0, t1; a step between them cannot be halved. Drop the near "
                                 f"duplicates.")
            self.targets = np.array(sorted(snapped - {0} | {end}))
        self.save_all = isinstance(save_at, str) and save_at == "all"
        self.save_list = np.array(sorted(self.save_idx), dtype=np.int64)
        P = run.members
        self.vector = bool(getattr(solver, "member_times", False)) and (
            not getattr(fields, "time_dependent", False) or getattr(fields, "batched_time", False))
        self.shared = (not self.vector if shared is None else bool(shared)) or P == 0
        self.lanes = n = 1 if self.shared else P
        self.lane_of = np.zeros(P, dtype=np.int64) if self.shared else np.arange(P)     # the lane of each member
        self.lane_members = np.arange(P)[None] if self.shared else np.arange(P)[:, None]   # (lanes, members)
        self.paths = np.broadcast_to(np.arange(tree.n_paths).reshape(tree.batch_shape), run.batch).ravel()
        self.whole_batch = self.shared and tuple(tree.batch_shape) == tuple(run.batch)
        order = solver.error_order if solver.error_order is not None else solver.order
        self.state, self.dt_min, dt_max = _checked_init(control, t0, t1, n, order)
        self.min_cells = max(2, int(math.ceil(self.dt_min / cell)))
        if dt_max < 2 * cell:                   # the shortest step the grid allows would exceed dt_max, silently
            need = min(62, L + math.ceil(math.log2(2 * cell / dt_max)))
            raise ValueError(f"{type(control).__name__}: dt_max({T!r}) = {dt_max!r} is shorter than the shortest step "
                             f"of the tree's grid, {2 * cell:.3g} (2 cells of (t1 - t0)·2^-{L}); build the "
                             f"BrownianTree with resolution={need} or more, or raise dt_max.")
        self.i, self.j, self.iterations = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64), 0
        self.accepted, self.rejected, self.at_min = (np.zeros(n, dtype=np.int64) for _ in range(3))
        # step ends snapped to spacing (h/4, h/2] per path, adaptive; else (h/16, h/8] (module docstring)
        self.fine = 1 if control.adaptive and (not self.shared or P == 1) else 3
        keep0 = self.save_all or 0 in self.save_idx
        # the saved states, a row per iteration: (lanes, their times, their members' states (lanes, members, e))
        self.saved = [(np.arange(n), np.full(n, t0), run.y[self.lane_members])] if keep0 else []
        self.n_saved = n if keep0 else 0                   # states saved so far, over all lanes
        if P == 0:         # no member to step (an empty batch axis): done at once, at the times asked (all: t0, t1)
            self.i[:] = end
            pts = np.array(sorted(self.save_idx | ({0, end} if self.save_all else set())), dtype=np.int64)
            self.saved = [(np.zeros(pts.size, dtype=np.int64), self._time(pts),
                           np.empty((pts.size, 0, run.e)))]
        self.y_new, self.err = np.empty_like(run.y), np.zeros(P)
        self.bad, self.tried, self.unmet = (np.zeros(P, dtype=bool) for _ in range(3))
        self.floor, self.act, self.done = np.zeros(n, dtype=bool), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
        self.cols, self.r = np.empty((n, 3 if control.adaptive else 2), dtype=np.int64), np.zeros(n)
        self.t_at, self.h_at = np.zeros(n), np.zeros(n)              # every lane's attempt [t, t + h]
        self.failing, self.held = np.zeros(P, dtype=bool), np.zeros(n, dtype=bool)
        self.progress_total, self.reached = (T, "solve (adaptive)", "time"), 0.0

    def propose(self):
        """The attempts of every lane not yet at ``t1``, lanes on the same interval together (``[]``: done)."""
        live = self.live = self.i < self.end
        if not live.any():
            return []
        self.iterations += 1                   # a lane's attempts so far are at most the iterations before this
        if self.iterations > self.control.max_steps and \
                (over := live & (self.accepted + self.rejected >= self.control.max_steps)).any():
            k = int(np.argmax(over))            # a lane still short of t1 (one done in max_steps attempts is fine)
            who = ("the batch's shared steps" if self.shared else
                   f"batch member {tuple(int(v) for v in np.unravel_index(k, self.run.batch))}")
            raise ValueError(f"{'adaptive ' if self.control.adaptive else ''}solve took {self.control.max_steps} "
                             f"attempts and reached t = "
                             f"{self.t0 + int(self.i[k]) * self.cell:.6g} of [{self.t0}, {self.t1}] for {who} "
                             f"({int(self.accepted[k])} accepted, {int(self.rejected[k])} rejected); loosen rtol/atol "
                             f"or raise the controller's max_steps.")
        h = _checked_steps(self.control, self.state, live, self.t0, self.i, self.span, self.L)
        n = _snap_nb(self.i, h, self.targets, self.end, self.L, self.fine, self.min_cells, self.t0,
                     self.span, self.cell, self.dt_min, self.j, self.floor, self.act, self.cols, self.t_at, self.h_at)
        act, i, j = self.act[:n], self.cols[:n, 0], self.cols[:n, -1]
        paths, hc = self.paths[act], self.h_at[act]
        self.bad[:], self.tried[:] = False, False
        ts = self.cols[:n] * self.cell + self.t0                # (lanes, 3) or (lanes, 2)
        if self.shared:
            members, ts, h = self.lane_members[0], ts[0], float(hc[0])
            if members.size == 1:               # one member: walked as a path of its own, as per member
                W, XX = self.tree.increments_and_areas(ts[None], self.paths)
            else:
                W, XX = self.tree.increments_and_areas(ts, None if self.whole_batch else self.paths)
            W, XX = W.reshape((members.size,) + W.shape[-2:]), XX.reshape((members.size,) + XX.shape[-3:])
        else:
            members, h = act, hc
            W, XX = self.tree.increments_and_areas(ts, paths)
        if self.shared or self.vector:            # one call: the batch on shared steps, or each member on its own
            return [self._attempt(members, ts, W, XX, h)]
        pairs, inverse = np.unique(np.stack([i, j]), axis=1, return_inverse=True)
        groups = [np.flatnonzero(inverse.ravel() == g) for g in range(pairs.shape[1])]
        return [self._attempt(members[k], ts[k[0]], W[k], XX[k], h[k[0]]) for k in groups]

    def _attempt(self, members, ts, W, XX, h):
        return _Attempt(members, ts, W, XX, np.zeros(ts.shape[-1] - 1, dtype=bool), h if self.control.adaptive else None)

    def judge(self, a, y_new, saved, first_bad, err):
        """Keep an attempt's result: its members' new states, error ratios and non-finite flags."""
        y_new, m = np.ascontiguousarray(y_new, dtype=np.float64), a.members.size     # a user's solver or controller
        err = _checked_ratios(self.control, err, m, a.h is not None)
        if y_new.shape != (m, self.run.e):
            raise ValueError(f"the solver returned states of shape {y_new.shape} for {m} member(s) of dimension "
                             f"{self.run.e}; a solver's step must return shape (members, e).")
        _judge_nb(a.members, y_new, self.err if err is None else err, err is not None, self.y_new, self.tried, self.bad,
                  self.err)

    def adapt(self, attempts):
        """Fail the members that miss the tolerance at ``dt_min``, let the controller decide, advance the lanes."""
        run, r, adaptive = self.run, self.r, self.control.adaptive
        failed = _ratios_nb(self.err, self.tried, self.bad, run.healthy, self.lane_of, self.floor, adaptive, r, self.unmet)
        if failed:
            m = np.flatnonzero(self.unmet)          # the tolerance cannot be met at dt_min: fail, never crawl
            np.add.at(self.at_min, self.lane_of[m], 1)
            k = self.lane_of[m[0]]
            run.fail(m, self.accepted[self.lane_of[m]], unmet=(float(np.max(self.err[m])), self.t_at[k], self.h_at[k],
                                                                self.control, self.dt_min, self.L))
        accept = _checked_verdict(self.control, self.state, self.t_at, self.h_at, r if adaptive else None)
        n, nbad = _advance_nb(accept, self.floor, self.live, self.tried, self.bad, run.healthy, self.lane_of,
                              self.accepted, self.rejected, self.i, self.j, run.y, self.y_new, self.done, self.failing,
                              self.held)
        if nbad:                                  # non-finite on an accepted step: report it, then move its lanes
            m = np.flatnonzero(self.failing)
            run.fail(m, self.accepted[self.lane_of[m]], times=self._times_of)
            self.accepted += self.held
            np.copyto(self.i, self.j, where=self.held)
        if n:
            self._save(n)
        if failed or nbad:                        # (on_failure="mask") a lane left without a healthy member stops
            self._stop_failed_lanes()

    def _save(self, n):
        """Save the states of the ``n`` lanes just accepted (``self.done[:n]``) that are at a save time."""
        run, cell = self.run, self.cell
        lanes = self.done[:n].copy()             # kept in self.saved: not a view of the reused buffer
        at = self.i[lanes]
        if not self.save_all:
            keep = at == self.end if self.save_list.size == 1 and self.save_list[0] == self.end else \
                np.isin(at, self.save_list)
            lanes, at = lanes[keep], at[keep]
        if lanes.size:
            self.saved.append((lanes, self._time(at),
                               run.y[self.lane_members[lanes]]))
            self.n_saved += lanes.size
            run.check_saves(self.n_saved // self.lanes, growing=True)
        reached = float(self.i.min()) * cell           # exact: cell = T / 2^L, and end * cell == T
        if reached > self.reached:
            self.reached = reached
            run.progress(reached)

    def _stop_failed_lanes(self):
        """Lanes whose members have all failed (masked) jump to ``t1``: their states are NaN at the save times left
        (``t1`` only, with ``save_at="all"``), and no more steps are taken or counted for them (before, they went on
        stepping NaN states, counted as accepted, to ``t1``)."""
        dead = np.flatnonzero((self.i < self.end) & ~self.run.healthy[self.lane_members].any(axis=1))
        for k in dead.tolist():
            at = np.array([self.end]) if self.save_all else self.save_list[self.save_list > self.i[k]]
            if at.size:
                self.saved.append((np.full(at.size, k), self._time(at),
                                   np.full((at.size,) + self.lane_members.shape[1:] + (self.run.e,), np.nan)))
                self.n_saved += at.size
            self.i[k] = self.end

    def _time(self, at):
        """The times of the grid indices ``at``: ``t0 + at cell``, and ``t1`` itself at the end (``t0 + end cell``
        may round off it)."""
        return np.where(at < self.end, self.t0 + at * self.cell, self.t1)

    def _times_of(self, member):
        """The step ends the failure message of ``member`` (flat index) reads: its failed attempt's start and end
        at positions ``accepted`` and ``accepted + 1`` (the earlier ends, not kept, are NaN)."""
        k = int(self.lane_of[member])
        times = np.full(int(self.accepted[k]) + 2, np.nan)
        times[-2:] = self.t0 + np.array([float(self.i[k]), float(self.j[k])]) * self.cell
        return times

    def finish(self):
        """``(times, states, stats)``: one time axis for shared steps and for save times; per member otherwise."""
        run = self.run
        lanes, times, states = (np.concatenate(v) for v in zip(*self.saved)) if self.saved else (
            np.empty(0, dtype=np.int64), np.empty(0), np.empty((0,) + self.lane_members.shape[1:] + (run.e,)))
        order = np.argsort(lanes, kind="stable")           # lane by lane, in the order saved
        times, states = times[order], states[order]
        counts = np.bincount(lanes, minlength=self.lanes)
        if self.shared or not self.save_all:               # every lane saved at the same times
            S = int(counts[0]) if counts.size else 0
            times = times[:S]
            states = states.reshape((self.lanes, S) + states.shape[1:]).swapaxes(1, 2).reshape(-1, S, run.e)
        else:          # each member its own step ends; shorter rows repeat their last time (t1) and state
            K = int(counts.max())
            first = np.concatenate([[0], np.cumsum(counts)[:-1]])
            idx = first[:, None] + np.minimum(np.arange(K), counts[:, None] - 1)
            times, states = times[idx].reshape(run.batch + (K,)), states[idx][:, :, 0]
        stats = {k: (int(v[0]) if self.shared else v.reshape(run.batch))
                 for k, v in (("accepted", self.accepted), ("rejected", self.rejected), ("at_dt_min", self.at_min))}
        stats.update(step_control=repr(self.control), n_steps=stats["accepted"], shared_steps=self.shared)
        return times, states.reshape(run.batch + states.shape[-2:]), stats
