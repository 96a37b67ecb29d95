r"""Fields on the sphere: grid values on a Gauss–Legendre latitude–longitude grid, their spherical-harmonic
coefficients, and the vorticity matrices that stand for them.

The grid (:func:`sphere_grid`): colatitudes :math:`\theta_i = \arccos x_i` at the ``n_lat`` Gauss–Legendre
nodes :math:`x_i` (north to south), longitudes :math:`\phi_k = 2\pi k/n_{lon}`. With
``n_lat >= L`` and ``n_lon >= 2L - 1`` the transforms are exact (to round-off) for fields of degree
:math:`l < L`: :math:`\int f\bar g\,dA = \sum_{i,k} w_i\frac{2\pi}{n_{lon}}f\bar g` for such fields
(Gauss–Legendre is exact for polynomials in :math:`x` of degree :math:`\le 2n_{lat}-1`; the longitude sum is
exact for :math:`|m - m'| < n_{lon}`). A field of higher degree is aliased: oversample it
(:func:`function_to_matrix`'s ``oversample``).

Harmonics: :math:`Y_{lm}(\theta,\phi) = \bar P_{lm}(\cos\theta)e^{im\phi}`, orthonormal on the unit sphere,
with the Condon–Shortley phase (the convention of ``scipy.special.sph_harm_y``). The normalised
associated Legendre functions come from the standard three-term recurrence in the degree
(:math:`\bar P_{00} = 1/\sqrt{4\pi}`, :math:`\bar P_{mm} = -\sqrt{(2m+1)/2m}\,\sin\theta\,\bar P_{m-1,m-1}`,
:math:`\bar P_{m+1,m} = \sqrt{2m+3}\,x\bar P_{mm}`, :math:`\bar P_{lm} = a_{lm}(x\bar P_{l-1,m} - b_{lm}\bar P_{l-2,m})`
with :math:`a_{lm} = \sqrt{(4l^2-1)/(l^2-m^2)}`, :math:`b_{lm} = \sqrt{((l-1)^2-m^2)/(4(l-1)^2-1)}`), stable
for every degree used here; values below :math:`10^{-300}` near the poles at high order underflow to 0.
Cost :math:`O(L^2 n_{lat})` plus FFTs in longitude: :math:`O(N^3)` for a matrix of size :math:`N`.

The symbol of a matrix. :func:`matrix_to_grid` evaluates :math:`\sum\omega_{lm}Y_{lm}` from the
coefficients of :func:`~mechanics.sphere.quantisation.matrix_to_coefficients` (Hoppe–Yau's symbol); for a
vorticity matrix :math:`W = i\sum\omega_{lm}T_{lm}` it returns the real field :math:`\omega`.

Examples
--------
>>> import numpy as np
>>> from mechanics.sphere import sphere_grid, grid_to_matrix, matrix_to_grid
>>> theta, phi, _ = sphere_grid(16, 32)
>>> field = np.cos(theta)[:, None] * np.ones_like(phi)     # x_3: a solid-body rotation's stream function
>>> W = grid_to_matrix(field, 16)
>>> bool(np.allclose(matrix_to_grid(W, 16, 32), field))
True
"""

from __future__ import annotations

import numbers

import numpy as np

from ._inputs import as_coefficients, check_bytes, check_size
from .quantisation import coefficients_to_matrix, lm_index, matrix_to_coefficients

__all__ = ["sphere_grid", "coefficients_to_grid", "grid_to_coefficients", "matrix_to_grid", "grid_to_matrix",
           "function_to_matrix"]


