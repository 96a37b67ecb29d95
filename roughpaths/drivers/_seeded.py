"""Shared machinery of the per-path seeded drivers (private): seed, grid, paths, selection, sizes.

A seeded driver keys the random stream of each path by the path's flat index ``i`` in the
original ``batch_shape`` (C order), so that a subset of paths (:meth:`SeededDriver.select`),
a block size or a process does not change any path's numbers. Subclasses define the streams and
``blocks``; :class:`roughpaths.BrownianDriver` and :class:`roughpaths.ColouredNoiseDriver`.
"""

from __future__ import annotations

import numbers
import os

import numpy as np

from .base import Driver
from ..validation import as_float_array, check_batch_shape, check_memory, check_positive_int, check_seed, check_times


def grid(times, dt, n_steps, t0):
    """``(times, h)``: the grid and its step sizes (exactly ``dt`` on a uniform grid)."""
    if times is not None:
        if dt is not None or n_steps is not None:
            raise ValueError("pass either times=... or dt=... with n_steps=..., not both.")
        t = check_times(times, "times")
        return t, np.diff(t)
    if dt is None or n_steps is None:
        raise ValueError("the grid is missing: pass times=<increasing array> or dt=<step> and n_steps=<int>.")
    n = check_positive_int(n_steps, "n_steps")
    # the grid is built eagerly; refuse what can never fit (physical memory, or ROUGHPATHS_MAX_BYTES if set)
    check_memory(8.0 * 2 * (n + 1), f"the time grid (n_steps={n})", "use fewer steps",
                 max_bytes=None if os.environ.get("ROUGHPATHS_MAX_BYTES") else phys_bytes())
    if isinstance(dt, bool) or not isinstance(dt, numbers.Real) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive finite number, got {dt!r}; pass times=... for a "
                         f"non-uniform grid.")
    if isinstance(t0, bool) or not isinstance(t0, numbers.Real) or not np.isfinite(t0):
        raise ValueError(f"t0 must be a finite number, got {t0!r}.")
    if not np.isfinite(float(t0) + float(dt) * n):
        raise ValueError(f"the grid t0 + dt * arange(n_steps + 1) overflows (t0={t0!r}, dt={dt!r}, n_steps={n}); "
                         f"use a smaller dt or fewer steps.")
    return float(t0) + float(dt) * np.arange(n + 1, dtype=np.float64), np.full(n, float(dt))


def phys_bytes() -> float:
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return float("inf")


def selected_paths(paths, n: int, owner: str) -> np.ndarray:
    """Flat path indices (int64, negatives wrapped) of a ``select(paths)`` on an ``owner`` of ``n`` paths.

    ``paths``: a slice, a range or a 1-D array of integers in ``[-n, n)``; anything else is refused
    with a message naming the argument.
    """
    if isinstance(paths, slice):
        return np.arange(n)[paths]
    if isinstance(paths, range):
        paths = np.arange(paths.start, paths.stop, paths.step)
    idx = np.asarray(paths)
    if idx.ndim != 1 or not (idx.size == 0 or idx.dtype.kind in "iu"):
        raise TypeError(f"paths must be a slice, a range or a 1-D array of integer path indices, got {paths!r}.")
    lo, hi = (int(idx.min()), int(idx.max())) if idx.size else (0, -1)
    if lo < -n or hi >= n:
        raise ValueError(f"paths holds indices outside [0, {n}) (this {owner} has {n} paths), "
                         f"e.g. {int(idx[(idx < -n) | (idx >= n)][0])}.")
    return (np.where(idx < 0, idx + n, idx) if lo < 0 else idx).astype(np.int64)


