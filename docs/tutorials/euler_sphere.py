"""Tutorial (beyond the paper): 2-D Euler on the sphere with SALT noise and the Lévy-area correction.

Run with ``python docs/tutorials/euler_sphere.py`` (``TUTORIAL_SMALL=1`` for reduced sizes; the figures go to
``$TUTORIAL_OUTPUT`` or the current folder).

Zeitlin's model quantises the vorticity of an incompressible fluid on the unit sphere as a matrix W in su(N):
dW = kappa [P, W] dt with the stream matrix P = Delta_N^{-1} W, a Lie–Poisson system whose Casimirs tr((iW)^k)
are the discrete enstrophies. With SALT noise (transport by given stream functions zeta_i, noise matrices xi_i)
and a Lévy-area perturbation s it is

    dW = [W, w] dt + sum_i [W, xi_i] o dX^i,   w = -kappa P + ell,   ell = 1/2 sum_ij s^{ij} [xi_i, xi_j],

the paper's equation on a fluid instead of a rigid body. The derivation and the conventions are on the
tutorial's page (docs/tutorials/euler-sphere.md) and in docs/conventions.md ("Euler on the sphere").
"""

# %%
import os
from pathlib import Path

import numpy as np

import roughpaths as rp
from mechanics import LieHeun
from mechanics.paper.plotting import (enstrophy_spectrum, new_figure, plot_casimir_drift, plot_enstrophy_spectrum,
                                      plot_field_hemisphere, plot_field_latlon)
from mechanics.sphere import (coefficients_to_matrix, energy, hbar, inverse_laplacian, matrix_to_coefficients,
                              matrix_to_grid, salt_noise, sphere_grid, zeitlin_system)

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
OUT = Path(os.environ.get("TUTORIAL_OUTPUT", "."))


def smooth_field(rng, lmax, amplitude=1.0):
    """Coefficients omega[l*(l+1)+m] of a random real vorticity of degrees 1..lmax, |omega_lm| ~ amplitude/l."""
    omega = np.zeros((lmax + 1) ** 2, dtype=complex)
    for l in range(1, lmax + 1):
        omega[l * (l + 1)] = amplitude * rng.standard_normal() / l
        for m in range(1, l + 1):
            c = amplitude * (rng.standard_normal() + 1j * rng.standard_normal()) / (np.sqrt(2) * l)
            omega[l * (l + 1) + m], omega[l * (l + 1) - m] = c, (-1) ** m * np.conj(c)
    return omega


def power_traces(M, orders=(2, 3, 4, 5, 6)):
    """tr((iW)^k) and sum |lambda|^k from the eigenvalues of the Hermitian iW."""
    lam = np.linalg.eigvalsh(1j * M)
    return (np.stack([np.sum(lam ** k, axis=-1) for k in orders], axis=-1),
            np.stack([np.sum(np.abs(lam) ** k, axis=-1) for k in orders], axis=-1))


# %% [markdown]
# ## 1. The model and one stochastic run
# `zeitlin_system(N, noise_modes=..., amplitudes=..., s=...)` is a `LiePoissonSystem` on `mechanics.su(N)`;
# states are the coordinates of W (`system.algebra.matrix_to_dual` / `dual_to_matrix`). The default noise is
# transport by the stream functions Y₁₀, Y₁₁, Y₂₁, which do not commute, so their Lévy areas matter.
# LieHeun updates W by conjugation, W ← e^{−σ} W e^{σ}: the spectrum of iW, hence every Casimir, is kept
# to round-off, while the energy is moved by the noise (transport by a velocity that is not the flow's own).

