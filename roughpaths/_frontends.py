"""What the framework front ends :mod:`roughpaths.torch` and :mod:`roughpaths.jax` share (private), and the
check of ``time_augment``'s times that they and the numpy function make alike.

Both wrap a numpy map that is batched over leading axes: the inputs' batch axes are broadcast against
each other before the call, and each input's cotangent is summed back over the axes broadcasting added
or stretched. numpy only: importing this module imports neither framework.
"""

from __future__ import annotations

import numpy as np

__all__ = ["batch_broadcast", "batch_shape", "sum_to", "check_times_batch", "rounded"]

_F32_MAX = float(np.finfo(np.float32).max)


def batch_shape(shapes: list, core: tuple, names: tuple) -> tuple:
    """The broadcast batch shape of inputs of ``shapes`` (``core[i]`` trailing axes of input ``i`` are not batch
    axes), or a ``ValueError`` naming the inputs, their shapes and the fix."""
    for shape, c, name in zip(shapes, core, names):
        if len(shape) < c:
            raise ValueError(f"{name} must have at least {c} axes, got shape {tuple(shape)}; add the missing axes "
                             f"(e.g. {name}[None]).")
    batches = [tuple(s[:len(s) - c]) for s, c in zip(shapes, core)]
    try:
        return tuple(np.broadcast_shapes(*batches))
    except ValueError:
        listed = ", ".join(f"{n} {b}" for n, b in zip(names, batches))
        raise ValueError(f"the batch axes of {listed} do not broadcast (shapes "
                         f"{', '.join(str(tuple(s)) for s in shapes)}); give them equal leading axes (or size 1 where "
                         f"one is shared).") from None


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


def check_times_batch(t_shape: tuple, x_shape: tuple) -> None:
    """Refuse ``time_augment`` times of shape ``t_shape`` whose batch axes do not broadcast to the points of
    paths of shape ``x_shape`` (numpy, torch and JAX alike: the shapes are static, so also under ``jit``)."""
    try:
        ok = np.broadcast_shapes(x_shape[:-1], t_shape) == x_shape[:-1]
    except ValueError:
        ok = False
    if not ok:
        raise ValueError(f"times of shape {t_shape} does not broadcast to the points of paths (shape {x_shape}, points "
                         f"{x_shape[:-1]}); pass times of shape (n,) or (..., n) with the batch axes of paths.")


def rounded(a, dtype, what: str, names: tuple, fix: str) -> np.ndarray:
    """The float64 result ``a`` (finite: the numpy API refuses an overflow of float64) as an array of ``dtype``; a
    float32 one that left float32's range (finite beyond 3.4e38, rounded to inf) is refused with a ``ValueError``
    naming ``what``, the inputs ``names``, the dtype and the fix (``fix``: how to pass float64 in the framework).

    The check is one float64 sum of the float32 result (inf or NaN if an entry is inf): the size of the result, not
    of the work that made it.
    """
    if np.dtype(dtype) != np.float32:
        return np.asarray(a, dtype=dtype)
    with np.errstate(over="ignore", invalid="ignore"):        # an overflow is refused below, with its fix
        out = np.asarray(a, dtype=np.float32)
        if not out.size or np.isfinite(np.add.reduce(out, axis=None, dtype=np.float64)):
            return out
    top = float(np.max(np.abs(np.asarray(a, dtype=np.float64))))
    inputs = " and ".join(names)
    raise ValueError(f"{what} overflows float32, the dtype of {inputs}: it is finite in float64 (values up to "
                     f"{top:.3g} in absolute value) but float32 holds at most {_F32_MAX:.3g}, so it would be returned "
                     f"as inf. Rescale {inputs} (e.g. divide the paths by their length or standard deviation: level k "
                     f"of a signature scales by c**k when the paths do by c), or pass float64 ({fix}).")
