"""What the framework front ends :mod:`roughpaths.torch` and :mod:`roughpaths.jax` share (private).

Both wrap a numpy map that is batched over leading axes: the inputs' batch axes are broadcast against
each other before the call, and each input's cotangent is summed back over the axes broadcasting added
or stretched. numpy only: importing this module imports neither framework.
"""

from __future__ import annotations

import numpy as np

__all__ = ["batch_broadcast", "sum_to"]


def batch_broadcast(arrays: list, core: tuple) -> list:
    """Broadcast the leading (batch) axes of several inputs; ``core[i]`` trailing axes of input ``i`` are kept."""
    if len(arrays) == 1:
        return arrays
    batch = np.broadcast_shapes(*(a.shape[:a.ndim - c] for a, c in zip(arrays, core)))
    return [np.broadcast_to(a, batch + a.shape[a.ndim - c:]) for a, c in zip(arrays, core)]


def sum_to(g: np.ndarray, shape: tuple) -> np.ndarray:
    """Sum a cotangent over the axes that broadcasting added or stretched, back to ``shape``."""
    if g.shape == shape:
        return g
    g = g.sum(axis=tuple(range(g.ndim - len(shape))))
    axes = tuple(k for k, (a, b) in enumerate(zip(shape, g.shape)) if a == 1 and b != 1)
    return g.sum(axis=axes, keepdims=True) if axes else g