def _check_grid_size(value, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer number of grid points, got {value!r}.")
    if value < minimum:
        raise ValueError(f"{name} must be at least {minimum} for the transforms to be exact here, got {value}; "
                         f"pass {name}={minimum} or more.")
    return int(value)


def sphere_grid(n_lat: int, n_lon: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""The Gauss–Legendre latitude–longitude grid.

    Parameters
    ----------
    n_lat, n_lon : int
        Numbers of colatitudes and longitudes (at least 1 each).

    Returns
    -------
    theta : numpy.ndarray, shape ``(n_lat,)``
        Colatitudes in :math:`(0, \pi)`, increasing (north to south).
    phi : numpy.ndarray, shape ``(n_lon,)``
        Longitudes :math:`2\pi k/n_{lon}`.
    weights : numpy.ndarray, shape ``(n_lat,)``
        Gauss–Legendre weights in :math:`x = \cos\theta` (sum 2); the area element of the point
        :math:`(i, k)` is ``weights[i] * 2 * pi / n_lon`` (they sum to :math:`4\pi`).
    """
    n_lat = _check_grid_size(n_lat, "n_lat", 1)
    n_lon = _check_grid_size(n_lon, "n_lon", 1)
    # numpy's nodes are the eigenvalues of the n_lat x n_lat companion matrix (it and eigvalsh's copy)
    check_bytes(16.0 * n_lat * n_lat + 8.0 * (6 * n_lat + n_lon), f"the grid's Gauss–Legendre nodes (an n_lat x n_lat "
                f"eigenvalue problem, n_lat = {n_lat}, n_lon = {n_lon})", "use fewer colatitudes (n_lat) or longitudes")
    x, w = np.polynomial.legendre.leggauss(n_lat)
    order = np.argsort(-x)
    return np.arccos(x[order]), 2.0 * np.pi * np.arange(n_lon) / n_lon, w[order]


def _legendre_offsets(L: int, x: np.ndarray):
    r"""Yield ``(k, P)`` for ``k = 0..L-1``: ``P[m] = \bar P_{m+k, m}(x)`` for ``m = 0..L-1-k``, shape ``(L-k, n)``."""
    sx = np.sqrt(np.maximum(0.0, 1.0 - x * x))
    diag = np.empty((L, x.size))
    diag[0] = 1.0 / np.sqrt(4.0 * np.pi)
    for m in range(1, L):
        diag[m] = -np.sqrt((2.0 * m + 1.0) / (2.0 * m)) * sx * diag[m - 1]
    prev2, prev = None, diag
    yield 0, diag
    if L == 1:
        return
    m = np.arange(L - 1, dtype=np.float64)
    cur = np.sqrt(2.0 * m + 3.0)[:, None] * x * diag[:L - 1]
    prev2, prev = diag, cur
    yield 1, cur
    for k in range(2, L):
        m = np.arange(L - k, dtype=np.float64)
        l = m + k
        a = np.sqrt((4.0 * l * l - 1.0) / (l * l - m * m))
        b = np.sqrt(((l - 1.0) ** 2 - m * m) / (4.0 * (l - 1.0) ** 2 - 1.0))
        cur = a[:, None] * (x * prev[:L - k] - b[:, None] * prev2[:L - k])
        prev2, prev = prev, cur
        yield k, cur


def coefficients_to_grid(omega, n_lat: int, n_lon: int) -> np.ndarray:
    r"""Grid values :math:`\sum_{l<L}\omega_{lm}Y_{lm}(\theta_i, \phi_k)`, shape ``(..., n_lat, n_lon)``.

    Parameters
    ----------
    omega : array_like, shape ``(..., L**2)``
        Coefficients ``omega[..., l*(l+1)+m]``.
    n_lat, n_lon : int
        Grid of :func:`sphere_grid`; ``n_lon >= 2L - 1`` (no aliasing in longitude).

    Returns
    -------
    numpy.ndarray, complex128 (real up to round-off for a real field)
    """
    arr, L = as_coefficients(omega)
    n_lat = _check_grid_size(n_lat, "n_lat", 1)
    n_lon = _check_grid_size(n_lon, "n_lon", 2 * L - 1)
    theta, _, _ = sphere_grid(n_lat, 1)
    x = np.cos(theta)
    batch = arr.shape[:-1]
    flat = arr.reshape((-1, L * L))
    check_bytes(48.0 * flat.shape[0] * n_lon * n_lat + 16.0 * L * n_lat, f"the grid values ({n_lat} x {n_lon})",
                "use a coarser grid or fewer fields at a time")
    spectrum = np.zeros((flat.shape[0], n_lon, n_lat), dtype=np.complex128)
    for k, p in _legendre_offsets(L, x):
        m = np.arange(L - k)
        l = m + k
        spectrum[:, m, :] += flat[:, lm_index(l, m)][:, :, None] * p
        neg = m[1:]
        if neg.size:
            sign = ((-1.0) ** neg)[:, None]
            spectrum[:, n_lon - neg, :] += flat[:, lm_index(l[1:], -neg)][:, :, None] * (sign * p[1:])
    values = np.fft.ifft(spectrum, axis=1) * n_lon
    return np.ascontiguousarray(values.transpose(0, 2, 1)).reshape(batch + (n_lat, n_lon))


def grid_to_coefficients(values, L: int) -> np.ndarray:
    r"""Coefficients :math:`\omega_{lm} = \int f\,\overline{Y_{lm}}\,dA` (Gauss quadrature), ``l < L``.

    Parameters
    ----------
    values : array_like, shape ``(..., n_lat, n_lon)``
        A field on :func:`sphere_grid` ``(n_lat, n_lon)``, with ``n_lat >= L`` and ``n_lon >= 2L - 1``
        (then exact for fields of degree below ``L``).
    L : int
        Number of degrees kept.

    Returns
    -------
    numpy.ndarray, shape ``(..., L**2)``, complex128
    """
    if isinstance(L, bool) or not isinstance(L, numbers.Integral) or L < 1:
        raise ValueError(f"L (the number of degrees kept) must be a positive integer, got {L!r}.")
    L = int(L)
    arr = np.asarray(values)
    if arr.ndim < 2 or arr.dtype == object or not np.issubdtype(arr.dtype, np.number):
        raise ValueError(f"values must be a numeric array (..., n_lat, n_lon) on sphere_grid, got shape "
                         f"{np.shape(values)} and dtype {arr.dtype}.")
    n_lat, n_lon = arr.shape[-2:]
    _check_grid_size(n_lat, "values.shape[-2] (n_lat)", L)
    _check_grid_size(n_lon, "values.shape[-1] (n_lon)", 2 * L - 1)
    check_bytes(64.0 * arr.size + 16.0 * L * n_lat, f"the transform of the grid values ({n_lat} x {n_lon})",
                "pass fewer fields at a time")
    arr = np.asarray(arr, dtype=np.complex128)
    if not np.all(np.isfinite(arr)):
        raise ValueError("values has non-finite entries (NaN or inf).")
    theta, _, w = sphere_grid(n_lat, 1)
    x = np.cos(theta)
    batch = arr.shape[:-2]
    flat = arr.reshape((-1, n_lat, n_lon))
    # G_m(theta_i) = (2 pi / n_lon) sum_k f_ik e^{-i m phi_k}, times the Gauss weight
    spectrum = np.fft.fft(flat, axis=-1) * (2.0 * np.pi / n_lon)
    spectrum = np.ascontiguousarray((spectrum * w[:, None]).transpose(0, 2, 1))  # (B, n_lon, n_lat)
    out = np.zeros((flat.shape[0], L * L), dtype=np.complex128)
    for k, p in _legendre_offsets(L, x):
        m = np.arange(L - k)
        l = m + k
        out[:, lm_index(l, m)] = (spectrum[:, m, :] * p).sum(axis=-1)
        neg = m[1:]
        if neg.size:
            sign = ((-1.0) ** neg)[:, None]
            out[:, lm_index(l[1:], -neg)] = (spectrum[:, n_lon - neg, :] * (sign * p[1:])).sum(axis=-1)
    return out.reshape(batch + (L * L,))


def matrix_to_grid(W, n_lat: int | None = None, n_lon: int | None = None) -> np.ndarray:
    r"""The vorticity field of a vorticity matrix on :func:`sphere_grid`, shape ``(..., n_lat, n_lon)``, float64.

    ``W = i sum omega_lm T_lm`` gives the real field :math:`\sum\omega_{lm}Y_{lm}`. For a matrix that is
    not skew-Hermitian this is the field of its skew-Hermitian part :math:`\frac12(W - W^*)` (the real
    part of the complex field: use ``coefficients_to_grid(matrix_to_coefficients(W), ...)`` for the whole
    complex field). Defaults ``n_lat = N``, ``n_lon = 2N``.
    """
    omega = matrix_to_coefficients(W)
    n = int(round(np.sqrt(omega.shape[-1])))
    values = coefficients_to_grid(omega, n if n_lat is None else n_lat, 2 * n if n_lon is None else n_lon)
    return np.ascontiguousarray(values.real)


def grid_to_matrix(values, N: int) -> np.ndarray:
    r"""The vorticity matrix :math:`W = i\sum_{l<N}\omega_{lm}T_{lm}` of a field on :func:`sphere_grid`.

    Parameters
    ----------
    values : array_like, shape ``(..., n_lat, n_lon)``
        Field values, ``n_lat >= N``, ``n_lon >= 2N - 1``; a real field gives a skew-Hermitian ``W``
        (its :math:`l = 0` part, the mean, stays as :math:`\operatorname{tr}W`: subtract the mean for su(N)).
    N : int
        Matrix size.
    """
    n = check_size(N)
    return coefficients_to_matrix(grid_to_coefficients(values, n), n)


def function_to_matrix(func, N: int, *, oversample: int = 2) -> np.ndarray:
    r"""The vorticity matrix of a field given as a function ``func(theta, phi)`` (vectorised).

    The coefficients :math:`l < N` are computed by quadrature on a grid ``oversample`` times finer
    (``(oversample * N, oversample * 2N)``), exact for fields of degree below ``oversample * N``, so
    that the truncation of a smooth field is computed without aliasing.
    """
    n = check_size(N)
    if not callable(func):
        raise TypeError(f"func must be a callable func(theta, phi) -> values, got {type(func).__name__}.")
    if isinstance(oversample, bool) or not isinstance(oversample, numbers.Integral) or oversample < 1:
        raise ValueError(f"oversample must be a positive integer, got {oversample!r}.")
    check_bytes(96.0 * oversample * n * oversample * 2 * n, f"the oversampled grid ({oversample * n} x "
                f"{oversample * 2 * n})", "use a smaller oversample")
    theta, phi, _ = sphere_grid(oversample * n, oversample * 2 * n)
    values = np.asarray(func(theta[:, None], phi[None, :]))
    shape = (theta.size, phi.size)
    try:
        values = np.broadcast_to(values, np.broadcast_shapes(values.shape, shape))
    except ValueError:
        raise ValueError(f"func(theta, phi) must return values broadcastable to the grid shape {shape} (theta "
                         f"as a column, phi as a row), got shape {values.shape}.") from None
    if values.dtype.kind in "fc" and not np.all(np.isfinite(values)):
        bad = int(np.count_nonzero(~np.isfinite(values)))
        raise ValueError(f"func(theta, phi) returned {bad} non-finite value(s) (NaN or inf) on the {shape} grid; "
                         f"the field must be finite on the whole sphere (theta in (0, pi), phi in [0, 2 pi)).")
    return coefficients_to_matrix(grid_to_coefficients(values, n), n)
