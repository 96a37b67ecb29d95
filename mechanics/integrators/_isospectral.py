r"""The coadjoint schemes on matrix states: isospectral updates for systems on a :class:`~mechanics.MatrixLieAlgebra`.

The schemes are those of :mod:`mechanics.integrators.base` (Lie–Euler, Lie–Heun, the implicit midpoint),
with the state :math:`\mu` held as its matrix :math:`M` (:meth:`MatrixLieAlgebra.dual_to_matrix`) for a whole
block of steps. The coadjoint update :math:`\mu_{n+1} = \exp(\mathrm{ad}^*_{\sigma_n})\mu_n` is the conjugation

.. math::  M_{n+1} = Q_n M_n Q_n^{-1},\qquad Q_n = e^{-\sigma_n}

(``Q^{-1} = Q^H`` on compact algebras), so :math:`M_{n+1}` has the spectrum of :math:`M_n` and every Casimir
:math:`\mathrm{tr}(M^k)` is kept to round-off; the result is projected back onto the algebra (trace form).
The Lie-algebra increment is built from matrices: :math:`\sigma_n = \bar w\,\Delta t_n + \eta_n` with
:math:`\eta_n = \sum_i\xi_iX^i_n + \sum_{i<j}A^{ij}_n[\xi_i,\xi_j]`
(:meth:`LiePoissonSystem.stochastic_velocity_matrix`) and the drift velocity :math:`w` as a matrix
(:meth:`LiePoissonSystem.drift_velocity_matrix`); the coadjoint operator is :math:`\mathrm{ad}^*_\xi\mu = [M, \xi]`:

* Lie–Euler: :math:`\bar w = w(M_n)`;
* Lie–Heun: :math:`\bar w = \tfrac12(w(M_n) + w(M^*))`, :math:`M^* = M_n + [M_n, \sigma^*] +
  \tfrac12[[M_n, \sigma^*], \sigma^*]`, :math:`\sigma^* = w(M_n)\Delta t + \eta_n`;
* implicit midpoint: :math:`\bar w = w(\tfrac12(M_n + M_{n+1}))`, solved per member by fixed-point iteration
  (no ``n × n`` Jacobian: the chord method of the coordinate path would need one); a member stops when
  :math:`\max|\Delta\sigma| \le` ``tol`` :math:`(1 + \max|\sigma|)` and fails after ``max_iter``.

These are the same equations as the coordinate path's, so the two agree to round-off (Lie–Euler,
Lie–Heun) or to the iteration's tolerance (midpoint); strong order 1 with the Lévy areas, ½ without.
Cost per member and step: one exponential of an ``N × N`` matrix (scaling and squaring of a Taylor
polynomial, :mod:`mechanics.systems._matrix_exp`: no linear solve) and about ten products, ``O(N³)``, plus
``O(N²)`` sparse maps; nothing of size ``n²`` in the algebra's dimension. Every product is per member
(stacked ``np.matmul``: one BLAS call per member, never a GEMM across the batch) and every other operation
elementwise or a sparse map per member, so a member's result is bitwise what it is alone. The members run
in blocks (:func:`block_members`: about :data:`BLOCK_WORK` of product work per step) shared by numba's
number of Python threads (numpy releases the GIL in its products); the split never changes a result.
Measured (``benchmarks/bench_lie_algebras.py``, CPU time per path-step, one thread, load 6-8): against a plain
batched numpy Lie–Heun step (batch-wide Padé), 0.88 to 1.20 times its cost from so(8) to su(64) at noise sizes
0.3 and 0.01 per component (su(64), a = 0.3: 2.0 ms against 2.1 ms); on so(3) .. su(4) 1.1 to 1.4 times (the
Python overhead of a step on tiny matrices), where the solver's cost model mostly runs the compiled constants
kernel instead (:mod:`._dispatch`).
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import check_memory, parallel_ranges

__all__ = ["integrate_matrix", "CHORD_FAILED", "block_members"]

#: ``reason`` code of a member whose implicit iteration did not converge (the compiled kernels' name)
CHORD_FAILED = 2
#: Work (real multiply-adds of one ``N × N`` product, ``4N³`` complex) aimed at per block of members: a block's
#: steps then cost well above the Python overhead of a step (tens of numpy calls), and blocks are what the
#: threads share.
BLOCK_WORK = 1 << 21


def block_members(alg, batch: int) -> int:
    """Members per block for an algebra on ``N × N`` matrices: about :data:`BLOCK_WORK` of product work per
    step, at least 4 (the split into blocks never changes a result: every operation is per member)."""
    N = alg.matrix_size
    work = float(N) ** 3 * (4.0 if alg.dtype.kind == "c" else 1.0)
    return int(max(4, min(max(batch, 1), BLOCK_WORK // max(work, 1.0))))


def _comm(A, B):
    return A @ B - B @ A


def _heun_sigma(system, M, dt, eta):
    w0 = system.drift_velocity_matrix(M)
    sig0 = w0 * dt + eta
    A1 = _comm(M, sig0)
    Mp = M + A1 + 0.5 * _comm(A1, sig0)
    w1 = system.drift_velocity_matrix(Mp)
    w1 += w0
    w1 *= 0.5 * dt
    w1 += eta
    return w1, None


def _euler_sigma(system, M, dt, eta):
    return system.drift_velocity_matrix(M) * dt + eta, None


def _midpoint_sigma(system, M, dt, eta, tol, max_iter):
    """Fixed-point iteration of :math:`\\sigma = w(\\frac12(M + e^{-\\sigma}Me^{\\sigma}))\\Delta t + \\eta`, per member."""
    alg = system.algebra
    sigma = system.drift_velocity_matrix(M) * dt + eta
    b = M.shape[0]
    ok = np.zeros(b, dtype=bool)
    active = np.arange(b)
    for _ in range(max_iter):
        if active.size == 0:
            break
        M_a, s_a = M[active], sigma[active]
        new = system.drift_velocity_matrix(0.5 * (M_a + alg.conjugate(s_a, M_a))) * dt + eta[active]
        err = np.max(np.abs(new - s_a), axis=(-2, -1))
        sigma[active] = new
        finite = np.isfinite(err)
        conv = finite & (err <= tol * (1.0 + np.max(np.abs(new), axis=(-2, -1))))
        ok[active[conv]] = True
        active = active[~(conv | ~finite)]
    return sigma, ok


def integrate_matrix(code, system, tol, max_iter, y, dX, dXX, dts, save, stop_on_failure):
    """Advance ``y (B, n)`` (dual coordinates) over the steps ``dts`` with increments ``dX (B, K, m)`` and
    second levels ``dXX (B, K, m, m)`` (or ``None``): ``(y (B, n), saved (B, S, n), first_bad (B,), reason (B,))``,
    ``reason == CHORD_FAILED`` where the implicit iteration failed (the solver's contract item 8).

    The members run in blocks of :func:`block_members` on numba's threads (``numba.set_num_threads``; numpy
    releases the GIL in its products and solves); a member's result is the same in any block and thread."""
    alg = system.algebra
    B, n = y.shape
    N = alg.matrix_size
    block = block_members(alg, B)
    check_memory(24.0 * min(B, block * 4) * N * N * alg.dtype.itemsize, f"the isospectral steps of {B} members "
                 f"on {N}x{N} matrices ({alg.name})", "solve fewer members at once (a smaller batch, or run_ensemble)")
    system._matrix_data()                           # formed once, before the threads read it
    nsave = int(np.count_nonzero(save))
    y2 = np.empty((B, n))
    saved = np.full((B, nsave, n), np.nan)
    first_bad = np.full(B, -1, dtype=np.int64)
    reason = np.zeros(B, dtype=np.int64)
    save = np.asarray(save, dtype=bool)

    def run(lo, hi):
        y2[lo:hi], saved[lo:hi], first_bad[lo:hi], reason[lo:hi] = _run_block(
            code, system, tol, max_iter, y[lo:hi], dX[lo:hi], None if dXX is None else dXX[lo:hi], dts, save,
            stop_on_failure, nsave)

    parallel_ranges(run, B, block)
    return y2, saved, first_bad, reason


