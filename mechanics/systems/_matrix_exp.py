r"""The matrix exponential and the conjugation :math:`M\mapsto e^{-\sigma}Me^{\sigma}` of the isospectral steps, per member.

The coadjoint flow of a :class:`~mechanics.systems.matrix_algebra.MatrixLieAlgebra` is a conjugation by
:math:`Q = e^{-\sigma}`; this module computes it for a stack of members ``(b, N, N)``, every member on its own:

* scaling and squaring with a truncated Taylor series evaluated by Paterson–Stockmeyer (:data:`TAYLOR`:
  degree ``m = p q`` in ``(p - 1) + (q - 1)`` products, no linear solve), the degree and the number of
  squarings ``s`` chosen per member from its own 1-norm: the pair of least cost with
  :math:`\|A/2^s\|_1\le\theta_m`, where :math:`\sum_{k>m}\theta_m^k/k! = 2^{-53}` (a forward bound of the
  truncation, below the unit roundoff);
* every product a stacked ``np.matmul`` (one BLAS call per member, never a GEMM across the batch, whose
  rounding would depend on the batch size) and every other operation elementwise, so a member's bits never
  depend on the batch (the members of one degree are evaluated together; a batch of one degree and one
  number of squarings, the common case, is never gathered or scattered);
* the conjugation :math:`QMQ^H` where :math:`Q` is unitary (compact algebras), after one Newton–Schulz step
  towards unitarity on the members whose exponential took :data:`POLAR_FROM` squarings or more (each squaring
  doubles the defect of :math:`Q^HQ = I`, and that defect is the step's Casimir drift); :math:`QMQ^{-1}` by a
  solve otherwise.

Why Taylor and not the diagonal Padé approximant of :func:`roughpaths.expm_batched`: the Padé approximant needs
a linear solve per member, and LAPACK's solve of a small matrix costs 4 to 8 products
(measured, one thread, ``(b, N, N)`` stacks: ``N = 8`` complex 1.6 µs against 0.21 µs for a product, ``N = 64``
203 µs against 51 µs); Paterson–Stockmeyer reaches the same norms with about as many products and no
solve. Cost per member: ``products(m) + s`` products for the exponential (e.g. 6 + 1 for a 1-norm of 1.5),
two for the conjugation, ``O(N³)`` each (``4×`` the real cost for complex matrices).
"""

from __future__ import annotations

from math import factorial

import numpy as np

__all__ = ["expm_members", "conjugate_members", "one_norms", "TAYLOR"]

_U = 2.0 ** -53


def _theta(m: int) -> float:
    r"""Largest :math:`\theta` with :math:`\sum_{k>m}\theta^k/k!\le u = 2^{-53}` (bisection on the summed tail)."""
    def tail(t):
        term, total, k = t ** (m + 1) / factorial(m + 1), 0.0, m + 1
        while term > 1e-40 * max(total, 1e-300):
            total += term
            k += 1
            term *= t / k
        return total
    lo, hi = 0.0, 16.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if tail(mid) <= _U else (lo, mid)
    return lo


