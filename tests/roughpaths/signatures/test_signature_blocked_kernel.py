"""Claim: the one-unit kernel that defers the top level over blocks of segments is exact and keeps the bits.

* ``signature`` equals ``iisignature.sig`` to 1e-12 on paths longer than a block (so the top level, or
  at depth 2 the table of areas (``_level2``, d >= 6, 16 points a sweep),
  is added in several sweeps, the last one partial), at the compiled widths (d = 8 at depths 3/4, d = 6
  at depth 4) and at run-time ones (d = 6 at depth 3, 7, 20; d = 4 at depth 6, a lone path; d = 3 at depth 9 and
  d = 4 at depth 7, whose lower levels are updated in place and both top levels deferred over a block);
* :func:`_blocked.block_units` gives the bits of the segment-by-segment kernel
  (``_lanes.scalar_units``), whatever the block and the number of segments: the deferred sweep adds
  every product in the order of the segments (with both top levels deferred, at (10, 5) and (17, 4): level 3's
  289 words in chunks of 128, 128 and 33, a packed row and a lone entry; at depth 3 with level 2 and the sweep
  transposed, rows of one, two and three packed rows);
* a path gets the same bits in a lane group of the run-time-``d`` lane kernel (d = 6, 7 at depth 3) as
  alone in the blocked kernel, whose rows at such widths end in partial packed rows;
* a lone path of at most 8 points (the plain one-unit kernel) gets the bits of the blocked kernel and of a lane;
* the tiled layout permutation equals numpy's gather (``src[:, perm]``) on a level large enough to
  be tiled.

Oracles: iisignature (an independent C++ implementation); the earlier one-segment kernel; numpy indexing.
"""

import iisignature
import numpy as np
import pytest

from roughpaths import signature
from roughpaths.algebra.flat import level_offsets
from roughpaths.signatures import _blocked, _lanes, _layout
from roughpaths.signatures._engine import _reversed_to_rowmajor, _units

CASES = [(6, 3), (6, 4), (8, 3), (8, 4), (20, 3), (7, 3), (4, 6), (7, 2), (20, 2), (3, 9), (4, 7)]   # depth 2: _level2

#: One worker runs the module (``--dist loadgroup``): its cases compile the same wide-alphabet variants (about
#: a minute of CPU in all), which two workers splitting the cases compiled twice, at the same time.
pytestmark = pytest.mark.xdist_group("blocked-kernels")


@pytest.mark.parametrize("d,m", CASES)
def test_blocked_signature_matches_iisignature(rng, d, m):
    n = 2 * _blocked.KBLOCK + 7 if d ** m < 10 ** 5 else _blocked.KBLOCK + 3
    x = np.cumsum(rng.standard_normal((2, n, d)) / np.sqrt(n), axis=-2)
    np.testing.assert_allclose(signature(x, m), iisignature.sig(x, m), rtol=0, atol=1e-12)


# by default the widths whose reference kernel is the one wide-alphabet variant (step_key -1) and every scheme
# of the blocked kernel ((6, 4) in place; depth 3 with level 2 transposed, its rows of one (d = 8), two (d = 10) and
# three packed rows (d = 17); the run-time one at partial packed rows, and in place with both top levels deferred
# at (10, 5) and (17, 4), where a row of the top level's T passes 4096 entries); with -m slow also
# the reference's own variants at d = 20, 5, 4 and 3 (about 10 s of compile each; d = 4 at depth 7 is the
# other in-place variant)
@pytest.mark.parametrize("d,m", [(6, 4), (8, 3), (10, 3), (17, 3), (9, 4), (13, 2), (10, 5), (17, 4)]
                         + [pytest.param(d, m, marks=pytest.mark.slow) for d, m in ((20, 3), (5, 3), (4, 7), (3, 5))])
def test_blocked_bits_equal_the_segment_kernel(rng, d, m):
    n = 2 * _blocked.KBLOCK + 5
    x = np.cumsum(rng.standard_normal((3, n, d)), axis=-2)
    off = level_offsets(d, m)
    units = _units(3, n, 2)                       # two units a path: 18 and 19 segments
    a = np.empty((6, off[m + 1]))
    b = np.empty_like(a)
    _lanes.scalar_units(x.shape[2])(x, *units, m, off, 0, 6, a)
    _blocked.block_units(x.shape[2], m)(x, *units, m, off, 0, 6, b)
    assert a.tobytes() == b.tobytes()


