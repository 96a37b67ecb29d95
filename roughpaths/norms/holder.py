r"""Hölder seminorms of rough paths over every pair of grid times, and the inhomogeneous distance.

:func:`holder_seminorm` (trace), :func:`area_holder_seminorm` (area), :func:`rough_path_holder_norm`
(homogeneous) and :func:`holder_distance` (inhomogeneous :math:`\rho_\alpha`). Definitions, tensor
norms, rescaling and cost: :mod:`roughpaths.norms`.
"""

from __future__ import annotations

import numpy as np

from . import _kernels as _k
from ._common import (_DEFAULT_MAX_POINTS, _check_alpha, _check_max_points, _dilate, _dummy_areas,
                           _lag_weights, _level1_data, _level2_data, _member_scale, _shape, _time_scale)
from ..validation import check_same_batch

__all__ = ["holder_seminorm", "area_holder_seminorm", "rough_path_holder_norm", "holder_distance"]


def holder_seminorm(X, alpha, *, times=None, prune=True, max_points=_DEFAULT_MAX_POINTS):
    r"""α-Hölder seminorm of the trace over all grid pairs, :math:`\sup_{s<t} |X_{s,t}|/(t-s)^\alpha`.

    Parameters
    ----------
    X : RoughPath or array_like of shape ``(..., n, d)``
        A rough path (its trace is used; the area is ignored), or samples of a path.
    alpha : float in (0, 1]
        Hölder exponent.
    times : array_like, shape ``(n,)``
        Sample times; required when ``X`` is an array, forbidden when it is a RoughPath.
    prune : bool
        Branch-and-bound (exact either way): for each start ``s``, end points are visited in
        blocks of 32 and a block is skipped when (largest distance from :math:`X_s` to the
        block's bounding box)² / (first gap)^{2α} cannot beat the best quotient so far; the scan
        stops when the same bound holds for the box of all later points. Worst case
        :math:`O(n^2 d)`, typically far less.
    max_points : int or None
        Refuse paths with more grid points (cost is :math:`O(n^2 d)`); None lifts the limit.

    Returns
    -------
    float or ndarray of shape ``(...)``
        Euclidean norm on :math:`\mathbb{R}^d`.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 4.0, 9)
    >>> float(holder_seminorm(np.outer(t, [3.0, 4.0]), 0.5, times=t))   # |v| T^(1-α) = 5·2
    10.0
    """
    a = _check_alpha(alpha)
    inc, t, batch = _level1_data(X, times, "X", need_times=True)
    _check_max_points(t.size, max_points, "X")
    nb, n, d = inc.shape
    c = _member_scale(inc)
    inc, _ = _dilate(inc, None, c)
    t, tau = _time_scale(t)
    if prune:
        paths = np.zeros((nb, n + 1, d))
        np.cumsum(inc, axis=-2, out=paths[:, 1:, :])
        s1 = _k.holder_level1_pruned(paths, t, a, 32)
    else:
        s1, _ = _k.holder_sups(inc, _dummy_areas(d), inc, _dummy_areas(d), t, a, False, False, _lag_weights(t, a))
    return _shape(np.sqrt(s1) * c * tau ** -a, batch)


def area_holder_seminorm(X, alpha, *, max_points=_DEFAULT_MAX_POINTS):
    r"""2α-Hölder seminorm of the area, :math:`\sup_{s<t} |\mathbb{X}_{s,t}|_F/(t-s)^{2\alpha}`.

    Parameters
    ----------
    X : RoughPath (level 2)
    alpha : float in (0, 1]
        The exponent of the trace; the area is measured with :math:`2\alpha`.
    max_points : int or None
        Refuse paths with more grid points (cost :math:`O(n^2 d^2)`); None lifts the limit.

    Returns
    -------
    float or ndarray of shape ``X.batch_shape``
        Frobenius norm of the full area :math:`\mathbb{X}` (symmetric part included), obtained
        over each pair by Chen's identity.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), times=[0.0, 1.0, 2.0])
    >>> float(area_holder_seminorm(X, 0.5))   # |XX_{0,2}| / 2 = |[[.5, 1], [0, .5]]|_F / 2
    0.6123724356957945
    """
    a = _check_alpha(alpha)
    inc, areas, t, batch = _level2_data(X, "X")
    _check_max_points(t.size, max_points, "X")
    c = _member_scale(inc, areas)
    inc, areas = _dilate(inc, areas, c)
    t, tau = _time_scale(t)
    _, s2 = _k.holder_sups(inc, areas, inc, areas, t, a, True, False, _lag_weights(t, a))
    return _shape(np.sqrt(s2) * c * c * tau ** (-2.0 * a), batch)


