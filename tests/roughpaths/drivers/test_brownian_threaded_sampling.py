"""BrownianDriver samples blocks of paths on numba's threads: the numbers are bitwise those of one thread.

Oracle: the same driver sampled on one thread, with the work split forced into many small ranges (the
split is an implementation choice that must never show in the numbers), and each path sampled alone
(``select``): a path's increments and areas depend on its own streams only.
"""

import numba
import numpy as np
import pytest

from roughpaths import BrownianDriver
from roughpaths import _threads


def _sample(levy_area, d, kind="stratonovich", **kw):
    drv = BrownianDriver(d, seed=11, dt=0.01, n_steps=37, batch_shape=(45,), levy_area=levy_area, kind=kind, **kw)
    blocks = list(drv.blocks(16))
    inc = np.concatenate([b.increments for b in blocks], axis=-2)
    areas = None if blocks[0].areas is None else np.concatenate([b.areas for b in blocks], axis=-3)
    return inc, areas, np.stack([b.x0 for b in blocks])


@pytest.mark.parametrize("levy_area, d, kind, kw", [("davie", 3, "stratonovich", {}),
                                                    ("foster", 2, "stratonovich", {"substeps": 3}),
                                                    ("exact", 2, "ito", {}),
                                                    (None, 3, "stratonovich", {}),
                                                    ("mrongowius-rossler", 3, "stratonovich", {})])
def test_threaded_split_is_bitwise_one_thread(monkeypatch, levy_area, d, kind, kw):
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        one = _sample(levy_area, d, kind, **kw)
    finally:
        numba.set_num_threads(threads)
    monkeypatch.setattr(_threads, "SERIAL_WORK", 1)       # split every block into ranges of a few paths
    monkeypatch.setattr(_threads, "RANGE_WORK", 1)
    many = _sample(levy_area, d, kind, **kw)
    for a, b in zip(one, many):
        assert (a is None and b is None) or np.array_equal(a, b)
    # each path alone (a selection of one path) is the same path: no dependence on the rest of the batch
    drv = BrownianDriver(d, seed=11, dt=0.01, n_steps=37, batch_shape=(45,), levy_area=levy_area, kind=kind, **kw)
    alone = next(iter(drv.select([7]).blocks(16)))
    assert np.array_equal(alone.increments[0], one[0][7, :16])
    if one[1] is not None:
        assert np.array_equal(alone.areas[0], one[1][7, :16])
