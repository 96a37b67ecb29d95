"""Reading and writing ``.npz`` archives safely: the one reader and the one writer of the library's files.

:func:`open_npz` opens a file as untrusted input and :func:`atomic_savez` writes one atomically; both are
public through :mod:`roughpaths.io` (``roughpaths.io.open_npz``, ``roughpaths.io.atomic_savez``), where
:func:`roughpaths.load` and :func:`roughpaths.save` use them, and so do ``mechanics``' ensemble checkpoints.

What the reader guarantees before a byte of an array is read: the path is a regular file (opened
without blocking, then ``fstat`` on the open descriptor, so the file checked is the file read and a
named pipe, a device or a folder is refused, never waited on); it is a zip archive of ``.npy``
entries whose directory fits the memory budget before ``zipfile`` parses it (one object per entry),
none repeated, none holding Python objects; every header declares exactly the bytes the
archive stores for it; compressed entries do not expand more than ``200x`` past 64 MiB (a zip bomb);
and the declared sizes together fit :func:`roughpaths.validation.check_memory`. Reading an array then
allocates exactly what its header declared and checks the archive's CRC. What the arrays must hold is
the caller's to check (:class:`NpzReader` offers ``expect`` and ``read(..., dtype=, shape=)`` from the
headers, before reading).
"""

from __future__ import annotations

import os
import stat
import struct
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from .validation import check_memory

__all__ = ["open_npz", "NpzReader", "atomic_savez"]

_MAX_EXPANSION = 200             # compressed entries expanding more than this (and past 64 MiB): refused
_CHUNK = 1 << 20                 # bytes per read (1 MiB: 16 MiB reads were ~1.5x slower, measured)
_FIX = "it is not a file written by roughpaths or mechanics, or it is truncated, corrupt or forged"
#: Bytes allocated per byte of zip directory when it is parsed: ~570 per entry of >= 46 bytes, plus the bytes.
_DIRECTORY_COST = 16


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
                try:
                    header = _read_npy_header(fh)
                except (ValueError, SyntaxError) as exc:
                    raise self.refuse(f"the header of {name!r} became unreadable while the file was read "
                                      f"({exc})") from None
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

    :func:`roughpaths.load`, :func:`roughpaths.load_metadata` and ``mechanics``' ensemble checkpoints
    read through it. Before
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


def _directory_bytes(fh, size: int) -> int:
    """The size of the archive's central directory, as its end record (or zip64 end record) declares it.

    :class:`zipfile.ZipFile` reads the whole directory and makes one ``ZipInfo`` per entry before any
    check is possible: about 570 bytes per entry of at least 46 bytes (measured with ``tracemalloc``, 10^5
    entries), plus the directory's bytes, so :data:`_DIRECTORY_COST` times its size bounds what parsing
    it allocates. A record that cannot be found gives 0 (``zipfile`` then refuses the file).
    """
    tail = min(size, 22 + 0xFFFF)                            # the end record and the longest comment
    fh.seek(size - tail)
    data = fh.read(tail)
    pos = data.rfind(b"PK\x05\x06")
    if pos < 0 or pos + 22 > len(data):
        return 0
    (cd_size,) = struct.unpack("<L", data[pos + 12:pos + 16])
    loc = pos - 20                                           # zip64 locator, just before the end record
    if loc >= 0 and data[loc:loc + 4] == b"PK\x06\x07":
        (offset,) = struct.unpack("<Q", data[loc + 8:loc + 16])
        if offset + 56 <= size:
            fh.seek(offset)
            rec = fh.read(56)
            if rec[:4] == b"PK\x06\x06":
                (cd_size,) = struct.unpack("<Q", rec[40:48])
    return int(cd_size)


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
    directory = min(_directory_bytes(fh, size), size)       # zipfile reads at most the file
    check_memory(_DIRECTORY_COST * directory, f"the zip directory of {p} ({directory} bytes, parsed into one "
                 f"object per entry)", f"read it on a machine with more memory, or set ROUGHPATHS_MAX_BYTES if you "
                 f"trust it; otherwise {fix}")
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
