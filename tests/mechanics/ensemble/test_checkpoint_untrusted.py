"""Checkpoints are untrusted input, and their identity cannot lie.

Claims (issue 36, items 1 and 2):

* ``run_ensemble(..., checkpoint=f)`` reads ``f`` through ``roughpaths.io.open_npz``: a named pipe is refused
  at once (not waited on), a forged header or a zip bomb is refused from the headers before anything is
  inflated, and the declared sizes are held to the memory budget;
* a checkpoint with the run's own fingerprint is still checked entry by entry: chunks done within the run,
  counts equal to the paths those chunks hold, finite statistics, shapes of this run; a tampered file is
  refused naming the file and saying to delete it, never resumed into partial or double-counted statistics;
* a run that calls code outside the library (an observable of the user's, reading a global or a helper that
  may change between the crash and the resume, or a user Hamiltonian) is refused with ``checkpoint=`` unless
  ``code_version`` is given, and a checkpoint written under another ``code_version`` is refused.
"""

import importlib
import io
import signal
import sys
import zipfile
from unittest import mock

import numpy as np
import pytest

import mechanics
import mechanics.ensemble.run as ens
from mechanics.systems.lie_algebra import so3
from mechanics.systems.lie_poisson import LiePoissonSystem

BODY = dict(inertia=[1.0, 2.0, 3.0], sigma=0.2, theta=0.5)
MU0 = [0.0, 0.6, 0.8]
# two chunks of 100 paths: after one chunk 64 paths sit in a complete leaf and 36 in the pending rows
KW = dict(dt=0.01, n_steps=20, n_paths=200, seed=3, keep_final=True, chunk_size=100, record_every=10)


class Blocked(Exception):
    """Raised by the alarm of :func:`no_hang` (not an OSError, so no loader can mistake it for a bad file)."""


@pytest.fixture
def no_hang():
    """Fail (instead of hanging the suite) if the body blocks for more than 20 s (the old loader did, for ever)."""
    def alarm(signum, frame):
        raise Blocked("run_ensemble blocked on the checkpoint for 20 s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def _run(ck, **kw):
    return mechanics.run_ensemble(mechanics.rigid_body(**BODY), MU0, checkpoint=ck, **dict(KW, **kw))


def _arrays(path):
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


@pytest.fixture
def complete(tmp_path):
    """A completed run's checkpoint (kept) and the run's result."""
    ck = tmp_path / "ck.npz"
    result = _run(ck, keep_checkpoint=True)
    return ck, result


def test_a_named_pipe_is_refused_not_waited_on(tmp_path, no_hang):
    import os

    fifo = tmp_path / "ck.npz"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="ck.npz is not a regular file.*delete it"):
        _run(fifo)


def test_a_forged_header_is_refused_before_allocating(complete):
    """A header declaring 10^10 float64 (74.5 GiB) for an entry of the right fingerprint's file."""
    ck, _ = complete
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": (10**10,)})
    arrays = _arrays(ck)
    with zipfile.ZipFile(ck, "w") as zf:
        for name, a in arrays.items():
            if name == "final_mean":
                zf.writestr("final_mean.npy", buf.getvalue() + b"\0" * 64)
            else:
                with zf.open(name + ".npy", "w") as fh:
                    np.lib.format.write_array(fh, a)
    with pytest.raises(ValueError, match=r"ck.npz: entry 'final_mean.npy' declares shape \(10000000000,\).*"
                                         r"delete it"):
        _run(ck)


