r"""Compiled so(3) kernels of the coadjoint solvers (quadratic Hamiltonian): an implementation detail.

:class:`~mechanics.integrators.base.CoadjointSolver.integrate` selects them when the system's algebra
is a :class:`~mechanics.systems.lie_algebra.SO3Algebra` and its Hamiltonian is quadratic; they compute the
same scheme as the numpy path (:mod:`mechanics.integrators.base`), not bit for bit.

Layout: the state lives in three contiguous rows ``m[0], m[1], m[2]`` (one entry per batch member)
and every step is a loop over members whose body is pure arithmetic, so LLVM vectorises it (SIMD over
members; no fast-math, so the vector and scalar loops round alike). All constants are unpacked into
scalars before the loops. The Rodrigues factors use the Taylor branch (exact in float64 for
``|sigma|² < 1e-2``, no trig); members whose ``|sigma|²`` exceeds it (or is not finite) keep their old
state in the vector loop, are flagged, and are redone by the scalar exact step. Each member's result
depends on its own data only, and a member that fails (non-finite, or a chord iteration that does
not converge) is marked by itself; the others go on.
"""

from __future__ import annotations

import functools

import numba
import numpy as np

from ..systems.lie_algebra import SMALL_ANGLE2, taylor_coefficients
from roughpaths.validation import parallel_ranges
from ._so3_scalar import CHORD_FAILED, NON_FINITE, OK, so3_rare_steps, so3_scalar_steps
from ._soa_rows import saw_rare_step, starts_full

_taylor = numba.njit(cache=True, inline="always")(taylor_coefficients)

# ---------------------------------------------------------------------- numba kernel (so(3), quadratic h)
# Structure-of-arrays block kernels. The state lives in three contiguous rows m[0], m[1], m[2]
# (one entry per path) and every step is a loop over paths whose body is pure arithmetic, so LLVM
# vectorises it (SIMD over paths). All constants are unpacked into scalars before the loops (no
# aliasing with the state rows, nothing recomputed per step). The Rodrigues factors use the Taylor
# branch of the Rodrigues factors (exact in float64 for |sigma|² < 1e-2, no trig); paths whose |sigma|² exceeds it
# keep their old state in the vector loop, are flagged, and are redone by the scalar exact step.
_NCOEF = 30
__all__ = ["CHORD_FAILED", "NON_FINITE", "OK", "integrate_so3", "so3_member_steps"]


def coefficients(data):
    """Flat float64 vector of the kernel constants from ``LiePoissonSystem.quadratic_velocity_data()``:
    Q (9), b + shift (3), theta·M⁻¹ (9), dissipation change (3), spare."""
    coef = np.zeros(_NCOEF)
    coef[0:9] = data["q"].ravel()
    coef[9:12] = data["linear"]
    coef[12:21] = (data["theta"] * data["metric_inv"]).ravel()
    coef[21:24] = data["dissipation_change"]
    return coef


