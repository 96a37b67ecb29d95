r"""Section 2.2 (rough Lagrange–d'Alembert): the forced Euler–Poincaré equation.

Claim. With a drift force ``F⁰`` and noise forces ``Fⁱ`` (``LiePoissonSystem(..., force=, noise_forces=)``) the
library solves, in its own signs (``ad*_ξ μ = ad(ξ)ᵀ μ``, on so(3) ``Π × ξ``; ``docs/conventions.md``, "Forces"),

    dμ = (ad*_{∇h + ℓ} μ + F⁰(μ)) dt + Σ_i (ad*_{ξ_i} μ + Fⁱ(μ)) d𝐗ⁱ,     ℓ = +½ Σ sⁱʲ [ξ_i, ξ_j],

driven by 𝐗: the paper's eq. (forcedeulerpoincare) with its forces moved to the right-hand side
(``F = −F_paper``) and the Lévy sign corrected. The Lévy term comes from the action and involves the ξ's only.

Checked here:

* *independent reference*: an RK4 on the pathwise ODE along a Brownian polygon where every step is
  followed by small square loops of area ``sⁱʲ δ`` that drive the ξ-fields ``μ × ξ_i`` only (no
  library bracket, ℓ or area enters it). The library (LieHeun, and Davie on ``system.vector_fields()``)
  on the same polygon converges to it at a fitted order ≈ 1; the flipped sign and the dropped ½ stay O(1);
* *the Fⁱ brackets*: the uncorrected forced system driven by ``X.perturb(s)`` is another equation
  (its Friz–Oberhauser drift has the brackets of the Fⁱ too): O(1) apart from the model, and equal to the
  loop reference whose loops drive the full fields; with ``Fⁱ = 0`` Proposition 2.1 still holds;
* *special case*: the double-bracket term passed as a ``force`` reproduces ``theta`` to round-off through
  the generic schemes, and at the scheme's order through the coadjoint schemes (``theta`` inside the group
  update, the force outside);
* *Casimirs*: a force tangent to the orbits (``F = ad*_{η(μ)} μ``) keeps ``|Π|`` up to the scheme's error,
  which falls at its order; a force that is not (``F⁰ = −κ μ``) moves it by O(1), exactly ``e^{−κT}``;
* *orders of the forced coadjoint schemes*: strong order 1 on Brownian rough paths (all three); on a smooth
  driver order 2 for LieHeun with ``F⁰`` alone, order 1 for LieEuler and ImplicitMidpoint.

Measured (seed 5, 16 paths, T = 1; RMS of μ_T against the ξ-loop reference, mesh δ = 1/n):

=====================  ========  ========  ========  ========  ========
n                      64        128       256       512       1024
=====================  ========  ========  ========  ========  ========
LieHeun                5.76e-03  3.25e-03  1.75e-03  1.00e-03  3.83e-04
Davie (vector_fields)  1.27e-02  5.75e-03  3.11e-03  1.61e-03  7.46e-04
flipped sign           1.06e+00  1.06e+00  1.06e+00  1.06e+00  1.06e+00
no ½ (2ℓ)              5.86e-01  5.85e-01  5.84e-01  5.84e-01  5.84e-01
X.perturb(s), no corr. 5.24e-01  5.13e-01  5.07e-01  5.04e-01  5.03e-01
(that vs full loops)   4.54e-02  2.17e-02  1.06e-02  5.85e-03  2.80e-03
=====================  ========  ========  ========  ========  ========
"""

import numpy as np
import pytest
from _oracles import rk4_flow

import mechanics
from mechanics.systems import LiePoissonSystem, so3
from roughpaths import Davie, Heun, brownian_rough_path, piecewise_linear_lift, solve

INERTIA = np.array([1.0, 2.0, 3.0])
XI = 0.6 * np.eye(3) + 0.15 * np.random.default_rng(1).standard_normal((3, 3))
S = np.array([[0.0, 1.5, -2.0], [-1.5, 0.0, 0.7], [2.0, -0.7, 0.0]])
MU0 = np.array([0.6, 0.0, 0.8])


def F0(mu):
    return -0.3 * mu + 0.2 * mu[..., [1, 2, 0]] ** 2


