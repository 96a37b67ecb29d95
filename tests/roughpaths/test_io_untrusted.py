"""Files are untrusted input: ``roughpaths.load`` refuses what it cannot trust, before allocating.

Claims: ``load`` opens regular files only (a named pipe is refused, not waited on); it reads every
``.npy`` header and checks the declared sizes against the memory budget and against the stored bytes
before reading an array; it cross-checks the metadata against the arrays (level, kind, dimensions,
``Solution`` times against states, ``EnsembleResult`` arrays against ``state_dim``); it bounds the
metadata's nesting; ``save`` writes strict JSON; and a saved and loaded ``RoughPath``, ``Solution`` or
``EnsembleResult`` compares equal (``==``) to the original. Each refusal names the file.
"""

import io
import json
import os
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import mechanics
import roughpaths as rp


def _rewrite(src, dst, meta_edit=None, drop=(), replace=None):
    """Copy the .npz ``src`` to ``dst`` with edited metadata / entries (a forged file)."""
    with np.load(src, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files if k not in drop}
    if meta_edit is not None:
        meta = json.loads(str(arrays["__metadata__"][()]))
        meta_edit(meta)
        arrays["__metadata__"] = np.array(json.dumps(meta))
    arrays.update(replace or {})
    np.savez(dst, **arrays)
    return dst


@pytest.fixture
def saved(tmp_path):
    X = rp.brownian_rough_path(np.linspace(0, 1, 5), 2, 0, batch_shape=(3,))
    return X, rp.save(X, tmp_path / "x.npz")


def test_round_trips_compare_equal(tmp_path):
    X = rp.brownian_rough_path(np.linspace(0, 1, 5), 2, 0, batch_shape=(3,), kind="ito")
    assert rp.load(rp.save(X, tmp_path / "x")) == X
    S = rp.solve(rp.LinearVectorFields(0.1 * np.ones((2, 2, 2))), X.to_level1(), np.ones(2), rp.Heun())
    assert rp.load(rp.save(S, tmp_path / "s")) == S
    r = mechanics.run_ensemble(mechanics.rigid_body([1, 2, 3], sigma=0.1), [0, 0, 1.0], dt=0.01, n_steps=10,
                               n_paths=6, seed=1, keep_final=True, record_every=5)
    loaded = rp.load(rp.save(r, tmp_path / "r"))
    assert loaded == r and not (loaded != r)
    other = mechanics.run_ensemble(mechanics.rigid_body([1, 2, 3], sigma=0.1), [0, 0, 1.0], dt=0.01, n_steps=10,
                                   n_paths=6, seed=2, keep_final=True, record_every=5)
    assert loaded != other and X != rp.brownian_rough_path(np.linspace(0, 1, 5), 2, 1, batch_shape=(3,))


