r"""Level-2 rough paths sampled on a time grid.

A :class:`RoughPath` stores, on a grid :math:`t_0 < t_1 < \dots < t_N` shared by every path of a
batch, the per-step increments :math:`X_{t_k, t_{k+1}}` and per-step areas
:math:`\mathbb{X}_{t_k, t_{k+1}}`. Every two-parameter quantity over a pair of grid times
``s < t`` follows from these by Chen's identity, so the stored object is Chen-consistent by
construction.

Conventions (``docs/conventions.md``)
--------------------------------
* area: ``XX[..., i, j]`` over ``[s, t]`` is :math:`\int_s^t (X^i_r - X^i_s)\,dX^j_r`
  (the ordering of ``iisignature`` and ``esig``: word ``(i, j)`` ↔ entry ``[i, j]``);
* Chen: :math:`\mathbb{X}_{s,t} = \mathbb{X}_{s,u} + \mathbb{X}_{u,t} + X_{s,u}\otimes X_{u,t}`;
* geometric: :math:`\mathrm{Sym}(\mathbb{X}_{s,t}) = \tfrac12 X_{s,t}\otimes X_{s,t}`;
* Lévy area: :math:`A_{s,t} = \mathrm{Alt}(\mathbb{X}_{s,t}) = \tfrac12(\mathbb{X} - \mathbb{X}^T)`
  *with* the ½ (the paper's eq. (LevyArea) omits it);
* perturbation: :math:`\widetilde{\mathbb{X}}_{s,t} = \mathbb{X}_{s,t} + \mathsf{s}\,(t - s)` with
  ``s`` antisymmetric.

Shapes: ``increments`` ``(..., N, d)``, ``areas`` ``(..., N, d, d)``, ``times`` ``(N + 1,)``,
``x0`` ``(..., d)``; the leading ``...`` are batch axes.
"""

from __future__ import annotations

import numpy as np

from ..validation import arrays_equal, as_float_array, check_antisymmetric, check_times
from ..algebra.level2 import outer

__all__ = ["RoughPath", "chen_defect", "grid_index"]

_KINDS = ("geometric", "ito", "general")


