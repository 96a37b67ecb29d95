r"""Fractional Brownian motion, exact on a uniform grid, and its geometric rough-path lift.

Fractional Brownian motion :math:`B^H` (Hurst index :math:`H\in(0,1)`) is the centred Gaussian process
with :math:`E[B^H_s B^H_t] = \tfrac12(s^{2H} + t^{2H} - |t-s|^{2H})`; its components here are
independent. For :math:`H<\tfrac12` it is not a semimartingale: Itô and Stratonovich calculus do not
apply and an equation driven by it means the RDE driven by a rough-path lift.

Sampling
--------
:func:`fbm` draws the path.
The increments on a uniform grid of step ``h`` (fractional Gaussian noise) have autocovariance
:math:`h^{2H}\gamma(k)`, :math:`\gamma(k) = \tfrac12(|k+1|^{2H} - 2|k|^{2H} + |k-1|^{2H})`
(:func:`fgn_autocovariance`). ``method="davies-harte"`` embeds this Toeplitz covariance into a circulant of
size ``2K`` whose eigenvalues are one real FFT of its first row; when they are non-negative (they are,
to round-off, for fractional Gaussian noise), one complex FFT of eigenvalue-weighted complex normals
gives **two** independent exact samples (real and imaginary parts). ``method="cholesky"`` factors the
``K x K`` covariance (``O(K^3)``, for short grids, and the fallback if the embedding ever had a
negative eigenvalue beyond round-off). Both are exact in law; they use the random stream differently.

Lift
----
:func:`piecewise_linear_lift` and :func:`fbm_rough_path` lift it.
The rough path is the signature of the piecewise-linear interpolation of a sample on a **fine** grid
(mesh :math:`\delta = h/m`, ``m`` substeps per coarse step), assembled on the coarse grid by Chen.

What is exact and what is approximate:

* the fine samples are exact fBM values; level 1 of the lift at the coarse grid times is exact;
* levels 2 and 3 are the *exact* iterated integrals of the piecewise-linear path (Chen products of
  :math:`\exp(\Delta X)` over the fine steps), computed to round-off. As rough paths of fBM they are
  approximations: they converge to the canonical (Coutin–Qian) lift of :math:`B^H` as
  :math:`\delta\to 0` in the ``p``-variation rough-path metric for :math:`H > 1/4`, ``p > 1/H``
  (Friz–Victoir, Multidimensional Stochastic Processes as Rough Paths, Ch. 15). The Lévy area over a
  coarse step misses the Lévy areas inside the fine steps, whose sum has :math:`L^2` size of order
  :math:`\delta^{2H - 1/2}\sqrt{h}` (mean zero): for ``H = 0.4`` that is :math:`\delta^{0.3}`, for
  ``H = 0.3`` only :math:`\delta^{0.1}` (measured in ``tests/roughpaths/drivers/test_fbm_levy_area_convergence.py``).
  No lift exists for :math:`H \le 1/4` (the areas diverge); :func:`fbm_rough_path` refuses it.

Seeds: every function takes an explicit ``numpy.random.Generator`` or an integer seed; the same seed
and arguments give the same numbers. The Davies–Harte stream pairs series two by two, so a path's
values depend on the batch size (not on chunking, which this module does not do).
"""

from __future__ import annotations

import numbers

import numpy as np

from ..paths.rough_path import RoughPath
from ..paths.rough_path_n import RoughPathN
from ..signatures.signature import signature
from ..validation import (as_float_array, check_batch_shape, check_memory, check_positive_int, check_positive_real,
                         check_times)

__all__ = ["fbm", "fbm_rough_path", "fgn_autocovariance", "piecewise_linear_lift"]

#: Working memory ``fbm`` may allocate (bytes) before it refuses; pass ``max_bytes`` to change it.
MAX_BYTES = 2 ** 31
#: Largest grid for the Cholesky method (its covariance is ``K x K``).
_MAX_CHOLESKY = 8192
#: ``method="auto"`` uses Cholesky at or below this many steps.
_AUTO_CHOLESKY = 32


