"""SignatureStream and windowed_signature: every answer against the direct signature of the sub-path
(roughpaths.signature on ``x[s:t+1]``), to the tolerance the module docstring states, and the reason for
the tree: the prefixes-and-inverse answer loses digits that the tree keeps."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import roughpaths as rp


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own id: its numbers do not depend on which tests ran before it
    (a module-wide generator gave each test other paths under another order of the suite)."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


def _brownian(rng, batch, n, d, step):
    inc = rng.normal(scale=step, size=batch + (n - 1, d))
    return np.concatenate([np.zeros(batch + (1, d)), inc.cumsum(axis=-2)], axis=-2)


def _levels(sig, d, depth):
    off = np.cumsum([0] + [d ** k for k in range(1, depth + 1)])
    return [sig[..., off[k]:off[k + 1]] for k in range(depth)]


def _assert_close_by_level(got, want, d, depth, rtol):
    """Each level to ``rtol`` times that level's largest entry (the scale a Chen product's rounding follows)."""
    for k, (g, w) in enumerate(zip(_levels(got, d, depth), _levels(want, d, depth)), start=1):
        scale = np.max(np.abs(w), axis=-1, keepdims=True)
        assert np.all(np.abs(g - w) <= rtol * scale), (k, float(np.max(np.abs(g - w) / np.maximum(scale, 1e-300))))


@pytest.mark.parametrize("block", [1, 3, 8, 32])
def test_stream_answers_equal_direct_signatures(rng, block):
    d, depth, n = 2, 4, 300
    x = _brownian(rng, (2,), n, d, 0.1)
    stream = rp.SignatureStream(x, depth, block=block)
    s = np.array([[0, 0, 5, 17], [100, 299, 31, 32], [7, 8, 63, 64]])
    t = np.array([[299, 0, 6, 40], [280, 299, 33, 96], [7, 200, 64, 299]])
    got = stream.signature(s, t)
    assert got.shape == (2, 3, 4, rp.sigdim(d, depth))
    want = np.stack([[[rp.signature(x[b, a:c + 1], depth) for a, c in zip(rs, rt)] for rs, rt in zip(s, t)]
                     for b in range(2)])
    zero = s == t
    assert np.all(got[:, zero] == 0.0)
    _assert_close_by_level(got[:, ~zero], want[:, ~zero], d, depth, 1e-12)
    logs = stream.logsignature(s, t)
    want_log = np.stack([[[rp.logsignature(x[b, a:c + 1], depth) for a, c in zip(rs, rt)] for rs, rt in zip(s, t)]
                         for b in range(2)])
    np.testing.assert_allclose(logs, want_log, rtol=0, atol=1e-12 * np.abs(want_log).max())


def test_stream_random_queries_and_scalar_query(rng):
    d, depth, n = 3, 3, 1000
    x = _brownian(rng, (), n, d, 0.05)
    stream = rp.SignatureStream(x, depth)
    s = rng.integers(0, n, size=60)
    t = np.minimum(n - 1, s + rng.integers(0, 400, size=60))
    got = stream.signature(s, t)
    for q in range(60):
        if s[q] < t[q]:
            _assert_close_by_level(got[q], rp.signature(x[s[q]:t[q] + 1], depth), d, depth, 1e-12)
    assert stream.signature(3, 900).shape == (rp.sigdim(d, depth),)
    np.testing.assert_array_equal(stream.signature(3, 900), stream.signature([3], [900])[0])


def test_stream_keeps_the_digits_that_prefixes_and_inverse_lose(rng):
    """Short windows late on a path whose prefix is large: the prefixes-and-inverse answer
    S(0,s)^{-1} ⊗ S(0,t) loses about (|X_{0,s}| / |X_{s,t}|)^k eps relative at level k (measured
    here: 2e-5 at level 5); the tree's answer stays at rounding level of the window itself."""
    d, depth, n = 2, 5, 20_001
    x = _brownian(rng, (), n, d, 1e-2)
    stream = rp.SignatureStream(x, depth)
    s = np.array([15_000, 17_321, 19_990])
    t = s + 2
    direct = np.stack([rp.signature(x[a:b + 1], depth) for a, b in zip(s, t)])
    inverse = rp.tensor_product(rp.tensor_inverse(np.stack([rp.signature(x[:a + 1], depth) for a in s]), d),
                                np.stack([rp.signature(x[:b + 1], depth) for b in t]), d)
    _assert_close_by_level(stream.signature(s, t), direct, d, depth, 1e-12)
    top = _levels(direct, d, depth)[-1]
    rel = np.max(np.abs(_levels(inverse, d, depth)[-1] - top)) / np.max(np.abs(top))
    print(f"prefixes-and-inverse, level {depth}: relative error {rel:.1e}")
    assert rel > 1e-10, rel       # the alternative the stream does not use really is worse


