r"""Save and load :class:`~roughpaths.RoughPath` and :class:`~roughpaths.Solution` objects.

One object per file, in NumPy's ``.npz`` format (a zip archive of ``.npy`` arrays), so a file can
also be read with plain :func:`numpy.load` and no pickling is ever involved (files are loaded with
``allow_pickle=False`` and are safe to open from anywhere). Arrays are stored bit for bit: a
round trip returns arrays whose bytes, dtype (``float64``) and shape are identical.

File format, version 1
----------------------
An ``.npz`` archive with these entries:

* ``__metadata__``: a 0-d unicode array holding one JSON object with the keys

  - ``format``: ``"roughpaths-npz"``; ``format_version``: ``1``, an integer raised whenever a
    reader of the previous version could misread a file (:func:`load` refuses a newer one);
  - ``type``: ``"RoughPath"`` or ``"Solution"``;
  - ``package``, ``package_version``, ``numpy_version``: who wrote the file; ``created``: the UTC
    time, ISO 8601;
  - ``conventions``: the area convention of the stored areas, ``XX[..., i, j]`` over
    :math:`[s, t]` being :math:`\int_s^t (X^i_r - X^i_s)\,dX^j_r` (the ordering of ``iisignature``
    and ``esig``), the Lévy area :math:`\tfrac12(\mathbb{X} - \mathbb{X}^T)` *with* the ½, and
    ``areas`` stored per grid step (the project's ``docs/conventions.md``);
  - ``seed``: the seed the data came from when the caller passes it to :func:`save` (an object
    does not know its seed), else ``null``;
  - ``user``: the caller's own JSON-serialisable ``metadata`` dict (``{}`` by default);
  - for a ``RoughPath``: ``kind``, ``level``, ``dim``, ``n_steps``, ``batch_shape``; for a
    ``Solution``: ``stats`` (tuples come back as tuples).

* for a ``RoughPath``: the arrays ``times`` ``(N + 1,)``, ``increments`` ``(..., N, d)``,
  ``areas`` ``(..., N, d, d)`` (absent for a level-1 path) and ``x0`` ``(..., d)``;
* for a ``Solution``: the arrays ``times`` ``(K,)``, ``states`` ``(..., K, e)`` and ``failed_step``
  (``int64``, the batch shape; see :attr:`roughpaths.Solution.failed_step`);
* for a type registered by another package (:func:`register_format`; ``mechanics`` registers
  ``EnsembleResult``): the arrays and metadata entries its encoder writes.

Writes are atomic: the file is written under a temporary name in the target folder and renamed
over the target only once complete, so a crash never leaves a half-written file under the name.

Files are untrusted input: :func:`load` and :func:`load_metadata` read through :func:`open_npz`, the
one reader of every file the library opens (also of ``mechanics``' ensemble checkpoints): regular
files only, every header and declared size checked against the stored bytes and the memory budget
before an array is read, no pickles; then the metadata is cross-checked against the arrays.
:func:`open_npz`, :class:`NpzReader` and :func:`atomic_savez` live in ``roughpaths._npz`` and are
public here.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from ._npz import _CHUNK, NpzReader, _fspath, atomic_savez, open_npz
from .paths.rough_path import RoughPath
from .rde.solution import Solution
from .validation import check_memory

__all__ = ["save", "load", "load_metadata", "register_format", "atomic_savez", "open_npz", "NpzReader", "FORMAT",
           "FORMAT_VERSION"]

FORMAT = "roughpaths-npz"
FORMAT_VERSION = 1
_META_KEY = "__metadata__"
_MAX_DEPTH = 64                  # metadata nesting, on save and on load
_FIX = "it is not a file written by roughpaths.save, or it is truncated, corrupt or forged"
_CONVENTIONS = {
    "area": "XX[..., i, j] over [s, t] = int_s^t (X^i_r - X^i_s) dX^j_r (iisignature/esig ordering: "
            "word (i, j) <-> entry [i, j])",
    "levy_area": "A = (XX - XX^T) / 2, with the 1/2",
    "areas": "per grid step: areas[..., k, :, :] is the area over [t_k, t_{k+1}]",
    "reference": "docs/conventions.md",
}
_ARRAYS = {"RoughPath": ("times", "increments", "x0"), "Solution": ("times", "states")}
#: Other packages' types: name -> (class, encode(obj) -> (extra metadata dict, arrays dict),
#: decode(metadata, arrays) -> obj). ``mechanics`` registers its ``EnsembleResult`` here.
_CODECS: dict = {}


def register_format(name: str, cls: type, encode, decode) -> None:
    """Teach :func:`save` and :func:`load` another type (used by ``mechanics`` for ``EnsembleResult``).

    Parameters
    ----------
    name : str
        The ``type`` written into the metadata.
    cls : type
        Instances of ``cls`` are saved with ``encode``.
    encode : callable ``obj -> (extra, arrays)``
        JSON-serialisable metadata entries and a dict of numpy arrays (any dtype but object).
    decode : callable ``(metadata, arrays) -> obj``
        The inverse; ``arrays`` holds every array that ``encode`` wrote.
    """
    if not isinstance(name, str) or name in _ARRAYS:
        raise ValueError(f"name must be a new type name (not one of {sorted(_ARRAYS)}), got {name!r}.")
    if not isinstance(cls, type) or not callable(encode) or not callable(decode):
        raise TypeError("register_format needs a class and two callables (encode, decode).")
    _CODECS[name] = (cls, encode, decode)


def _package_version() -> str:
    from ._version import __version__

    return __version__


def _to_json(value, where: str, depth: int = 0):
    """``value`` as JSON-ready data; tuples tagged so that they come back as tuples."""
    if depth > _MAX_DEPTH:
        raise ValueError(f"{where} is nested deeper than {_MAX_DEPTH} levels (or refers to itself); save flatter "
                         f"metadata.")
    if isinstance(value, tuple):
        return {"__tuple__": [_to_json(v, f"{where}[{i}]", depth + 1) for i, v in enumerate(value)]}
    if isinstance(value, list):
        return [_to_json(v, f"{where}[{i}]", depth + 1) for i, v in enumerate(value)]
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{where} has the key {k!r} of type {type(k).__name__}; only str keys can be "
                                f"saved (JSON).")
            out[k] = _to_json(v, f"{where}[{k!r}]", depth + 1)
        return out
    if isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise TypeError(f"{where} = {value!r} has type {type(value).__name__}, which cannot be saved as "
                    f"metadata; use str, int, float, bool, None, or lists/tuples/dicts of them.")


def _from_json(value):
    if isinstance(value, dict):
        if set(value) == {"__tuple__"}:
            return tuple(_from_json(v) for v in value["__tuple__"])
        return {k: _from_json(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_from_json(v) for v in value]
    return value


def save(obj, path, *, seed=None, metadata=None) -> Path:
    """Write a :class:`~roughpaths.RoughPath` or :class:`~roughpaths.Solution` to a ``.npz`` file.

    Parameters
    ----------
    obj : RoughPath or Solution
        What to save (any batch shape; arrays are stored bit for bit).
    path : str or os.PathLike
        Target file; ``.npz`` is appended when the name has another suffix (as :func:`numpy.savez`
        does). An existing file is replaced atomically.
    seed : int, optional
        The seed the data were generated from, recorded in the metadata (``None``: unknown).
    metadata : dict, optional
        Your own JSON-serialisable metadata (str keys; str, int, float, bool, None, lists, tuples,
        dicts), returned by :func:`load_metadata` under ``"user"``.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    TypeError
        ``obj`` is neither a ``RoughPath`` nor a ``Solution``, or the metadata is not serialisable.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from roughpaths import brownian_rough_path, save, load, load_metadata
    >>> X = brownian_rough_path(np.linspace(0.0, 1.0, 9), 2, np.random.default_rng(7))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     f = save(X, f"{tmp}/driver", seed=7)
    ...     Y = load(f)
    ...     meta = load_metadata(f)
    >>> f.name, Y.kind, meta["seed"], meta["format_version"]
    ('driver.npz', 'geometric', 7, 1)
    >>> bool(np.array_equal(Y.areas, X.areas))
    True
    """
    if isinstance(obj, RoughPath):
        kind = "RoughPath"
        arrays = {"times": obj.times, "increments": obj.increments, "x0": obj.x0}
        if obj.areas is not None:
            arrays["areas"] = obj.areas
        extra = {"kind": obj.kind, "level": obj.level, "dim": obj.dim, "n_steps": obj.n_steps,
                 "batch_shape": list(obj.batch_shape)}
    elif isinstance(obj, Solution):
        kind = "Solution"
        arrays = {"times": obj.times, "states": obj.states}
        if obj.failed_step is not None:
            arrays["failed_step"] = np.asarray(obj.failed_step, dtype=np.int64)
        extra = {"stats": _to_json(dict(obj.stats), "Solution.stats")}
    else:
        for name, (cls, encode, _) in _CODECS.items():
            if isinstance(obj, cls):
                kind = name
                extra, arrays = encode(obj)
                extra = _to_json(dict(extra), name)
                break
        else:
            raise TypeError(f"save() writes a RoughPath, a Solution or a registered type "
                            f"({sorted(_CODECS) or 'none registered'}), got {type(obj).__name__}; for other "
                            f"arrays use numpy.savez.")
    if seed is not None and not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be an int or None, got {seed!r} ({type(seed).__name__}).")
    if metadata is not None and not isinstance(metadata, dict):
        raise TypeError(f"metadata must be a dict or None, got {type(metadata).__name__}.")
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "type": kind,
        "package": "roughpaths-mechanics",
        "package_version": _package_version(),
        "numpy_version": np.__version__,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "conventions": _CONVENTIONS,
        "seed": None if seed is None else int(seed),
        "user": _to_json(metadata or {}, "metadata"),
        **extra,
    }
    payload = {name: np.asarray(a, order="C") for name, a in arrays.items()}   # keeps 0-d arrays 0-d
    try:
        payload[_META_KEY] = np.array(json.dumps(meta, ensure_ascii=False, allow_nan=False))   # strict JSON
    except ValueError:
        raise ValueError("metadata holds NaN or infinity, which strict JSON cannot store; pass finite numbers "
                         "(or strings such as 'nan') in metadata and stats.") from None

    target = Path(_fspath(path))
    if target.suffix != ".npz":
        target = target.with_name(target.name + ".npz")
    return atomic_savez(target, payload)


def _depth(value, limit: int = _MAX_DEPTH) -> None:
    """Refuse metadata nested deeper than ``limit`` (iteratively: a deep file cannot exhaust the stack)."""
    stack = [(value, 0)]
    while stack:
        v, level = stack.pop()
        if level > limit:
            raise ValueError(f"metadata nested deeper than {limit} levels")
        if isinstance(v, dict):
            stack.extend((x, level + 1) for x in v.values())
        elif isinstance(v, list):
            stack.extend((x, level + 1) for x in v)


def _metadata(npz: NpzReader) -> dict:
    p = npz.path
    if _META_KEY not in npz.entries:
        raise ValueError(f"{p} has no {_META_KEY!r} entry, so it was not written by roughpaths.save (it holds "
                         f"the arrays {sorted(npz.entries)}; read it with numpy.load).")
    shape, dtype = npz.entries[_META_KEY]
    if shape != () or dtype.kind != "U":
        raise npz.refuse(f"the metadata entry is an array of shape {shape} and dtype {dtype}, not a string")
    try:
        meta = json.loads(str(npz.read(_META_KEY)[()]))
        _depth(meta)
    except (ValueError, RecursionError) as exc:
        if str(exc).startswith(str(p)):
            raise
        raise ValueError(f"{p}: the metadata entry is unreadable ({type(exc).__name__}: {exc}); the file is "
                         f"corrupt.") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ValueError(f"{p}: the metadata does not declare format {FORMAT!r}; not a roughpaths file.")
    version = meta.get("format_version")
    if not isinstance(version, int) or version < 1:
        raise ValueError(f"{p}: invalid format_version {version!r}; the file is corrupt.")
    if version > FORMAT_VERSION:
        raise ValueError(f"{p} uses format version {version} (written by {meta.get('package')} "
                         f"{meta.get('package_version')}), newer than the version this roughpaths "
                         f"{_package_version()} reads ({FORMAT_VERSION}); upgrade roughpaths-mechanics to load it.")
    if meta.get("type") not in _ARRAYS and meta.get("type") not in _CODECS:
        hint = " (import mechanics to load an EnsembleResult)" if meta.get("type") == "EnsembleResult" else ""
        raise ValueError(f"{p}: unknown object type {meta.get('type')!r} (expected one of "
                         f"{sorted(_ARRAYS) + sorted(_CODECS)}){hint}.")
    return meta


def load_metadata(path) -> dict:
    """The metadata of a file written by :func:`save` (see the module documentation for the keys).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    dict
        Tuples saved in ``stats`` or ``user`` come back as tuples.

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        The file is not one written by :func:`save` (or not a regular file), is corrupt or truncated,
        or uses a newer format version than this package reads.
    """
    with open_npz(path, fix=_FIX) as npz:
        meta = _metadata(npz)
    return _from_json(meta)


def _check_reading_memory(npz: NpzReader, names, kind) -> None:
    """Refuse, before reading, what :func:`load` holds beyond the arrays (which :func:`open_npz` checked).

    With ``T`` bytes of arrays and ``A`` bytes of areas: zipfile's read buffer and its copy (``2 x 1 MiB``),
    the finiteness mask of the largest array (one byte per entry, ``T / 8``) and the check that the areas are
    geometric (three area-sized temporaries: the symmetric part, ½ x⊗x and their difference; four for Itô
    areas, whose Stratonovich form is made first), so ``2 MiB + T / 8 + 3 A`` (``4 A`` for Itô).
    """
    nbytes = {n: float(np.prod(npz.entries[n][0], dtype=float)) * npz.entries[n][1].itemsize for n in names}
    areas = nbytes.get("areas", 0.0)
    need = 2.0 * _CHUNK + max(nbytes.values(), default=0.0) / 8 + (4.0 if kind == "ito" else 3.0) * areas
    check_memory(need, f"the buffers and consistency checks of reading {npz.path} ({len(names)} arrays)",
                 "read it on a machine with more memory, or set ROUGHPATHS_MAX_BYTES if you trust it")


def load(path):
    """Read a :class:`~roughpaths.RoughPath` or :class:`~roughpaths.Solution` written by :func:`save`.

    The file is read through :func:`open_npz` (regular files only; every header and declared size
    checked before an array is read).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    RoughPath or Solution
        With arrays bitwise equal to the saved ones. A ``RoughPath`` is rebuilt through its
        validating constructor (with its saved ``kind``), so a damaged file cannot produce an
        inconsistent path.

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        The file is not one written by :func:`save` (or not a regular file), is corrupt or truncated,
        lacks an array, or uses a newer format version than this package reads.
    """
    with open_npz(path, fix=_FIX) as npz:
        p = npz.path
        meta = _metadata(npz)
        kind = meta["type"]
        if kind in _CODECS:
            arrays = {n: npz.read(n) for n in npz.entries if n != _META_KEY}
            try:
                return _CODECS[kind][2](_from_json(meta), arrays)
            except (KeyError, ValueError, TypeError) as exc:
                raise ValueError(f"{p}: the stored {kind} is inconsistent ({exc}); the file is corrupt.") from None
        names = _ARRAYS[kind] + (("areas",) if kind == "RoughPath" and meta.get("level") == 2 else ())
        if kind == "RoughPath" and meta.get("level") not in (1, 2):
            raise ValueError(f"{p}: metadata level {meta.get('level')!r}, expected 1 or 2; the file is corrupt.")
        if kind == "RoughPath" and meta.get("level") == 1 and "areas" in npz.entries:
            raise ValueError(f"{p}: the metadata says level 1 but the file holds areas; the file is corrupt.")
        missing = [n for n in names if n not in npz.entries]
        if missing:
            raise ValueError(f"{p}: the {kind} arrays {missing} are missing; the file is corrupt.")
        for n in names:
            dtype = npz.entries[n][1]
            if dtype != np.float64:
                raise ValueError(f"{p}: array {n!r} has dtype {dtype}, expected float64; the file is corrupt.")
        has_failed = kind == "Solution" and "failed_step" in npz.entries
        if has_failed:
            npz.expect("failed_step", dtype=np.int64)
        _check_reading_memory(npz, names, meta.get("kind"))
        arrays = {n: npz.read(n) for n in names}
        failed_arr = npz.read("failed_step") if has_failed else None
    if failed_arr is not None and failed_arr.shape != arrays["states"].shape[:-2]:
        raise ValueError(f"{p}: array 'failed_step' has dtype {failed_arr.dtype} and shape {failed_arr.shape}, "
                         f"expected int64 of the batch shape; the file is corrupt.")
    if kind == "Solution":
        if arrays["times"].ndim != 1 or arrays["states"].ndim < 2 or \
                arrays["states"].shape[-2] != arrays["times"].shape[0]:
            raise ValueError(f"{p}: times of shape {arrays['times'].shape} and states of shape "
                             f"{arrays['states'].shape} disagree (states must be (..., len(times), e)); the file is "
                             f"corrupt.")
        return Solution(times=arrays["times"], states=arrays["states"], failed_step=failed_arr,
                        stats=_from_json(meta.get("stats", {})))
    try:
        X = RoughPath(arrays["increments"], arrays.get("areas"), times=arrays["times"], x0=arrays["x0"],
                      kind=meta.get("kind"))
    except ValueError as exc:
        raise ValueError(f"{p}: the stored rough path is inconsistent ({exc}); the file is corrupt.") from None
    bs = meta.get("batch_shape")
    declared = (meta.get("dim"), meta.get("n_steps"), tuple(bs) if isinstance(bs, list) else bs)
    if declared != (X.dim, X.n_steps, tuple(X.batch_shape)):
        raise ValueError(f"{p}: the metadata declares dim, n_steps, batch_shape = {declared}, the arrays have "
                         f"{(X.dim, X.n_steps, tuple(X.batch_shape))}; the file is corrupt.")
    if X.kind == "ito":                       # Itô areas: Sym(XX) = ½ X⊗X − ½ h I
        h = np.diff(X.times)[:, None, None]
        strat = arrays["areas"] + 0.5 * h * np.eye(X.dim)
        sym = 0.5 * (strat + np.swapaxes(strat, -1, -2)) - 0.5 * arrays["increments"][..., :, None] * \
            arrays["increments"][..., None, :]
        scale = 1.0 + float(np.max(np.abs(strat), initial=0.0))
        if float(np.max(np.abs(sym), initial=0.0)) > 1e-9 * scale:
            raise ValueError(f"{p}: the metadata says kind 'ito' but the areas' symmetric part is not "
                             f"½ X⊗X − ½ h I (off by {float(np.max(np.abs(sym))):.3g}); the file is corrupt.")
    return X
