"""The main job never loses or corrupts its output (``mechanics.paper.output``).

Claims:

* a run into ``OUT`` works in ``OUT.incomplete`` (marked by ``INCOMPLETE.txt``) and renames it to
  ``OUT`` only when complete, with ``manifest.json`` (every file's size and SHA-256) written last;
  killed (SIGKILL) at any moment, it leaves either no ``OUT`` or a complete ``OUT`` equal to an
  uninterrupted run, and ``--resume`` finishes it with the same bytes as an uninterrupted run;
* SIGTERM stops the run with exit code 143 and a one-line hint to ``--resume``;
* a lock keeps a second run out of a folder in use (it refuses in one line, exit 2);
* ``--overwrite`` replaces the whole folder (no file of the earlier run survives) and only a folder
  written by an earlier run; without ``--resume`` or ``--overwrite`` an unfinished run is refused;
* ``--resume`` refuses other options, reuses only finished pieces whose checksums match, and
  reruns a damaged one;
* a full disk or a permission error is one line naming the file, exit 2, with the unfinished run
  kept for ``--resume`` (simulated by making the one low-level write raise).
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mechanics.paper import output
from mechanics.paper.cli import main
from mechanics.paper.output import RunFolder, sha256_hex

QUICK = ["--tiny", "--quiet", "--only", "surf,chen,girsanov"]      # a couple of seconds in-process
#: figures and checks of several kinds (long simulation, portrait, rough paths, ensemble), a few seconds
SUBSET = "fig1,surf2,chen,gibbs_mean"


def _files(folder: Path) -> dict:
    """{name: sha256} of the files the manifest lists, after checking the folder matches it."""
    man = json.loads((folder / "manifest.json").read_text())
    assert man["complete"] is True
    listed = {f["name"]: f for f in man["files"]}
    present = {p.name for p in folder.iterdir()} - {"manifest.json"}
    assert present == set(listed), (present ^ set(listed))
    for name, f in listed.items():
        data = (folder / name).read_bytes()
        assert len(data) == f["size"] and sha256_hex(data) == f["sha256"], name
    return {name: f["sha256"] for name, f in listed.items()}


def _one_line(err: str) -> str:
    assert err.count("\n") == 1 and err.startswith("levy-area-paper: error:") and "Traceback" not in err, err
    return err


# ------------------------------------------------------------------------------------------- in-process
@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """An uninterrupted QUICK run."""
    out = tmp_path_factory.mktemp("ref") / "run"
    assert main(QUICK + ["--output", str(out)]) == 0
    return _files(out)


def test_run_is_reproducible_and_leaves_no_trace(tmp_path, reference):
    out = tmp_path / "run"
    assert main(QUICK + ["--output", str(out)]) == 0
    assert _files(out) == reference          # same bytes in every file but the manifest
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]    # no lock, no work folder left


def test_lock_refuses_a_second_run(tmp_path, capsys):
    out = tmp_path / "run"
    holder = RunFolder(out)
    holder.acquire()
    try:
        assert main(QUICK + ["--output", str(out)]) == 2
        err = _one_line(capsys.readouterr().err)
        assert "another run" in err and f"pid {os.getpid()}" in err and str(out) in err
        assert not out.exists() and not Path(str(out) + ".incomplete").exists()
    finally:
        holder.release()
    assert main(QUICK + ["--output", str(out)]) == 0


def test_overwrite_replaces_the_whole_folder(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["--tiny", "--quiet", "--only", "surf,chen", "--output", str(out)]) == 0
    (out / "stale-from-an-earlier-run.png").write_bytes(b"old")
    assert main(["--tiny", "--quiet", "--only", "planar_constant", "--output", str(out)]) == 2
    assert "--overwrite" in _one_line(capsys.readouterr().err)
    assert main(["--tiny", "--quiet", "--only", "planar_constant", "--output", str(out), "--overwrite"]) == 0
    names = set(_files(out))
    assert "stale-from-an-earlier-run.png" not in names and "surf.png" not in names
    assert "planar_constant" in (out / "report.md").read_text() and "`chen`" not in (out / "report.md").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_overwrite_refuses_a_folder_that_is_not_an_output(tmp_path, capsys, monkeypatch):
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    assert main(QUICK + ["--output", str(out), "--overwrite"]) == 2
    assert "not the output of an earlier run" in _one_line(capsys.readouterr().err)
    assert (out / "chapter1.tex").read_text() == "precious"
    monkeypatch.chdir(tmp_path)
    assert main(QUICK + ["--output", ".", "--overwrite"]) == 2
    assert "current folder" in _one_line(capsys.readouterr().err)


def _fail_writes(monkeypatch, name: str, err: int):
    real = output._write_file

    def write(path, data):
        if Path(path).name.endswith(name):
            raise OSError(err, os.strerror(err), str(path))
        real(path, data)

    monkeypatch.setattr(output, "_write_file", write)


@pytest.mark.parametrize("name, err, words", [
    ("report.html", errno.ENOSPC, "No space left on device"),
    ("surf.png", errno.EACCES, "Permission denied"),
])
def test_write_errors_are_one_line_naming_the_file_and_resumable(tmp_path, capsys, monkeypatch, reference,
                                                                   name, err, words):
    out = tmp_path / "run"
    _fail_writes(monkeypatch, name, err)
    assert main(QUICK + ["--output", str(out)]) == 2
    msg = _one_line(capsys.readouterr().err)
    assert f"'{out}.incomplete/{name}'" in msg and words in msg
    assert not out.exists()
    work = Path(str(out) + ".incomplete")
    assert (work / "INCOMPLETE.txt").is_file()
    assert not [p for p in work.iterdir() if p.name.startswith(".tmp-")]     # no half-written file left
    monkeypatch.undo()
    # not silently continued: the unfinished run must be resumed or discarded explicitly
    assert main(QUICK + ["--output", str(out)]) == 2
    assert "--resume" in _one_line(capsys.readouterr().err)
    assert main(QUICK + ["--output", str(out), "--resume"]) == 0
    assert _files(out) == reference and not work.exists()


def test_resume_verifies_pieces_and_refuses_other_options(tmp_path, capsys, monkeypatch, reference):
    out = tmp_path / "run"
    _fail_writes(monkeypatch, "results.json", errno.ENOSPC)     # every piece finished, the report not
    assert main(QUICK + ["--output", str(out)]) == 2
    monkeypatch.undo()
    capsys.readouterr()
    work = Path(str(out) + ".incomplete")
    assert main(["--tiny", "--quiet", "--only", "surf,chen,girsanov", "--seed", "1", "--output", str(out),
                 "--resume"]) == 2
    assert "seed: 0 then, 1 now" in _one_line(capsys.readouterr().err)
    assert main(QUICK + ["--levy-area", "davie", "--output", str(out), "--resume"]) == 2
    assert "levy_area: 'auto' then, 'davie' now" in _one_line(capsys.readouterr().err)
    with open(work / "surf.png", "r+b") as f:          # damage a finished figure
        f.seek(1000)
        f.write(b"\0\0\0\0")
    assert main(["--tiny", "--output", str(out), "--resume", "--only", "surf,chen,girsanov"]) == 0
    err = capsys.readouterr().err
    assert "2 finished pieces verified and reused, 1 with damaged files run again (figure surf)" in err
    assert _files(out) == reference
    # resuming a complete run does nothing; resuming nothing starts a new run
    assert main(QUICK + ["--output", str(out), "--resume"]) == 0
    other = tmp_path / "other"
    assert main(QUICK + ["--output", str(other), "--resume"]) == 0
    assert _files(other) == reference


def test_report_states_the_levy_area_method(tmp_path):
    """A non-default --levy-area is in the report (Markdown, HTML, results.json), the command and the manifest."""
    out = tmp_path / "run"
    assert main(["--tiny", "--quiet", "--only", "chen,brownian_levy_area", "--levy-area", "Foster",
                 "--output", str(out)]) == 0
    md, page = (out / "report.md").read_text(), (out / "report.html").read_text()
    assert "Lévy areas: **foster** (Foster: conditional mean given the space-time area" in md
    assert "- Lévy areas: foster (" in md and "--levy-area foster" in md
    assert "Lévy areas: <b>foster</b>" in page and "<th>Lévy areas</th><td>foster (" in page
    assert "levy_area='foster'" in md     # the check that depends on the method says which it used
    assert json.loads((out / "results.json").read_text())["metadata"]["levy_area"] == "foster"
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["levy_area"] == "foster" and "--levy-area foster" in manifest["command"]


def test_overwrite_discards_an_unfinished_run(tmp_path, monkeypatch, reference):
    out = tmp_path / "run"
    _fail_writes(monkeypatch, "surf.npz", errno.ENOSPC)
    main(QUICK + ["--output", str(out)])
    monkeypatch.undo()
    stray = Path(str(out) + ".incomplete") / "stray.txt"
    stray.write_text("x")
    assert main(QUICK + ["--output", str(out), "--overwrite"]) == 0
    assert _files(out) == reference and not stray.exists()


# ------------------------------------------------------------------------------------------- processes
def _start(out: Path, *extra, only=SUBSET):
    return subprocess.Popen([sys.executable, "-m", "mechanics", "--tiny", "--quiet", "--only", only,
                             "--output", str(out), *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def _check_state(out: Path, ref: dict, note: str) -> None:
    """After a kill: no complete-looking folder is wrong, an unfinished one is marked."""
    work = Path(str(out) + ".incomplete")
    if out.exists():
        assert _files(out) == ref, note
        assert not work.exists(), note
    if work.exists():
        names = {p.name for p in work.iterdir()}
        # marked, or (in the instant between removing the marks and the rename) complete, or (in the instant
        # between creating the folder and renaming its marker into place) holding the marker's temporary file
        # only: its name says unfinished, and --resume, finding no record, starts over
        assert ("INCOMPLETE.txt" in names or "manifest.json" in names
                or (len(names) == 1 and next(iter(names)).startswith(".tmp-")
                    and next(iter(names)).endswith("-INCOMPLETE.txt"))), (note, names)


def _kill_and_resume(tmp_path: Path, only: str, n_kills: int):
    seed = int(os.environ.get("KILL_TEST_SEED", time.time_ns() % 100_000))
    rnd = random.Random(seed)
    t0 = time.perf_counter()
    ref_out = tmp_path / "reference"
    proc = _start(ref_out, only=only)
    assert proc.wait(timeout=600) == 0, proc.stderr.read()
    duration = time.perf_counter() - t0
    ref = _files(ref_out)
    out = tmp_path / "killed"
    for k in range(n_kills):
        moment = rnd.uniform(0.2, duration)
        proc = _start(out, *(["--resume"] if k else []), only=only)
        time.sleep(moment)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
        _check_state(out, ref, f"kill {k} at {moment:.2f}s of ~{duration:.1f}s (KILL_TEST_SEED={seed})")
    proc = _start(out, "--resume", only=only)
    assert proc.wait(timeout=600) == 0, proc.stderr.read()
    assert _files(out) == ref, f"KILL_TEST_SEED={seed}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["killed", "reference"]   # no lock or work folder


def test_sigkill_at_random_moments_then_resume_is_bitwise(tmp_path):
    _kill_and_resume(tmp_path, SUBSET, n_kills=2)         # 8 kills over the whole job in the slow version


@pytest.mark.slow
def test_sigkill_at_random_moments_then_resume_is_bitwise_whole_job(tmp_path):
    from mechanics.paper.checks import CHECKS
    from mechanics.paper.figures import FIGURES

    _kill_and_resume(tmp_path, ",".join(list(FIGURES) + list(CHECKS)), n_kills=8)


def test_sigterm_leaves_a_marked_unfinished_run(tmp_path):
    out = tmp_path / "run"
    proc = _start(out, only="fig1,surf,surf2,chen")
    work = Path(str(out) + ".incomplete")
    deadline = time.monotonic() + 120
    while not (work / ".progress.json").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, "the run ended before its first piece was recorded"
    proc.send_signal(signal.SIGTERM)          # three pieces (seconds) are left: the run cannot finish first
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert not out.exists() and (work / "INCOMPLETE.txt").is_file()
    assert "--resume" in err and "Traceback" not in err


def test_a_stop_signal_swallowed_by_a_callback_from_c_still_stops_the_run(tmp_path, monkeypatch, capsys):
    """A signal handled inside a callback from C (numba's compiler calls back into Python while it caches a
    kernel) raises into a frame that prints and drops the exception: the run must still stop, at the next
    piece boundary, with its usual message and no traceback. (It went on to the end, exit code 0.)"""
    from mechanics.paper.checks import CHECKS
    from mechanics.paper.tasks import Task

    chen = CHECKS["chen"]

    def signalled_inside_a_callback(ctx):
        @ctypes.CFUNCTYPE(None)
        def callback():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.5)                       # the handler runs here and raises into ctypes, which drops it
        callback()
        return chen.run(ctx)

    monkeypatch.setitem(CHECKS, "chen", Task(name="chen", title=chen.title, func=signalled_inside_a_callback))
    out = tmp_path / "run"
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGINT)}
    hook = sys.unraisablehook
    assert main(["--tiny", "--only", "chen,girsanov", "--output", str(out)]) == 128 + signal.SIGTERM
    err = capsys.readouterr().err
    assert "terminated" in err and "--resume" in err and "Traceback" not in err and "ignored" not in err, err
    work = Path(str(out) + ".incomplete")
    assert not out.exists() and (work / "INCOMPLETE.txt").is_file()
    tasks = json.loads((work / ".progress.json").read_text())["tasks"]
    assert list(tasks) == ["check chen"]          # the piece in progress finished; the next never started
    assert {sig: signal.getsignal(sig) for sig in before} == before and sys.unraisablehook is hook   # restored


def test_a_stop_signal_that_leaves_an_object_half_built_prints_no_traceback(tmp_path, monkeypatch, capsys):
    """A signal that cuts a constructor short leaves an object whose ``__del__`` fails (llvmlite's
    ``ObjectRef`` while numba compiles: ``AttributeError: ... '_as_parameter_'``, seen in CI): the run stops
    with its usual message and no traceback. Before any signal, such errors are still passed on."""
    from mechanics.paper.checks import CHECKS
    from mechanics.paper.tasks import Task

    chen = CHECKS["chen"]

    class HalfBuilt:
        def __init__(self, signalled):
            if not signalled:
                return                            # failed some other way, before the attribute exists
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.5)                       # the handler raises here, before the attribute exists
            self.handle = 1

        def __del__(self):
            del self.handle                       # AttributeError when the constructor was cut short

    def cut_short(ctx):
        HalfBuilt(signalled=False)                # a failing __del__ before the signal: passed on
        try:
            HalfBuilt(signalled=True)
        except BaseException as exc:              # the frames go (as in numba's unwinding): __del__ runs now
            stop = exc.with_traceback(None)
        raise stop

    passed_on = []
    monkeypatch.setattr(sys, "unraisablehook", passed_on.append)
    monkeypatch.setitem(CHECKS, "chen", Task(name="chen", title=chen.title, func=cut_short))
    out = tmp_path / "run"
    assert main(["--tiny", "--only", "chen", "--output", str(out)]) == 128 + signal.SIGTERM
    err = capsys.readouterr().err
    assert "terminated" in err and "--resume" in err and "Traceback" not in err, err
    assert [type(u.exc_value) for u in passed_on] == [AttributeError]     # the one before the signal only
    assert (Path(str(out) + ".incomplete") / "INCOMPLETE.txt").is_file()


def test_a_previous_run_hidden_by_an_interrupted_overwrite_is_restored_or_cleaned(tmp_path, capsys):
    """A kill between the two renames of --overwrite left '.run.replaced-PID': reported and cleaned up."""
    out = tmp_path / "run"
    assert main(["--tiny", "--quiet", "--only", "chen", "--output", str(out)]) == 0
    before = _files(out)
    hidden = tmp_path / ".run.replaced-12345"
    out.rename(hidden)                               # the state after the first rename only
    assert main(["--tiny", "--only", "planar_constant", "--output", str(out)]) == 2     # no --overwrite
    err = capsys.readouterr()
    assert "restored" in err.out + err.err and not hidden.exists()
    assert _files(out) == before                     # the previous run is back, intact
    stale = tmp_path / ".run.replaced-999"
    stale.mkdir()
    (stale / "report.md").write_text("old")
    assert main(["--tiny", "--only", "planar_constant", "--output", str(out), "--overwrite"]) == 0
    err = capsys.readouterr()
    assert "removed" in err.out + err.err and not stale.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_overwrite_refuses_a_mount_point_before_the_run(tmp_path, capsys, monkeypatch):
    import mechanics.paper.output as output

    out = tmp_path / "run"
    assert main(["--tiny", "--quiet", "--only", "chen", "--output", str(out)]) == 0
    real = output.os.path.ismount
    monkeypatch.setattr(output.os.path, "ismount", lambda p: Path(p) == out or real(p))
    assert main(["--tiny", "--quiet", "--only", "chen", "--output", str(out), "--overwrite"]) == 2
    assert "mount point" in _one_line(capsys.readouterr().err)
    assert not (tmp_path / "run.incomplete").exists()
