r"""Queries of a :class:`~roughpaths.BrownianTree` where every path has times of its own, in one compiled walk.

Adaptive steps per batch member ask each path about a different interval. :func:`member_cells` answers them
all in one compiled call: for each path, the tree's own depth-first walk from the root, splitting the nodes
that hold one of its query points strictly inside (each with the stream of its ``(path, depth, index)``, so
the nodes are bitwise the tree's) and Chen-multiplying the others, left to right, into the cell they lie
in. A path's answer depends on its own times only, bitwise, whatever the other paths of the query; it
equals the tree's answer on shared times (``BrownianTree._cells``) to round-off, since the cells there are
assembled by another order of the same sums.

The children of the last two nodes split at each depth of each path are kept (if 64 MiB hold two such pairs per
depth for every path of the tree, else one pair if that fits; the pair used less recently is replaced): consecutive
attempts of a path share their ancestors, so a walk starts at the deepest kept node that holds all its times and
splits only the few nodes near its new times (the same nodes, Chen-multiplied in the same order, as a walk from the
root). A rejected attempt's retry ends between the nodes its halves split, which one pair per depth had
overwritten. Adaptive steps of the noise-burst problem (:mod:`roughpaths.rde.adaptive`, 64 paths, rtol 1e-3): 2.79
splits per path-attempt (3.74 with one pair per depth, 2.65 with three, 2.63 with four), about 5 µs per path and
attempt (7 with one pair): the splits, about 1.5-2 µs each, and 0.7 µs of walking and Chen products. Since the split
kernel's rewrite (the same bits), 3.2 µs against 4.3 (the solve's 97 149 path-queries replayed on one thread): per
split about 0.07 µs of seeding, 0.4 µs of normals (65 at d = 2) and 0.4 µs of the split's arithmetic; the rigid body
(d = 3, 3.6 splits per path-attempt, 105 normals each) 5.4 µs against 6.2-6.7. Compiling
:func:`_walk_nb` (first call, empty cache) costs about 2.7 s of CPU after the tree's split kernel
(``_refine_segments_nb``, 2.8 s, compiled with it on a first adaptive solve), of which about 1 s re-optimises that
kernel's code linked into the walk; from numba's cache, 0.03 s. (Measured at load 1.3-1.4: 2.60-2.73 s, against
2.54-2.62 s with one pair per depth; at load 2.3-2.9, three pairs kept in least-recently-used order took 2.7-3.0 s
against 2.2-2.4 s, more compile than their 0.03 s per solve is worth.) Measured again at load 1 (exclusive compile
times from numba's events): ``_walk_nb`` 2.1-2.4 s, ``_refine_segments_nb`` 1.4-1.6 s, its ``_solve_pairs`` 0.45-0.6 s;
after the split kernel's rewrite (its pair solves for ``d = 2, 3`` written out; 14 runs at load about 1) 2.4-2.7 s,
1.3-1.5 s and 0.8-1.1 s.
Inlining (``inline="always"``) does not pay here: ``_refine_segments_nb`` inlined into the walk took 5.4 s against
4.2 s for the three kernels apart (numba copies and re-types the callee's IR per call site, and the code that LLVM
re-optimises inside the walk is only about a third of a kernel's compile), and ``_stream_states`` or
``_solve_pairs`` inlined cost 0.3-0.8 s more than compiled apart. Converting and checking the query's times in the
walk (and adding the ``½ W ⊗ W`` of the Stratonovich areas there) added about 0.2 s to its compile and took about
20 µs of numpy calls off each query.

Large queries are walked on numba's threads (:mod:`roughpaths._threads`), in about two contiguous ranges of rows per
thread, once they hold about ``2^20 / 5000`` path-cells (200 paths of an attempt's two halves): the rows are
independent, each keeps its own nodes, so a row's answer is bitwise the same on any number of threads. A query that
asks a tree row twice is walked on the calling thread (two threads would write that row's kept nodes). Adaptive steps
of the stochastic rigid body (1000 paths, rtol 1e-3, quiet 2-core machine, interleaved runs): 0.59-0.62 s of wall
time against 0.87-0.89 s on one thread, for 2-4 % more CPU time; the walk alone (1000 rows) 0.46 against 0.88 s.
The noise burst's 64 paths stay on one thread.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit

from .. import _threads
from ._random import _pcg64_fill, _stream_states
from ._tree_kernels import _refine_segments_nb, split_width

__all__ = ["member_cells"]

_WALK_CACHE_BYTES = 64 * 2 ** 20
#: A row's walk per cell, in the work units of :func:`roughpaths._threads.ranges` (about 5 us: 3 splits)
_WALK_WORK = 5000.0


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _walk_nb(prefix, root_w, root_G, rows, keys, times, t0, t1, idx, L, span, tag, width, W, A, cidx, cw, cG):
    """Row by row, the tree's depth-first walk for the cells ``idx[q]`` (see :func:`member_cells`). The children of
    the last ``S`` (2, or 1 for a tree too large for two) nodes split at each depth of each tree row are kept in
    ``cidx, cw, cG``: slots ``S depth .. S depth + S - 1`` of a row (``DS = S (L + 1)`` slots) hold a pair each,
    ``cidx[r, slot]`` their parent's index (-1: none) and ``cidx[r, DS + depth]`` the slot of the depth used last
    (one flat axis of slots: numba compiles the indexing of one slot per depth); with ``cidx.shape[0] == 0`` a
    scratch cache of one row serves each query. A node on the walk's stack is read where it is kept (the root, or
    its parent's slot of children): the walk is depth first, so no node of a depth is split between a split (or a
    hit) of its parent and the reading of both children it holds; a split replaces the pair of its depth used less
    recently. A node inside a cell is reduced here (the arithmetic of ``reduce_node``, one compiled kernel less to
    link). No array assignments: numba compiles a shape check with a formatted error message for them (about 3 s).

    The cells' ends ``idx (Q, n + 1)`` are the grid indices of ``times`` (rounded to the nearest, at most ``2^L``),
    computed here. Returns 0, or ``q + 1`` for the first row ``q`` whose times are not strictly increasing on the
    grid within ``[t0, t1]`` (nothing walked then; ``t0 + span`` may round below ``t1``). ``A`` receives the Stratonovich areas, the Lévy area plus
    ``½ W ⊗ W``."""
    Q, n = idx.shape[0], idx.shape[1] - 1
    top_index = np.int64(1) << L
    scale = 2.0 ** L
    for q in range(Q):
        for k in range(n + 1):
            v = times[q, k]
            if not (v >= t0 and v <= t1):
                return q + 1
            idx[q, k] = min(np.int64(np.rint((v - t0) / span * scale)), top_index)
            if k > 0 and idx[q, k] <= idx[q, k - 1]:
                return q + 1
    nseg, d = root_w.shape[1], root_w.shape[2]
    m = prefix.size
    caching = cidx.shape[0] > 0
    DS = cw.shape[1]                  # S slots per depth, S (L + 1)
    S = DS // (L + 1)
    sd, si = np.empty(L + 4, dtype=np.int64), np.empty(L + 4, dtype=np.int64)
    ent = np.empty((1, m + 5), dtype=np.uint32)
    states = np.empty((1, 4), dtype=np.uint64)
    z, Wn, An = np.empty((1, width)), np.empty(d), np.empty((d, d))
    words = np.empty(width + 64, dtype=np.uint64)
    kidx = np.empty(1 if caching else DS + L + 1, dtype=np.int64)         # reset per row below
    zero = np.int64(0)                # not the literal 0, which numba compiles as a variant of its own
    kw, kG = np.empty((1 if caching else DS, 2, nseg, d)), np.empty((1 if caching else DS, 2, d, d))
    for j in range(m):
        ent[0, j] = prefix[j]
    ent[0, m] = tag
    for q in range(Q):
        r = rows[q]
        if caching:
            ri, rw, rG = cidx[r], cw[r], cG[r]
        else:
            ri, rw, rG = kidx, kw, kG
            for j in range(DS + L + 1):
                ri[j] = -1 if j < DS else 0
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
        while start > 0 and ri[S * start - S] != (first >> (L - start + 1)) and \
                ri[S * start - 1] != (first >> (L - start + 1)):
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
                u = S * depth - S                             # the parent's slot (kept, see above)
                if ri[u] != (index >> 1):
                    u += 1
                h = index & 1
                w, G = rw[u, h:h + 1], rG[u, h:h + 1]
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
            u = S * depth                             # the depth's slots: u (and u + 1 if S == 2)
            if S == 2 and (ri[u + 1] == index or (ri[u] != index and ri[DS + depth] == 0)):
                u += 1                                # kept there, or a miss and u was used last
            ri[DS + depth] = u - S * depth            # the slot used last
            if ri[u] != index:
                ent[0, m + 1] = keys[q]
                ent[0, m + 2] = depth
                ent[0, m + 3] = index >> 32
                ent[0, m + 4] = index & 0xFFFFFFFF
                _stream_states(ent, states)
                _pcg64_fill(states, zero, z[0], words)    # _pcg64_normals of one row, without its pair kernel
                _refine_segments_nb(w, G, span / float(np.int64(1) << depth) / nseg, z,
                                    rw[u].reshape((1, 2 * nseg, d)), rG[u, 0:1], rG[u, 1:2])
                ri[u] = index
            sd[top], si[top] = depth + 1, 2 * index + 1          # the right child, then the left (popped first)
            sd[top + 1], si[top + 1] = depth + 1, 2 * index
            top += 2
        for c in range(n):
            for a in range(d):
                for b in range(d):
                    A[q, c, a, b] += 0.5 * W[q, c, a] * W[q, c, b]
    return 0


def _walk_parts(Q, n, rows):
    """Ranges of the query's rows for the threads: about ``2 x`` numba's threads of them (a range's call costs
    some 10 us of dispatch) once the walk is worth a hand-off, if no tree row is asked twice (a row's kept
    nodes are written by its walk: two threads must not walk one row)."""
    if Q * n * _WALK_WORK < _threads.SERIAL_WORK or not np.all(rows[1:] > rows[:-1]):
        return [(0, Q)]
    k = min(2 * numba.get_num_threads(), Q)
    step = -(-Q // k)
    return [(lo, min(lo + step, Q)) for lo in range(0, Q, step)]


def member_cells(tree, rows, times, tag):
    """``(W (Q, n, d), XX (Q, n, d, d))``, increments and Stratonovich areas: row ``q`` of ``tree`` (flat index
    ``rows[q]``) between its ``times[q]`` (``(Q, n + 1)``, strictly increasing on the tree's grid in ``[t0, t1]``,
    else a ``ValueError``; ``tag`` the tree's split stream tag). Needs the tree's seeded fast path (``tree._prefix``)."""
    fixed = tree.__dict__.get("_walk_cache")
    if fixed is None:            # the walk's fixed arguments, and the children of two nodes per depth and row (or one)
        if tree._root_node is None:                                     # if 64 MiB hold them
            tree._root_node = tree._root()
        w, G = (np.ascontiguousarray(v) for v in tree._root_node)
        P, D, nseg, d = tree.n_paths, tree.resolution + 1, w.shape[1], tree.dim
        fits = [S for S in (2, 1) if P * D * (S * (2 * nseg * d + 2 * d * d + 1) + 1) * 8.0 <= _WALK_CACHE_BYTES]
        S, R = (fits[0], P) if fits else (1, 0)
        slots = np.concatenate([np.full(S * D, -1), np.zeros(D)]).astype(np.int64)
        fixed = tree._walk_cache = (w, G, float(tree.t0), float(tree.t1), tree.resolution, float(tree.t1 - tree.t0),
                                    split_width(nseg, d), (np.repeat(slots[None], R, axis=0),
                                                           np.empty((R, S * D, 2, nseg, d)), np.empty((R, S * D, 2, d, d))))
    w, G, t0, t1, L, span, width, cache = fixed
    Q, n, d = times.shape[0], times.shape[1] - 1, w.shape[2]
    W, A, idx = np.empty((Q, n, d)), np.empty((Q, n, d, d)), np.empty((Q, n + 1), dtype=np.int64)
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    keys, times = tree._paths[rows], np.ascontiguousarray(times, dtype=np.float64)
    parts = _walk_parts(Q, n, rows)
    bad = np.zeros(len(parts), dtype=np.int64)

    def walk(i, lo, hi):
        bad[i] = _walk_nb(tree._prefix, w, G, rows[lo:hi], keys[lo:hi], times[lo:hi], t0, t1, idx[lo:hi], L, span,
                          tag, width, W[lo:hi], A[lo:hi], *cache)

    if len(parts) == 1:
        walk(0, 0, Q)
    else:
        index = {p: i for i, p in enumerate(parts)}
        _threads.run(lambda lo, hi: walk(index[lo, hi], lo, hi), parts)
    q = next((int(b) + lo for b, (lo, _) in zip(bad, parts) if b), 0)
    if q:
        raise ValueError(f"times must increase strictly in [t0, t1] = [{tree.t0}, {tree.t1}] on the tree's grid "
                         f"(t1 - t0)·2^-{L}, row by row; row {q - 1} is {np.asarray(times)[q - 1]!r}.")
    return W, A
