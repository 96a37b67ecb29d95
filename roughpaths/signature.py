r"""Signatures and log-signatures of piecewise-linear paths and of level-2 geometric rough paths.

Output layouts (see :mod:`roughpaths.tensor_algebra`):

* :func:`signature` — flat, levels ``1..depth`` concatenated, row-major words, no leading 1:
  the layout of ``iisignature.sig(path, depth)`` (and of ``esig.stream2sig`` minus its 1).
  Level 2 ``[i, j]`` is the area :math:`\int (X^i - X^i_s)\,dX^j` of ``docs/conventions.md``.
* :func:`logsignature` — coordinates in the Lyndon basis (standard bracketing, ordered by
  length then lexicographically; :func:`roughpaths.tensor_algebra.lyndon_basis` names them),
  the coordinates of ``iisignature.logsig(path, iisignature.prepare(d, depth))``. Level-2
  coordinate of ``[i,j]`` (``i < j``) is the Lévy area :math:`\tfrac12(\mathbb{X}^{ij} - \mathbb{X}^{ji})`.

Kernels are numba-compiled and cached (:mod:`roughpaths._signature_kernels`): level 2 is a fused
one-pass kernel (increment and shoelace Lévy area), depth >= 3 a Horner–Chen update per segment.
"""

from __future__ import annotations

import numba
import numpy as np

from . import _signature_kernels as _k
from ._validation import as_float_array, check_positive_int
from .tensor_algebra import (_reversed_to_rowmajor, lyndon_coordinates, logsigdim, sigdim,
                             tensor_log)

__all__ = ["signature", "logsignature", "rough_path_signature"]

# Cut a long path into parallel chunks (glued by Chen) only when the batch cannot feed the
# threads and the path is long enough for the split to pay.
_CHUNK_MIN_POINTS_L2 = 50_000
_CHUNK_MIN_POINTS = 5_000


def _offsets(dim: int, depth: int) -> np.ndarray:
    off = np.zeros(depth + 2, dtype=np.int64)
    for k in range(1, depth + 1):
        off[k + 1] = off[k] + dim ** k
    return off


