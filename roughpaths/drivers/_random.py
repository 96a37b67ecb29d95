r"""Fast, bit-exact standard normals (private; used by the Brownian driver and samplers).

Two services, both reproducing numpy **bit for bit** (so that the stream of a seed is defined by
plain numpy calls and can be checked against them):

* :func:`standard_normal_into` ``(rng, out)``: ``rng.standard_normal(out=out)`` for a
  ``numpy.random.Generator``, same values and end state, faster (:mod:`roughpaths.drivers._ziggurat`).
* :class:`PathStreams`: one independent stream per path for many paths at once, the stream of
  key ``k`` (a tuple of ints) being::

      numpy.random.Generator(numpy.random.PCG64(
          numpy.random.SeedSequence(entropy, spawn_key=base_key + k))).standard_normal(...)

  ``fill(out)`` with ``out`` of shape ``(P, n)`` writes the next ``n`` normals of stream ``p``
  into ``out[p]``; successive calls continue the streams, so the numbers do not depend on how a
  stream is cut into calls. Fast path: the ``SeedSequence`` hashing, the ``PCG64`` seeding and
  stepping (128-bit LCG, XSL-RR output) and the ziggurat run in one numba kernel over all paths
  (no Python per path; seeding costs ~0.2 µs per stream instead of ~35 µs through numpy; up to
  :data:`_NUMPY_SEEDING` streams are seeded by numpy, which costs less than compiling or loading the kernel). Each
  path's words are generated first and then turned into normals by a branch-free ziggurat loop
  (:func:`_pcg64_fill`): about 5 ns per normal here, against 11 ns for numpy's
  ``standard_normal`` on one stream and 11 ns for the one-call-per-normal version it replaced.
  It is self-checked once per process against numpy on a few keys (``SeedSequence``,
  ``PCG64`` state, normals including the ziggurat tail); if the check fails (a future numpy
  changing an algorithm) the streams fall back to one numpy ``Generator`` per path, same
  numbers, slower.

The ziggurat (numpy's tables and algorithm over raw words) is :mod:`roughpaths.drivers._ziggurat`.

Compile cost (first call, empty cache, CPU, load about 1): the stream kernels of a first tree query or adaptive
solve take about 0.3-0.5 s each (:func:`_stream_states` 0.45-0.5, :func:`_pcg64_fill2` 0.4, :func:`_pcg64_rounds`
0.3, :func:`_pcg64_normals` 0.3-0.35, :func:`_pcg64_normal` 0.25). The kernels of the stream, ziggurat, area,
Fourier and tree modules compile with the library's one set of numba flags (``docs/architecture.md``,
``tests/test_kernel_flags.py``): numba keys its compiled ``@overload`` implementations (``np.empty`` and the like)
by the flags of the kernel being compiled, so mixed flags compiled some of them twice, and none of these kernels
is used as a first-class function (its cfunc wrapper was lowered and optimised for nothing). Together 0.2-0.5 s
less on the first call of the Brownian-tree and adaptive-solve families (medians of interleaved cold runs).
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from ._ziggurat import (_ZIG_F, _ZIG_INV_R, _ZIG_K, _ZIG_R, _ZIG_W, _abscissa, _split_word, _ziggurat_fill,
                        standard_normal_into)

__all__ = ["standard_normal_into", "PathStreams"]


# ----------------------------------------------------------------------------- SeedSequence
# numpy's SeedSequence (numpy/random/bit_generator.pyx), 32-bit arithmetic, pool size 4.
_INIT_A = np.uint32(0x43B0D7E5)
_MULT_A = np.uint32(0x931E8875)
_INIT_B = np.uint32(0x8B51F9DD)
_MULT_B = np.uint32(0x58F38DED)
_MIX_MULT_L = np.uint32(0xCA01F9DD)
_MIX_MULT_R = np.uint32(0x4973F715)
_XSHIFT = np.uint32(16)


@njit(cache=True, inline="always")
def _hashmix(value, hc):
    value = np.uint32(value ^ hc)
    hc = np.uint32(hc * _MULT_A)
    value = np.uint32(value * hc)
    value = np.uint32(value ^ (value >> _XSHIFT))
    return value, hc


@njit(cache=True, inline="always")
def _mix(x, y):
    r = np.uint32(np.uint32(_MIX_MULT_L * x) - np.uint32(_MIX_MULT_R * y))
    return np.uint32(r ^ (r >> _XSHIFT))


@njit(cache=True, inline="always")
def _generate_state(entropy, p, mixer, st32):
    """``SeedSequence`` pool of ``entropy[p]`` and its ``generate_state(4, uint64)``, as a tuple of four uint64.

    ``entropy`` (P, L) uint32: the assembled entropy words of each stream (``L >= 4``: the run entropy padded
    to the pool size, then the spawn key); ``mixer`` (4,) and ``st32`` (8,) uint32 scratch.
    """
    L = entropy.shape[1]
    hc = _INIT_A
    for i in range(4):
        mixer[i], hc = _hashmix(entropy[p, i], hc)
    for i_src in range(4):
        for i_dst in range(4):
            if i_src != i_dst:
                v, hc = _hashmix(mixer[i_src], hc)
                mixer[i_dst] = _mix(mixer[i_dst], v)
    for i_src in range(4, L):
        for i_dst in range(4):
            v, hc = _hashmix(entropy[p, i_src], hc)
            mixer[i_dst] = _mix(mixer[i_dst], v)
    hb = _INIT_B
    for i in range(8):
        v = np.uint32(mixer[i % 4] ^ hb)
        hb = np.uint32(hb * _MULT_B)
        v = np.uint32(v * hb)
        v = np.uint32(v ^ (v >> _XSHIFT))
        st32[i] = v
    w = np.uint64(32)
    return (np.uint64(st32[0]) | (np.uint64(st32[1]) << w), np.uint64(st32[2]) | (np.uint64(st32[3]) << w),
            np.uint64(st32[4]) | (np.uint64(st32[5]) << w), np.uint64(st32[6]) | (np.uint64(st32[7]) << w))


# ----------------------------------------------------------------------------- PCG64
_PCG_MUL = (2549297995355413924 << 64) | 4865540595714422341       # numpy's PCG_DEFAULT_MULTIPLIER_128


@intrinsic
def _lcg(typingctx, sh, sl, ih, il):
    """One step of PCG64's 128-bit LCG, ``s <- s * MUL + inc (mod 2**128)``, on (hi, lo) uint64 halves.

    Written as an LLVM ``i128`` multiply-add (twice as fast as emulating it with 64-bit halves).
    """
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        i128, i64 = ir.IntType(128), ir.IntType(64)
        c64 = ir.Constant(i128, 64)

        def join(hi, lo):
            return builder.or_(builder.shl(builder.zext(hi, i128), c64), builder.zext(lo, i128))

        r = builder.add(builder.mul(join(args[0], args[1]), ir.Constant(i128, _PCG_MUL)), join(args[2], args[3]))
        lo = builder.trunc(r, i64)
        hi = builder.trunc(builder.lshr(r, c64), i64)
        return context.make_tuple(builder, signature.return_type, [hi, lo])

    return sig, codegen


@njit(cache=True, inline="always")
def _xsl_rr(sh, sl):
    x = sh ^ sl
    rot = sh >> np.uint64(58)
    return (x >> rot) | (x << ((np.uint64(64) - rot) & np.uint64(63)))


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _stream_states(entropy, states):
    """PCG64 states ``(P, 4)`` = (state_hi, state_lo, inc_hi, inc_lo) of the streams whose ``SeedSequence``
    entropy words are the rows of ``entropy`` (P, L) uint32 (see :func:`_generate_state`): numpy's
    ``PCG64(SeedSequence(...))`` seeding from ``generate_state(4, uint64)``. One kernel for both steps (two
    kernels compiled ~0.15 s longer)."""
    one = np.uint64(1)
    mixer = np.empty(4, dtype=np.uint32)
    st32 = np.empty(8, dtype=np.uint32)
    for p in range(entropy.shape[0]):
        s0, s1, s2, s3 = _generate_state(entropy, p, mixer, st32)
        ih = (s2 << one) | (s3 >> np.uint64(63))
        il = (s3 << one) | one
        sh, sl = _lcg(np.uint64(0), np.uint64(0), ih, il)
        lo = sl + s1
        sh = sh + s0 + (one if lo < sl else np.uint64(0))
        sh, sl = _lcg(sh, lo, ih, il)
        states[p, 0] = sh
        states[p, 1] = sl
        states[p, 2] = ih
        states[p, 3] = il


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _pcg64_normal(sh, sl, ih, il):
    """One standard normal (numpy's ziggurat) from PCG64 state ``(sh, sl)``; returns ``(x, sh, sl)``.

    The tables are module globals (numba freezes them as constants): passing them as arguments
    costs a reference count per call, and an ``inline="always"`` version multiplied the
    compile time of its callers.
    """
    ki, wi, fi, r_tail, inv_r = _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R
    one = np.uint64(1)
    s8 = np.uint64(8)
    s11 = np.uint64(11)
    scale = 1.0 / 9007199254740992.0
    while True:
        sh, sl = _lcg(sh, sl, ih, il)
        idx, rabs, neg = _split_word(_xsl_rr(sh, sl))
        x = _abscissa(idx, rabs, neg, wi)
        if rabs < ki[idx]:
            return x, sh, sl
        if idx == 0:
            while True:
                sh, sl = _lcg(sh, sl, ih, il)
                u1 = float(_xsl_rr(sh, sl) >> s11) * scale
                sh, sl = _lcg(sh, sl, ih, il)
                u2 = float(_xsl_rr(sh, sl) >> s11) * scale
                xx = -inv_r * math.log1p(-u1)
                yy = -math.log1p(-u2)
                if yy + yy > xx * xx:
                    return (-(r_tail + xx) if (rabs >> s8) & one else r_tail + xx), sh, sl
        else:
            sh, sl = _lcg(sh, sl, ih, il)
            u = float(_xsl_rr(sh, sl) >> s11) * scale
            if (fi[idx - 1] - fi[idx]) * u + fi[idx] < math.exp(-0.5 * x * x):
                return x, sh, sl


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _pcg64_rounds(sh, sl, ih, il, out, buf, left, i):
    """Continue filling ``out[i:]`` from PCG64 state ``(sh, sl)``; ``buf[:left]`` holds words not yet used.

    Words are requested as in :func:`_fill_normals_raw` (``n - i`` at a time, an unfinished
    attempt carried over), which never draws a word the ziggurat does not use, so the state
    ends where the one-normal version :func:`_pcg64_normal` leaves it. Returns ``(sh, sl)``.
    """
    n = out.size
    while i < n:
        need = n - i
        if left + need > buf.size:
            nb = np.empty(left + need + 64, dtype=np.uint64)
            for j in range(left):            # a loop, not nb[:left] = buf[:left]: the slice's shape check
                nb[j] = buf[j]               # compiles numba's error formatting (~3 s of CPU)
            buf = nb
        for j in range(left, left + need):
            sh, sl = _lcg(sh, sl, ih, il)
            buf[j] = _xsl_rr(sh, sl)
        used, i = _ziggurat_fill(buf[:left + need], out, i, _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)
        left = left + need - used
        for j in range(left):
            buf[j] = buf[used + j]
    return sh, sl


@njit(cache=True, nogil=True, inline="always")
def _pcg64_fill(states, p, out, words):
    """``out`` (1-D) <- the next ``out.size`` normals of PCG64 stream ``states[p]``; the state advances.

    Same numbers and end state as :func:`_pcg64_normal` called ``out.size`` times, in two
    passes: the LCG writes raw words into ``words`` (uint64 scratch; a larger one is allocated if
    needed), then :func:`_ziggurat_fill` turns them into normals. Both passes are tight loops
    without calls (one call per normal measured ~2x slower). Inlined into its callers (as a kernel of its own
    it compiled for ~0.2 s more).
    """
    zero = np.int64(0)                   # not the literal 0, which numba compiles as a variant of its own
    sh, sl = _pcg64_rounds(states[p, 0], states[p, 1], states[p, 2], states[p, 3], out, words, zero, zero)
    states[p, 0] = sh
    states[p, 1] = sl


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _pcg64_fill2(states, p, q, out_p, out_q, words_p, words_q):
    """:func:`_pcg64_fill` for two streams ``p``, ``q`` and rows of equal length, same numbers.

    The first ``n`` words of both streams are generated in one loop (two independent LCG chains
    overlap in the pipeline: ~1.3x faster word generation); the rest as in :func:`_pcg64_fill`.
    """
    n = out_p.size
    ph, pl, pih, pil = states[p, 0], states[p, 1], states[p, 2], states[p, 3]
    qh, ql, qih, qil = states[q, 0], states[q, 1], states[q, 2], states[q, 3]
    for j in range(n):
        ph, pl = _lcg(ph, pl, pih, pil)
        words_p[j] = _xsl_rr(ph, pl)
        qh, ql = _lcg(qh, ql, qih, qil)
        words_q[j] = _xsl_rr(qh, ql)
    used, i = _ziggurat_fill(words_p[:n], out_p, np.int64(0), _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)
    for j in range(n - used):
        words_p[j] = words_p[used + j]
    states[p, 0], states[p, 1] = _pcg64_rounds(ph, pl, pih, pil, out_p, words_p, n - used, i)
    used, i = _ziggurat_fill(words_q[:n], out_q, np.int64(0), _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)
    for j in range(n - used):
        words_q[j] = words_q[used + j]
    states[q, 0], states[q, 1] = _pcg64_rounds(qh, ql, qih, qil, out_q, words_q, n - used, i)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _pcg64_normals(states, out):
    """Row ``p`` of ``out (P, n)`` <- the next ``n`` standard normals of PCG64 stream ``states[p]``."""
    P, n = out.shape
    wp = np.empty(n + 64, dtype=np.uint64)
    wq = np.empty(n + 64, dtype=np.uint64)
    for p in range(0, P - 1, 2):
        _pcg64_fill2(states, p, p + 1, out[p], out[p + 1], wp, wq)
    if P % 2:
        _pcg64_fill(states, P - 1, out[P - 1], wp)


def _uint32_words(value: int) -> list:
    """numpy's ``_coerce_to_uint32_array`` for one non-negative int (little-endian 32-bit words)."""
    if value == 0:
        return [0]
    words = []
    while value:
        words.append(value & 0xFFFFFFFF)
        value >>= 32
    return words


def _entropy_words(seed_seq: np.random.SeedSequence) -> list:
    ent = seed_seq.entropy
    if isinstance(ent, (int, np.integer)):
        words = _uint32_words(int(ent))
    else:
        words = [w for v in ent for w in _uint32_words(int(v))]
    return words


def stream_prefix(seed_seq: np.random.SeedSequence) -> np.ndarray:
    """The entropy words (uint32) that every stream of ``seed_seq`` hashes before its key: the run entropy
    padded to the pool size 4 (numpy's ``hashmix(0)`` fill), then the spawn key."""
    run = _entropy_words(seed_seq)
    run = run + [0] * max(0, 4 - len(run))
    return np.array(run + [w for v in seed_seq.spawn_key for w in _uint32_words(int(v))], dtype=np.uint32)


_FAST_OK: list = []
#: Streams up to this many are seeded by numpy itself (about 35 µs a stream): a small batch, what first calls and
#: tests use, then never compiles the seeding kernel (:func:`_stream_states`, about 0.5 s of CPU), and even
#: loading the cached kernel in a new process costs more than numpy's seeding of 32 streams.
_NUMPY_SEEDING = 32
_SEEDING_CHECKED: list = []
_MASK64 = (1 << 64) - 1


def _numpy_states(seed_seq: np.random.SeedSequence, keys) -> np.ndarray:
    """PCG64 states ``(P, 4)`` (state hi, lo, increment hi, lo) of the streams of ``keys``, seeded by numpy."""
    states = np.empty((len(keys), 4), dtype=np.uint64)
    for j, k in enumerate(keys):
        st = np.random.PCG64(np.random.SeedSequence(
            seed_seq.entropy, spawn_key=tuple(seed_seq.spawn_key) + tuple(int(v) for v in k),
            pool_size=seed_seq.pool_size)).state["state"]
        states[j] = (st["state"] >> 64, st["state"] & _MASK64, st["inc"] >> 64, st["inc"] & _MASK64)
    return states


def _fast_streams_ok() -> bool:
    """One-off self-check of the numba SeedSequence/PCG64/ziggurat against numpy (cached per process)."""
    if not _FAST_OK:
        ok = _ZIG_K is not None
        if ok:
            try:
                for ent, base in ((12345, ()), (2**70 + 3, (7,)), ([1, 2**40], ())):
                    ss = np.random.SeedSequence(ent, spawn_key=base)
                    keys = [(0, 0), (1, 1), (2**33 + 5, 0)]
                    s = PathStreams(ss, keys, _force_numpy=False)
                    # two contiguous blocks (fill copies a strided block into a contiguous one, so that
                    # no layout compiles a second specialisation of the kernels, ~15 s of CPU)
                    first, rest = np.empty((len(keys), 1000)), np.empty((len(keys), 2000))
                    s.fill(first)
                    s.fill(rest)
                    got = np.concatenate([first, rest], axis=1)
                    for j, k in enumerate(keys):
                        g = np.random.Generator(np.random.PCG64(
                            np.random.SeedSequence(ent, spawn_key=base + k)))
                        ok = ok and np.array_equal(got[j], g.standard_normal(3000))
            except Exception:  # pragma: no cover - defensive: any failure means "use numpy"
                ok = False
        _FAST_OK.append(bool(ok))
    return _FAST_OK[0]


class PathStreams:
    """Independent standard-normal streams, one per key, continued across :meth:`fill` calls.

    Stream ``j`` is that of ``numpy.random.Generator(numpy.random.PCG64(SeedSequence(
    seed_seq.entropy, spawn_key=seed_seq.spawn_key + keys[j], pool_size=seed_seq.pool_size)))``.

    Parameters
    ----------
    seed_seq : numpy.random.SeedSequence
        Root of the streams (its ``pool_size`` must be 4, numpy's default, for the fast path).
    keys : sequence of tuples of non-negative ints, or ndarray ``(P, k)`` of int
        The spawn-key suffix of each stream.
    """

    def __init__(self, seed_seq, keys, *, _force_numpy=None):
        keys = np.asarray(keys, dtype=object) if not isinstance(keys, np.ndarray) else keys
        self._seed_seq = seed_seq
        self._keys = keys
        self.n_streams = int(keys.shape[0])
        fast = (seed_seq.pool_size == 4 and _fast_streams_ok()) if _force_numpy is None else not _force_numpy
        self._fast = fast
        #: ``(P, 4)`` uint64 PCG64 states (hi, lo, inc hi, inc lo) on the fast path, else None
        self.states = None
        if fast:
            self.states = self._fast_states()
        else:
            self._gens = [np.random.Generator(np.random.PCG64(np.random.SeedSequence(
                seed_seq.entropy, spawn_key=tuple(seed_seq.spawn_key) + tuple(int(v) for v in k),
                pool_size=seed_seq.pool_size))) for k in keys]

    def _fast_states(self) -> np.ndarray:
        ss = self._seed_seq
        keys = self._keys
        P = self.n_streams
        if P <= _NUMPY_SEEDING:
            return _numpy_states(ss, keys)
        run = _entropy_words(ss)
        base = [w for v in ss.spawn_key for w in _uint32_words(int(v))]
        kint = np.asarray(keys, dtype=np.int64) if keys.dtype != object else None
        states = np.empty((P, 4), dtype=np.uint64)
        if kint is not None and kint.ndim == 2 and kint.min(initial=0) >= 0 and kint.max(initial=0) < 2**32:
            # the common case: every key element is one 32-bit word, the entropy rows have one length
            prefix = stream_prefix(ss)
            ent = np.empty((P, prefix.size + kint.shape[1]), dtype=np.uint32)
            ent[:, :prefix.size] = prefix
            ent[:, prefix.size:] = kint.astype(np.uint32)
            _stream_states(ent, states)
        else:
            for j, k in enumerate(keys):
                spawn = base + [w for v in k for w in _uint32_words(int(v))]
                r = run + [0] * max(0, 4 - len(run))    # zero padding == numpy's hashmix(0) fill
                _stream_states(np.array([r + spawn], dtype=np.uint32), states[j:j + 1])
        if not _SEEDING_CHECKED:                        # once a process: the kernel's first row against numpy's
            _SEEDING_CHECKED.append(np.array_equal(states[:1], _numpy_states(ss, keys[:1])))
        return states if _SEEDING_CHECKED[0] else _numpy_states(ss, keys)

    def fill(self, out: np.ndarray) -> None:
        """Write the next ``out.shape[1]`` normals of stream ``p`` into ``out[p]`` (``out`` float64 ``(P, n)``)."""
        if out.shape[0] != self.n_streams or out.ndim != 2 or out.dtype != np.float64:
            raise ValueError(f"out must be float64 of shape ({self.n_streams}, n), got {out.dtype} {out.shape}.")
        if self._fast:
            if out.flags.c_contiguous:
                _pcg64_normals(self.states, out)
            else:                       # a strided block (e.g. a column slice) would compile every stream kernel
                block = np.empty(out.shape)     # again for its layout (about 15 s of CPU): fill a copy instead
                _pcg64_normals(self.states, block)
                out[...] = block
        else:
            for p, g in enumerate(self._gens):
                row = out[p]
                if row.flags.c_contiguous:
                    standard_normal_into(g, row)
                else:
                    out[p] = g.standard_normal(out.shape[1])
