"""Proposition 3.1: without dissipation the law tends to the uniform law on the orbit, with or without s.

Claim: for spanning noise ``ξ_i = σ e_i`` and ``θ = 0`` the stochastic rigid body
``dΠ = Π × (𝕀⁻¹Π + c) dt + σ Π × ∘dB`` on the sphere ``|Π| = r`` has the uniform invariant law,
whatever the Lévy-area perturbation ``s`` (the Lévy torque ``Π × c`` only adds a coadjoint drift).
Its moments are ``E[Π] = 0`` and ``E[ΠΠᵀ] = (r²/3) I``. An ensemble started at ``r e3`` reaches it:
the mean decays like ``e^{-σ² t}`` (the l = 1 eigenvalue of ``½σ²Δ_{S²}``), so with σ = 0.7,
T = 16 the residual bias is ``r e^{-7.8} ≈ 6e-4``, below the standard errors. Independent paths
give honest standard errors; the test also checks that at ``t = 1`` the law is *not* yet uniform
and that the dissipative model (θ > 0) is not uniform (so the test can fail).

Default size: σ = 0.7, r = 1.5, dt = 0.02, 1000 paths. Slow size: the paper's σ = 0.05 (relaxation
time 1/σ² = 400) with its s13 = 25, up to T = 2400.
"""

import numpy as np
import pytest

from mechanics.ensemble import run_ensemble
from mechanics.systems.rigid_body import rigid_body

IU = np.triu_indices(3)


def _s(s12=0.0, s13=0.0, s23=0.0):
    s = np.zeros((3, 3))
    s[0, 1], s[0, 2], s[1, 2] = s12, s13, s23
    return s - s.T


def _uniform_features(r):
    return np.concatenate([np.zeros(3), (r * r / 3.0 * np.eye(3))[IU]])


def _run(sigma, s, theta, r, *, n_paths, dt, T, seed, record_every=None):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=sigma, s=s, theta=theta)
    return run_ensemble(rb, [0.0, 0.0, r], dt=dt, n_steps=int(round(T / dt)), n_paths=n_paths, seed=seed,
                        burn_in=int(round(0.75 * T / dt)), record_every=record_every, chunk_size=500)


@pytest.mark.parametrize("s", [None, _s(s13=2.0), _s(s12=-4.0, s13=2.0, s23=2.0)],
                         ids=["s=0", "s13", "all"])
def test_law_tends_to_uniform(s):
    sigma, r, T, dt = 0.7, 1.5, 16.0, 0.02
    res = _run(sigma, s, 0.0, r, n_paths=1000, dt=dt, T=T, seed=11, record_every=int(round(1.0 / dt)))
    pred = _uniform_features(r)
    for stats, label in ((res.final, "final"), (res.time_average, "time average")):
        z = (stats.mean - pred) / stats.standard_error
        print(f"{label}: mean {np.round(stats.mean, 4)} se {np.round(stats.standard_error, 4)} "
              f"z {np.round(z, 2)}")
        assert np.max(np.abs(z)) < 4.0
    # the Lévy torque is large here (|c| = σ²|s| up to 2.4 r) and still the law is uniform
    # power check: at t = 1 the ensemble still remembers its start (E[Π3] ≈ r e^{-σ²} for s = 0)
    snap = res.snapshots[1]
    assert np.isclose(res.snapshot_times[1], 1.0)
    z1 = (snap.mean - pred) / snap.standard_error
    assert np.max(np.abs(z1)) > 10.0


def test_dissipative_model_is_not_uniform():
    """With θ > 0 the same statistic rejects uniformity (the Gibbs law is not uniform)."""
    sigma, r = 0.7, 1.5
    res = _run(sigma, _s(s13=2.0), 1.0, r, n_paths=400, dt=0.02, T=16.0, seed=12)
    z = (res.time_average.mean - _uniform_features(r)) / res.time_average.standard_error
    assert np.max(np.abs(z)) > 10.0


@pytest.mark.slow
@pytest.mark.parametrize("s", [None, _s(s13=25.0)], ids=["s=0", "paper s13=25"])
def test_law_tends_to_uniform_paper_sigma(s):
    sigma, r = 0.05, 1.0
    res = _run(sigma, s, 0.0, r, n_paths=400, dt=0.05, T=2400.0, seed=13)
    pred = _uniform_features(r)
    z = (res.final.mean - pred) / res.final.standard_error
    print(f"final: mean {np.round(res.final.mean, 4)} z {np.round(z, 2)}")
    assert np.max(np.abs(z)) < 4.5
