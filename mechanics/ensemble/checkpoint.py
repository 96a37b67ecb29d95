"""Checkpoints of :func:`mechanics.run_ensemble`: the statistics merged so far, saved after every chunk.

A checkpoint is an ``.npz`` file (written atomically by :func:`roughpaths.io.atomic_savez`) holding
the number of chunks done, the state of every :class:`~mechanics.ensemble.statistics.LeafReducer` (count,
mean, scatter and the rows of its unfinished leaf), the final states kept so far, and a SHA-256
fingerprint of the run's arguments. Resuming restores the reducers exactly, so the merge sequence, and
hence every bit of the result, is that of an uninterrupted run.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import zipfile
from pathlib import Path

import numpy as np

from roughpaths.io import atomic_savez

from .statistics import LeafReducer

__all__ = ["fingerprint", "save_checkpoint", "load_checkpoint"]


def fingerprint(system, mu0, dt, n_steps, n_paths, seed, method, levy_area, burn_in, average_every,
                 record_every, chunk_size, keep_final, observable) -> str:
    """A digest of what determines the numbers of a run (a checkpoint of another run is refused)."""
    h = hashlib.sha256()
    for part in (repr(system), repr(method), getattr(observable, "__qualname__", repr(observable)),
                 (float(dt), int(n_steps), int(n_paths), int(seed), levy_area, int(burn_in), int(average_every),
                  record_every, int(chunk_size), bool(keep_final))):
        h.update(pickle.dumps(part))
    h.update(np.ascontiguousarray(mu0).tobytes())
    try:                                   # the whole system when it pickles (inertia, Hamiltonian, ...)
        h.update(pickle.dumps(system))
    except Exception:                      # noqa: BLE001 - user callables that do not pickle: repr and arrays
        pass
    for name in ("xi", "s"):
        value = getattr(system, name, None)
        if value is not None:
            h.update(np.ascontiguousarray(np.asarray(value, dtype=np.float64)).tobytes())
    return h.hexdigest()


def save_checkpoint(path, fingerprint, done, final, tavg, snaps, finals) -> None:
    """Write the merged statistics after ``done`` chunks to ``path`` atomically (temporary file + rename)."""
    arrays = {"__fingerprint__": np.array(fingerprint), "__done__": np.array(done, dtype=np.int64),
              "__layout__": np.array(json.dumps({"tavg": tavg is not None, "snaps": len(snaps),
                                                 "finals": len(finals)}))}
    for name, red in [("final", final), ("tavg", tavg)] + [(f"snap{k}", r) for k, r in enumerate(snaps)]:
        if red is None:
            continue
        arrays[name + "_count"] = np.array(red.moments.count, dtype=np.int64)
        arrays[name + "_mean"] = red.moments.mean
        arrays[name + "_scatter"] = red.moments.scatter
        arrays[name + "_pending"] = red._pending
    for k, fs in enumerate(finals):
        arrays[f"finals{k}"] = fs
    atomic_savez(path, arrays)


def load_checkpoint(path, fingerprint):
    """``(chunks done, final, tavg, snaps, finals)`` from ``path``, or None if it does not exist."""
    target = Path(os.fspath(path))
    for stale in target.parent.glob(f".{target.name}.*.tmp"):      # left by a run killed while writing
        try:
            stale.unlink()
        except OSError:
            pass
    if not target.exists():
        return None
    try:
        with np.load(target, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise ValueError(f"checkpoint {os.fspath(path)!r} is unreadable ({exc}); delete it to start the run "
                         f"afresh.") from None
    if str(arrays.get("__fingerprint__", "")) != fingerprint:
        raise ValueError(f"checkpoint {os.fspath(path)!r} belongs to a run with other arguments (system, mu0, "
                         f"sizes, seed, method or observable); pass another checkpoint file or delete this one.")
    layout = json.loads(str(arrays["__layout__"]))

    def reducer(name):
        red = LeafReducer(arrays[name + "_mean"].shape[0])
        red.moments.count = int(arrays[name + "_count"])
        red.moments.mean = np.array(arrays[name + "_mean"])
        red.moments.scatter = np.array(arrays[name + "_scatter"])
        red._pending = np.array(arrays[name + "_pending"]).reshape(-1, red.moments.dim)
        return red

    final = reducer("final")
    tavg = reducer("tavg") if layout["tavg"] else None
    snaps = [reducer(f"snap{k}") for k in range(layout["snaps"])]
    finals = [arrays[f"finals{k}"] for k in range(layout["finals"])]
    return int(arrays["__done__"]), final, tavg, snaps, finals
