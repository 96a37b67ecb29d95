r"""The driver protocol: a rough path delivered in time blocks, consumed by :func:`roughpaths.solve`.

:func:`~roughpaths.solve` accepts either a materialised :class:`~roughpaths.RoughPath` or a
:class:`Driver`: an object that produces the same rough path lazily, block by block in time, so that
long or large runs need memory for one block only. A driver has

* ``times`` (``(N + 1,)``), ``n_steps`` (``N``), ``dim`` (``d``), ``level`` (1 or 2) and
  ``batch_shape`` (the leading axes of every block), like a ``RoughPath``;
* :meth:`Driver.blocks`, an iterator of consecutive ``RoughPath`` blocks covering the grid (block
  ``b`` has ``times = self.times[k_b : k_{b+1} + 1]``); the numbers must not depend on the block size;
* :meth:`Driver.rough_path`, the whole path materialised (the blocks concatenated);
* optionally ``select(paths)``: a driver for a subset of the paths (flat indices), bitwise equal to
  those paths of the full driver; ``solve(..., executor=...)`` uses it to split a batch.

A driver that answers on *any* times of its interval ``[t0, t1]`` (a :class:`~roughpaths.BrownianTree`) sets
``any_times = True`` and has ``t0``, ``t1`` and ``increments_and_areas(times, paths=None)``: the increments
``(..., n, d)`` and (Stratonovich) areas ``(..., n, d, d)`` between the ``n + 1`` increasing ``times``, for all
paths or for the flat path indices ``paths`` (then with one leading axis, ``(len(paths), n, ...)``, and
``times`` may be ``(len(paths), n + 1)``: each path on its own times). ``solve`` then chooses the steps with a
step controller (:mod:`roughpaths.rde.step_control`); its ``times`` are ``[t0, t1]``, its one grid step.
"""

from __future__ import annotations

from typing import Iterator

__all__ = ["Driver"]


class Driver:
    """Abstract base class of lazily generated drivers (see the module docstring for the protocol)."""

    times = None
    dim: int = 0
    level: int = 2
    batch_shape: tuple = ()
    any_times: bool = False

    @property
    def n_steps(self) -> int:
        """The number of grid steps ``N``."""
        return int(self.times.shape[0]) - 1

    def blocks(self, max_steps: int | None = None) -> Iterator:  # pragma: no cover - abstract
        """Yield consecutive ``RoughPath`` blocks of at most ``max_steps`` steps covering the grid."""
        raise NotImplementedError

    def rough_path(self):
        """The whole driver as one ``RoughPath`` (its blocks concatenated)."""
        import numpy as np

        from ..paths.rough_path import RoughPath

        blocks = list(self.blocks())
        inc = np.concatenate([b.increments for b in blocks], axis=-2)
        areas = None if blocks[0].areas is None else np.concatenate([b.areas for b in blocks], axis=-3)
        return RoughPath(inc, areas, times=self.times, x0=blocks[0].x0, kind=blocks[0].kind, check=False)