def test_stream_on_a_long_path_is_bounded_by_the_windows_own_size(rng):
    """10^5 points; queries of every size, the answer against the direct signature to 1e-12 per level."""
    d, depth, n = 2, 4, 100_001
    x = _brownian(rng, (), n, d, 1e-3)
    stream = rp.SignatureStream(x, depth)
    s = np.array([0, 50_000, 99_990, 12_345, 70_000])
    t = np.array([100_000, 50_010, 100_000, 87_654, 70_001])
    want = np.stack([rp.signature(x[a:b + 1], depth) for a, b in zip(s, t)])
    _assert_close_by_level(stream.signature(s, t), want, d, depth, 1e-12)


@pytest.mark.slow
def test_stream_on_a_million_points(rng):
    """The module docstring's measurement: 10^6 points, d = 2, depth 4, windows of 10, 10^3 and 10^5 steps
    in the second half; the stream within 1e-12 of each level's largest entry (measured: below 4e-15)."""
    d, depth, n = 2, 4, 1_000_001
    x = _brownian(rng, (), n, d, 1e-3)
    stream = rp.SignatureStream(x, depth)
    for w in (10, 1000, 100_000):
        s = rng.integers(n // 2, n - 1 - w, size=10)
        want = np.stack([rp.signature(x[a:a + w + 1], depth) for a in s])
        _assert_close_by_level(stream.signature(s, s + w), want, d, depth, 1e-12)


@pytest.mark.parametrize("expanding", [False, True])
@pytest.mark.parametrize("length, step", [(1, 1), (5, 2), (40, 7), (80, 3)])
def test_windowed_signature_matches_loops(rng, expanding, length, step):
    d, depth, n = 2, 3, 120
    x = _brownian(rng, (3,), n, d, 0.2)
    got = rp.windowed_signature(x, depth, length, step=step, expanding=expanding)
    got_log = rp.windowed_signature(x, depth, length, step=step, expanding=expanding, log=True)
    windows = []
    k = 0
    while length + k * step <= n - 1:
        windows.append((0 if expanding else k * step, length + k * step))
        k += 1
    assert got.shape == (3, len(windows), rp.sigdim(d, depth))
    want = np.stack([[rp.signature(x[b, a:c + 1], depth) for a, c in windows] for b in range(3)])
    want_log = np.stack([[rp.logsignature(x[b, a:c + 1], depth) for a, c in windows] for b in range(3)])
    _assert_close_by_level(got, want, d, depth, 1e-12)
    np.testing.assert_allclose(got_log, want_log, rtol=0, atol=1e-12 * np.abs(want_log).max())


def test_a_block_longer_than_the_path_is_the_whole_path(rng):
    x = _brownian(rng, (), 30, 2, 1.0)
    stream = rp.SignatureStream(x, 3, block=10 ** 12)
    assert stream.block == 29
    _assert_close_by_level(stream.signature(2, 27), rp.signature(x[2:28], 3), 2, 3, 1e-12)


def test_one_point_and_one_channel(rng):
    x = np.array([[2.0]])
    assert np.all(rp.SignatureStream(x, 3).signature(0, 0) == 0.0)
    y = _brownian(rng, (), 50, 1, 1.0)
    got = rp.SignatureStream(y, 4, block=4).signature([0, 10], [49, 30])
    for q, (a, b) in enumerate([(0, 49), (10, 30)]):
        inc = y[b, 0] - y[a, 0]
        # Chen products of the blocks: rounding relative to the window's excursion, not to the (maybe small) increment
        big = np.max(np.abs(y[a:b + 1, 0] - y[a, 0]))
        for k, v in enumerate([inc, inc ** 2 / 2, inc ** 3 / 6, inc ** 4 / 24]):
            np.testing.assert_allclose(got[q][k], v, rtol=1e-12, atol=1e-13 * big ** (k + 1))


@pytest.mark.parametrize("call, exc, word", [
    (lambda st: st.signature(5, 3), ValueError, "s must be <= t"),
    (lambda st: st.signature(-1, 3), ValueError, "s holds"),
    (lambda st: st.signature(0, 10), ValueError, "t holds"),
    (lambda st: st.signature(0.0, 3), TypeError, "s must"),
    (lambda st: st.signature([0, 1], [2, 3, 4]), ValueError, "broadcast"),
    (lambda st: st.logsignature(0, "3"), TypeError, "t must"),
])
def test_stream_refuses_bad_queries(rng, call, exc, word):
    stream = rp.SignatureStream(_brownian(rng, (), 10, 2, 1.0), 2)
    with pytest.raises(exc, match=word):
        call(stream)


@pytest.mark.parametrize("call, exc, word", [
    (lambda: rp.SignatureStream("x", 2), TypeError, "paths"),
    (lambda: rp.SignatureStream(np.ones((4, 2)), 0), ValueError, "depth"),
    (lambda: rp.SignatureStream(np.ones((4, 2)), 2, block=0), ValueError, "block"),
    (lambda: rp.SignatureStream(np.ones((0, 2)), 2), ValueError, "paths"),
    (lambda: rp.windowed_signature(np.ones((4, 2)), 2, 4), ValueError, "length"),
    (lambda: rp.windowed_signature(np.ones((4, 2)), 2, 1, step=0), ValueError, "step"),
    (lambda: rp.windowed_signature(np.ones((4, 2)), 2, 1, expanding="yes"), TypeError, "expanding"),
    (lambda: rp.windowed_signature(np.ones((4, 2)), 2, 1, log=1), TypeError, "log"),
])
def test_constructors_refuse_bad_input(call, exc, word):
    with pytest.raises(exc, match=word):
        call()


@pytest.mark.parametrize("batch", [(0,), (2, 0)])
@pytest.mark.parametrize("length, expanding, log", [(3, False, False), (3, False, True), (3, True, False),
                                                    (70, False, False), (70, True, True)])
def test_an_empty_batch_axis_gives_empty_answers(batch, length, expanding, log):
    """An empty batch axis is a batch of no paths: empty answers of the documented shape (the tensor
    algebra's products reshaped to ``-1``, which numpy cannot infer on size 0, raised instead)."""
    n, d, depth = 100, 2, 3
    W = (n - 1 - length) + 1
    width = (2 + 1 + 2) if log else (2 + 4 + 8)                 # logsigdim(2, 3), sigdim(2, 3)
    got = rp.windowed_signature(np.zeros(batch + (n, d)), depth, length, expanding=expanding, log=log)
    assert got.shape == batch + (W, width)
    stream = rp.SignatureStream(np.zeros(batch + (n, d)), depth, block=8)
    assert stream.signature([0, 5, 7], [99, 50, 7]).shape == batch + (3, 14)
    assert stream.logsignature(3, 40).shape == batch + (5,)


def test_windows_of_one_point_paths_are_refused_with_a_fix_that_works():
    """One point has no step, so no window fits. The refusal said 'pass length <= 1' although length=1 was the
    value refused; it now asks for longer paths, and the length it names for two points does work."""
    with pytest.raises(ValueError, match=r"1 point .* at least 2 points") as info:
        rp.windowed_signature(np.ones((3, 1, 2)), 2, 1)
    assert "length <= 1" not in str(info.value)
    x = np.array([[0.0, 0.0], [1.0, 2.0]])
    with pytest.raises(ValueError, match=r"pass length <= 1 "):
        rp.windowed_signature(x, 2, 2)
    np.testing.assert_allclose(rp.windowed_signature(x, 2, 1), [[1.0, 2.0, 0.5, 1.0, 1.0, 2.0]])   # exp(1, 2)


def test_broadcast_queries_are_refused_before_their_allocation(rng, monkeypatch):
    """``s`` and ``t`` broadcast to the query shape; an outer product of index arrays (4000 x 4000 queries) was
    compared (``s > t``, 16 MB) before the memory check refused the answers. The check now comes first: the
    refusal allocates nothing of the queries' size (tracemalloc traces numpy's allocations)."""
    import tracemalloc

    x = _brownian(rng, (), 50, 2, 1.0)
    stream = rp.SignatureStream(x, 2)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10 ** 6))
    s, t = np.zeros((4000, 1), dtype=np.int64), (np.arange(4000) % 50)[None]
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match="memory budget"):
            stream.signature(s, t)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10 ** 6, peak
    got = stream.signature(s[:3], t[:, :4])                     # a small outer product is answered
    assert got.shape == (3, 4, 6)
    np.testing.assert_allclose(got[1, 3], rp.signature(x[0:4], 2), rtol=1e-12)


