r"""Queries of a :class:`~roughpaths.BrownianTree` where every path has times of its own, in one vectorised walk.

Adaptive steps per batch member ask each path about a different interval. :func:`member_cells` answers them
all in one descent of the tree, depth by depth: at each depth the nodes of every path that hold one of its
query points strictly inside are split together (one compiled call, each row with the stream of its own
``(path, depth, index)``), and the nodes that lie within one of its cells are reduced together. A cell is
then the Chen product of its canonical dyadic nodes, assembled in left-to-right order by the same formulas
as the tree's own walk (``BrownianTree._cells``), per row; so a path's answer does not depend on the other
paths of the query or on their times (bitwise; ``tests/roughpaths/rde/test_adaptive_per_member_steps.py``).

Cost: a depth costs one split call over the rows that need it and one reduction; a query of ``Q`` paths
with ``n`` cells down to depth ``k`` splits at most ``Q (n + 1) k`` rows (far fewer when the points share
ancestors), with no cache. Compiling :func:`_split_rows_nb` (first call, empty cache) costs about as much
as the tree's own split kernel (see ``benchmarks/bench_first_call.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._random import _pcg64_normals, _pcg64_seed, _seed_states
from ._tree_kernels import _reduce_nb, _refine_segments_nb, polygon_area, reduce_node, split_width

__all__ = ["member_cells"]

_WALK_CACHE_BYTES = 64 * 2 ** 20


@njit(cache=True, nogil=True)
def _walk_nb(prefix, root_w, root_G, rows, keys, idx, L, span, tag, width, W, A, cidx, cw, cG):
    """Row by row, the tree's depth-first walk for the cells ``idx[q]`` (see :func:`member_cells`); the children
    of the last node split at each depth of each tree row are kept in ``cidx, cw, cG`` (``cidx`` -1: none;
    a 1-row cache with ``cidx.shape[0] == 0`` disables it)."""
    Q, n = idx.shape[0], idx.shape[1] - 1
    nseg, d = root_w.shape[1], root_w.shape[2]
    m = prefix.size
    cap = L + 4
    sd, si = np.empty(cap, dtype=np.int64), np.empty(cap, dtype=np.int64)
    sw, sG = np.empty((cap, nseg, d)), np.empty((cap, d, d))
    ent = np.empty((1, m + 5), dtype=np.uint32)
    seeds, states = np.empty((1, 4), dtype=np.uint64), np.empty((1, 4), dtype=np.uint64)
    z, fine = np.empty((1, width)), np.empty((1, 2 * nseg, d))
    GL, GR, Wn, An = np.empty((1, d, d)), np.empty((1, d, d)), np.empty((1, d)), np.empty((1, d, d))
    for q in range(m):
        ent[0, q] = prefix[q]
    ent[0, m] = tag
    for q in range(Q):
        W[q] = 0.0
        A[q] = 0.0
        first, last = idx[q, 0], idx[q, n]
        sd[0], si[0] = 0, 0
        sw[0], sG[0] = root_w[rows[q]], root_G[rows[q]]
        top = 1
        while top > 0:
            top -= 1
            depth, index = sd[top], si[top]
            size = np.int64(1) << (L - depth)
            lo = index * size
            if lo + size <= first or lo >= last:
                continue
            k = 0
            while k <= n and idx[q, k] <= lo:
                k += 1
            if k > n or idx[q, k] >= lo + size:            # within cell k - 1: Chen-multiply it in
                c = k - 1
                _reduce_nb(sw[top:top + 1], sG[top:top + 1], Wn, An)
                for a in range(d):
                    for b in range(d):
                        A[q, c, a, b] += An[0, a, b] + 0.5 * (W[q, c, a] * Wn[0, b] - W[q, c, b] * Wn[0, a])
                for a in range(d):
                    W[q, c, a] += Wn[0, a]
                continue
            r = rows[q]
            if cidx.shape[0] == 0 or cidx[r, depth] != index:
                ent[0, m + 1] = keys[q]
                ent[0, m + 2] = depth
                ent[0, m + 3] = index >> 32
                ent[0, m + 4] = index & 0xFFFFFFFF
                _seed_states(ent, seeds)
                _pcg64_seed(seeds, states)
                _pcg64_normals(states, z)
                _refine_segments_nb(sw[top:top + 1], sG[top:top + 1], span / float(np.int64(1) << depth) / nseg,
                                    z, fine, GL, GR)
                if cidx.shape[0] == 0:
                    sd[top], si[top], sw[top], sG[top] = depth + 1, 2 * index + 1, fine[0, nseg:], GR[0]
                    sd[top + 1], si[top + 1], sw[top + 1], sG[top + 1] = depth + 1, 2 * index, fine[0, :nseg], GL[0]
                    top += 2
                    continue
                cidx[r, depth] = index
                cw[r, depth, 0], cw[r, depth, 1], cG[r, depth, 0], cG[r, depth, 1] = \
                    fine[0, :nseg], fine[0, nseg:], GL[0], GR[0]
            sd[top], si[top], sw[top], sG[top] = depth + 1, 2 * index + 1, cw[r, depth, 1], cG[r, depth, 1]
            sd[top + 1], si[top + 1], sw[top + 1], sG[top + 1] = depth + 1, 2 * index, cw[r, depth, 0], cG[r, depth, 0]
            top += 2


@njit(cache=True, nogil=True)
def _split_rows_nb(prefix, paths, tag, depth, index, width, w, G, delta, fine, GL, GR):
    """``_split_seeded_nb`` with a node index per row: row ``r`` draws from stream ``(tag, paths[r], depth, index[r])``."""
    P = w.shape[0]
    m = prefix.size
    ent = np.empty((P, m + 5), dtype=np.uint32)
    for r in range(P):
        for q in range(m):
            ent[r, q] = prefix[q]
        ent[r, m] = tag
        ent[r, m + 1] = paths[r]
        ent[r, m + 2] = depth
        ent[r, m + 3] = index[r] >> 32
        ent[r, m + 4] = index[r] & 0xFFFFFFFF
    seeds = np.empty((P, 4), dtype=np.uint64)
    _seed_states(ent, seeds)
    states = np.empty((P, 4), dtype=np.uint64)
    _pcg64_seed(seeds, states)
    z = np.empty((P, width))
    _pcg64_normals(states, z)
    _refine_segments_nb(w, G, delta, z, fine, GL, GR)


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
    if cache is None:                     # the children of one node per depth and row, if 64 MiB hold them
        P, D, nseg = tree.n_paths, tree.resolution + 1, w.shape[1]
        R = P if P * D * (2 * nseg * d + 2 * d * d + 1) * 8.0 <= _WALK_CACHE_BYTES else 0
        cache = tree._walk_cache = (np.full((R, D), -1, dtype=np.int64), np.empty((R, D, 2, nseg, d)),
                                    np.empty((R, D, 2, d, d)))
    _walk_nb(tree._prefix, np.ascontiguousarray(w), np.ascontiguousarray(G), rows, tree._paths[rows],
             np.ascontiguousarray(idx, dtype=np.int64), tree.resolution, float(tree.t1 - tree.t0), tag,
             split_width(w.shape[1], d), W, A, *cache)
    return W, A


def _member_cells_numpy(tree, rows, idx, tag):
    """``(W (Q, n, d), A (Q, n, d, d))``: row ``q`` of ``tree`` (flat index ``rows[q]``) on the grid cells
    ``[idx[q, k], idx[q, k + 1])`` (``idx (Q, n + 1)`` strictly increasing grid indices per row; ``tag`` the
    tree's split stream tag). Needs the tree's seeded fast path (``tree._prefix``)."""
    L, d = tree.resolution, tree.dim
    Q, n = idx.shape[0], idx.shape[1] - 1
    if tree._root_node is None:
        tree._root_node = tree._root()
    w, G = tree._root_node
    nseg = w.shape[1]
    fq, fidx, fw, fG = np.arange(Q), np.zeros(Q, dtype=np.int64), w[rows], G[rows]
    first, last = idx[:, 0], idx[:, -1]
    parts, depth = [], 0
    while fq.size:
        size = 1 << (L - depth)
        lo = fidx * size
        g = idx[fq]
        keep = (lo + size > first[fq]) & (lo < last[fq])
        inside = ((g > lo[:, None]) & (g < (lo + size)[:, None])).any(axis=1)
        red = keep & ~inside                                 # within one cell: reduced to its (W, A)
        if red.any():
            Wr, Ar = reduce_node(fw[red], fG[red])
            parts.append((fq[red], (g[red] <= lo[red, None]).sum(axis=1) - 1, lo[red], Wr, Ar))
        sp = keep & inside                                  # a query point strictly inside: split
        if not sp.any():
            break
        fw_s, fG_s = np.ascontiguousarray(fw[sp]), np.ascontiguousarray(fG[sp])
        P = fw_s.shape[0]
        fine, GL, GR = np.empty((P, 2 * nseg, d)), np.empty((P, d, d)), np.empty((P, d, d))
        _split_rows_nb(tree._prefix, tree._paths[rows[fq[sp]]], np.int64(tag), np.int64(depth), fidx[sp],
                       split_width(nseg, d), fw_s, fG_s, float((tree.t1 - tree.t0) / 2 ** depth / nseg), fine, GL, GR)
        fq, fidx = np.concatenate([fq[sp], fq[sp]]), np.concatenate([2 * fidx[sp], 2 * fidx[sp] + 1])
        fw, fG = np.concatenate([fine[:, :nseg], fine[:, nseg:]]), np.concatenate([GL, GR])
        depth += 1
    q, c, lo, Wn, An = (np.concatenate(x) for x in zip(*parts))
    order = np.lexsort((lo, c, q))
    q, c, Wn, An = q[order], c[order], Wn[order], An[order]
    cell = q * n + c
    starts = np.flatnonzero(np.r_[True, cell[1:] != cell[:-1]])
    counts = np.diff(np.r_[starts, cell.size])
    W, A = np.empty((Q, n, d)), np.empty((Q, n, d, d))
    for r in np.unique(counts).tolist():                  # cells of r nodes together, as the tree's walk sums them
        s = starts[counts == r]
        take = s[:, None] + np.arange(r)
        Wk, Ak = Wn[take], An[take]
        acc = 0 + Ak[:, 0]
        for k in range(1, r):
            acc = acc + Ak[:, k]
        W[q[s], c[s]] = Wk.sum(axis=1)
        A[q[s], c[s]] = acc + polygon_area(Wk)
    return W, A
