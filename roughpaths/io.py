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
"""

from __future__ import annotations

import json
import os
import stat
import tempfile
import zipfile
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from .paths.rough_path import RoughPath
from .validation import check_memory
from .rde.solution import Solution

__all__ = ["save", "load", "load_metadata", "register_format", "atomic_savez", "open_npz", "NpzReader", "FORMAT",
           "FORMAT_VERSION"]

FORMAT = "roughpaths-npz"
FORMAT_VERSION = 1
_META_KEY = "__metadata__"
_MAX_DEPTH = 64                  # metadata nesting, on save and on load
_MAX_EXPANSION = 200             # compressed entries expanding more than this (and past 64 MiB): refused
_CHUNK = 1 << 24                 # bytes per read when an array is read from an archive
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


def _fspath(path):
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a str or os.PathLike naming a .npz file, got {type(path).__name__}.")
    p = os.fspath(path)
    if "\0" in str(p):
        raise ValueError(f"path must not contain a null byte, got {p!r}; pass a plain file name.")
    return p


def _remove_stale_temporaries(target: Path) -> None:
    """Delete ``.NAME.PID.*.tmp`` files that a writer of ``target`` killed mid-write left (its PID is gone)."""
    for stale in target.parent.glob(f".{target.name}.*.tmp"):
        pid = stale.name[len(target.name) + 2:].split(".", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            os.kill(int(pid), 0)                  # raises if no such process: its temporary is stale
        except ProcessLookupError:
            try:
                stale.unlink()
            except OSError:
                pass
        except OSError:                           # it exists (another user's): leave its file alone
            pass


def atomic_savez(target, arrays: dict) -> Path:
    """Write ``arrays`` to the ``.npz`` file ``target`` atomically (a temporary file in the same folder,
    flushed to disk, then renamed over ``target``): a crash or kill never leaves a partial file under
    the name; the temporary of a writer killed mid-write is removed by the next write. Returns the path
    written."""
    target = Path(os.fspath(target))
    _remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return target


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


class NpzReader:
    """An ``.npz`` archive opened by :func:`open_npz`: its entries' headers checked, its arrays read on demand.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    entries : dict
        ``name -> (shape, dtype)`` of every array, as its ``.npy`` header declares it (``name`` without
        ``.npy``); already checked against the stored bytes and the memory budget.
    """

    def __init__(self, path: Path, fh, zf: zipfile.ZipFile, entries: dict, infos: dict, fix: str):
        self.path, self.entries, self._fh, self._zip, self._infos, self._fix = path, entries, fh, zf, infos, fix

    def __enter__(self) -> "NpzReader":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the file (also done on leaving a ``with`` block)."""
        self._zip.close()
        self._fh.close()

    def refuse(self, problem: str) -> ValueError:
        """A ``ValueError`` naming the file, the problem and the fix given to :func:`open_npz` (to raise)."""
        return ValueError(f"{self.path}: {problem}; {self._fix}.")

    def read(self, name: str, *, dtype=None, shape=None) -> np.ndarray:
        """The array ``name``, read in full (its size was checked when the file was opened).

        Parameters
        ----------
        name : str
            An entry of :attr:`entries`.
        dtype : numpy dtype, optional
            Refuse (``ValueError``) unless the array has exactly this dtype.
        shape : tuple, optional
            Refuse unless the array has exactly this shape. Both are checked from the header, before
            the array is allocated.

        Returns
        -------
        numpy.ndarray
            A new array of the declared shape and dtype.
        """
        if name not in self.entries:
            raise self.refuse(f"the array {name!r} is missing (the file holds {sorted(self.entries)})")
        self.expect(name, dtype=dtype, shape=shape)
        declared_shape, declared_dtype = self.entries[name]
        try:
            with self._zip.open(self._infos[name]) as fh:
                header = _read_npy_header(fh)
                if header[:2] != (declared_shape, declared_dtype):
                    raise self.refuse(f"the header of {name!r} changed while the file was read")
                fortran = header[2]
                count = int(np.prod(declared_shape, dtype=np.int64))
                flat = np.empty(count, dtype=declared_dtype)
                view = memoryview(flat).cast("B") if flat.nbytes else memoryview(b"")
                got = 0
                while got < flat.nbytes:
                    n = fh.readinto(view[got:got + _CHUNK])
                    if not n:
                        raise self.refuse(f"the array {name!r} is truncated ({got} of {flat.nbytes} bytes)")
                    got += n
                if fh.read(1):
                    raise self.refuse(f"the array {name!r} holds more bytes than its header declares")
        except (zipfile.BadZipFile, OSError, EOFError, RuntimeError, NotImplementedError) as exc:
            raise self.refuse(f"the array {name!r} is unreadable ({type(exc).__name__}: {exc})") from None
        if fortran:
            return flat.reshape(declared_shape[::-1]).transpose()
        return flat.reshape(declared_shape)

    def expect(self, name: str, *, dtype=None, shape=None) -> None:
        """Refuse (``ValueError`` naming the file) unless the entry ``name`` has this dtype and shape."""
        if name not in self.entries:
            raise self.refuse(f"the array {name!r} is missing (the file holds {sorted(self.entries)})")
        got_shape, got_dtype = self.entries[name]
        if dtype is not None and got_dtype != np.dtype(dtype):
            raise self.refuse(f"the array {name!r} has dtype {got_dtype}, expected {np.dtype(dtype)}")
        if shape is not None and tuple(got_shape) != tuple(shape):
            raise self.refuse(f"the array {name!r} has shape {got_shape}, expected {tuple(shape)}")


