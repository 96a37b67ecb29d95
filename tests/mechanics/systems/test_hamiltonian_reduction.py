"""Section 2.3 (Hamiltonian reduction): the Lévy-area correction survives reduction by the momentum map.

Claim: for a Lie–Poisson system (algebra g, Hamiltonian h, noise vectors ξ_k, antisymmetric s) and a
matrix representation A of g on R^N, the rough Hamiltonian system on T*R^N with collective Hamiltonians
H_0 = h∘J, H_k = ξ_k∘J (J the cotangent-lift momentum map of the right action, J(q, p)(ξ) = −p·A_ξ q),
driven by the perturbed rough path X̃ = X.perturb(s), is mapped by J onto the library's Lie–Poisson
solution with the Lévy-area correction, dμ = ad*_{∇h + ℓ} μ dt + ad*_{ξ_k} μ dX^k, ℓ = +½ s^{ij}[ξ_i, ξ_j],
driven by X. In bracket form: df = {f, h − ½ s^{ij}{ξ_i, ξ_j}} dt + {f, ξ_k} dX^k with the library's
(minus) Lie–Poisson bracket {f, g}(μ) = −⟨μ, [∇f, ∇g]⟩, which is the sign the paper prints in Section
2.3 (the printed rigid-body formulas (srblevy) etc. are the ones with the flipped torque).

Checked for so(3) on R³, se(3) on homogeneous R⁴ (the heavy top), sl(2, R) on R², and so(3) given by a
user's explicit (non-orthogonal, conjugated) matrices:

* J intertwines: dJ·X_{H_ξ} = ad*_ξ J and dJ·X_{h∘J} = ad*_{∇h} J (round-off); J is equivariant;
  {H_i, H_j}_ω = {ξ_i, ξ_j}∘J; the printed reduced Hamiltonian gives the library's drift;
* pathwise: J(Y_T) of the lift driven by X.perturb(s) (LogODE) against the Lie–Poisson solution
  with the correction driven by X (LogODE, same grid): the gap falls with the step (fitted slope),
  while the wrong variants (sign of the correction flipped, or the ½ dropped) stay O(1) apart;
* symplecticity: the generators are Hamiltonian matrices, the LogODE step map of the noise and the
  time-1 flow of the noise part satisfy Mᵀ𝕁M = 𝕁;
* bad input is refused with the argument and the fix named.

Measured by the ``slow`` test (RMS over 8 Brownian paths, T = 1, seed 5; LogODE for both): ``rp``,
``flip``, ``no ½`` are |J(Y_T) − μ_T| with μ solved on the same grid with the correction +ℓ, −ℓ, 2ℓ;
``vs fine`` is |J(Y_T) − μ_T| against the corrected solution on 4096 steps.

=============  ========  ========  ========  ========  ========
case / n       16        64        256       1024      4096
=============  ========  ========  ========  ========  ========
so3 rp         3.08e-04  1.77e-05  9.45e-07  4.49e-08  3.13e-09
so3 vs fine    1.48e-02  3.40e-03  1.08e-03  2.55e-04  (ref.)
so3 flip       1.11e+00  1.11e+00  1.11e+00  1.11e+00  1.11e+00
so3 no ½       6.86e-01  6.91e-01  6.89e-01  6.89e-01  6.89e-01
se3 rp         7.51e-04  8.54e-05  6.84e-06  2.99e-07  1.89e-08
se3 vs fine    3.92e-02  6.88e-03  2.27e-03  5.62e-04  (ref.)
se3 flip       1.23e+00  1.24e+00  1.23e+00  1.23e+00  1.23e+00
se3 no ½       9.16e-01  9.08e-01  9.08e-01  9.07e-01  9.07e-01
sl2 rp         1.99e-04  1.04e-05  6.67e-07  2.20e-08  1.57e-09
sl2 vs fine    9.20e-02  1.72e-02  4.97e-03  1.20e-03  (ref.)
sl2 flip       1.41e+00  1.45e+00  1.43e+00  1.44e+00  1.44e+00
sl2 no ½       1.71e+00  1.73e+00  1.70e+00  1.70e+00  1.70e+00
user so3 rp    4.51e-04  2.38e-05  1.23e-06  5.83e-08  3.94e-09
user vs fine   1.74e-02  5.10e-03  1.52e-03  3.57e-04  (ref.)
user so3 flip  1.35e+00  1.35e+00  1.35e+00  1.35e+00  1.35e+00
user so3 no ½  8.23e-01  8.30e-01  8.28e-01  8.28e-01  8.28e-01
=============  ========  ========  ========  ========  ========

Against the fine solution the gap falls at LogODE's strong order 1 (fitted ≈ 0.9–1.0). On the same grid
it falls faster (≈ 2.2): both schemes take the same step log-signature, and J maps the lift's exact
noise exponentials onto the coadjoint ones (equivariance), so most of the two discretisation errors
coincide through J. The default test runs n = 16, 64, 256 on 4 paths (reference 1024 steps) and asserts
a fitted same-grid order ≥ 1, a fine-reference order ≥ 0.7, and the wrong variants O(1).
"""

