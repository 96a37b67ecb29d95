r"""Steps per member on any structure-constant algebra, compiled: each member with a ``dt`` of its own.

Adaptive solves take a step per member (contract item 10); the block kernels of :mod:`._generic_kernels` share one
``dt`` per step across a block (structure of arrays), so they cannot take these. This kernel runs the numpy path's
schemes (:mod:`mechanics.integrators.base`) one member at a time in scalar code, with the pieces of
:mod:`._generic_member`: the velocity :math:`w(\mu)` (:func:`._generic_member.velocity1`), ``ad*`` from the non-zero
structure constants, the exponential (:func:`._generic_member.exp1`: Taylor on the vector to the degree of the
table, scaling and squaring past :data:`._generic_member.THETA_VECTOR`) and the implicit midpoint's chord iteration
(:func:`._generic_member.midpoint1`, compiled for dimensions 3 and 6 as the block kernel is).

What is exact, what is approximate: the same scheme as the numpy path; the exponential's Taylor remainder is below
round-off relative to :math:`|\mu|`, so a step agrees with the numpy path's (a dense ``expm`` or a conjugation of
matrices) to round-off, not bit for bit. A member's bits depend on its own ``mu``, ``eta`` and ``dt`` only.

Compile cost (empty cache, one process, load about 1): Lie–Heun 3.5 s (with the exponential's scaling and
squaring), Lie–Euler 1.6 s more, the implicit midpoint rule 8.3 s (its chord iteration and dimension variant; 2.0 s
where the block kernel's midpoint rule compiled them first). Each scheme is its own kernel, compiled on first use;
``tools/warm_kernels.py`` compiles the Lie–Heun one (``--more`` the others).
"""

from __future__ import annotations

import math
import weakref
from functools import lru_cache

import numba
import numpy as np

from roughpaths.validation import parallel_ranges

from ._generic_member import DEGREE_THETA, DIMS3, DIMS6, ad_star1, exp1, midpoint1, velocity1
from ._soa_rows import CHORD_FAILED, NON_FINITE, algebra_tables, sparse_rows

__all__ = ["generic_member_steps"]

_TABLES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
#: A member-step's cost (ns): a constant and a term per non-zero structure constant (Lie–Heun, measured: su(2) 0.47 µs,
#: su(3) 1.8 µs); the members are split between numba's threads in ranges of about RANGE_NS each.
MEMBER_NS = (300.0, 40.0)
RANGE_NS = 2e5


def _tables(system):
    """The kernel's constants of ``system`` (formed once per system: the non-zeros of ``n³`` structure constants)."""
    if system not in _TABLES:
        data = system.quadratic_velocity_data()
        ti, tj, tk, tv, _, cnorm = algebra_tables(system.algebra.structure_constants)
        theta = float(data["theta"])
        mth = np.array(theta * data["metric_inv"].T, dtype=np.float64, order="C")
        _TABLES[system] = (np.array(data["q"], dtype=np.float64, order="C"), sparse_rows(data["q"]),
                           np.array(data["linear"], dtype=np.float64), np.array(data["dissipation_change"],
                                                                                dtype=np.float64),
                           sparse_rows(mth) + (np.zeros(system.dim),), theta, ti, tj, tk, tv, cnorm)
    return _TABLES[system]


