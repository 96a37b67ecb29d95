r"""The raw-word ziggurat (``roughpaths.drivers._ziggurat``) is numpy's ``standard_normal``, bit for bit.

Claim. From a bit generator's raw 64-bit words, ``_ziggurat_fill`` produces numpy's normals and consumes
exactly the words numpy consumes, however the words are cut into buffers (an attempt that runs out of
words stops and is redone from its first word with the next buffer). Checked against numpy itself on
enough normals that every branch runs many times: the box test (~98.5 % of attempts), the wedges (~1.5 %)
and the tail beyond r (~0.03 %, about 90 times in 3·10^5 normals).
"""

import numpy as np
import pytest

from roughpaths.drivers._random import standard_normal_into
from roughpaths.drivers._ziggurat import _ZIG_F, _ZIG_INV_R, _ZIG_K, _ZIG_R, _ZIG_W, _ziggurat_fill

TABLES = (_ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)


@pytest.mark.parametrize("bit_generator", [np.random.PCG64, np.random.SFC64, np.random.Philox])
def test_raw_word_normals_equal_numpy_and_end_in_the_same_state(bit_generator):
    ours, ref = np.random.Generator(bit_generator(123)), np.random.Generator(bit_generator(123))
    out = np.empty(300_001)
    standard_normal_into(ours, out)
    np.testing.assert_array_equal(out, ref.standard_normal(300_001))
    assert ours.bit_generator.random_raw() == ref.bit_generator.random_raw()


def test_cutting_the_words_into_buffers_changes_nothing():
    words = np.random.PCG64(7).random_raw(40_000)
    n = 30_000
    whole = np.empty(n)
    used, done = _ziggurat_fill(words, whole, 0, *TABLES)
    assert done == n
    np.testing.assert_array_equal(whole, np.random.Generator(np.random.PCG64(7)).standard_normal(n))
    rng = np.random.default_rng(1)
    for _ in range(5):
        cut = np.empty(n)
        pos = i = 0
        left = words[:0]
        while i < n:                              # buffers of 1 to 40 new words, the unused rest carried over
            take = int(rng.integers(1, 41))
            buf = np.concatenate([left, words[pos:pos + take]])
            pos += take
            k, i = _ziggurat_fill(buf, cut, i, *TABLES)
            left = buf[k:]
        np.testing.assert_array_equal(cut, whole)
        assert pos - left.size == used            # the same words consumed