@numba.njit(cache=True, inline="always")
def _so3_vector_steps(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta, first_bad, reason, k):
    """Advance every member of ``m`` (3, B) by one Lie–Euler (``code`` 0) or Lie–Heun (1) step with stochastic
    velocities ``e`` (3, B), in the vectorised loop. A member whose ``|sigma|²`` is past the Taylor branch (or
    non-finite) keeps its state and is flagged in ``bad``: the exact scalar step
    (:func:`._so3_scalar.so3_rare_steps`) redoes it. Returns minus the number of flagged members that have not failed before (0: the step is done).
    """
    nb = m.shape[1]
    ma, mb, mc = m[0], m[1], m[2]
    ea, eb, ec = e[0], e[1], e[2]
    nbad = 0
    q00, q01, q02, q10, q11, q12, q20, q21, q22 = (coef[0], coef[1], coef[2], coef[3], coef[4], coef[5],
                                                   coef[6], coef[7], coef[8])
    l0, l1, l2 = coef[9], coef[10], coef[11]
    f0, f1, f2 = coef[21], coef[22], coef[23]     # gradient change inside the double bracket
    n00, n01, n02, n10, n11, n12, n20, n21, n22 = (coef[12], coef[13], coef[14], coef[15], coef[16],
                                                   coef[17], coef[18], coef[19], coef[20])
    hdt = 0.5 * dt
    for p in range(nb):
        m0 = ma[p]
        m1 = mb[p]
        m2 = mc[p]
        e0 = ea[p]
        e1 = eb[p]
        e2 = ec[p]
        # w(mu) = g + theta M⁻¹ (mu × (g + f)), g = Q mu + b + shift, f = shift_dissipation - shift
        g0 = q00 * m0 + q01 * m1 + q02 * m2 + l0
        g1 = q10 * m0 + q11 * m1 + q12 * m2 + l1
        g2 = q20 * m0 + q21 * m1 + q22 * m2 + l2
        v0 = m1 * (g2 + f2) - m2 * (g1 + f1)
        v1 = m2 * (g0 + f0) - m0 * (g2 + f2)
        v2 = m0 * (g1 + f1) - m1 * (g0 + f0)
        w0 = g0 + n00 * v0 + n01 * v1 + n02 * v2
        w1 = g1 + n10 * v0 + n11 * v1 + n12 * v2
        w2 = g2 + n20 * v0 + n21 * v1 + n22 * v2
        s0 = w0 * dt + e0
        s1 = w1 * dt + e1
        s2 = w2 * dt + e2
        if code == 1:
            # predictor mu* = (1 + ad*_s + ½ ad*_s²) mu, corrector s = ½(w(mu) + w(mu*)) dt + e
            c0 = m1 * s2 - m2 * s1
            c1 = m2 * s0 - m0 * s2
            c2 = m0 * s1 - m1 * s0
            y0 = m0 + c0 + 0.5 * (c1 * s2 - c2 * s1)
            y1 = m1 + c1 + 0.5 * (c2 * s0 - c0 * s2)
            y2 = m2 + c2 + 0.5 * (c0 * s1 - c1 * s0)
            g0 = q00 * y0 + q01 * y1 + q02 * y2 + l0
            g1 = q10 * y0 + q11 * y1 + q12 * y2 + l1
            g2 = q20 * y0 + q21 * y1 + q22 * y2 + l2
            v0 = y1 * (g2 + f2) - y2 * (g1 + f1)
            v1 = y2 * (g0 + f0) - y0 * (g2 + f2)
            v2 = y0 * (g1 + f1) - y1 * (g0 + f0)
            s0 = (w0 + g0 + n00 * v0 + n01 * v1 + n02 * v2) * hdt + e0
            s1 = (w1 + g1 + n10 * v0 + n11 * v1 + n12 * v2) * hdt + e1
            s2 = (w2 + g2 + n20 * v0 + n21 * v1 + n22 * v2) * hdt + e2
        # exp(ad*_s) m = m - a s×m + b s×(s×m), Taylor to t^8 (exact in float64 for t² < 1e-2)
        t2 = s0 * s0 + s1 * s1 + s2 * s2
        big = not (t2 < SMALL_ANGLE2)           # also NaN: redone (and diagnosed) by the scalar step
        bad[p] = big
        nbad += big
        a, b, _ = _taylor(t2)
        c0 = s1 * m2 - s2 * m1
        c1 = s2 * m0 - s0 * m2
        c2 = s0 * m1 - s1 * m0
        d0 = s1 * c2 - s2 * c1
        d1 = s2 * c0 - s0 * c2
        d2 = s0 * c1 - s1 * c0
        ma[p] = m0 if big else m0 - a * c0 + b * d0
        mb[p] = m1 if big else m1 - a * c1 + b * d1
        mc[p] = m2 if big else m2 - a * c2 + b * d2
    nlazy = 0
    if nbad > 0:
        for p in range(nb):
            if bad[p] and first_bad[p] < 0:
                nlazy += 1
    return -nlazy


