r"""The momentum sphere seen from a camera: orthographic geometry and the phase portrait.

:func:`plot_sphere_portrait` draws the level sets of a function on the sphere (e.g. the modified
Hamiltonian ``h̃``) with curves and equilibria; :func:`orthographic_basis`, :func:`sphere_image` and
:func:`project` are its geometry.
"""

from __future__ import annotations

import numpy as np

from .figure import AXIS_LABELS

__all__ = ["orthographic_basis", "sphere_image", "project", "plot_sphere_portrait"]


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
    >>> from mechanics.paper.plotting import new_figure
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
