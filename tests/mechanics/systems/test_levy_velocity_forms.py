"""The Lévy-area velocity has one meaning, whichever way a model is assembled.

Claims (formerly checked through the removed wrappers ``levy_torque``, ``RigidBody.levy_torque_vector``
and ``integrate_rigid_body``, now against the current API):

* :func:`mechanics.levy_velocity` is the closed form ``c = ½ Σ s^{ij} ξ_i × ξ_j`` on so(3), and for
  isotropic noise ``ξ_i = σ e_i`` the rigid body's ``levy_velocity`` is ``σ² (s23, −s13, s12)``;
* putting ``c·Π`` into the Hamiltonian (``QuadraticHamiltonian.from_inertia(I, linear=c)``, ``s = 0``)
  is the same model as the Lévy velocity of ``s`` (``rigid_body(..., s=s)``, torque in both terms): the
  two solutions agree to round-off on a level-2 path with non-zero areas, and the torque matters.
"""

import numpy as np

from mechanics import LieHeun, LiePoissonSystem, QuadraticHamiltonian, levy_velocity, rigid_body, so3
from roughpaths import RoughPath, solve

I3 = [1.0, 2.0, 3.0]
S = np.array([[0.0, 1.5, -2.0], [-1.5, 0.0, 0.7], [2.0, -0.7, 0.0]])


def _path(rng, batch=(4,), n=50, T=1.0):
    """A geometric level-2 path with non-zero step Lévy areas (Brownian-sized)."""
    h = T / n
    dw = np.sqrt(h) * rng.standard_normal(batch + (n, 3))
    lam = 0.5 * h * rng.standard_normal(batch + (n, 3, 3))
    areas = 0.5 * dw[..., :, None] * dw[..., None, :] + 0.5 * (lam - np.swapaxes(lam, -1, -2))
    return RoughPath.from_increments(dw, areas, times=np.linspace(0.0, T, n + 1))


def test_levy_velocity_closed_form(rng):
    xi = rng.standard_normal((3, 3))
    c = levy_velocity(S, xi)
    ref = 0.5 * sum(S[i, j] * np.cross(xi[i], xi[j]) for i in range(3) for j in range(3))
    np.testing.assert_allclose(c, ref, atol=1e-14)


def test_rigid_body_isotropic_levy_velocity():
    rb = rigid_body(I3, sigma=0.05, s=S, theta=1.0)
    np.testing.assert_array_equal(rb.levy_velocity, levy_velocity(S, 0.05 * np.eye(3)))
    np.testing.assert_allclose(rb.levy_velocity, 0.05 ** 2 * np.array([S[1, 2], -S[0, 2], S[0, 1]]), atol=1e-15)


def test_torque_in_hamiltonian_equals_levy_velocity(rng):
    X = _path(rng)
    xi = 0.5 * np.eye(3)
    Pi0 = [0.0, 0.6, 0.8]
    c = levy_velocity(S, xi)
    in_h = LiePoissonSystem(so3(), QuadraticHamiltonian.from_inertia(I3, linear=c), xi, theta=1.0)
    via_s = rigid_body(I3, xi=xi, s=S, theta=1.0)
    a = solve(in_h, X, Pi0, LieHeun(), save_at=X.times[::5])
    b = solve(via_s, X, Pi0, LieHeun(), save_at=X.times[::5])
    np.testing.assert_array_equal(a.times, b.times)
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=1e-13)
    plain = solve(rigid_body(I3, xi=xi, theta=1.0), X, Pi0, LieHeun()).states
    assert np.max(np.abs(b.final - plain[:, -1])) > 1e-3                 # the torque mattered
