r"""The result of :func:`~mechanics.ensemble.run.run_ensemble` and its save/load codec.

:class:`EnsembleResult` holds the across-path statistics of a run; it is registered with
:func:`roughpaths.register_format`, so ``roughpaths.save`` / ``roughpaths.load`` write and read it
(every :class:`~mechanics.ensemble.statistics.RunningMoments` as its count, mean and scatter).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughpaths import register_format
from roughpaths.validation import arrays_equal

from .statistics import RunningMoments, moments_problem, split_moment_features

__all__ = ["EnsembleResult"]


@dataclass(eq=False)
class EnsembleResult:
    """Output of :func:`run_ensemble`.

    Attributes
    ----------
    final : RunningMoments
        Across-path statistics of ``observable(μ_T)``.
    time_average : RunningMoments or None
        Across-path statistics of the per-path time averages over ``burn_in < n ≤ n_steps``
        (every ``average_every``-th step); None if that window is empty.
    snapshot_times : ndarray (S,)
    snapshots : list of RunningMoments
        Statistics of ``observable(μ_t)`` at ``snapshot_times``.
    final_states : ndarray (n_paths, n) or None
        Only with ``keep_final=True`` (memory ``O(n_paths)``).
    n_paths, n_steps, dt, seed
    """

    final: RunningMoments
    time_average: RunningMoments | None
    snapshot_times: np.ndarray
    snapshots: list
    final_states: np.ndarray | None
    n_paths: int
    n_steps: int
    dt: float
    seed: int
    state_dim: int = 0

    def __eq__(self, other) -> bool:
        """Equal statistics, snapshot times and final states (entry by entry) and equal sizes and seed."""
        if not isinstance(other, EnsembleResult):
            return NotImplemented
        return (self.final == other.final and self.time_average == other.time_average
                and self.snapshots == other.snapshots and arrays_equal(self.snapshot_times, other.snapshot_times)
                and arrays_equal(self.final_states, other.final_states)
                and (self.n_paths, self.n_steps, self.dt, self.seed, self.state_dim)
                == (other.n_paths, other.n_steps, other.dt, other.seed, other.state_dim))

    __hash__ = None

    def moments(self, which: str = "time_average"):
        """For the default observable: ``(mean (n,), second_moment (n, n), se_mean (n,), se_second (n, n))``
        of ``which`` in {"time_average", "final"}."""
        rm = self.time_average if which == "time_average" else self.final if which == "final" else None
        if rm is None:
            raise ValueError(f"which must be 'time_average' or 'final' (and that statistic must exist), got {which!r}.")
        n = self.state_dim
        if rm.dim != n + n * (n + 1) // 2:
            raise ValueError("moments() needs the default observable (moment_observable).")
        mean, m2 = split_moment_features(rm.mean, n)
        se_mean, se_m2 = split_moment_features(rm.standard_error, n)
        return mean, m2, se_mean, se_m2


def _moments_to_arrays(rm, prefix, arrays):
    arrays[prefix + "count"] = np.array(rm.count, dtype=np.int64)
    arrays[prefix + "mean"] = rm.mean
    arrays[prefix + "scatter"] = rm.scatter


def _moments_from_arrays(arrays, prefix):
    mean = arrays[prefix + "mean"]
    rm = RunningMoments(mean.shape[0])
    rm.count = int(arrays[prefix + "count"])
    rm.mean = np.array(mean, dtype=np.float64)
    rm.scatter = np.array(arrays[prefix + "scatter"], dtype=np.float64)
    return rm


def _encode_ensemble(res: "EnsembleResult"):
    arrays = {"snapshot_times": np.asarray(res.snapshot_times, dtype=np.float64)}
    _moments_to_arrays(res.final, "final_", arrays)
    if res.time_average is not None:
        _moments_to_arrays(res.time_average, "time_average_", arrays)
    for k, rm in enumerate(res.snapshots):
        _moments_to_arrays(rm, f"snapshot{k}_", arrays)
    if res.final_states is not None:
        arrays["final_states"] = res.final_states
    extra = {"n_paths": res.n_paths, "n_steps": res.n_steps, "dt": res.dt, "seed": res.seed,
             "state_dim": res.state_dim, "n_snapshots": len(res.snapshots),
             "has_time_average": res.time_average is not None}
    return extra, arrays


def _decode_ensemble(meta, arrays):
    """The inverse of :func:`_encode_ensemble`; refuses arrays that disagree with each other or the metadata, and
    statistics no run writes (:func:`~mechanics.ensemble.statistics.moments_problem`: counts beyond ``n_paths``,
    non-finite values, a scatter matrix that is not one)."""
    n, paths = meta["state_dim"], meta["n_paths"]
    for key in ("n_paths", "n_steps", "state_dim", "n_snapshots"):
        v = meta[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < (0 if key == "n_snapshots" else 1):
            raise ValueError(f"the metadata entry {key!r} is {v!r}, not a positive whole number")
    dt = meta["dt"]
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"the metadata entry 'dt' is {dt!r}, not a positive finite step")
    fs = arrays.get("final_states")
    if fs is not None and fs.shape != (paths, n):
        raise ValueError(f"final_states has shape {fs.shape}, but n_paths={paths} and state_dim={n}")
    dims = {arrays[k].shape for k in arrays if k.endswith("_mean")}
    scat = {arrays[k].shape for k in arrays if k.endswith("_scatter")}
    if len(dims) != 1 or {(d[0], d[0]) for d in dims} != scat or len(next(iter(dims))) != 1:
        raise ValueError(f"the statistics' means {sorted(dims)} and scatter matrices {sorted(scat)} disagree")
    if arrays["snapshot_times"].shape != (meta["n_snapshots"],):
        raise ValueError(f"snapshot_times has shape {arrays['snapshot_times'].shape}, but n_snapshots="
                         f"{meta['n_snapshots']}")
    names = ["final"] + (["time_average"] if meta["has_time_average"] else []) + [
        f"snapshot{k}" for k in range(meta["n_snapshots"])]
    for name in names:
        count = arrays[name + "_count"]
        count = int(count) if count.shape == () and count.dtype.kind in "iu" else count
        problem = moments_problem(name, count, arrays[name + "_mean"], arrays[name + "_scatter"], max_count=paths)
        if problem is not None:
            raise ValueError(problem)
    return EnsembleResult(
        final=_moments_from_arrays(arrays, "final_"),
        time_average=_moments_from_arrays(arrays, "time_average_") if meta["has_time_average"] else None,
        snapshot_times=arrays["snapshot_times"],
        snapshots=[_moments_from_arrays(arrays, f"snapshot{k}_") for k in range(meta["n_snapshots"])],
        final_states=arrays.get("final_states"), n_paths=meta["n_paths"], n_steps=meta["n_steps"],
        dt=meta["dt"], seed=meta["seed"], state_dim=meta["state_dim"])


# roughpaths.save / roughpaths.load write and read ensemble results (format in roughpaths.io)
register_format("EnsembleResult", EnsembleResult, _encode_ensemble, _decode_ensemble)
