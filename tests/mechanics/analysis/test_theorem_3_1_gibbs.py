"""Theorem 3.1 (Gibbs measure with the Lévy-area correction), rigid body, RP convention.

Claim: the dissipative stochastic rigid body
``dΠ = Π × W dt + θ Π × (Π × W) dt + σ Π × ∘dB``, ``W = 𝕀⁻¹Π + c``, ``c = σ²(s23, −s13, s12)``
(= ``+½ Σ s^{ij} ξ_i × ξ_j`` for ``ξ_i = σ e_i``), has the invariant law
``Z⁻¹ exp(−2θ h̃/σ²)`` on ``|Π| = 1``, ``h̃ = ½Π·𝕀⁻¹Π + c·Π``. Long ensemble runs match its mean
and second moments (computed by quadrature) within a few standard errors for several ``s``
(``s13 ≠ 0``, ``s23 ≠ 0``, all three), and the models without the correction (``s`` ignored) or with
the paper's flipped torque sign (``convention="paper"``) do not.

Standard errors are honest: each path contributes one time average over ``[burn-in, T]`` and the
paths are independent (per-path seeded streams), so the error of the ensemble mean is the
across-path standard deviation over ``√n_paths`` whatever the autocorrelation within a path.

Default size: σ = 0.5, θ = 1 (β = 8, relaxation time ≈ 2), T = 20, burn-in 12, dt = 0.02, 800
paths per model. Slow size: the paper's σ = 0.05 (β = 800) with its s values; starting from e3 the
paths never cross the equator (barrier ≈ 26/β), so the prediction there is the Gibbs law
conditioned on the northern hemisphere, except for the unimodal s12 = −50, s13 = s23 = 25 case.
"""


import numpy as np
import pytest

from mechanics.ensemble import run_ensemble
from mechanics.analysis.gibbs import GibbsMeasure
from mechanics.systems.rigid_body import rigid_body

INERTIA = np.array([1.0, 2.0, 3.0])
IU = np.triu_indices(3)


def _s(s12=0.0, s13=0.0, s23=0.0):
    s = np.zeros((3, 3))
    s[0, 1], s[0, 2], s[1, 2] = s12, s13, s23
    return s - s.T


def _c(sigma, s):
    """c = ½ Σ_ij s^{ij} ξ_i × ξ_j for ξ_i = σ e_i, written out (independent of the library)."""
    e = np.eye(3)
    return 0.5 * sum(s[i, j] * np.cross(sigma * e[i], sigma * e[j]) for i in range(3) for j in range(3))


def _prediction(sigma, theta, c, north_only=False):
    g = GibbsMeasure(INERTIA, c, sigma=sigma, theta=theta)
    if not north_only:
        return np.concatenate([g.mean, g.second_moment[IU]])

    def f(P):
        ind = (P[..., 2] > 0).astype(float)[..., None]
        feats = np.concatenate([P, (P[..., :, None] * P[..., None, :])[..., IU[0], IU[1]]], axis=-1)
        return np.concatenate([feats * ind, ind], axis=-1)

    v = g.expectation(f)
    return v[:-1] / v[-1]


def _zscores(sigma, theta, s, pred, *, convention="rp", n_paths, dt, T, burn, seed):
    rb = rigid_body(INERTIA, sigma=sigma, s=s, theta=theta, convention=convention)
    res = run_ensemble(rb, [0.0, 0.0, 1.0], dt=dt, n_steps=int(round(T / dt)), n_paths=n_paths, seed=seed,
                       burn_in=int(round(burn / dt)), chunk_size=400)
    ta = res.time_average
    return (ta.mean - pred) / ta.standard_error, ta, res.final


CASES = {
    "s13": _s(s13=1.0),              # c = (0, -0.25, 0)
    "s23": _s(s23=1.0),              # c = (0.25, 0, 0)
    "all": _s(s12=-2.0, s13=1.0, s23=1.0),   # c = (0.25, -0.25, -0.5)
}


@pytest.mark.parametrize("name", list(CASES))
def test_gibbs_moments_match_and_uncorrected_models_do_not(name):
    sigma, theta = 0.5, 1.0
    s = CASES[name]
    c = _c(sigma, s)
    assert np.linalg.norm(c) > 0.2
    pred = _prediction(sigma, theta, c)
    kw = dict(n_paths=800, dt=0.02, T=20.0, burn=12.0, seed=31)
    z, ta, final = _zscores(sigma, theta, s, pred, **kw)
    print(f"{name}: measured {np.round(ta.mean, 4)}\n  predicted {np.round(pred, 4)}\n"
          f"  se {np.round(ta.standard_error, 4)}\n  z {np.round(z, 2)}")
    assert np.max(np.abs(z)) < 4.0
    # the final states are independent samples of (nearly) the invariant law as well
    zf = (final.mean - pred) / final.standard_error
    assert np.max(np.abs(zf)) < 4.0
    # Hotelling-type combined statistic with the across-path covariance, dropping Π3² (the three
    # squares sum to |Π|² = 1): χ² with 8 dof, 99.99% quantile ≈ 31.8
    k = slice(0, 8)
    d = (ta.mean - pred)[k]
    t2 = float(np.linalg.solve(ta.covariance[k, k] / ta.count, d) @ d)
    assert t2 < 31.8
    # the paper's printed torque sign (c -> -c) and the uncorrected model (s ignored) fail
    z_paper, *_ = _zscores(sigma, theta, s, pred, convention="paper", **kw)
    z_none, *_ = _zscores(sigma, theta, None, pred, **kw)
    assert np.max(np.abs(z_paper)) > 15.0
    assert np.max(np.abs(z_none)) > 8.0


@pytest.mark.slow
@pytest.mark.parametrize("name, s, north_only", [
    ("paper s13=25", _s(s13=25.0), True),
    ("paper s23=25", _s(s23=25.0), True),
    ("surf4 s12=-50,s13=25,s23=25", _s(s12=-50.0, s13=25.0, s23=25.0), False),
])
def test_gibbs_paper_parameters(name, s, north_only):
    sigma, theta = 0.05, 1.0
    c = _c(sigma, s)
    pred = _prediction(sigma, theta, c, north_only=north_only)
    z, ta, _ = _zscores(sigma, theta, s, pred, n_paths=2000, dt=0.01, T=40.0, burn=20.0, seed=5)
    print(f"{name}: measured {np.round(ta.mean, 5)}\n  predicted {np.round(pred, 5)}\n"
          f"  se {np.round(ta.standard_error, 5)}\n  z {np.round(z, 2)}")
    assert np.max(np.abs(z)) < 4.5
    z_paper, *_ = _zscores(sigma, theta, s, pred, convention="paper", n_paths=400, dt=0.01, T=30.0,
                           burn=15.0, seed=6)
    assert np.max(np.abs(z_paper)) > 15.0
