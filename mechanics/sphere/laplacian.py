r"""The Hoppe–Yau quantised Laplacian :math:`\Delta_N` and its inverse (the stream matrix of a vorticity
matrix), in :math:`O(N^2)` per matrix.

:math:`\Delta_N = -\sum_{a=1}^3\operatorname{ad}_{S_a}^2`, i.e.
:math:`\Delta_N P = -\sum_a[S_a, [S_a, P]] = -2s(s+1)P + 2S_3PS_3 + S_+PS_- + S_-PS_+`
(:math:`s = (N-1)/2`, spin matrices as in :mod:`.quantisation`). It is the quantisation of the
Laplace–Beltrami operator of the unit sphere, :math:`\Delta = \sum_a L_a^2` with
:math:`L_a\leftrightarrow\operatorname{ad}_{S_a}`, and it is exact on the basis:
:math:`\Delta_N T_{lm} = -l(l+1)T_{lm}` for every :math:`l < N` (the Casimir of spin :math:`l`).

It is self-adjoint for the Frobenius inner product and maps each diagonal of a matrix to itself: on the
entries :math:`p_j = P_{j,j+m}` (or :math:`P_{j+m,j}`) it is a symmetric tridiagonal matrix
(:func:`mechanics.sphere.quantisation.band_tridiagonal`), positive definite for :math:`m\neq0`
(eigenvalues :math:`l(l+1)\ge |m|(|m|+1)`) and, on the main diagonal, positive semi-definite with the
one null vector :math:`(1, \dots, 1)` (:math:`l = 0`: the identity, :math:`\Delta_N I = 0`).

The inverse. :func:`inverse_laplacian` solves :math:`\Delta_N P = W` on all :math:`2N-1` diagonals at once,
as one block-diagonal tridiagonal system of size :math:`N^2` whose :math:`LDL^{\mathsf T}` factors
(LAPACK ``dpttrf``) are computed once per :math:`N`; a solve is LAPACK ``dpttrs`` on the real and imaginary
parts (:math:`O(N^2)` per matrix; CPU time on one core, gather and scatter included: 0.1 ms at N = 64,
0.5 ms at N = 128, about 3 ms at N = 256, about one complex N x N product (2.8 ms at N = 256, 0.36 ms at
N = 128; load 6 on 2 cores)).
The :math:`l = 0` part, :math:`\operatorname{tr}(W)I/N` (a constant vorticity; on a closed sphere the total
vorticity, :math:`\int\omega\,dA = \sqrt{4\pi}\,\omega_{00}`, is zero), has no preimage: it is removed
from :math:`W` first, and the solution is the one with :math:`\operatorname{tr}P = 0`. On the main
diagonal the singular system is solved with its last equation dropped and :math:`p_{N-1} = 0` (the
remaining leading block is positive definite; the dropped equation is implied once
:math:`\sum_j w_j = 0`), then the mean is subtracted. For skew-Hermitian :math:`W` the result is
skew-Hermitian to the last bit (the lower diagonals are the same real systems as the upper ones, with
the sign of the real part flipped).

Examples
--------
>>> import numpy as np
>>> from mechanics.sphere import harmonic_matrix, laplacian, inverse_laplacian
>>> T = 1j * harmonic_matrix(16, 3, -2)
>>> bool(np.allclose(laplacian(T), -12 * T))
True
>>> bool(np.allclose(inverse_laplacian(T), -T / 12))
True
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.linalg import lapack

from ._inputs import as_matrix, check_bytes
from .quantisation import band_tridiagonal, ladder, weights

__all__ = ["laplacian", "inverse_laplacian"]


def laplacian(P) -> np.ndarray:
    r""":math:`\Delta_N P = -\sum_a[S_a, [S_a, P]]`, shape ``(..., N, N)``, in :math:`O(N^2)`.

    Parameters
    ----------
    P : array_like, shape ``(..., N, N)``
        Any complex matrices (a stream matrix in :math:`\mathfrak{su}(N)`, typically).

    Returns
    -------
    numpy.ndarray, complex128
        Elementwise: :math:`-2s(s+1)P_{ij} + 2\mu_i\mu_jP_{ij} + a_ia_jP_{i+1,j+1} + a_{i-1}a_{j-1}P_{i-1,j-1}`.
    """
    arr = as_matrix(P, "P")
    n = arr.shape[-1]
    check_bytes(48.0 * arr.size, f"the Laplacian of {arr.size // (n * n)} matrices of size {n}", "pass fewer at a time")
    mu, a = weights(n), ladder(n)
    s = (n - 1) / 2.0
    out = (2.0 * np.multiply.outer(mu, mu) - 2.0 * s * (s + 1.0)) * arr
    aa = np.multiply.outer(a, a)
    out[..., :-1, :-1] += aa * arr[..., 1:, 1:]
    out[..., 1:, 1:] += aa * arr[..., :-1, :-1]
    return out


@functools.lru_cache(maxsize=8)
def _factors(N: int):
    """``(perm, inverse, d, e)``: the diagonals in the order 0, +1, -1, +2, -2, ... (a permutation of the
    ``N^2`` entries and its inverse), and the LDL^T factors of -Delta_N on them."""
    perm, diag, off = [], [], []
    for m in range(N):
        d, e = band_tridiagonal(N, m)
        j = np.arange(N - m)
        if m == 0:
            d = d.copy()
            e = e.copy()
            d[-1], e[-1] = 1.0, 0.0  # drop the last equation of the singular block; p_{N-1} = 0
            perm.append(j * N + j)
            diag.append(d)
            off.append(np.append(e, 0.0))
            continue
        for rows, cols in ((j, j + m), (j + m, j)):
            perm.append(rows * N + cols)
            diag.append(d)
            off.append(np.append(e, 0.0))  # no coupling to the next block
    perm = np.concatenate(perm)
    d = np.concatenate(diag)
    e = np.concatenate(off)[:-1]
    df, ef, info = lapack.dpttrf(d, e)
    if info != 0:  # pragma: no cover - the blocks are positive definite by construction
        raise RuntimeError(f"dpttrf failed (info={info}) factorising the quantised Laplacian at N={N}.")
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(perm.size)
    for arr in (perm, inverse, df, ef):
        arr.setflags(write=False)
    return perm, inverse, df, ef


def inverse_laplacian(W) -> np.ndarray:
    r"""The stream matrix :math:`P = \Delta_N^{-1}W`: the solution of :math:`\Delta_N P = W - \frac{\operatorname{tr}W}{N}I`
    with :math:`\operatorname{tr}P = 0`.

    Parameters
    ----------
    W : array_like, shape ``(..., N, N)``
        Vorticity matrices (skew-Hermitian and trace-free for :math:`\mathfrak{su}(N)`; any complex
        matrices are accepted, and their trace part is dropped).

    Returns
    -------
    numpy.ndarray, shape ``(..., N, N)``, complex128
        :math:`P` with :math:`P = -\sum_{l\ge1}\frac{1}{l(l+1)}(\text{the spin-}l\text{ part of }W)`;
        skew-Hermitian to the last bit when :math:`W` is. :math:`O(N^2)` per matrix; a batch member's
        result is bitwise the one it has alone.
    """
    arr = as_matrix(W)
    n = arr.shape[-1]
    check_bytes(48.0 * n * n + 96.0 * arr.size, f"the Poisson solve of {arr.size // (n * n)} matrices of size {n}",
                "pass fewer matrices at a time")
    perm, inverse, df, ef = _factors(n)
    batch = arr.shape[:-2]
    flat = arr.reshape((-1, n * n))
    b = flat.shape[0]
    rhs = np.take(flat, perm, axis=1)  # (B, n^2), the diagonals one after the other
    rhs[:, :n] -= rhs[:, :n].mean(axis=1, keepdims=True)  # drop the l = 0 part
    rhs[:, n - 1] = 0.0
    cols = np.empty((2 * b, n * n))  # C order (2B, n^2): its transpose is LAPACK's (n^2, 2B) column layout
    cols[0::2], cols[1::2] = rhs.real, rhs.imag
    x, info = lapack.dpttrs(df, ef, cols.T, overwrite_b=True)
    if info != 0:  # pragma: no cover
        raise RuntimeError(f"dpttrs failed (info={info}) solving the quantised Poisson equation at N={n}.")
    rows = x.T
    sol = np.empty((b, n * n), dtype=np.complex128)
    sol.real, sol.imag = -rows[0::2], -rows[1::2]  # dpttrs solved (-Delta_N) x = rhs
    sol[:, :n] -= sol[:, :n].mean(axis=1, keepdims=True)
    out = np.take(sol, inverse, axis=1)
    return out.reshape(batch + (n, n))
