"""Tutorial 2: the Friz–Oberhauser theorem — perturbing the Lévy area is adding a drift.

Run with ``python docs/tutorials/friz_oberhauser.py`` (``TUTORIAL_SMALL=1`` for reduced sizes).

Claim (paper Theorem A.1, with the sign and factor of docs/conventions.md): solving
``dY = V_i(Y) dX^i`` driven by ``(X, XX + s (t − s))`` gives the same solution as driving by ``X`` and
adding the drift ``½ Σ_{i,j} s^{ij} [V_i, V_j]``, with ``[V, W] = DW·V − DV·W``. The paper prints
``½ Σ_{i≤j}`` (half of it); the opposite sign is the other classic slip.
"""

# %%
import os

import numpy as np

from roughpaths import brownian_rough_path, Davie, LinearVectorFields, LogODE, solve

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
rng = np.random.default_rng(7)

# %% [markdown]
# ## 1. Non-commuting linear fields and an antisymmetric perturbation
# `V_i(y) = M_i y`; their brackets are `[V_i, V_j](y) = (M_j M_i − M_i M_j) y`.

# %%
d = e = 3
M = rng.standard_normal((d, e, e)) * 0.5
V = LinearVectorFields(M)
s = np.array([[0.0, 0.7, -0.4], [-0.7, 0.0, 0.3], [0.4, -0.3, 0.0]])
print("bracket matrix [V_0, V_1]:\n", V.bracket_matrices()[0, 1])
assert np.allclose(V.bracket_matrices()[0, 1], M[1] @ M[0] - M[0] @ M[1])

# %% [markdown]
# ## 2. Exactly, step by step: the log-ODE method on linear fields
# For linear fields the log-ODE step is the exponential of the step's log-signature, so the
# perturbed area and the extra drift give the same numbers to round-off.

# %%
paths, k = (4, 8) if SMALL else (32, 12)
X = brownian_rough_path(np.linspace(0.0, 1.0, 2**k + 1), d, rng, batch_shape=(paths,))
y0 = np.ones(e)
y_area = solve(V, X.perturb(s), y0, LogODE(), save_at="end").states[..., -1, :]
y_drift = solve(V, X, y0, LogODE(), drift=V.friz_oberhauser_drift(s), save_at="end").states[..., -1, :]
print("log-ODE: max |Y(perturbed area) − Y(extra drift)| =", np.max(np.abs(y_area - y_drift)))
assert np.allclose(y_area, y_drift, rtol=1e-9, atol=1e-9)

# %% [markdown]
# ## 3. Pathwise, in the limit: Davie's scheme on refined meshes
# Davie's step uses the area explicitly; the two solutions differ by the discretisation error only,
# which shrinks at the scheme's strong order (1). The wrong variants stay O(1) apart.

# %%
errors, hs = [], []
for j in range(k - 4, k + 1):
    Xj = X.restrict(X.times[:: 2 ** (k - j)])
    a = solve(V, Xj.perturb(s), y0, Davie(), save_at="end").states[..., -1, :]
    b = solve(V, Xj, y0, Davie(), drift=V.friz_oberhauser_drift(s), save_at="end").states[..., -1, :]
    hs.append(2.0**-j)
    errors.append(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))
    print(f"h = 2^-{j:<2d}  L² gap = {errors[-1]:.3e}")
slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
print(f"fitted order of the gap: {slope:.2f} (Davie's declared strong order: {Davie().order})")
assert slope > 0.7

for name, factor in (("opposite sign", -1.0), ("paper's ½ Σ_{i≤j} (half)", 0.5)):
    w = solve(V, X, y0, Davie(), drift=V.friz_oberhauser_drift(factor * s), save_at="end").states[..., -1, :]
    gap = np.sqrt(np.mean(np.sum((y_area - w) ** 2, axis=-1)))
    print(f"{name:>28}: L² gap {gap:.3f}")
    assert gap > 10 * errors[-1]