def rough_path_holder_norm(X, alpha, *, max_points=_DEFAULT_MAX_POINTS):
    r"""Homogeneous α-Hölder rough-path norm :math:`\|X\|_\alpha + \|\mathbb{X}\|_{2\alpha}^{1/2}`.

    Euclidean norm on level 1, Frobenius on level 2; both suprema over all grid pairs (one
    :math:`O(n^2 d^2)` pass). See :func:`holder_seminorm` and :func:`area_holder_seminorm`.

    Returns
    -------
    float or ndarray of shape ``X.batch_shape``
    """
    a = _check_alpha(alpha)
    inc, areas, t, batch = _level2_data(X, "X")
    _check_max_points(t.size, max_points, "X")
    c = _member_scale(inc, areas)
    inc, areas = _dilate(inc, areas, c)
    t, tau = _time_scale(t)
    s1, s2 = _k.holder_sups(inc, areas, inc, areas, t, a, True, False, _lag_weights(t, a))
    return _shape((np.sqrt(s1) + s2 ** 0.25) * c * tau ** -a, batch)


def holder_distance(X, Y, alpha, *, max_points=_DEFAULT_MAX_POINTS):
    r"""Inhomogeneous α-Hölder rough-path distance between two rough paths on the same grid.

    .. math::
        \rho_\alpha(X, Y) = \sup_{s<t}\frac{|X_{s,t} - Y_{s,t}|}{(t-s)^\alpha}
        + \sup_{s<t}\frac{|\mathbb{X}_{s,t} - \mathbb{Y}_{s,t}|_F}{(t-s)^{2\alpha}}

    over all grid pairs (Euclidean norm on level 1, Frobenius on level 2). Both areas are
    accumulated by Chen's identity pair by pair, in one :math:`O(n^2 d^2)` pass.

    Parameters
    ----------
    X, Y : RoughPath (level 2)
        Same grid (to round-off) and dimension; batch shapes must broadcast.
    alpha : float in (0, 1]
    max_points : int or None

    Returns
    -------
    float or ndarray of the broadcast batch shape

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), times=[0.0, 1.0, 2.0])
    >>> s = np.array([[0.0, 1.0], [-1.0, 0.0]])
    >>> round(float(holder_distance(X, X.perturb(s), 0.25)), 12)   # |s|_F · T^(1 - 2α) = √2 · √2
    2.0
    """
    a = _check_alpha(alpha)
    ix, ax, tx, bx = _level2_data(X, "X")
    iy, ay, ty, by = _level2_data(Y, "Y")
    if X.dim != Y.dim:
        raise ValueError(f"X and Y must have the same dimension, got X.dim={X.dim} and Y.dim={Y.dim}.")
    if tx.shape != ty.shape or not np.allclose(tx, ty, rtol=1e-12, atol=1e-12 * max(1.0, float(np.max(np.abs(tx))))):
        raise ValueError(f"X and Y must live on the same time grid, got X.times with {tx.size} points "
                         f"on [{tx[0]:g}, {tx[-1]:g}] and Y.times with {ty.size} points on "
                         f"[{ty[0]:g}, {ty[-1]:g}]; restrict both to a common grid first "
                         f"(X.restrict(times), Y.restrict(times)).")
    batch = check_same_batch(bx, by, "X", "Y")
    _check_max_points(tx.size, max_points, "X")
    n, d = X.n_steps, X.dim

    def full(z, shape_b, tail):
        z = z.reshape(shape_b + tail)
        return np.ascontiguousarray(np.broadcast_to(z, batch + tail).reshape((-1,) + tail))

    ix, iy = full(ix, bx, (n, d)), full(iy, by, (n, d))
    ax, ay = full(ax, bx, (n, d, d)), full(ay, by, (n, d, d))
    c = np.maximum(_member_scale(ix, ax), _member_scale(iy, ay))      # one dilation for both paths
    ix, ax = _dilate(ix, ax, c)
    iy, ay = _dilate(iy, ay, c)
    tx, tau = _time_scale(tx)
    s1, s2 = _k.holder_sups(ix, ax, iy, ay, tx, a, True, True, _lag_weights(tx, a))
    return _shape(np.sqrt(s1) * c * tau ** -a + np.sqrt(s2) * c * c * tau ** (-2.0 * a), batch)
