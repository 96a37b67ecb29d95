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


def _identity(obj, name: str) -> bytes:
    """Bytes that identify ``obj`` across processes, or a refusal: a checkpoint never guesses.

    A picklable object is identified by its pickle (a module-level function by its module and name) and,
    for a function, by its code too (an edited body is another function). A lambda, a closure or a local
    function does not pickle: nothing can prove that a later run passes the same one.
    """
    try:
        ident = pickle.dumps(obj)
    except Exception:                      # noqa: BLE001 - whatever pickling raises, the answer is the same
        raise ValueError(f"{name}={obj!r} cannot be identified across runs (a lambda, a closure or a local "
                         f"function, or an object holding one), so a resumed run could not prove it is the "
                         f"same; with checkpoint=..., define {name} at module level (or as a picklable "
                         f"callable object), or run without a checkpoint.") from None
    code = getattr(obj, "__code__", None)
    if code is not None:
        ident += code.co_code + repr(code.co_consts).encode()
    return ident


def fingerprint(system, mu0, dt, n_steps, n_paths, seed, method, levy_area, burn_in, average_every,
                 record_every, chunk_size, keep_final, observable) -> str:
    """A digest of what determines the numbers of a run (a checkpoint of another run is refused).

    Raises ``ValueError`` when the system, the solver or the observable cannot be identified (see
    :func:`_identity`).
    """
    h = hashlib.sha256()
    for part in (_identity(system, "system"), _identity(method, "method"), _identity(observable, "observable"),
                 pickle.dumps((float(dt), int(n_steps), int(n_paths), int(seed), levy_area, int(burn_in),
                               int(average_every), record_every, int(chunk_size), bool(keep_final)))):
        h.update(part)
    h.update(np.ascontiguousarray(mu0).tobytes())
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
    try:
        layout = json.loads(str(arrays["__layout__"]))
    except (KeyError, ValueError) as exc:
        raise ValueError(f"checkpoint {os.fspath(path)!r} has no readable layout ({exc}); delete it to start the "
                         f"run afresh.") from None

    def reducer(name):
        red = LeafReducer(arrays[name + "_mean"].shape[0])
        red.moments.count = int(arrays[name + "_count"])
        red.moments.mean = np.array(arrays[name + "_mean"])
        red.moments.scatter = np.array(arrays[name + "_scatter"])
        red._pending = np.array(arrays[name + "_pending"]).reshape(-1, red.moments.dim)
        return red

    try:
        final = reducer("final")
        tavg = reducer("tavg") if layout["tavg"] else None
        snaps = [reducer(f"snap{k}") for k in range(layout["snaps"])]
        finals = [arrays[f"finals{k}"] for k in range(layout["finals"])]
        done = int(arrays["__done__"])
    except (KeyError, ValueError, TypeError) as exc:
        raise ValueError(f"checkpoint {os.fspath(path)!r} is incomplete or damaged ({type(exc).__name__}: {exc}); "
                         f"delete it to start the run afresh.") from None
    return done, final, tavg, snaps, finals