#: ``(m, p, products, θ_m)``: the Taylor degree ``m = p q``, the block ``p`` of Paterson–Stockmeyer (``A², ..,
#: A^p`` and ``q - 1`` Horner products in ``A^p``), its number of products, and the largest 1-norm for which the
#: truncated tail is below the unit roundoff (``||A^k|| <= ||A||^k``; computed at import). Three degrees only
#: (4, 9, 16: 2, 4, 6 products; θ = 1.7e-3, 0.115, 0.82): the intermediate ones (6, 12, 20, 25) would save
#: one product on some members but split a batch into more groups, each a separate evaluation with its
#: gathers (so(16), 32 members, a = 0.01: 22.8 µs per path-step with eight degrees, 18.9 with these three and
#: the vectorised choice; CPU time, load ~12).
TAYLOR = tuple((m, p, (p - 1) + (m // p - 1), _theta(m))
               for m, p in ((4, 2), (9, 3), (16, 4)))
_COSTS = np.array([t[2] for t in TAYLOR], dtype=np.float64)
_LOG_THETA = np.log2([t[3] for t in TAYLOR])
#: From this many squarings on, a compact algebra's ``Q`` gets one Newton–Schulz step before the conjugation ``Q M Q^H``:
#: the squarings multiply the unitarity defect of the Taylor polynomial (``~u``) by ``2^s``, and the defect is
#: the Casimir drift of the step (su(64), a = 0.3, s ≈ 6: 1.7e-14 per step without the step).
POLAR_FROM = 3
_INV_FACTORIAL = tuple(1.0 / factorial(k) for k in range(17))


def one_norms(A) -> np.ndarray:
    """The 1-norms (largest column sum of moduli) of a stack ``(b, N, N)``: NaN or inf for a non-finite member."""
    return np.max(np.sum(np.abs(A), axis=-2), axis=-1)


def _plus_identity(X, c):
    """``X + c I`` on a fresh stack ``X (b, N, N)``, in place on the diagonal."""
    N = X.shape[-1]
    X.reshape(X.shape[0], N * N)[:, :: N + 1] += c
    return X


def _taylor(A, m, p):
    r""":math:`\sum_{k\le m}A^k/k!` on a stack ``A (b, N, N)`` by Paterson–Stockmeyer (``m = p q``):
    :math:`B_0 + A^p(B_1 + A^p(\cdots(B_{q-1} + c_mA^p)))` with :math:`B_j = \sum_{i<p}c_{jp+i}A^i`."""
    c = _INV_FACTORIAL
    powers = [None, A]
    for _ in range(2, p + 1):
        powers.append(powers[-1] @ A)

    def block(j):
        out = c[j * p + 1] * A
        for i in range(2, p):
            out += c[j * p + i] * powers[i]
        return _plus_identity(out, c[j * p])

    Ap = powers[p]
    R = block(m // p - 1)
    R += c[m] * Ap
    for j in range(m // p - 2, -1, -1):
        R = R @ Ap
        R += block(j)
    return R


def _square(R, s):
    """``R^(2^s)`` per member (``s (b,)``): all members together up to the smallest ``s``, then the members that
    need more as one shrinking subset, each written back once when done (no gather per round)."""
    top, low = int(s.max(initial=0)), int(s.min(initial=0))
    for _ in range(low):
        R = R @ R
    if top == low:
        return R
    idx = np.flatnonzero(s > low)
    sub, left = R[idx], s[idx]
    for r in range(low + 1, top + 1):
        sub = sub @ sub
        done = left == r
        if done.any():
            R[idx[done]] = sub[done]
            keep = ~done
            idx, sub, left = idx[keep], sub[keep], left[keep]
    return R


def expm_members(A, norms=None, *, squarings=False):
    r"""``exp`` of each member of ``A (b, N, N)`` (real or complex), from its own 1-norm ``norms (b,)``: the
    Taylor degree of :data:`TAYLOR` and the number ``s`` of squarings (:math:`\|A/2^s\|_1\le\theta_m`) of least
    cost (products plus squarings; ties go to the lower degree, so that large norms share one degree and differ
    only in their squarings: one evaluation for the batch). The members must be finite
    (the caller drops the others). Returns a new stack (and each member's number of squarings if ``squarings``)."""
    if norms is None:
        norms = one_norms(A)
    b = A.shape[0]
    sq = np.maximum(0.0, np.ceil(np.log2(np.maximum(norms, 1e-300))[:, None] - _LOG_THETA))
    degree = np.argmin(_COSTS + sq, axis=1)                     # the first of equal costs: the lower degree
    s = sq[np.arange(b), degree].astype(np.int64)
    scale = (0.5 ** s)[:, None, None]
    first = degree[0] if b else 0
    if np.all(degree == first):
        m, p = TAYLOR[first][:2]
        out = _square(_taylor(A * scale if np.any(s) else A, m, p), s)
    else:
        out = np.empty_like(A)
        for i, (m, p, _, _) in enumerate(TAYLOR):
            idx = np.flatnonzero(degree == i)
            if idx.size:
                out[idx] = _square(_taylor(A[idx] * scale[idx], m, p), s[idx])
    return (out, s) if squarings else out


def _polar_step(Q):
    r"""One Newton–Schulz step towards the unitary polar factor, :math:`Q(3I - Q^HQ)/2`: a defect
    :math:`Q^HQ = I + E` becomes :math:`I - \tfrac34E^2 + O(E^3)` (two products)."""
    X = np.conj(np.swapaxes(Q, -1, -2)) @ Q
    X *= -0.5
    _plus_identity(X, 1.5)
    return Q @ X


def conjugate_members(sigma, M, compact: bool, norms=None) -> np.ndarray:
    r""":math:`e^{-\sigma}Me^{\sigma}` per member of stacks ``(b, N, N)`` (finite ``sigma``): ``Q M Q^H`` with
    ``Q = e^{-σ}`` when the algebra is compact (``Q`` unitary), ``Q M Q^{-1}`` otherwise. Not projected."""
    Q, s = expm_members(-sigma, norms, squarings=True)
    if compact:                     # each squaring doubles Q's unitarity defect: restore it where s >= POLAR_FROM
        fix = s >= POLAR_FROM
        if np.all(fix):
            Q = _polar_step(Q)
        elif np.any(fix):
            idx = np.flatnonzero(fix)
            Q[idx] = _polar_step(Q[idx])
    QM = Q @ M
    if compact:
        return QM @ np.conj(np.swapaxes(Q, -1, -2))
    return np.swapaxes(np.linalg.solve(np.swapaxes(Q, -1, -2), np.swapaxes(QM, -1, -2)), -1, -2)
