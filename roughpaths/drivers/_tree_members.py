r"""Queries of a :class:`~roughpaths.BrownianTree` where every path has times of its own, in one compiled walk.

Adaptive steps per batch member ask each path about a different interval. :func:`member_cells` answers them
all in one compiled call: for each path, the tree's own depth-first walk from the root, splitting the nodes
that hold one of its query points strictly inside (each with the stream of its ``(path, depth, index)``, so
the nodes are bitwise the tree's) and Chen-multiplying the others, left to right, into the cell they lie
in. A path's answer depends on its own times only, bitwise, whatever the other paths of the query; it
equals the tree's answer on shared times (``BrownianTree._cells``) to round-off, since the cells there are
assembled by another order of the same sums.

The children of the last three nodes split at each depth of each path are kept (if 64 MiB hold three such pairs
per depth for every path of the tree; least recently used first out): consecutive attempts of a path share
their ancestors, so a walk starts at the deepest kept node that holds all its times and splits only the few
nodes near its new times (the same nodes, Chen-multiplied in the same order, as a walk from the root). A
rejected attempt's retry ends between the nodes its halves split, which one slot per depth had overwritten:
with three slots a path-attempt of the noise-burst problem (:mod:`roughpaths.rde.adaptive`, 64 paths, rtol
1e-3) splits 2.65 nodes instead of 3.74 (2.79 with two slots, 2.63 with four), about 5.3 µs per path and
attempt instead of 7: the splits, about 1.5-2 µs each, and 0.7 µs of walking and Chen products. Compiling :func:`_walk_nb` (first call, empty
cache) costs about 2.7 s of CPU after the tree's split kernel (``_refine_segments_nb``, 2.8 s, compiled with it
on a first adaptive solve), of which about 1 s re-optimises that kernel's code linked into the walk (load 3;
the three slots compile in the same time as one: 2.6-2.7 s against 2.3-2.9 s, load 3.6-3.8); from numba's
cache, 0.03 s.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._random import _pcg64_fill, _stream_states
from ._tree_kernels import _refine_segments_nb, split_width

__all__ = ["member_cells"]

_WALK_CACHE_BYTES = 64 * 2 ** 20
_SLOTS = 3            # kept splits per depth and row (module docstring)


@njit(cache=True, nogil=True)
def _walk_nb(prefix, root_w, root_G, rows, keys, idx, L, span, tag, width, W, A, cidx, cw, cG):
    """Row by row, the tree's depth-first walk for the cells ``idx[q]`` (see :func:`member_cells`). The children
    of the last ``S`` nodes split at each depth of each tree row are kept in ``cidx, cw, cG`` (``cidx[r, depth,
    :S]`` their parents' indices, -1: none, ``cidx[r, depth, S:]`` the slots from the most to the least recently
    used; with ``cidx.shape[0] == 0`` a scratch cache of one row serves each query). A node on the walk's stack
    is read where it is kept (the root, or its parent's slot of children): the walk is depth first, so no other
    node of a depth is split between a split (or a hit) and the reading of both children it holds; a split
    writes its children into the least recently used slot of its depth. A node inside a cell is reduced here
    (the arithmetic of ``reduce_node``, one compiled kernel less to link). No array assignments: numba compiles
    a shape check with a formatted error message for them (about 3 s)."""
    Q, n = idx.shape[0], idx.shape[1] - 1
    nseg, d = root_w.shape[1], root_w.shape[2]
    m = prefix.size
    caching = cidx.shape[0] > 0
    S = cw.shape[2]
    sd, si = np.empty(L + 4, dtype=np.int64), np.empty(L + 4, dtype=np.int64)
    ent = np.empty((1, m + 5), dtype=np.uint32)
    states = np.empty((1, 4), dtype=np.uint64)
    z, Wn, An = np.empty((1, width)), np.empty(d), np.empty((d, d))
    words = np.empty(width + 64, dtype=np.uint64)
    kidx = np.empty((1 if caching else L + 1, 2 * S), dtype=np.int64)         # reset per row below
    zero = np.int64(0)                # not the literal 0, which numba compiles as a variant of its own
    kw = np.empty((1 if caching else L + 1, S, 2, nseg, d))
    kG = np.empty((1 if caching else L + 1, S, 2, d, d))
    for j in range(m):
        ent[0, j] = prefix[j]
    ent[0, m] = tag
    for q in range(Q):
        r = rows[q]
        if caching:
            ri, rw, rG = cidx[r], cw[r], cG[r]
        else:
            ri, rw, rG = kidx, kw, kG
            for j in range(L + 1):
                for u in range(S):
                    ri[j, u] = -1
                    ri[j, S + u] = u
        for c in range(n):
            for a in range(d):
                W[q, c, a] = 0.0
                for b in range(d):
                    A[q, c, a, b] = 0.0
        first, last = idx[q, 0], idx[q, n]
        # start at the deepest node holding [first, last) whose state is kept (the root at worst): the nodes
        # above it hold a query point strictly inside and would only be descended through
        start = L - 1
        while start > 0 and (first >> (L - start)) != ((last - 1) >> (L - start)):
            start -= 1
        while start > 0:
            u = 0
            while u < S and ri[start - 1, u] != (first >> (L - start + 1)):
                u += 1
            if u < S:
                break
            start -= 1
        sd[0], si[0] = start, first >> (L - start)
        top = 1
        while top > 0:
            top -= 1
            depth, index = sd[top], si[top]
            size = np.int64(1) << (L - depth)
            lo = index * size
            if lo + size <= first or lo >= last:
                continue
            if depth == 0:
                w, G = root_w[r:r + 1], root_G[r:r + 1]
            else:
                u = 0
                while ri[depth - 1, u] != (index >> 1):       # the parent's slot (kept, see above)
                    u += 1
                h = index & 1
                w, G = rw[depth - 1, u, h:h + 1], rG[depth - 1, u, h:h + 1]
            k = 0
            while k <= n and idx[q, k] <= lo:
                k += 1
            if k > n or idx[q, k] >= lo + size:            # within cell k - 1: Chen-multiply it in
                c = k - 1
                for a in range(d):                    # the node's increment and Lévy area (reduce_node)
                    Wn[a] = 0.0
                    for b in range(d):
                        An[a, b] = G[0, a, b]
                for i in range(nseg):
                    for a in range(d):
                        for b in range(a + 1, d):
                            v = 0.5 * (Wn[a] * w[0, i, b] - Wn[b] * w[0, i, a])
                            An[a, b] += v
                            An[b, a] -= v
                    for a in range(d):
                        Wn[a] += w[0, i, a]
                for a in range(d):
                    for b in range(d):
                        A[q, c, a, b] += An[a, b] + 0.5 * (W[q, c, a] * Wn[b] - W[q, c, b] * Wn[a])
                for a in range(d):
                    W[q, c, a] += Wn[a]
                continue
            pos = 0                                   # the node's slot in the recency order (S - 1: evicted)
            while pos < S - 1 and ri[depth, ri[depth, S + pos]] != index:
                pos += 1
            u = ri[depth, S + pos]
            for v in range(pos, 0, -1):               # now the most recently used
                ri[depth, S + v] = ri[depth, S + v - 1]
            ri[depth, S] = u
            if ri[depth, u] != index:
                ent[0, m + 1] = keys[q]
                ent[0, m + 2] = depth
                ent[0, m + 3] = index >> 32
                ent[0, m + 4] = index & 0xFFFFFFFF
                _stream_states(ent, states)
                _pcg64_fill(states, zero, z[0], words)    # _pcg64_normals of one row, without its pair kernel
                _refine_segments_nb(w, G, span / float(np.int64(1) << depth) / nseg, z,
                                    rw[depth, u].reshape((1, 2 * nseg, d)), rG[depth, u, 0:1], rG[depth, u, 1:2])
                ri[depth, u] = index
            sd[top], si[top] = depth + 1, 2 * index + 1          # the right child, then the left (popped first)
            sd[top + 1], si[top + 1] = depth + 1, 2 * index
            top += 2


def member_cells(tree, rows, idx, tag):
    """``(W (Q, n, d), A (Q, n, d, d))``: row ``q`` of ``tree`` (flat index ``rows[q]``) on the grid cells
    ``[idx[q, k], idx[q, k + 1])`` (``idx (Q, n + 1)`` strictly increasing grid indices per row; ``tag`` the
    tree's split stream tag). Needs the tree's seeded fast path (``tree._prefix``)."""
    if tree._root_node is None:
        tree._root_node = tree._root()
    w, G = tree._root_node
    Q, n, d = idx.shape[0], idx.shape[1] - 1, tree.dim
    W, A = np.empty((Q, n, d)), np.empty((Q, n, d, d))
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    cache = tree.__dict__.get("_walk_cache")
    if cache is None:            # the children of _SLOTS nodes per depth and row, if 64 MiB hold them
        P, D, nseg, S = tree.n_paths, tree.resolution + 1, w.shape[1], _SLOTS
        R = P if P * D * S * (2 * nseg * d + 2 * d * d + 2) * 8.0 <= _WALK_CACHE_BYTES else 0
        order = np.broadcast_to(np.arange(S), (R, D, S))
        cache = tree._walk_cache = (np.concatenate([np.full((R, D, S), -1, dtype=np.int64), order], axis=-1),
                                    np.empty((R, D, S, 2, nseg, d)), np.empty((R, D, S, 2, d, d)))
    _walk_nb(tree._prefix, np.ascontiguousarray(w), np.ascontiguousarray(G), rows, tree._paths[rows],
             np.ascontiguousarray(idx, dtype=np.int64), tree.resolution, float(tree.t1 - tree.t0), tag,
             split_width(w.shape[1], d), W, A, *cache)
    return W, A
