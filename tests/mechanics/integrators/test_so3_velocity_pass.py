"""The so(3) kernels' stochastic velocities (formed in tiles of steps inside the kernel): equal to
``LiePoissonSystem.stochastic_velocity`` (numpy) for 2, 3 (the written-out sums) and 4 noise fields, with
and without the Lévy area, on every tile of a block whose length is not a multiple of the tile."""

import numpy as np
import pytest

from mechanics import rigid_body
from mechanics.integrators import _so3_kernels


@pytest.mark.parametrize("nm", [2, 3, 4])
@pytest.mark.parametrize("area", [True, False])
def test_velocity_tiles_equal_numpy(nm, area):
    rng = np.random.default_rng(5)
    xi = None if nm == 3 else rng.standard_normal((nm, 3)) * 0.3
    rb = rigid_body([1.0, 2.0, 3.0], xi=xi, sigma=0.3 if xi is None else None, theta=0.5)
    P, K, T = 4, 2 * _so3_kernels._TILE + 5, _so3_kernels._TILE
    dX = 0.1 * rng.standard_normal((P, K, nm))
    dXX = 0.01 * rng.standard_normal((P, K, nm, nm)) if area else np.empty((0, 0, 0, 0))
    pi, pj = _so3_kernels._pairs(nm)
    brk = np.ascontiguousarray(rb.xi_brackets[pi, pj])
    got = np.full((P, K, 3), np.nan)
    tile = np.empty((P, T, 3))
    for k0 in range(0, K, T):
        _so3_kernels._velocities(dX, dXX, np.ascontiguousarray(rb.xi), brk, pi, pj, k0, tile)
        got[:, k0:k0 + T] = tile[:, :min(T, K - k0)]
    levy = 0.5 * (dXX - np.swapaxes(dXX, -1, -2)) if area else None
    np.testing.assert_allclose(got, rb.stochastic_velocity(dX, levy), rtol=1e-13, atol=1e-16)
