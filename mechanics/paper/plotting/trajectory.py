r"""Trajectories on the momentum sphere: in 3D and projected on a coordinate plane, coloured by time, and
their components against time."""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from .figure import AXIS_LABELS

__all__ = ["plot_trajectory_3d", "plot_projected_trajectory", "plot_components"]


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
    >>> from mechanics.paper.plotting import new_figure
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
    ax.set_aspect("equal", adjustable="box")    # the frame takes the data's shape (no empty half panel)
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


def plot_components(ax, times, traj, *, title="", max_points=20_000, colors=("tab:blue", "tab:orange", "tab:green")):
    """The three components of a trajectory on the unit sphere against time.

    The components of a point of the unit sphere lie in ``[−1, 1]``; the legend sits in a band above
    that range (the axis runs to 1.45), where no trace can be, so it never covers one.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    times : ndarray, shape ``(K,)``
    traj : ndarray, shape ``(K, 3)``
        States on the unit sphere ``|Π| = 1``.
    title : str
    max_points : int
        At most about this many states are drawn per component.
    colors : sequence of three colours

    Returns
    -------
    matplotlib.legend.Legend

    Raises
    ------
    ValueError
        ``traj`` is not of shape ``(K, 3)`` with ``K = len(times)``, or leaves ``[−1, 1]`` by more than
        round-off (not a trajectory on the unit sphere: the band would not be free).

    Examples
    --------
    >>> t = np.linspace(0.0, 6.0, 200)
    >>> traj = np.stack([np.sin(t), np.cos(t), np.zeros_like(t)], axis=-1)
    >>> from mechanics.paper.plotting import new_figure
    >>> fig = new_figure()
    >>> leg = plot_components(fig.add_subplot(), t, traj)
    >>> len(leg.get_texts()), tuple(float(y) for y in fig.axes[0].get_ylim())
    (3, (-1.08, 1.45))
    """
    traj = np.asarray(traj, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    if traj.ndim != 2 or traj.shape[1] != 3 or traj.shape[0] != times.shape[0]:
        raise ValueError(f"traj must have shape (len(times), 3) = ({times.shape[0]}, 3), got {traj.shape}: pass "
                         f"the states of one trajectory, one row per time.")
    if traj.size and not np.all(np.abs(traj) <= 1.0 + 1e-6):
        raise ValueError(f"traj leaves [-1, 1] (max |component| = {np.nanmax(np.abs(traj)):.6g}): plot_components "
                         f"draws trajectories on the unit sphere; normalise them by their Casimir |Π| first.")
    step = max(len(times) // max_points, 1)
    for k, col in enumerate(colors):
        ax.plot(times[::step], traj[::step, k], color=col, lw=0.6, label=AXIS_LABELS[k])
    ax.set_xlabel("time t")
    ax.set_ylabel("components of Π")
    ax.set_ylim(-1.08, 1.45)
    ax.set_yticks([-1.0, -0.5, 0.0, 0.5, 1.0])
    ax.axhline(1.0, color="0.85", lw=0.6, zorder=0)
    if title:
        ax.set_title(title, fontsize=9)
    # the band (1.05, 1.45] of the axis holds the legend: anchored at the top, one row
    return ax.legend(loc="upper center", bbox_to_anchor=(0.5, 1.0), fontsize=8, ncol=3, frameon=False,
                     borderaxespad=0.3, handlelength=1.5)
