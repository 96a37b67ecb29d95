"""The so(3) kernels' stochastic velocities: the three-component pass (sums written out) gives the bits of
the general one, and both agree with ``LiePoissonSystem.stochastic_velocity`` (numpy)."""

import numpy as np
import pytest

from mechanics import rigid_body
from mechanics.integrators import _so3_kernels


@pytest.mark.parametrize("area", [True, False])
def test_three_component_pass_equals_general_pass(area):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5)
    rng = np.random.default_rng(5)
    P, K = 4, 6
    dX = 0.1 * rng.standard_normal((P, K, 3))
    dXX = 0.01 * rng.standard_normal((P, K, 3, 3)) if area else np.empty((0, 0, 0, 0))
    pi, pj = _so3_kernels._pairs(3)
    brk = np.ascontiguousarray(rb.xi_brackets[pi, pj])
    xi = np.ascontiguousarray(rb.xi)
    a, b = np.empty((P, K, 3)), np.empty((P, K, 3))
    _so3_kernels._eta_from_increments(dX, dXX, xi, brk, pi, pj, a)
    _so3_kernels._eta_from_increments3(dX, dXX, xi, brk, b)
    np.testing.assert_array_equal(a, b)
    levy = 0.5 * (dXX - np.swapaxes(dXX, -1, -2)) if area else None
    np.testing.assert_allclose(b, rb.stochastic_velocity(dX, levy), rtol=1e-13, atol=1e-16)