def test_a_named_pipe_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / "pipe.npz"
    os.mkfifo(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        rp.load(fifo)
    with pytest.raises(ValueError, match="not a regular file"):
        rp.load(tmp_path)


def test_a_header_claiming_1e12_elements_is_refused_before_allocating(tmp_path, saved):
    _, path = saved
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
    forged = tmp_path / "huge.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(forged, "w") as dst:
        for info in src.infolist():
            dst.writestr(info, buf.getvalue() + b"\0" * 64 if info.filename == "increments.npy" else src.read(info))
    with pytest.raises(ValueError, match="huge.npz.*increments.npy.*declares shape"):
        rp.load(forged)


def test_a_zip_bomb_is_refused_before_expanding(tmp_path, saved):
    """A few hundred KiB of compressed zeros declaring 80 MB: refused from the headers, not inflated."""
    X, path = saved
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["x0"] = np.zeros((10**7,))
    bomb = tmp_path / "bomb.npz"
    np.savez_compressed(bomb, **arrays)
    assert bomb.stat().st_size < 10**6
    with pytest.raises(ValueError, match="bomb.npz expands from .* MiB .* zip bomb"):
        rp.load(bomb)


def test_declared_sizes_are_checked_against_the_budget(tmp_path, monkeypatch):
    X = rp.brownian_rough_path(np.linspace(0, 1, 200), 2, 0, batch_shape=(3,))   # ~30 kB of arrays
    path = rp.save(X, tmp_path / "x.npz")
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", "10000")          # above the zip directory's ~5 kB estimate
    with pytest.raises(ValueError, match="the arrays of .*x.npz.*memory budget"):
        rp.load(path)


def test_metadata_is_cross_checked_against_the_arrays(tmp_path, saved):
    X, path = saved
    cases = {
        "level 1 with areas": lambda m: m.update(level=1),
        "dimension": lambda m: m.update(dim=5),
        "batch shape": lambda m: m.update(batch_shape=[4]),
    }
    for name, edit in cases.items():
        with pytest.raises(ValueError, match="corrupt"):
            rp.load(_rewrite(path, tmp_path / f"{name.replace(' ', '_')}.npz", edit))
    # Stratonovich areas relabelled as Itô are refused; genuine Itô areas load
    with pytest.raises(ValueError, match="kind 'ito'"):
        rp.load(_rewrite(path, tmp_path / "ito.npz", lambda m: m.update(kind="ito")))
    S = rp.solve(rp.LinearVectorFields(0.1 * np.ones((2, 2, 2))), X.to_level1(), np.ones(2), rp.Heun())
    sp = rp.save(S, tmp_path / "s.npz")
    with pytest.raises(ValueError, match="times of shape .* and states of shape .* disagree"):
        rp.load(_rewrite(sp, tmp_path / "s2.npz", replace={"times": np.linspace(0, 1, 3)}))
    r = mechanics.run_ensemble(mechanics.rigid_body([1, 2, 3], sigma=0.1), [0, 0, 1.0], dt=0.01, n_steps=10,
                               n_paths=6, seed=1, keep_final=True)
    rpath = rp.save(r, tmp_path / "r.npz")
    with pytest.raises(ValueError, match="final_states has shape"):
        rp.load(_rewrite(rpath, tmp_path / "r2.npz", lambda m: m.update(state_dim=4)))


def test_deep_metadata_and_nan_metadata(tmp_path, saved):
    X, path = saved
    deep = []
    for _ in range(500):
        deep = [deep]
    with pytest.raises(ValueError, match="metadata entry is unreadable.*deeper than 64"):
        rp.load(_rewrite(path, tmp_path / "deep.npz", lambda m: m.update(user={"x": deep})))
    loop = {}
    loop["self"] = loop
    for bad in (loop, {"x": deep}):
        with pytest.raises(ValueError, match="nested deeper than 64"):
            rp.save(X, tmp_path / "deep2.npz", metadata=bad)
    with pytest.raises(ValueError, match="NaN or infinity"):
        rp.save(X, tmp_path / "nan.npz", metadata={"loss": float("nan")})
    assert not (tmp_path / "nan.npz").exists()


@settings(max_examples=40, deadline=None)
@given(meta=st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=5),
                         lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=3), c, max_size=3),
                         max_leaves=20),
       shape=st.lists(st.integers(0, 10**7), min_size=0, max_size=4))
def test_random_metadata_and_headers_give_an_object_or_a_clear_error(tmp_path_factory, meta, shape):
    """Property: whatever the metadata and the declared array shape, load returns or raises ValueError."""
    tmp = tmp_path_factory.mktemp("fuzz")
    X = rp.brownian_rough_path(np.linspace(0, 1, 3), 2, 0)
    path = rp.save(X, tmp / "x.npz")
    forged = _rewrite(path, tmp / "f.npz", lambda m: m.update(user=meta, n_steps=meta if isinstance(meta, int) else 2))
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": tuple(shape)})
    forged2 = tmp / "g.npz"
    with zipfile.ZipFile(forged) as src, zipfile.ZipFile(forged2, "w") as dst:
        for info in src.infolist():
            dst.writestr(info, buf.getvalue() + b"\0" * 32 if info.filename == "x0.npy" else src.read(info))
    for p in (forged, forged2):
        try:
            out = rp.load(p)
        except ValueError as exc:
            assert str(p) in str(exc)
        else:
            assert isinstance(out, rp.RoughPath)


def test_a_writer_killed_mid_write_leaves_nothing_after_the_next_write(tmp_path, saved):
    """The temporary of a dead writer (its PID gone) is removed by the next save to the same name; a live
    writer's is kept."""
    import subprocess
    import sys

    X, _ = saved
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stale = tmp_path / f".y.npz.{int(dead.stdout)}.abc.tmp"
    stale.write_bytes(b"half")
    live = tmp_path / f".y.npz.{os.getppid()}.def.tmp"
    live.write_bytes(b"in progress")
    rp.save(X, tmp_path / "y.npz")
    assert not stale.exists() and live.exists()
    assert rp.load(tmp_path / "y.npz") == X