def test_a_zip_bomb_is_refused_before_inflating(complete):
    """80 MB of zeros deflated to ~80 KB under a checkpoint with the right fingerprint: refused from the headers
    (the old loader inflated every entry first)."""
    ck, _ = complete
    arrays = _arrays(ck)
    n = 10**7
    with zipfile.ZipFile(ck, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, a in arrays.items():
            with zf.open(name + ".npy", "w") as fh:
                if name != "final_pending":
                    np.lib.format.write_array(fh, a)
                    continue
                np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (n,)})
                zeros = bytes(8 * 10**6)
                for _ in range(n // 10**6):
                    fh.write(zeros)
    assert ck.stat().st_size < 10**6
    with pytest.raises(ValueError, match="ck.npz expands from .* zip bomb.*delete it"):
        _run(ck)


def test_declared_sizes_are_held_to_the_memory_budget(complete, monkeypatch):
    """The run's own allocations fit 10 kB; its checkpoint's zip directory (~28 kB to parse, estimated from its
    end record) does not: refused before it is parsed (the old loader read the whole file). The arrays' own
    budget check is tested in tests/roughpaths/test_io_untrusted.py."""
    ck, _ = complete
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", "10000")
    calls = []
    with mock.patch.object(ens, "_run_chunk", lambda *a: calls.append(a)):
        with pytest.raises(ValueError, match="the zip directory of .*ck.npz.*memory budget.*delete it"):
            _run(ck)
    assert not calls


def _tampered(ck, edit):
    arrays = _arrays(ck)
    edit(arrays)
    np.savez(ck, **arrays)
    return ck


TAMPERED = {
    "done negative": lambda a: a.update(__done__=np.array(-1, dtype=np.int64)),
    "done zero": lambda a: a.update(__done__=np.array(0, dtype=np.int64)),
    "done beyond the run": lambda a: a.update(__done__=np.array(7, dtype=np.int64)),
    "count changed": lambda a: a.update(final_count=np.array(64, dtype=np.int64)),
    "count negative": lambda a: a.update(tavg_count=np.array(-128, dtype=np.int64)),
    "NaN mean": lambda a: a["final_mean"].__setitem__(0, np.nan),
    "infinite pending row": lambda a: a["snap1_pending"].__setitem__((0, 0), np.inf),
    "negative variance": lambda a: a["final_scatter"].__setitem__((1, 1), -1.0),
    "asymmetric scatter": lambda a: a["final_scatter"].__setitem__((0, 1), a["final_scatter"][0, 1] + 1.0),
    "pending rows dropped": lambda a: a.update(final_pending=a["final_pending"][:3]),
    "a snapshot missing": lambda a: a.pop("snap2_mean"),
    "final states dropped": lambda a: a.pop("finals1"),
    "final states of another shape": lambda a: a.update(finals0=a["finals0"][:10]),
    "NaN final state": lambda a: a["finals0"].__setitem__((5, 1), np.nan),
    "int mean": lambda a: a.update(final_mean=a["final_mean"].astype(np.int64)),
    "extra entry": lambda a: a.update(extra=np.zeros(3)),
    "layout": lambda a: a.update(__layout__=np.array('{"tavg": true, "snaps": 2, "finals": 2}')),
}


@pytest.mark.parametrize("case", sorted(TAMPERED))
def test_a_tampered_checkpoint_with_an_intact_fingerprint_is_refused(complete, case):
    ck, _ = complete
    _tampered(ck, TAMPERED[case])
    calls = []
    with mock.patch.object(ens, "_run_chunk", lambda *a: calls.append(a)):
        with pytest.raises(ValueError, match=r"checkpoint '.*ck.npz' is incomplete or damaged \(.*\); delete it"):
            _run(ck)
    assert not calls                                   # refused before any work


def test_an_untampered_checkpoint_resumes_and_a_partial_one_finishes_bitwise(tmp_path, complete):
    """The checks accept what the run writes: the kept checkpoint of a completed run returns its result, and a
    checkpoint written after one chunk (36 paths pending in a leaf) finishes to the uninterrupted result."""
    ck, result = complete
    again = _run(ck)
    assert again == result
    ck2 = tmp_path / "partial.npz"
    original = ens._run_chunk
    calls = {"n": 0}

    def interrupted(spec, a, b):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return original(spec, a, b)

    with mock.patch.object(ens, "_run_chunk", interrupted):
        with pytest.raises(KeyboardInterrupt):
            _run(ck2)
    assert int(_arrays(ck2)["__done__"]) == 1 and _arrays(ck2)["final_pending"].shape == (36, 9)
    assert _run(ck2) == result
    # burn-in past the horizon: no time averages, and a layout without them is what the loader expects
    ck3 = tmp_path / "no_average.npz"
    r = _run(ck3, burn_in=50, keep_checkpoint=True)
    assert r.time_average is None and _run(ck3, burn_in=50) == r


# ------------------------------------------------------------------------------------- identity of the run
HELPER_MODULE = """
import numpy as np

SCALE = {scale}


def helper(x):
    return SCALE * np.asarray(x)


def scaled(x):
    return SCALE * np.asarray(x)


def via_helper(x):
    return helper(x)
"""


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    """A module of the user's, written to disk and imported (``write(scale)`` rewrites and reloads it)."""
    monkeypatch.syspath_prepend(str(tmp_path))
    path = tmp_path / "user_observables.py"

    def write(scale):
        path.write_text(HELPER_MODULE.format(scale=scale))
        importlib.invalidate_caches()
        if "user_observables" in sys.modules:
            return importlib.reload(sys.modules["user_observables"])
        return importlib.import_module("user_observables")

    yield write
    sys.modules.pop("user_observables", None)


@pytest.mark.parametrize("name", ["scaled", "via_helper"])
def test_an_observable_reading_a_global_or_helper_is_refused_without_code_version(tmp_path, user_module, name):
    """The probe's case: the observable reads a module global (directly or through a helper) that changes
    between the crash and the resume. Its pickle is its name, so without code_version the run is refused
    before any work; with code_version the changed code is a new version and its checkpoint is refused."""
    mod = user_module(1.0)
    ck = tmp_path / "ck.npz"
    with pytest.raises(ValueError, match=r"observable refers to user_observables\." + name + r".*code_version"):
        _run(ck, observable=getattr(mod, name))
    assert not ck.exists()
    original = ens._run_chunk

    def crash_after_one(spec, a, b):
        if a > 0:
            raise KeyboardInterrupt
        return original(spec, a, b)

    with mock.patch.object(ens, "_run_chunk", crash_after_one):
        with pytest.raises(KeyboardInterrupt):
            _run(ck, observable=getattr(mod, name), code_version="scale-1")
    assert ck.exists()
    mod = user_module(2.0)                                            # the global changed between crash and resume
    with pytest.raises(ValueError, match="belongs to a run with other arguments.*code_version"):
        _run(ck, observable=getattr(mod, name), code_version="scale-2")
    fresh = _run(tmp_path / "fresh.npz", observable=getattr(mod, name), code_version="scale-2")
    # an independent oracle for the fresh run: the default observable's first moments, scaled by 2
    base = _run(tmp_path / "base.npz")
    np.testing.assert_allclose(fresh.final.mean, 2.0 * base.final.mean[:3], rtol=1e-12, atol=1e-15)


def _energy(mu):
    return 0.5 * np.sum(np.asarray(mu) ** 2 / np.array([1.0, 2.0, 3.0]), axis=-1)


def _energy_gradient(mu):
    return np.asarray(mu) / np.array([1.0, 2.0, 3.0])


def test_a_system_holding_user_code_is_refused_without_code_version(tmp_path):
    system = LiePoissonSystem(so3(), _energy, 0.2 * np.eye(3), hamiltonian_gradient=_energy_gradient, theta=0.5)
    with pytest.raises(ValueError, match=r"system refers to .*_energy.*code_version"):
        mechanics.run_ensemble(system, MU0, checkpoint=tmp_path / "ck.npz", **KW)
    assert not (tmp_path / "ck.npz").exists()


def test_code_version_is_checked(tmp_path):
    with pytest.raises(ValueError, match="code_version='v1' .* no checkpoint"):
        mechanics.run_ensemble(mechanics.rigid_body(**BODY), MU0, code_version="v1", **KW)
    for bad in ("", "  ", 3, b"v1"):
        with pytest.raises(TypeError, match="code_version must be a non-empty string"):
            _run(tmp_path / "ck.npz", code_version=bad)
