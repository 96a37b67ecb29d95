"""Tutorial: the Lévy area from deterministic chaos.

Run with ``python docs/tutorials/deterministic_chaos.py`` (``TUTORIAL_SMALL=1`` for reduced sizes).

A fast chaotic map ``y ↦ T(y)`` and an observable ``v`` with mean zero: the sums ``n^{-1/2} Σ_{j<nt} v(y_j)``
converge to a Brownian motion, but their iterated sums converge to the Itô area **plus** ``E t``,
``E = Σ_{m≥1} ∫ v ⊗ v∘T^m dμ`` (Kelly–Melbourne). In the library's conventions the limit of the
driver's geometric lift is the Stratonovich Brownian rough path perturbed by ``s = Alt(E) = ½(E − Eᵀ)``: a
fast–slow system driven by deterministic chaos converges to "neither Itô nor Stratonovich". The derivation is
on the tutorial's page (``docs/tutorials/deterministic-chaos.md``).
"""

# %%
import os
import time

import numpy as np
from scipy.linalg import expm

from roughpaths import (ChaoticDriver, LinearVectorFields, SineObservable, brownian_rough_path, cat_map, chaotic_limit,
                        chaotic_limit_path, green_kubo, lorenz63_map, observable_orbits, solve)

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")

# %% [markdown]
# ## 1. Why the cat map is iterated on a lattice
# In floating point the doubling map `y ↦ 2y mod 1` loses one bit per step and reaches 0 after 53 steps.
# The cat map `y ↦ A y mod 1`, `A = [[2, 1], [1, 1]]`, is iterated by `cat_map()` exactly on the
# lattice `2⁻⁶⁴ Z²` in `uint64` arithmetic, whose uniform measure is invariant and sampled exactly.

# %%
y = np.random.default_rng(0).random(1000)
for _ in range(60):
    y = (2.0 * y) % 1.0
print("doubling map in floating point, 60 steps: all zero?", bool(np.all(y == 0.0)))
assert np.all(y == 0.0)

T = cat_map()
s = T.sample(np.random.default_rng(1), 1)
a, b = int(s[0, 0]), int(s[0, 1])
for _ in range(1000):
    s = T.step(s)
    a, b = (2 * a + b) % 2**64, (a + b) % 2**64
print("cat map on the lattice after 1000 steps equals Python-integer arithmetic:",
      (int(s[0, 0]), int(s[0, 1])) == (a, b))
assert (int(s[0, 0]), int(s[0, 1])) == (a, b)

# %% [markdown]
# ## 2. An observable whose `E` is exact
# Sines at frequencies on the orbits of `A`: `v¹ = sin 2πk·y + ½ sin 2πA²q·y`, `v² = sin 2πAk·y + sin 2πq·y`
# with `k = (1, 0)`, `q = (0, 1)`. Then `v²`'s first term is `v¹`'s first term one step later, and `v¹`'s
# second term is `v²`'s second term two steps later: `C²¹(1) = ½`, `C¹²(2) = ¼`, and every other
# correlation vanishes. `E = [[0, ¼], [½, 0]]`, `Alt(E)₁₂ = ½(¼ − ½) = −⅛`.

# %%
A = np.array([[2, 1], [1, 1]])
k, q = np.array([1, 0]), np.array([0, 1])
v = SineObservable([[k, A @ A @ q], [A @ k, q]], [[1.0, 0.5], [1.0, 1.0]])
C = v.correlations(6)
E = C[1:].sum(axis=0)
Sigma = C[0] + E + E.T
lim = chaotic_limit(Sigma, E)
print("E =", E.tolist(), " Sigma =", Sigma.tolist(), " Alt(E) =", lim.levy_perturbation.tolist())
assert lim.levy_perturbation[0, 1] == -0.125

# %% [markdown]
# ## 3. Green–Kubo from orbits
# `green_kubo` estimates `C(m)` per orbit (FFT) and reports standard errors across independent orbits; the
# only bias is the lag truncation, zero here beyond lag 2.

# %%
t0 = time.perf_counter()
vals = observable_orbits(T, v, 2000 if SMALL else 8000, seed=2, batch_shape=(32 if SMALL else 128,))
est = green_kubo(vals, 6)
print(f"orbits and estimate in {time.perf_counter() - t0:.2f} s")
print("Ê =", np.round(est.E, 4).tolist(), "±", np.round(est.E_se, 4).tolist())
assert np.all(np.abs(est.E - E) < 4 * est.E_se)

# %% [markdown]
# ## 4. The driver's Lévy area grows at the rate Alt(E)
# `ChaoticDriver` gives the geometric (piecewise-linear) lift of the sums. Over `[0, 1]` with `n` fast steps
# the exact mean Lévy area is `Alt(Σ_m (n − m) C(m))/n`, which tends to `Alt(E)`.

