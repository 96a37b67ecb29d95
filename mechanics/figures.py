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

__all__ = ["FIGURES", "register", "orthographic_basis", "sphere_image", "plot_sphere_portrait"]

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


def plot_sphere_portrait(ax, hfun, *, elev, azim, levels=24, equilibria=(), title="", cmap="viridis",
                         n=500):
    """Phase portrait on the unit sphere seen from ``(elev, azim)``: level sets of ``hfun``.

    The visible hemisphere is coloured by ``hfun`` with its level sets drawn as black lines (the
    orbits of the rigid body, which lie on the intersections of energy levels with the sphere);
    ``equilibria`` are ``(point (3,), kind)`` with kind in {"stable", "unstable", ...}: visible ones
    are filled markers, hidden ones hollow. Returns the image artist (for a colour bar).
    """
    u, v, vals = sphere_image(hfun, elev, azim, n=n)
    finite = vals[np.isfinite(vals)]
    # levels from the values on the whole sphere, so that every view of the same function agrees
    lev_vals = _whole_sphere_values(hfun)
    lv = np.linspace(lev_vals.min(), lev_vals.max(), levels + 2)[1:-1] if np.isscalar(levels) else levels
    im = ax.imshow(vals, origin="lower", extent=(-1, 1, -1, 1), cmap=cmap, alpha=0.9,
                   vmin=lev_vals.min(), vmax=lev_vals.max(), interpolation="bilinear")
    if finite.size:
        ax.contour(u, v, vals, levels=lv, colors="k", linewidths=0.7)
    t = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(t), np.sin(t), color="k", lw=1.2)
    styles = {"stable": dict(marker="o", color="tab:red"), "unstable": dict(marker="X", color="white"),
              "saddle": dict(marker="X", color="white")}
    seen = set()
    for point, kind in equilibria:
        pu, pv, depth = project(point, elev, azim)
        st = styles.get(kind, dict(marker="s", color="tab:orange"))
        lab = f"{kind} equilibrium" if kind not in seen and depth > 0 else None
        if depth > 0:
            seen.add(kind)
            ax.plot(pu, pv, ls="none", marker=st["marker"], ms=10, mfc=st["color"], mec="k", mew=1.2,
                    label=lab, zorder=5)
        else:
            ax.plot(pu, pv, ls="none", marker=st["marker"], ms=8, mfc="none", mec="0.45", mew=0.9, zorder=4)
    _draw_axes_triad(ax, elev, azim)
    ax.set_xlim(-1.4, 1.4)
    ax.set_ylim(-1.4, 1.4)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for sp in ax.spines.values():
        sp.set_visible(False)
    if title:
        ax.set_title(title, fontsize=10)
    if seen:
        ax.legend(loc="upper right", fontsize=8, framealpha=0.8)
    return im


def _whole_sphere_values(func, n=120):
    th = np.linspace(0, np.pi, n)
    ph = np.linspace(0, 2 * np.pi, 2 * n)
    T, P = np.meshgrid(th, ph, indexing="ij")
    pts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    return np.asarray(func(pts), dtype=np.float64)


def sphere_quadrature(n: int = 400):
    """Midpoint quadrature on the unit sphere: points ``(M, 3)`` and area weights ``(M,)`` (sum 4π).

    Used only to *draw* a predicted density in a projection (binning weights), never as the
    library's quadrature of the Gibbs measure.
    """
    th_edges = np.linspace(0, np.pi, n + 1)
    ph_edges = np.linspace(0, 2 * np.pi, 2 * n + 1)
    th = 0.5 * (th_edges[1:] + th_edges[:-1])
    ph = 0.5 * (ph_edges[1:] + ph_edges[:-1])
    T, P = np.meshgrid(th, ph, indexing="ij")
    w = (np.cos(th_edges[:-1]) - np.cos(th_edges[1:]))[:, None] * np.diff(ph_edges)[None, :]
    pts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    return pts.reshape(-1, 3), w.reshape(-1)


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
        pts, w = sphere_quadrature(500)
        other = [k for k in range(3) if k not in axes][0]
        if hemisphere is not None:
            keep = np.sign(pts[:, other]) == np.sign(hemisphere)
        else:
            keep = np.ones(len(pts), bool)
        p = np.asarray(density_fn(pts), dtype=np.float64) * w
        p = p / p.sum()
        pred, _, _ = np.histogram2d(pts[keep, axes[0]], pts[keep, axes[1]], bins=[xe, ye], weights=p[keep])
        pred = pred / cell
        xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
        top = pred.max()
        if top > 0:
            cs = ax.contour(xc, yc, pred.T, levels=top * np.array([0.1, 0.3, 0.5, 0.7, 0.9]), colors="cyan",
                            linewidths=0.9)
            cs.collections[0].set_label("Gibbs prediction") if hasattr(cs, "collections") else None
            ax.plot([], [], color="cyan", lw=0.9, label="Gibbs prediction (10..90% of max)")
    if start is not None:
        ax.plot(start[0], start[1], "o", color="red", ms=7, mec="white", label="Π(0)")
    for (px, py), style, lab in marks:
        ax.plot(px, py, ls="none", label=lab, **style)
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
    ax.set_xlabel(AXIS_LABELS[0])
    ax.set_ylabel(AXIS_LABELS[1])
    ax.set_zlabel(AXIS_LABELS[2])
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