class SeededDriver(Driver):
    """Base of the per-path seeded drivers: grid, batch, path indices, ``x0``-like start, ``select``."""

    def _init_common(self, dim, seed, times, dt, n_steps, t0, batch_shape, block_bytes):
        self.dim = check_positive_int(dim, "dim")
        self.seed_sequence = check_seed(seed)
        self.times, self._h = grid(times, dt, n_steps, t0)
        self.times.setflags(write=False)
        self.batch_shape = check_batch_shape(batch_shape)
        check_memory(8.0 * 4 * (self.dim + self.dim * self.dim), f"one step of one path in dim={self.dim}",
                     "use a smaller dim")
        self.block_bytes = check_positive_int(block_bytes, "block_bytes")
        self._paths = None                   # None: all paths 0..n-1 (nothing allocated before blocks())

    def _check_start(self, x0, name: str, dim: int):
        """A start value broadcastable to ``batch_shape + (dim,)`` (kept unbroadcast until needed)."""
        z = as_float_array(x0, name, last_dims=(dim,))
        try:
            np.broadcast_shapes(z.shape, self.batch_shape + (dim,))
        except ValueError:
            raise ValueError(f"{name} of shape {z.shape} does not broadcast to the batch shape "
                             f"{self.batch_shape} + ({dim},).") from None
        return z.copy()

    @property
    def n_paths(self) -> int:
        """Number of paths (``prod(batch_shape)``)."""
        return int(np.prod(self.batch_shape, dtype=np.int64))

    @property
    def path_indices(self) -> np.ndarray:
        """Flat indices (in the original batch) of this driver's paths; they key the streams."""
        return np.arange(self.n_paths, dtype=np.int64) if self._paths is None else self._paths.copy()

    def _flat(self, start, dim: int) -> np.ndarray:
        """A start value (``(dim,)`` or batch-shaped) as ``(n_paths, dim)``."""
        return np.broadcast_to(start, self.batch_shape + (dim,)).reshape(-1, dim)

    def _starts(self) -> dict:                # pragma: no cover - overridden
        """The per-path start arrays, by attribute name, and their last dimension."""
        return {}

    def default_block_steps(self) -> int:
        """Steps per block used by :meth:`blocks` when ``max_steps`` is None (from ``block_bytes``)."""
        per_step = max(1, self.n_paths) * self._bytes_per_path_step()
        return max(1, min(self.n_steps, self.block_bytes // per_step))

    def block_nbytes(self, max_steps=None) -> float:
        """Bytes one block of :meth:`blocks` (``max_steps``, default :meth:`default_block_steps`) holds while it
        is made: its increments, areas and sampling scratch, ``P × min(K, N) × b`` for ``P`` paths, blocks of
        ``K`` steps and ``b`` bytes per path-step. A consumer that keeps a block while the next is made holds
        two. Callers add it to the estimate they pass to :func:`roughpaths.validation.check_memory`.

        Examples
        --------
        >>> from roughpaths import BrownianDriver
        >>> drv = BrownianDriver(2, seed=0, dt=0.01, n_steps=100, batch_shape=(10,), levy_area=None)
        >>> drv.block_nbytes(max_steps=50)      # 10 paths x 50 steps x (increments and normals, 2 x 2 floats)
        16000.0
        """
        K = self.default_block_steps() if max_steps is None else check_positive_int(max_steps, "max_steps")
        return float(self.n_paths) * min(K, self.n_steps) * self._bytes_per_path_step()

    def _block_size(self, max_steps) -> int:
        K = self.default_block_steps() if max_steps is None else check_positive_int(max_steps, "max_steps")
        need = float(self.n_paths) * min(K, self.n_steps) * self._bytes_per_path_step()
        if need > 0.5 * phys_bytes():
            raise ValueError(f"one block of {min(K, self.n_steps)} step(s) for {self.n_paths} paths needs "
                             f"{need / 2**30:.1f} GiB, more than half the machine's memory; pass a smaller "
                             f"max_steps or select(...) fewer paths.")
        return K

    def select(self, paths):
        """A driver for a subset of this driver's paths, bitwise equal to those paths of this one.

        Parameters
        ----------
        paths : slice, range or array_like of int
            Flat indices into this driver's batch (C order). The result has ``batch_shape ==
            (len(paths),)``; its start values are taken from this driver's.

        Returns
        -------
        Driver
            Of the same class.
        """
        idx = selected_paths(paths, self.n_paths, "driver")
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new._paths = self.path_indices[idx]
        for name, dim in self._starts().items():
            start = getattr(self, name)
            if start is not None:
                setattr(new, name, self._flat(start, dim)[idx])
        new.batch_shape = (int(idx.size),)
        return new

    def rough_path(self):
        """The whole driver as one ``RoughPath`` (refused, naming the size, if it would not fit in memory).

        The blocks are copied into the whole path as they come, so the call holds the whole path and two
        blocks (the generator releases a block when it has made the next): with ``P`` paths, ``N`` steps,
        blocks of ``K`` steps and ``b`` bytes per path-step of a block (its increments, areas and sampling
        scratch, :meth:`default_block_steps`), ``8 P N (d + d²) + 2 P K b`` bytes (``d²`` at level 2 only),
        checked before the first block.
        """
        P, N, d = self.n_paths, self.n_steps, self.dim
        per_step = d + (d * d if self.level == 2 else 0)
        K = min(self.default_block_steps(), N)
        blocks = 2 if K < N else 1
        need = 8.0 * P * N * per_step + blocks * self.block_nbytes(K) + 4096.0
        check_memory(need, f"the whole path ({P} paths x {N} steps x {per_step} numbers, and {blocks} "
                           f"block(s) of {K} steps)",
                     "pass the driver to solve(...) (it is consumed block by block) or iterate driver.blocks(), "
                     "or select(...) fewer paths")
        from ..paths.rough_path import RoughPath

        inc = np.empty(self.batch_shape + (N, d))
        areas = np.empty(self.batch_shape + (N, d, d)) if self.level == 2 else None
        x0 = kind = None
        k0 = 0
        for block in self.blocks(K):
            if k0 == 0:                                  # keep the start and kind, not the first block
                x0, kind = block.x0, block.kind
            k1 = k0 + block.increments.shape[-2]
            inc[..., k0:k1, :] = block.increments
            if areas is not None:
                areas[..., k0:k1, :, :] = block.areas
            k0 = k1
        return RoughPath(inc, areas, times=self.times, x0=x0, kind=kind, check=False)
