"""Tutorial 1: rough paths, Chen's identity and the Lévy area.

Run it with ``python docs/tutorials/rough_paths_chen_levy_area.py``. Set the environment variable
``TUTORIAL_SMALL=1`` for reduced sizes (the test suite does).

Conventions (docs/conventions.md): the area is ``XX[i, j]_{s,t} = ∫_s^t (X^i_r - X^i_s) dX^j_r`` (the
ordering of iisignature and esig), the Lévy area is ``A = ½(XX - XXᵀ)`` *with* the ½.
"""

# %% [markdown]
# ## 1. A level-2 rough path from sampled data
# `RoughPath.from_path` lifts samples piecewise-linearly: on each linear piece the area is
# `½ ΔX ⊗ ΔX` (no Lévy area). Queries take grid times `s <= t`.

# %%
import os

import numpy as np

from roughpaths import RoughPath, chen_defect

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
rng = np.random.default_rng(2024)

# the L-shaped path (0,0) -> (1,0) -> (1,1)
L = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), times=[0.0, 1.0, 2.0])
print(L)
print("increment X_{0,2} =", L.increment(0.0, 2.0))
print("area XX_{0,2} =\n", L.area(0.0, 2.0))
print("Lévy area ½(XX - XXᵀ) =\n", L.levy_area(0.0, 2.0))
# going first along e1 then e2: XX[0, 1] = ∫ (X^1 - X^1_0) dX^2 = 1, XX[1, 0] = 0
assert np.allclose(L.area(0.0, 2.0), [[0.5, 1.0], [0.0, 0.5]])

# %% [markdown]
# ## 2. The Lévy area is the signed area swept by the chord
# For a closed loop the Lévy area `A[0, 1] = ½ ∮ (x dy - y dx)` is the enclosed (signed) area.
# A polygon with `n` vertices on the unit circle encloses `(n/2) sin(2π/n) → π`.

# %%
n = 64 if SMALL else 1024
theta = np.linspace(0.0, 2 * np.pi, n + 1)
circle = RoughPath.from_path(np.stack([np.cos(theta), np.sin(theta)], axis=-1), times=theta)
A = circle.levy_area(0.0, 2 * np.pi)[0, 1]
print(f"Lévy area of the {n}-gon: {A:.10f}; polygon area {(n / 2) * np.sin(2 * np.pi / n):.10f}; π = {np.pi:.10f}")
assert abs(A - (n / 2) * np.sin(2 * np.pi / n)) < 1e-12
# clockwise traversal flips the sign; the time-reversed path is the group inverse
assert np.isclose(circle.reverse().levy_area(0.0, 2 * np.pi)[0, 1], -A)

# %% [markdown]
# ## 3. Chen's identity
# `XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t}`. A `RoughPath` stores per-step increments and
# areas; every two-parameter query is built by Chen, and `restrict` moves to a coarser grid by Chen
# sums. Here a random walk in d = 3 (a piecewise-linear approximation of Brownian motion).

# %%
n_steps = 1_000 if SMALL else 100_000
t = np.linspace(0.0, 1.0, n_steps + 1)
walk = np.concatenate([np.zeros((1, 3)), np.cumsum(rng.standard_normal((n_steps, 3)) * np.sqrt(1.0 / n_steps), 0)])
X = RoughPath.from_path(walk, times=t)
u = t[n_steps // 3]
lhs = X.area(0.0, 1.0)
rhs = X.area(0.0, u) + X.area(u, 1.0) + np.outer(X.increment(0.0, u), X.increment(u, 1.0))
print("Chen defect at u = 1/3:", np.max(np.abs(lhs - rhs)))
assert np.allclose(lhs, rhs, atol=1e-12)
# transposing the cross term (a classic slip) is not a rough path identity:
wrong = X.area(0.0, u) + X.area(u, 1.0) + np.outer(X.increment(u, 1.0), X.increment(0.0, u))
print("with the cross term transposed the defect is", np.max(np.abs(lhs - wrong)))

coarse = X.restrict(t[:: n_steps // 10])
print("coarse path:", coarse, "; chen_defect(fine, coarse) =", chen_defect(X, coarse))
assert np.allclose(coarse.area(0.0, 1.0), lhs, atol=1e-12)

# %% [markdown]
# ## 4. Geometric paths: the symmetric part of the area is fixed by the increment
# `Sym(XX_{s,t}) = ½ X_{s,t} ⊗ X_{s,t}`, so the only new information at level 2 is the Lévy area.
# Equivalently the level-2 logarithm `XX - ½ X⊗X` equals the Lévy area.

# %%
from roughpaths import level2_log

x, xx = X.increment(0.0, 1.0), X.area(0.0, 1.0)
print("max |Sym(XX) - ½ X⊗X| =", np.max(np.abs(0.5 * (xx + xx.T) - 0.5 * np.outer(x, x))))
_, log2 = level2_log(x, xx)
assert np.allclose(log2, X.levy_area(0.0, 1.0), atol=1e-12)

# %% [markdown]
# ## 5. The Lévy area of Brownian motion
# For a 2-dimensional Brownian motion, `A_{0,t} = ½ ∫ (W¹ dW² - W² dW¹)` has mean 0 and variance
# `t²/4` (with the ½; without it the variance would be `t²`). The piecewise-linear lift of a fine
# random walk converges to the Stratonovich lift; here a Monte Carlo estimate over many walks.

# %%
paths, steps = (400, 200) if SMALL else (4_000, 1_000)
dw = rng.standard_normal((paths, steps, 2)) * np.sqrt(1.0 / steps)
W = RoughPath.from_path(np.concatenate([np.zeros((paths, 1, 2)), np.cumsum(dw, axis=1)], axis=1),
                        times=np.linspace(0.0, 1.0, steps + 1))
a = W.levy_area(0.0, 1.0)[..., 0, 1]
se = np.std(a ** 2) / np.sqrt(paths)
print(f"E[A] = {a.mean():+.4f} (0),  E[A²] = {np.mean(a ** 2):.4f} ± {se:.4f} (predicted 1/4)")
assert abs(np.mean(a ** 2) - 0.25) < 5 * se + 0.25 / steps

# %% [markdown]
# ## 6. Perturbing the area: `XX + s (t - s)`
# `perturb(s)` adds a deterministic antisymmetric matrix times the elapsed time to the area. The
# trace is unchanged, the path stays geometric, and the Lévy area moves by `s (t - s)`. A
# non-antisymmetric `s` is refused: it would break geometricity.

# %%
s = np.array([[0.0, 0.3, 0.0], [-0.3, 0.0, 0.1], [0.0, -0.1, 0.0]])
Xs = X.perturb(s)
shift = Xs.levy_area(0.0, 1.0) - X.levy_area(0.0, 1.0)
print("Lévy-area shift over [0, 1]:\n", shift)
assert np.allclose(shift, s)
try:
    X.perturb(np.eye(3))
except ValueError as exc:
    print("perturb(I) refused:", str(exc).splitlines()[0])
