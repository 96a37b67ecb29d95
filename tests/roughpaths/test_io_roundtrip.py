"""Saving and loading ``RoughPath`` and ``Solution`` (``roughpaths.io``, format version 1).

Claims:

* round trip is bitwise: every array comes back with the same bytes, dtype and shape (checked on
  the raw bytes, so ``-0.0``, subnormals and NaN payloads count), and the non-array state (``kind``,
  level, ``Solution.stats`` with its tuples) is equal;
* the file is a plain ``.npz`` that :func:`numpy.load` reads without pickling, with the documented
  metadata (format and package version, area convention, seed);
* writing is atomic: a failure while writing leaves an existing file untouched and no temporary file;
* a wrong, truncated or corrupt file, one from a newer format version, or an unsupported object gives a
  clear ``ValueError``/``TypeError`` naming the file and the fix.
"""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import roughpaths
from roughpaths import RoughPath, Solution, brownian_rough_path, load, load_metadata, save
from roughpaths.io import FORMAT_VERSION


def assert_bitwise(a, b):
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype and a.shape == b.shape
    assert np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


def assert_same_rough_path(X, Y):
    assert type(Y) is RoughPath
    for name in ("times", "increments", "x0"):
        assert_bitwise(getattr(X, name), getattr(Y, name))
    if X.areas is None:
        assert Y.areas is None
    else:
        assert_bitwise(X.areas, Y.areas)
    assert (Y.kind, Y.level, Y.batch_shape) == (X.kind, X.level, X.batch_shape)


# ------------------------------------------------------------------------------------ round trips
@pytest.mark.parametrize("kind", ["stratonovich", "ito"])
def test_brownian_rough_path_round_trip(tmp_path, kind):
    times = np.cumsum(np.r_[0.0, np.random.default_rng(1).uniform(0.01, 0.1, 12)])  # non-uniform grid
    X = brownian_rough_path(times, 3, np.random.default_rng(5), batch_shape=(2, 4), kind=kind,
                            x0=[1.0, -2.0, 0.5])
    f = save(X, tmp_path / "X.npz", seed=5, metadata={"experiment": "unit test", "sizes": (2, 4)})
    Y = load(f)
    assert_same_rough_path(X, Y)
    assert Y.kind == ("ito" if kind == "ito" else "geometric")
    # derived quantities agree exactly too (same arrays in, same arithmetic)
    assert_bitwise(X.area(times[2], times[9]), Y.area(times[2], times[9]))
    meta = load_metadata(f)
    assert meta["format"] == "roughpaths-npz" and meta["format_version"] == FORMAT_VERSION == 1
    assert meta["type"] == "RoughPath" and meta["seed"] == 5
    assert meta["package_version"] == roughpaths.__version__
    assert "(X^i_r - X^i_s) dX^j_r" in meta["conventions"]["area"]
    assert "1/2" in meta["conventions"]["levy_area"]
    assert meta["user"] == {"experiment": "unit test", "sizes": (2, 4)}
    assert (meta["kind"], meta["level"], meta["dim"], meta["n_steps"]) == (Y.kind, 2, 3, 12)


def test_level1_and_general_paths(tmp_path):
    rng = np.random.default_rng(2)
    inc = rng.standard_normal((5, 2))
    X1 = RoughPath(inc, times=np.linspace(0.0, 2.0, 6))
    assert_same_rough_path(X1, load(save(X1, tmp_path / "level1")))
    areas = rng.standard_normal((5, 2, 2))  # not geometric
    Xg = RoughPath(inc, areas, kind="general")
    Y = load(save(Xg, tmp_path / "general.npz"))
    assert_same_rough_path(Xg, Y)
    assert Y.kind == "general" and load_metadata(tmp_path / "general.npz")["seed"] is None


def test_solution_round_trip(tmp_path):
    X = brownian_rough_path(np.linspace(0.0, 1.0, 21), 2, np.random.default_rng(3), batch_shape=(3,))
    V = roughpaths.LinearVectorFields(np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]]))
    sol = roughpaths.solve(V, X, np.array([1.0, 0.0]))
    back = load(save(sol, tmp_path / "sol.npz", seed=3))
    assert type(back) is Solution
    assert_bitwise(sol.times, back.times)
    assert_bitwise(sol.states, back.states)
    assert back.stats == sol.stats and isinstance(back.stats["batch_shape"], tuple)
    assert load_metadata(tmp_path / "sol.npz")["stats"] == sol.stats


@given(states=hnp.arrays(np.float64, hnp.array_shapes(min_dims=2, max_dims=4, max_side=4),
                         elements=st.floats(allow_nan=True, allow_infinity=True, allow_subnormal=True)))
