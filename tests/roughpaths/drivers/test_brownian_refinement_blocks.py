"""A refined Brownian driver's default blocks keep to the coarse driver's ``block_bytes``.

Statement: without ``max_steps``, ``RefinedBrownianDriver.blocks`` cuts whole coarse steps, as many as keep
``block_nbytes`` within ``block_bytes`` (one coarse step at least, whose bytes are then what one step needs).
Sized by the coarse driver's own steps, the default block of 200 paths refined by 16 with Mrongowius–Rößler
areas held 3.5 GiB against 16 MiB. The numbers do not depend on the block size (tested elsewhere); here the
blocks' sizes, and that the default blocks give the same path as explicit ones.
"""

import numpy as np
import pytest

import roughpaths as rp


@pytest.mark.parametrize("levy_area,d", [("mrongowius-rossler", 3), ("exact", 2), (None, 3)])
@pytest.mark.parametrize("factor", [4, 16])
def test_default_blocks_keep_to_block_bytes(levy_area, d, factor):
    coarse = rp.BrownianDriver(d, seed=0, dt=1e-3, n_steps=20000, batch_shape=(200,), levy_area=levy_area)
    fine = coarse.refine(factor)
    K = fine.default_block_steps()
    assert K % factor == 0 and K >= factor
    one_step = fine.block_nbytes(factor)
    assert fine.block_nbytes() <= max(coarse.block_bytes, one_step)
    if K > factor:                                   # then the next whole coarse step would not have fitted
        assert fine.block_nbytes(K + factor) > coarse.block_bytes


def test_default_blocks_give_the_same_path():
    coarse = rp.BrownianDriver(3, seed=4, dt=0.01, n_steps=64, batch_shape=(50,), levy_area="mrongowius-rossler",
                               block_bytes=2**16)
    fine = coarse.refine(4)
    assert fine.default_block_steps() < fine.n_steps          # several blocks
    default = list(fine.blocks())
    (whole,) = list(fine.blocks(max_steps=fine.n_steps))
    assert len(default) > 1
    np.testing.assert_array_equal(np.concatenate([b.increments for b in default], axis=-2), whole.increments)
    np.testing.assert_array_equal(np.concatenate([b.areas for b in default], axis=-3), whole.areas)
