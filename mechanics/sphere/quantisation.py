r"""Quantised spherical harmonics :math:`T_{lm}`: the basis of :math:`\mathfrak{gl}(N)` that stands for
:math:`Y_{lm}` (Hoppe's quantisation of the sphere), and the maps between a vorticity matrix and the
spherical-harmonic coefficients of its field.

Conventions (derived here; ``docs/conventions.md``, section "Euler on the sphere", summarises them)
-------------------------------------------------------------------------------------------------
*Spin matrices.* :math:`S_1, S_2, S_3` are the Hermitian spin-:math:`s` matrices, :math:`s = (N-1)/2`,
:math:`[S_a, S_b] = i\varepsilon_{abc}S_c`, :math:`\sum_a S_a^2 = s(s+1)I`, in the basis ordered by
*decreasing* weight: :math:`S_3 = \operatorname{diag}(s, s-1, \dots, -s)` (row 0 is the north pole),
:math:`S_+ = S_1 + iS_2` on the first superdiagonal with :math:`(S_+)_{j,j+1} = a_j = \sqrt{(j+1)(N-1-j)} > 0`.

*The quantisation.* :math:`\hbar = 2/\sqrt{N^2-1}` and :math:`x_a \mapsto \hbar S_a`, so that
:math:`\sum_a(\hbar S_a)^2 = I` (the unit sphere). A real function :math:`f` goes to a Hermitian matrix
:math:`T(f)` whose eigenvalues approximate the values of :math:`f`; the coordinate brackets
:math:`\{x_a, x_b\} = \varepsilon_{abc}x_c` of the area form, :math:`\{f, g\} = x\cdot(\nabla f\times\nabla g)
= (f_\theta g_\phi - f_\phi g_\theta)/\sin\theta`, are reproduced exactly:
:math:`\tfrac{1}{i\hbar}[\hbar S_a, \hbar S_b] = \varepsilon_{abc}\hbar S_c`. The generators of rotations
act on matrices by commutators: the angular momentum :math:`L_a = -i(x\times\nabla)_a` of the continuous
harmonics corresponds exactly to :math:`\operatorname{ad}_{S_a}` (:math:`\{x_a, f\} = -iL_a f` and
:math:`\tfrac{1}{i\hbar}[\hbar S_a, T] = -i\operatorname{ad}_{S_a}T`). Under :math:`\operatorname{ad}`,
:math:`\mathfrak{gl}(N) = \bigoplus_{l=0}^{N-1} V_l` (spin :math:`s\otimes s`), each spin :math:`l` once.

*The basis.* :math:`T_{lm}` (:math:`0\le l<N`, :math:`|m|\le l`) is the element of :math:`V_l` of weight
:math:`m` (:math:`[S_3, T_{lm}] = mT_{lm}`, so it lives on the :math:`m`-th diagonal: entries
:math:`(j, j+m)`), with the phases of :math:`Y_{lm}` (Condon–Shortley, as ``scipy.special.sph_harm_y``):

* :math:`T_{ll} = (-1)^l c_l S_+^l` with :math:`c_l > 0`: :math:`Y_{ll} = (-1)^l\,\text{positive}\,(x_1+ix_2)^l`
  and :math:`(x_1+ix_2)^l\mapsto(\hbar S_+)^l` (a single variable: no ordering ambiguity);
* :math:`T_{l,m-1} = [S_-, T_{lm}]/\sqrt{(l+m)(l-m+1)}`, the lowering rule of :math:`L_- Y_{lm}`;
* hence :math:`T_{l,-m} = (-1)^m T_{lm}^{*}` (:math:`Y_{l,-m} = (-1)^m\overline{Y_{lm}}`), all entries real,
  and :math:`T_{l0}` real diagonal.

*Normalisation and orthogonality.* :math:`\operatorname{tr}(T_{lm}T_{l'm'}^{*}) = \frac{N}{4\pi}\delta_{ll'}
\delta_{mm'}`: the trace average :math:`\frac1N\operatorname{tr}` stands for the area average
:math:`\frac1{4\pi}\int\cdot\,dA`, so that :math:`\operatorname{tr}(T(f)T(g)^{*}) = \frac{N}{4\pi}\int f\bar g\,dA`
for band-limited fields, exactly. For :math:`l = 1` this makes :math:`T(x_a) = \hbar S_a` exactly
(:math:`T_{10} = \sqrt{3/4\pi}\,\hbar S_3`, :math:`T_{11} = -\sqrt{3/8\pi}\,\hbar S_+`);
:math:`T_{00} = I/\sqrt{4\pi}`. For larger :math:`l` this fixes Hoppe's :math:`T_{lm}` up to a positive
factor that tends to 1 as :math:`N\to\infty` at fixed :math:`l`.

*How it is computed.* The Hoppe–Yau Laplacian :math:`\Delta_N = -\sum_a\operatorname{ad}_{S_a}^2`
(:mod:`.laplacian`) maps each diagonal of a matrix to itself as a symmetric tridiagonal matrix, with
eigenvalues :math:`-l(l+1)`, :math:`l = |m|, \dots, N-1` on the :math:`m`-th diagonal. Its eigenvectors
(``scipy.linalg.eigh_tridiagonal``) are the :math:`T_{lm}` up to sign; the sign is fixed by the two rules
above, read as inner products (:math:`\langle [S_-, T_{l,m+1}], T_{lm}\rangle > 0`, and :math:`T_{mm}`'s
entries, which all have one sign, of sign :math:`(-1)^m`), never by a single tiny entry. Cost
:math:`O(N^3)` once per :math:`N` (CPU time on one core: 0.05 s at N = 128, 0.3 s at N = 256); the basis is
stored band by band, :math:`N^3/3` floats (45 MB at N = 256), cached for :math:`N\le 256` and streamed (two
bands at a time) above, where every call rebuilds it (2.5 s at N = 512). The dynamics never needs it: only
the maps to coefficients and grids do.

*The vorticity matrix.* The field :math:`\omega = \sum\omega_{lm}Y_{lm}` goes to the
:math:`\mathfrak{su}(N)`-type element :math:`W = i\sum_{l,m}\omega_{lm}T_{lm}` (skew-Hermitian exactly when
:math:`\omega` is real; trace-free exactly when :math:`\omega_{00} = 0`). Coefficients are stored flat,
``omega[..., l*(l+1)+m]``, complex, for all :math:`l < L` (``L**2`` entries).

The products of these matrices approximate the products of the harmonics, with errors falling like
:math:`1/N` (:math:`T_\alpha T_\beta - T(Y_\alpha Y_\beta)`), :math:`1/N^2` (the symmetrised product) and
:math:`1/N^2` (:math:`\tfrac{1}{i\hbar}[T_\alpha, T_\beta] - T(\{Y_\alpha, Y_\beta\})`, exact when one
factor has :math:`l = 1`): measured in ``tests/mechanics/sphere/test_quantisation_limit.py``.

Examples
--------
>>> import numpy as np
>>> from mechanics.sphere import harmonic_matrix, spin_matrices, hbar
>>> N = 8
>>> T10 = harmonic_matrix(N, 1, 0)
>>> bool(np.allclose(T10, np.sqrt(3 / (4 * np.pi)) * hbar(N) * spin_matrices(N)[2]))
True
>>> bool(np.isclose(np.trace(T10 @ T10.conj().T).real, N / (4 * np.pi)))
True
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.linalg import eigh_tridiagonal

from ._inputs import as_coefficients, as_matrix, check_bytes, check_size

__all__ = ["hbar", "spin_matrices", "lm_index", "harmonic_matrix", "coefficients_to_matrix",
           "matrix_to_coefficients"]

#: Sizes up to which the whole basis is kept in memory (N^3/3 floats: 45 MB at N = 256).
_CACHE_MAX_N = 256


def hbar(N: int) -> float:
    r""":math:`\hbar = 2/\sqrt{N^2-1}`, the quantisation parameter of :math:`\mathfrak{su}(N)` (``N >= 2``).

    Physical time :math:`t` and Zeitlin's "quantum" time :math:`\tau` of :math:`\dot W = [P, W]` are related
    by :math:`t = \hbar\tau`.
    """
    n = check_size(N)
    return 2.0 / np.sqrt(float(n) * n - 1.0)


def weights(N: int) -> np.ndarray:
    """The weights :math:`\\mu_j = s - j` (the diagonal of :math:`S_3`), shape ``(N,)``."""
    return (N - 1) / 2.0 - np.arange(N, dtype=np.float64)


def ladder(N: int) -> np.ndarray:
    """The superdiagonal :math:`a_j = \\sqrt{(j+1)(N-1-j)}` of :math:`S_+`, shape ``(N-1,)``."""
    j = np.arange(N - 1, dtype=np.float64)
    return np.sqrt((j + 1.0) * (N - 1.0 - j))


def spin_matrices(N: int) -> np.ndarray:
    r"""The Hermitian spin matrices :math:`(S_1, S_2, S_3)` of spin :math:`(N-1)/2`, shape ``(3, N, N)``.

    Weight order decreasing (:math:`S_3 = \operatorname{diag}(s, \dots, -s)`); :math:`[S_1, S_2] = iS_3`
    and cyclic. :math:`\hbar S_a` is the quantised coordinate function :math:`x_a`, and
    :math:`i\hbar S_a` its vorticity matrix.
    """
    n = check_size(N)
    a = ladder(n)
    splus = np.diag(a, 1).astype(np.complex128)
    s1 = 0.5 * (splus + splus.T)
    s2 = -0.5j * (splus - splus.T)
    s3 = np.diag(weights(n)).astype(np.complex128)
    return np.stack([s1, s2, s3])


def lm_index(l, m):
    """The flat coefficient index ``l*(l+1)+m`` of :math:`(l, m)` (arrays broadcast)."""
    l_arr, m_arr = np.asarray(l), np.asarray(m)
    if l_arr.dtype.kind not in "iu" or m_arr.dtype.kind not in "iu":
        raise TypeError(f"l and m must be integers (or integer arrays), got l={l!r}, m={m!r}; pass e.g. "
                        f"lm_index(2, -1).")
    if np.any(l_arr < 0) or np.any(np.abs(m_arr) > l_arr):
        raise ValueError(f"(l, m) must satisfy l >= 0 and |m| <= l, got l={l!r}, m={m!r}.")
    return l_arr * (l_arr + 1) + m_arr


def band_tridiagonal(N: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    r"""Diagonal ``(N-m,)`` and off-diagonal ``(N-m-1,)`` of :math:`-\Delta_N` on the :math:`m`-th diagonal.

    For :math:`p_j = P_{j, j+m}` (and equally :math:`P_{j+m, j}`):
    :math:`(-\Delta_N P)_{j,j+m} = 2(s(s+1) - \mu_j\mu_{j+m})p_j - a_ja_{j+m}p_{j+1} - a_{j-1}a_{j+m-1}p_{j-1}`,
    from :math:`\Delta_N P = -2s(s+1)P + 2S_3PS_3 + S_+PS_- + S_-PS_+`.
    """
    s = (N - 1) / 2.0
    mu = weights(N)
    a = np.append(ladder(N), 0.0)
    j = np.arange(N - m)
    diag = 2.0 * (s * (s + 1.0) - mu[j] * mu[j + m])
    off = -a[j[:-1]] * a[j[:-1] + m]
    return diag, off


def _bands_descending(N: int):
    """Yield ``(m, V_m)`` for ``m = N-1, ..., 0``: ``V_m[:, l-m]`` is the m-th diagonal of :math:`T_{lm}`."""
    a = np.append(ladder(N), 0.0)
    scale = np.sqrt(N / (4.0 * np.pi))
    upper = None
    for m in range(N - 1, -1, -1):
        diag, off = band_tridiagonal(N, m)
        _, vec = eigh_tridiagonal(diag, off)  # eigenvalues l(l+1), l = m..N-1, ascending
        vec *= scale
        # T_mm: the lowest eigenvector, one sign throughout; its sign is (-1)^m (T_mm = (-1)^m c S_+^m)
        if (-1) ** m * vec[:, 0].sum() < 0:
            vec[:, 0] *= -1.0
        if upper is not None:
            # [S_-, T_{l,m+1}] on the m-th diagonal: r_i = a_{i-1} u_{i-1} - a_{i+m} u_i
            n = N - m
            i = np.arange(n)
            below = np.concatenate([np.zeros((1, upper.shape[1])), upper])[:n]
            here = np.concatenate([upper, np.zeros((1, upper.shape[1]))])[:n]
            a_prev = np.concatenate([[0.0], a[:n - 1]])
            lowered = a_prev[:, None] * below - a[i + m][:, None] * here
            flip = np.einsum("jl,jl->l", lowered, vec[:, 1:]) < 0
            vec[:, 1:][:, flip] *= -1.0
        upper = vec
        yield m, vec


@functools.lru_cache(maxsize=2)
def _cached_basis(N: int) -> tuple:
    bands = [None] * N
    for m, vec in _bands_descending(N):
        vec.setflags(write=False)
        bands[m] = vec
    return tuple(bands)


def band_basis(N: int):
    """Iterate ``(m, V_m)`` over the diagonals (descending m; cached for ``N <= 256``, else streamed)."""
    # the bands kept when cached (N(N+1)(2N+1)/6 floats) and, while a band is computed, it, the one before, the
    # eigen-solver's workspace and the sign rule's temporaries: 9 N^2 floats and small arrays (tracemalloc, N = 32 to
    # 200, cached or streamed, with harmonic_matrix's N x N result: 43-75 N^2 bytes besides the bands kept)
    kept = N * (N + 1.0) * (2.0 * N + 1.0) / 6.0 if N <= _CACHE_MAX_N else 0.0
    check_bytes(8.0 * (kept + 9.0 * N * N) + 2.0 ** 15, f"the quantised basis at N = {N}", "use a smaller N")
    if N <= _CACHE_MAX_N:
        bands = _cached_basis(N)
        return ((m, bands[m]) for m in range(N - 1, -1, -1))
    return _bands_descending(N)


def _rows_times(rows, mat):
    """``rows (..., k) @ mat (k, n)``, each output entry summed over ``k`` in order by an elementwise reduction.

    Not BLAS: numpy sends one row to a matrix-vector kernel and a stack of rows to a matrix-matrix kernel,
    whose last bits differ; here a batch member's bits do not depend on the batch. Temporaries are kept
    to about 32 MB by blocks of members.
    """
    k, n = mat.shape
    flat = np.ascontiguousarray(rows.reshape((-1, k)))
    out = np.empty((flat.shape[0], n), dtype=np.complex128)
    step = max(1, (1 << 21) // max(1, k * n))
    for start in range(0, flat.shape[0], step):
        block = flat[start:start + step]
        out[start:start + step] = np.add.reduce(np.multiply(block[:, :, None], mat[None, :, :], order="C"), axis=1)
    return out.reshape(rows.shape[:-1] + (n,))


def harmonic_matrix(N: int, l: int, m: int) -> np.ndarray:
    r"""The quantised spherical harmonic :math:`T_{lm}`, shape ``(N, N)``, complex128 (real entries).

    Parameters
    ----------
    N : int
        Matrix size, ``N >= 2``.
    l, m : int
        Degree ``0 <= l < N`` and order ``|m| <= l``.

    Returns
    -------
    numpy.ndarray
        :math:`T_{lm}`: on the :math:`m`-th diagonal (entries :math:`(j, j+m)`; below the diagonal for
        :math:`m < 0`), :math:`T_{l,-m} = (-1)^m T_{lm}^*`, :math:`\operatorname{tr}(T_{lm}T_{l'm'}^*) =
        \frac{N}{4\pi}\delta_{ll'}\delta_{mm'}`, :math:`\Delta_N T_{lm} = -l(l+1)T_{lm}`. Its vorticity
        matrix (the su(N) element of the field :math:`Y_{lm}`) is :math:`iT_{lm}`.
    """
    n = check_size(N)
    for val, name in ((l, "l"), (m, "m")):
        if isinstance(val, bool) or not isinstance(val, (int, np.integer)):
            raise TypeError(f"{name} must be an integer, got {val!r}.")
    if not 0 <= l < n or abs(m) > l:
        raise ValueError(f"(l, m) must satisfy 0 <= l < N = {n} and |m| <= l, got (l, m) = ({l}, {m}).")
    return _harmonic_matrices(n, [(int(l), int(m))])[0]


def _harmonic_matrices(n: int, pairs) -> list:
    """:func:`harmonic_matrix` of every ``(l, m)`` of ``pairs`` (checked by the caller), from one pass over the
    bands: above N = 256, where every pass builds the basis anew (O(N^3): 2.5 s at N = 512), many matrices cost
    one pass, not one each (private to this package: SALT noise asks for many)."""
    want = {}
    for l, m in pairs:
        want.setdefault(abs(m), set()).add(l)
    cols, left = {}, set(want)
    for band, v in band_basis(n):
        if band in left:
            for l in want[band]:
                cols[l, band] = v[:, l - band].copy()
            left.discard(band)
            if not left:
                break
    out = []
    for l, m in pairs:
        am = abs(m)
        mat = np.zeros((n, n), dtype=np.complex128)
        j = np.arange(n - am)
        if m >= 0:
            mat[j, j + am] = cols[l, am]
        else:
            mat[j + am, j] = (-1.0) ** am * cols[l, am]
        out.append(mat)
    return out


def coefficients_to_matrix(omega, N: int | None = None) -> np.ndarray:
    r"""The vorticity matrix :math:`W = i\sum_{l<L,|m|\le l}\omega_{lm}T_{lm}` of the field
    :math:`\sum\omega_{lm}Y_{lm}`.

    Parameters
    ----------
    omega : array_like, shape ``(..., L**2)``
        Complex coefficients, ``omega[..., l*(l+1)+m]``; a real field has
        :math:`\omega_{l,-m} = (-1)^m\overline{\omega_{lm}}` and gives a skew-Hermitian :math:`W`.
    N : int, optional
        Matrix size (default ``L``); ``L <= N`` (higher modes have no matrix: truncate them first).

    Returns
    -------
    numpy.ndarray, shape ``(..., N, N)``, complex128
    """
    arr, L = as_coefficients(omega)
    n = L if N is None else check_size(N)
    if n < 2:
        raise ValueError("omega must hold at least the l <= 1 modes (length 4) when N is not given.")
    if L > n:
        raise ValueError(f"omega holds modes up to l = {L - 1}, but N = {n} holds only l < {n}; pass "
                         f"omega[..., :{n * n}] (the truncation) or a larger N.")
    batch = arr.shape[:-1]
    check_bytes(32.0 * n * n * max(1, arr.size // (L * L)) + 2.0 ** 25, "the vorticity matrices",
                "pass fewer coefficient vectors at a time")
    out = np.zeros(batch + (n, n), dtype=np.complex128)
    for m, vec in band_basis(n):
        if m >= L:
            continue
        ls = np.arange(m, L)
        j = np.arange(n - m)
        v = vec[:, :L - m]
        out[..., j, j + m] = 1j * _rows_times(arr[..., lm_index(ls, m)], v.T)
        if m > 0:
            out[..., j + m, j] = 1j * (-1.0) ** m * _rows_times(arr[..., lm_index(ls, -m)], v.T)
    return out


def matrix_to_coefficients(W, L: int | None = None) -> np.ndarray:
    r"""The coefficients :math:`\omega_{lm} = \frac{4\pi}{N}\operatorname{tr}(T_{lm}^*\,W/i)` of a matrix.

    The inverse of :func:`coefficients_to_matrix` on all of :math:`\mathfrak{gl}(N)` (exact up to round-off).

    Parameters
    ----------
    W : array_like, shape ``(..., N, N)``
    L : int, optional
        Keep the modes ``l < L`` (default ``N``).

    Returns
    -------
    numpy.ndarray, shape ``(..., L**2)``, complex128
        ``omega[..., l*(l+1)+m]``.
    """
    arr = as_matrix(W)
    n = arr.shape[-1]
    keep = n if L is None else check_size(L, "L")
    if keep > n:
        raise ValueError(f"L = {keep} exceeds the matrix size N = {n} (a matrix holds the modes l < N).")
    batch = arr.shape[:-2]
    check_bytes(32.0 * arr.size + 2.0 ** 25, "the coefficients of the matrices", "pass fewer matrices at a time")
    out = np.zeros(batch + (keep * keep,), dtype=np.complex128)
    scale = 4.0 * np.pi / n
    for m, vec in band_basis(n):
        if m >= keep:
            continue
        ls = np.arange(m, keep)
        j = np.arange(n - m)
        v = vec[:, :keep - m]
        out[..., lm_index(ls, m)] = -1j * scale * _rows_times(arr[..., j, j + m], v)
        if m > 0:
            out[..., lm_index(ls, -m)] = -1j * scale * (-1.0) ** m * _rows_times(arr[..., j + m, j], v)
    return out