@numba.njit(cache=True, inline="always")
def _so3_full_steps(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta, first_bad, reason, k):
    """:func:`_so3_vector_steps`, then the exact scalar step for the members it flagged, in the same kernel.
    Returns the number of members that failed for the first time."""
    if _so3_vector_steps(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta, first_bad, reason, k) < 0:
        return so3_scalar_steps(m[0], m[1], m[2], e[0], e[1], e[2], bad, dt, q, lin, minv, theta, code, tol,
                                 max_iter, first_bad, reason, k)
    return 0


@numba.njit(cache=True, inline="always")
def _so3_midpoint_steps(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta, first_bad, reason, k):
    """One implicit-midpoint step (``code`` 2) of every member of ``m`` (3, B): the scalar chord solve per member
    (:func:`._so3_scalar.so3_scalar_steps`). Returns the number of members that failed for the first time."""
    for p in range(m.shape[1]):
        bad[p] = True
    return so3_scalar_steps(m[0], m[1], m[2], e[0], e[1], e[2], bad, dt, q, lin, minv, theta, code, tol, max_iter,
                             first_bad, reason, k)


@functools.lru_cache(maxsize=32)
def _pairs(nm: int):
    """The pairs ``i < j`` of ``nm`` noise components (``numpy.triu_indices`` order), as int64 arrays."""
    pi, pj = np.triu_indices(nm, 1)
    return pi.astype(np.int64), pj.astype(np.int64)


#: Steps whose stochastic velocities are formed at a time (a (members, steps, 3) tile that stays in cache).
_TILE = 32


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _velocities(dX, dXX, xi, brk, pi, pj, k0, tile):
    """``tile[p, t]`` <- the stochastic velocity of member ``p`` at step ``k0 + t``:
    Σ_i dX_i ξ_i + Σ_{i<j} A_ij [ξ_i, ξ_j], ``A = ½(XX - XXᵀ)`` (no area term when ``dXX`` is empty).

    ``dX`` (B, K, m); ``dXX`` (B, K, m, m) or empty; ``xi`` (m, 3); ``brk`` (npair, 3) the brackets of the
    pairs ``pi < pj`` (``numpy.triu_indices`` order); ``tile`` (B, T, 3). Each sum runs from 0.0 in this
    order (``LiePoissonSystem.stochastic_velocity`` up to round-off). Member by member, so the increments
    and areas are read in memory order.
    """
    nb, nt = tile.shape[0], min(tile.shape[1], dX.shape[1] - k0)
    nm = dX.shape[2]
    area = dXX.shape[0] > 0
    if nm == 3:                                 # the same sums written out (measured 2x faster with the area)
        x00, x01, x02, x10, x11, x12 = xi[0, 0], xi[0, 1], xi[0, 2], xi[1, 0], xi[1, 1], xi[1, 2]
        x20, x21, x22 = xi[2, 0], xi[2, 1], xi[2, 2]
        b00, b01, b02, b10, b11, b12 = brk[0, 0], brk[0, 1], brk[0, 2], brk[1, 0], brk[1, 1], brk[1, 2]
        b20, b21, b22 = brk[2, 0], brk[2, 1], brk[2, 2]
        for p in range(nb):
            for t in range(nt):
                k = k0 + t
                x = dX[p, k, 0]
                e0 = 0.0 + x * x00
                e1 = 0.0 + x * x01
                e2 = 0.0 + x * x02
                x = dX[p, k, 1]
                e0 += x * x10
                e1 += x * x11
                e2 += x * x12
                x = dX[p, k, 2]
                e0 += x * x20
                e1 += x * x21
                e2 += x * x22
                if area:
                    a = 0.5 * (dXX[p, k, 0, 1] - dXX[p, k, 1, 0])
                    e0 += a * b00
                    e1 += a * b01
                    e2 += a * b02
                    a = 0.5 * (dXX[p, k, 0, 2] - dXX[p, k, 2, 0])
                    e0 += a * b10
                    e1 += a * b11
                    e2 += a * b12
                    a = 0.5 * (dXX[p, k, 1, 2] - dXX[p, k, 2, 1])
                    e0 += a * b20
                    e1 += a * b21
                    e2 += a * b22
                tile[p, t, 0] = e0
                tile[p, t, 1] = e1
                tile[p, t, 2] = e2
        return
    for p in range(nb):
        for t in range(nt):
            k = k0 + t
            e0 = 0.0
            e1 = 0.0
            e2 = 0.0
            for i in range(nm):
                x = dX[p, k, i]
                e0 += x * xi[i, 0]
                e1 += x * xi[i, 1]
                e2 += x * xi[i, 2]
            if area:
                for r in range(pi.shape[0]):
                    i, j = pi[r], pj[r]
                    a = 0.5 * (dXX[p, k, i, j] - dXX[p, k, j, i])
                    e0 += a * brk[r, 0]
                    e1 += a * brk[r, 1]
                    e2 += a * brk[r, 2]
            tile[p, t, 0] = e0
            tile[p, t, 1] = e1
            tile[p, t, 2] = e2


