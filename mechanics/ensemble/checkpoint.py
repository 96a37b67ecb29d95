"""Checkpoints of :func:`mechanics.run_ensemble`: the statistics merged so far, saved after every chunk.

A checkpoint is an ``.npz`` file (written atomically by :func:`roughpaths.io.atomic_savez`) holding
the number of chunks done, the state of every :class:`~mechanics.ensemble.statistics.LeafReducer` (count,
mean, scatter and the rows of its unfinished leaf), the final states kept so far, and a SHA-256
fingerprint of the run. Resuming restores the reducers exactly, so the merge sequence, and hence every
bit of the result, is that of an uninterrupted run.

What the fingerprint identifies (:func:`fingerprint`). The run's numerical arguments; the ``system``,
``method`` and ``observable`` by their pickles (protocol 2, so every function or class they refer to
appears by name); the versions of ``roughpaths-mechanics`` and numpy; and ``code_version``. Data
(arrays, numbers) and the library's own code (``roughpaths``, ``mechanics``, numpy) are identified
completely. Code from anywhere else is not: a pickle names a function, and what the function
computes can change while its name stays (an edited body, a global or a helper it reads, a file).
So a checkpointed run whose system, method or observable refers to any such code is refused unless
the caller passes ``code_version``, a string they change whenever that code changes; the fingerprint
never claims an identity it cannot check.

Loading (:func:`load_checkpoint`) treats the file as untrusted: it is opened with
:func:`roughpaths.io.open_npz` (regular files only, every header and declared size checked against the
memory budget before a byte of an array is read), every entry is checked against the shapes the run
implies before it is read, and every value after (chunks done within the run, counts equal to the
paths those chunks hold, finite statistics, symmetric scatter matrices with non-negative diagonal).
A damaged or tampered file is refused, naming it and saying to delete it.
"""

from __future__ import annotations

import hashlib
import json
import pickle
import pickletools

import numpy as np

from roughpaths import __version__ as _package_version
from roughpaths.io import atomic_savez, open_npz

from .statistics import LEAF, LeafReducer, moments_problem

__all__ = ["fingerprint", "save_checkpoint", "load_checkpoint", "LIBRARY_MODULES"]

#: Top-level modules whose code a fingerprint identifies by name: the library's own (its version is
#: fingerprinted), numpy (likewise) and the standard modules that protocol-2 pickles of plain data use.
LIBRARY_MODULES = frozenset({"roughpaths", "mechanics", "numpy", "builtins", "copyreg", "_codecs"})
_OPCODES_BY_NAME = {"GLOBAL", "STACK_GLOBAL", "INST", "EXT1", "EXT2", "EXT4"}


def _foreign_code(data: bytes) -> list:
    """The functions and classes outside :data:`LIBRARY_MODULES` that the pickle ``data`` refers to by name."""
    foreign = []
    for op, arg, _ in pickletools.genops(data):
        if op.name in ("GLOBAL", "INST"):
            module, name = arg.split(" ", 1)
            if module.split(".", 1)[0] not in LIBRARY_MODULES:
                foreign.append(f"{module}.{name}")
        elif op.name in _OPCODES_BY_NAME:             # protocol 2 writes GLOBAL; anything else is not identifiable
            foreign.append(f"<{op.name} {arg!r}>")
    return sorted(set(foreign))


def _identity(obj, name: str):
    """``(bytes identifying obj, foreign code it refers to)``, or a refusal if it does not pickle."""
    try:
        ident = pickle.dumps(obj, protocol=2, fix_imports=False)
    except Exception:                      # noqa: BLE001 - whatever pickling raises, the answer is the same
        raise ValueError(f"{name}={obj!r} cannot be identified across runs (a lambda, a closure or a local "
                         f"function, or an object holding one), so a resumed run could not prove it is the "
                         f"same; with checkpoint=..., define {name} at module level (or as a picklable "
                         f"callable object), or run without a checkpoint.") from None
    code = getattr(obj, "__code__", None)
    if code is not None:                   # an extra check for a function passed directly: its own bytecode
        ident += code.co_code + repr(code.co_consts).encode()
    return ident, _foreign_code(ident)