import numpy as np
import pytest
import scipy.linalg

from mechanics.systems import (CotangentLift, LiePoissonSystem, cotangent_lift, hat, heavy_top, rigid_body, sl2r,
                               so3)
from roughpaths import LinearVectorFields, LogODE, brownian_rough_path, solve

S = np.array([[0.0, 1.5, -2.0], [-1.5, 0.0, 0.7], [2.0, -0.7, 0.0]])
_R = np.array([[1.0, 0.3, -0.2], [0.1, 0.8, 0.4], [-0.3, 0.2, 1.2]])
USER_SO3 = np.einsum("ab,kbc,cd->kad", _R, hat(np.eye(3)), np.linalg.inv(_R))    # R hat(e_k) R⁻¹


def _case(name):
    """(system, representation, initial phase state y0) for each case."""
    g = np.random.default_rng(11)
    if name in ("so3", "user_so3"):
        system = rigid_body([1.0, 2.0, 3.0], xi=0.7 * np.eye(3) + 0.1 * g.standard_normal((3, 3)), s=S)
        return system, ("so3" if name == "so3" else USER_SO3), np.array([0.6, 0.0, 0.8, 0.1, 0.7, -0.2])
    if name == "se3":
        system = heavy_top([1.0, 1.5, 2.0], [0.0, 0.0, 0.5], xi=0.5 * g.standard_normal((3, 6)), s=S)
        return system, "se3", np.array([0.3, -0.4, 0.5, 1.0, 0.2, 0.6, -0.5, 0.4])
    system = LiePoissonSystem(sl2r(), np.diag([1.0, 2.0, 3.0]), 0.3 * (np.eye(3) + 0.2 * g.standard_normal((3, 3))),
                              s=S)
    return system, "sl2", np.array([0.5, -0.3, 0.2, 0.6])


CASES = ["so3", "se3", "sl2", "user_so3"]


def _ladder(name, ks, ref_k, paths=4, seed=5):
    """Gaps |J(Y_T) − μ_T| (RMS over paths) at 2^k steps for the right correction and the two wrong ones
    (same grid), and ``vs_fine``: J(Y_T) against the corrected Lie–Poisson solution on 2^ref_k steps."""
    system, rep, y0 = _case(name)
    lift = cotangent_lift(system, rep)
    kmax = max(max(ks), ref_k)
    X = brownian_rough_path(np.linspace(0.0, 1.0, 2**kmax + 1), system.n_noise, np.random.default_rng(seed),
                            batch_shape=(paths,))
    mu0 = lift.momentum_of_state(y0)
    variants = {"rp": system, "flip": system.with_s(-system.s), "no_half": system.with_s(2.0 * system.s)}
    table = {v: [] for v in variants}
    lifted = []
    for k in ks:
        Xk = X.restrict(X.times[:: 2 ** (kmax - k)])
        y = solve(lift.vector_fields, lift.perturbed(Xk), y0, LogODE(), save_at="end").states[..., -1, :]
        mu_lift = lift.momentum_of_state(y)
        lifted.append(mu_lift)
        for v, sys_v in variants.items():
            mu = solve(sys_v.vector_fields(), Xk, mu0, LogODE(), save_at="end").states[..., -1, :]
            table[v].append(_rms(mu_lift - mu))
    # against the finest Lie–Poisson solution: the strong error of the lift (order 1 expected)
    ref = solve(system.vector_fields(), X, mu0, LogODE(), save_at="end").states[..., -1, :]
    table["vs_fine"] = [_rms(m - ref) for m in lifted]
    return [2**k for k in ks], table


