r"""Signatures of any sub-interval of a sampled path, and windowed signatures in one call.

A :class:`SignatureStream` holds a path's signatures in a form that answers :math:`S(X)_{s,t}` for
any grid points ``s <= t`` without running over the sub-path again. The obvious form stores the
prefixes :math:`S_{0,t}` and answers by Chen with the inverse,
:math:`S_{s,t} = S_{0,s}^{-1} \otimes S_{0,t}`, in one product. Its rounding error, however, is
that of the prefixes, not of the answer: level ``k`` of the product is a sum of terms of the size of
:math:`|X_{0,s}|^k` that cancel down to the size of :math:`|X_{s,t}|^k`, so about
:math:`(|X_{0,s}| / |X_{s,t}|)^k \varepsilon` of the answer is lost. Measured on a Brownian path of
10⁶ points in ``d = 2`` (step ``10⁻³``, ``|X_{0,s}| ≈ 0.8``) at depth 4, relative to each level's
largest entry, worst of 20 windows in the second half of the path:

===========  ==============================================  ==========================
window       prefixes and inverse, levels 1 / 2 / 3 / 4       this stream, all levels
===========  ==============================================  ==========================
10 steps     8e-13 / 2.5e-10 / 1.5e-7 / **8e-5**              below 3e-15
1000 steps   1e-13 / 7e-12 / 2e-10 / 7e-9                     below 4e-15
10⁵ steps    3e-14 / 8e-14 / 4e-13 / 1.4e-12                  below 3e-15
===========  ==============================================  ==========================

(``benchmarks/bench_signatures.py --only-streams`` prints this table.) The stream therefore stores a
**segment tree of block signatures**: the grid is cut into blocks of ``block`` steps, each block's
signature is computed directly (:func:`roughpaths.signature`), and level ``j`` of the tree holds the
Chen products of ``2**j`` consecutive blocks. A query ``[s, t]`` is answered as

.. math:: S_{s,t} = S_{s, b_1} \otimes (\text{at most } 2 \log_2(n / \text{block}) \text{ tree nodes})
          \otimes S_{b_2, t},

with the partial blocks ``[s, b_1]`` and ``[b_2, t]`` (fewer than ``block`` steps each) computed
directly. Every factor is the signature of a piece of ``[s, t]`` itself, so nothing cancels against the
rest of the path: the error is a few rounding units of the answer's own level sizes and grows only like
the number of factors, ``log n`` (the table's right column; the tests assert ``1e-12`` of each level's
largest entry, against the direct signature of the sub-path). Costs, same path, ``block = 32``: build
0.34 s (the path read once, ``n / block`` tensor products), 14 MiB stored (``2 n / block``
signatures); 72 µs a query in a call of 10⁴ random queries (at most ``2 block`` segments and
``2 log2(n / block)`` tensor products each, vectorised over the queries), against 10 ms for the direct
signature of a sub-path of 2·10⁵ steps. Blocks of 8 or 128 steps gave the same query time (the tree's
products dominate), 57 or 3.6 MiB stored.

:func:`windowed_signature` answers sliding and expanding windows in one call (short sliding windows
directly, the others through a stream).
"""

from __future__ import annotations

import numpy as np

from ..algebra import logsigdim, lyndon_coordinates, sigdim, tensor_log
from ..algebra.flat import product_flat
from ..validation import as_float_array, check_memory, check_positive_int
from ._engine import _all_finite, _overflow
from .signature import signature

__all__ = ["SignatureStream", "windowed_signature"]

#: Target number of floats in one gathered chunk of queries (about 32 MiB).
_CHUNK_FLOATS = 1 << 22
#: Working floats of a query, in signatures (measured peak about 6; a margin for the log and other layouts).
_QUERY_WORK = 8.0
#: Sliding windows of at most this many steps are signed directly (gathered), longer ones by a stream.
_DIRECT_WINDOW = 64