# %%
N = 32 if SMALL else 64
S = np.array([[0.0, 10.0, 0.0], [-10.0, 0.0, 0.0], [0.0, 0.0, 0.0]])     # s^12 = 10
rng = np.random.default_rng(38)
W0 = coefficients_to_matrix(smooth_field(rng, 6, amplitude=2.0), N)
n_steps, T = (50, 2.0) if SMALL else (200, 2.0)
X = rp.brownian_rough_path(np.linspace(0.0, T, n_steps + 1), 3, rng)    # one path, with its Lévy areas
plain = zeitlin_system(N, amplitudes=0.3)                                 # s = 0
levy = zeitlin_system(N, amplitudes=0.3, s=S)
g = plain.algebra
runs = {name: g.dual_to_matrix(rp.solve(system, X, g.matrix_to_dual(W0), LieHeun()).states)
        for name, system in (("s = 0", plain), ("s12 = 10", levy))}
c0, scale = power_traces(W0)
for name, Ms in runs.items():
    drift = np.max(np.abs(power_traces(Ms)[0] - c0) / scale)
    e = energy(Ms)
    print(f"{name:9s}: Casimir drift k=2..6 {drift:.1e} (relative); energy {e[0]:.4f} -> {e[-1]:.4f}")
    assert drift <= 1e-12 and abs(e[-1] - e[0]) > 1e-4 * e[0]

# %% [markdown]
# ## 2. The figures: two projections, the spectrum, the Casimir drift
# `matrix_to_grid` gives the vorticity field on a Gauss–Legendre grid; the helpers of
# `mechanics.paper.plotting` draw it from above each pole and in latitude–longitude. The correction
# s¹² = 10 adds the drift [W, ℓ], ℓ ∝ [ξ₁, ξ₂] ∝ the stream function of Y₁,₋₁: a solid-body rotation
# about x₂, visible as a tilt of the whole pattern against the run without it on the same path.

# %%
n_lat, n_lon = max(N, 48), max(2 * N, 96)        # exact transforms need n_lat >= N, n_lon >= 2N - 1
theta, phi, _ = sphere_grid(n_lat, n_lon)
fields = matrix_to_grid(np.stack([W0] + [Ms[-1] for Ms in runs.values()]), n_lat, n_lon)
labels = ["t = 0"] + [f"t = {T:g}, {name}" for name in runs]
lim = np.max(np.abs(fields))
fig = new_figure(figsize=(11, 9), layout="constrained")
grid = fig.add_gridspec(3, 3, width_ratios=[1, 1, 2])
for row, (field, label) in enumerate(zip(fields, labels)):
    plot_field_hemisphere(fig.add_subplot(grid[row, 0]), theta, phi, field, "north", vmin=-lim, vmax=lim,
                          title=f"{label}: north")
    plot_field_hemisphere(fig.add_subplot(grid[row, 1]), theta, phi, field, "south", vmin=-lim, vmax=lim,
                          title=f"{label}: south")
    plot_field_latlon(fig.add_subplot(grid[row, 2]), theta, phi, field, vmin=-lim, vmax=lim, title=label)
fig.savefig(OUT / "euler_sphere_fields.png", dpi=60)

fig = new_figure(figsize=(11, 3.6), layout="constrained")
axes = fig.subplots(1, 2)
spectra = enstrophy_spectrum(matrix_to_coefficients(np.stack([W0] + [Ms[-1] for Ms in runs.values()]), N))
plot_enstrophy_spectrum(axes[0], dict(zip(labels, spectra)))
for (name, Ms), style in zip(runs.items(), ("-", "--")):
    rel = np.abs(power_traces(Ms)[0] - c0) / scale
    plot_casimir_drift(axes[1], X.times, rel, (2, 3, 4, 5, 6), label_prefix=f"{name}, ", linestyle=style)
axes[1].set_ylim(1e-18, 1e-10)
axes[1].legend(fontsize=6, ncol=2)
fig.savefig(OUT / "euler_sphere_spectrum.png", dpi=70)
Z = spectra.sum(axis=-1)
print("enstrophy (sum of the spectrum) at t = 0 and at T, both runs:", np.round(Z, 6))
assert np.allclose(Z, Z[0], rtol=1e-10)   # C_2 is the enstrophy: kept, though the spectrum spreads

