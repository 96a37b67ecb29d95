r"""One Brownian path at every resolution: :class:`BrownianTree`, a Lévy-area tree on ``[t0, t1]``.

``BrownianTree(dim, seed=...)`` answers :meth:`~BrownianTree.increment`, :meth:`~BrownianTree.area` and
:meth:`~BrownianTree.levy_area` on any ``[s, t]`` in ``[t0, t1]``, batched over paths, for one fixed
Brownian path per batch member: the answer depends only on the seed and the query (bitwise), never on the
order or number of earlier queries, and Chen's identity holds across any subdivision. Conventions as in
:class:`~roughpaths.RoughPath` (``docs/conventions.md``): area
:math:`\mathbb{X}^{ij}_{s,t} = \int_s^t (X^i_r - X^i_s)\circ dX^j_r` (Stratonovich, geometric), Lévy area
:math:`A = \tfrac12(\mathbb{X} - \mathbb{X}^T)`.

The tree
--------
The dyadic intervals of ``[t0, t1]`` form a binary tree; the node at depth ``k`` has length
:math:`h = (t_1 - t_0)2^{-k}`. A node holds its *polygon* at relative depth ``m = polygon_levels``
(``2^m`` segment increments of length :math:`\delta = h 2^{-m}`) and its *tail*, the sum of the segments'
own Lévy areas, from which its increment and Lévy area follow by Chen's identity
(:mod:`roughpaths.drivers._tree_kernels`). A node is split into its two children by halving every
segment (the Brownian-bridge midpoints) and dividing the tail between the halves, conditioned exactly on
the parent's tail, so ``parent = left ⊗ right`` holds to round-off. The root's polygon is ``2^m``
independent steps of length :math:`(t_1 - t_0)2^{-m}`: exact increments, and Lévy areas drawn by
``levy_area`` (``"auto"``: exact in law for ``d <= 2``, error-controlled for ``d >= 3``), whose sum is the
root's tail. Each split draws its normals from its own stream, keyed by (path, depth, index): a node
depends on its ancestors' streams only.

Queries are snapped to the dyadic grid of spacing :math:`(t_1 - t_0)2^{-L}`, ``L = resolution``
(default 40, a relative time error below :math:`10^{-12}`), and answered as the Chen product of the
canonical dyadic nodes between the snapped ends (at most ``2L`` nodes, none longer than ``t - s``).

What is exact and what is approximate
-------------------------------------
Exact (to round-off, path by path): Chen's identity across any subdivision; order independence. Exact
in law: the root's polygon (for ``d <= 2`` with ``levy_area="auto"``; else the method's error per
segment). Approximate: inside a split, the tail (:math:`2^{-m}` of a node's area variance) is Gaussian
given the polygon, and the midpoints are conditioned on it as if jointly Gaussian (they keep their exact
second moments when the tail has its exact conditional variance). The error does not compound with
depth: a node's law depends on its parent's tail only through a regression on a small part of its
variance, and the polygon it inherits is refined by bridge midpoints whose law is exact up to that
regression, so the distance to Brownian motion levels off after a few generations. Measured (``d = 2``, ``m = 3``,
10⁶ paths, nodes near ``t = 0.618``; ``A/h`` against Lévy's law, CDF :math:`\tfrac2\pi\arctan e^{\pi a}`,
variance 1/4, fourth moment 5/16; the sampling noise of the Kolmogorov distance is about 0.0009, of the
variance ratio 0.002, of the fourth-moment ratio 0.007):

===== ======= ============ ============= ======== =======
depth KS(A/h) Var A/(h²/4) E A⁴/(5h⁴/16) KS(W/√h) Var W/h
===== ======= ============ ============= ======== =======
1     0.0007  1.0008       1.0004        0.0004   0.9999
3     0.0008  1.0000       0.9992        0.0005   1.0005
6     0.0013  0.9942       0.9721        0.0006   0.9990
12    0.0016  1.0055       0.9999        0.0009   1.0001
===== ======= ============ ============= ======== =======

So the law error of a deep node is about 0.5 % in the area's variance and up to 3 % in its fourth
moment (invisible below about 10⁵ paths), and the increments are Brownian within sampling error. More
depths and ``m = 2`` in ``docs/brownian-tree.md``.

Cost and memory: a split is one compiled call over the batch that seeds its streams, draws its normals
and bisects (``d = 2``, ``m = 3``: 15 µs for one path, 90 µs for 64, about 1 µs per path beyond); a query
walks down from the root and splits at most two nodes per depth (at most ``2L``), holding a few node
states at a time (``8 P (2^m d + d^2)`` bytes each). Splits already made are found in a least-recently-used
cache of at most ``cache_size`` nodes (default: as many as fit in 64 MiB, at most 8192), which does not grow
with the number of queries.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from ..paths.rough_path import RoughPath
from ..validation import as_float_array, check_batch_shape, check_memory, check_positive_int, check_real, check_seed
from ._random import PathStreams
from ._seeded import selected_paths
from .base import Driver
from ._tree_members import member_cells
from ._tree_kernels import polygon_area, reduce_node, refine_segments_fast, seed_prefix, split_seeded, split_width
from .areas import _Sampler

__all__ = ["BrownianTree"]

_ROOT, _SPLIT = 0, 2
_CACHE_BYTES = 64 * 2 ** 20


def _reduce(node):
    """``(W, A)`` of a node state ``(w, G)``: Chen's identity over its polygon."""
    return reduce_node(*node)