def fingerprint(system, mu0, dt, n_steps, n_paths, seed, method, levy_area, burn_in, average_every,
                record_every, chunk_size, keep_final, observable, code_version=None) -> str:
    """A SHA-256 digest of what determines the numbers of a run (a checkpoint of another run is refused).

    Parameters
    ----------
    system, mu0, dt, n_steps, n_paths, seed, method
        The run's arguments, as checked by :func:`~mechanics.run_ensemble`.
    levy_area : tuple
        The pair ``(levy_area, levy_area_error)``.
    burn_in, average_every, record_every, chunk_size, keep_final, observable
        The run's arguments.
    code_version : str, optional
        Required when ``system``, ``method`` or ``observable`` refers to code outside
        :data:`LIBRARY_MODULES`; part of the digest.

    Returns
    -------
    str
        64 hexadecimal digits.

    Raises
    ------
    ValueError
        ``system``, ``method`` or ``observable`` does not pickle (a lambda, a closure), or refers to code
        outside the library and ``code_version`` is not given.
    TypeError
        ``code_version`` is not a non-empty string.

    Examples
    --------
    >>> import numpy as np, mechanics
    >>> body = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.2)
    >>> args = (body, np.zeros(3), 0.01, 10, 4, 0, mechanics.LieHeun(), (None, None), 0, 1, None, 2, False)
    >>> a = fingerprint(*args, mechanics.moment_observable)
    >>> a == fingerprint(*args, mechanics.moment_observable), len(a)
    (True, 64)
    """
    if code_version is not None and (not isinstance(code_version, str) or not code_version.strip()):
        raise TypeError(f"code_version must be a non-empty string naming the version of your own code (e.g. "
                        f"'energy-observable-2'), got {code_version!r}.")
    h = hashlib.sha256()
    foreign = {}
    for name, obj in (("system", system), ("method", method), ("observable", observable)):
        ident, refs = _identity(obj, name)
        h.update(hashlib.sha256(ident).digest())
        if refs:
            foreign[name] = refs
    if foreign and code_version is None:
        listed = "; ".join(f"{k} refers to {', '.join(v)}" for k, v in foreign.items())
        raise ValueError(f"with checkpoint=..., a resumed run must prove it computes what the interrupted run "
                         f"computed, but {listed}: code outside roughpaths, mechanics and numpy, which a "
                         f"checkpoint knows by name only (its body, the globals and helpers it reads can change "
                         f"under the same name). Pass code_version='...' (any string; change it whenever that "
                         f"code changes, and the old checkpoint is refused), use the built-in observable, or "
                         f"run without a checkpoint.")
    h.update(pickle.dumps((float(dt), int(n_steps), int(n_paths), int(seed), levy_area, int(burn_in),
                           int(average_every), record_every, int(chunk_size), bool(keep_final), code_version,
                           _package_version, np.__version__), protocol=2))
    mu0 = np.ascontiguousarray(mu0, dtype=np.float64)
    h.update(repr(mu0.shape).encode() + mu0.tobytes())
    return h.hexdigest()


def save_checkpoint(path, fingerprint, done, final, tavg, snaps, finals) -> None:
    """Write the merged statistics after ``done`` chunks to ``path`` atomically (temporary file + rename)."""
    arrays = {"__fingerprint__": np.array(fingerprint), "__done__": np.array(done, dtype=np.int64),
              "__layout__": np.array(json.dumps({"tavg": tavg is not None, "snaps": len(snaps),
                                                 "finals": len(finals)}))}
    for name, red in _reducers(final, tavg, snaps):
        arrays[name + "_count"] = np.array(red.moments.count, dtype=np.int64)
        arrays[name + "_mean"] = red.moments.mean
        arrays[name + "_scatter"] = red.moments.scatter
        arrays[name + "_pending"] = red._pending
    for k, fs in enumerate(finals):
        arrays[f"finals{k}"] = fs
    atomic_savez(path, arrays)


def _reducers(final, tavg, snaps):
    return [(name, red) for name, red in [("final", final), ("tavg", tavg)] + [(f"snap{k}", r) for k, r in
                                                                             enumerate(snaps)] if red is not None]