@pytest.mark.parametrize("call", [
    lambda x: rp.windowed_signature(x, 3, 16),
    lambda x: rp.windowed_signature(x, 3, 16, log=True),
    lambda x: rp.windowed_signature(x, 3, 100, log=True),
    lambda x: rp.windowed_signature(x, 3, 100, expanding=True),
    lambda x: rp.SignatureStream(x, 3, block=8).logsignature(np.arange(1000), np.arange(999, 1999)),
], ids=["sliding", "sliding log", "long sliding log", "expanding", "stream queries log"])
def test_a_call_the_memory_budget_accepts_stays_within_it(monkeypatch, call):
    """Under any budget a call is refused or allocates at most the budget (tracemalloc). Only the result was
    estimated (1.2e7 bytes for the sliding signatures) while the chunks' signatures were joined by a concatenation
    (twice the result) and the log taken of all of them at once: 4.6 to 6.5 times the estimate was allocated."""
    import tracemalloc

    x = np.random.default_rng(0).normal(size=(20, 2000, 3)).cumsum(axis=-2) * 0.05
    call(x[:1])                                           # compiled and cached before measuring
    accepted = 0
    for mib in (8, 16, 32, 64, 128, 256):
        monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(mib * 2 ** 20))
        tracemalloc.start()
        try:
            call(x)
            peak = tracemalloc.get_traced_memory()[1]
        except ValueError as err:
            assert "would take" in str(err)
            continue
        finally:
            tracemalloc.stop()
        accepted += 1
        assert peak <= mib * 2 ** 20, f"accepted under a budget of {mib} MiB, allocated {peak / 2 ** 20:.1f} MiB"
    assert accepted, "refused under every budget"


