r"""The result of :func:`~roughpaths.solve`: :class:`Solution`, and :class:`NonFiniteStateError`.

Made by the one time loop of :mod:`roughpaths.rde.integrate`, on a grid or with a step controller.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..validation import arrays_equal

__all__ = ["Solution", "NonFiniteStateError"]


class NonFiniteStateError(ValueError):
    """Batch members of a :func:`solve` became non-finite.

    Attributes
    ----------
    members : tuple of tuple of int
        The batch indices of the failed members (all of them, in C order).
    steps : tuple of int
        For each failed member, the index ``k`` of the step ``[t_k, t_{k+1}]`` after which it was
        first non-finite.
    """

    def __init__(self, message, members=(), steps=()):
        super().__init__(message)
        self.members = tuple(members)
        self.steps = tuple(steps)


@dataclass(frozen=True, eq=False)
class Solution:
    """Result of :func:`solve`.

    Attributes
    ----------
    times : ndarray, shape ``(K,)``
        The saved times (all grid times by default; with a step controller, every accepted step's end). With
        steps per member and ``save_at="all"``, shape ``(..., K)``: each member's own step ends, a shorter row
        repeating its last time (``t1``) and state.
    states : ndarray, shape ``(..., K, e)``
        The solution at ``times``; leading axes are the broadcast batch of driver and ``y0``.
    failed_step : ndarray of int, shape ``(...)``
        Per batch member, the index of the step after which it first became non-finite, ``-1`` for
        a healthy member (all ``-1`` unless ``on_failure="mask"`` kept a batch with failures). The
        states of a failed member are NaN from that step on.
    stats : dict
        ``solver``, ``n_steps``, ``n_blocks``, ``batch_shape``, ``wall_time`` (seconds); with a step controller
        (``step_control``) ``step_control``, ``shared_steps``, ``accepted`` (``= n_steps``), ``rejected`` and
        ``at_dt_min`` (members failed at ``dt_min``) instead of ``n_blocks``: integers with shared steps, arrays
        over the batch with steps per member.
    """

    times: np.ndarray
    states: np.ndarray
    failed_step: np.ndarray = None
    stats: dict = field(default_factory=dict)

    @property
    def final(self) -> np.ndarray:
        """The state at the last saved time, shape ``(..., e)``."""
        return self.states[..., -1, :]

    def __eq__(self, other) -> bool:
        """Equal times, states and failed steps (entry by entry, NaN equal) and equal ``stats``."""
        if not isinstance(other, Solution):
            return NotImplemented
        return (arrays_equal(self.times, other.times) and arrays_equal(self.states, other.states)
                and arrays_equal(self.failed_step, other.failed_step) and self.stats == other.stats)

    __hash__ = None

    @property
    def failed(self) -> np.ndarray:
        """Boolean mask ``(...)`` of the batch members that became non-finite."""
        if self.failed_step is None:
            return np.zeros(self.states.shape[:-2], dtype=bool)
        return self.failed_step >= 0

    def __repr__(self) -> str:
        return (f"Solution(times: {self.times.shape}, states: {self.states.shape}, "
                f"solver={self.stats.get('solver')!r})")


def _failure_message(failed_step, times, batch) -> tuple:
    """``(message, members, steps)``; ``times`` the step ends ``(K,)``, or a callable of a member giving its own."""
    members = [tuple(int(i) for i in idx) for idx in np.argwhere(failed_step >= 0)]
    steps = [int(failed_step[m]) for m in members]
    first = int(np.argmin(steps))
    k, m = steps[first], members[first]
    times = times(m) if callable(times) else times
    msg = (f"the solution became non-finite at step {k} (t = {float(times[k + 1]):.6g}, step from "
           f"t = {float(times[k]):.6g}) for batch member {m}")
    if len(members) > 1:
        shown = ", ".join(f"{mm} at step {kk}" for mm, kk in zip(members[:8], steps[:8]))
        more = f" and {len(members) - 8} more" if len(members) > 8 else ""
        msg += (f"; {len(members)} of {int(np.prod(batch, dtype=np.int64))} members failed: "
                f"{shown}{more}")
    msg += ("; the vector fields may blow up there, or the step is too large: refine the driver's "
            "grid. Pass on_failure='mask' to keep the healthy members' results (Solution.failed marks "
            "the others).")
    return msg, members, steps


def _unmet_message(members, batch, r, t, h, control, dt_min=None, resolution=None):
    """The message of a step at ``dt_min`` whose error exceeds the tolerance (``on_failure="raise"``); a step held
    above ``dt_min`` by the driver's grid (two cells of a coarse tree) names the tree's ``resolution`` instead."""
    first = tuple(int(v) for v in np.unravel_index(int(members[0]), batch))
    by_grid = dt_min is not None and resolution is not None and h > dt_min * (1 + 1e-9)
    at = (f"the shortest step of the tree's grid (2 cells of (t1 - t0)·2^-{resolution}; dt_min = {dt_min:.3g})"
          if by_grid else f"dt_min = {h:.3g}")
    lower = (f"build the BrownianTree with a higher resolution (now {resolution}, at most 62)" if by_grid else
             "lower dt_min (PIController(dt_min=...))")
    return (f"the error tolerance cannot be met: the step [{t:.6g}, {t + h:.6g}] at {at} still has "
            f"{r:.3g} times the error {control!r} allows, for {len(members)} batch member(s) (first {first}); "
            f"loosen rtol/atol, {lower}, or pass on_failure='mask' to mark these "
            f"members failed (Solution.failed) and finish the others.")
