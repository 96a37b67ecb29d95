r"""Exact p-variation of rough paths over partitions by grid times.

:func:`p_variation` (trace), :func:`area_p_variation` (area) and :func:`rough_path_p_variation`
(homogeneous). Definitions, tensor norms, rescaling and cost: :mod:`roughpaths.norms`.
"""

from __future__ import annotations

import numpy as np

from ..paths.rough_path import RoughPath
from ..validation import as_float_array, check_memory
from . import _kernels as _k
from ._common import (_DEFAULT_MAX_POINTS, _check_max_points, _check_p, _dilate, _level1_data,
                           _level2_data, _member_scale, _shape)

__all__ = ["p_variation", "area_p_variation", "rough_path_p_variation"]


def _partition_mask(prev: np.ndarray) -> np.ndarray:
    """Boolean mask of the optimal partition's grid points from the DP predecessor table."""
    nb, npts = prev.shape
    mask = np.zeros((nb, npts), dtype=bool)
    for b in range(nb):
        j = npts - 1
        mask[b, j] = True
        while j > 0:
            j = int(prev[b, j])
            mask[b, j] = True
    return mask


def _check_memory(X) -> None:
    """Refuse a trace whose working arrays exceed the memory budget, before any is allocated.

    With ``B`` members, ``n`` grid points and ``d`` dimensions, :func:`p_variation` holds at once, 8 bytes
    per entry: two arrays of increments (B, n - 1, d) (the differences and their rescaled copy), the
    cumulated paths (B, n, d) with the rescaled increments, the predecessor table (B, n) and the values (B);
    the kernel's per-path scratch (values, block and prefix boxes: n + 4 n d + 2 d), and the partition mask
    (B n bytes). Bound: ``8 (2 B n d + B n + B + n + 4 n d + 2 d) + B n``, plus 4 KiB of Python objects.
    """
    if isinstance(X, RoughPath):
        shape = X.increments.shape
        n, d = shape[-2] + 1, shape[-1]
    else:
        shape = X.shape
        n, d = shape[-2], shape[-1]
    B = float(np.prod(shape[:-2], dtype=float))
    n, d = float(n), float(d)
    need = 8.0 * (2 * B * n * d + B * n + B + n + 4 * n * d + 2 * d) + B * n + 4096.0
    check_memory(need, f"the p-variation of {B:.0f} paths of {n:.0f} points in {d:.0f} dimensions "
                       f"(increments, paths and predecessor tables)",
                 "pass fewer paths at a time (slice the leading axes) or fewer points "
                 "(X.restrict(coarser_times) for a RoughPath, X[..., ::k, :] for samples)")


def p_variation(X, p, *, times=None, return_partition=False, prune=True,
                max_points=_DEFAULT_MAX_POINTS):
    r"""Exact p-variation of the trace over partitions by grid points.

    .. math::
        \|X\|_{p\text{-var}} = \Big(\max_{0 = k_0 < k_1 < \dots < k_m = N}
        \sum_{l} |X_{t_{k_{l+1}}} - X_{t_{k_l}}|^p\Big)^{1/p}

    computed exactly (all partitions, not dyadic ones) by the dynamic programme
    :math:`V_j = \max_{i<j} V_i + |X_{t_j} - X_{t_i}|^p`, :math:`V_0 = 0`, answer :math:`V_N^{1/p}`.
    The norm is Euclidean on :math:`\mathbb{R}^d`; the grid times play no role.

    Worst case :math:`O(N^2 d)` per path. With ``prune=True`` (default) candidates ``i`` are
    visited in blocks of 32 from ``j - 1`` backwards, and a block is skipped when
    :math:`V_e + R^p \le` (best so far), where ``e`` is the block's last index and ``R`` the largest
    distance from :math:`X_{t_j}` to the block's bounding box (the scan stops when the same bound
    holds for the box of all points before ``e``). Since :math:`V` is nondecreasing (appending
    one step never lowers the sum), this bound dominates every skipped candidate: pruning does not
    change the result. It helps most for small ``p`` and for paths that wander far.

    Parameters
    ----------
    X : RoughPath or array_like of shape ``(..., n, d)``
        A rough path (trace used) or samples of a path.
    p : float >= 1
    times : array_like, optional
        Only validated (p-variation does not depend on the parametrisation); forbidden with a
        RoughPath.
    return_partition : bool
        Also return a boolean mask of shape ``(..., n)`` marking the grid points of an optimal
        partition (ties broken towards the predecessor met first in the backward scan).
    prune : bool
        Use the branch-and-bound above (exact either way).
    max_points : int or None

    Returns
    -------
    float or ndarray of shape ``(...)`` (and the mask if requested)

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0], [2.0], [1.0], [3.0]])
    >>> float(p_variation(x, 1.0))        # total variation 2 + 1 + 2
    5.0
    >>> round(float(p_variation(x, 3.0)), 12)   # one jump 0 -> 3 beats 2^3 + 1 + 2^3
    3.0
    """
    pp = _check_p(p)
    if not isinstance(X, RoughPath):
        # float64 samples first (no copy for a float64 array; a list's float64 copy is smaller than the list)
        X = as_float_array(X, "X", min_ndim=2)
    _check_memory(X)
    inc, _, batch = _level1_data(X, times, "X", need_times=False)
    _check_max_points(inc.shape[-2] + 1, max_points, "X")
    nb, n, d = inc.shape
    c = _member_scale(inc)
    inc, _ = _dilate(inc, None, c)
    paths = np.zeros((nb, n + 1, d))
    np.cumsum(inc, axis=-2, out=paths[:, 1:, :])
    vals, prev = _k.pvar_level1(paths, pp, bool(prune), 32)
    out = _shape(vals ** (1.0 / pp) * c, batch)
    if return_partition:
        return out, _partition_mask(prev).reshape(batch + (n + 1,))
    return out