def _n_chunks(batch: int, n: int, min_points: int) -> int:
    threads = numba.get_num_threads()
    if threads <= 1 or batch >= threads or n < min_points:
        return 1
    return max(1, min(threads // max(batch, 1), n // (min_points // 2)))


def _check_depth(depth) -> int:
    return check_positive_int(depth, "depth")


def _check_paths(paths) -> np.ndarray:
    x = as_float_array(paths, "paths", min_ndim=2)
    if x.shape[-2] < 1:
        raise ValueError(f"paths needs at least one point along axis -2 (shape (..., n, d)), got shape "
                         f"{x.shape}.")
    if x.shape[-1] < 1:
        raise ValueError(f"paths needs at least one coordinate along the last axis (shape (..., n, d)), "
                         f"got shape {x.shape}.")
    return x


def _signature_flat(x: np.ndarray, depth: int) -> np.ndarray:
    """Signatures of a validated ``(B, n, d)`` C-contiguous batch, shape ``(B, sigdim)``."""
    nb, n, d = x.shape
    if nb == 0 or n == 1:
        return np.zeros((nb, sigdim(d, depth)))
    if depth == 1:
        return x[:, -1, :] - x[:, 0, :]
    if depth == 2:
        return _k.sig2_kernel(x, _n_chunks(nb, n, _CHUNK_MIN_POINTS_L2))
    out = _k.sig_kernel(x, depth, _offsets(d, depth), _n_chunks(nb, n, _CHUNK_MIN_POINTS))
    return out[:, _reversed_to_rowmajor(d, depth)]


def signature(paths, depth: int) -> np.ndarray:
    r"""Truncated signature of piecewise-linear paths, in ``iisignature.sig``'s layout.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
        ``n >= 1`` points of each path in :math:`\mathbb{R}^d` (linearly interpolated); leading
        axes are batch axes. A single point (``n = 1``) has the zero signature.
    depth : int
        Truncation level ``m >= 1``.

    Returns
    -------
    ndarray, shape ``(..., d + d**2 + ... + d**m)``
        Levels ``1..m`` concatenated (no leading 1), words row-major; level 2 ``[i, j]`` is the area
        :math:`\int (X^i_r - X^i_0)\,dX^j_r`.

    Examples
    --------
    >>> import numpy as np
    >>> signature(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 2)   # the L-shaped path
    array([1. , 1. , 0.5, 1. , 0. , 0.5])
    """
    depth = _check_depth(depth)
    x = _check_paths(paths)
    batch, (n, d) = x.shape[:-2], x.shape[-2:]
    flat = np.ascontiguousarray(x.reshape((-1, n, d)))
    return _signature_flat(flat, depth).reshape(batch + (sigdim(d, depth),))


def logsignature(paths, depth: int) -> np.ndarray:
    r"""Log-signature of piecewise-linear paths in the Lyndon basis (``iisignature.logsig`` coordinates).

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
    depth : int
        Truncation level ``m >= 1``.

    Returns
    -------
    ndarray, shape ``(..., logsigdim(d, m))``
        Coordinates ``c`` with :math:`\log S(X) = \sum_w c_w P(w)` over Lyndon words ``w``, basis
        :func:`roughpaths.tensor_algebra.lyndon_basis` (e.g. ``'1', '2', '[1,2]', ...``). The
        ``[i,j]`` coordinate is the Lévy area :math:`\tfrac12(\mathbb{X}^{ij} - \mathbb{X}^{ji})`
        (with the ½). For the expanded (tensor) log use
        ``tensor_log(signature(paths, m), d)``.

    Examples
    --------
    >>> import numpy as np
    >>> logsignature(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 2)   # x = (1, 1), Lévy area ½
    array([1. , 1. , 0.5])
    """
    depth = _check_depth(depth)
    x = _check_paths(paths)
    d = x.shape[-1]
    if depth == 1 or d == 1:
        # d = 1: the free Lie algebra is R (a path's log-signature is its increment).
        return signature(x, 1)[..., :logsigdim(d, depth)]
    return lyndon_coordinates(tensor_log(signature(x, depth), d), d)


def rough_path_signature(X, depth: int) -> np.ndarray:
    r"""Depth-``m`` signature of a level-2 geometric :class:`~roughpaths.RoughPath` over its whole grid.

    This is the canonical (minimal) extension of a geometric level-2 rough path to level ``m``
    (Lyons' extension theorem): on each grid step the rough path is replaced by the geodesic
    :math:`\exp(X_k + A_k)`, ``A_k`` the step Lévy area :math:`\tfrac12(\mathbb{X}_k - \mathbb{X}_k^T)`,
    and the steps are multiplied by Chen,

    .. math:: S^{(m)}(\mathbf{X})_{t_0, t_N} = \prod_{k=0}^{N-1} \exp(X_{t_k, t_{k+1}} + A_{t_k, t_{k+1}}).

    Levels 1 and 2 of the result are exactly ``X.increment(t0, tN)`` and ``X.area(t0, tN)``;
    the higher levels are the iterated integrals one uses, e.g., to lift a Brownian (Stratonovich)
    rough path to level 3 and beyond (for a Brownian lift on a grid they are the minimal extension
    of the sampled level-2 data, not the iterated integrals of the Brownian path itself, which need
    information between grid points). For a piecewise-linear lift it equals :func:`signature` of the
    path.

    Parameters
    ----------
    X : RoughPath
        Level 2, ``kind == "geometric"`` (an Itô or general area has no geometric extension:
        convert an Itô lift first, ``XX^Strat = XX^Itô + ½(t - s) I``).
    depth : int
        Truncation level ``m >= 1``.

    Returns
    -------
    ndarray, shape ``(*X.batch_shape, sigdim(d, m))``
        In :func:`signature`'s layout.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    >>> bool(np.allclose(rough_path_signature(RoughPath.from_path(pts), 3), signature(pts, 3)))
    True
    """
    from .rough_path import RoughPath

    if not isinstance(X, RoughPath):
        raise TypeError(f"X must be a RoughPath, got {type(X).__name__}; for sampled points use "
                        f"signature(points, depth) or RoughPath.from_path(points).")
    depth = _check_depth(depth)
    if X.level != 2:
        raise ValueError("X is a level-1 path (no area); its rough-path signature is not defined. Use "
                         "signature(X.path, depth) for the piecewise-linear path, or build X with areas.")
    if X.kind != "geometric":
        raise ValueError(f"X has kind={X.kind!r}; the canonical extension needs a geometric level-2 path "
                         f"(Sym(XX) = ½ X⊗X). Convert an Itô lift to Stratonovich first "
                         f"(XX + ½(t - s) I), or build X with kind='geometric'.")
    d, n, batch = X.dim, X.n_steps, X.batch_shape
    inc = np.ascontiguousarray(X.increments.reshape((-1, n, d)))
    lev = np.ascontiguousarray(X.step_levy_areas.reshape((-1, n, d, d)))
    out = _k.rough_sig_kernel(inc, lev, depth, _offsets(d, depth))
    return out[:, _reversed_to_rowmajor(d, depth)].reshape(batch + (sigdim(d, depth),))
