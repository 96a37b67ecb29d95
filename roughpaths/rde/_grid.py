"""Fixed steps on a grid driver: the proposer of :func:`~roughpaths.solve`'s loop (the driver's blocks, all accepted)."""

from __future__ import annotations

import numpy as np

from ..drivers.base import Driver
from ..paths.rough_path import grid_index
from ..validation import check_memory
from .adaptive import _Attempt


class _GridSteps:
    """The proposer of the loop on a grid driver (fixed steps): its blocks in order, every step accepted."""

    span = None

    def __init__(self, run, driver, save_at, block_steps, level, step_bytes=None):
        self.run, self.level, self.times, self.n = run, level, np.asarray(driver.times), driver.n_steps
        n, e, members = self.n, run.e, float(run.members)
        if isinstance(save_at, str):
            if save_at not in ("all", "end"):
                raise ValueError(f"save_at must be 'all', 'end' or an array of grid times, got {save_at!r}.")
            self.idx = np.arange(n + 1) if save_at == "all" else np.array([n])
        else:
            self.idx = np.unique(grid_index(self.times, save_at, "save_at").ravel())
        self.save_mask = np.zeros(n + 1, dtype=bool)
        self.save_mask[self.idx] = True
        run.check_saves(self.idx.size)
        work, what = _working_bytes(driver, block_steps, members, e, level, int(self.idx.size), step_bytes)
        check_memory(work, f"the solver's working arrays ({members:.0f} member(s): {what}, the states saved "
                           f"per block and one step's temporaries)",
                     "pass a smaller block_steps, or solve the batch in parts (driver.select(...), or executor=...)")
        self.out = np.empty(run.batch + (self.idx.size, e))
        self.slot = int(self.save_mask[0])
        if self.slot:
            self.out[..., 0, :] = run.y
        self.blocks = iter(driver.blocks(block_steps) if isinstance(driver, Driver) else (driver,))
        self.k0 = self.n_blocks = 0
        self.progress_total = (n * members, "solve", "member-steps")

    def propose(self):
        block = next(self.blocks, None)
        if block is None:
            if self.k0 != self.n:
                raise RuntimeError(f"the driver's blocks covered {self.k0} of its {self.n} steps; its blocks() is "
                                   f"broken.")
            return []
        a = _Attempt(Ellipsis, block.times, block.increments, _higher_levels(block, self.level),
                     self.save_mask[self.k0 + 1:self.k0 + block.n_steps + 1])
        a.stop = self.run.on_failure == "raise"
        return [a]

    def judge(self, a, y, saved, first_bad, err):
        run = self.run
        new_bad = ((first_bad >= 0).ravel() & (run.failed < 0))
        if new_bad.any():
            m = np.flatnonzero(new_bad)
            run.fail(m, first_bad.ravel()[m] + self.k0, self.times)
            y[(run.failed >= 0).reshape(run.batch)] = np.nan
        run.y = y
        nsave = saved.shape[-2]
        self.out[..., self.slot:self.slot + nsave, :] = saved
        self.slot += nsave
        self.k0 += a.times.shape[0] - 1
        self.n_blocks += 1
        run.progress(self.k0 * float(run.members))

    def adapt(self, attempts):
        """Fixed steps: every step is accepted."""

    def finish(self):
        failed = self.run.failed.reshape(self.run.batch)
        if (failed >= 0).any():
            self.out[(failed[..., None] >= 0) & (self.idx > failed[..., None])] = np.nan
        return self.times[self.idx].copy(), self.out, {"n_steps": self.n, "n_blocks": self.n_blocks}


def _working_bytes(driver, block_steps, members: float, e: int, level: int, n_saved: int, step_bytes=None):
    """Bytes a fixed-step :func:`solve` holds besides its saved states, and what holds them (for the message).

    With ``M`` members, ``N`` steps, blocks of ``K`` steps, ``d`` noise and ``e`` state dimensions:

    * a lazy driver's blocks: two of ``driver.block_nbytes(K)`` (the generator makes the next block while
      the loop still holds the last; one if a block covers the grid); a ``RoughPath`` is read in place;
    * the states a block saves before they are copied out, ``8 M min(K, saved) e``;
    * the state, its copy and the failure indices, ``8 M (2 e + 1)``;
    * one step's temporaries, per member: the slice of the area (d²) and of level 3 (d³) the step is given,
      the fields' values and their product with the area (2 e d), their Jacobians (d e²), the linear
      generators (2 e²) with a log-ODE step's matrix exponential (up to 14 e², scaling and squaring) and up to
      eight state-sized sums (8 e), 8 bytes each; or what the solver states for itself (``step_bytes``, from
      ``solver.step_nbytes(fields)``, contract item 11 of :class:`~roughpaths.Solver`: the coadjoint solvers on a
      matrix Lie algebra hold ``N × N`` matrices, not ``e × e`` generators).
    """
    N, d = driver.n_steps, driver.dim
    if isinstance(driver, Driver):
        K = block_steps if block_steps is not None else getattr(driver, "default_block_steps", lambda: N)()
        K = min(K, N)
        nb = 2 if K < N else 1
        # a driver without block_nbytes (one of the caller's own) states nothing of its blocks
        per_block = driver.block_nbytes(K) if hasattr(driver, "block_nbytes") else 0.0
        blocks, what = nb * per_block, f"{nb} driver block(s) of {K} steps"
    else:
        K, blocks, what = N, 0.0, "the path read in place"
    d3 = float(d) ** 3 if level >= 3 else 0.0
    step = float(d) ** 2 + d3 + 2.0 * e * d + float(d) * e * e + 16.0 * e * e + 8.0 * e
    if step_bytes is not None:                  # what the solver states for itself (solver.step_nbytes(fields))
        step = float(d) ** 2 + d3 + step_bytes / 8.0
    return (blocks + 8.0 * members * (min(K, n_saved) * e + 2 * e + 1 + step) + 4096.0), what


def _higher_levels(block, increment_level):
    """The ``dXX`` argument of contract item 8: None, the areas, or ``(areas, level-3 components)``."""
    if increment_level < 2:
        return None
    if increment_level == 2:
        return block.areas
    return block.areas, block.step_level(3)