def _check_hurst(hurst) -> float:
    if isinstance(hurst, bool) or not isinstance(hurst, numbers.Real):
        raise TypeError(f"hurst must be a real number in (0, 1), got {hurst!r}.")
    H = float(hurst)
    if not 0.0 < H < 1.0:
        raise ValueError(f"hurst must lie strictly between 0 and 1, got {H!r} (H = 0.5 is Brownian motion).")
    return H


def _rng(rng):
    if isinstance(rng, np.random.Generator):
        return rng
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool):
        return np.random.default_rng(int(rng))
    raise TypeError(f"rng must be a numpy.random.Generator or an integer seed, got {rng!r}; pass "
                    f"rng=numpy.random.default_rng(seed) (no hidden global state).")


def fgn_autocovariance(hurst, n: int) -> np.ndarray:
    r"""Autocovariance :math:`\gamma(0..n-1)` of unit-step fractional Gaussian noise.

    :math:`\gamma(k) = \tfrac12(|k+1|^{2H} - 2|k|^{2H} + |k-1|^{2H})`; on a grid of step ``h`` the
    increments have covariance :math:`h^{2H}\gamma(|k - l|)`.

    >>> fgn_autocovariance(0.5, 3)          # Brownian increments are independent
    array([1., 0., 0.])
    """
    H = _check_hurst(hurst)
    n = check_positive_int(n, "n")
    check_memory(8.0 * 4 * n, f"the autocovariance of {n} lags", "ask for fewer lags")
    k = np.arange(n, dtype=np.float64)
    return 0.5 * (np.abs(k + 1) ** (2 * H) - 2 * k ** (2 * H) + np.abs(k - 1) ** (2 * H))


def _davies_harte(gamma_ext: np.ndarray, n_series: int, rng: np.random.Generator, scale: float = 1.0):
    r"""``(n_series, K)`` unit-step fGn samples by circulant embedding, or None if the embedding is not PSD.

    ``gamma_ext`` is :math:`\gamma(0..K)` (``K + 1`` entries); the circulant's first row is
    :math:`(\gamma(0), \dots, \gamma(K), \gamma(K-1), \dots, \gamma(1))`, of length ``2K``.
    """
    K = gamma_ext.shape[0] - 1
    row = np.concatenate([gamma_ext, gamma_ext[K - 1:0:-1]])
    M = row.shape[0]
    import scipy.fft                                       # lazy: keeps import roughpaths light

    lam = scipy.fft.fft(row).real                          # circulant eigenvalues (row is symmetric)
    tol = 1e-10 * float(np.max(np.abs(lam)))
    if float(np.min(lam)) < -tol:
        return None
    weight = scale * np.sqrt(np.clip(lam, 0.0, None) / M)
    n_fft = (n_series + 1) // 2
    w = np.empty((n_fft, M), dtype=np.complex128)
    rng.standard_normal(out=w.view(np.float64))            # real, imaginary parts interleaved
    w *= weight
    y = scipy.fft.fft(w, axis=-1, overwrite_x=True)
    out = np.empty((2 * n_fft, K))
    out[0::2] = y.real[:, :K]
    out[1::2] = y.imag[:, :K]
    return out[:n_series]


def _cholesky(gamma: np.ndarray, n_series: int, rng: np.random.Generator) -> np.ndarray:
    K = gamma.shape[0]
    if K > _MAX_CHOLESKY:
        raise ValueError(f"the Cholesky method needs a {K}x{K} covariance; it is limited to "
                         f"{_MAX_CHOLESKY} steps. Use method='davies-harte'.")
    idx = np.arange(K)
    C = gamma[np.abs(idx[:, None] - idx[None, :])]
    import scipy.linalg                                    # lazy: keeps import roughpaths light

    L = scipy.linalg.cholesky(C, lower=True)
    z = rng.standard_normal((n_series, K))
    return z @ L.T


