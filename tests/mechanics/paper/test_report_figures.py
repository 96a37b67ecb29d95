"""The report's figures do not hide their data: legends placed where no trace can be, panels as wide as
their data (mechanics.paper.plotting).

Oracle: the drawn geometry itself, in display coordinates after a draw (legend boxes against the pixels
of every plotted point), not the helpers' own placement parameters.
"""

from __future__ import annotations

import numpy as np
import pytest

from mechanics.paper.plotting import new_figure, plot_components, plot_density, plot_projected_trajectory


def _rotation_trajectory(n=3000):
    """A path on the unit sphere whose three components each reach +1 and −1 (also at the right edge)."""
    phi = np.linspace(0.0, 2.0 * np.pi, n // 3)
    c, s, z = np.cos(phi), np.sin(phi), np.zeros_like(phi)
    # a great circle in each coordinate plane, one after the other
    traj = np.concatenate([np.stack([c, s, z], -1), np.stack([z, c, s], -1), np.stack([s, z, c], -1)])
    return np.linspace(0.0, 30.0, len(traj)), traj


def test_components_legend_covers_no_point():
    t, traj = _rotation_trajectory()
    assert np.allclose(np.linalg.norm(traj, axis=-1), 1.0)
    assert np.all(traj.max(axis=0) > 0.999) and np.all(traj.min(axis=0) < -0.999)
    fig = new_figure(figsize=(6, 3.5), layout="constrained")
    ax = fig.add_subplot()
    legend = plot_components(ax, t, traj, title="components")
    fig.draw_without_rendering()
    box = legend.get_window_extent()
    for line in ax.get_lines():
        xy = ax.transData.transform(np.column_stack(line.get_data()))
        inside = (xy[:, 0] >= box.x0) & (xy[:, 0] <= box.x1) & (xy[:, 1] >= box.y0) & (xy[:, 1] <= box.y1)
        assert not inside.any(), f"{line.get_label()}: {inside.sum()} points under the legend"
    # and the legend is inside the panel, above the top of the data
    frame = ax.get_window_extent()
    assert frame.y0 <= box.y0 and box.y1 <= frame.y1 + 1
    assert box.y0 >= ax.transData.transform((0.0, 1.0))[1]


def test_components_legend_would_be_caught_where_it_covers_data():
    """The check above can fail: the same geometry test flags a legend put over the traces."""
    t, traj = _rotation_trajectory()
    fig = new_figure(figsize=(6, 3.5), layout="constrained")
    ax = fig.add_subplot()
    plot_components(ax, t, traj)
    legend = ax.legend(loc="lower right", ncol=3)          # where the report had it before
    fig.draw_without_rendering()
    box = legend.get_window_extent()
    covered = 0
    for line in ax.get_lines()[:3]:
        xy = ax.transData.transform(np.column_stack(line.get_data()))
        covered += int(((xy[:, 0] >= box.x0) & (xy[:, 0] <= box.x1)
                        & (xy[:, 1] >= box.y0) & (xy[:, 1] <= box.y1)).sum())
    assert covered > 0


@pytest.mark.parametrize("times, traj, match", [
    (np.zeros(4), np.zeros((4, 2)), "traj must have shape"),
    (np.zeros(3), np.zeros((4, 3)), "traj must have shape"),
    (np.zeros(2), np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.5]]), "leaves \\[-1, 1\\]"),
])
def test_components_refuses_what_is_not_a_unit_sphere_trajectory(times, traj, match):
    ax = new_figure().add_subplot()
    with pytest.raises(ValueError, match=match):
        plot_components(ax, times, traj)


def test_density_legend_below_the_panel(rng):
    xy = rng.uniform(-1.0, 1.0, size=(5000, 2))          # data all over the panel, corners included
    fig = new_figure(figsize=(5, 5.5), layout="constrained")
    ax = fig.add_subplot()
    plot_density(ax, xy, bins=30, extent=((-1.1, 1.1), (-1.1, 1.1)), start=(0.0, 1.0), legend="below",
                 marks=[((0.0, 0.0), dict(marker="D", mfc="none", mec="cyan"), "centre")])
    fig.draw_without_rendering()
    legend, frame = ax.get_legend().get_window_extent(), ax.get_window_extent()
    assert legend.y1 <= frame.y0, "the legend overlaps the density panel"
    # it is not cut off by the figure either
    canvas = fig.bbox
    assert canvas.x0 <= legend.x0 and legend.x1 <= canvas.x1 and legend.y0 >= canvas.y0
    with pytest.raises(TypeError, match="legend must be a location string"):
        plot_density(ax, xy, bins=5, extent=((-1, 1), (-1, 1)), legend=1)


def test_projected_trajectory_panel_is_as_wide_as_its_data():
    """A tall cloud in a wide panel: the frame takes the data's shape (equal scales), no empty half panel."""
    t = np.linspace(0.0, 200.0, 4000)
    x, y = 0.1 * np.sin(1.3 * t), 0.3 * np.sin(0.7 * t)
    traj = np.stack([x, y, np.sqrt(1.0 - x**2 - y**2)], axis=-1)
    fig = new_figure(figsize=(8, 4), layout="constrained")
    ax = fig.add_subplot()
    plot_projected_trajectory(ax, traj, t, start=traj[0], colorbar=False)
    fig.draw_without_rendering()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x1 - x0 <= 1.15 * np.ptp(x) and y1 - y0 <= 1.15 * np.ptp(y)
    # equal scales: the frame's aspect is the data's
    frame = ax.get_window_extent()
    assert frame.width / frame.height == pytest.approx((x1 - x0) / (y1 - y0), rel=0.02)
