r"""Time-densities of projected trajectories against a predicted density on the sphere.

:func:`plot_density` bins a projected trajectory and overlays the contours of a predicted density
(e.g. the Gibbs measure), binned the same way by :func:`projected_density`.
"""

from __future__ import annotations

import numpy as np

from .figure import AXIS_LABELS

__all__ = ["projected_density", "plot_density"]


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
                 title="", cmap="magma", colorbar=True, legend="upper left"):
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
    legend : str or None
        Where the legend goes: a location inside the panel as matplotlib names them
        (``"upper left"``, ...), ``"below"`` (under the panel, one row: it covers nothing), or None.

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
    if legend is not None and not isinstance(legend, str):
        raise TypeError(f"legend must be a location string, 'below' or None, got {type(legend).__name__}.")
    handles = ax.get_legend_handles_labels()[0]
    if handles and legend == "below":
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), fontsize=7, ncol=len(handles), frameon=False,
                  borderaxespad=0.0, columnspacing=1.2, handletextpad=0.4)
    elif handles and legend is not None:
        ax.legend(loc=legend, fontsize=7, framealpha=0.7)
    return H, pred, (xe, ye)