# %%
n, P = (100, 2000) if SMALL else (400, 8000)
drv = ChaoticDriver(T, v, n, seed=3, dt=1.0 / n, n_steps=n, batch_shape=(P,))
t0 = time.perf_counter()
X = drv.rough_path()
el = time.perf_counter() - t0
area = X.levy_area(0.0, 1.0)[:, 0, 1]
rate = sum((n - m) * C[m] for m in range(1, 7)) / n
pred = 0.5 * (rate - rate.T)[0, 1]
se = area.std(ddof=1) / np.sqrt(P)
print(f"{P} orbits x {n} fast steps lifted in {el:.2f} s ({P * n / el:.3g} fast steps per second)")
print(f"mean Lévy area {area.mean():.4f} ± {se:.4f}; exact {pred:.4f}; Alt(E)12 = -0.125")
assert abs(area.mean() - pred) < 4 * se and abs(area.mean()) > 6 * se

# %% [markdown]
# ## 5. A fast–slow system: neither Itô nor Stratonovich
# `dx = b(x) dX` with `b_γ(x) = B_γ x`, rotations about `e₁` and `e₂` (they do not commute), solved on the
# driver (log-ODE, exact on each fast step), against the mean of its limit `exp(Σ K^{βγ} B_γ B_β) x₀` with
# `K = E + ½C(0) = ½Σ + Alt(E)`. The two wrong guesses: Stratonovich without the area (`K = ½Σ`), Itô
# without `E` (`K = 0`). The limit path `chaotic_limit_path` gives the same mean through `solve`.

# %%
B = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
              [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]])
x0 = np.array([0.0, 0.6, 0.8])


def mean_of_limit(K):
    return expm(sum(K[i, j] * B[j] @ B[i] for i in range(2) for j in range(2))) @ x0


V = LinearVectorFields(B)
x = solve(V, drv, x0, solver="logode", save_at="end").final
m, se = x.mean(axis=0), x.std(axis=0, ddof=1) / np.sqrt(P)
for name, K in (("limit with the area", E + 0.5 * C[0]), ("Stratonovich without area", 0.5 * Sigma),
                ("Itô without E", 0.0 * E)):
    z = np.abs(m - mean_of_limit(K)) / se
    print(f"{name:28s} {np.round(mean_of_limit(K), 4)}  max |z| = {z.max():.1f}")
assert np.max(np.abs(m - mean_of_limit(E + 0.5 * C[0])) / se) < 4
assert np.max(np.abs(m - mean_of_limit(0.0 * E)) / se) > 6
B_path = brownian_rough_path(np.linspace(0.0, 1.0, 65), 2, np.random.default_rng(4), batch_shape=(P,))
xl = solve(V, chaotic_limit_path(lim, B_path), x0, solver="logode", save_at="end").final
print("solve on the limit path:", np.round(xl.mean(axis=0), 4), "simulated fast-slow:", np.round(m, 4))
assert np.max(np.abs(xl.mean(axis=0) - mean_of_limit(E + 0.5 * C[0])) / (xl.std(axis=0) / np.sqrt(P))) < 4

# %% [markdown]
# ## 6. Lorenz-63: E estimated
# The Lorenz flow sampled every 0.05, `v = (x, y)/30` (mean zero by the symmetry `(x, y, z) ↦ (−x, −y, z)`).
# `Σ` is (nearly) of rank one: `y − x = ẋ/σ` is a time derivative, so its sums telescope and `W^x = W^y` in
# the limit. The area drift survives: `Alt(E)₁₂ ≠ 0`. The tail diagnostic shows the lag truncation.

# %%
L = lorenz63_map(0.05)


def obs(u):
    return u[..., :2] / 30.0


vals = observable_orbits(L, obs, 3000 if SMALL else 8000, seed=5, batch_shape=(32 if SMALL else 128,))
est = green_kubo(vals, 200)
print("Lorenz Ê =", np.round(est.E, 3).tolist(), "±", round(float(est.E_se.max()), 3),
      " tail =", np.round(est.tail, 3).tolist())
print("Σ̂ =", np.round(est.Sigma, 3).tolist(), " Alt(Ê)12 =", round(0.5 * (est.E[0, 1] - est.E[1, 0]), 3))
assert abs(est.E[0, 1] - est.E[1, 0]) > 4 * max(est.E_se[0, 1], est.E_se[1, 0])
nL, PL = (200, 600) if SMALL else (800, 3000)
t0 = time.perf_counter()
xL = solve(V, ChaoticDriver(L, obs, nL, seed=6, dt=1.0 / nL, n_steps=nL, batch_shape=(PL,)), x0,
           solver="logode", save_at="end").final
el = time.perf_counter() - t0
print(f"Lorenz fast-slow: {PL} orbits x {nL} fast steps in {el:.1f} s; E[x_1] = {np.round(xL.mean(axis=0), 4)}, "
      f"limit from Ê: {np.round(mean_of_limit(est.E + 0.5 * est.correlations[0]), 4)}, "
      f"Itô without E: {mean_of_limit(0.0 * E)}")
far = np.abs(xL.mean(axis=0) - mean_of_limit(0.0 * E)) / (xL.std(axis=0, ddof=1) / np.sqrt(PL))
assert far.max() > 6
