"""Tutorial: rough drivers — fractional Brownian motion, level-3 rough paths, and the rigid body.

Run with ``python docs/tutorials/rough_drivers.py`` (``TUTORIAL_SMALL=1`` for reduced sizes).

Fractional Brownian motion with Hurst index ``H < 1/2`` is not a semimartingale: an equation driven by it
has no Itô or Stratonovich meaning, only the rough-path one. This tutorial samples fBM exactly, lifts it
to a geometric rough path (level 2 for ``H = 0.4``, level 3 for ``H = 0.3``), and drives the stochastic
rigid body with it, with and without a Lévy-area perturbation, keeping the Casimir ``|Π|`` exactly.
"""

# %%
import os

import numpy as np

import mechanics
from roughpaths import (Davie3, LinearVectorFields, LogODE3, RoughPathN, fbm, fbm_rough_path,
                        piecewise_linear_lift, solve)

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")

# %% [markdown]
# ## 1. Exact fBM on a grid
# `fbm` uses the Davies–Harte circulant embedding (one complex FFT gives two exact samples); the
# grid values have covariance `½(s^{2H} + t^{2H} − |t − s|^{2H})`, so `E|B_t|² = t^{2H}`.

# %%
paths = 400 if SMALL else 4000
for H in (0.3, 0.4, 0.7):
    B = fbm(256, H, rng=np.random.default_rng(1), dim=1, batch_shape=(paths,))
    var = np.mean(B[:, [64, 256], 0] ** 2, axis=0)
    print(f"H = {H}: E|B_1/4|² = {var[0]:.4f} (exact {0.25 ** (2 * H):.4f}), E|B_1|² = {var[1]:.4f} (exact 1)")
    assert np.allclose(var, [0.25 ** (2 * H), 1.0], rtol=6 / np.sqrt(paths))

# %% [markdown]
# ## 2. The rough-path lift and its Lévy area
# The lift is the signature of the polygon through a fine sample (`substeps` fine steps per coarse
# step), assembled by Chen. Its Lévy area converges as the fine mesh `δ` shrinks, slowly for small `H`
# (the missing areas are of size `δ^{2H − 1/2}`): refining the same sample changes it less and less.

# %%
n_fine = 1024 if SMALL else 8192
V = fbm(n_fine, 0.4, rng=np.random.default_rng(2), dim=2, batch_shape=(200,))
ref = piecewise_linear_lift(V, n_fine).levy_area(0.0, 1.0)[..., 0, 1]
for n in (16, 64, 256):
    A = piecewise_linear_lift(V[:, ::n_fine // n], n).levy_area(0.0, 1.0)[..., 0, 1]
    print(f"H = 0.4, δ = 1/{n}: RMS |A_δ − A_ref| = {np.sqrt(np.mean((A - ref) ** 2)):.4f}")

# %% [markdown]
# For `H = 0.3` the path is `p`-rough only for `p > 1/H ≈ 3.3`: level 2 is not enough and the lift is a
# `RoughPathN` of level 3. Its homogeneous p-variation (exact over grid partitions) is finite for `p > 1/H`.

# %%
X3 = fbm_rough_path(32, 0.3, rng=3, substeps=64, level=3, dim=3, batch_shape=(4,))
print(X3, "| homogeneous 3.5-variation:", np.round(X3.p_variation(3.5), 3))
assert X3.level == 3 and np.all(np.isfinite(X3.p_variation(3.5)))

# %% [markdown]
# ## 3. The rigid body driven by fBM (H = 0.4, level 2), with and without the Lévy-area perturbation
# `roughpaths.solve` with a coadjoint solver (`mechanics.LieHeun()`) takes any geometric level-2 rough path;
# the coadjoint scheme keeps `|Π|` exactly.
# Perturbing the area by `s (t − s)` (`X.perturb(s)`) is, by Friz–Oberhauser, the same as adding the Lévy
# torque `c = ½ Σ s^{ij} ξ_i × ξ_j` to the body (`rigid_body(..., s=s, levy_in_dissipation=False)`). The
# coadjoint scheme sees the step Lévy area and the torque in the same Lie-algebra element, so on an fBM
# path the two agree to round-off, step by step, while the perturbation moves the body by O(1).

# %%
s = np.zeros((3, 3))
s[0, 2], s[2, 0] = 4.0, -4.0
body = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.5, theta=0.2)
body_torque = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.5, s=s, theta=0.2, levy_in_dissipation=False)
mu0 = np.array([0.0, 0.6, 0.8])
n_paths = 8 if SMALL else 64
X = fbm_rough_path(512, 0.4, rng=4, substeps=8, T=4.0, dim=3, batch_shape=(n_paths,))
Pi_plain = solve(body, X, mu0, mechanics.LieHeun()).states
Pi_pert = solve(body, X.perturb(s), mu0, mechanics.LieHeun()).states
Pi_torque = solve(body_torque, X, mu0, mechanics.LieHeun()).states
casimir = max(np.abs(np.linalg.norm(P, axis=-1) - 1.0).max() for P in (Pi_plain, Pi_pert, Pi_torque))
gap = np.abs(Pi_pert - Pi_torque).max()
effect = np.sqrt(np.mean(np.sum((Pi_pert[..., -1, :] - Pi_plain[..., -1, :]) ** 2, -1)))
print(f"max ||Π| − 1| = {casimir:.1e}; effect of the perturbation at t = 4: {effect:.3f}; "
      f"max |perturbed path − Lévy torque| = {gap:.1e}")