def _product(a: np.ndarray, b: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """Chen product of two batches of signatures of one depth, unchecked: a tree node that overflowed (inf or NaN)
    reaches the answers of the queries that use it, and the answers are checked (:func:`_refuse_overflow`)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return product_flat(a, b, dim, depth)


def _refuse_overflow(values: np.ndarray, x: np.ndarray, depth: int, what: str) -> None:
    """Refuse the answers ``values`` of a chunk of queries on the finite paths ``x`` if one overflowed float64 (a
    product of the tree's nodes, or its logarithm): a scan of the answers, not of the path."""
    if not _all_finite(values):
        _overflow(x, depth, what)


class SignatureStream:
    r"""The signature of every sub-interval ``[s, t]`` of a sampled path's grid, by Chen from a tree.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
        ``n >= 1`` points (linearly interpolated); leading axes are batch axes.
    depth : int
        Truncation level ``m >= 1``.
    block : int, optional
        Steps per stored block (default 32). Smaller blocks store more (``2 n / block`` signatures) and
        make queries cheaper (at most ``2 block`` segments each); the answers are the same to rounding.
        A block longer than the path is cut to the path's ``n - 1`` steps.

    Attributes
    ----------
    depth, dim, n_points, block : int
    batch_shape : tuple

    Notes
    -----
    The module docstring states the design (a segment tree of block signatures instead of the prefixes
    and their inverses) and the measured rounding error.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import signature
    >>> x = np.random.default_rng(0).normal(size=(200, 2)).cumsum(axis=0)
    >>> stream = SignatureStream(x, 3, block=8)
    >>> stream.signature([5, 0], [150, 199]).shape            # two queries: [5, 150] and [0, 199]
    (2, 14)
    >>> bool(np.allclose(stream.signature(5, 150), signature(x[5:151], 3)))
    True
    """

    def __init__(self, paths, depth: int, *, block: int = 32):
        self.depth = check_positive_int(depth, "depth")
        block = check_positive_int(block, "block")
        x = as_float_array(paths, "paths", min_ndim=2)
        self.batch_shape, (self.n_points, self.dim) = x.shape[:-2], x.shape[-2:]
        if self.n_points < 1 or self.dim < 1:
            raise ValueError(f"paths must have shape (..., n, d) with n >= 1 and d >= 1, got shape {x.shape}.")
        self.block = min(block, max(1, self.n_points - 1))       # one block holds the whole path at most
        self._sigdim = sigdim(self.dim, self.depth)
        n_paths = float(np.prod(self.batch_shape, dtype=float))
        n_blocks = max(1, -(-(self.n_points - 1) // self.block))
        check_memory(n_paths * (2.0 * n_blocks * self._sigdim + n_blocks * (self.block + 1) * self.dim) * 8.0,
                     f"the stream's tree ({self.batch_shape} paths x 2 x {n_blocks} blocks x {self._sigdim} "
                     f"signature entries)", "pass a larger block or a smaller depth, or fewer paths at a time")
        self._x = x
        idx = np.minimum(np.arange(n_blocks)[:, None] * self.block + np.arange(self.block + 1), self.n_points - 1)
        level = signature(x[..., idx, :], self.depth)                 # (..., n_blocks, D)
        self._levels = [level]
        while level.shape[-2] > 1:
            if level.shape[-2] % 2:                                    # pad with the identity (zeros)
                level = np.concatenate([level, np.zeros(level.shape[:-2] + (1, self._sigdim))], axis=-2)
            level = _product(level[..., 0::2, :], level[..., 1::2, :], self.dim, self.depth)
            self._levels.append(level)

    def __repr__(self) -> str:
        return (f"SignatureStream(batch_shape={self.batch_shape}, n_points={self.n_points}, dim={self.dim}, "
                f"depth={self.depth}, block={self.block})")

    # ------------------------------------------------------------------------------ queries
    def _chunk(self) -> int:
        """Queries answered together: their working arrays (about :data:`_QUERY_WORK` signatures each, and the
        gathered points of two partial blocks) stay near :data:`_CHUNK_FLOATS` floats."""
        per_query = float(np.prod(self.batch_shape, dtype=float)) * max((self.block + 1) * self.dim, 4 * self._sigdim)
        return max(1, int(_CHUNK_FLOATS // max(per_query, 1.0)))

    def _check_query(self, s, t, width: int) -> tuple:
        out = []
        for v, name in ((s, "s"), (t, "t")):
            if isinstance(v, (str, bytes)) or v is None:
                raise TypeError(f"{name} must be grid indices (integers), got {v!r}.")
            a = np.asarray(v)
            if a.dtype.kind not in "iu":
                raise TypeError(f"{name} must be grid indices (integers 0..{self.n_points - 1}), got dtype "
                                f"{a.dtype}; pass point indices, e.g. np.searchsorted(times, t_query).")
            out.append(a.astype(np.int64))
        try:
            q = np.broadcast_shapes(out[0].shape, out[1].shape)
        except ValueError:
            raise ValueError(f"s of shape {out[0].shape} and t of shape {out[1].shape} do not broadcast.") from None
        # checked before any work on the broadcast queries: s > t below allocates one byte a query and the answer
        # 16 more (s, t raveled), so an outer product of index arrays allocated gigabytes before this refusal
        n_paths = float(np.prod(self.batch_shape, dtype=float))
        size = float(np.prod(q, dtype=float))
        # the answers (width floats a query) and the working arrays of one chunk of queries: the gathered points of
        # two partial blocks and about _QUERY_WORK signatures a query (the partial blocks' signatures and their
        # engine arrays, the tree's left and right products, the Chen products, the log and its coordinates)
        work = min(size, self._chunk()) * n_paths * (2.0 * (self.block + 1) * self.dim + _QUERY_WORK * self._sigdim)
        check_memory(size * (n_paths * width * 8.0 + 17.0) + 8.0 * work, f"the answers ({self.batch_shape} paths x "
                     f"{size:.0f} queries x {width}) and the working arrays of {min(size, self._chunk()):.0f} queries",
                     "ask fewer queries at a time")
        for a, name in zip(out, ("s", "t")):
            if a.size and (a.min() < 0 or a.max() > self.n_points - 1):
                bad = int(a[(a < 0) | (a > self.n_points - 1)].ravel()[0])
                raise ValueError(f"{name} holds the index {bad}, outside the grid 0..{self.n_points - 1}.")
        s, t = np.broadcast_arrays(*out)
        if np.any(s > t):
            k = tuple(int(i) for i in np.argwhere(s > t)[0])
            raise ValueError(f"s must be <= t, but s{list(k)} = {int(s[k])} > t{list(k)} = {int(t[k])}; the "
                             f"signature of the reversed piece is tensor_inverse(stream.signature(t, s), dim).")
        return s, t

    def _direct(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """``S(lo, hi)`` for ``hi - lo <= block``: the sub-path padded by repeating its last point."""
        idx = np.minimum(lo[:, None] + np.arange(self.block + 1), hi[:, None])
        return signature(self._x[..., idx, :], self.depth)

    def _tree(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The product of blocks ``a .. b-1`` (identity where ``a == b``): bottom-up segment-tree walk."""
        shape = self.batch_shape + (a.shape[0], self._sigdim)
        left, right = np.zeros(shape), np.zeros(shape)
        lo, hi = a.copy(), b.copy()
        for level in self._levels:
            take = np.nonzero((lo < hi) & (lo % 2 == 1))[0]
            if take.size:                                  # left <- left ⊗ node[lo], on those rows only
                left[..., take, :] = _product(left[..., take, :], level[..., lo[take], :], self.dim, self.depth)
                lo[take] += 1
            take = np.nonzero((lo < hi) & (hi % 2 == 1))[0]
            if take.size:                                  # right <- node[hi - 1] ⊗ right
                hi[take] -= 1
                right[..., take, :] = _product(level[..., hi[take], :], right[..., take, :], self.dim, self.depth)
            lo, hi = lo // 2, hi // 2
        return _product(left, right, self.dim, self.depth)

    def _answer(self, s: np.ndarray, t: np.ndarray) -> np.ndarray:
        B = self.block
        first = np.minimum(-(-s // B) * B, t)            # first block boundary at or after s (or t)
        last = np.maximum(t // B * B, first)             # last block boundary at or before t (or first)
        middle = self._tree(first // B, last // B)
        return _product(_product(self._direct(s, first), middle, self.dim, self.depth),
                        self._direct(last, t), self.dim, self.depth)

    def signature(self, s, t) -> np.ndarray:
        r"""The signature :math:`S(X)_{s,t}` of the path between grid points ``s`` and ``t``.

        Parameters
        ----------
        s, t : int or array_like of int
            Point indices ``0 <= s <= t <= n - 1``, broadcast against each other to a query shape ``q``.

        Returns
        -------
        ndarray, shape ``(*batch_shape, *q, sigdim(d, depth))``
            In :func:`roughpaths.signature`'s layout: equal (to rounding, see the module docstring) to
            ``signature(paths[..., s:t + 1, :], depth)``; zero where ``s == t``.
        """
        return self._answers(s, t, log=False)

    def _answers(self, s, t, *, log: bool) -> np.ndarray:
        """The signatures (or with ``log`` the log-signatures) of the queries, a chunk at a time into the result."""
        width = logsigdim(self.dim, self.depth) if log else self._sigdim
        s, t = self._check_query(s, t, width)
        q = s.shape
        s, t = s.ravel(), t.ravel()
        chunk = self._chunk()
        out = np.empty(self.batch_shape + (s.size, width))
        for lo in range(0, s.size, chunk):
            sig = self._answer(s[lo:lo + chunk], t[lo:lo + chunk])
            _refuse_overflow(sig, self._x, self.depth, "signature (a SignatureStream query)")
            if log:                                      # (the log of a finite signature may itself overflow)
                sig = lyndon_coordinates(tensor_log(sig, self.dim), self.dim)
                _refuse_overflow(sig, self._x, self.depth, "log-signature (a SignatureStream query)")
            out[..., lo:lo + chunk, :] = sig
        return out.reshape(self.batch_shape + q + (width,))

    def logsignature(self, s, t) -> np.ndarray:
        r"""The log-signature of the path between grid points ``s`` and ``t``, in the Lyndon basis.

        Parameters
        ----------
        s, t : int or array_like of int
            As for :meth:`signature`.

        Returns
        -------
        ndarray, shape ``(*batch_shape, *q, logsigdim(d, depth))``
            ``lyndon_coordinates(tensor_log(self.signature(s, t), d), d)``: the coordinates of
            :func:`roughpaths.logsignature` of the sub-path.
        """
        return self._answers(s, t, log=True)


def windowed_signature(paths, depth: int, length: int, *, step: int = 1, expanding: bool = False,
                       log: bool = False) -> np.ndarray:
    r"""Signatures (or log-signatures) of sliding or expanding windows of sampled paths, in one call.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
    depth : int
        Truncation level ``m >= 1``.
    length : int
        Steps in a sliding window, or in the first expanding window (``1 <= length <= n - 1``).
    step : int
        Steps between consecutive windows (default 1).
    expanding : bool
        ``False`` (default): sliding windows ``[k step, k step + length]``; ``True``: expanding windows
        ``[0, length + k step]``; ``k = 0, ..., W - 1`` with ``W = (n - 1 - length) // step + 1``.
    log : bool
        ``True``: log-signatures in the Lyndon basis instead of signatures.

    Returns
    -------
    ndarray, shape ``(..., W, sigdim(d, m))`` (or ``logsigdim(d, m)`` with ``log=True``)
        Window ``k`` in :func:`roughpaths.signature`'s (or :func:`roughpaths.logsignature`'s) layout.
        Sliding windows of at most 64 steps are computed directly (each window's points gathered),
        longer ones and expanding windows by a :class:`SignatureStream` (its rounding error).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> windowed_signature(x, 2, 2, log=True)                      # increments and Lévy areas
    array([[ 1. ,  1. ,  0.5],
           [-1. ,  1. ,  0.5]])
    >>> windowed_signature(x, 1, 1, expanding=True)                # the path's value minus its start
    array([[1., 0.],
           [1., 1.],
           [0., 1.]])
    """
    x = as_float_array(paths, "paths", min_ndim=2)
    n = x.shape[-2]
    if n < 1 or x.shape[-1] < 1:
        raise ValueError(f"paths must have shape (..., n, d) with n >= 1 and d >= 1, got shape {x.shape}.")
    length = check_positive_int(length, "length")
    step = check_positive_int(step, "step")
    if not isinstance(expanding, (bool, np.bool_)):
        raise TypeError(f"expanding must be True or False, got {expanding!r}.")
    if not isinstance(log, (bool, np.bool_)):
        raise TypeError(f"log must be True or False, got {log!r}.")
    if n < 2:                                 # no window of one step or more fits ("length <= 1" is no fix)
        raise ValueError(f"paths have {n} point (shape {x.shape}): a window spans length >= 1 steps, so it needs "
                         f"paths of at least 2 points; pass longer paths (the signature of one point is zero).")
    if length > n - 1:
        raise ValueError(f"length={length} is more than the {n - 1} steps of the paths (shape {x.shape}); pass "
                         f"length <= {n - 1} or longer paths.")
    depth = check_positive_int(depth, "depth")
    k = np.arange((n - 1 - length) // step + 1)
    s = np.zeros_like(k) if expanding else k * step
    t = length + k * step
    if not expanding and length <= _DIRECT_WINDOW:
        # short sliding windows: each one's points gathered and signed directly (cheaper than the tree's
        # partial blocks and products: 16 steps, 10^5 windows, d = 3, depth 3 took 0.3 s against 1.6 s)
        d = x.shape[-1]
        n_paths = float(np.prod(x.shape[:-2], dtype=float))
        dim = sigdim(d, depth)
        width = logsigdim(d, depth) if log else dim
        # a chunk of windows at a time, written into the result: its gathered points, its signatures with the
        # engine's arrays (about 3 signatures a window) and, with log, the log and its coordinates (2 more; 6 in all
        # with a margin: measured 5.4 at d = 3, depth 3)
        chunk = max(1, int(_CHUNK_FLOATS // max(1.0, n_paths * max((length + 1) * d, dim))))
        work = min(k.size, chunk) * n_paths * ((length + 1) * d + 6.0 * dim)
        check_memory((n_paths * k.size * width + work) * 8.0, f"the windows' {'log-' if log else ''}signatures "
                     f"({x.shape[:-2]} paths x {k.size} windows x {width}) and the working arrays of "
                     f"{min(k.size, chunk)} windows", "pass a larger step or fewer paths at a time")
        out = np.empty(x.shape[:-2] + (k.size, width))
        for lo in range(0, k.size, chunk):
            sig = signature(x[..., s[lo:lo + chunk, None] + np.arange(length + 1), :], depth)
            if log:                                      # (signature refused an overflow; its log may overflow)
                sig = lyndon_coordinates(tensor_log(sig, d), d)
                _refuse_overflow(sig, x, depth, "log-signature (a window)")
            out[..., lo:lo + chunk, :] = sig
        return out
    stream = SignatureStream(x, depth)
    return stream.logsignature(s, t) if log else stream.signature(s, t)
