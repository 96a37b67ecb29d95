r"""Batched dense linear algebra shared by the solvers (private; exported as :func:`roughpaths.expm_batched`).

The matrix exponential of a batch is computed member by member in the sense that matters to a
user: each member's Padé degree and number of squarings are chosen from that member's own norm,
so a member's result is bitwise the same whether it is computed alone or beside others, and a
non-finite member gives NaN for itself only. The work is still vectorised: the members are grouped
by degree (at most five groups), and the squarings run on the shrinking set of members that still
need them. ``2 x 2`` matrices (the planar and other two-dimensional linear fields) take a compiled
closed form instead, member by member, more accurate than Padé and without the grouping.

The small products :func:`matvec` and :func:`vecmat` serve the same promise for the linear vector
fields: ``y @ A.T`` on a batch ``(B, e)`` is one BLAS matrix product whose summation order depends on
``B`` (a member differs in the last bit from the same row computed alone), whereas these generalised
ufuncs sum every member's product in one fixed order, whatever the batch.
"""

from __future__ import annotations

import math
from math import factorial

import numba
import numpy as np

from .validation import as_float_array

__all__ = ["expm_batched", "matvec", "vecmat"]

# (degree m, largest 1-norm for which the degree-m diagonal Padé approximant has backward error
# below the float64 unit roundoff): Higham, SIAM J. Matrix Anal. Appl. 26 (2005), Table 2.3.
_THETA = ((3, 1.495585217958292e-2), (5, 2.539398330063230e-1), (7, 9.504178996162932e-1),
          (9, 2.097847961257068e0), (13, 5.371920351148152e0))


def _pade_coefficients(m: int) -> list:
    return [factorial(2 * m - k) * factorial(m) / (factorial(2 * m) * factorial(k) * factorial(m - k))
            for k in range(m + 1)]


_PADE = {m: _pade_coefficients(m) for m, _ in _THETA}