def FI(mu):
    return 0.3 * np.stack([np.sin(mu), mu * mu[..., [2, 0, 1]], np.cos(mu[..., [1, 2, 0]]) - 1.0], axis=-1)


def _system(s=S, **kw):
    return LiePoissonSystem(so3(), np.diag(INERTIA), XI, s=s, **kw)


def _cross(a, b):
    """a × b over the last axis, written out (np.cross's axis handling dominated this module's run time)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def _rms(d):
    return float(np.sqrt(np.mean(np.sum(d**2, axis=-1))))


def _slope(hs, errs):
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


# ------------------------------------------------------------------ the independent reference
def _loop_reference(values, s, full_loops=False):
    """RK4 along the polygon through ``values`` (T = 1), each step followed by square loops of area s^{pq}δ.

    Legs of the polygon drive V_0 = μ × I⁻¹μ + F⁰ (time) and V_i = μ × ξ_i + Fⁱ; the loops drive μ × ξ_i
    only (``full_loops``: the full V_i). Alternate steps use the point-reflected loops (same area).
    """
    n = values.shape[-2] - 1
    delta = 1.0 / n
    dx = np.diff(values, axis=-2)

    def loop_field(i):
        if full_loops:
            return lambda z: _cross(z, XI[i]) + FI(z)[..., :, i]
        return lambda z: _cross(z, XI[i])

    y = np.broadcast_to(MU0, values.shape[:-2] + (3,)).copy()
    for k in range(n):
        def leg(z, k=k):
            out = (_cross(z, z / INERTIA) + F0(z)) * delta
            for i in range(3):
                out = out + (_cross(z, XI[i]) + FI(z)[..., :, i]) * dx[..., k, i, None]
            return out
        y = rk4_flow(leg, y, 1.0, n=2)
        sign = 1.0 if k % 2 == 0 else -1.0
        for p in range(3):
            for q in range(p + 1, 3):
                a = np.sqrt(abs(s[p, q]) * delta)
                pp, qq = (p, q) if s[p, q] > 0 else (q, p)
                for i, c in ((pp, a), (qq, a), (pp, -a), (qq, -a)):
                    f = loop_field(i)
                    y = rk4_flow(lambda z, f=f, c=c: sign * c * f(z), y, 1.0, n=1)
    return y


def _brownian_values(paths, n, seed):
    g = np.random.default_rng(seed)
    inc = g.standard_normal((paths, n, 3)) * np.sqrt(1.0 / n)
    return np.concatenate([np.zeros((paths, 1, 3)), np.cumsum(inc, axis=1)], axis=1)


def test_library_matches_the_loop_reference_and_rejects_the_wrong_variants():
    system = _system(force=F0, noise_forces=FI)
    values = _brownian_values(8, 256, seed=5)
    ns = [32, 64, 128, 256]
    table = {k: [] for k in ("heun", "davie", "flip", "no_half", "perturbed", "perturbed_vs_full_loops")}
    for n in ns:
        v = values[:, :: 256 // n]
        ref = _loop_reference(v, S)
        X = piecewise_linear_lift(v, 1)
        table["heun"].append(_rms(solve(system, X, MU0, mechanics.LieHeun(), save_at="end").final - ref))
        table["davie"].append(_rms(solve(system.vector_fields(), X, MU0, Davie(), save_at="end").final - ref))
        table["flip"].append(_rms(solve(system.with_s(-S), X, MU0, mechanics.LieHeun(), save_at="end").final - ref))
        table["no_half"].append(_rms(solve(system.with_s(2 * S), X, MU0, mechanics.LieHeun(),
                                           save_at="end").final - ref))
        pert = solve(system.with_s(0 * S).vector_fields(), X.perturb(S), MU0, Davie(), save_at="end").final
        table["perturbed"].append(_rms(pert - ref))
        table["perturbed_vs_full_loops"].append(_rms(pert - _loop_reference(v, S, full_loops=True)))
    msg = "\n".join(f"{k:>24s} " + " ".join(f"{e:9.2e}" for e in errs) for k, errs in table.items())
    hs = 1.0 / np.array(ns)
    for k in ("heun", "davie", "perturbed_vs_full_loops"):
        assert _slope(hs, table[k]) >= 0.7, msg
        assert table[k][-1] < 1e-2, msg
    for k in ("flip", "no_half", "perturbed"):                  # O(1) apart and not converging
        assert min(table[k]) > 0.2 and table[k][-1] > 0.8 * table[k][0], msg
        assert table[k][-1] > 50 * table["heun"][-1], msg
    print(msg)


# ------------------------------------------------------------------ the Fⁱ brackets
def test_perturbed_driver_differs_by_the_brackets_of_the_noise_forces():
    X = brownian_rough_path(np.linspace(0.0, 1.0, 2**9 + 1), 3, np.random.default_rng(2), batch_shape=(8,))
    forced = _system(force=F0, noise_forces=FI)
    plain = forced.with_s(0 * S)
    model = solve(forced.vector_fields(), X, MU0, Davie(), save_at="end").final
    pert = solve(plain.vector_fields(), X.perturb(S), MU0, Davie(), save_at="end").final
    assert _rms(model - pert) > 0.1
    # the difference is exactly the F-part of the full Friz–Oberhauser drift ½ s^{ij}[V_i, V_j]
    V = plain.vector_fields()
    with_fo = solve(V, X, MU0, Davie(), drift=V.friz_oberhauser_drift(S), save_at="end").final
    assert _rms(with_fo - pert) < 0.05 * _rms(model - pert)
    # without noise forces Proposition 2.1 holds with F⁰: X.perturb(s) is the corrected model
    only0 = _system(force=F0)
    a = solve(only0, X, MU0, mechanics.LieHeun(), save_at="end").final
    b = solve(only0.with_s(0 * S), X.perturb(S), MU0, mechanics.LieHeun(), save_at="end").final
    np.testing.assert_allclose(a, b, atol=1e-10)


# ------------------------------------------------------------------ special case: double bracket
def test_double_bracket_as_a_force_reproduces_theta():
    theta = 0.7
    dbd = _system(theta=theta)
    forced = _system(force=dbd.dissipation)
    wrong = _system(force=lambda mu: -dbd.dissipation(mu))
    X = brownian_rough_path(np.linspace(0.0, 1.0, 2**9 + 1), 3, np.random.default_rng(4), batch_shape=(6,))
    for scheme in (Heun(), Davie()):
        a = solve(dbd.vector_fields(), X, MU0, scheme).states
        b = solve(forced.vector_fields(), X, MU0, scheme).states
        np.testing.assert_allclose(a, b, atol=1e-12)
        assert _rms(solve(wrong.vector_fields(), X, MU0, scheme, save_at="end").final - a[..., -1, :]) > 0.05
    for solver in (mechanics.LieEuler(), mechanics.LieHeun(), mechanics.ImplicitMidpoint()):
        gaps = []
        for k in (5, 6, 7, 8, 9):
            Xk = X.restrict(X.times[:: 2 ** (9 - k)])
            a = solve(dbd, Xk, MU0, solver, save_at="end").final
            gaps.append(_rms(solve(forced, Xk, MU0, solver, save_at="end").final - a))
        assert _slope(2.0 ** -np.arange(5, 10), gaps) >= 0.8, (solver, gaps)
        assert gaps[-1] < 5e-3, (solver, gaps)


# ------------------------------------------------------------------ Casimirs
def _eta(mu):
    return np.stack([mu[..., 1] ** 2, np.sin(mu[..., 0]), mu[..., 0] * mu[..., 2]], axis=-1)


def test_casimir_kept_by_tangent_forces_and_moved_by_the_others():
    X = brownian_rough_path(np.linspace(0.0, 1.0, 2**9 + 1), 3, np.random.default_rng(8), batch_shape=(4,))
    tangent = _system(force=lambda mu: _cross(mu, _eta(mu)),
                      noise_forces=lambda mu: 0.2 * _cross(mu, _eta(mu))[..., :, None] * np.ones(3))
    kappa = 0.3
    radial = _system(force=lambda mu: -kappa * mu)
    for solver in (mechanics.LieEuler(), mechanics.LieHeun(), mechanics.ImplicitMidpoint()):
        drift_t, drift_r = [], []
        for k in (5, 6, 7, 8, 9):
            Xk = X.restrict(X.times[:: 2 ** (9 - k)])
            drift_t.append(float(np.max(np.abs(np.linalg.norm(solve(tangent, Xk, MU0, solver).states, axis=-1) - 1))))
            drift_r.append(float(np.max(np.abs(np.linalg.norm(solve(radial, Xk, MU0, solver, save_at="end").final,
                                                              axis=-1) - np.exp(-kappa)))))
        # tangent: the exact flow keeps |Π| = 1; the scheme's drift falls at its order
        assert _slope(2.0 ** -np.arange(5, 10), drift_t) >= 0.8 and drift_t[-1] < 5e-3, (solver, drift_t)
        # not tangent: |Π_T| = e^{-κT} (an O(1) move off the orbit), reached at the scheme's order
        assert drift_r[-1] < 2e-3, (solver, drift_r)
        assert abs(1 - np.exp(-kappa)) > 100 * drift_r[-1], (solver, drift_r)
    # theta alone (no force) stays inside the group update: |Π| to round-off
    out = solve(_system(theta=0.5), X, MU0, mechanics.LieHeun()).states
    assert np.max(np.abs(np.linalg.norm(out, axis=-1) - 1)) < 1e-12


# ------------------------------------------------------------------ orders of the forced coadjoint schemes
def test_forced_coadjoint_strong_order_one():
    system = _system(force=F0, noise_forces=FI)
    X = brownian_rough_path(np.linspace(0.0, 1.0, 2**11 + 1), 3, np.random.default_rng(3), batch_shape=(8,))
    ref = solve(system.vector_fields(), X, MU0, Davie(), save_at="end").final
    ks = np.arange(4, 9)
    for solver in (mechanics.LieEuler(), mechanics.LieHeun(), mechanics.ImplicitMidpoint()):
        errs = [_rms(solve(system, X.restrict(X.times[:: 2 ** (11 - k)]), MU0, solver, save_at="end").final - ref)
                for k in ks]
        assert 0.8 <= _slope(2.0 ** -ks, errs) <= 1.3, (solver, errs)


@pytest.mark.parametrize("solver, order", [(mechanics.LieEuler(), 1.0), (mechanics.LieHeun(), 2.0),
                                           (mechanics.ImplicitMidpoint(), 1.0)])
def test_forced_coadjoint_smooth_order(solver, order):
    system = _system(theta=0.5, force=F0)
    t = np.linspace(0.0, 1.0, 2**12 + 1)
    values = np.stack([np.sin(3 * t), t**2, np.cos(2 * t) - 1], axis=-1)
    ref = solve(system.vector_fields(), piecewise_linear_lift(values, 1), MU0, Heun(), save_at="end").final
    ks = np.arange(4, 8)
    errs = [float(np.linalg.norm(solve(system, piecewise_linear_lift(values, 2 ** (12 - k)), MU0, solver,
                                       save_at="end").final - ref)) for k in ks]
    assert abs(_slope(2.0 ** -ks, errs) - order) < 0.25, errs


def test_unforced_systems_keep_the_compiled_path_and_bad_forces_are_refused():
    X = brownian_rough_path(np.linspace(0.0, 1.0, 65), 3, np.random.default_rng(1), batch_shape=(3,))
    plain = _system(theta=0.3)
    assert not plain.has_forces and plain.with_s(0 * S).force is None
    zero = _system(theta=0.3, force=lambda mu: 0.0 * mu)
    for solver in (mechanics.LieEuler(), mechanics.LieHeun(), mechanics.ImplicitMidpoint()):
        a = solve(plain, X, MU0, solver).states                      # compiled kernel
        np.testing.assert_allclose(solve(zero, X, MU0, solver).states, a, atol=1e-12)   # numpy forced path
    assert zero.with_s(2 * S).force is zero.force                  # with_s keeps the forces
    with pytest.raises(ValueError, match="noise_forces"):
        _system(noise_forces=lambda mu: mu)
    with pytest.raises(TypeError, match="force"):
        _system(force=np.zeros(3))
