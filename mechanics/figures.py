"""Registry of the paper's figures, rendered with matplotlib (Agg) by the main job.

Each figure is a function ``figure(ctx) -> FigureResult`` that runs the library (simulations,
Gibbs quadrature, equilibria, coloured noise), saves the data behind the figure as ``<name>.npz``
and the picture as ``<name>.png`` in ``ctx.out_dir``. Figures of the paper (Section 4 and the
appendix):

* ``fig1``: the dissipative stochastic rigid body (``s = 0``): trajectory on the sphere in 3D, and the
  time-density of its ``(Π1, Π2)`` projection with the Gibbs prediction overlaid;
* ``fig2``: the same Brownian path for several Lévy-area perturbations ``s``: densities recentred
  away from the north pole, Gibbs predictions and the shifted equilibria overlaid;
* ``surf``, ``surf2``, ``surf3``, ``surf4``, ``surf5``: phase portraits, level sets of ``h`` / ``h̃`` on
  the momentum sphere with the equilibria marked (stable/unstable), without and with the Lévy shift;
* ``fig4``, ``fig5``: the rigid body driven by coloured (OU) noise, and its white-noise limit with
  the noise scaled by ``A⁻¹D`` and the Lévy torque of ``N = Alt(ΣA⁻ᵀ)``.

The mathematics lives in the library; here we only call it and draw. Rendering helpers below take
plain arrays (points on the unit sphere, values of a function on it).
"""

from __future__ import annotations

import numpy as np

from .report import FigureResult, Task

__all__ = [
    "FIGURES", "register", "orthographic_basis", "sphere_image", "project", "projected_density",
    "plot_sphere_portrait", "plot_density", "plot_trajectory_3d", "plot_projected_trajectory",
]

#: name -> Task, in report order
FIGURES: dict[str, Task] = {}

DPI = 130
AXIS_LABELS = (r"$\Pi_1$", r"$\Pi_2$", r"$\Pi_3$")


def register(name: str, title: str, caption: str, requires: tuple = ()):
    """Decorator adding a figure to :data:`FIGURES`."""

    def deco(func):
        FIGURES[name] = Task(name=name, title=title, func=func, requires=tuple(requires), caption=caption)
        return func

    return deco


# =========================================================================================== rendering
def orthographic_basis(elev: float, azim: float) -> np.ndarray:
    """Rows ``(right, up, towards viewer)`` of an orthographic camera at ``(elev, azim)`` degrees."""
    e, a = np.deg2rad(elev), np.deg2rad(azim)
    d = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    r = np.array([-np.sin(a), np.cos(a), 0.0])
    u = np.array([-np.sin(e) * np.cos(a), -np.sin(e) * np.sin(a), np.cos(e)])
    return np.stack([r, u, d])


def sphere_image(func, elev: float, azim: float, n: int = 400, radius: float = 1.0):
    """Values of ``func(Pi)`` (``Pi`` of shape ``(..., 3)``) on the visible hemisphere, as an image.

    Returns ``(u, v, values)`` with ``values`` of shape ``(n, n)`` (NaN outside the disk): pixel
    ``(u, v)`` of the screen is the point ``radius·(u r + v up + sqrt(1-u²-v²) d)`` of the sphere.
    """
    B = orthographic_basis(elev, azim)
    u = np.linspace(-1.0, 1.0, n)
    U, V = np.meshgrid(u, u)
    W2 = 1.0 - U**2 - V**2
    inside = W2 >= 0
    W = np.sqrt(np.where(inside, W2, 0.0))
    pts = radius * (U[..., None] * B[0] + V[..., None] * B[1] + W[..., None] * B[2])
    vals = np.asarray(func(pts), dtype=np.float64)
    vals = np.where(inside, vals, np.nan)
    return u, u, vals


def project(points, elev: float, azim: float, radius: float = 1.0):
    """Screen coordinates ``(u, v)`` and depth (``> 0`` visible) of points ``(..., 3)``."""
    B = orthographic_basis(elev, azim)
    p = np.asarray(points, dtype=np.float64) / radius
    return p @ B[0], p @ B[1], p @ B[2]


def _draw_axes_triad(ax, elev, azim):
    """A small axis triad in an inset: the screen directions of Π1, Π2, Π3 (dotted: away from viewer)."""
    tri = ax.inset_axes([0.0, 0.0, 0.2, 0.2])
    tri.set_xlim(-1.6, 1.6)
    tri.set_ylim(-1.6, 1.6)
    tri.set_aspect("equal")
    tri.axis("off")
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1.0
        u, v, depth = project(e, elev, azim)
        tri.annotate("", xy=(u, v), xytext=(0, 0),
                     arrowprops=dict(arrowstyle="->", color="0.15", lw=1.0, ls="-" if depth >= 0 else ":"))
        off = 0.35 if np.hypot(u, v) < 0.25 else 0.0
        tri.text(1.35 * u + off, 1.35 * v + off, AXIS_LABELS[k], ha="center", va="center", fontsize=9)


