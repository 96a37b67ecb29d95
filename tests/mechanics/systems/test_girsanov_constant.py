"""Girsanov constant of the Lévy-area drift.

Claim: if the noise vectors span the Lévy velocity, u^k ξ_k = ℓ = ½ s^{ij}[ξ_i, ξ_j], then the corrected
system driven by X equals the uncorrected one driven by X_t + u t, pathwise; for ξ_k = e_k
u^k = ½ s^{ij} c^k_{ij}. The paper's (LieDepXis) drops the ½ (u^k = s^{ij} c^k_{ij}): that shift does
not reproduce the corrected system (asserted). Since u is constant, Novikov holds and the laws are
equivalent: reweighting the uncorrected model by exp(u·W_T - ½|u|²T) gives the corrected model's
expectations (checked by a small Monte Carlo of a non-trivial observable).
"""

import importlib
import numpy as np
import pytest

from mechanics.integrators import ImplicitMidpoint, LieHeun
from mechanics.systems.lie_algebra import sl2r, so3, su2
from mechanics.systems.girsanov import girsanov_shift
from mechanics.systems.lie_poisson import LiePoissonSystem
from mechanics.systems.rigid_body import rigid_body
from roughpaths import RoughPath, solve

S = np.array([[0.0, 0.8, -1.2], [-0.8, 0.0, 0.5], [1.2, -0.5, 0.0]])


@pytest.mark.parametrize("algebra", [so3, su2, sl2r], ids=["so3", "su2", "sl2r"])
def test_constant_is_half_s_c(algebra):
    g = algebra()
    c = g.structure_constants
    system = LiePoissonSystem(g, np.diag([1.0, 2.0, 3.0]), np.eye(3), s=S)
    naive = np.array([0.5 * sum(S[i, j] * c[i, j, k] for i in range(3) for j in range(3)) for k in range(3)])
    np.testing.assert_allclose(girsanov_shift(system), naive, atol=1e-14)
    np.testing.assert_allclose(girsanov_shift(system, convention="paper"), 2 * naive, atol=1e-14)
    # scaled isotropic noise ξ_i = σ e_i: u = ½ σ s^{ij} c^k_{ij}
    sys2 = LiePoissonSystem(g, np.diag([1.0, 2.0, 3.0]), 0.3 * np.eye(3), s=S)
    np.testing.assert_allclose(girsanov_shift(sys2), 0.3 * naive, atol=1e-14)


def _path(rng, paths=4, n=300):
    vals = np.cumsum(rng.standard_normal((paths, n + 1, 3)) * np.sqrt(1.0 / n), axis=1)
    return vals, np.linspace(0.0, 1.0, n + 1)


@pytest.mark.parametrize("method", [LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_pathwise_identity(method, rng):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.4, s=S, theta=0.0)
    u = girsanov_shift(rb)
    vals, t = _path(rng)
    X = RoughPath.from_path(vals, times=t)
    shifted = RoughPath.from_path(vals + u * t[:, None], times=t)
    mu0 = np.array([0.0, 0.6, 0.8])
    a = solve(rb, X, mu0, method).states
    b = solve(rb.with_s(np.zeros((3, 3))), shifted, mu0, method).states
    np.testing.assert_allclose(a, b, atol=1e-12)
    paper = RoughPath.from_path(vals + girsanov_shift(rb, convention="paper") * t[:, None], times=t)
    c = solve(rb.with_s(np.zeros((3, 3))), paper, mu0, method).states
    assert np.max(np.abs(c - a)) > 1e-3


def test_pathwise_identity_generic_solver(rng):
    solve_mod = importlib.import_module("roughpaths")
    solvers = importlib.import_module("roughpaths")
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.4, s=S, theta=0.0)
    u = girsanov_shift(rb)
    vals, t = _path(rng, n=2000)
    mu0 = np.array([0.0, 0.6, 0.8])
    a = solve_mod.solve(rb.vector_fields(), RoughPath.from_path(vals, times=t), mu0, solvers.Davie()).final
    b = solve_mod.solve(rb.with_s(np.zeros((3, 3))).vector_fields(),
                        RoughPath.from_path(vals + u * t[:, None], times=t), mu0, solvers.Davie()).final
    assert np.max(np.abs(a - b)) < 2e-3


def test_no_constant_shift_when_xi_do_not_span(rng):
    xi = np.array([[0.5, 0.0, 0.0], [0.0, 0.5, 0.0]])       # [ξ1, ξ2] ∝ e3 is not in span(ξ)
    rb = rigid_body([1.0, 2.0, 3.0], xi=xi, s=[[0.0, 1.0], [-1.0, 0.0]])
    with pytest.raises(ValueError, match="not a combination"):
        girsanov_shift(rb)


def test_change_of_measure_reweights_expectations(rng):
    """E_corrected[f(Π_T)] = E_plain[f(Π_T) exp(u·W_T - ½|u|²T)] (Novikov: u constant), up to MC error."""
    from mechanics.integrators import LieEuler
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.5, s=S, theta=0.0)
    u = girsanov_shift(rb)
    n_paths, n, T = 4000, 50, 1.0
    dw = rng.standard_normal((n_paths, n, 3)) * np.sqrt(T / n)
    vals = np.concatenate([np.zeros((n_paths, 1, 3)), np.cumsum(dw, axis=1)], axis=1)
    t = np.linspace(0.0, T, n + 1)
    X = RoughPath.from_path(vals, times=t)
    mu0 = np.array([0.0, 0.6, 0.8])
    a = solve(rb, X, mu0, LieEuler(), save_at=X.times[::n]).states
    b = solve(rb.with_s(np.zeros((3, 3))), X, mu0, LieEuler(), save_at=X.times[::n]).states
    weights = np.exp(vals[:, -1] @ u - 0.5 * (u @ u) * T)
    f_a, f_b, f_plain = a[:, -1], b[:, -1] * weights[:, None], b[:, -1]
    se = np.sqrt(np.var(f_a, axis=0) / n_paths + np.var(f_b, axis=0) / n_paths)
    assert np.all(np.abs(f_a.mean(0) - f_b.mean(0)) < 4 * se), (f_a.mean(0), f_b.mean(0), se)
    # the unweighted plain model is detectably different (the test has power)
    se_plain = np.sqrt(np.var(f_a - f_plain, axis=0) / n_paths)
    assert np.max(np.abs(f_a.mean(0) - f_plain.mean(0)) / se_plain) > 6