def test_solution_arrays_bitwise_any_values(tmp_path_factory, states):
    """Every float64 bit pattern hypothesis draws (NaN, ±inf, -0.0, subnormals) survives."""
    times = np.arange(states.shape[-2], dtype=np.float64) * 0.1
    sol = Solution(times=times, states=states, stats={"note": "x", "n": 1, "t": (1, 2.5)})
    back = load(save(sol, tmp_path_factory.mktemp("h") / "s.npz"))
    assert_bitwise(sol.states, back.states)
    assert back.stats == sol.stats


def test_plain_npz_readable_without_pickle(tmp_path):
    X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
    f = save(X, tmp_path / "p")
    assert f.name == "p.npz"  # suffix appended, as numpy.savez does
    with np.load(f, allow_pickle=False) as data:
        assert set(data.files) == {"__metadata__", "times", "increments", "areas", "x0"}
        meta = json.loads(str(data["__metadata__"][()]))
        assert_bitwise(data["areas"], X.areas)
    assert meta["format_version"] == 1


# ------------------------------------------------------------------------------------ atomic writes
def test_failed_write_leaves_existing_file_untouched(tmp_path, monkeypatch):
    X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
    f = save(X, tmp_path / "x.npz")
    before = f.read_bytes()

    def broken_savez(fh, **arrays):
        fh.write(b"PK\x03\x04 partial")
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez", broken_savez)
    with pytest.raises(OSError, match="disk full"):
        save(RoughPath.from_path(np.zeros((4, 2))), f)
    assert f.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.npz"]  # no temporary file left


# ------------------------------------------------------------------------------------ bad input
@pytest.fixture
def saved(tmp_path):
    X = brownian_rough_path(np.linspace(0.0, 1.0, 33), 2, np.random.default_rng(0), batch_shape=(8,))
    return save(X, tmp_path / "X.npz")


def test_not_an_npz(tmp_path):
    f = tmp_path / "notes.npz"
    f.write_text("hello")
    with pytest.raises(ValueError, match="notes.npz is not a readable .npz file"):
        load(f)


def test_truncated_file(saved):
    data = saved.read_bytes()
    saved.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="corrupt|truncated"):
        load(saved)


def test_corrupt_bytes(saved):
    data = bytearray(saved.read_bytes())
    with zipfile.ZipFile(saved) as z:
        info = z.getinfo("increments.npy")
    # flip a byte inside the increments' payload (past the local header and the .npy header)
    pos = info.header_offset + 30 + len(info.filename) + 200
    data[pos] ^= 0xFF
    saved.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="corrupt"):
        load(saved)


def test_npz_from_elsewhere(tmp_path):
    f = tmp_path / "other.npz"
    np.savez(f, a=np.zeros(3))
    with pytest.raises(ValueError, match=r"not written by roughpaths.save \(it holds the arrays \['a'\]"):
        load(f)


def _rewrite_metadata(path, **changes):
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["__metadata__"][()]))
    meta.update(changes)
    arrays["__metadata__"] = np.array(json.dumps(meta))
    np.savez(path, **arrays)


def test_newer_format_version(saved):
    _rewrite_metadata(saved, format_version=FORMAT_VERSION + 1, package_version="9.0")
    with pytest.raises(ValueError, match=r"format version 2 \(written by roughpaths-mechanics 9.0\), newer "
                                         r"than the version .* reads \(1\); upgrade"):
        load(saved)
    with pytest.raises(ValueError, match="newer"):
        load_metadata(saved)


def test_missing_array_and_wrong_type(saved, tmp_path):
    with np.load(saved) as data:
        arrays = {k: data[k] for k in data.files if k != "areas"}
    np.savez(saved, **arrays)
    with pytest.raises(ValueError, match=r"arrays \['areas'\] are missing"):
        load(saved)
    _rewrite_metadata(saved, type="Ensemble")
    with pytest.raises(ValueError, match="unknown object type 'Ensemble'"):
        load(saved)


def test_inconsistent_rough_path_is_refused(saved):
    with np.load(saved) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["areas"] = arrays["areas"] + 1.0  # symmetric part no longer ½ X⊗X, but kind says geometric
    np.savez(saved, **arrays)
    with pytest.raises(ValueError, match="inconsistent .* not geometric"):
        load(saved)


def test_missing_file_and_bad_arguments(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.npz"):
        load(tmp_path / "nope.npz")
    with pytest.raises(TypeError, match="writes a RoughPath, a Solution or a registered type .*, got ndarray"):
        save(np.zeros(3), tmp_path / "a.npz")
    X = RoughPath.from_path(np.zeros((3, 2)))
    with pytest.raises(TypeError, match=r"metadata\['f'\] = .* has type builtin_function"):
        save(X, tmp_path / "a.npz", metadata={"f": print})
    with pytest.raises(TypeError, match="seed must be an int or None"):
        save(X, tmp_path / "a.npz", seed="7")
    assert not list(tmp_path.iterdir())