# %% [markdown]
# ## 3. Friz–Oberhauser, path by path
# The s = 0 model driven by `X.perturb(s)` (area + s(t − s)) is the model with s driven by X. The wrong
# sign (−s) and the missing ½ (2s) are not.

# %%
a = rp.solve(plain, X.perturb(S), g.matrix_to_dual(W0), LieHeun(), save_at="end").final
b = rp.solve(levy, X, g.matrix_to_dual(W0), LieHeun(), save_at="end").final
wrong = rp.solve(plain.with_s(-S), X, g.matrix_to_dual(W0), LieHeun(), save_at="end").final
half = rp.solve(plain.with_s(2 * S), X, g.matrix_to_dual(W0), LieHeun(), save_at="end").final
rel = lambda u, v: np.max(np.abs(u - v)) / np.max(np.abs(v))   # noqa: E731
print(f"perturbed path vs corrected model: {rel(a, b):.1e}; -s: {rel(wrong, a):.2f}; 2s: {rel(half, a):.2f}")
assert rel(a, b) <= 1e-11 and rel(wrong, a) > 1e-2 and rel(half, a) > 1e-2

# %% [markdown]
# ## 4. The Lévy-area drift of the mean, against its prediction
# From a fixed W₀, E[W(h)] = W₀ + hF + h²/2·LF + O(h³) with F = κ[P, W] + [W, ℓ] + ½Σ[[W, ξᵢ], ξᵢ] (L the
# Stratonovich generator; F and LF of a quadratic field by exact central differences). Along the direction
# of the Lévy drift [W₀, ℓ] the ensemble mean of (W(h) − W₀)/h must match, and the predictions with −s, 2s
# and s = 0 must not (standard errors from the sample).

# %%
n4, h, s4 = (2000 if SMALL else 20000), 0.1, np.array([[0.0, 2.0, 0.0], [-2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
small = zeitlin_system(4, amplitudes=0.5, s=s4)
xi = salt_noise(4, ((1, 0), (1, 1), (2, 1)), amplitudes=0.5)
V0 = coefficients_to_matrix(smooth_field(np.random.default_rng(11), 3), 4)
Xs = rp.brownian_rough_path(np.linspace(0.0, h, 9), 3, np.random.default_rng(12), batch_shape=(n4,))
D = (small.algebra.dual_to_matrix(rp.solve(small, Xs, small.algebra.matrix_to_dual(V0), LieHeun(),
                                           save_at="end").final) - V0) / h


def comm(A, B):
    return A @ B - B @ A


def predicted_mean(W, s):
    ell = 0.5 * sum(s[i, j] * comm(xi[i], xi[j]) for i in range(3) for j in range(3))
    b = lambda V: comm(inverse_laplacian(V), V) / hbar(4) + comm(V, ell)             # noqa: E731
    F = lambda V: b(V) + 0.5 * sum(comm(comm(V, x), x) for x in xi)                  # noqa: E731
    DF = lambda V, Y: 0.5 * (F(V + Y) - F(V - Y))                                    # noqa: E731
    LF = DF(W, b(W)) + 0.5 * sum(F(W + comm(W, x)) - 2 * F(W) + F(W - comm(W, x)) + DF(W, comm(comm(W, x), x))
                                 for x in xi)
    return F(W) + 0.5 * h * LF, comm(W, ell)


pred, direction = predicted_mean(V0, s4)
u = direction / np.linalg.norm(direction)
along = lambda A: np.real(np.sum(np.conj(u) * A, axis=(-2, -1)))                    # noqa: E731
d = along(D)
se = d.std(ddof=1) / np.sqrt(n4)
for label, factor in (("correct", 1.0), ("wrong sign", -1.0), ("no 1/2", 2.0), ("no correction", 0.0)):
    z = (d.mean() - along(predicted_mean(V0, factor * s4)[0])) / se
    print(f"{label:14s}: measured {d.mean():+.4f}, predicted {along(predicted_mean(V0, factor * s4)[0]):+.4f}, "
          f"{z:+.1f} SE")
    assert abs(z) <= 4 if factor == 1.0 else abs(z) >= 6