@numba.njit(cache=True, inline="always")
def _so3_dx_block(step, m, dX, dXX, xi, brk, pi, pj, dts, e, bad, coef, code, tol, max_iter, q, lin, minv, theta,
                  save, out, first_bad, reason, stop, k0, eout):
    """Advance m (3, B) over the increments ``dX`` (B, K, m) and areas ``dXX`` from step ``k0`` on
    (:func:`_velocities`, formed :data:`_TILE` steps at a time); after step k with ``save[k]`` the state goes to
    the next slot of out (B, S, 3). With ``stop``, returns after the first step at which a member failed.
    Returns ``-1`` when done (or stopped), or the step ``k`` whose members flagged in ``bad`` need the exact
    scalar step (Lie–Euler, Lie–Heun): their state is left as before step ``k``, the step's stochastic
    velocities are in ``eout`` (B, 3), and step ``k`` is not saved yet."""
    nb = m.shape[1]
    slot = 0
    for k in range(k0):
        if save[k]:
            slot += 1
    tile = np.empty((nb, _TILE, 3))
    for k in range(k0, dX.shape[1]):
        t = (k - k0) % _TILE
        if t == 0:
            _velocities(dX, dXX, xi, brk, pi, pj, k, tile)
        for p in range(nb):
            e[0, p] = tile[p, t, 0]
            e[1, p] = tile[p, t, 1]
            e[2, p] = tile[p, t, 2]
        nnew = step(m, e, dts[k], coef, code, tol, max_iter, bad, q, lin, minv, theta, first_bad, reason, k)
        if nnew < 0:
            for p in range(nb):
                eout[p, 0], eout[p, 1], eout[p, 2] = e[0, p], e[1, p], e[2, p]
            return k
        if save[k]:
            for p in range(nb):
                out[p, slot, 0] = m[0, p]
                out[p, slot, 1] = m[1, p]
                out[p, slot, 2] = m[2, p]
            slot += 1
        if stop and nnew > 0:
            return -1
    return -1


#: Members per block of the thread split (each block runs all its steps on one thread).
BLOCK = 256