def load_checkpoint(path, fingerprint, *, bounds, dim, state_dim, time_average, n_snapshots, keep_final):
    """``(chunks done, final, tavg, snaps, finals)`` from the checkpoint ``path``, or None if there is none.

    Parameters
    ----------
    path : str or os.PathLike
    fingerprint : str
        The run's :func:`fingerprint`; a checkpoint of another run is refused.
    bounds : list of (int, int)
        The run's chunks, ``[first_path, last_path)`` each, in order.
    dim : int
        Values per state of the observable (``p``).
    state_dim : int
        The system's dimension ``n`` (the final states kept are ``(chunk paths, n)``).
    time_average : bool
        Whether the run has time averages (a non-empty averaging window).
    n_snapshots : int
        Snapshot statistics of the run (0 without ``record_every``).
    keep_final : bool
        Whether the run keeps the final states.

    Returns
    -------
    tuple or None
        ``(done, final, tavg, snaps, finals)``: chunks done, the reducers (``tavg`` None without time
        averages), the list of snapshot reducers and the list of kept final-state arrays.

    Raises
    ------
    ValueError
        The file is not a regular file, is unreadable, belongs to another run, or holds anything the
        run could not have written (names the file and says to delete it).
    """
    fix = "delete it to start the run afresh"
    try:
        npz = open_npz(path, fix=f"it is not a checkpoint run_ensemble can resume; {fix}",
                       what="the checkpoint's arrays")
    except FileNotFoundError:
        return None
    with npz:
        def refuse(problem):
            return ValueError(f"checkpoint {str(npz.path)!r} is incomplete or damaged ({problem}); {fix}.")

        if "__fingerprint__" not in npz.entries:
            raise refuse("it has no fingerprint")
        shape, dtype = npz.entries["__fingerprint__"]
        if shape != () or dtype != np.dtype("<U64"):
            raise refuse(f"its fingerprint is an array of shape {shape} and dtype {dtype}, not 64 hex digits")
        if str(npz.read("__fingerprint__")[()]) != fingerprint:
            raise ValueError(f"checkpoint {str(npz.path)!r} belongs to a run with other arguments (system, mu0, "
                             f"sizes, seed, method, observable, code_version, or the library's version); pass "
                             f"another checkpoint file or delete this one.")
        for key in ("__done__", "__layout__"):
            if key not in npz.entries:
                raise refuse(f"{key!r} is missing")
        if npz.entries["__done__"] != ((), np.dtype(np.int64)):
            raise refuse(f"'__done__' is {npz.entries['__done__']}, not an int64 scalar")
        done = int(npz.read("__done__")[()])
        if not 1 <= done <= len(bounds):
            raise refuse(f"it says {done} chunks are done, but the run has {len(bounds)} (at least 1 is done "
                         f"when a checkpoint is written)")
        shape, dtype = npz.entries["__layout__"]
        if shape != () or dtype.kind != "U" or dtype.itemsize > 4 * 1024:
            raise refuse(f"'__layout__' is an array of shape {shape} and dtype {dtype}, not a short string")
        want_layout = {"tavg": bool(time_average), "snaps": int(n_snapshots),
                       "finals": done if keep_final else 0}
        try:
            layout = json.loads(str(npz.read("__layout__")[()]))
        except ValueError as exc:
            if str(exc).startswith(str(npz.path)):
                raise
            raise refuse(f"its layout is not JSON: {exc}") from None
        if layout != want_layout:
            raise refuse(f"its layout {layout!r} is not the run's {want_layout!r}")

        # every entry the run writes after `done` chunks, with its shape, checked from the headers first
        paths = bounds[done - 1][1]
        count, pending = (paths // LEAF) * LEAF, paths % LEAF
        p = int(dim)
        names = ["final"] + (["tavg"] if time_average else []) + [f"snap{k}" for k in range(n_snapshots)]
        want = {"__fingerprint__": ((), np.dtype("<U64")), "__done__": ((), np.dtype(np.int64)),
                "__layout__": npz.entries["__layout__"]}
        for name in names:
            want[name + "_count"] = ((), np.dtype(np.int64))
            want[name + "_mean"] = ((p,), np.dtype(np.float64))
            want[name + "_scatter"] = ((p, p), np.dtype(np.float64))
            want[name + "_pending"] = ((pending, p), np.dtype(np.float64))
        for k in range(want_layout["finals"]):
            want[f"finals{k}"] = ((bounds[k][1] - bounds[k][0], int(state_dim)), np.dtype(np.float64))
        extra = sorted(set(npz.entries) - set(want))
        if extra:
            raise refuse(f"it holds entries the run does not write: {extra[:5]}")
        for key, (shape, dtype) in want.items():
            if key not in npz.entries:
                raise refuse(f"the entry {key!r} is missing")
            if npz.entries[key] != (shape, dtype):
                got = npz.entries[key]
                raise refuse(f"{key!r} has shape {got[0]} and dtype {got[1]}, but after {done} chunks ({paths} "
                             f"paths) the run has shape {shape} and dtype {dtype}")

        def reducer(name):
            stored = int(npz.read(name + "_count")[()])
            if stored != count:
                raise refuse(f"{name + '_count'!r} is {stored}, but {done} chunks hold {paths} paths, of which "
                             f"{count} are in complete leaves of {LEAF}")
            mean, scatter, rows = (npz.read(name + s) for s in ("_mean", "_scatter", "_pending"))
            if not np.all(np.isfinite(rows)):
                raise refuse(f"{name + '_pending'!r} holds non-finite values")
            problem = moments_problem(name, count, mean, scatter)
            if problem is not None:
                raise refuse(problem)
            red = LeafReducer(p)
            red.moments.count, red.moments.mean, red.moments.scatter = count, mean, scatter
            red._pending = rows
            return red

        final = reducer("final")
        tavg = reducer("tavg") if time_average else None
        snaps = [reducer(f"snap{k}") for k in range(n_snapshots)]
        finals = []
        for k in range(want_layout["finals"]):
            fs = npz.read(f"finals{k}")
            if not np.all(np.isfinite(fs)):
                raise refuse(f"'finals{k}' holds non-finite states")
            finals.append(fs)
    return done, final, tavg, snaps, finals