def _rms(d):
    return float(np.sqrt(np.mean(np.sum(d**2, axis=-1))))


def _format(name, steps, table):
    rows = [f"{name}: steps " + "  ".join(f"{n:>9d}" for n in steps)]
    rows += [f"  {v:>8s}      " + "  ".join(f"{g:9.2e}" for g in gaps) for v, gaps in table.items()]
    return "\n".join(rows)


def _check_ladder(name, steps, table, min_slope, ref_steps):
    msg = _format(name, steps, table) + f"\n  (vs_fine: against the corrected Lie–Poisson solution on {ref_steps} steps)"
    gaps = np.array(table["rp"])
    slope = np.polyfit(np.log(1.0 / np.array(steps)), np.log(gaps), 1)[0]
    assert slope >= min_slope, f"fitted order {slope:.2f} < {min_slope}\n{msg}"
    assert gaps[-1] < 1e-4, f"the gap does not close\n{msg}"
    keep = np.array(steps) < ref_steps                                  # not the reference grid itself
    fine = np.array(table["vs_fine"])[keep]
    fine_slope = np.polyfit(np.log(1.0 / np.array(steps)[keep]), np.log(fine), 1)[0]
    assert fine_slope >= 0.7 and fine[-1] < fine[0], f"no convergence to the fine solution ({fine_slope:.2f})\n{msg}"
    for wrong in ("flip", "no_half"):
        w = np.array(table[wrong])
        assert w.min() > 1e-2 and w[-1] > 0.5 * w[0], f"the {wrong} variant converges (it should not)\n{msg}"
        assert w[-1] > 100.0 * gaps[-1], f"the {wrong} variant is not separated\n{msg}"
    print(msg)


# ---------------------------------------------------------------------- exact identities
@pytest.mark.parametrize("name", CASES)
def test_momentum_map_intertwines_noise_and_drift(name):
    system, rep, _ = _case(name)
    lift = cotangent_lift(system, rep)
    y = np.random.default_rng(2).standard_normal((7, 2 * lift.dim_config))
    mu = lift.momentum_of_state(y)
    dJ = lift.momentum_gradient(y)
    V = lift.vector_fields
    np.testing.assert_allclose(dJ @ V.fields(y), system.noise(mu), atol=1e-13)
    plain = system.with_s(np.zeros_like(system.s))
    np.testing.assert_allclose((dJ @ V.drift(y)[..., None])[..., 0], plain.drift(mu), atol=1e-12)
    # ... and the Friz–Oberhauser drift of the lifted noise is X_{ℓ∘J}, mapped to the Lévy torque ad*_ℓ μ
    fo = V.friz_oberhauser_drift(system.s)
    np.testing.assert_allclose(fo(y), lift.hamiltonian_field(system.levy_velocity, y), atol=1e-13)
    np.testing.assert_allclose((dJ @ fo(y)[..., None])[..., 0], system.algebra.ad_star(system.levy_velocity, mu),
                               atol=1e-13)
    # the noise fields are the Hamiltonian fields 𝕁∇(ξ_k∘J) and dJ is J's derivative (central differences)
    np.testing.assert_allclose(V.fields(y), np.einsum("ab,...kb,ik->...ai", lift.symplectic_matrix, dJ, system.xi),
                               atol=1e-13)
    e = 1e-6
    fd = np.stack([(lift.momentum_of_state(y + e * d) - lift.momentum_of_state(y - e * d)) / (2 * e)
                   for d in np.eye(y.shape[-1])], axis=-1)
    np.testing.assert_allclose(dJ, fd, atol=1e-8)
    fdj = np.stack([(V.drift(y + e * d) - V.drift(y - e * d)) / (2 * e) for d in np.eye(y.shape[-1])], axis=-1)
    np.testing.assert_allclose(V.drift_jacobian(y), fdj, atol=1e-7)