@functools.lru_cache(maxsize=None)
def _range_kernel(C: int, full: bool):
    """The compiled :func:`_so3_dx_block` over a range of members for scheme ``C`` (0 Lie–Euler, 1 Lie–Heun,
    2 implicit midpoint), a compile-time constant: each scheme is its own kernel, compiled on first use and
    cached, so a Lie–Heun solve does not compile the chord iteration of the midpoint rule.

    Lie–Euler and Lie–Heun come in two variants. The first (``full=False``) has the vectorised loop only and
    returns at a step that needs the exact scalar step (a member with ``|sigma|²`` past the Taylor branch, or
    non-finite); :func:`integrate_so3` then does that step (:func:`._so3_scalar.so3_rare_steps`) and runs the
    rest of the solve with the second (``full=True``), which has the scalar step inline. A solve that never needs the scalar
    step compiles only the first (about 1.4 s of CPU less); one that does compiles both, once per cache."""
    F = bool(full)             # closure constants (ints and bools only: they key numba's cache)

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def so3_range(y, dX, dXX, xi, brk, pi, pj, dts, coef, code, tol, max_iter, q, lin, minv, theta, save, out,
                  first_bad, reason, stop, bad, eout, lo, hi, k0):
        """Run :func:`_so3_dx_block` on members ``lo .. hi-1`` of ``y`` (B, 3) from step ``k0`` (one block of the
        thread split; a member's result does not depend on its block); ``code`` is the variant's ``C``. Returns
        what :func:`_so3_dx_block` returns; the state is written back to ``y`` either way."""
        bc = hi - lo
        m = np.empty((3, bc))
        for p in range(bc):
            for i in range(3):
                m[i, p] = y[lo + p, i]
        dXb, dXXb, e = dX[lo:hi], dXX[lo:hi] if dXX.shape[0] > 0 else dXX, np.empty((3, bc))
        bb, ob, fb, rb, eb = bad[lo:hi], out[lo:hi], first_bad[lo:hi], reason[lo:hi], eout[lo:hi]
        if C == 2:
            k = _so3_dx_block(_so3_midpoint_steps, m, dXb, dXXb, xi, brk, pi, pj, dts, e, bb, coef, C, tol, max_iter, q, lin,
                              minv, theta, save, ob, fb, rb, stop, k0, eb)
        elif F:
            k = _so3_dx_block(_so3_full_steps, m, dXb, dXXb, xi, brk, pi, pj, dts, e, bb, coef, C, tol, max_iter, q, lin,
                              minv, theta, save, ob, fb, rb, stop, k0, eb)
        else:
            k = _so3_dx_block(_so3_vector_steps, m, dXb, dXXb, xi, brk, pi, pj, dts, e, bb, coef, C, tol, max_iter, q, lin,
                              minv, theta, save, ob, fb, rb, stop, k0, eb)
        for p in range(bc):
            for i in range(3):
                y[lo + p, i] = m[i, p]
        return k

    return so3_range


def _readonly(a):
    """A read-only view: the kernel then compiles one signature whether the driver's arrays are writable or not."""
    v = a.view()
    v.flags.writeable = False
    return v


def integrate_so3(system, code, tol, max_iter, y, dX, dXX, dts, save, stop_on_failure):
    """Run the so(3) kernel on ``y`` (B, 3) driven by ``dX`` (B, K, m) and ``dXX`` (B, K, m, m) or None;
    returns (y, saved, first_bad, reason).

    Blocks of :data:`BLOCK` members run in parallel (:func:`roughpaths.validation.parallel_ranges`;
    ``numba.set_num_threads``); each forms its stochastic velocities step by step, so no (B, K, 3) array
    of them is written."""
    data = system.quadratic_velocity_data()
    nb, nk, nm = dX.shape
    coef = coefficients(data)
    lin = np.concatenate([data["linear"], data["dissipation_change"]])
    y = np.array(y, dtype=np.float64, order="C")
    out = np.full((nb, int(np.count_nonzero(save)), 3), np.nan)
    first_bad = np.full(nb, -1, dtype=np.int64)
    reason = np.zeros(nb, dtype=np.int8)
    pi, pj = _pairs(nm)
    brk = np.ascontiguousarray(system.xi_brackets[pi, pj])
    bad, eout = np.zeros(nb, dtype=np.bool_), np.empty((nb, 3))
    args = (y, _readonly(dX), _readonly(np.empty((0, 0, 0, 0)) if dXX is None else dXX),
            np.ascontiguousarray(system.xi, dtype=np.float64), brk, pi, pj, np.ascontiguousarray(dts, dtype=np.float64),
            coef, code, float(tol), int(max_iter), data["q"], lin, data["metric_inv"], float(data["theta"]),
            np.ascontiguousarray(save, dtype=np.bool_), out, first_bad, reason, bool(stop_on_failure), bad, eout)
    key = ("so3", int(code))
    kernel = _range_kernel(int(code), code != 2 and starts_full(
        key, system, y, dX, dXX, dts, lambda sig: np.any(~(np.sum(sig * sig, -1) < SMALL_ANGLE2))))

    def run(lo, hi):
        k = kernel(*args, lo, hi, 0)
        if k < 0:
            return
        # a step the vector loop left to the exact scalar step: do it, then go on with the variant that has it
        saw_rare_step(key)
        nnew = so3_rare_steps(y[lo:hi], eout[lo:hi], bad[lo:hi], float(dts[k]), data["q"], lin, data["metric_inv"],
                               float(data["theta"]), int(code), float(tol), int(max_iter), first_bad[lo:hi],
                               reason[lo:hi], k)
        if args[16][k]:
            out[lo:hi, np.count_nonzero(args[16][:k])] = y[lo:hi]
        if not ((stop_on_failure and nnew > 0) or k + 1 == nk):
            _range_kernel(int(code), True)(*args, lo, hi, k + 1)

    parallel_ranges(run, nb, BLOCK)
    return y, out, first_bad, reason