def area_p_variation(X, p, *, return_partition=False, max_points=_DEFAULT_MAX_POINTS):
    r"""Exact p/2-variation of the area over partitions by grid points.

    .. math::
        \|\mathbb{X}\|_{p/2\text{-var}} = \Big(\max_{\mathcal P} \sum_{[s,t]\in\mathcal P}
        |\mathbb{X}_{s,t}|_F^{p/2}\Big)^{2/p}

    by dynamic programming over all grid partitions, :math:`O(N^2 d^2)` per path (no pruning:
    the area is not a metric increment). :math:`\mathbb{X}_{s,t}` is the full area (Frobenius
    norm), obtained by Chen's identity.

    Parameters
    ----------
    X : RoughPath (level 2)
    p : float >= 1
        The variation exponent of the trace; the area uses ``p / 2``.
    return_partition : bool
        Also return the mask of an optimal partition, shape ``X.batch_shape + (N + 1,)``.
    max_points : int or None
    """
    pp = _check_p(p)
    inc, areas, t, batch = _level2_data(X, "X")
    _check_max_points(t.size, max_points, "X")
    c = _member_scale(inc, areas)
    inc, areas = _dilate(inc, areas, c)
    vals, prev = _k.pvar_level2(inc, areas, 0.5 * pp)
    out = _shape(vals ** (2.0 / pp) * c * c, batch)
    if return_partition:
        return out, _partition_mask(prev).reshape(batch + (t.size,))
    return out


def rough_path_p_variation(X, p, *, max_points=_DEFAULT_MAX_POINTS):
    r"""Homogeneous p-variation rough-path norm :math:`\|X\|_{p\text{-var}} + \|\mathbb{X}\|_{p/2\text{-var}}^{1/2}`.

    Each of the two terms is an exact supremum over grid partitions (taken separately, each with
    its own optimal partition); see :func:`p_variation` and :func:`area_p_variation`. Euclidean
    norm on level 1, Frobenius on level 2. For a level-2 rough path one usually takes
    :math:`p \in [2, 3)`.

    Returns
    -------
    float or ndarray of shape ``X.batch_shape``

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> X = RoughPath.from_path(np.array([[0.0], [1.0]]))   # XX = ½: ‖X‖ + ‖XX‖^½ = 1 + √½
    >>> round(float(rough_path_p_variation(X, 2.5)), 12)
    1.707106781187
    """
    pp = _check_p(p)
    _level2_data(X, "X")
    lvl1 = p_variation(X, pp, max_points=max_points)
    lvl2 = area_p_variation(X, pp, max_points=max_points)
    return lvl1 + np.sqrt(lvl2)