class BrownianTree(Driver):
    r"""A Brownian path with Lévy areas on ``[t0, t1]``, queried on any sub-interval (module docstring).

    Parameters
    ----------
    dim : int
        Dimension ``d`` of the Brownian motion.
    seed : int or numpy.random.SeedSequence
        The path of batch member ``i`` (C order) depends on ``seed`` and ``i`` only.
    t0, t1 : float
        The interval (``t0 < t1``).
    batch_shape : tuple of int
        Independent paths; answers have shape ``batch_shape + (d,)`` or ``batch_shape + (d, d)``.
    levy_area : str
        Sampler of the Lévy areas of the root's ``2^m`` segments (a method of
        :data:`~roughpaths.LEVY_AREA_METHODS`, default ``"auto"``: exact in law for ``d <= 2``, L² error
        ``levy_area_error`` for ``d >= 3``); the splits below the root are the tree's own.
    levy_area_error : float, optional
        Error per root segment of the error-controlled methods (default :math:`\delta^{3/2}`,
        :math:`\delta = (t_1 - t_0)2^{-m}`).
    polygon_levels : int
        ``m``: each node carries ``2^m`` segments (default 3; the tail is ``2^-m`` of the area variance).
    resolution : int
        ``L``: queries are snapped to the grid of spacing ``(t1 - t0) 2^-L`` (default 40, at most 62).
    cache_size : int, optional
        Most nodes kept between queries (default: 64 MiB worth, at most 8192; 0 keeps none). The cache
        only saves work: a query splits at most two nodes per depth and holds a few node states at a time.

    Examples
    --------
    >>> import numpy as np
    >>> tree = BrownianTree(2, seed=0, batch_shape=(3,))
    >>> tree.increment(0.1, 0.7).shape, tree.area(0.1, 0.7).shape
    ((3, 2), (3, 2, 2))
    >>> w1, a1 = tree.increment(0.1, 0.4), tree.area(0.1, 0.4)
    >>> w2, a2 = tree.increment(0.4, 0.7), tree.area(0.4, 0.7)
    >>> bool(np.allclose(tree.area(0.1, 0.7), a1 + a2 + w1[:, :, None] * w2[:, None, :], atol=1e-12))
    True
    >>> again = BrownianTree(2, seed=0, batch_shape=(3,))
    >>> bool(np.array_equal(again.area(0.4, 0.7), a2))      # the order of queries does not matter
    True
    """

    #: The level of the rough path it answers (increments and areas).
    level = 2
    #: It answers on any times of ``[t0, t1]`` (the :class:`~roughpaths.Driver` protocol): steps are chosen by
    #: a step controller, its only grid step is ``[t0, t1]``.
    any_times = True

    def __init__(self, dim, *, seed, t0=0.0, t1=1.0, batch_shape=(), levy_area="auto", levy_area_error=None,
                 polygon_levels=3, resolution=40, cache_size=None):
        self.dim = check_positive_int(dim, "dim")
        self.seed_sequence = check_seed(seed)
        self.t0, self.t1 = check_real(t0, "t0"), check_real(t1, "t1")
        if not self.t1 > self.t0:
            raise ValueError(f"t1 must be greater than t0, got t0={t0!r}, t1={t1!r}.")
        if not np.isfinite(self.t1 - self.t0):
            raise ValueError(f"t1 - t0 overflows float64 (t0={t0!r}, t1={t1!r}): every node length and "
                             f"increment would be inf or 0; use an interval of finite length (shift or rescale "
                             f"time, e.g. t0=0).")
        self.batch_shape = check_batch_shape(batch_shape)
        if levy_area is None or levy_area == "none":
            raise ValueError("levy_area=None: the tree always carries Lévy areas (its splits are conditioned on "
                             "them); pass a method of LEVY_AREA_METHODS (default 'auto') and use increment().")
        self.levy_area_method = levy_area
        self.polygon_levels = check_positive_int(polygon_levels, "polygon_levels", minimum=0)
        if self.polygon_levels > 8:
            raise ValueError(f"polygon_levels must be at most 8 (2^m segments per node), got {polygon_levels}; "
                             f"the default 3 already keeps the tail at 1/8 of a node's area variance.")
        self._sampler = _Sampler(levy_area, self.dim, [(self.t1 - self.t0) / 2 ** self.polygon_levels], None,
                                 levy_area_error)
        self.resolution = check_positive_int(resolution, "resolution")
        if self.resolution > 62:
            raise ValueError(f"resolution must be at most 62 (grid indices are int64), got {resolution}.")
        finest = (self.t1 - self.t0) / 2.0 ** (self.resolution + self.polygon_levels)
        if not finest >= np.finfo(np.float64).tiny:
            raise ValueError(f"the finest segment (t1 - t0) 2^-(resolution + polygon_levels) = {finest!r} underflows "
                             f"float64 (t0={t0!r}, t1={t1!r}, resolution={self.resolution}); rescale time to a "
                             f"longer interval or lower the resolution.")
        self.n_paths = int(np.prod(self.batch_shape, dtype=object))
        n, d = 2 ** self.polygon_levels, self.dim
        self.node_bytes = max(1, self.n_paths) * 8 * (n * d + d * d)
        user_cache = cache_size is not None
        if cache_size is None:
            cache_size = int(min(8192, _CACHE_BYTES // self.node_bytes))
        self.cache_size = check_positive_int(cache_size, "cache_size", minimum=0)
        check_memory(self._setup_bytes(), f"the tree of {self.n_paths} path(s) in dim={d} (the path index, the "
                     f"root's {n} segments and one split)", "use fewer paths (a smaller batch_shape) or split the "
                     "batch into several trees (tree.select)")
        if user_cache:
            check_memory(float(self.cache_size) * self.node_bytes, f"cache_size={self.cache_size} nodes of "
                         f"{self.node_bytes} bytes each (batch of {self.n_paths} path(s))",
                         "pass a smaller cache_size, or leave it unset (64 MiB worth)")
        self._cache: OrderedDict = OrderedDict()
        self._root_node = None
        self._paths = np.arange(self.n_paths, dtype=np.int64)
        self._prefix = seed_prefix(self.seed_sequence)          # None: seed the splits' streams in numpy

    # ------------------------------------------------------------------ sizes (checked before work)
    def _setup_bytes(self) -> float:
        """Bytes of the path index, the root's state and sampling, and one split: what any query needs first.

        Per path (``n = 2^m`` segments, ``w`` normals per segment of the root's Lévy-area method): the index
        and stream keys (48), the root's normals, polygon and areas (``8 (4 n d + 4 n d² + n w + 2 d²)``) and
        a split's normals and outputs (``8 (split_width + 4 n d + 2 d²)`` plus its seeds, 100).
        """
        P, n, d = float(max(1, self.n_paths)), 2.0 ** self.polygon_levels, float(self.dim)
        root = 8.0 * (4 * n * d + 4 * n * d * d + n * self._sampler.width + 2 * d * d)
        split = 8.0 * (split_width(int(n), int(d)) + 4 * n * d + 2 * d * d) + 100.0
        return P * (48.0 + root + split)

    def _query_bytes(self, idx) -> float:
        """Bytes a query on the grid indices ``idx`` allocates (the estimate :meth:`_cells` checks).

        The outputs (``W``, ``A``, and three temporaries of ``A``'s size for :meth:`area` and
        :meth:`rough_path`), the reduced canonical nodes of every cell (counted exactly: a cell ``[i, j)``
        decomposes into ``popcount(k - i) + popcount(j - k)`` dyadic nodes, ``k`` the multiple of the highest
        power of two in ``(i, j]``), and the splits it may keep: at most ``L`` per grid point, of which at most
        ``cache_size / 2`` stay in the cache and ``L + 1`` more on the walk's stack, two nodes each. A grid
        point ``g`` lies strictly inside ``L - tz(g)`` nodes (``tz``: its trailing zero bits), so a walk splits
        at most the sum of those.
        """
        P, d, L = float(max(1, self.n_paths)), float(self.dim), self.resolution
        cells = len(idx) - 1
        nodes = 0
        inside = 0
        pts = idx.tolist()
        for a, b in zip(pts[:-1], pts[1:]):
            if b > a:
                h = (a ^ b).bit_length() - 1
                k = (b >> h) << h
                nodes += (k - a).bit_count() + (b - k).bit_count()
        for g in pts:
            if 0 < g < 1 << L:
                inside += L - ((g & -g).bit_length() - 1)
        splits = min(float(inside), self.cache_size // 2 + L + 1.0)
        return 8.0 * P * (d + d * d) * (4.0 * cells + nodes) + 2.0 * splits * self.node_bytes

    def __repr__(self) -> str:
        return (f"BrownianTree(dim={self.dim}, t0={self.t0}, t1={self.t1}, batch_shape={self.batch_shape}, "
                f"levy_area={self.levy_area_method!r}, polygon_levels={self.polygon_levels}, "
                f"resolution={self.resolution})")

    @property
    def cached_nodes(self) -> int:
        """Nodes held in the cache now (never more than ``cache_size``)."""
        return 2 * len(self._cache)

    def select(self, paths):
        """A tree of some of this tree's paths, bitwise equal to those paths of this one.

        Parameters
        ----------
        paths : slice, range or array_like of int
            Flat indices into this tree's batch (C order).

        Returns
        -------
        BrownianTree
            ``batch_shape == (len(paths),)``, the same seed and settings, an empty cache. Member ``k`` answers
            every query as member ``paths[k]`` of this tree does, so each member can be solved with steps of
            its own (``solve(..., tree.select([i]), ..., step_control=...)``).

        Examples
        --------
        >>> import numpy as np
        >>> tree = BrownianTree(2, seed=3, batch_shape=(4,))
        >>> bool(np.array_equal(tree.select([2]).area(0.1, 0.3)[0], tree.area(0.1, 0.3)[2]))
        True
        """
        idx = selected_paths(paths, self.n_paths, "tree")
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new._paths = self._paths[idx]
        new.batch_shape = (int(idx.size),)
        new.n_paths = int(idx.size)
        new.node_bytes = max(1, new.n_paths) * self.node_bytes // max(1, self.n_paths)
        new._cache = OrderedDict()
        new._root_node = None
        new.__dict__.pop("_walk_cache", None)
        return new

    @property
    def times(self):
        """``[t0, t1]``: the tree has no grid of its own (``Driver`` protocol; steps come from a controller)."""
        return np.array([self.t0, self.t1])

    def blocks(self, max_steps=None):
        raise ValueError("a BrownianTree has no grid to cut into blocks: solve it with a step controller "
                         "(step_control=PIController(rtol, atol) or FixedSteps(dt)), or materialise a grid with "
                         "tree.rough_path(times).")

    def increments_and_areas(self, times, paths=None):
        """Increments and Stratonovich areas between ``times`` (the ``Driver`` protocol for ``any_times``).

        Parameters
        ----------
        times : array_like, shape ``(n + 1,)`` or ``(len(paths), n + 1)``
            Increasing times in ``[t0, t1]``; a 2-D array gives each selected path its own times.
        paths : array_like of int, optional
            Flat path indices; ``None``: all paths (``times`` then 1-D).

        Returns
        -------
        dX, dXX : ndarray
            ``batch_shape + (n, d)`` and ``batch_shape + (n, d, d)``, or with the leading axis ``len(paths)``.
            On 1-D ``times`` path ``paths[k]`` answers bitwise as it does in the whole tree; on 2-D ``times`` each
            path is walked on its own (:mod:`roughpaths.drivers._tree_members`): bitwise the same in any query
            of any set of paths, and equal to the shared-times answer to round-off (its cells are Chen products
            of the same nodes, accumulated in another order).
        """
        if paths is None:
            W, A = self.increments_and_levy_areas(times)
        else:
            paths = selected_paths(paths, self.n_paths, "tree")
            t = np.asarray(times, dtype=np.float64)
            t = t if t.shape == (paths.size, t.shape[-1]) else np.broadcast_to(t, (paths.size, t.shape[-1]))
            if np.ndim(times) == 1:                  # shared times: the tree's own walk, then the rows
                W, A = self.increments_and_levy_areas(t[0])
                W, A = W.reshape((self.n_paths,) + W.shape[-2:])[paths], A.reshape((self.n_paths,) + A.shape[-3:])[paths]
            elif self._prefix is not None:          # one vectorised walk for every path on its own times
                return member_cells(self, paths, t, _SPLIT)
            else:
                W, A = (np.concatenate(x) for x in zip(*[self.select([p]).increments_and_levy_areas(tk)
                                                         for p, tk in zip(paths.tolist(), t)]))
        return W, A + 0.5 * W[..., :, None] * W[..., None, :]

    # ------------------------------------------------------------------ nodes
    def _streams(self, tag, depth, index):
        P = self.n_paths
        keys = np.empty((P, 5), dtype=np.int64)
        keys[:, 0] = tag
        keys[:, 1] = self._paths
        keys[:, 2] = depth
        keys[:, 3] = index >> 32
        keys[:, 4] = index & 0xFFFFFFFF
        return PathStreams(self.seed_sequence, keys)

    def _root(self):
        """The root's polygon: ``2^m`` independent steps ``(w_i, A_i)`` drawn by ``levy_area``; ``G = Σ A_i``."""
        P, d, n = self.n_paths, self.dim, 2 ** self.polygon_levels
        delta = (self.t1 - self.t0) / n
        streams = self._streams(_ROOT, 0, 0)
        z = np.empty((P, n * d))
        streams.fill(z)
        w = np.sqrt(delta) * z.reshape(P, n, d)
        X = self._sampler.fill(np.ascontiguousarray(w), np.full(n, delta), streams, False,
                               np.empty(max(self._sampler.width, 1)))
        return w, 0.5 * (X - np.swapaxes(X, -1, -2)).sum(axis=1)

    def _children(self, depth: int, index: int, node):
        """The two children ``(left, right)`` of the node ``(depth, index)`` whose state is ``node`` (cached)."""
        key = (depth, index)
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            return hit
        w, G = node
        P, n, d = w.shape
        delta = (self.t1 - self.t0) / 2 ** depth / n
        if self._prefix is not None and P:
            fine, GL, GR = split_seeded(self._prefix, self._paths, _SPLIT, depth, index, w, G, delta)
        else:
            z = np.empty((P, split_width(n, d)))
            self._streams(_SPLIT, depth, index).fill(z)
            fine, GL, GR = refine_segments_fast(w, G, delta, z)
        pair = ((fine[:, :n], GL), (fine[:, n:], GR))
        self._cache[key] = pair
        while 2 * len(self._cache) > self.cache_size:
            self._cache.popitem(last=False)
        return pair

    # ------------------------------------------------------------------ queries
    def _index(self, t, name):
        t = check_real(t, name)
        if not self.t0 <= t <= self.t1:
            raise ValueError(f"{name} must lie in [t0, t1] = [{self.t0}, {self.t1}], got {t!r}.")
        L = self.resolution
        return min(int(round((t - self.t0) / (self.t1 - self.t0) * 2.0 ** L)), 2 ** L)

    def _pair(self, s, t):
        i, j = self._index(s, "s"), self._index(t, "t")
        if i > j:
            raise ValueError(f"s must not exceed t, got s={s!r}, t={t!r}; swap them.")
        return i, j

    def _chen(self, i: int, j: int):
        """``(W (P, d), A (P, d, d))`` over grid cells ``[i, j)``: the one cell of :meth:`_cells` (zeros if empty)."""
        if i == j:
            return np.zeros((self.n_paths, self.dim)), np.zeros((self.n_paths, self.dim, self.dim))
        W, A = self._cells(np.array([i, j], dtype=np.int64))
        return W[:, 0], A[:, 0]

    def _out(self, x):
        return x.reshape(self.batch_shape + x.shape[1:])

    def increment(self, s, t) -> np.ndarray:
        """``X_t - X_s``, shape ``batch_shape + (d,)`` (``s``, ``t`` snapped to the grid; ``s <= t``)."""
        return self._out(self._chen(*self._pair(s, t))[0])

    def levy_area(self, s, t) -> np.ndarray:
        """Lévy area ``½ (XX - XXᵀ)`` over ``[s, t]``, shape ``batch_shape + (d, d)``."""
        return self._out(self._chen(*self._pair(s, t))[1])

    def area(self, s, t) -> np.ndarray:
        """Stratonovich area ``XX[i, j] = ∫_s^t (X^i - X^i_s) dX^j``, shape ``batch_shape + (d, d)``."""
        W, A = self._chen(*self._pair(s, t))
        return self._out(A + 0.5 * W[:, :, None] * W[:, None, :])

    def increments_and_levy_areas(self, times):
        """Increments ``batch_shape + (n, d)`` and Lévy areas ``batch_shape + (n, d, d)`` between ``times (n + 1,)``.

        ``times`` increasing in ``[t0, t1]``; step ``k`` is ``[times[k], times[k+1]]``, answered as by
        :meth:`increment` and :meth:`levy_area` (the hook a solver consumes: one call per grid).
        """
        t = as_float_array(times, "times", ndim=1)
        if t.size < 2 or not np.all(np.diff(t) > 0):
            raise ValueError(f"times must be a strictly increasing 1-D array of at least 2 points, got {t!r}.")
        idx = np.array([self._index(v, "times") for v in t], dtype=np.int64)
        if not np.all(np.diff(idx) > 0):
            raise ValueError(f"times are closer than the tree's resolution (t1 - t0)·2^-{self.resolution}; "
                             f"drop the duplicates or build the tree with a larger resolution.")
        W, A = self._cells(idx)
        return self._out(W), self._out(A)

    def _cells(self, idx):
        """``(W (P, n, d), A (P, n, d, d))`` of the cells ``[idx[k], idx[k+1])`` in one walk of the tree.

        A depth-first walk from the root, left to right, that splits exactly the nodes holding a grid point
        strictly inside (at most two per depth and grid point): every other node lies in one cell and is
        reduced to its ``(W, A)`` at once. So a cell is the Chen product of its canonical dyadic nodes,
        whatever the other grid points, and only a few node states are alive at a time whatever the cache
        holds.
        """
        P, d, L = self.n_paths, self.dim, self.resolution
        n = idx.size - 1
        check_memory(self._query_bytes(idx), f"a query of {n} interval(s) of the tree of {P} path(s) in dim={d}",
                     "ask for fewer intervals at a time, or use fewer paths (tree.select)")
        if self._root_node is None:
            self._root_node = self._root()
        parts = [[] for _ in range(n)]
        stack = [(0, 0, self._root_node)]
        first, last = int(idx[0]), int(idx[-1])
        while stack:
            depth, index, node = stack.pop()
            size = 1 << (L - depth)
            lo, hi = index * size, (index + 1) * size
            if hi <= first or lo >= last:
                continue
            k = int(np.searchsorted(idx, lo, side="right"))     # first grid point > lo
            if k > n or idx[k] >= hi:                           # none strictly inside: within cell k - 1
                parts[k - 1].append(_reduce(node))
                continue
            left, right = self._children(depth, index, node)
            stack.append((depth + 1, 2 * index + 1, right))
            stack.append((depth + 1, 2 * index, left))
        W = np.empty((P, n, d))
        A = np.empty((P, n, d, d))
        for c, nodes in enumerate(parts):
            Wk = np.stack([w for w, _ in nodes], axis=1)
            W[:, c] = Wk.sum(axis=1)
            A[:, c] = sum(a for _, a in nodes) + polygon_area(Wk)
        return W, A

    def rough_path(self, times) -> RoughPath:
        """The tree on the grid ``times``: a geometric (Stratonovich) :class:`~roughpaths.RoughPath`.

        Its increments have shape ``batch_shape + (n, d)``, its areas ``batch_shape + (n, d, d)``.

        Examples
        --------
        >>> tree = BrownianTree(2, seed=1, batch_shape=(4,))
        >>> X = tree.rough_path([0.0, 0.25, 0.6, 1.0])
        >>> X.increments.shape, X.areas.shape
        ((4, 3, 2), (4, 3, 2, 2))
        """
        W, A = self.increments_and_levy_areas(times)
        t = as_float_array(times, "times", ndim=1)
        return RoughPath(W, A + 0.5 * W[..., :, None] * W[..., None, :], times=t, kind="geometric", check=False)