@functools.lru_cache(maxsize=None)
def _member_kernel(C: int):
    """The exact scalar step (:func:`._so3_scalar.so3_scalar_steps`) of scheme ``C`` for members each on a step of its
    own (``dt (B,)``), compiled per scheme: with ``C`` a compile-time constant the chord iteration of the implicit
    midpoint rule is left out of the Lie–Euler and Lie–Heun kernels. Compiling (first adaptive so(3) solve, empty
    cache, load about 1): about 1 s for one scheme, against 3 s for the kernel with ``C`` read at run time."""

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def so3_members(ma, mb, mc, ea, eb, ec, every, dt, q, lin, minv, theta, tol, max_iter, first_bad, reason):
        return so3_scalar_steps(ma, mb, mc, ea, eb, ec, every, dt, q, lin, minv, theta, C, tol, max_iter, first_bad,
                                reason, 0)

    return so3_members


def so3_member_steps(system, code, tol, max_iter, mu, dt, eta):
    """One step of every member on its own step (contract item 10: adaptive steps per member), compiled: the exact
    scalar step of the block kernels' rare members (:func:`_member_kernel`) with member ``p``'s ``dt[p]``; ``mu``,
    ``eta`` (B, 3), ``dt`` (B,). Returns ``(mu, ok, converged)`` as the numpy path's ``_advance`` does: a failed
    member NaN, ``ok`` False; ``converged`` (the implicit midpoint, ``code`` 2) False where its chord iteration did
    not converge, else None.

    The numpy path's scheme to round-off (its exponential in closed form, ``Ad_star_exp``), in a loop over members
    instead of some forty numpy calls a step: the stochastic rigid body, LieHeun adaptive per member, 1000 paths at
    rtol 1e-3, 0.81-0.86 s of CPU against 0.94-1.12 s (interleaved, one thread; the tree's walk is most of it)."""
    data = system.quadratic_velocity_data()
    B = mu.shape[0]
    cols = [np.array(mu[:, i], dtype=np.float64) for i in range(3)]
    first_bad, reason = np.full(B, -1, dtype=np.int64), np.zeros(B, dtype=np.int8)
    own = lambda a: np.array(a, dtype=np.float64, order="C")      # noqa: E731  writeable copies: one signature
    _member_kernel(int(code))(*cols, *(own(eta[:, i]) for i in range(3)), np.ones(B, dtype=np.bool_), own(dt),
                              own(data["q"]), np.concatenate([data["linear"], data["dissipation_change"]]),
                              own(data["metric_inv"]), float(data["theta"]), float(tol), int(max_iter), first_bad,
                              reason)
    return np.stack(cols, axis=-1), first_bad < 0, (reason != CHORD_FAILED) if code == 2 else None
