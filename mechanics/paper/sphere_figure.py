r"""Main-job figure beyond the paper: SALT Euler on the sphere with and without the Lévy-area correction.

``sphere_euler`` (registered by :mod:`mechanics.paper.figures`; reported in the section "Beyond the paper: Euler on
the sphere"): Zeitlin's model on :math:`\mathfrak{su}(N)` (:func:`mechanics.sphere.zeitlin_system`) from a smooth
random vorticity, driven by one Brownian rough path (with its Lévy areas) through three non-commuting SALT modes,
solved by LieHeun twice from the same path: without the correction (``s = 0``) and with it
(``s^{12} = 3``: the drift :math:`[W, \ell]`, :math:`\ell = \tfrac12 s^{ij}[\xi_i, \xi_j]`, which for the modes
:math:`Y_{10}, Y_{11}` is a solid-body rotation about :math:`x_2`). Drawn with
:mod:`mechanics.paper.plotting.sphere_fields`: the vorticity at t = 0 and at t = T for both, each in two
projections (orthographic views of the two hemispheres, and latitude–longitude); the enstrophy spectra; the
relative Casimir drift of both runs; the energy of both runs (not conserved under SALT noise).
"""

from __future__ import annotations

import numpy as np

import mechanics
import roughpaths
from mechanics.sphere import coefficients_to_matrix, energy, matrix_to_coefficients, matrix_to_grid, sphere_grid, zeitlin_system

from .plotting import (enstrophy_spectrum, new_figure, plot_casimir_drift, plot_enstrophy_spectrum,
                       plot_field_hemisphere, plot_field_latlon)
from .sphere_checks import smooth_vorticity

__all__ = ["sphere_euler", "SPHERE_FIGURE_TITLE", "SPHERE_FIGURE_CAPTION"]

_ORDERS = (2, 3, 4, 5, 6)
T_END, S12, AMPLITUDE = 2.0, 10.0, 0.3

SPHERE_FIGURE_TITLE = "Beyond the paper: SALT Euler on the sphere with and without the Lévy-area correction"
SPHERE_FIGURE_CAPTION = (
    "Zeitlin's model of 2-D Euler on the unit sphere (vorticity matrix W in su(N)), SALT noise through the stream "
    f"functions Y₁₀, Y₁₁, Y₂₁ (amplitude {AMPLITUDE}), one Brownian rough path with its Lévy areas, LieHeun "
    f"(strong order 1), t ∈ [0, {T_END:g}]. Rows 1–3: the vorticity at t = 0, at t = {T_END:g} without the "
    f"correction (s = 0) and at t = {T_END:g} with it (s¹² = {S12:g}, drift [W, ℓ], ℓ = ½ sᶦʲ[ξᵢ, ξⱼ]: a "
    "rotation about x₂), from the same path; each seen from above the north pole, from below the south pole "
    "(x₁ to the right) and in latitude–longitude. Bottom: the enstrophy per degree l (Z_l = ½Σ_m|ω_lm|²), the "
    "Casimirs' relative drift |C_k(t) − C_k(0)|/Σ|λ|ᵏ (round-off: the scheme is isospectral), and the energy "
    "(not conserved under SALT noise). This model is not in the paper.")


def _run(system, X, W0, keep):
    """The vorticity matrices at the times ``keep`` (about 100 of them: memory stays ~100 N x N matrices)."""
    g = system.algebra
    return g.dual_to_matrix(roughpaths.solve(system, X, g.matrix_to_dual(W0), mechanics.LieHeun(),
                                             save_at=keep).states)


def _drift(Ms):
    lam = np.linalg.eigvalsh(1j * Ms)
    c = np.stack([np.sum(lam ** k, axis=-1) for k in _ORDERS], axis=-1)
    scale = np.stack([np.sum(np.abs(lam[0]) ** k) for k in _ORDERS])
    return np.abs(c - c[0]) / scale