def _read_npy_header(fh):
    """``(shape, dtype, fortran_order)`` from the ``.npy`` header at the start of ``fh`` (versions 1 and 2)."""
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
    else:
        raise ValueError(f".npy format version {version} (1.0 and 2.0 are read)")
    return tuple(int(s) for s in shape), dtype, bool(fortran)


def open_npz(path, *, fix: str = _FIX, what: str = "the arrays") -> NpzReader:
    """Open an ``.npz`` file as untrusted input: the one reader of every file the library opens.

    :func:`load`, :func:`load_metadata` and ``mechanics``' ensemble checkpoints read through it. Before
    any array is read it checks that ``path`` is a regular file (opened without blocking, then
    ``fstat``: a named pipe, a device or a folder is refused, never waited on), that it is a zip
    archive of ``.npy`` entries (no pickled objects, no duplicate or foreign entries), that every
    header declares exactly the bytes stored, that the compressed entries do not expand more than
    ``200x`` past 64 MiB (a zip bomb), and that the declared sizes fit
    :func:`roughpaths.validation.check_memory`. Reading an array then allocates what its header
    declared and checks the stored CRC.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    fix : str
        What the caller tells the user to do when the file is refused (ends every message).
    what : str
        What the arrays are, for the memory-budget message (e.g. ``"the checkpoint's arrays"``).

    Returns
    -------
    NpzReader
        Use it in a ``with`` block (it holds the open file).

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        Anything above, each message naming the file, the problem and ``fix``.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     f = atomic_savez(f"{tmp}/a.npz", {"x": np.arange(6.0).reshape(2, 3)})
    ...     with open_npz(f) as npz:
    ...         shapes = npz.entries
    ...         x = npz.read("x", dtype=np.float64, shape=(2, 3))
    >>> shapes["x"][0], float(x[1, 2])
    ((2, 3), 5.0)
    """
    p = Path(_fspath(path))
    try:
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise FileNotFoundError(f"no such file: {p}") from None
    except OSError as exc:
        raise ValueError(f"{p} cannot be opened ({exc}); {fix}.") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"{p} is not a regular file (a folder, a pipe or a device); {fix}.")
        fh = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    try:
        return _scan(p, fh, st.st_size, fix, what)
    except BaseException:
        fh.close()
        raise


def _scan(p: Path, fh, size: int, fix: str, what: str) -> NpzReader:
    """Check the archive's entries from their headers (see :func:`open_npz`)."""
    def refuse(problem):
        return ValueError(f"{p}: {problem}; {fix}.")

    head = fh.read(6)
    fh.seek(0)
    if head == b"\x93NUMPY":
        raise refuse("it is a single .npy array, not an .npz archive")
    if not zipfile.is_zipfile(fh):
        raise ValueError(f"{p} is not a readable .npz file (not a zip archive); {fix}.")
    fh.seek(0)
    entries, infos = {}, {}
    total, packed, compressed = 0.0, 0, False
    try:
        zf = zipfile.ZipFile(fh)
    except (zipfile.BadZipFile, OSError, EOFError, ValueError, RuntimeError, NotImplementedError) as exc:
        raise ValueError(f"{p} is not a readable .npz file ({exc}); {fix}.") from None
    try:
        for info in zf.infolist():
            name = info.filename
            if not name.endswith(".npy") or name[:-4] in entries:
                raise refuse(f"entry {name!r} is " + ("repeated" if name.endswith(".npy") else "not an .npy array"))
            if info.compress_size > size or info.header_offset > size:
                raise refuse(f"entry {name!r} claims {info.compress_size} stored bytes at offset "
                             f"{info.header_offset} in a file of {size} bytes (truncated or forged)")
            try:
                with zf.open(info) as efh:
                    shape, dtype, _ = _read_npy_header(efh)
                    header = efh.tell()
            except (zipfile.BadZipFile, OSError, EOFError, RuntimeError, NotImplementedError, ValueError,
                    SyntaxError) as exc:
                raise refuse(f"the header of entry {name!r} is unreadable ({type(exc).__name__}: {exc})") from None
            if dtype.hasobject:
                raise refuse(f"entry {name!r} holds Python objects (roughpaths never pickles)")
            nbytes = float(np.prod(shape, dtype=float)) * dtype.itemsize
            if info.file_size - header != nbytes:
                raise refuse(f"entry {name!r} declares shape {shape} of {dtype} ({nbytes:.3g} bytes) but holds "
                             f"{info.file_size - header} bytes (corrupt or forged)")
            entries[name[:-4]] = (shape, dtype)
            infos[name[:-4]] = info
            total += nbytes
            packed += info.compress_size
            compressed |= info.compress_type != zipfile.ZIP_STORED
        if compressed and total > _MAX_EXPANSION * max(packed, 1) and total > 2**26:
            raise ValueError(f"{p} expands from {packed / 2**20:.3g} MiB of compressed entries to "
                             f"{total / 2**30:.3g} GiB (more than {_MAX_EXPANSION}x): roughpaths never compresses, "
                             f"and a file this compressible is forged (a zip bomb) or not ours; {fix}.")
        check_memory(total, f"{what} of {p}", f"read it on a machine with more memory, or set "
                     f"ROUGHPATHS_MAX_BYTES if you trust it; otherwise {fix}")
    except BaseException:
        zf.close()
        raise
    return NpzReader(p, fh, zf, entries, infos, fix)


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
    with open_npz(path) as npz:
        meta = _metadata(npz)
    return _from_json(meta)


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
    with open_npz(path) as npz:
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
