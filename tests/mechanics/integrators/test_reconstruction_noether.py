"""Reconstruction and the discrete Noether theorem.

Statement: along a coadjoint solution ``mu_{n+1} = exp(ad*_{sigma_n}) mu_n`` the group path
``g_{n+1} = g_n exp(sigma_n)`` conserves the spatial momentum ``m = Ad*_{g^{-1}} mu`` exactly (round-off),
stays on the group (orthogonal / unitary), and its reduced states are those of ``roughpaths.solve``. The
check has teeth: the other sign ``g_{n+1} = g_n exp(-sigma_n)`` (an equally plausible guess) does not conserve
``m``, and neither does the left update ``exp(sigma_n) g_n``.
"""

import numpy as np
import pytest

import roughpaths as rp
from mechanics import LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, rigid_body, so, solve_with_group, su


def _path(m, steps=200, batch=(2,), seed=0):
    return rp.brownian_rough_path(np.linspace(0.0, 1.0, steps + 1), m, np.random.default_rng(seed), batch_shape=batch)


def test_rigid_body_attitude_conserves_the_spatial_angular_momentum():
    body = rigid_body([1.0, 2.0, 3.0], sigma=0.3)
    X = _path(3)
    Pi0 = np.array([0.6, 0.0, 0.8])
    sol = solve_with_group(body, X, Pi0, LieHeun())
    R = sol.group
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape), atol=1e-13)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-13)
    spatial = (R @ sol.states[..., None])[..., 0]                       # m = R Pi, an oracle written here
    np.testing.assert_allclose(spatial, np.broadcast_to(Pi0, spatial.shape), atol=1e-13)
    np.testing.assert_allclose(sol.spatial_momentum(), spatial, atol=1e-13)
    np.testing.assert_allclose(sol.states[..., -1, :], rp.solve(body, X, Pi0, LieHeun()).final, atol=1e-12)
    assert np.max(np.abs(sol.states[..., -1, :] - Pi0)) > 0.05        # the body did move


@pytest.mark.parametrize("g", [su(3), so(4)], ids=["su3", "so4"])
def test_matrix_algebra_group_path(g):
    rng = np.random.default_rng(4)
    system = LiePoissonSystem(g, 1.0 + rng.random(g.dim), 0.4 * rng.standard_normal((3, g.dim)), theta=0.0)
    X = _path(3, steps=100)
    mu0 = rng.standard_normal(g.dim)
    sol = solve_with_group(system, X, mu0, LieEuler())
    U = sol.group
    UH = np.conj(np.swapaxes(U, -1, -2))
    np.testing.assert_allclose(UH @ U, np.broadcast_to(np.eye(g.matrix_size), U.shape), atol=1e-13)
    np.testing.assert_allclose(sol.spatial_momentum(), np.broadcast_to(mu0, sol.states.shape), atol=1e-12)
    # the oracle: U M U^H with M from the coordinates, written here
    M = np.einsum("...i,iab->...ab", sol.states, g.basis)
    np.testing.assert_allclose(U @ M @ UH, np.broadcast_to(np.einsum("i,iab->ab", mu0, g.basis), M.shape),
                               atol=1e-12)
    # the wrong reconstructions: g exp(-sigma) and exp(sigma) g do not conserve m
    consts = LiePoissonSystem(LieAlgebra(g.structure_constants), np.diag(1.0 / system.hamiltonian.q_diagonal),
                              system.xi)
    np.testing.assert_allclose(sol.states[..., -1, :], rp.solve(consts, X, mu0, LieEuler()).final, atol=1e-12)
    inc = np.linalg.solve(U[..., :-1, :, :], U[..., 1:, :, :])         # exp(sigma_n) recovered from the path
    wrong = [U[..., 0, :, :]]
    left = [U[..., 0, :, :]]
    for k in range(inc.shape[-3]):
        E = inc[..., k, :, :]
        wrong.append(wrong[-1] @ np.conj(np.swapaxes(E, -1, -2)))
        left.append(E @ left[-1])
    for bad in (np.stack(wrong, axis=-3), np.stack(left, axis=-3)):
        m_bad = bad @ M @ np.conj(np.swapaxes(bad, -1, -2))
        assert np.max(np.abs(m_bad[..., -1, :, :] - m_bad[..., 0, :, :])) > 1e-3


def test_refusals():
    body = rigid_body([1.0, 2.0, 3.0], sigma=0.3)
    X = _path(2)
    with pytest.raises(ValueError, match="3 noise vectors"):
        solve_with_group(body, X, [0.6, 0.0, 0.8], LieHeun())
    with pytest.raises(TypeError, match="LieEuler"):
        solve_with_group(body, _path(3), [0.6, 0.0, 0.8], rp.Heun())
    no_basis = LiePoissonSystem(LieAlgebra(so(3).structure_constants), np.eye(3), 0.1 * np.eye(3))
    with pytest.raises(ValueError, match="no matrix basis"):
        solve_with_group(no_basis, _path(3), [0.6, 0.0, 0.8], LieHeun())