assert casimir < 1e-12 and gap < 1e-10 and effect > 0.1

# %% [markdown]
# ## 4. H = 0.3: a level-3 driver and the log-ODE method at depth 3
# The noise part of the body, `dΠ = Σ_i Π × ξ_i dX^i`, has linear fields `V_i(Π) = −ξ̂_i Π` with skew
# matrices, so the level-3 log-ODE step is the exponential of a skew matrix: a rotation, `|Π|` exact.
# The third-order Taylor step `Davie3` is not a Lie-group method and drifts off the sphere. The level-2
# solvers refuse this driver (they would drop its level 3).

# %%
xi = 0.8 * np.eye(3)
noise = LinearVectorFields(-mechanics.hat(xi))
X3 = fbm_rough_path(128 if SMALL else 512, 0.3, rng=5, substeps=16, level=3, dim=3, batch_shape=(n_paths,))
Y = solve(noise, X3, mu0, LogODE3()).states
Yp = solve(noise, X3.perturb(s), mu0, LogODE3()).states
Yd = solve(noise, X3, mu0, LogODE3(), drift=noise.friz_oberhauser_drift(s)).states
Yt = solve(noise, X3, mu0, Davie3()).states
print("LogODE3: max ||Π| − 1| =", f"{np.abs(np.linalg.norm(Y, axis=-1) - 1).max():.1e}",
      "| with the perturbation:", f"{np.abs(np.linalg.norm(Yp, axis=-1) - 1).max():.1e}")
print("Davie3 (Taylor): max ||Π| − 1| =", f"{np.abs(np.linalg.norm(Yt, axis=-1) - 1).max():.1e}")
print("Friz–Oberhauser, LogODE3: max |perturbed path − drift| =", f"{np.abs(Yp - Yd).max():.1e}")
assert np.abs(np.linalg.norm(Y, axis=-1) - 1).max() < 1e-12
assert np.abs(np.linalg.norm(Yp, axis=-1) - 1).max() < 1e-12
assert np.abs(Yp - Yd).max() < 1e-11
try:
    solve(noise, X3, mu0, "davie")
except ValueError as err:
    print("Davie() on a level-3 driver:", str(err).split(";")[0])
assert isinstance(X3, RoughPathN)