class RoughPath:
    r"""A batch of level-1 or level-2 rough paths on a common time grid.

    Parameters
    ----------
    increments : array_like, shape ``(..., N, d)``
        Per-step increments :math:`X_{t_k, t_{k+1}}`.
    areas : array_like, shape ``(..., N, d, d)``, or None
        Per-step areas :math:`\mathbb{X}_{t_k, t_{k+1}}` (``iisignature`` ordering). ``None`` makes
        a level-1 path (no area): level-2 solvers refuse it rather than silently dropping the area.
    times : array_like, shape ``(N + 1,)``, optional
        Strictly increasing grid; default ``linspace(0, 1, N + 1)``.
    x0 : array_like, shape ``(..., d)``, optional
        Starting point of the trace (default 0); only :attr:`path` depends on it.
    kind : {"geometric", "ito", "general"}, optional
        What the area is: ``"geometric"`` (Stratonovich-type, checked unless ``check=False``),
        ``"ito"`` or ``"general"``. Default: ``"geometric"`` if the areas satisfy
        :math:`\mathrm{Sym}(\mathbb{X}) = \tfrac12 X\otimes X` to round-off, else ``"general"``.
    check : bool
        Validate shapes, finiteness and the declared kind (default True).

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), times=[0.0, 1.0, 2.0])
    >>> X.increment(0.0, 2.0)
    array([1., 1.])
    >>> X.levy_area(0.0, 2.0)   # Alt(XX) = ½(XX - XXᵀ): the signed area of the L-shaped path
    array([[ 0. ,  0.5],
           [-0.5,  0. ]])
    """

    __slots__ = ("_times", "_increments", "_areas", "_x0", "_kind", "_cache")

    def __init__(self, increments, areas=None, *, times=None, x0=None, kind=None, check=True):
        if check:
            inc = as_float_array(increments, "increments", min_ndim=2)
            if inc.shape[-2] < 1:
                raise ValueError(f"increments must have at least one step (axis -2), got shape {inc.shape}.")
        else:
            inc = np.asarray(increments, dtype=np.float64)
        n, d = inc.shape[-2], inc.shape[-1]
        if times is None:
            t = np.linspace(0.0, 1.0, n + 1)
        else:
            t = check_times(times, "times", n=n + 1) if check else np.asarray(times, dtype=np.float64)
        if areas is not None:
            if check:
                a = as_float_array(areas, "areas")
                if a.ndim < 3 or a.shape[-3:] != (n, d, d):
                    raise ValueError(f"areas must have shape (..., n, d, d) = (..., {n}, {d}, {d}) to match "
                                     f"increments of shape {inc.shape}, got shape {a.shape}.")
                if a.shape[:-3] != inc.shape[:-2]:
                    raise ValueError(f"areas has batch shape {a.shape[:-3]} but increments has "
                                     f"{inc.shape[:-2]}; both need the same leading axes.")
            else:
                a = np.asarray(areas, dtype=np.float64)
        else:
            a = None
        if x0 is None:
            z = np.zeros(inc.shape[:-2] + (d,))
        else:
            z = as_float_array(x0, "x0", last_dims=(d,)) if check else np.asarray(x0, dtype=np.float64)
            if check:
                try:
                    z = np.broadcast_to(z, inc.shape[:-2] + (d,))
                except ValueError:
                    raise ValueError(f"x0 has shape {z.shape}, which does not broadcast to the batch "
                                     f"shape of increments, {inc.shape[:-2] + (d,)}; give x0 shape "
                                     f"(d,) or the increments' batch axes.") from None
        if kind is not None and kind not in _KINDS:
            raise ValueError(f"kind must be one of {_KINDS}, got {kind!r}.")
        if a is not None and check:
            defect = _geometric_defect(inc, a)
            tol = 1e-9 * (1.0 + float(np.max(np.abs(a), initial=0.0)) + float(np.max(inc * inc, initial=0.0)))
            is_geo = float(np.max(defect, initial=0.0)) <= tol
            if kind is None:
                kind = "geometric" if is_geo else "general"
            elif kind == "geometric" and not is_geo:
                k = int(np.argmax(defect.reshape(-1)))
                raise ValueError(
                    f"areas are not geometric: Sym(XX) differs from ½ X⊗X by up to "
                    f"{float(np.max(defect)):.3g} (flat step index {k}); pass kind='general' (or "
                    f"kind='ito' for an Itô lift) if that is intended, or fix the symmetric part.")
        if a is None:
            kind = None
        elif kind is None:
            kind = "general"
        self._times, self._increments, self._areas = t, inc, a
        self._x0, self._kind, self._cache = z, kind, {}

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_increments(cls, increments, areas=None, *, times=None, x0=None, kind=None):
        """Build from per-step increments and areas; see :class:`RoughPath` for shapes."""
        return cls(increments, areas, times=times, x0=x0, kind=kind)

    @classmethod
    def from_path(cls, values, *, times=None):
        r"""Piecewise-linear (canonical, geometric) lift of sampled data.

        Parameters
        ----------
        values : array_like, shape ``(..., N + 1, d)``
            Samples :math:`X_{t_0}, \dots, X_{t_N}`.
        times : array_like, shape ``(N + 1,)``, optional
            Sample times; default ``linspace(0, 1, N + 1)``.

        Returns
        -------
        RoughPath
            Level 2 with per-step areas :math:`\tfrac12 \Delta X\otimes \Delta X` (zero Lévy area
            on each linear piece); ``x0`` is the first sample.
        """
        v = as_float_array(values, "values", min_ndim=2)
        if v.shape[-2] < 2:
            raise ValueError(f"values needs at least 2 samples along axis -2, got shape {v.shape}.")
        inc = np.diff(v, axis=-2)
        return cls(inc, 0.5 * outer(inc, inc), times=times, x0=v[..., 0, :], kind="geometric", check=True)

    # ------------------------------------------------------------------ basic attributes
    @property
    def times(self) -> np.ndarray:
        """Grid times, shape ``(N + 1,)``."""
        return self._times

    @property
    def increments(self) -> np.ndarray:
        """Per-step increments, shape ``(..., N, d)``."""
        return self._increments

    @property
    def areas(self) -> np.ndarray | None:
        """Per-step areas (``iisignature`` ordering), shape ``(..., N, d, d)``; ``None`` at level 1."""
        return self._areas

    @property
    def step_levy_areas(self) -> np.ndarray:
        """Per-step Lévy areas ``½(XX - XXᵀ)`` (with the ½), shape ``(..., N, d, d)``."""
        self._need_level2("step_levy_areas")
        a = self._areas
        return 0.5 * (a - np.swapaxes(a, -1, -2))

    @property
    def x0(self) -> np.ndarray:
        """Starting point of the trace, shape ``(..., d)``."""
        return self._x0

    @property
    def kind(self) -> str | None:
        """``"geometric"``, ``"ito"``, ``"general"``, or ``None`` for a level-1 path."""
        return self._kind

    @property
    def level(self) -> int:
        """1 if the path carries no area, else 2."""
        return 1 if self._areas is None else 2

    @property
    def dim(self) -> int:
        """Dimension ``d`` of the trace."""
        return self._increments.shape[-1]

    @property
    def n_steps(self) -> int:
        """Number of grid steps ``N``."""
        return self._increments.shape[-2]

    @property
    def batch_shape(self) -> tuple:
        """Leading batch axes ``...``."""
        return self._increments.shape[:-2]

    @property
    def dt(self) -> np.ndarray:
        """Step sizes, shape ``(N,)``."""
        return np.diff(self._times)

    @property
    def path(self) -> np.ndarray:
        """The trace on the grid, ``x0`` plus cumulative increments, shape ``(..., N + 1, d)``."""
        p = self._cache.get("path")
        if p is None:
            rel = self._relative_path()
            p = rel + self._x0[..., None, :]
            self._cache["path"] = p
        return p

    def _relative_path(self) -> np.ndarray:
        rel = self._cache.get("rel")
        if rel is None:
            inc = self._increments
            rel = np.concatenate([np.zeros(inc.shape[:-2] + (1, inc.shape[-1])), np.cumsum(inc, axis=-2)], axis=-2)
            self._cache["rel"] = rel
        return rel

    def _cumulative_area(self) -> np.ndarray:
        """``XX_{t_0, t_k}`` for every k, shape ``(..., N + 1, d, d)`` (cached)."""
        c = self._cache.get("cum_area")
        if c is None:
            rel = self._relative_path()
            steps = self._areas + outer(rel[..., :-1, :], self._increments)
            c = np.concatenate([np.zeros(steps.shape[:-3] + (1,) + steps.shape[-2:]), np.cumsum(steps, axis=-3)], axis=-3)
            self._cache["cum_area"] = c
        return c

    def _need_level2(self, what: str) -> None:
        if self._areas is None:
            raise ValueError(f"{what} needs a level-2 rough path, but this path has no area (level 1); "
                             f"build it with areas, e.g. RoughPath.from_path(values) for the "
                             f"piecewise-linear lift.")

    # ------------------------------------------------------------------ queries
    def index_of(self, t, name: str = "t") -> np.ndarray:
        """Grid indices of the times ``t`` (scalar or array); each must be a grid point."""
        return grid_index(self._times, t, name)

    def _pair(self, s, t):
        i, j = self.index_of(s, "s"), self.index_of(t, "t")
        if np.any(i > j):
            raise ValueError("s must not exceed t (s <= t); for the reversed direction use "
                             "path.reverse() or the group inverse.")
        return i, j

    def increment(self, s, t) -> np.ndarray:
        """Increment :math:`X_{s,t}` over grid times ``s <= t``; shape ``(..., *q, d)`` for query shape ``q``."""
        i, j = self._pair(s, t)
        rel = self._relative_path()
        return rel[..., j, :] - rel[..., i, :]

    def area(self, s, t) -> np.ndarray:
        r"""Area :math:`\mathbb{X}_{s,t}` over grid times ``s <= t`` (Chen), shape ``(..., *q, d, d)``."""
        self._need_level2("area")
        i, j = self._pair(s, t)
        rel, c = self._relative_path(), self._cumulative_area()
        return c[..., j, :, :] - c[..., i, :, :] - outer(rel[..., i, :], rel[..., j, :] - rel[..., i, :])

    def levy_area(self, s, t) -> np.ndarray:
        r"""Lévy area :math:`\tfrac12(\mathbb{X}_{s,t} - \mathbb{X}_{s,t}^T)` (with the ½)."""
        a = self.area(s, t)
        return 0.5 * (a - np.swapaxes(a, -1, -2))

    # ------------------------------------------------------------------ transformations
    def restrict(self, times) -> "RoughPath":
        """The same rough path on a coarser grid (a subset of :attr:`times`), by Chen sums.

        The result covers ``[times[0], times[-1]]``; its ``x0`` is the trace at ``times[0]``.
        """
        tt = check_times(times, "times")
        idx = self.index_of(tt, "times")
        if np.any(np.diff(idx) <= 0):
            k = int(np.argmax(np.diff(idx) <= 0))
            raise ValueError(f"times[{k}]={float(tt[k])!r} and times[{k + 1}]={float(tt[k + 1])!r} are the same grid "
                             f"point of this rough path (to the grid tolerance); drop one of them.")
        rel = self._relative_path()
        inc = rel[..., idx[1:], :] - rel[..., idx[:-1], :]
        x0 = self.path[..., idx[0], :]
        if self._areas is None:
            return RoughPath(inc, None, times=self._times[idx], x0=x0, check=False)
        lo, hi = idx[0], idx[-1]
        seg = np.repeat(np.arange(idx.size - 1), np.diff(idx))          # coarse step of each fine step
        start = rel[..., idx[:-1], :][..., seg, :]                        # trace at the coarse step's start
        steps = self._areas[..., lo:hi, :, :] + outer(rel[..., lo:hi, :] - start, self._increments[..., lo:hi, :])
        areas = np.add.reduceat(steps, idx[:-1] - lo, axis=-3)
        return RoughPath(inc, areas, times=self._times[idx], x0=x0, kind=self._kind, check=False)

    def concatenate(self, other: "RoughPath") -> "RoughPath":
        """Append ``other`` after this path; its grid is shifted to start at ``self.times[-1]``.

        The trace is continued (``other.x0`` is ignored); batch shapes must agree.
        """
        if not isinstance(other, RoughPath):
            raise TypeError(f"other must be a RoughPath, got {type(other).__name__}.")
        if other.dim != self.dim or other.batch_shape != self.batch_shape:
            raise ValueError(f"cannot concatenate a path of batch shape {other.batch_shape} and d={other.dim} "
                             f"after one of batch shape {self.batch_shape} and d={self.dim}; they must match.")
        if (self._areas is None) != (other._areas is None):
            raise ValueError("cannot concatenate a level-1 and a level-2 path; drop the area of one "
                             "(path.to_level1()) or lift the other.")
        t = np.concatenate([self._times, other._times[1:] - other._times[0] + self._times[-1]])
        inc = np.concatenate([self._increments, other._increments], axis=-2)
        areas = None if self._areas is None else np.concatenate([self._areas, other._areas], axis=-3)
        kind = self._kind if self._kind == other._kind else "general"
        return RoughPath(inc, areas, times=t, x0=self._x0, kind=kind, check=False)

    def reverse(self) -> "RoughPath":
        r"""Time reversal :math:`u \mapsto X_{t_0 + t_N - u}`.

        Each step becomes its group inverse, :math:`(x, a) \mapsto (-x, -a + x\otimes x)`, in reversed
        order; the new ``x0`` is the old end point. Geometric paths stay geometric. An Itô path
        becomes ``kind="general"``: its reversal has :math:`\mathrm{Sym}(\mathbb{X}) = \tfrac12 X\otimes X
        + \tfrac12 (t - s) I`` (a backward-Itô area), not the Itô symmetric part.
        """
        t = self._times[0] + self._times[-1] - self._times[::-1]
        inc = -self._increments[..., ::-1, :]
        areas = None
        if self._areas is not None:
            areas = -self._areas[..., ::-1, :, :] + outer(inc, inc)
        kind = "general" if self._kind == "ito" else self._kind
        return RoughPath(inc, areas, times=t, x0=self.path[..., -1, :], kind=kind, check=False)

    def perturb(self, s) -> "RoughPath":
        r"""The path with area :math:`\mathbb{X}_{s,t} + \mathsf{s}\,(t - s)`.

        Parameters
        ----------
        s : array_like, shape ``(d, d)`` or ``(..., d, d)`` broadcasting against the batch
            Antisymmetric perturbation; a non-antisymmetric ``s`` is rejected because it would
            break geometricity.
        """
        self._need_level2("perturb")
        s = check_antisymmetric(s, "s", dim=self.dim)
        try:
            batch = np.broadcast_shapes(s.shape[:-2], self.batch_shape)
        except ValueError:
            raise ValueError(f"s has batch shape {s.shape[:-2]}, which does not broadcast against the "
                             f"path's batch shape {self.batch_shape}.") from None
        n, d = self.n_steps, self.dim
        areas = self._areas + s[..., None, :, :] * self.dt[:, None, None]
        inc = np.broadcast_to(self._increments, batch + (n, d))
        x0 = np.broadcast_to(self._x0, batch + (d,))
        return RoughPath(inc, areas, times=self._times, x0=x0, kind=self._kind, check=False)

    def to_level1(self) -> "RoughPath":
        """The trace alone (area dropped)."""
        return RoughPath(self._increments, None, times=self._times, x0=self._x0, check=False)

    def __getitem__(self, index) -> "RoughPath":
        """Index the batch axes only, e.g. ``X[0]`` or ``X[:10]``."""
        if not self.batch_shape:
            raise IndexError("this rough path has no batch axes to index.")
        probe = np.empty(self.batch_shape, dtype=bool)[index]  # validates the index on batch axes
        del probe
        # explicit trailing slices keep the core axes (N, d[, d]) untouched, also for X[..., k]
        idx = index if isinstance(index, tuple) else (index,)
        inc = self._increments[idx + (slice(None),) * 2]
        areas = None if self._areas is None else self._areas[idx + (slice(None),) * 3]
        x0 = self._x0[idx + (slice(None),)]
        return RoughPath(inc, areas, times=self._times, x0=x0, kind=self._kind, check=False)

    # ------------------------------------------------------------------ diagnostics
    def geometric_defect(self) -> np.ndarray:
        r"""Per-path :math:`\max_k |\mathrm{Sym}(\mathbb{X}_k) - \tfrac12 X_k\otimes X_k|`, shape ``(...)``."""
        self._need_level2("geometric_defect")
        return np.max(_geometric_defect(self._increments, self._areas), axis=-1)

    def __eq__(self, other) -> bool:
        """Same kind and level, and equal times, start, increments and areas (entry by entry, NaN equal)."""
        if not isinstance(other, RoughPath):
            return NotImplemented
        return (self._kind == other._kind and self.level == other.level
                and all(arrays_equal(getattr(self, n), getattr(other, n))
                        for n in ("_times", "_x0", "_increments", "_areas")))

    __hash__ = None

    def __repr__(self) -> str:
        return (f"RoughPath(level={self.level}, kind={self._kind!r}, d={self.dim}, n_steps={self.n_steps}, "
                f"batch_shape={self.batch_shape}, t=[{self._times[0]:g}, {self._times[-1]:g}])")