@lru_cache(maxsize=None)
def _member_kernel(C: int, N: int):
    """One step of scheme ``C`` (0 Lie–Euler, 1 Lie–Heun, 2 implicit midpoint) for members each on a step of its own
    (``dt (B,)``). ``C`` is a compile-time constant (Lie–Euler and Lie–Heun compile without the chord iteration);
    ``N`` (3, 6 or 0) the midpoint rule's compile-time dimension. A member whose input, Lie–Heun predictor or result
    is not finite, or whose chord iteration fails, comes back NaN with ``first_bad = 0`` and its ``reason``."""

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def generic_members(y, e, dt, q, qs, lin, f, mts, theta, tol, max_iter, ti, tj, tk, tv, cnorm, degth,
                        first_bad, reason):
        n = y.shape[1]
        V = np.empty((12, n))
        mu, ee, w0, w1, s, a, b, mp, g, t1, t2, new = V[0], V[1], V[2], V[3], V[4], V[5], V[6], V[7], V[8], V[9], \
            V[10], V[11]
        work = (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, 2 * n)),
                np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((8, n)))
        for p in range(y.shape[0]):
            finite_in = True
            for i in range(n):
                mu[i], ee[i] = y[p, i], e[p, i]
                if not (math.isfinite(mu[i]) and math.isfinite(ee[i])):
                    finite_in = False
            ok = finite_in
            chord_failed = False
            if finite_in and C == 2:
                if N == 3:
                    ok, chord_failed = midpoint1(mu, ee, s, new, dt[p], q, qs, lin, f, mts, theta, tol, max_iter,
                                                 ti, tj, tk, tv, cnorm, degth, work, DIMS3)
                elif N == 6:
                    ok, chord_failed = midpoint1(mu, ee, s, new, dt[p], q, qs, lin, f, mts, theta, tol, max_iter,
                                                 ti, tj, tk, tv, cnorm, degth, work, DIMS6)
                else:
                    ok, chord_failed = midpoint1(mu, ee, s, new, dt[p], q, qs, lin, f, mts, theta, tol, max_iter,
                                                 ti, tj, tk, tv, cnorm, degth, work)
            elif finite_in:
                velocity1(mu, qs, lin, f, mts, theta, g, t1, t2, w0, ti, tj, tk, tv)
                for i in range(n):
                    s[i] = w0[i] * dt[p] + ee[i]
                    if not math.isfinite(s[i]):
                        ok = False
                if ok and C == 1:               # predictor mu + a + ½ ad*_s a, a = ad*_s mu; corrector on its velocity
                    ad_star1(s, mu, a, ti, tj, tk, tv)
                    ad_star1(s, a, b, ti, tj, tk, tv)
                    for i in range(n):
                        mp[i] = mu[i] + a[i] + 0.5 * b[i]
                        if not math.isfinite(mp[i]):
                            ok = False
                    velocity1(mp, qs, lin, f, mts, theta, g, t1, t2, w1, ti, tj, tk, tv)
                    for i in range(n):
                        s[i] = 0.5 * (w0[i] + w1[i]) * dt[p] + ee[i]
                if ok:
                    ok = exp1(s, mu, new, work[5], work[6], work[7], work[8][6], work[8][7], ti, tj, tk, tv, cnorm,
                              degth)
            for i in range(n):
                y[p, i] = new[i] if ok else np.nan
            if not ok:
                first_bad[p] = 0
                reason[p] = CHORD_FAILED if chord_failed else NON_FINITE

    return generic_members


def generic_member_steps(system, code, tol, max_iter, mu, dt, eta):
    """One step of every member on its own step (contract item 10: adaptive steps per member), compiled
    (:func:`_member_kernel`); ``mu``, ``eta`` (B, n), ``dt`` (B,), ``system`` on a structure-constant algebra with a
    quadratic Hamiltonian and no forces. Returns ``(mu, ok, converged)`` as the numpy path's ``_advance`` does
    (``converged`` None but for the implicit midpoint, ``code`` 2)."""
    q, qs, lin, f, mts, theta, ti, tj, tk, tv, cnorm = _tables(system)
    B, n = mu.shape
    y = np.array(mu, dtype=np.float64, order="C")
    first_bad, reason = np.full(B, -1, dtype=np.int64), np.zeros(B, dtype=np.int8)
    N = n if code == 2 and n in (3, 6) else 0
    kernel = _member_kernel(int(code), N)
    e, dt = np.array(eta, dtype=np.float64, order="C"), np.array(dt, dtype=np.float64, order="C")   # writeable:
    # whatever views the caller passes, the kernel meets one signature (a read-only dt would compile another)
    parallel_ranges(lambda lo, hi: kernel(y[lo:hi], e[lo:hi], dt[lo:hi], q, qs, lin, f, mts, theta, float(tol),
                                          int(max_iter), ti, tj, tk, tv, cnorm, DEGREE_THETA, first_bad[lo:hi],
                                          reason[lo:hi]),
                    B, max(32, int(RANGE_NS / (MEMBER_NS[0] + MEMBER_NS[1] * tv.shape[0]))))
    return y, first_bad < 0, (reason != CHORD_FAILED) if code == 2 else None