_EQ_STYLE = {
    "minimum": dict(marker="o", mfc="tab:red", label="min of h̃ (centre; stable with dissipation)"),
    "maximum": dict(marker="o", mfc="tab:blue", label="max of h̃ (centre; unstable with dissipation)"),
    "saddle": dict(marker="X", mfc="white", label="saddle"),
    "degenerate": dict(marker="s", mfc="tab:orange", label="degenerate"),
}


def plot_sphere_portrait(ax, hfun, *, elev, azim, curves=(), separatrix=(), equilibria=(), title="",
                         cmap="viridis", n=500, contour_levels=None):
    """Phase portrait on the unit sphere seen from ``(elev, azim)``: level sets of ``hfun``.

    The visible hemisphere is coloured by ``hfun(Pi)``. ``curves``: the level sets, as a list (one
    entry per level) of lists of polylines ``(m, 3)`` on the sphere (e.g. from
    :func:`mechanics.equilibria.rigid_body_level_sets`); ``separatrix[k]`` marks a saddle level
    (drawn thicker, in red). Without ``curves`` the image is contoured at ``contour_levels``.
    ``equilibria``: ``(point (3,), kind)`` with kind in {"minimum", "maximum", "saddle", ...};
    visible ones are filled markers, those on the hidden side hollow. Returns the image artist.
    """
    u, v, vals = sphere_image(hfun, elev, azim, n=n)
    whole = _whole_sphere_values(hfun)
    im = ax.imshow(vals, origin="lower", extent=(-1, 1, -1, 1), cmap=cmap, alpha=0.85,
                   vmin=whole.min(), vmax=whole.max(), interpolation="bilinear")
    if len(curves):
        for k, level_curves in enumerate(curves):
            sep = bool(separatrix[k]) if len(separatrix) else False
            for line in level_curves:
                pu, pv, depth = project(np.asarray(line), elev, azim)
                pu = np.where(depth >= -1e-9, pu, np.nan)
                ax.plot(pu, pv, color="tab:red" if sep else "k", lw=1.6 if sep else 0.7, zorder=3)
        ax.plot([], [], color="tab:red", lw=1.6, label="separatrix (saddle level)")
    else:
        lv = contour_levels if contour_levels is not None else np.linspace(whole.min(), whole.max(), 26)[1:-1]
        ax.contour(u, v, vals, levels=lv, colors="k", linewidths=0.7)
    t = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(t), np.sin(t), color="k", lw=1.2)
    seen = set()
    for point, kind in equilibria:
        pu, pv, depth = project(point, elev, azim)
        st = _EQ_STYLE.get(kind, _EQ_STYLE["degenerate"])
        if depth > 0:
            ax.plot(pu, pv, ls="none", marker=st["marker"], ms=10, mfc=st["mfc"], mec="k", mew=1.2, zorder=6,
                    label=None if kind in seen else st["label"])
            seen.add(kind)
        else:
            ax.plot(pu, pv, ls="none", marker=st["marker"], ms=8, mfc="none", mec="0.35", mew=0.9, zorder=5)
    ax.plot([], [], ls="none", marker="o", ms=8, mfc="none", mec="0.35", label="equilibrium on the hidden side")
    _draw_axes_triad(ax, elev, azim)
    ax.set_xlim(-1.25, 1.25)
    ax.set_ylim(-1.25, 1.25)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for sp in ax.spines.values():
        sp.set_visible(False)
    if title:
        ax.set_title(title, fontsize=10)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.01), fontsize=7, ncol=2, framealpha=0.8)
    return im


def _whole_sphere_values(func, n=120):
    th = np.linspace(0, np.pi, n)
    ph = np.linspace(0, 2 * np.pi, 2 * n)
    T, P = np.meshgrid(th, ph, indexing="ij")
    pts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    return np.asarray(func(pts), dtype=np.float64)


def projected_density(density_fn, xe, ye, *, axes=(0, 1), hemisphere=1.0, sub=4):
    """Density, per unit area of the projection plane, of a density on the unit sphere seen in a plane.

    A point ``(x, y)`` of the plane ``(Π_a, Π_b)`` lifts to the hemisphere ``sign(Π_c) = hemisphere``
    with ``|Π_c| = sqrt(1 - x² - y²)``; the area element is ``dS = dx dy / |Π_c|``. The density is
    normalised on that hemisphere (the basin a trajectory explores) and averaged over each bin of the
    edges ``xe, ye`` (``sub × sub`` midpoints per bin), so it compares with a histogram directly.
    """
    other = [k for k in range(3) if k not in axes][0]
    # normalisation on the hemisphere, on a fine grid of the unit disk
    g = np.linspace(-1, 1, 801)
    gc = 0.5 * (g[1:] + g[:-1])
    X, Y = np.meshgrid(gc, gc, indexing="ij")
    zn = _hemisphere_values(density_fn, X, Y, axes, other, hemisphere)
    total = np.nansum(zn) * (g[1] - g[0]) ** 2
    # bin averages
    fx = np.concatenate([np.linspace(a, b, sub + 1)[:-1] + (b - a) / (2 * sub) for a, b in zip(xe[:-1], xe[1:])])
    fy = np.concatenate([np.linspace(a, b, sub + 1)[:-1] + (b - a) / (2 * sub) for a, b in zip(ye[:-1], ye[1:])])
    Xf, Yf = np.meshgrid(fx, fy, indexing="ij")
    q = np.nan_to_num(_hemisphere_values(density_fn, Xf, Yf, axes, other, hemisphere))
    q = q.reshape(len(xe) - 1, sub, len(ye) - 1, sub).mean(axis=(1, 3))
    return q / total if total > 0 else q