@pytest.mark.parametrize("name", CASES)
def test_equivariance_and_poisson_brackets(name):
    system, rep, _ = _case(name)
    lift = cotangent_lift(system, rep)
    g = np.random.default_rng(4)
    N, n = lift.dim_config, system.dim
    q, p = g.standard_normal((2, N))
    A = lift.representation
    for eta in 0.4 * g.standard_normal((3, n)):
        a = np.einsum("k,kab->ab", eta, A)
        moved = lift.momentum(scipy.linalg.expm(-a) @ q, scipy.linalg.expm(a).T @ p)
        np.testing.assert_allclose(moved, system.algebra.Ad_star_exp(eta, lift.momentum(q, p)), atol=1e-12)
    # {H_i, H_j}_ω = {ξ_i, ξ_j}∘J with the minus Lie–Poisson bracket {f, g}(μ) = −⟨μ, [∇f, ∇g]⟩
    y = np.concatenate([q, p])
    mu, dJ = lift.momentum_of_state(y), lift.momentum_gradient(y)
    grad_h = system.xi @ dJ                                                       # ∇(ξ_i∘J), (m, 2N)
    omega = grad_h[:, :N] @ grad_h[:, N:].T - grad_h[:, N:] @ grad_h[:, :N].T     # {H_i, H_j}_ω
    lp = -np.einsum("k,ijk->ij", mu, system.xi_brackets)                          # {ξ_i, ξ_j}(μ)
    np.testing.assert_allclose(omega, lp, atol=1e-12)
    # the paper's printed reduced Hamiltonian h − ½ s^{ij}{ξ_i, ξ_j}: its gradient is ∇h + ℓ, so
    # df = {f, ·} dt is the library's conservative drift ad*_{∇h + ℓ} μ (the flipped sign is not)
    grad_printed = system.hamiltonian.gradient(mu) + 0.5 * np.einsum("ij,ijk->k", system.s, system.xi_brackets)
    np.testing.assert_allclose(system.algebra.ad_star(grad_printed, mu), system.conservative_drift(mu), atol=1e-13)
    flipped = system.hamiltonian.gradient(mu) - system.levy_velocity
    assert np.max(np.abs(system.algebra.ad_star(flipped, mu) - system.conservative_drift(mu))) > 1e-3