def _pade(A: np.ndarray, m: int) -> np.ndarray:
    """Degree-``m`` diagonal Padé approximant of ``exp`` on a stack ``A`` of shape ``(k, n, n)``."""
    b = _PADE[m]
    n = A.shape[-1]
    eye = np.broadcast_to(np.eye(n), A.shape)
    A2 = A @ A
    powers = [eye, A2]                                 # A^0, A^2, A^4, ...
    for _ in range(2, m // 2 + 1):
        powers.append(powers[-1] @ A2)
    U = A @ sum(b[2 * k + 1] * powers[k] for k in range(m // 2 + 1))
    V = sum(b[2 * k] * powers[k] for k in range(m // 2 + 1))
    return np.linalg.solve(V - U, V + U)


def expm_batched(A) -> np.ndarray:
    r"""Matrix exponential of a batch ``A`` of shape ``(..., n, n)``, each member on its own.

    ``2 x 2`` members use the closed form :func:`_expm2` (compiled, one member at a time). Larger ones:
    scaling and squaring with the diagonal Padé approximant of degree ``m ∈ {3, 5, 7, 9, 13}``
    (Higham 2005 thresholds, backward error below the float64 unit roundoff), with the degree and
    the number of squarings ``s`` chosen **per member** from its own 1-norm. Consequences a user can
    rely on:

    * a member's result does not depend on the other members: it is bitwise the one computed for
      that member alone (batching is only faster);
    * a member with a NaN or infinite entry gives an all-NaN result for itself only.

    Cost: one batched Padé evaluation per degree that occurs in the batch (at most five), plus
    ``max(s)`` rounds of squaring on the members that need them.

    Parameters
    ----------
    A : array_like, shape ``(..., n, n)``
        Real (float64) or complex (complex128) matrices; complex ones (e.g. the skew-Hermitian elements of
        su(N)) take the Padé route at every size.

    Returns
    -------
    ndarray, shape ``(..., n, n)``, float64 or complex128 like ``A``

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import expm_batched
    >>> R = expm_batched(np.array([[0.0, -np.pi / 2], [np.pi / 2, 0.0]]))   # rotation by 90°
    >>> np.round(R, 12) + 0.0
    array([[ 0., -1.],
           [ 1.,  0.]])

    A huge or NaN member does not disturb its neighbour:

    >>> B = np.array([[0.1, 1.0], [-1.0, 0.2]])
    >>> pair = expm_batched(np.stack([B, [[0.0, np.nan], [0.0, 0.0]]]))
    >>> bool(np.array_equal(pair[0], expm_batched(B))), bool(np.isnan(pair[1]).all())
    (True, True)
    """
    if np.iscomplexobj(A):
        A = np.asarray(A, dtype=np.complex128)
    else:
        A = as_float_array(A, "A", allow_nonfinite=True)     # NaN members: documented NaN result, see above
    if A.ndim < 2 or A.shape[-1] != A.shape[-2]:
        raise ValueError(f"A must have shape (..., n, n) (a batch of square matrices), got shape {A.shape}.")
    shape, n = A.shape, A.shape[-1]
    if A.size == 0:                          # no members, or 0 x 0 matrices: nothing to exponentiate
        return np.broadcast_to(np.eye(n, dtype=A.dtype), shape).copy()
    flat = A.reshape(-1, n, n)
    if n == 2 and A.dtype == np.float64:     # closed form, member by member (compiled)
        out = np.empty(flat.shape)
        _expm2(np.ascontiguousarray(flat), out)
        return out.reshape(shape)
    out = np.full(flat.shape, np.nan, dtype=A.dtype)
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.max(np.sum(np.abs(flat), axis=-2), axis=-1)
    finite = np.isfinite(norms)
    degree = np.full(norms.shape, 13)
    for m, theta in reversed(_THETA):
        degree[norms <= theta] = m
    squarings = np.zeros(norms.shape, dtype=np.int64)
    big = finite & (norms > _THETA[-1][1])
    squarings[big] = np.maximum(0, np.ceil(np.log2(norms[big] / _THETA[-1][1]))).astype(np.int64)
    for m, _ in _THETA:
        idx = np.flatnonzero(finite & (degree == m))
        if idx.size == 0:
            continue
        s = squarings[idx]
        scaled = flat[idx] / (2.0 ** s)[:, None, None] if m == 13 else flat[idx]
        with np.errstate(over="ignore", invalid="ignore"):      # a member whose exp overflows: inf/NaN
            R = _pade(scaled, m)
            for r in range(1, int(s.max(initial=0)) + 1):
                active = np.flatnonzero(s >= r)
                R[active] = R[active] @ R[active]
        out[idx] = R
    return out.reshape(shape)


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _expm2(M, out):
    r"""``exp`` of each 2x2 matrix of ``M (B, 2, 2)`` in closed form, into ``out``.

    With :math:`\mu = \operatorname{tr}/2`, :math:`N = M - \mu I` and :math:`N^2 = q I`
    (:math:`q = ((a - d)/2)^2 + bc`): :math:`e^M = e^{\mu}\,(C(q) I + S(q) N)`, where
    :math:`C = \cosh\sqrt q,\ S = \sinh\sqrt q/\sqrt q` for :math:`q > 0`, their cos/sin
    forms for :math:`q < 0`, and the Taylor series in :math:`q` (to :math:`q^4`, truncation below
    1e-18) for :math:`|q| < 10^{-3}`. Each member is computed alone, in a fixed order (bitwise
    independent of the batch); a non-finite member gives NaN for itself.
    """
    for p in range(M.shape[0]):
        a, b, c, d = M[p, 0, 0], M[p, 0, 1], M[p, 1, 0], M[p, 1, 1]
        if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c) and math.isfinite(d)):
            out[p, 0, 0] = out[p, 0, 1] = out[p, 1, 0] = out[p, 1, 1] = np.nan
            continue
        mu = 0.5 * (a + d)
        al = 0.5 * (a - d)
        q = al * al + b * c
        if abs(q) < 1e-3:
            C = 1.0 + q * (1.0 / 2 + q * (1.0 / 24 + q * (1.0 / 720 + q / 40320)))
            S = 1.0 + q * (1.0 / 6 + q * (1.0 / 120 + q * (1.0 / 5040 + q / 362880)))
        elif q > 0.0:
            r = math.sqrt(q)
            C = math.cosh(r)
            S = math.sinh(r) / r
        else:
            r = math.sqrt(-q)
            C = math.cos(r)
            S = math.sin(r) / r
        e = math.exp(mu)
        out[p, 0, 0] = e * (C + S * al)
        out[p, 0, 1] = e * (S * b)
        out[p, 1, 0] = e * (S * c)
        out[p, 1, 1] = e * (C - S * al)


def _matvec_kernel(A, x, out):  # pragma: no cover - compiled
    for a in range(A.shape[0]):
        acc = 0.0
        for b in range(A.shape[1]):
            acc += A[a, b] * x[b]
        out[a] = acc


def _vecmat_kernel(x, M, out):  # pragma: no cover - compiled
    for c in range(M.shape[1]):
        out[c] = 0.0
    for b in range(M.shape[0]):
        xb = x[b]
        for c in range(M.shape[1]):
            out[c] += xb * M[b, c]


_GUFUNCS: dict = {}


def _gufunc(name):
    """Compile (or load from numba's cache) a gufunc on first use, so that importing stays cheap."""
    g = _GUFUNCS.get(name)
    if g is None:
        kernel, sig, layout = {"matvec": (_matvec_kernel, "void(float64[:, :], float64[:], float64[:])", "(a,b),(b)->(a)"),
                               "vecmat": (_vecmat_kernel, "void(float64[:], float64[:, :], float64[:])", "(b),(b,c)->(c)")}[name]
        g = _GUFUNCS[name] = numba.guvectorize([sig], layout, nopython=True, cache=True)(kernel)
    return g


def matvec(A, x):
    """``out[..., a] = Σ_b A[..., a, b] x[..., b]`` (broadcast over leading axes), one summation order."""
    return _gufunc("matvec")(np.asarray(A, dtype=np.float64), np.asarray(x, dtype=np.float64))


def vecmat(x, M):
    """``out[..., c] = Σ_b x[..., b] M[..., b, c]`` (broadcast over leading axes), one summation order."""
    return _gufunc("vecmat")(np.asarray(x, dtype=np.float64), np.asarray(M, dtype=np.float64))