def _fbm_bytes(method: str, n_series: int, K: int) -> float:
    """Bytes :func:`fbm` holds at its peak for ``n_series`` series of ``K`` steps (float, cannot overflow).

    Both methods: the autocovariance and its temporaries (6 (K + 2) floats) and the result
    ``(n_series, K + 1)``. Davies–Harte (``M = 2K``, ``F = ceil(n_series / 2)`` complex series): the
    circulant row, its eigenvalues and weights (6 M floats), the complex noise ``(F, M)`` and its FFT (a second
    ``(F, M)`` if scipy does not transform in place), 16 bytes each, and the real samples ``(2F, K)``; so
    ``8 (6 (K + 2) + 6 M) + 2 * 16 F M + 8 (2F K + n_series (K + 1))``. Cholesky: the covariance, its index
    temporaries and the factor (4 K² floats), the normals and their product with the factor
    (``2 n_series K``); so ``8 (6 (K + 2) + 4 K² + 2 n_series K + n_series (K + 1))``.
    """
    S, K = float(n_series), float(K)
    common = 8.0 * (6 * (K + 2) + S * (K + 1))
    if method == "cholesky":
        return common + 8.0 * (4 * K * K + 2 * S * K)
    F, M = float((n_series + 1) // 2), 2.0 * K
    return common + 8.0 * 6 * M + 2 * 16.0 * F * M + 8.0 * 2 * F * K


def _check_fbm_memory(method: str, n_series: int, K: int, d: int, batch_shape: tuple, max_bytes) -> None:
    """Refuse, before sampling, working memory above ``max_bytes`` or above the memory budget."""
    need = _fbm_bytes(method, n_series, K) + 4096.0         # + Python objects (array headers, FFT plan)
    if need > max_bytes:
        raise ValueError(f"fbm would need about {need / 2**20:.0f} MiB for {n_series} series (dim={d} x batch_shape={batch_shape}) of n_steps={K} steps "
                         f"(method={method!r}) > max_bytes={max_bytes / 2**20:.0f} MiB; sample in smaller "
                         f"batches (a loop over seeds) or pass a larger max_bytes.")
    check_memory(need, f"fbm's working arrays ({n_series} series (dim={d} x batch_shape={batch_shape}) of "
                       f"n_steps={K} steps, method={method!r})",
                 "sample in smaller batches (a loop over seeds) or fewer steps")


def fbm(n_steps: int, hurst, *, rng, T: float = 1.0, dim: int = 1, batch_shape=(), method: str = "auto",
        max_bytes: int = MAX_BYTES) -> np.ndarray:
    r"""Sample fractional Brownian motion exactly on the uniform grid ``linspace(0, T, n_steps + 1)``.

    Parameters
    ----------
    n_steps : int
        Number of grid steps ``K``.
    hurst : float
        Hurst index ``H`` in ``(0, 1)`` (``0.5``: Brownian motion).
    rng : numpy.random.Generator or int
        The random source (an integer is a seed for ``numpy.random.default_rng``).
    T : float
        Final time (default 1).
    dim : int
        Number of independent components ``d``.
    batch_shape : tuple of int
        Leading batch axes.
    method : {"auto", "davies-harte", "cholesky"}
        ``"auto"``: Cholesky for ``K <= 32``, else Davies–Harte (Cholesky if the embedding failed).
    max_bytes : int
        Refuse (before allocating) if the working memory would exceed this many bytes.

    Returns
    -------
    ndarray, shape ``(*batch_shape, K + 1, d)``
        :math:`B^H_{t_k}`, starting at 0.

    Examples
    --------
    >>> import numpy as np
    >>> B = fbm(256, 0.3, rng=np.random.default_rng(0), dim=2, batch_shape=(4,))
    >>> B.shape, float(np.abs(B[..., 0, :]).max())
    ((4, 257, 2), 0.0)
    """
    H = _check_hurst(hurst)
    K = check_positive_int(n_steps, "n_steps")
    d = check_positive_int(dim, "dim")
    T = check_positive_real(T, "T")
    batch_shape = check_batch_shape(batch_shape)
    if method not in ("auto", "davies-harte", "cholesky"):
        raise ValueError(f"method must be 'auto', 'davies-harte' or 'cholesky', got {method!r}.")
    rng = _rng(rng)
    n_series = int(np.prod(batch_shape, dtype=np.int64)) * d
    if method == "auto":
        method = "cholesky" if K <= _AUTO_CHOLESKY else "davies-harte"
    _check_fbm_memory(method, n_series, K, d, batch_shape, max_bytes)
    gamma = fgn_autocovariance(H, K + 1)
    x = None
    if method == "davies-harte":
        x = _davies_harte(gamma, n_series, rng, scale=(T / K) ** H)
    if x is None:
        if method != "cholesky":                           # the embedding failed: Cholesky's own arrays
            _check_fbm_memory("cholesky", n_series, K, d, batch_shape, max_bytes)
        x = _cholesky(gamma[:K], n_series, rng)
        x *= (T / K) ** H
    nb = n_series // d
    out = np.empty((nb, K + 1, d))
    out[:, 0, :] = 0.0
    # cumulative sums written straight into the (batch, time, component) layout
    np.cumsum(x.reshape(nb, d, K), axis=-1, out=np.swapaxes(out[:, 1:, :], -1, -2))
    return out.reshape(batch_shape + (K + 1, d))


def piecewise_linear_lift(values, substeps: int, *, level: int = 2, times=None):
    r"""Rough path of the piecewise-linear interpolation of fine samples, on the coarse grid.

    Parameters
    ----------
    values : array_like, shape ``(..., K m + 1, d)``
        Samples on the fine grid.
    substeps : int
        ``m``, fine steps per coarse step.
    level : int
        1 or 2: a :class:`~roughpaths.RoughPath`; ``>= 3``: a :class:`~roughpaths.RoughPathN`.
    times : array_like, shape ``(K m + 1,)``, optional
        Fine grid times (default ``linspace(0, 1, K m + 1)``); the result lives on ``times[::m]``.

    Returns
    -------
    RoughPath or RoughPathN
        Step ``k`` is the signature, truncated at ``level``, of the polygon through
        ``values[..., k m : (k+1) m + 1, :]`` (exact iterated integrals of the polygon).

    Examples
    --------
    >>> import numpy as np
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    >>> X = piecewise_linear_lift(pts, 4)                  # one coarse step: the unit square
    >>> float(X.levy_area(0.0, 1.0)[0, 1])
    1.0
    """
    v = as_float_array(values, "values", min_ndim=2)
    m = check_positive_int(substeps, "substeps")
    level = check_positive_int(level, "level")
    nf = v.shape[-2] - 1
    if nf < 1 or nf % m:
        raise ValueError(f"values has {nf} fine steps (axis -2 holds {nf + 1} samples), which is not a positive "
                         f"multiple of substeps={m}; give K*m + 1 samples.")
    t = np.linspace(0.0, 1.0, nf + 1) if times is None else check_times(times, "times", n=nf + 1)
    K, d = nf // m, v.shape[-1]
    if level > 2:
        from ..algebra.tensor import sigdim

        try:
            size = sigdim(d, level)
        except ValueError as exc:
            raise ValueError(f"level={level} is too deep: {exc}") from None
        check_memory(8.0 * 2 * size * K * max(1, v.size // max(1, v.shape[-1] * v.shape[-2])),
                     f"the level-{level} step signatures (sigdim({d}, {level}) = {size} per step, {K} steps)",
                     "ask for a lower level")
    tc = t[::m]
    if level == 1:
        return RoughPath(np.diff(v[..., ::m, :], axis=-2), None, times=tc, x0=v[..., 0, :], check=False)
    if m == 1:
        seg_sig = None
    else:
        v = np.ascontiguousarray(v)
        st = v.strides
        seg = np.lib.stride_tricks.as_strided(v, shape=v.shape[:-2] + (K, m + 1, d),
                                              strides=st[:-2] + (m * st[-2], st[-2], st[-1]), writeable=False)
        seg_sig = signature(seg, level)                    # (..., K, sigdim)
    if seg_sig is None:
        return (RoughPath.from_path(v, times=tc) if level == 2 else RoughPathN.from_path(v, level, times=tc))
    if level == 2:
        return RoughPath(seg_sig[..., :d], seg_sig[..., d:].reshape(seg_sig.shape[:-1] + (d, d)), times=tc,
                         x0=v[..., 0, :], kind="geometric", check=False)
    return RoughPathN(seg_sig, d, times=tc, x0=v[..., 0, :], check=False)


def fbm_rough_path(n_steps: int, hurst, *, rng, substeps: int = 16, level: int = 2, T: float = 1.0,
                   dim: int = 2, batch_shape=(), method: str = "auto", max_bytes: int = MAX_BYTES):
    r"""Fractional Brownian rough path: fBM sampled on a fine grid and lifted by :func:`piecewise_linear_lift`.

    The trace at the ``n_steps + 1`` coarse grid times is exact fBM; levels ``>= 2`` are the
    iterated integrals of the polygon through ``n_steps * substeps + 1`` exact samples (see the
    module docstring for the error of this lift against the canonical lift).

    Parameters
    ----------
    n_steps : int
        Coarse steps ``K`` of the returned rough path.
    hurst : float
        ``H`` in ``(1/4, 1)`` (no geometric lift exists for ``H <= 1/4``). ``level`` must be at least
        ``floor(1/H)`` so that the path is a ``p``-rough path with ``p < level + 1``.
    rng : numpy.random.Generator or int
    substeps : int
        ``m``, fine steps per coarse step (default 16).
    level : int
        2: a :class:`~roughpaths.RoughPath` (``H > 1/3``); 3: a :class:`~roughpaths.RoughPathN`
        (``H > 1/4``); higher levels are allowed.
    T, dim, batch_shape, method, max_bytes
        As for :func:`fbm` (``dim`` defaults to 2 here: a one-dimensional path has no area).

    Examples
    --------
    >>> import numpy as np
    >>> X = fbm_rough_path(64, 0.3, rng=np.random.default_rng(1), substeps=8, level=3, batch_shape=(5,))
    >>> X
    RoughPathN(level=3, d=2, n_steps=64, batch_shape=(5,), t=[0, 1])
    """
    H = _check_hurst(hurst)
    level = check_positive_int(level, "level")
    if H <= 0.25:
        raise ValueError(f"hurst={H} <= 1/4: fractional Brownian motion has no geometric rough-path lift "
                         f"(its piecewise-linear Lévy areas diverge); use H > 1/4.")
    need = int(np.floor(1.0 / H))
    if level < need:
        raise ValueError(f"hurst={H} makes the path p-rough only for p > {1 / H:.3g}; the lift needs level >= "
                         f"{need} (level={level} given). Use level={need}, e.g. a RoughPathN at level 3 "
                         f"for 1/4 < H <= 1/3.")
    K = check_positive_int(n_steps, "n_steps")
    m = check_positive_int(substeps, "substeps")
    try:
        values = fbm(K * m, H, rng=rng, T=T, dim=dim, batch_shape=batch_shape, method=method, max_bytes=max_bytes)
    except ValueError as exc:
        if "would need" not in str(exc):
            raise
        raise ValueError(f"n_steps={K} x substeps={m} fine steps: {exc}") from None
    return piecewise_linear_lift(values, m, level=level, times=np.linspace(0.0, float(T), K * m + 1))