def test_repeated_and_foreign_entries_are_refused(tmp_path, saved):
    """A zip holding two ``x0.npy`` (the old reader silently used one of them) or a non-``.npy`` member is not a
    file ``save`` writes: refused, naming the file and the entry."""
    X, path = saved
    twice = tmp_path / "twice.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(twice, "w") as dst:
        for info in src.infolist():
            dst.writestr(info.filename, src.read(info))
        with pytest.warns(UserWarning, match="Duplicate name"):
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.full(X.x0.shape, 7.0))
            dst.writestr("x0.npy", buf.getvalue())
    with pytest.raises(ValueError, match=r"twice.npz: entry 'x0.npy' is repeated"):
        rp.load(twice)
    foreign = tmp_path / "foreign.npz"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(foreign, "w") as dst:
        for info in src.infolist():
            dst.writestr(info.filename, src.read(info))
        dst.writestr("notes.txt", b"hello")
    with pytest.raises(ValueError, match=r"foreign.npz: entry 'notes.txt' is not an .npy array"):
        rp.load_metadata(foreign)


def test_open_npz_reads_what_the_headers_declare_and_refuses_other_expectations(tmp_path):
    """The one reader: shapes and dtypes come from the checked headers, a C- or Fortran-ordered array reads back
    equal, and an expectation the header does not meet is refused before the array is read."""
    from roughpaths.io import atomic_savez, open_npz

    a = np.arange(12.0).reshape(3, 4)
    f = atomic_savez(tmp_path / "a.npz", {"c": a, "f": np.asfortranarray(a), "i": np.arange(5)})
    with open_npz(f, fix="do something") as npz:
        assert npz.entries == {"c": ((3, 4), np.dtype(np.float64)), "f": ((3, 4), np.dtype(np.float64)),
                               "i": ((5,), np.dtype(np.int64))}
        np.testing.assert_array_equal(npz.read("c"), a)
        np.testing.assert_array_equal(npz.read("f"), a)
        with pytest.raises(ValueError, match=r"a.npz: the array 'i' has dtype int64, expected float64; do something"):
            npz.read("i", dtype=np.float64)
        with pytest.raises(ValueError, match=r"the array 'c' has shape \(3, 4\), expected \(4, 3\); do something"):
            npz.read("c", shape=(4, 3))
        with pytest.raises(ValueError, match=r"the array 'x' is missing"):
            npz.read("x")
    with pytest.raises(ValueError, match="is not a regular file"):
        open_npz("/dev/null")


def test_the_zip_directory_is_held_to_the_budget_before_it_is_parsed(tmp_path, monkeypatch):
    """``zipfile`` parses the whole directory into one object per entry before any entry can be checked, so its
    size is estimated first (``_DIRECTORY_COST`` bytes per byte of directory) and held to the budget. The
    estimate bounds what parsing a worst-case directory (10^4 entries with one-letter names) allocates."""
    import tracemalloc

    from roughpaths import _npz

    many = tmp_path / "many.npz"
    np.savez(many, **{f"a{i}": np.zeros(0) for i in range(2000)})
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**6))       # 2000 entries: ~0.1 MB of directory
    with pytest.raises(ValueError, match=r"the zip directory of .*many.npz \(\d+ bytes.*memory budget"):
        rp.load(many)
    monkeypatch.delenv("ROUGHPATHS_MAX_BYTES")
    with pytest.raises(ValueError, match="has no '__metadata__' entry"):
        rp.load(many)                                             # within the budget: read, then refused as foreign

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for i in range(10**4):
            zf.writestr(f"{i:x}", b"")                           # names of 1 to 4 letters
    zipfile.ZipFile(io.BytesIO(buf.getvalue()))                   # warm up zipfile's own structures
    directory = _npz._directory_bytes(io.BytesIO(buf.getvalue()), len(buf.getvalue()))
    assert 10**4 * 46 < directory < 10**4 * 60
    tracemalloc.start()
    try:
        zipfile.ZipFile(io.BytesIO(buf.getvalue()))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < _npz._DIRECTORY_COST * directory, (peak, directory)