def sphere_euler(ctx):
    """The figure's data and picture: ``(fig, data)`` (the caller saves them)."""
    N, n = ctx.size("sphere_euler.N"), ctx.size("sphere_euler.n_steps")
    rng = ctx.rng("sphere_euler")
    W0 = coefficients_to_matrix(smooth_vorticity(rng, 6, amplitude=2.0), N)
    X = roughpaths.brownian_rough_path(np.linspace(0.0, T_END, n + 1), 3, rng, levy_area=ctx.levy_area_for(3))
    s = np.array([[0.0, S12, 0.0], [-S12, 0.0, 0.0], [0.0, 0.0, 0.0]])
    times = np.append(X.times[: n: max(1, n // 100)], X.times[-1])
    plain = _run(zeitlin_system(N, amplitudes=AMPLITUDE), X, W0, times)
    levy = _run(zeitlin_system(N, amplitudes=AMPLITUDE, s=s), X, W0, times)
    n_lat, n_lon = max(N, 48), max(2 * N, 96)
    theta, phi, _ = sphere_grid(n_lat, n_lon)
    fields = matrix_to_grid(np.stack([W0, plain[-1], levy[-1]]), n_lat, n_lon)
    lim = float(np.max(np.abs(fields)))
    fig = new_figure(figsize=(13, 15), layout="constrained")
    gs = fig.add_gridspec(4, 4, width_ratios=[1, 1, 2, 0.08])
    labels = ["t = 0", f"t = {T_END:g}, s = 0", f"t = {T_END:g}, s¹² = {S12:g}"]
    mesh = None
    for row, (field, label) in enumerate(zip(fields, labels)):
        plot_field_hemisphere(fig.add_subplot(gs[row, 0]), theta, phi, field, "north", vmin=-lim, vmax=lim,
                              title=f"{label}: north")
        plot_field_hemisphere(fig.add_subplot(gs[row, 1]), theta, phi, field, "south", vmin=-lim, vmax=lim,
                              title=f"{label}: south")
        mesh = plot_field_latlon(fig.add_subplot(gs[row, 2]), theta, phi, field, vmin=-lim, vmax=lim,
                                 title=f"{label}: latitude–longitude")
    fig.colorbar(mesh, cax=fig.add_subplot(gs[:3, 3]), label="vorticity ω")
    coef = matrix_to_coefficients(np.stack([W0, plain[-1], levy[-1]]), N)
    spectra = enstrophy_spectrum(coef)
    plot_enstrophy_spectrum(fig.add_subplot(gs[3, 0:2]), dict(zip(labels, spectra)))
    drifts = {"s0": _drift(plain), "levy": _drift(levy)}
    sub = gs[3, 2:].subgridspec(1, 2)
    ax = fig.add_subplot(sub[0, 0])
    plot_casimir_drift(ax, times, drifts["s0"], _ORDERS, label_prefix="s = 0, ")
    plot_casimir_drift(ax, times, drifts["levy"], _ORDERS, label_prefix="s ≠ 0, ", linestyle="--")
    ax.set_ylim(1e-18, 1e-10)
    ax.legend(fontsize=5, ncol=2, loc="upper left")
    ax.set_title("Casimir drift (relative)", fontsize=9)
    ax2 = fig.add_subplot(sub[0, 1])
    e_plain, e_levy = energy(plain), energy(levy)
    ax2.plot(times, e_plain, lw=1, label="s = 0")
    ax2.plot(times, e_levy, lw=1, ls="--", label=f"s¹² = {S12:g}")
    ax2.tick_params(labelsize=7)
    ax2.set_xlabel("t", fontsize=8)
    ax2.legend(fontsize=7)
    ax2.set_title("energy E(t) = ½∫|u|²dA", fontsize=9)
    fig.suptitle(f"Beyond the paper: SALT Euler on the sphere, N = {N}, {n} LieHeun steps, same Brownian path",
                 fontsize=11)
    data = dict(theta=theta, phi=phi, fields=fields, times=times, coefficients=coef, spectra=spectra,
                casimir_drift_s0=drifts["s0"], casimir_drift_levy=drifts["levy"], energy_s0=e_plain,
                energy_levy=e_levy, s=s, N=N)
    return fig, data