def _geometric_defect(inc: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """``max_{ij} |Sym(a) - ½ x⊗x|`` per step, shape ``(..., N)``."""
    sym = 0.5 * (areas + np.swapaxes(areas, -1, -2)) - 0.5 * outer(inc, inc)
    return np.max(np.abs(sym), axis=(-1, -2)) if sym.size else np.zeros(sym.shape[:-2])


def chen_defect(fine: RoughPath, coarse: RoughPath) -> float:
    r"""How far ``coarse`` is from ``fine`` restricted to the coarse grid (Chen sums).

    Returns :math:`\max |X^{c}_{k} - X^{f}_{t_k,t_{k+1}}| + \max|\mathbb{X}^{c}_k - \mathbb{X}^{f}_{t_k,t_{k+1}}|`
    over the coarse steps and the batch. The coarse grid must be a subset of the fine grid. Zero
    (to round-off) when ``coarse`` is a restriction of ``fine``, e.g. a refined Brownian path
    restricted back to its original grid.
    """
    if not isinstance(fine, RoughPath) or not isinstance(coarse, RoughPath):
        raise TypeError("fine and coarse must both be RoughPath objects.")
    r = fine.restrict(coarse.times)
    err = float(np.max(np.abs(r.increments - coarse.increments)))
    if fine.level == 2 and coarse.level == 2:
        err += float(np.max(np.abs(r.areas - coarse.areas)))
    return err


def grid_index(grid, t, name: str = "t") -> np.ndarray:
    """Indices into the increasing ``grid`` of the times ``t`` (scalar or array); each must be a grid point
    (to ``1e-10`` relative), else a ``ValueError`` names ``name``, the time and the grid."""
    tt = as_float_array(t, name)
    idx = np.clip(np.searchsorted(grid, tt), 0, grid.size - 1)
    left = np.clip(idx - 1, 0, grid.size - 1)
    idx = np.where(np.abs(grid[left] - tt) < np.abs(grid[idx] - tt), left, idx)
    tol = 1e-10 * max(1.0, float(np.max(np.abs(grid))))
    off = np.abs(grid[idx] - tt) > tol
    if np.any(off):
        bad = float(np.ravel(tt)[int(np.argmax(np.ravel(off)))])
        raise ValueError(f"{name}={bad!r} is not a grid time of this rough path (grid runs from "
                         f"{grid[0]!r} to {grid[-1]!r} in {grid.size - 1} steps); query grid times "
                         f"only, or refine/restrict the path to a grid containing it.")
    return idx