def _run_block(code, system, tol, max_iter, y, dX, dXX, dts, save, stop_on_failure, nsave):
    """:func:`integrate_matrix` on one block of members (all of it computed member by member)."""
    alg = system.algebra
    b, n = y.shape
    saved = np.full((b, nsave, n), np.nan)
    first_bad = np.full(b, -1, dtype=np.int64)
    reason = np.zeros(b, dtype=np.int64)
    live = np.all(np.isfinite(y), axis=-1)
    first_bad[~live] = 0
    M = alg.dual_to_matrix(np.where(live[:, None], y, 0.0))
    slot = 0
    for k in range(dts.size):
        dt = float(dts[k])
        every = bool(live.all())
        idx = None if every else np.flatnonzero(live)
        if every or idx.size:
            dx = dX[:, k] if every else dX[idx, k]
            if dXX is None:
                areas = None
            else:
                xx = dXX[:, k] if every else dXX[idx, k]
                areas = 0.5 * (xx - np.swapaxes(xx, -1, -2))
            with np.errstate(all="ignore"):
                eta = system.stochastic_velocity_matrix(dx, areas)
                Ml = M if every else M[idx]
                if code == 0:
                    sigma, conv = _euler_sigma(system, Ml, dt, eta)
                elif code == 1:
                    sigma, conv = _heun_sigma(system, Ml, dt, eta)
                else:
                    sigma, conv = _midpoint_sigma(system, Ml, dt, eta, tol, max_iter)
                new = alg.conjugate(sigma, Ml)                  # a non-finite sigma gives NaN for its member
                good = np.isfinite(np.sum(new.reshape(new.shape[0], -1).view(np.float64), axis=-1))
                good &= np.all(np.isfinite(dx), axis=-1)
                if conv is not None:
                    good &= conv
            if every and good.all():
                M = new
            else:
                target = np.arange(b) if every else idx
                M[target] = np.where(good[:, None, None], new, np.nan)
                bad = target[~good]
                live[bad] = False
                first_bad[bad] = k
                if conv is not None:
                    reason[bad[~conv[~good]]] = CHORD_FAILED
        if save[k]:
            saved[:, slot] = _coordinates(alg, M, live)
            slot += 1
        if stop_on_failure and not np.all(live):
            break
    return _coordinates(alg, M, live), saved, first_bad, reason


def _coordinates(alg, M, live):
    """Dual coordinates of the live members, NaN for the others."""
    if live.all():
        return alg.matrix_to_dual(M)
    return np.where(live[:, None], alg.matrix_to_dual(np.where(live[:, None, None], M, 0.0)), np.nan)