def test_phase_state_and_documented_so3_formulas():
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.5, s=S)
    lift = cotangent_lift(rb, "so3")
    g = np.random.default_rng(8)
    q, p = g.standard_normal((2, 5, 3))
    xi = g.standard_normal(3)
    np.testing.assert_allclose(lift.momentum(q, p), np.cross(p, q), atol=1e-14)
    y = np.concatenate([q, p], axis=-1)
    np.testing.assert_allclose(lift.hamiltonian_field(xi, y), np.concatenate([np.cross(q, xi), np.cross(p, xi)], -1),
                               atol=1e-14)
    omega = lift.momentum(q, p) / np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(lift.vector_fields.drift(y), np.concatenate([np.cross(q, omega), np.cross(p, omega)], -1),
                               atol=1e-14)
    mus = g.standard_normal((4, 3))
    ys = lift.phase_state(mus)
    np.testing.assert_allclose(lift.momentum_of_state(ys), mus, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(ys[:, :3], axis=-1), 1.0)
    user = cotangent_lift(rb, USER_SO3)                          # generic least squares route
    np.testing.assert_allclose(user.momentum_of_state(user.phase_state(mus)), mus, atol=1e-12)
    se = cotangent_lift(heavy_top([1.0, 1.5, 2.0], [0.0, 0.0, 0.5], sigma=0.3), "se3")
    with pytest.raises(ValueError, match="not reached"):      # Π·Γ ≠ 0 is not in the image of J on R⁴
        se.phase_state([1.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    assert isinstance(lift, CotangentLift) and lift.perturbed.__doc__


# ---------------------------------------------------------------------- symplecticity
@pytest.mark.parametrize("name", CASES)
def test_linear_noise_flow_is_symplectic(name):
    system, rep, _ = _case(name)
    lift = cotangent_lift(system, rep)
    Jm = lift.symplectic_matrix
    for K in lift.generator_matrices:                     # Hamiltonian matrices: Kᵀ𝕁 + 𝕁K = 0
        np.testing.assert_allclose(K.T @ Jm + Jm @ K, 0.0, atol=1e-14)
    y = np.random.default_rng(1).standard_normal((3, 2 * lift.dim_config))
    D = lift.vector_fields.drift_jacobian(y)               # the drift is Hamiltonian too
    np.testing.assert_allclose(np.swapaxes(D, -1, -2) @ Jm + Jm @ D, 0.0, atol=1e-12)
    # one log-ODE step of the noise: M = expm(Σ x^i K_i + Σ A^{ij} K_j K_i)
    g = np.random.default_rng(6)
    x, a = g.standard_normal(system.n_noise), g.standard_normal((system.n_noise,) * 2)
    a = a - a.T
    K = lift.noise_matrices
    M = scipy.linalg.expm(np.einsum("i,iab->ab", x, K) + np.einsum("ij,jab,ibc->ac", a, K, K))
    np.testing.assert_allclose(M.T @ Jm @ M, Jm, atol=1e-10 * max(1.0, np.max(np.abs(M)) ** 2))
    # the time-1 flow of the noise part on a Brownian rough path (columns: images of the basis)
    X = brownian_rough_path(np.linspace(0.0, 1.0, 65), system.n_noise, np.random.default_rng(9))
    noise_only = LinearVectorFields(K)
    M = np.stack([solve(noise_only, lift.perturbed(X), e, LogODE(), save_at="end").states[-1]
                  for e in np.eye(2 * lift.dim_config)], axis=-1)
    np.testing.assert_allclose(M.T @ Jm @ M, Jm, atol=1e-10 * max(1.0, np.max(np.abs(M)) ** 2))


# ---------------------------------------------------------------------- pathwise reduction
@pytest.mark.parametrize("name", CASES)
def test_lift_driven_by_perturbed_path_reduces_to_corrected_lie_poisson(name):
    steps, table = _ladder(name, (4, 6, 8), ref_k=10)
    _check_ladder(name, steps, table, min_slope=1.0, ref_steps=2**10)


@pytest.mark.slow
@pytest.mark.parametrize("name", CASES)
def test_reduction_long_ladder(name):
    steps, table = _ladder(name, (4, 6, 8, 10, 12), ref_k=12, paths=8)
    _check_ladder(name, steps, table, min_slope=1.0, ref_steps=2**12)


# ---------------------------------------------------------------------- bad input
def test_bad_input_names_the_argument_and_the_fix():
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.5, s=S)
    with pytest.raises(ValueError, match="anti-representation; pass -representation"):
        cotangent_lift(rb, -hat(np.eye(3)))
    with pytest.raises(ValueError, match="not a representation.*from_matrix_basis"):
        cotangent_lift(rb, np.random.default_rng(0).standard_normal((3, 3, 3)))
    with pytest.raises(ValueError, match=r"shape \(n, N, N\) = \(3, N, N\)"):
        cotangent_lift(rb, hat(np.eye(3))[:2])
    with pytest.raises(ValueError, match=r"shape \(n, N, N\)"):
        cotangent_lift(rb, np.zeros((3, 3, 4)))
    with pytest.raises(ValueError, match="not a representation of 'so3'"):
        cotangent_lift(rb, "sl2")
    with pytest.raises(ValueError, match="not a built-in one"):
        cotangent_lift(rb, "su2")
    with pytest.raises(TypeError, match="real matrices"):
        cotangent_lift(rb, hat(np.eye(3)) * (1 + 0j))
    with pytest.raises(TypeError, match="representation must be"):
        cotangent_lift(rb, 3.0)
    with pytest.raises(TypeError, match="system must be a LiePoissonSystem"):
        cotangent_lift(so3(), "so3")
    with pytest.raises(ValueError, match="theta=0"):
        cotangent_lift(rigid_body([1.0, 2.0, 3.0], sigma=0.5, theta=1.0), "so3")
    lift = cotangent_lift(rb, "so3")
    with pytest.raises(ValueError, match="y"):
        lift.momentum_of_state(np.zeros(5))
