r"""Stratonovich Brownian forcing for the deprecated :func:`simulate_brownian` (to be replaced by
``roughpaths.BrownianDriver``).

Random stream (every path): for each step in turn, for each path in turn, the ``w`` unit normals of
that path-step: ``dW`` (``m``), then with the area ``H`` (``m``) and ``lambda`` (``m(m-1)/2``, pairs
``i < j`` lexicographic) — exactly ``rng.standard_normal((n_steps, n_paths, w))`` in C order,
whatever the chunking in time, and the generator ends in the same state as after that call.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from roughpaths import Driver, RoughPath

# ---------------------------------------------------------------------- bulk standard normals
# numpy's Generator.standard_normal (ziggurat, 256 layers) re-implemented over a buffer of raw
# 64-bit outputs of the bit generator (``bit_generator.random_raw``): the same raw words give the
# same normals, bit for bit, so paths agree with ``rng.standard_normal`` and the generator ends in
# the same state, but the per-draw function-pointer calls disappear (about 3x faster per normal).
# Used for bit generators whose ``next_double`` is ``(raw >> 11) * 2**-53`` (checked once per
# process against ``standard_normal``); any other generator (e.g. MT19937) uses numpy directly.
try:  # the ziggurat tables numpy uses (numba ships a copy for its own Generator support)
    from numba.np.random._constants import fi_double as _ZIG_F
    from numba.np.random._constants import ki_double as _ZIG_K
    from numba.np.random._constants import wi_double as _ZIG_W
    from numba.np.random._constants import ziggurat_nor_inv_r as _ZIG_INV_R
    from numba.np.random._constants import ziggurat_nor_r as _ZIG_R
except ImportError:  # pragma: no cover - another numba layout: fall back to numpy's sampler
    _ZIG_K = None

_RAW_BIT_GENERATORS = ("PCG64", "PCG64DXSM", "SFC64", "Philox")
_RAW_OK: dict = {}


@numba.njit(cache=True)
def _ziggurat_fill(raw, out, start, ki, wi, fi, r_tail, inv_r):
    """Fill ``out[start:]`` from ``raw`` (uint64) with numpy's ziggurat; returns (raw consumed, next index).

    Stops at the first attempt that would need more raw words than remain (that attempt is then
    redone from its first word on the next call, so no word is skipped or reused).
    """
    n = out.size
    nr = raw.size
    pos = 0
    i = start
    m255 = np.uint64(255)
    m52 = np.uint64(0x000FFFFFFFFFFFFF)
    one = np.uint64(1)
    s8 = np.uint64(8)
    s11 = np.uint64(11)
    scale = 1.0 / 9007199254740992.0
    while i < n:
        if pos >= nr:
            break
        first = pos
        r = raw[pos]
        pos += 1
        idx = np.intp(r & m255)
        r = r >> s8
        rabs = (r >> one) & m52
        x = float(rabs) * wi[idx]
        if r & one:
            x = -x
        if rabs < ki[idx]:
            out[i] = x
            i += 1
            continue
        if idx == 0:
            done = False
            while True:
                if pos + 2 > nr:
                    break
                xx = -inv_r * math.log1p(-(float(raw[pos] >> s11) * scale))
                yy = -math.log1p(-(float(raw[pos + 1] >> s11) * scale))
                pos += 2
                if yy + yy > xx * xx:
                    out[i] = -(r_tail + xx) if (rabs >> s8) & one else r_tail + xx
                    done = True
                    break
            if not done:
                pos = first
                break
            i += 1
        else:
            if pos + 1 > nr:
                pos = first
                break
            u = float(raw[pos] >> s11) * scale
            pos += 1
            if (fi[idx - 1] - fi[idx]) * u + fi[idx] < math.exp(-0.5 * x * x):
                out[i] = x
                i += 1
    return pos, i


def _raw_normals_ok(rng) -> bool:
    name = type(rng.bit_generator).__name__
    if _ZIG_K is None or name not in _RAW_BIT_GENERATORS:
        return False
    if name not in _RAW_OK:                  # one-off self-check against numpy on a private generator
        bg = type(rng.bit_generator)(12345)
        ref = np.random.Generator(type(rng.bit_generator)(12345)).standard_normal(20_000)
        got = np.empty(20_000)
        _RAW_OK[name] = _fill_normals_raw(bg, got) and np.array_equal(got, ref)
    return _RAW_OK[name]


def _fill_normals_raw(bit_generator, out) -> bool:
    """Fill ``out`` (C-contiguous float64) from ``bit_generator.random_raw``, requesting exactly the words used."""
    flat = out.reshape(-1)
    n = flat.size
    i = 0
    left = np.empty(0, dtype=np.uint64)
    while i < n:
        # every remaining normal needs >= 1 word and the pending attempt needs > len(left) words, so
        # asking for n - i new words never over-draws: the generator ends where numpy's would
        new = bit_generator.random_raw(n - i)
        raw = new if left.size == 0 else np.concatenate([left, new])
        used, i = _ziggurat_fill(raw, flat, i, _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)
        left = raw[used:]
    return left.size == 0


def _standard_normal_into(rng, out):
    """``rng.standard_normal(out=out)``, same values and end state, faster for 64-bit bit generators."""
    if _raw_normals_ok(rng):
        if _fill_normals_raw(rng.bit_generator, out):
            return
        raise RuntimeError("internal error: the raw-word normal sampler over-drew the bit generator.")
    rng.standard_normal(out=out)


def _brownian_chunk(rng, batch, k, dt, m, levy_area, substeps):
    r"""Increments (batch, k, m) and Lévy areas (batch, k, m, m) (or None) of Stratonovich Brownian motion.

    ``substeps == 1`` with the Davie area (or no area): drawn here in the same order as the fused
    numba kernel (step-major; per step and path: ``dW`` (m), ``H`` (m), ``lambda`` (m(m-1)/2)), so
    both implementations give the same paths for the same seed, and the stream does not depend on
    the chunking in time. Area :math:`A_{ij} = H_i dW_j - dW_i H_j + \lambda_{ij}` with
    :math:`H\sim N(0, dt/12)`, :math:`\lambda_{ij}\sim N(0, dt^2/12)` (Davie's moment-matched area;
    exact second moments). Otherwise ``roughpaths.brownian.brownian_increments_and_areas``.
    """
    method = None if not levy_area else ("davie" if levy_area is True else levy_area)
    if method is None or m < 2:
        z = np.empty((k, batch, m))
        _standard_normal_into(rng, z)
        return np.swapaxes(z, 0, 1) * math.sqrt(dt), None
    if method == "davie" and substeps == 1:
        npair = m * (m - 1) // 2
        z = np.empty((k, batch, 2 * m + npair))
        _standard_normal_into(rng, z)
        z = np.swapaxes(z, 0, 1)
        dw = z[..., :m] * math.sqrt(dt)
        h = z[..., m:2 * m] * math.sqrt(dt / 12.0)
        a = h[..., :, None] * dw[..., None, :]
        a = a - np.swapaxes(a, -1, -2)
        iu = np.triu_indices(m, 1)
        lam = z[..., 2 * m:] * (dt / math.sqrt(12.0))
        a[..., iu[0], iu[1]] += lam
        a[..., iu[1], iu[0]] -= lam
        return dw, a
    from roughpaths.brownian import brownian_increments_and_areas
    dw, xx = brownian_increments_and_areas(rng, k, dt, m, batch_shape=(batch,), levy_area=method,
                                           substeps=substeps)
    return dw, 0.5 * (xx - np.swapaxes(xx, -1, -2))



class _LegacyBrownianStream(Driver):
    """Stratonovich Brownian motion with Davie's Lévy area drawn from ``rng`` in the documented stream."""

    level = 2
    kind = "geometric"

    def __init__(self, rng, n_paths, n_steps, dt, m, levy_area, substeps, chunk_steps):
        self.rng, self.n_paths, self.dt, self.dim = rng, n_paths, dt, m
        self.levy_area, self.substeps, self.chunk_steps = levy_area, substeps, chunk_steps
        self.times = np.arange(n_steps + 1) * dt
        self.batch_shape = (n_paths,)
        self.level = 2 if levy_area else 1

    def blocks(self, max_steps=None):
        n, start = self.n_steps, 0
        k_max = max(1, min(n, self.chunk_steps))
        while start < n:
            k = min(k_max, n - start)
            dw, a = _brownian_chunk(self.rng, self.n_paths, k, self.dt, self.dim, self.levy_area, self.substeps)
            times = self.times[start:start + k + 1]
            if self.levy_area:
                if a is None:
                    a = np.zeros(dw.shape + (self.dim,))
                yield RoughPath(dw, a + 0.5 * dw[..., :, None] * dw[..., None, :], times=times, kind="geometric",
                                check=False)
            else:
                yield RoughPath(dw, None, times=times, check=False)
            start += k
