"""Shared checks, data extraction and exact power-of-two rescaling of the norms (private).

Used by :mod:`roughpaths.norms.holder` and :mod:`roughpaths.norms.p_variation`; see :mod:`roughpaths.norms` for
the definitions, the tensor norms and why every quantity is computed on a rescaled copy.
"""

from __future__ import annotations

import numbers

import numpy as np

from ..validation import as_float_array, check_times
from ..paths.rough_path import RoughPath

#: Default ``max_points``: paths with more grid points are refused (cost O(n²) pairs).
_DEFAULT_MAX_POINTS = 100_001


# ---------------------------------------------------------------------------------- validation
def _check_real(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r} of type {type(value).__name__}.")
    v = float(value)
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}.")
    return v


def _check_alpha(alpha) -> float:
    a = _check_real(alpha, "alpha")
    if not 0.0 < a <= 1.0:
        raise ValueError(f"alpha must lie in (0, 1], got alpha={alpha!r}; rough paths of level 2 "
                         f"typically use alpha in (1/3, 1/2].")
    return a


def _check_p(p) -> float:
    v = _check_real(p, "p")
    if v < 1.0:
        raise ValueError(f"p must be >= 1 (p-variation with p < 1 is infinite or trivial for "
                         f"non-constant continuous paths), got p={p!r}.")
    return v


def _check_max_points(n_points: int, max_points, name: str) -> None:
    if max_points is None:
        return
    if isinstance(max_points, bool) or not isinstance(max_points, numbers.Integral) or max_points < 2:
        raise ValueError(f"max_points must be an integer >= 2 or None, got {max_points!r}.")
    if n_points > max_points:
        raise ValueError(
            f"{name} has {n_points} grid points, more than max_points={max_points}; the exact norm "
            f"costs O(n^2) = {float(n_points) ** 2 / 2:.2g} pair evaluations per path. Pass "
            f"max_points=None to compute it anyway, or pass {name}.restrict(coarser_times) to "
            f"compute the (smaller) norm of a coarsened path.")


def _level1_data(X, times, name: str, *, need_times: bool):
    """Return ``(increments (B, N, d), times (N + 1,), batch_shape)`` for a RoughPath or an array."""
    if isinstance(X, RoughPath):
        if times is not None:
            raise ValueError(f"times must not be given when {name} is a RoughPath (its grid "
                             f"{name}.times is used); drop the times argument.")
        inc, t = X.increments, X.times
    else:
        v = as_float_array(X, name, min_ndim=2)
        if v.shape[-2] < 2:
            raise ValueError(f"{name} needs at least 2 samples along axis -2 (shape (..., n, d)), "
                             f"got shape {v.shape}.")
        if times is None:
            if need_times:
                raise ValueError(f"times is required when {name} is an array of samples (shape "
                                 f"(..., n, d)): the Hölder quotient depends on the time grid; pass "
                                 f"times=<array of shape ({v.shape[-2]},)>.")
            t = np.linspace(0.0, 1.0, v.shape[-2])
        else:
            t = check_times(times, "times", n=v.shape[-2])
        inc = np.diff(v, axis=-2)
    batch = inc.shape[:-2]
    return np.ascontiguousarray(inc.reshape((-1,) + inc.shape[-2:])), t, batch


def _level2_data(X, name: str):
    if not isinstance(X, RoughPath):
        raise TypeError(f"{name} must be a RoughPath (level 2) for an area norm, got "
                        f"{type(X).__name__}; build one with RoughPath.from_path(values, times=...) "
                        f"or from increments and areas.")
    if X.level != 2:
        raise ValueError(f"{name} is a level-1 path (no area); area norms need a level-2 rough "
                         f"path, e.g. RoughPath.from_path(values) or a Brownian lift.")
    inc = np.ascontiguousarray(X.increments.reshape((-1,) + X.increments.shape[-2:]))
    areas = np.ascontiguousarray(X.areas.reshape((-1,) + X.areas.shape[-3:]))
    return inc, areas, X.times, X.batch_shape


def _shape(values: np.ndarray, batch: tuple):
    out = values.reshape(batch)
    return out[()] if out.ndim == 0 else out


def _dummy_areas(d: int) -> np.ndarray:
    return np.zeros((1, 1, d, d))


def _pow2(x: np.ndarray) -> np.ndarray:
    """A power of two within a factor 2 of each positive ``x`` (1 where ``x`` is 0): exact to divide by."""
    _, e = np.frexp(x)
    return np.where(x > 0, np.ldexp(1.0, e), 1.0)


def _member_scale(inc: np.ndarray, areas: np.ndarray | None = None) -> np.ndarray:
    """Per-member dilation ``c`` (shape ``(B,)``) bringing increments (and areas / c²) near unit size."""
    big = np.max(np.abs(inc), axis=(-2, -1), initial=0.0)
    if areas is not None:
        big = np.maximum(big, np.sqrt(np.max(np.abs(areas), axis=(-3, -2, -1), initial=0.0)))
    return _pow2(big)


def _dilate(inc: np.ndarray, areas: np.ndarray | None, c: np.ndarray):
    """Increments / c and areas / c² per member (exact: c is a power of two)."""
    inc = inc / c[:, None, None]
    if areas is not None:
        cc = c[:, None, None, None]
        areas = areas / cc / cc
    return np.ascontiguousarray(inc), None if areas is None else np.ascontiguousarray(areas)


def _time_scale(t: np.ndarray):
    """``(t / τ, τ)`` with τ a power of two near the grid length if that lies outside [2⁻⁶⁴, 2⁶⁴], else (t, 1)."""
    span = float(t[-1] - t[0])
    if 2.0 ** -64 <= span <= 2.0 ** 64:
        return t, 1.0
    tau = float(_pow2(np.array(span)))
    return t / tau, tau


def _lag_weights(t: np.ndarray, alpha: float) -> np.ndarray:
    """``(t_k - t_0)^{2α}`` if the grid is uniform to round-off (then ``t_j - t_i = t_{j-i} - t_0``), else empty."""
    dt = np.diff(t)
    if np.max(np.abs(dt - dt[0])) <= 1e-12 * dt[0] * t.size:
        h = (t[-1] - t[0]) / (t.size - 1)
        return (h * np.arange(t.size)) ** (2.0 * alpha)
    return np.zeros(0)