def _two_ramps(first: float, second: float) -> np.ndarray:
    """A 41-point path in d = 1 rising by ``first`` over points 0..32 and by ``second`` over 32..40."""
    return np.concatenate([np.linspace(0.0, first, 33), first + np.linspace(0.0, second, 9)[1:]])[:, None]


@pytest.mark.parametrize("log", [False, True])
def test_a_query_whose_tree_product_overflows_is_refused_with_the_fix(log):
    # the block [0, 32] and the partial block [32, 40] have finite signatures (level 2 ~ 1.1e308 each), their Chen
    # product does not (~4.5e308): the query returned inf (its log-signature nan) without an error
    x = _two_ramps(1.5e154, 1.5e154)
    stream = rp.SignatureStream(x, 2, block=32)
    query = stream.logsignature if log else stream.signature
    assert np.all(np.isfinite(query([0, 32], [32, 40])))            # each piece alone is representable
    with pytest.raises(ValueError, match=r"depth-2 (log-)?signature \(a SignatureStream query\).*overflows "
                                         r"float64.*Rescale the paths"):
        query(0, 40)
    with pytest.raises(ValueError, match=r"overflows float64.*Rescale the paths"):
        rp.windowed_signature(x, 2, 8, step=32, expanding=True, log=log)   # windows [0, 8], [0, 40]
    y = _two_ramps(1.5e153, 1.5e153)                                 # rescaled: answered, equal to the direct one
    np.testing.assert_allclose(rp.SignatureStream(y, 2, block=32).signature(0, 40), rp.signature(y, 2), rtol=1e-13)


def test_a_query_through_an_overflowed_tree_node_is_refused_naming_the_paths():
    # a node of the tree (the product of two blocks) overflowed: the next product refused it as "b contains non-finite
    # values ... remove or interpolate them", an input the caller never passed
    x = np.cumsum(np.ones((1000, 2)), axis=0) * 3e151
    stream = rp.SignatureStream(x, 2, block=32)
    assert np.all(np.isfinite(stream.signature(0, 31)))
    with pytest.raises(ValueError, match=r"depth-2 signature \(a SignatureStream query\) of paths \(finite, values "
                                         r"up to 3e\+154.*Rescale the paths"):
        stream.signature(0, 999)
