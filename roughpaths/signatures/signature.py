r"""Signatures and log-signatures of piecewise-linear paths and of level-2 geometric rough paths.

Output layouts (see :mod:`roughpaths.algebra.tensor`):

* :func:`signature` — flat, levels ``1..depth`` concatenated, row-major words, no leading 1:
  the layout of ``iisignature.sig(path, depth)`` (and of ``esig.stream2sig`` minus its 1).
  Level 2 ``[i, j]`` is the area :math:`\int (X^i - X^i_s)\,dX^j` of ``docs/conventions.md``.
* :func:`logsignature` — coordinates in the Lyndon basis (standard bracketing, ordered by
  length then lexicographically; :func:`roughpaths.lyndon_basis` names them),
  the coordinates of ``iisignature.logsig(path, iisignature.prepare(d, depth))``. Level-2
  coordinate of ``[i,j]`` (``i < j``) is the Lévy area :math:`\tfrac12(\mathbb{X}^{ij} - \mathbb{X}^{ji})`.

Gradients (vector–Jacobian products, the quantities of ``iisignature.sigbackprop`` /
``logsigbackprop``) are in :mod:`roughpaths.signatures.gradients`.

Kernels are numba-compiled and cached (:mod:`roughpaths.signatures._level2`, :mod:`roughpaths.signatures._lanes`,
:mod:`roughpaths.signatures._kernels`; the backward pass :mod:`roughpaths.signatures._vjp`): level 2 is a fused
one-pass kernel (increment and shoelace Lévy area), depth >= 3 a Horner–Chen update per segment,
run side by side on groups of work units (paths, or chunks of a long path glued by Chen's
identity). The split of the work depends on the input's size only, so results are bitwise
identical for any number of threads; small inputs run on one thread. The log-signature takes the
truncated logarithm by Horner's scheme and the Lyndon coordinates by forward substitution with a
sparse triangular map (:mod:`roughpaths.algebra._lyndon`, cached under a byte budget); a request whose
arrays would not fit in the available memory is refused with a ``ValueError`` before allocating.
"""

from __future__ import annotations

import numpy as np

from .. import _threads
from ..algebra.flat import level_offsets, log_lyndon_flat
from . import _kernels as _k
from ._engine import (_check_depth, _check_fits, _check_paths, _finite_or_raise, _kernel_array, _level2_flat,
                      _logsigdim, _reversed_to_rowmajor, _sigdim, _signature_flat)

__all__ = ["signature", "logsignature", "rough_path_signature"]

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
    x = _check_paths(paths, finite=depth == 1)     # depth >= 2: checked through the output
    batch, (n, d) = x.shape[:-2], x.shape[-2:]
    flat = _kernel_array(x, (-1, n, d))
    _check_fits(flat.shape[0], d, depth, n=n)
    return _finite_or_raise(_signature_flat(flat, depth), x, depth).reshape(batch + (_sigdim(d, depth),))


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
        :func:`roughpaths.lyndon_basis` (e.g. ``'1', '2', '[1,2]', ...``). The
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
    x = _check_paths(paths, finite=False)          # checked by signature(x, 1) or through the output
    d = x.shape[-1]
    if depth == 1 or d == 1:
        # d = 1: the free Lie algebra is R (a path's log-signature is its increment).
        return signature(x, 1)[..., :_logsigdim(d, depth)]
    batch, n = x.shape[:-2], x.shape[-2]
    flat = _kernel_array(x, (-1, n, d))
    _check_fits(flat.shape[0], d, depth, log=True, n=n)
    if depth == 2:
        # log at level 2 is S_2 - ½ x⊗x; its Lyndon coordinates ([i,j], i < j) are the Lévy areas,
        # which the level-2 kernel accumulates directly
        if flat.shape[0] == 0 or n == 1:
            return np.zeros(batch + (_logsigdim(d, 2),))
        return _finite_or_raise(_level2_flat(flat, log=True), x, 2, "log-signature").reshape(batch + (-1,))
    sig = np.ascontiguousarray(_signature_flat(flat, depth))
    # checked through the Lyndon coordinates: a NaN/inf point reaches them, and the log of a finite signature may
    # itself overflow (its products of levels)
    out = log_lyndon_flat(sig, d, depth)
    return _finite_or_raise(out, x, depth, "log-signature").reshape(batch + (_logsigdim(d, depth),))


def signature_shape(shape: tuple, depth, *, log: bool = False) -> tuple:
    """The shape of ``signature(paths, depth)`` (``logsignature`` with ``log``) for paths of ``shape`` ``(..., n, d)``,
    after the checks the shapes decide: the depth and the memory estimate. For callers that allocate the result
    themselves (the JAX front end, whose result buffer XLA allocates before the host call runs)."""
    *batch, n, d = shape
    depth = _check_depth(depth)
    _check_fits(int(np.prod(batch, dtype=np.int64)), d, depth, log=log, n=n)
    return tuple(batch) + ((_logsigdim if log else _sigdim)(d, depth),)


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
    from ..paths.rough_path import RoughPath

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
    inc = _kernel_array(X.increments, (-1, n, d))
    lev = _kernel_array(X.step_levy_areas, (-1, n, d, d))
    out = np.empty((inc.shape[0], _sigdim(d, depth)))
    off = level_offsets(d, depth)
    _threads.run(lambda lo, hi: _k.rough_sig_rows(inc, lev, depth, off, lo, hi, out),
                 _threads.ranges(inc.shape[0], n * depth * _sigdim(d, depth)))
    return out[:, _reversed_to_rowmajor(d, depth)].reshape(batch + (_sigdim(d, depth),))


# the gradients live in their own module; imported last (it builds on the helpers above)