@pytest.mark.parametrize("d,m", [(7, 3), (6, 3)])
def test_lanes_and_lone_units_give_the_same_bits_at_run_time_widths(rng, d, m):
    # 10 paths: one lane group of 8 (the run-time-d lane kernel) and 2 paths alone (the blocked kernel)
    x = np.cumsum(rng.standard_normal((10, 2 * _blocked.KBLOCK + 9, d)) * 0.1, axis=-2)
    whole = signature(x, m)
    for b in (0, 7, 8, 9):
        assert signature(x[b:b + 1], m)[0].tobytes() == whole[b].tobytes()


@pytest.mark.parametrize("d,m", [(3, 3), (8, 3)])
def test_short_lone_paths_take_the_plain_kernel_with_the_bits_of_the_others(rng, d, m):
    """Lone paths of at most 8 points run the plain one-unit kernel (``_engine.alone_kernel``: it compiles in less
    than half the blocked kernel's time): the bits of the same path in a lane group (d = 3: 8 of 10 paths on lanes)
    and of the blocked kernel, and iisignature's values."""
    from roughpaths.signatures._engine import alone_kernel

    for n in (2, 5, 8):
        assert alone_kernel(n, d, m) is _lanes.scalar_units(d)
        x = np.cumsum(rng.standard_normal((10, n, d)) * 0.3, axis=-2)
        whole = signature(x, m)
        off = level_offsets(d, m)
        flipped = n * d < off[m + 1]               # the engine's layout trick (the path negated and reversed)
        y = np.ascontiguousarray(-x[:, ::-1] if flipped else x)
        blocked = np.empty((10, off[m + 1]))
        _blocked.block_units(d, m)(y, *_units(10, n, 1), m, off, 0, 10, blocked)
        blocked = blocked if flipped else blocked[:, _reversed_to_rowmajor(d, m)]
        for b in (0, 8, 9):
            lone = signature(x[b:b + 1], m)[0]
            assert lone.tobytes() == whole[b].tobytes()
            assert lone.tobytes() == blocked[b].tobytes()
        np.testing.assert_allclose(whole, iisignature.sig(x, m), rtol=0, atol=1e-14)
    assert alone_kernel(9, d, m) is _blocked.block_units(d, m)          # from 8 segments: the blocked kernel


@pytest.mark.parametrize("d,m", [(4, 8), (5, 7)])   # 8 x 8 tiles only; tiles and edges (125 x 625)
def test_tiled_permutation_equals_numpy_gather(rng, d, m):
    assert d ** m > _layout._TILED                # the top level is permuted in tiles
    off = level_offsets(d, m)
    perm = _reversed_to_rowmajor(d, m)
    src = rng.standard_normal((2, off[m + 1]))
    out = np.empty_like(src)
    _layout.to_rowmajor(src, perm, off, m, 0, 2, out)
    assert out.tobytes() == src[:, perm].tobytes()


@pytest.mark.parametrize("d,m", [(6, 3), (6, 4), (8, 3), (20, 3), (7, 3)])
def test_wide_vjp_in_blocks_matches_iisignature(rng, d, m):
    from roughpaths import sigdim, signature_vjp
    from roughpaths.signatures import _vjp_wide

    n = 2 * _vjp_wide.KB + 5                      # two full blocks of segments and a partial one
    x = np.cumsum(rng.standard_normal((2, n, d)) / np.sqrt(n), axis=-2)
    g = rng.standard_normal((2, sigdim(d, m)))
    ref = iisignature.sigbackprop(g, x, m)        # iisignature's gradients agree to about 1e-7 only
    np.testing.assert_allclose(signature_vjp(x, m, g), ref, rtol=0, atol=1e-6 * np.abs(ref).max())


def test_wide_vjp_bits_do_not_depend_on_the_batch(rng):
    from roughpaths import sigdim, signature_vjp

    x = np.cumsum(rng.standard_normal((5, 2 * 1024 + 40, 6)) * 0.03, axis=-2)   # two chunks a path
    g = rng.standard_normal((5, sigdim(6, 3)))
    whole = signature_vjp(x, 3, g)
    for b in (0, 3):
        assert signature_vjp(x[b:b + 1], 3, g[b:b + 1])[0].tobytes() == whole[b].tobytes()
