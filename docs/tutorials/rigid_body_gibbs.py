"""Tutorial 3: the stochastic rigid body, its Lévy torque and its Gibbs measure.

Run with ``python docs/tutorials/rigid_body_gibbs.py`` (``TUTORIAL_SMALL=1`` for reduced sizes).

The rough-path rigid body of docs/conventions.md, body frame, isotropic noise ``ξ_i = σ e_i``:

    dΠ = Π × W dt + θ Π × (Π × W) dt + Σ_i Π × ξ_i ∘ dW^i,   W = 𝕀⁻¹Π + c,   c = σ² (s23, −s13, s12),

has the Gibbs density ``∝ exp(−2θ h̃ / σ²)`` on the sphere, ``h̃ = ½ Π·𝕀⁻¹Π + c·Π`` (Theorem 3.1 with its ½;
the paper prints the torque with the opposite sign).
"""

# %%
import os

import numpy as np

from mechanics.analysis.equilibria import rigid_body_equilibria
from mechanics.analysis.gibbs import GibbsMeasure
from mechanics.integrators import LieHeun
from mechanics.systems.rigid_body import rigid_body
from roughpaths import BrownianDriver, brownian_rough_path, solve

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
rng = np.random.default_rng(3)
inertia, sigma, theta = [1.0, 2.0, 3.0], 0.05, 1.0
s = np.zeros((3, 3))
s[0, 2], s[2, 0] = 25.0, -25.0                     # the paper's s13 = 25

# %% [markdown]
# ## 1. The system and its Lévy torque

# %%
body = rigid_body(inertia, sigma=sigma, s=s, theta=theta)
print("Lévy torque c = ½ Σ s^{ij} ξ_i × ξ_j =", body.levy_velocity)
assert np.allclose(body.levy_velocity, sigma**2 * np.array([s[1, 2], -s[0, 2], s[0, 1]]))
print("h̃ at the north pole:", float(body.modified_energy([0.0, 0.0, 1.0])))

# %% [markdown]
# ## 2. Where the Gibbs measure is centred: the equilibria of h̃
# The north pole is no longer an equilibrium; the new minimum of `h̃` on the sphere is found from
# `(𝕀⁻¹ − λ) Π = −c`, `|Π| = 1` (the paper's sentence "(0, 3σ²s13, …)" is not it).

# %%
eqs = rigid_body_equilibria(inertia, body.levy_velocity, theta=theta)
for eq in eqs:
    print(eq)
north = min((q for q in eqs if q.kind == "minimum" and q.point[2] > 0), key=lambda q: -q.point[2])

# %% [markdown]
# ## 3. Simulate: Casimir-preserving coadjoint scheme, Brownian motion with its Lévy areas
# `roughpaths.solve` integrates the Lie–Poisson system with the coadjoint Lie–Heun solver on a
# `BrownianDriver` (Stratonovich Brownian increments and Davie's step Lévy areas, generated block by
# block, path `i` seeded by `(seed, i)`); the coadjoint update keeps `|Π| = 1` to round-off.

# %%
P, T, dt = (8, 60.0, 0.01) if SMALL else (64, 300.0, 0.005)
driver = BrownianDriver(3, seed=3, dt=dt, n_steps=int(T / dt), batch_shape=(P,))
sol = solve(body, driver, [0.0, 0.0, 1.0], LieHeun(), save_at=driver.times[::10])
times, Pi = sol.times, sol.states
print("max ||Π| − 1| over all paths and times:", np.max(np.abs(np.linalg.norm(Pi, axis=-1) - 1)))
assert np.max(np.abs(np.linalg.norm(Pi, axis=-1) - 1)) < 1e-12
burn = times >= 30.0
path_means = Pi[:, burn].mean(axis=1)                      # time average of each path
mean, se = path_means.mean(axis=0), path_means.std(axis=0, ddof=1) / np.sqrt(P)

# %% [markdown]
# ## 4. Compare with the Gibbs measure (quadrature on the sphere)
# The runs start at the north pole and stay in its basin (the barrier is huge at `β = 2θ/σ² = 800`),
# so we compare with the Gibbs mean conditioned on `Π3 > 0`.

# %%
g = GibbsMeasure(inertia, body.levy_velocity, sigma=sigma, theta=theta)
f = lambda x: np.concatenate([x * (x[..., 2:3] > 0), (x[..., 2:3] > 0) * 1.0], axis=-1)
e = g.expectation(f)
gibbs_mean = e[:3] / e[3]
print("time-averaged E[Π]:", np.round(mean, 4), "±", np.round(se, 4))
print("Gibbs mean (Π3 > 0):", np.round(gibbs_mean, 4), "; stable equilibrium:", np.round(north.point, 4))
assert np.all(np.abs(mean - gibbs_mean) < 5 * se + 0.02)
# the uncorrected body (s = 0) would be centred at the north pole: Π2 ≈ 0, far from the measured 0.38
assert abs(mean[1]) > 0.3

# %% [markdown]
# ## 5. Proposition 2.1: perturbing the driver is the same as adding the torque
# Without dissipation, the corrected body driven by `X` equals the plain body driven by `X.perturb(s)`.

# %%
X = brownian_rough_path(np.linspace(0.0, 5.0, 501), 3, rng, batch_shape=(4,))
a = solve(rigid_body(inertia, sigma=sigma, s=s), X, [0.0, 0.0, 1.0], LieHeun()).states
b = solve(rigid_body(inertia, sigma=sigma), X.perturb(s), [0.0, 0.0, 1.0], LieHeun()).states
print("max |corrected(X) − plain(X.perturb(s))| =", np.max(np.abs(a - b)))
assert np.max(np.abs(a - b)) < 1e-12