def _hemisphere_values(density_fn, X, Y, axes, other, hemisphere):
    r2 = X**2 + Y**2
    inside = r2 < 1.0
    Z = np.sqrt(np.where(inside, 1.0 - r2, 1.0))
    P = np.zeros(X.shape + (3,))
    P[..., axes[0]], P[..., axes[1]], P[..., other] = X, Y, np.sign(hemisphere) * Z
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.asarray(density_fn(P), dtype=np.float64) / Z
    return np.where(inside & (Z > 1e-6), v, np.nan)


def plot_density(ax, fig, xy, *, bins, extent, density_fn=None, hemisphere=None, axes=(0, 1),
                 start=None, marks=(), title="", cmap="magma"):
    """Time-density of a projected trajectory, with a predicted density's contours overlaid.

    ``xy``: samples ``(M, 2)`` of the projection. ``density_fn(Pi)``: an (unnormalised) density on
    the unit sphere, predicted for those samples: it is binned the same way (by quadrature) and drawn
    as white contour lines at the same normalisation. ``hemisphere``: +1/-1 to keep only the
    samples and quadrature nodes with that sign of the remaining coordinate (as the paper's
    projected plots, which show one hemisphere).
    """
    (x0, x1), (y0, y1) = extent
    H, xe, ye = np.histogram2d(xy[:, 0], xy[:, 1], bins=bins, range=[[x0, x1], [y0, y1]])
    cell = (xe[1] - xe[0]) * (ye[1] - ye[0])
    H = H / max(len(xy), 1) / cell
    im = ax.imshow(H.T, origin="lower", extent=(x0, x1, y0, y1), cmap=cmap, aspect="equal",
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    cb.set_label("time density (per unit area)")
    pred = None
    if density_fn is not None:
        pred = projected_density(density_fn, xe, ye, axes=axes, hemisphere=hemisphere)
        xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
        top = np.nanmax(pred) if np.any(np.isfinite(pred)) else 0.0
        if top > 0:
            ax.contour(xc, yc, np.nan_to_num(pred).T, levels=top * np.array([0.1, 0.3, 0.5, 0.7, 0.9]),
                       colors="cyan", linewidths=0.9)
            ax.plot([], [], color="cyan", lw=0.9, label="Gibbs prediction (10..90% of max)")
    if start is not None:
        ax.plot(start[0], start[1], "o", color="red", ms=7, mec="white", label="Π(0)")
    for (px, py), style, lab in marks:
        ax.plot(px, py, ls="none", label=lab, **style)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_xlabel(AXIS_LABELS[axes[0]])
    ax.set_ylabel(AXIS_LABELS[axes[1]])
    if title:
        ax.set_title(title, fontsize=10)
    ax.legend(loc="upper left", fontsize=7, framealpha=0.7)
    return H, pred, (xe, ye)


def plot_trajectory_3d(ax, traj, *, start=None, title="", max_points=30_000, times=None):
    """A trajectory on the unit sphere in 3D, coloured by time, over a wireframe sphere."""
    from matplotlib.collections import LineCollection  # noqa: F401  (3D: Line3DCollection below)
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    step = max(len(traj) // max_points, 1)
    p = traj[::step]
    th, ph = np.mgrid[0:np.pi:19j, 0:2 * np.pi:37j]
    ax.plot_wireframe(np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th), color="0.8", lw=0.4)
    segs = np.stack([p[:-1], p[1:]], axis=1)
    tt = np.linspace(0, 1, len(segs)) if times is None else np.asarray(times)[::step][:-1]
    lc = Line3DCollection(segs, cmap="plasma", linewidths=0.6)
    lc.set_array(tt)
    ax.add_collection3d(lc)
    if start is not None:
        ax.scatter(*start, color="red", s=40, depthshade=False, label="Π(0)")
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_zlim(-1, 1)
    ax.set_box_aspect((1, 1, 1))
    for setter in (ax.set_xticks, ax.set_yticks, ax.set_zticks):
        setter([-1, 0, 1])
    ax.set_xlabel(AXIS_LABELS[0])
    ax.set_ylabel(AXIS_LABELS[1])
    ax.set_zlabel(AXIS_LABELS[2])
    if title:
        ax.set_title(title, fontsize=10)
    return lc


def plot_projected_trajectory(ax, fig, traj, times, *, axes=(0, 1), start=None, title="", max_points=40_000):
    """The trajectory projected on the plane ``(Π_a, Π_b)``, coloured by time, with a colour bar."""
    from matplotlib.collections import LineCollection

    step = max(len(traj) // max_points, 1)
    p = traj[::step][:, list(axes)]
    segs = np.stack([p[:-1], p[1:]], axis=1)
    lc = LineCollection(segs, cmap="plasma", linewidths=0.5)
    lc.set_array(np.asarray(times)[::step][:-1])
    ax.add_collection(lc)
    ax.autoscale()
    ax.set_aspect("equal", adjustable="datalim")
    if start is not None:
        ax.plot(start[axes[0]], start[axes[1]], "o", color="red", ms=7, mec="white", label="Π(0)", zorder=5)
        ax.legend(loc="upper left", fontsize=7)
    cb = fig.colorbar(lc, ax=ax, fraction=0.046, pad=0.04)
    cb.set_label("time t")
    ax.set_xlabel(AXIS_LABELS[axes[0]])
    ax.set_ylabel(AXIS_LABELS[axes[1]])
    if title:
        ax.set_title(title, fontsize=10)
    return lc


def _new_figure(*args, **kw):
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt.figure(*args, **kw)


def _save(ctx, name, fig, data: dict):
    import matplotlib.pyplot as plt

    png = ctx.out_dir / f"{name}.png"
    npz = ctx.out_dir / f"{name}.npz"
    fig.savefig(png, dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    np.savez_compressed(npz, **{k: np.asarray(v) for k, v in data.items()})
    return png, npz


# =========================================================================================== the paper
#: the paper's Section 4 parameters
INERTIA = (1.0, 2.0, 3.0)
SIGMA = 0.05
THETA = 1.0
PI0 = np.array([0.0, 0.0, 1.0])
_RB = ("mechanics.rigid_body", "mechanics.integrators", "mechanics.gibbs", "mechanics.equilibria")


def s_matrix(s12: float = 0.0, s13: float = 0.0, s23: float = 0.0) -> np.ndarray:
    """The antisymmetric 3×3 ``s`` with the given upper-triangular entries."""
    return np.array([[0.0, s12, s13], [-s12, 0.0, s23], [-s13, -s23, 0.0]])


def s_label(s) -> str:
    parts = [f"s$^{{{i + 1}{j + 1}}}$={s[i, j]:g}" for i, j in ((0, 1), (0, 2), (1, 2)) if s[i, j] != 0]
    return ", ".join(parts) if parts else "s = 0"


def _body(ctx, s=None, xi=None, sigma=SIGMA, theta=THETA, convention=None):
    from mechanics.rigid_body import rigid_body

    return rigid_body(INERTIA, xi=xi, sigma=None if xi is not None else sigma, s=s, theta=theta,
                      convention=ctx.convention if convention is None else convention)


def _simulate_long(ctx, body, rng, T, dt, label, save_every):
    """One long Brownian trajectory from Π(0) = e3, in chunks (progress bar), constant memory."""
    from mechanics.integrators import simulate_brownian

    n_steps = int(round(T / dt))
    n_chunks = max(1, min(50, n_steps // 10_000))
    per = n_steps // n_chunks
    per -= per % save_every
    mu = PI0.copy()
    states, done = [PI0[None, :]], 0
    with ctx.progress.bar(label, n_steps) as bar:
        while done < n_steps:
            k = min(per, n_steps - done) if done + per < n_steps else n_steps - done
            _, out = simulate_brownian(body, mu, dt, k, rng, n_paths=1, save_every=save_every)
            states.append(out[0, 1:])
            mu = out[0, -1]
            done += k
            bar.update(k)
    traj = np.concatenate(states, axis=0)
    times = np.arange(len(traj)) * dt * save_every
    return times, traj


def _gibbs(body, sigma=SIGMA, theta=THETA):
    from mechanics.gibbs import GibbsMeasure

    return GibbsMeasure(INERTIA, body.torque_velocity, sigma=sigma, theta=theta)


def _conditional_mean(g, sign: float):
    """Gibbs mean conditioned on the hemisphere sign(Π3) = sign (the basin a trajectory explores)."""
    f = lambda P: np.concatenate([P * (np.sign(P[..., 2:3]) == sign), (np.sign(P[..., 2:3]) == sign)], -1)
    e = g.expectation(f)
    return e[:3] / e[3]


def _extent(center, half=0.32):
    cx, cy = center
    return ((cx - half, cx + half), (cy - half, cy + half))


@register("fig1", "Figure 1: the dissipative stochastic rigid body and its Gibbs measure (s = 0)",
          "Simulation of the rough-path rigid body with θ = 1, σ = 0.05, 𝕀 = diag(1, 2, 3), Π(0) = (0, 0, 1) "
          "(red dot), s = 0, on one long Stratonovich Brownian path (Lie–Heun coadjoint scheme with the step "
          "Lévy areas). Left: the trajectory stays on the unit sphere (coloured by time); middle: its projection on "
          "(Π₁, Π₂). Right: time-density "
          "of (Π₁, Π₂) after a burn-in, with the Gibbs prediction ∝ exp(−2θh̃/σ²) on the upper hemisphere, "
          "projected on the plane and bin-averaged like the data (cyan contours at 10..90 % of its maximum).", requires=_RB)
def fig1(ctx) -> FigureResult:
    body = _body(ctx)
    T = ctx.size("fig1.T", tiny=20.0, default=2_000.0, full=20_000.0)
    dt = ctx.size("fig1.dt", tiny=0.01, default=0.005, full=0.001)
    save = max(1, int(round(0.05 / dt)))
    times, traj = _simulate_long(ctx, body, ctx.rng("fig1"), T, dt, "fig1: simulate", save)
    g = _gibbs(body)
    keep = times >= 0.1 * T
    xy = traj[keep][:, :2]
    mean_pred = _conditional_mean(g, 1.0)
    fig = _new_figure(figsize=(18, 5.8), layout="constrained")
    ax3 = fig.add_subplot(1, 3, 1, projection="3d")
    lc = plot_trajectory_3d(ax3, traj, start=PI0, times=times, title="trajectory on the sphere |Π| = 1")
    cb = fig.colorbar(lc, ax=ax3, fraction=0.035, pad=0.12, orientation="horizontal")
    cb.set_label("time t")
    ax3.view_init(elev=28, azim=-55)
    plot_projected_trajectory(fig.add_subplot(1, 3, 2), fig, traj, times, start=PI0,
                              title="the same trajectory projected on (Π₁, Π₂)")
    ax = fig.add_subplot(1, 3, 3)
    H, pred, edges = plot_density(
        ax, fig, xy, bins=70, extent=_extent((0.0, 0.0)), density_fn=g.density, hemisphere=1.0, start=PI0[:2],
        marks=[((mean_pred[0], mean_pred[1]), dict(marker="x", color="cyan", ms=9, mew=2), "Gibbs mean"),
               ((xy[:, 0].mean(), xy[:, 1].mean()), dict(marker="+", color="lime", ms=11, mew=2), "time average")],
        title="density of (Π₁, Π₂), t ≥ T/10")
    fig.suptitle(f"Figure 1: θ = {THETA:g}, σ = {SIGMA:g}, 𝕀 = diag(1, 2, 3), s = 0, T = {T:g}, dt = {dt:g}",
                 fontsize=11)
    png, npz = _save(ctx, "fig1", fig, dict(times=times, trajectory=traj, histogram=H, gibbs_binned=pred,
                                            x_edges=edges[0], y_edges=edges[1], gibbs_mean_upper=mean_pred,
                                            dt=dt, T=T))
    return FigureResult("fig1", FIGURES["fig1"].title, FIGURES["fig1"].caption, png, npz)


FIG2_S = (s_matrix(s13=25.0), s_matrix(s23=25.0), s_matrix(s12=25.0), s_matrix(s12=-50.0, s13=25.0, s23=25.0))


@register("fig2", "Figure 2: the Lévy area recentres the Gibbs measure (several s, one Brownian path)",
          "Time-densities of (Π₁, Π₂) for the same Brownian realisation and four Lévy-area perturbations s "
          "(θ = 1, σ = 0.05, 𝕀 = diag(1, 2, 3), Π(0) = (0, 0, 1), red dot). The Lévy torque c = ½ Σ s^{ij} ξ_i × ξ_j "
          "(rp convention: c = σ²(s²³, −s¹³, s¹²)) shifts the minimum of h̃ = ½Π·𝕀⁻¹Π + c·Π; cyan contours: the "
          "Gibbs density exp(−2θh̃/σ²) restricted to the hemisphere the trajectory explores, binned like the "
          "data; ×: its mean; ◆: the stable equilibrium of the modified deterministic dynamics.", requires=_RB)
def fig2(ctx) -> FigureResult:
    T = ctx.size("fig2.T", tiny=20.0, default=1_000.0, full=20_000.0)
    dt = ctx.size("fig2.dt", tiny=0.01, default=0.005, full=0.001)
    save = max(1, int(round(0.05 / dt)))
    fig = _new_figure(figsize=(12.5, 10.5), layout="constrained")
    data = {}
    for k, s in enumerate(FIG2_S):
        body = _body(ctx, s=s)
        # the same seed for every panel: the same Brownian path (the paper's "identical realisation")
        times, traj = _simulate_long(ctx, body, ctx.rng("fig2"), T, dt, f"fig2: {s_label(s)}".replace("$^{", "").replace("}$", ""), save)
        g = _gibbs(body)
        keep = times >= 0.1 * T
        xy = traj[keep][:, :2]
        hemi = 1.0 if traj[keep][:, 2].mean() >= 0 else -1.0
        mean_pred = _conditional_mean(g, hemi)
        stable = [e for e in g.equilibria if e.kind == "minimum" and np.sign(e.point[2]) == hemi]
        eq = min(stable, key=lambda e: np.linalg.norm(e.point - PI0)).point if stable else mean_pred
        ax = fig.add_subplot(2, 2, k + 1)
        H, pred, edges = plot_density(
            ax, fig, xy, bins=70, extent=_extent((round(eq[0], 1), round(eq[1], 1)), 0.42), density_fn=g.density,
            hemisphere=hemi, start=PI0[:2],
            marks=[((mean_pred[0], mean_pred[1]), dict(marker="x", color="cyan", ms=9, mew=2), "Gibbs mean"),
                   ((xy[:, 0].mean(), xy[:, 1].mean()), dict(marker="+", color="lime", ms=11, mew=2), "time average"),
                   ((eq[0], eq[1]), dict(marker="D", mfc="none", mec="white", ms=8, mew=1.5), "stable equilibrium")],
            title=f"{s_label(s)}:  c = ({', '.join(f'{v + 0.0:+.4g}' for v in body.torque_velocity)})")
        data.update({f"s_{k}": s, f"trajectory_{k}": traj, f"histogram_{k}": H, f"gibbs_binned_{k}": pred,
                     f"x_edges_{k}": edges[0], f"y_edges_{k}": edges[1], f"gibbs_mean_{k}": mean_pred,
                     f"equilibrium_{k}": eq, f"c_{k}": body.torque_velocity})
    data.update(times=times, dt=dt, T=T)
    fig.suptitle(f"Figure 2: one Brownian path, four Lévy areas (convention '{ctx.convention}', T = {T:g}, "
                 f"dt = {dt:g})", fontsize=11)
    png, npz = _save(ctx, "fig2", fig, data)
    return FigureResult("fig2", FIGURES["fig2"].title, FIGURES["fig2"].caption, png, npz)


# ------------------------------------------------------------------------------- phase portraits
def _portrait(ctx, name, s, views, title):
    from mechanics.equilibria import rigid_body_level_sets

    body = _body(ctx, s=s, theta=0.0)
    c = body.torque_velocity
    n_levels = ctx.size("portrait.levels", tiny=8, default=18, full=24)
    ls = rigid_body_level_sets(INERTIA, c, levels=n_levels, include_separatrices=True)
    eqs = [(e.point, e.kind) for e in ls.equilibria]
    fig = _new_figure(figsize=(6.2 * len(views), 6.4))
    im = None
    for k, (elev, azim) in enumerate(views):
        ax = fig.add_subplot(1, len(views), k + 1)
        im = plot_sphere_portrait(ax, body.modified_hamiltonian, elev=elev, azim=azim, curves=ls.curves,
                                  separatrix=ls.separatrix, equilibria=eqs,
                                  title=f"view: elevation {elev}°, azimuth {azim}°")
    cb = fig.colorbar(im, ax=fig.axes, fraction=0.03, pad=0.02)
    cb.set_label(r"$\tilde h(\Pi) = \frac{1}{2}\Pi\cdot\mathbb{I}^{-1}\Pi + c\cdot\Pi$")
    fig.suptitle(f"{title}\nc = ({', '.join(f'{v + 0.0:+.4g}' for v in c)}), convention '{ctx.convention}'", fontsize=11)
    data = dict(c=c, s=s, levels=ls.levels, separatrix=ls.separatrix,
                equilibria=np.array([e.point for e in ls.equilibria]),
                equilibrium_kinds=np.array([e.kind for e in ls.equilibria]),
                equilibrium_energies=np.array([e.energy for e in ls.equilibria]), views=np.array(views))
    for k, lev in enumerate(ls.curves):
        for j, line in enumerate(lev):
            data[f"curve_{k}_{j}"] = line
    png, npz = _save(ctx, name, fig, data)
    return FigureResult(name, FIGURES[name].title, FIGURES[name].caption, png, npz)


_VIEW = (22, 35)
_BACK = (22, 215)
_PORTRAIT_CAP = ("Level sets of h̃ on the unit sphere |Π| = 1 (the orbits of the conservative rigid body, "
                 "𝕀 = diag(1, 2, 3)), coloured by h̃, separatrices (levels of the saddles) in red, equilibria "
                 "computed from h̃ (red: minima, blue: maxima, white crosses: saddles; hollow: hidden side). ")


@register("surf", "Figure surf: phase portrait of the rigid body, h (no Lévy shift)",
          _PORTRAIT_CAP + "Unshifted Hamiltonian h = ½Π·𝕀⁻¹Π: centres at ±e1, ±e3, saddles at ±e2 joined by four "
          "heteroclinic orbits.", requires=("mechanics.rigid_body", "mechanics.equilibria"))
def surf(ctx):
    return _portrait(ctx, "surf", s_matrix(), [_VIEW], "Figure surf: level sets of h on the momentum sphere")


@register("surf2", "Figure surf2: phase portrait with the Lévy shift of s¹³ = 25 (σ = 0.05)",
          _PORTRAIT_CAP + "Isotropic noise σ = 0.05 and s¹³ = −s³¹ = 25: in the rp convention c = (0, −0.0625, 0) "
          "(the paper's printed sign gives +0.0625 Π₂; --convention paper draws that one). The reflection "
          "symmetry is broken; pairs of homoclinic orbits (figures of eight) form around the Π₂ poles.",
          requires=("mechanics.rigid_body", "mechanics.equilibria"))
def surf2(ctx):
    return _portrait(ctx, "surf2", s_matrix(s13=25.0), [_VIEW],
                     "Figure surf2: level sets of h̃, s¹³ = 25, σ = 0.05")


@register("surf3", "Figure surf3: the shifted phase portrait of surf2 seen from the opposite side",
          _PORTRAIT_CAP + "Same h̃ as surf2, seen from the opposite side of the sphere: the second figure-of-eight "
          "pair of homoclinic orbits is rotated by π/2.", requires=("mechanics.rigid_body", "mechanics.equilibria"))
def surf3(ctx):
    return _portrait(ctx, "surf3", s_matrix(s13=25.0), [_BACK],
                     "Figure surf3: level sets of h̃, s¹³ = 25, opposite side")


@register("surf4", "Figures surf4 and surf5: anisotropic Lévy shift s¹² = −50, s¹³ = 25, s²³ = 25 (view 1)",
          _PORTRAIT_CAP + "σ = 0.05, s¹² = −50, s¹³ = 25, s²³ = 25: c = (0.0625, −0.0625, −0.125) in the rp "
          "convention; all fixed points move and no discrete symmetry is left.",
          requires=("mechanics.rigid_body", "mechanics.equilibria"))
def surf4(ctx):
    return _portrait(ctx, "surf4", s_matrix(s12=-50.0, s13=25.0, s23=25.0), [_VIEW],
                     "Figure surf4: level sets of h̃, s¹² = −50, s¹³ = s²³ = 25")


@register("surf5", "Figure surf5: anisotropic Lévy shift s¹² = −50, s¹³ = 25, s²³ = 25 (view 2)",
          _PORTRAIT_CAP + "Same h̃ as surf4 seen from the opposite side.",
          requires=("mechanics.rigid_body", "mechanics.equilibria"))
def surf5(ctx):
    return _portrait(ctx, "surf5", s_matrix(s12=-50.0, s13=25.0, s23=25.0), [_BACK],
                     "Figure surf5: level sets of h̃, s¹² = −50, s¹³ = s²³ = 25, opposite side")


# ------------------------------------------------------------------------------- coloured noise
_WZ = ("mechanics.wong_zakai", "roughpaths.coloured_noise")
K_PAPER = 0.05


def _wong_zakai_run(ctx):
    """One coupled run (same Brownian motion): coloured system, exact limit, limit without torque, srblevy."""
    if "wong_zakai" in ctx.cache:
        return ctx.cache["wong_zakai"]
    from mechanics.wong_zakai import rigid_body_wong_zakai_limit, simulate_wong_zakai_rigid_body
    from roughpaths.coloured_noise import paper_coloured_noise_matrices

    eps = ctx.size("fig4.eps", tiny=0.05, default=0.01, full=0.005)
    T = ctx.size("fig4.T", tiny=10.0, default=200.0, full=500.0)
    A, D = paper_coloured_noise_matrices(K_PAPER)
    wz = rigid_body_wong_zakai_limit(A, D, SIGMA)
    h = eps**2 / (2.0 * float(np.linalg.norm(A, 2)))
    save = max(1, int(round(0.02 / h)))
    with ctx.progress.bar(f"coloured noise eps={eps:g}, T={T:g} ({int(T / h):,} steps)", 1) as bar:
        res = simulate_wong_zakai_rigid_body(A, D, eps, SIGMA, inertia=INERTIA, theta=THETA, Pi0=PI0, T=T,
                                             rng=ctx.rng("wong_zakai"), save_every=save,
                                             systems=("coloured", "limit", "no_torque", "srblevy"))
        bar.update(1)
    out = dict(res=res, wz=wz, eps=eps, T=T, A=A, D=D)
    ctx.cache["wong_zakai"] = out
    return out


def _near_e2(traj, times, T):
    keep = times >= 0.5 * T
    return float(np.mean(np.abs(traj[keep, 1]) > 0.9))


def _wz_row(fig, gs_row, traj, times, T, label):
    ax3 = fig.add_subplot(gs_row[0], projection="3d")
    plot_trajectory_3d(ax3, traj, start=PI0, times=times, title=f"{label}: trajectory")
    ax3.view_init(elev=20, azim=-60)
    ax = fig.add_subplot(gs_row[1])
    step = max(len(times) // 20_000, 1)
    for k, col in enumerate(("tab:blue", "tab:orange", "tab:green")):
        ax.plot(times[::step], traj[::step, k], color=col, lw=0.6, label=AXIS_LABELS[k])
    ax.set_xlabel("time t")
    ax.set_ylabel("components of Π")
    ax.set_ylim(-1.05, 1.05)
    ax.legend(loc="lower right", fontsize=8, ncol=3)
    frac = _near_e2(traj, times, T)
    ax.set_title(f"{label}: fraction of t ≥ T/2 with |Π₂| > 0.9: {frac:.2f}", fontsize=9)
    axd = fig.add_subplot(gs_row[2])
    keep = times >= 0.1 * T
    H, xe, ye = plot_density(axd, fig, traj[keep][:, [0, 2]], bins=60, extent=((-1, 1), (-1, 1)), axes=(0, 2),
                             start=PI0[[0, 2]], marks=[((0.0, 0.0), dict(marker="D", mfc="none", mec="cyan", ms=8,
                                                                           mew=1.5), "±e₂ (projected)")],
                             title=f"{label}: density of (Π₁, Π₃), t ≥ T/10")
    return H, frac


@register("fig4", "Figure 4: the rigid body driven by coloured (OU) noise, no added drift",
          "The dissipative rigid body (paper eq. srbcoloured) driven by the smooth coloured noise B^ε = ∫y/ε dt with "
          "dy = −ε⁻²Ay dt + ε⁻¹dB, A = kI + Λ, k = 0.05, Λ = skew(0,0,1) read as Λ₁₃ = 1 = −Λ₃₁ (the reading fixed "
          "by the paper's printed A⁻¹D), θ = 1, σ = 0.05, 𝕀 = diag(1, 2, 3), Π(0) = e₃ (red dot). The equation has "
          "no Lévy drift; the trajectory leaves the north pole and settles near ±e₂. Integrated with the "
          "Casimir-preserving coadjoint Lie–Heun scheme on the exact level-2 lift of B^ε (steps ε²/(2‖A‖)).", requires=_WZ)
def fig4(ctx) -> FigureResult:
    run = _wong_zakai_run(ctx)
    res, T = run["res"], run["T"]
    fig = _new_figure(figsize=(18, 5.6), layout="constrained")
    gs = fig.add_gridspec(1, 3)
    H, frac = _wz_row(fig, [gs[0, 0], gs[0, 1], gs[0, 2]], res["coloured"][0], res["times"], T,
                      f"coloured, ε = {run['eps']:g}")
    fig.suptitle(f"Figure 4: coloured noise, k = {K_PAPER:g}, ε = {run['eps']:g}, T = {T:g}, step h = {res['h']:.3g}",
                 fontsize=11)
    png, npz = _save(ctx, "fig4", fig, dict(times=res["times"], coloured=res["coloured"][0], eps=run["eps"], T=T,
                                            h=res["h"], A=run["A"], D=run["D"], density=H,
                                            fraction_near_e2=frac))
    return FigureResult("fig4", FIGURES["fig4"].title, FIGURES["fig4"].caption, png, npz)


@register("fig5", "Figure 5: the white-noise limit with the Lévy torque (and without it, for comparison)",
          "The ε → 0 limit of Figure 4 on the same Brownian motion: noise vectors σA⁻¹D e_k driven by B, plus "
          "the Lévy torque c = ½ Σ N^{ij} ξ_i × ξ_j with N = Alt(ΣA⁻ᵀ) (the paper's “s¹³ ≈ 19.95” is 2N¹³; N¹³ ≈ "
          "9.975). Top: the exact limit (torque in the conservative part; the dissipation of srbcoloured is built "
          "from h). Bottom: the same without the torque (the naive Wong–Zakai guess). Both drift to ±e₂: as "
          "CONVENTIONS.md notes, that drift is dominated by the anisotropic noise A⁻¹D, so the figure alone does not "
          "diagnose the torque; the report's Wong–Zakai check does.", requires=_WZ)
def fig5(ctx) -> FigureResult:
    run = _wong_zakai_run(ctx)
    res, T = run["res"], run["T"]
    fig = _new_figure(figsize=(18, 11), layout="constrained")
    gs = fig.add_gridspec(2, 3)
    c = run["wz"].torque
    H1, f1 = _wz_row(fig, [gs[0, 0], gs[0, 1], gs[0, 2]], res["limit"][0], res["times"], T, "limit with torque")
    H2, f2 = _wz_row(fig, [gs[1, 0], gs[1, 1], gs[1, 2]], res["no_torque"][0], res["times"], T, "limit, no torque")
    fig.suptitle(f"Figure 5: white-noise limit, noise σA⁻¹D, torque c = ({', '.join(f'{v + 0.0:+.4g}' for v in c)}), "
                 f"N¹³ = {run['wz'].limit.N[0, 2]:.4g}, T = {T:g}", fontsize=11)
    png, npz = _save(ctx, "fig5", fig, dict(times=res["times"], limit=res["limit"][0], no_torque=res["no_torque"][0],
                                            srblevy=res["srblevy"][0], torque=c, N=run["wz"].limit.N,
                                            limit_xi=run["wz"].limit_xi, density_limit=H1, density_no_torque=H2,
                                            fraction_near_e2_limit=f1, fraction_near_e2_no_torque=f2))
    return FigureResult("fig5", FIGURES["fig5"].title, FIGURES["fig5"].caption, png, npz)
