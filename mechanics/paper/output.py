"""The main job's output folder: written in a marked sibling folder, renamed into place when complete.

A run into ``OUT`` works in ``OUT.incomplete`` (with a file ``INCOMPLETE.txt`` saying so) and holds
the lock file ``.OUT.lock`` beside it (``flock``: released by the kernel when the process dies, so a
killed run never leaves a stale lock). Every file is written to a temporary name, flushed to disk
and renamed, so no file is ever seen half written; after each figure or check, the record of the
finished pieces (``.progress.json``: file sizes and SHA-256 checksums, the results) is rewritten the
same way. When everything is written, ``manifest.json`` goes last, the marks are removed and the
folder is renamed to ``OUT`` (replacing an earlier ``OUT`` only with ``--overwrite``, and only then).
So ``OUT`` either does not exist or is complete and matches its manifest.

``--resume`` continues an interrupted run: the pieces whose files still match the recorded checksums
are reused, the others are run again. Every piece draws its random numbers from its own stream (seed
and name), and every file is written deterministically (no time stamps), so a resumed run gives the
same bytes as an uninterrupted one; only ``manifest.json`` (timings, dates) differs.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import io
import json
import os
import shutil
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["OutputError", "RunFolder", "npz_bytes", "sha256_hex", "PROGRESS_FORMAT", "MANIFEST_FORMAT"]

PROGRESS_FORMAT = "levy-area-paper-progress/1"
MANIFEST_FORMAT = "levy-area-paper-manifest/1"
MARKER = "INCOMPLETE.txt"
PROGRESS = ".progress.json"
MANIFEST = "manifest.json"
_TMP = ".tmp-"


class OutputError(Exception):
    """The output folder cannot be used or written: one line on stderr, exit code 2."""


def _why(exc: OSError) -> str:
    text = exc.strerror or str(exc)
    if exc.errno == errno.ENOSPC:
        text += " (free some space, then continue with --resume)"
    elif exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        text += " (choose a folder you can write to with --output)"
    return text


def sha256_hex(data: bytes) -> str:
    """SHA-256 of ``data`` as 64 hexadecimal digits."""
    return hashlib.sha256(data).hexdigest()


def npz_bytes(arrays: dict) -> bytes:
    """A compressed ``.npz`` archive of ``arrays`` whose bytes depend only on the arrays.

    ``numpy.savez_compressed`` stamps each member with the current time; here every member gets the
    same fixed time stamp, so equal data give equal files (and equal checksums). Read it with
    ``numpy.load``.

    Examples
    --------
    >>> a = npz_bytes({"x": np.arange(3.0)})
    >>> a == npz_bytes({"x": np.arange(3.0)}), float(np.load(io.BytesIO(a))["x"][2])
    (True, 2.0)
    """
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for key, value in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            with zf.open(info, "w", force_zip64=True) as f:
                np.lib.format.write_array(f, np.asarray(value), allow_pickle=False)
    return buf.getvalue()


def _write_file(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` and flush it to disk (the one place the job writes bytes)."""
    with open(path, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


class RunFolder:
    """The output folder of one run of the main job (see the module docstring).

    Parameters
    ----------
    output : str or Path
        The final folder ``OUT`` as the user gave it.

    Attributes
    ----------
    final, staging, lockfile : Path
        ``OUT``, ``OUT.incomplete`` and ``.OUT.lock`` (absolute).
    reused : dict
        After :meth:`open` with ``resume=True``: the verified records of finished pieces.
    """

    def __init__(self, output):
        shown = str(Path(output))
        absolute = Path(os.path.abspath(output))
        if not shown.strip() or absolute.name in ("", ".", ".."):
            raise OutputError(f"--output must name a folder, got {str(output)!r}")
        cwd = Path(os.getcwd())
        if absolute == cwd or absolute in cwd.parents:
            raise OutputError(f"--output '{shown}' is the current folder or contains it; the run replaces the "
                              "whole output folder, so choose a new folder name")
        self.shown = shown
        self.final = absolute
        self.parent = absolute.parent
        self.staging = absolute.with_name(absolute.name + ".incomplete")
        self.lockfile = absolute.with_name(f".{absolute.name}.lock")
        self.reused: dict = {}
        self.progress: dict | None = None
        self.already_complete = False
        self._lock_fd: int | None = None

    # ----------------------------------------------------------------------------------- naming
    def show(self, path: Path) -> str:
        """``path`` as the user would write it (relative to the ``--output`` they gave)."""
        path = Path(path)
        if path == self.final:
            return self.shown
        if path == self.staging:
            return self.shown + ".incomplete"
        if path.parent == self.staging:
            return f"{self.shown}.incomplete/{path.name}"
        return str(path)

    # ----------------------------------------------------------------------------------- lock
    def acquire(self) -> None:
        """Take the lock of ``OUT`` or raise :class:`OutputError` naming the run that holds it."""
        try:
            self.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"cannot create output folder '{self.shown}': {_why(exc)}") from None
        if self.final.exists() and not self.final.is_dir():
            raise OutputError(f"output path '{self.shown}' exists and is not a folder; choose another with --output")
        while True:
            try:
                fd = os.open(self.lockfile, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise OutputError(f"cannot create output folder '{self.shown}': cannot write in "
                                  f"'{self.parent}': {_why(exc)}") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                try:
                    holder = os.read(fd, 200).decode(errors="replace").strip()
                finally:
                    os.close(fd)
                who = f"pid {holder}" if holder else "another process"
                raise OutputError(f"another run ({who}) is writing '{self.shown}'; wait for it to finish or "
                                  "choose another --output") from None
            try:
                same = os.stat(self.lockfile).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # the holder removed the file between our open and our lock: try again
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            self._lock_fd = fd
            return

    def release(self) -> None:
        """Remove the lock file and release the lock (idempotent)."""
        if self._lock_fd is None:
            return
        try:
            os.unlink(self.lockfile)
        except OSError:
            pass
        os.close(self._lock_fd)
        self._lock_fd = None

    def __enter__(self):
        self.acquire()
        return self

    def __exit__(self, *exc):
        self.release()
        return False

    # ----------------------------------------------------------------------------------- open
    def open(self, run: dict, *, overwrite: bool, resume: bool, notify=print) -> None:
        """Prepare ``OUT.incomplete`` for the run described by ``run`` (must hold the lock).

        ``run`` holds the options that determine the results (seed, convention, sizes, selection,
        versions); a resumed run must have the same. Sets :attr:`reused` (resume) or
        :attr:`already_complete` (``--resume`` of a run that had finished).
        """
        assert self._lock_fd is not None, "acquire() first"
        self._recover_replaced(notify)
        if overwrite and os.path.ismount(self.final):
            raise OutputError(f"output folder '{self.shown}' is a mount point: a completed run is renamed into place, "
                              f"which a mount point cannot be; pass --output '{self.shown}/run' (a folder inside it)")
        final_used = self.final.is_dir() and any(self.final.iterdir())
        if final_used and not overwrite:
            if resume and not self.staging.exists() and self._verify_manifest(self.final):
                self.already_complete = True
                return
            raise OutputError(f"output folder '{self.shown}' exists and is not empty; pass --overwrite to replace "
                              "it, or choose a new name with --output")
        if final_used and not ((self.final / MANIFEST).is_file() or (self.final / "report.md").is_file()):
            raise OutputError(f"output folder '{self.shown}' is not the output of an earlier run (no manifest.json "
                              "or report.md); --overwrite replaces the whole folder, so it only replaces such "
                              "folders: remove it yourself or choose another --output")
        if self.staging.exists() and not self.staging.is_dir():
            raise OutputError(f"'{self.show(self.staging)}' exists and is not a folder; remove it or choose "
                              "another --output")
        if self.staging.exists():
            if resume:
                if self._resume(run, notify):
                    return
            elif overwrite:
                notify(f"discarding the unfinished run in '{self.show(self.staging)}' (--overwrite)")
            else:
                raise OutputError(f"an unfinished run left '{self.show(self.staging)}'; pass --resume to continue "
                                  "it, or --overwrite to start over")
            self._remove_tree(self.staging)
        elif resume:
            notify(f"nothing to resume for '{self.shown}' (no '{self.show(self.staging)}'): starting a new run")
        self._start(run)

    def _recover_replaced(self, notify) -> None:
        """Report and clean up what a kill between the two renames of ``--overwrite`` left.

        ``_rename_into_place`` first moves the previous run aside as ``.OUT.replaced-PID``, then the new one
        into place, then deletes the previous one. If ``OUT`` exists, the replacement had completed: the
        leftover is deleted. If not, the newest leftover is the previous run: it is restored to ``OUT``
        (the new, complete run stays in ``OUT.incomplete``, where ``--resume`` finishes it).
        """
        leftovers = sorted(self.parent.glob(f".{self.final.name}.replaced-*"), key=lambda p: p.stat().st_mtime)
        if not leftovers:
            return
        if not self.final.exists():
            newest = leftovers.pop()
            try:
                os.replace(newest, self.final)
            except OSError as exc:
                raise OutputError(f"cannot restore '{self.show(newest)}' to '{self.shown}': {_why(exc)}") from None
            notify(f"restored '{self.shown}' from '{self.show(newest)}', where an interrupted --overwrite had "
                   f"moved it")
        for old in leftovers:
            self._remove_tree(old)
            notify(f"removed '{self.show(old)}', a previous run that an interrupted --overwrite had already "
                   f"replaced")

    def _remove_tree(self, path: Path) -> None:
        try:
            shutil.rmtree(path)
        except OSError as exc:
            raise OutputError(f"cannot remove '{self.show(path)}': {_why(exc)}") from None

    def _start(self, run: dict) -> None:
        try:
            self.staging.mkdir()
        except OSError as exc:
            raise OutputError(f"cannot create output folder '{self.show(self.staging)}': {_why(exc)}") from None
        note = (f"This folder holds an unfinished run of levy-area-paper (pid {os.getpid()}); its files are not a "
                f"complete result. When the run completes, the folder is renamed to '{self.final.name}'.\n"
                f"If the run was interrupted, continue it with the same options and --resume, or start over "
                f"with --overwrite.\n")
        self.write_bytes(MARKER, note.encode())
        self.progress = {"format": PROGRESS_FORMAT, "run": run, "tasks": {}}
        self._save_progress()

    def _resume(self, run: dict, notify) -> bool:
        """Load and verify the record of an interrupted run; True if it can be continued."""
        record = self._read_json(self.staging / PROGRESS)
        if record is None:
            if self._verify_manifest(self.staging):   # killed between the manifest and the rename
                self.already_complete = True
                self._rename_into_place()
                notify(f"the interrupted run had finished writing; moved it to '{self.shown}'")
                return True
            notify(f"no usable record of finished pieces in '{self.show(self.staging)}': starting over")
            return False
        if record.get("format") != PROGRESS_FORMAT:
            notify(f"'{self.show(self.staging)}' was written by another version: starting over")
            return False
        old = record.get("run", {})
        diffs = [f"{k}: {old.get(k)!r} then, {run.get(k)!r} now" for k in run if old.get(k) != run.get(k)]
        if diffs:
            raise OutputError(f"--resume: the unfinished run in '{self.show(self.staging)}' used other options or "
                              f"versions ({'; '.join(diffs)}); rerun with its options, or start over with --overwrite")
        kept, dropped = {}, []
        for key, entry in record.get("tasks", {}).items():
            if all(self._file_matches(self.staging / name, meta) for name, meta in entry.get("files", {}).items()):
                kept[key] = entry
            else:
                dropped.append(key)
        keep_names = {MARKER, PROGRESS} | {name for e in kept.values() for name in e.get("files", {})}
        for p in self.staging.iterdir():   # temporary files and pieces of unfinished tasks
            if p.name not in keep_names:
                try:
                    shutil.rmtree(p) if p.is_dir() else p.unlink()
                except OSError as exc:
                    raise OutputError(f"cannot remove '{self.show(p)}': {_why(exc)}") from None
        self.progress = {"format": PROGRESS_FORMAT, "run": old, "tasks": kept}
        self.reused = kept
        self._save_progress()
        notify(f"resuming '{self.show(self.staging)}': {len(kept)} finished pieces verified and reused"
               + (f", {len(dropped)} with damaged files run again ({', '.join(dropped)})" if dropped else ""))
        return True

    @staticmethod
    def _read_json(path: Path):
        try:
            return json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None

    @staticmethod
    def _file_matches(path: Path, meta: dict) -> bool:
        try:
            data = path.read_bytes()
        except OSError:
            return False
        return len(data) == meta.get("size") and sha256_hex(data) == meta.get("sha256")

    def _verify_manifest(self, folder: Path) -> bool:
        man = self._read_json(folder / MANIFEST)
        if not isinstance(man, dict) or man.get("format") != MANIFEST_FORMAT or not man.get("complete"):
            return False
        files = man.get("files", [])
        names = {f.get("name") for f in files} | {MANIFEST}
        try:
            present = {p.name for p in folder.iterdir()}
        except OSError:
            return False
        return present == names and all(self._file_matches(folder / f["name"], f) for f in files)

    # ----------------------------------------------------------------------------------- writing
    def write_bytes(self, name: str, data: bytes) -> dict:
        """Write ``OUT.incomplete/name`` atomically; return ``{"size", "sha256"}``.

        Raises :class:`OutputError` (one line naming the file) on any OS error, e.g. a full disk.
        """
        if "/" in name or name.startswith(_TMP):
            raise ValueError(f"name must be a plain file name, got {name!r}")
        target = self.staging / name
        tmp = self.staging / f"{_TMP}{os.getpid()}-{name}"
        try:
            _write_file(tmp, data)
            os.replace(tmp, target)
        except OSError as exc:
            try:
                tmp.unlink()
            except OSError:
                pass
            raise OutputError(f"cannot write '{self.show(target)}': {_why(exc)}") from None
        return {"size": len(data), "sha256": sha256_hex(data)}

    def _save_progress(self) -> None:
        self.write_bytes(PROGRESS, json.dumps(self.progress, indent=1, allow_nan=True).encode())

    def record(self, key: str, entry: dict) -> None:
        """Record a finished piece (``{"files": {name: {"size", "sha256"}}, ...}``) in the progress file."""
        self.progress["tasks"][key] = entry
        self._save_progress()

    def finish(self, manifest: dict) -> Path:
        """Write ``manifest.json`` (listing every file) last, remove the marks, rename to ``OUT``."""
        files = []
        for p in sorted(self.staging.iterdir(), key=lambda q: q.name):
            if p.name in (MARKER, PROGRESS, MANIFEST) or p.name.startswith(_TMP):
                continue
            try:
                data = p.read_bytes()
            except OSError as exc:
                raise OutputError(f"cannot read '{self.show(p)}': {_why(exc)}") from None
            files.append({"name": p.name, "size": len(data), "sha256": sha256_hex(data)})
        manifest = {"format": MANIFEST_FORMAT, "complete": True, **manifest, "files": files}
        self.write_bytes(MANIFEST, json.dumps(manifest, indent=1, allow_nan=True).encode())
        for name in (MARKER, PROGRESS):
            try:
                (self.staging / name).unlink()
            except FileNotFoundError:
                pass
            except OSError as exc:
                raise OutputError(f"cannot remove '{self.show(self.staging / name)}': {_why(exc)}") from None
        _fsync_dir(self.staging)
        self._rename_into_place()
        return self.final

    def _rename_into_place(self) -> None:
        old = None
        try:
            if self.final.exists():
                old = self.final.with_name(f".{self.final.name}.replaced-{os.getpid()}")
                os.replace(self.final, old)
            os.replace(self.staging, self.final)
        except OSError as exc:
            raise OutputError(f"cannot rename '{self.show(self.staging)}' to '{self.shown}': {_why(exc)}") from None
        _fsync_dir(self.parent)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
