"""Figures without pyplot, and the axis labels of the momentum coordinates."""

from __future__ import annotations

from matplotlib.figure import Figure

__all__ = ["AXIS_LABELS", "new_figure"]

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
