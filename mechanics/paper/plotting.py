r"""Plotting helpers behind the paper's figures: the momentum sphere, densities, phase portraits.

Every helper draws on a matplotlib ``Axes`` you pass in and takes plain arrays (points on the unit
sphere ``|Π| = 1`` of shape ``(..., 3)``, and functions ``f(Π)`` evaluated on such arrays), so it
works with any simulation, not only the library's. Figures are built with :func:`new_figure`
(a :class:`matplotlib.figure.Figure` that needs no pyplot and no display).

* :func:`plot_trajectory_3d`, :func:`plot_projected_trajectory`: a trajectory on the sphere, in 3D
  and projected on a coordinate plane, coloured by time;
* :func:`plot_density`: the time-density of a projected trajectory with the contours of a
  predicted density overlaid (the paper's Gibbs measure ``∝ exp(−2θh̃/σ²)``), binned the same way
  by :func:`projected_density`;
* :func:`plot_sphere_portrait`: a phase portrait, the level sets of a Hamiltonian on the sphere seen
  from a camera, with the equilibria marked; :func:`sphere_image`, :func:`project` and
  :func:`orthographic_basis` are its geometry.

The conventions of the library (``docs/conventions.md``) do not enter here: the caller passes the
functions to draw (e.g. ``rigid_body(...).modified_hamiltonian`` or ``GibbsMeasure(...).density``).

Examples
--------
>>> import numpy as np
>>> from mechanics.paper.plotting import new_figure, plot_density
>>> rng = np.random.default_rng(0)
>>> xy = 0.05 * rng.standard_normal((2000, 2))                  # samples of (Π1, Π2) near e3
>>> fig = new_figure(figsize=(4, 4))
>>> ax = fig.add_subplot()
>>> H, pred, edges = plot_density(ax, xy, bins=20, extent=((-0.3, 0.3), (-0.3, 0.3)),
...                               density_fn=lambda P: np.exp(-200 * (1 - P[..., 2])), hemisphere=1.0)
>>> H.shape, pred.shape
((20, 20), (20, 20))
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection

__all__ = [
    "AXIS_LABELS", "new_figure", "orthographic_basis", "sphere_image", "project", "projected_density",
    "plot_sphere_portrait", "plot_density", "plot_trajectory_3d", "plot_projected_trajectory",
]

#: axis labels of the momentum coordinates (matplotlib mathtext)
AXIS_LABELS = (r"$\Pi_1$", r"$\Pi_2$", r"$\Pi_3$")


def new_figure(**kwargs) -> Figure:
    """A :class:`matplotlib.figure.Figure` independent of pyplot (no global state, no display).

    Parameters
    ----------
    **kwargs
        Passed to :class:`matplotlib.figure.Figure` (``figsize``, ``layout``, ``dpi``, ...).

    Returns
    -------
    matplotlib.figure.Figure
        Save it with ``fig.savefig(path_or_buffer, format="png")``; it is freed with its last
        reference (nothing to close).
    """
    return Figure(**kwargs)


def orthographic_basis(elev: float, azim: float) -> np.ndarray:
    """The screen basis of an orthographic camera looking at the unit sphere.

    Parameters
    ----------
    elev, azim : float
        Elevation and azimuth of the viewer, in degrees (as in matplotlib's 3D ``view_init``).

    Returns
    -------
    ndarray, shape ``(3, 3)``
        Rows ``(right, up, towards the viewer)``, an orthonormal basis of ``R³``.

    Examples
    --------
    >>> B = orthographic_basis(90.0, 0.0)     # looking down the Π3 axis
    >>> bool(np.allclose(B @ B.T, np.eye(3))), bool(np.allclose(B[2], [0, 0, 1]))
    (True, True)
    """
    e, a = np.deg2rad(elev), np.deg2rad(azim)
    d = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    r = np.array([-np.sin(a), np.cos(a), 0.0])
    u = np.array([-np.sin(e) * np.cos(a), -np.sin(e) * np.sin(a), np.cos(e)])
    return np.stack([r, u, d])


def sphere_image(func, elev: float, azim: float, n: int = 400, radius: float = 1.0):
    """Values of a function on the visible hemisphere of a sphere, as an image.

    Pixel ``(u, v)`` of the screen (``u, v ∈ [−1, 1]``) is the point
    ``radius · (u·right + v·up + √(1 − u² − v²)·towards)`` of the sphere (see
    :func:`orthographic_basis`).

    Parameters
    ----------
    func : callable
        ``func(P)`` with ``P`` of shape ``(n, n, 3)`` returns an array of shape ``(n, n)``.
    elev, azim : float
        Camera position in degrees.
    n : int
        Pixels per side.
    radius : float
        Radius of the sphere (the Casimir ``|Π|``).

    Returns
    -------
    u, v : ndarray, shape ``(n,)``
        Screen coordinates of the pixel columns and rows.
    values : ndarray, shape ``(n, n)``
        ``func`` at the pixels (row index ``v``), NaN outside the disk.

    Examples
    --------
    >>> u, v, img = sphere_image(lambda P: P[..., 2], 90.0, 0.0, n=5)
    >>> float(img[2, 2]), bool(np.isnan(img[0, 0]))
    (1.0, True)
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
    """Screen coordinates and depth of points of the sphere for an orthographic camera.

    Parameters
    ----------
    points : array_like, shape ``(..., 3)``
    elev, azim : float
        Camera position in degrees.
    radius : float
        Radius of the sphere.

    Returns
    -------
    u, v, depth : ndarray, shape ``(...)``
        ``depth > 0`` on the visible side.
    """
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


def _whole_sphere_values(func, n=120):
    th = np.linspace(0, np.pi, n)
    ph = np.linspace(0, 2 * np.pi, 2 * n)
    T, P = np.meshgrid(th, ph, indexing="ij")
    pts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    return np.asarray(func(pts), dtype=np.float64)


def plot_sphere_portrait(ax, hfun, *, elev, azim, curves=(), separatrix=(), equilibria=(), title="",
                         cmap="viridis", n=500, contour_levels=None):
    """Phase portrait on the unit sphere seen from a camera: the level sets of a Hamiltonian.

    The visible hemisphere is coloured by ``hfun(Π)`` (colour scale of the whole sphere); the level
    sets are drawn as given (``curves``) or contoured from the image.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        A 2D axes; the sphere fills ``[−1.25, 1.25]²``.
    hfun : callable
        ``hfun(P)``, ``P`` of shape ``(..., 3)`` → ``(...)``, e.g. ``rigid_body(...).modified_hamiltonian``.
    elev, azim : float
        Camera position in degrees.
    curves : sequence of sequences of ndarray ``(m, 3)``, optional
        One entry per level, each a list of polylines on the sphere (e.g. ``LevelSets.curves`` of
        :func:`mechanics.rigid_body_level_sets`).
    separatrix : sequence of bool, optional
        ``separatrix[k]`` marks level ``k`` as a saddle level (drawn thicker, in red).
    equilibria : sequence of ``(point (3,), kind)``
        ``kind`` in ``{"minimum", "maximum", "saddle", "degenerate"}``; visible ones are filled
        markers, those on the hidden side hollow.
    title : str
    cmap : str
    n : int
        Pixels per side of the image.
    contour_levels : array_like, optional
        Levels contoured when no ``curves`` are given (default: 24 equally spaced levels).

    Returns
    -------
    matplotlib.image.AxesImage
        The coloured hemisphere (for a colour bar).

    Examples
    --------
    >>> import mechanics
    >>> h = mechanics.rigid_body((1.0, 2.0, 3.0), sigma=0.05).modified_hamiltonian
    >>> fig = new_figure(figsize=(4, 4))
    >>> im = plot_sphere_portrait(fig.add_subplot(), h, elev=22, azim=35, n=60,
    ...                           equilibria=[(np.array([0.0, 0.0, 1.0]), "minimum")])
    >>> im.get_array().shape
    (60, 60)
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


def projected_density(density_fn, xe, ye, *, axes=(0, 1), hemisphere=1.0, sub=4):
    """A density on the unit sphere, seen in a coordinate plane and averaged over histogram bins.

    A point ``(x, y)`` of the plane ``(Π_a, Π_b)`` lifts to the hemisphere
    ``sign(Π_c) = hemisphere`` with ``|Π_c| = √(1 − x² − y²)``; the area element is
    ``dS = dx dy / |Π_c|``. The density is normalised on that hemisphere (the basin a trajectory
    explores) and averaged over each bin, so it compares with a normalised histogram directly.

    Parameters
    ----------
    density_fn : callable
        ``density_fn(P)``, ``P`` of shape ``(..., 3)``: an unnormalised density on the sphere.
    xe, ye : ndarray
        Bin edges in ``Π_a`` and ``Π_b``.
    axes : tuple of two ints
        The plotted coordinates ``(a, b)``.
    hemisphere : {1.0, -1.0}
        Sign of the remaining coordinate.
    sub : int
        Quadrature midpoints per bin and direction.

    Returns
    -------
    ndarray, shape ``(len(xe) − 1, len(ye) − 1)``
        Bin averages of the projected density (per unit area of the plane).

    Examples
    --------
    The uniform law on the upper hemisphere integrates to one over the unit disk (up to the
    bins cut by the circle, where the projected density has an integrable singularity):

    >>> e = np.linspace(-1.0, 1.0, 41)
    >>> q = projected_density(lambda P: np.ones(P.shape[:-1]), e, e)
    >>> round(float(q.sum() * (e[1] - e[0]) ** 2), 1)
    1.0
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


def plot_density(ax, xy, *, bins, extent, density_fn=None, hemisphere=None, axes=(0, 1), start=None, marks=(),
                 title="", cmap="magma", colorbar=True):
    """Time-density of a projected trajectory, with a predicted density's contours overlaid.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    xy : ndarray, shape ``(M, 2)``
        Samples of the projection ``(Π_a, Π_b)`` (e.g. the saved states of one long path).
    bins : int
        Bins per direction.
    extent : ``((x0, x1), (y0, y1))``
        Histogram range.
    density_fn : callable, optional
        ``density_fn(P)``: an unnormalised density on the unit sphere predicted for the samples
        (e.g. ``GibbsMeasure(...).density``). It is binned like the data by
        :func:`projected_density` and drawn as cyan contours at 10, 30, 50, 70, 90 % of its maximum.
    hemisphere : {1.0, -1.0}, optional
        Sign of the remaining coordinate on which ``density_fn`` is normalised (needed with
        ``density_fn``).
    axes : tuple of two ints
        The coordinates ``(a, b)`` of ``xy`` (axis labels, projection of ``density_fn``).
    start : array_like, shape ``(2,)``, optional
        The initial point, marked by a red dot.
    marks : sequence of ``((x, y), style dict, label)``
        Extra markers (``style`` is passed to ``Axes.plot``).
    title, cmap : str
    colorbar : bool
        Add a colour bar to ``ax.figure``.

    Returns
    -------
    H : ndarray, shape ``(bins, bins)``
        The normalised histogram (per unit area), indexed ``[x bin, y bin]``.
    predicted : ndarray or None
        The binned prediction (same shape), or None without ``density_fn``.
    edges : tuple ``(xe, ye)``
        Bin edges.
    """
    xy = np.asarray(xy, dtype=np.float64)
    (x0, x1), (y0, y1) = extent
    H, xe, ye = np.histogram2d(xy[:, 0], xy[:, 1], bins=bins, range=[[x0, x1], [y0, y1]])
    cell = (xe[1] - xe[0]) * (ye[1] - ye[0])
    H = H / max(len(xy), 1) / cell
    im = ax.imshow(H.T, origin="lower", extent=(x0, x1, y0, y1), cmap=cmap, aspect="equal",
                   interpolation="nearest")
    if colorbar:
        cb = ax.figure.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
        cb.set_label("time density (per unit area)")
    pred = None
    if density_fn is not None:
        if hemisphere is None:
            raise ValueError("hemisphere must be +1.0 or -1.0 when density_fn is given, got None.")
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
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", fontsize=7, framealpha=0.7)
    return H, pred, (xe, ye)


def plot_trajectory_3d(ax, traj, *, start=None, times=None, title="", max_points=30_000):
    """A trajectory on the unit sphere in 3D, coloured by time, over a wireframe sphere.

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
        A 3D axes (``fig.add_subplot(projection="3d")``).
    traj : ndarray, shape ``(K, 3)``
        The states, in time order.
    start : array_like, shape ``(3,)``, optional
        The initial point, marked by a red dot.
    times : ndarray, shape ``(K,)``, optional
        Times of the states (colour scale; default: the index scaled to ``[0, 1]``).
    title : str
    max_points : int
        At most about this many states are drawn (every ``K // max_points``-th one).

    Returns
    -------
    mpl_toolkits.mplot3d.art3d.Line3DCollection
        The coloured line (for a colour bar).

    Examples
    --------
    >>> t = np.linspace(0.0, 6.0, 200)
    >>> traj = np.stack([np.sin(t) * 0.3, np.cos(t) * 0.3, np.full_like(t, np.sqrt(0.91))], axis=-1)
    >>> fig = new_figure()
    >>> lc = plot_trajectory_3d(fig.add_subplot(projection="3d"), traj, start=traj[0], times=t)
    >>> lc.get_array().shape                 # one time value per segment
    (199,)
    """
    traj = np.asarray(traj, dtype=np.float64)
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


def plot_projected_trajectory(ax, traj, times, *, axes=(0, 1), start=None, title="", max_points=40_000,
                              colorbar=True):
    """A trajectory projected on the coordinate plane ``(Π_a, Π_b)``, coloured by time.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    traj : ndarray, shape ``(K, 3)``
    times : ndarray, shape ``(K,)``
    axes : tuple of two ints
        The coordinates ``(a, b)`` drawn.
    start : array_like, shape ``(3,)``, optional
        The initial point, marked by a red dot.
    title : str
    max_points : int
        At most about this many states are drawn.
    colorbar : bool
        Add a colour bar (time) to ``ax.figure``.

    Returns
    -------
    matplotlib.collections.LineCollection
    """
    traj = np.asarray(traj, dtype=np.float64)
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
    if colorbar:
        cb = ax.figure.colorbar(lc, ax=ax, fraction=0.046, pad=0.04)
        cb.set_label("time t")
    ax.set_xlabel(AXIS_LABELS[axes[0]])
    ax.set_ylabel(AXIS_LABELS[axes[1]])
    if title:
        ax.set_title(title, fontsize=10)
    return lc
