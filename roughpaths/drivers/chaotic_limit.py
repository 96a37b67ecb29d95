r"""The Brownian limit of chaotic drivers: Green–Kubo estimates of ``Σ`` and ``E``, and the perturbed limit path.

Derivation, in the library's conventions (``docs/conventions.md``: ``XX[a, b] = ∫ (X^a − X^a_s) dX^b``,
perturbation ``XX + s (t − s)`` with ``s`` antisymmetric). Take a map ``T`` with invariant ``μ``, an
observable ``v`` (``∫ v dμ = 0``), ``y_0 ~ μ``, ``v_j = v(T^j y_0)`` and ``Δ_j = n^{-1/2} v_j``
(:mod:`roughpaths.drivers.chaotic`). Write

.. math:: C(m) = \int v\otimes (v\circ T^m)\, d\mu, \quad E = \sum_{m\ge1} C(m), \quad
          \Sigma_0 = C(0), \quad \Sigma = \Sigma_0 + E + E^T,

so ``C^{ab}(m) = E[v^a_0 v^b_m]``: the **earlier** ``a``, the **later** ``b``.

1. *Mean of the iterated sums (exact).* By stationarity ``E[v_i ⊗ v_j] = C(j − i)`` for ``i < j``, so with
   ``N = nt`` fast steps ``E[Σ_{0≤i<j<N} Δ_i⊗Δ_j] = t Σ_{m<N} C(m) − n⁻¹ Σ_{m<N} m C(m) → t E``. The
   entry ``[a, b]`` pairs the earlier ``Δ^a`` with the later ``Δ^b``, as ``XX[a, b]`` does: **no transpose**
   between Kelly–Melbourne's ``E^{ab}`` and the library's area.
2. *Limit of the iterated sums* (Kelly and Melbourne 2016, Thm 1.1; for these maps also Chevyrev, Friz,
   Korepanov, Melbourne and Zhang 2019): ``(W_n, Σ_{i<j} Δ_i⊗Δ_j) → (W, ∫ W ⊗ dW + E t)`` in law, ``W``
   Brownian with covariance ``Σ``, ``∫ W ⊗ dW`` the **Itô** area.
3. *The piecewise-linear lift* that :class:`~roughpaths.drivers.chaotic.ChaoticDriver` gives adds
   ``½ Σ_j Δ_j⊗Δ_j → ½ Σ_0 t`` (ergodic theorem). The Stratonovich area is the Itô area plus ``½ Σ t``, so
   the lift tends to the Stratonovich area plus ``(E + ½Σ_0 − ½Σ) t = ½(E − Eᵀ) t``: the symmetric parts
   cancel (the lift is geometric, so must its limit be), and the limit is the Stratonovich Brownian rough
   path **perturbed by** ``s = Alt(E) = ½(E − Eᵀ)``, the Lévy-area drift. Its expected area rate is
   ``½ Σ + Alt(E)`` (:attr:`ChaoticLimit.area_rate`).
4. *Fast–slow systems* ``dx = a dt + b(x) dX`` (fields ``b_β``, Friz–Oberhauser: a perturbation ``K (t − s)``
   of the area is the drift ``Σ K^{βγ} Db_γ·b_β``):

   * driven by the piecewise-linear path (``x' = a(x) + n^{1/2} b(x) v_j`` on fast step ``j``, i.e.
     ``solve`` on the driver with a convergent scheme): the Stratonovich equation plus
     ``Σ_{βγ} s^{βγ} Db_γ·b_β = ½ Σ s^{βγ}[b_β, b_γ]`` (``solve`` on :func:`chaotic_limit_path`);
   * the Euler system of the theory, ``x_{k+1} = x_k + n⁻¹ a(x_k) + b(x_k) Δ_k``, sees the
     piecewise-constant sums: the Itô equation plus ``Σ E^{βγ} Db_γ·b_β`` (Kelly–Melbourne), i.e. the
     limit path of (3) with the extra drift ``−½ Σ Σ_0^{βγ} Db_γ·b_β``.

   For linear fields ``a(x) = A_0 x``, ``b_γ(x) = B_γ x`` (``Db_γ·b_β = B_γ B_β``) the mean solves a linear
   ODE: ``E[x_t] = exp(t (A_0 + Σ_{βγ} K^{βγ} B_γ B_β)) x_0`` with ``K = E + ½Σ_0`` (piecewise linear),
   ``K = E`` (Euler); the wrong guesses are ``K = ½Σ`` (Stratonovich without the area) and ``K = 0`` (Itô
   without ``E``).

Exact example (``E`` in closed form, :class:`SineObservable`). On a cat map ``y ↦ A y mod 1`` with
sine observables ``v^a(y) = Σ_r c_{ar} sin(2π k_{ar}·y)``, ``sin(2π l·A^m y) = sin(2π (Aᵀ)^m l·y)`` and
``∫ sin(2π p·y) sin(2π q·y) dy = ½(1{p = q} − 1{p = −q})`` for non-zero integer ``p, q``, so

.. math:: C^{ab}(m) = \tfrac12 \sum_{r,s} c_{ar} c_{bs}\,[\,1\{k_{ar} = (A^T)^m k_{bs}\}
          - 1\{k_{ar} = -(A^T)^m k_{bs}\}\,]:

``C(m)`` vanishes once ``(Aᵀ)^m`` has carried every frequency past the others, and ``E`` is a finite
sum. Odd observables have vanishing odd moments (``y ↦ −y`` commutes with ``A``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..paths.rough_path import RoughPath
from ..validation import as_float_array, check_memory, check_positive_int

__all__ = ["GreenKuboEstimate", "green_kubo", "ChaoticLimit", "chaotic_limit", "chaotic_limit_path",
           "SineObservable"]


@dataclass(frozen=True)
class ChaoticLimit:
    r"""The Brownian limit of a chaotic driver: ``(M B, M BB Mᵀ + s (t − s))``, ``M Mᵀ = Σ``, ``s = Alt(E)``.

    Attributes
    ----------
    Sigma : ndarray ``(d, d)``
        Covariance of the limiting Brownian motion per unit time, ``C(0) + E + Eᵀ``.
    E : ndarray ``(d, d)``
        ``Σ_{m≥1} C(m)``: the rate of the piecewise-constant iterated sums beyond Itô.
    scaling : ndarray ``(d, d)``
        ``M``, the symmetric square root of ``Σ`` (``Σ`` may be singular).
    levy_perturbation : ndarray ``(d, d)``
        ``s = ½(E − Eᵀ)``, the perturbation of the Stratonovich area (module docstring, step 3).
    area_rate : ndarray ``(d, d)``
        ``½ Σ + s``: the expected area of the driver's (geometric) lift per unit time.
    """

    Sigma: np.ndarray
    E: np.ndarray
    scaling: np.ndarray
    levy_perturbation: np.ndarray
    area_rate: np.ndarray


def chaotic_limit(Sigma, E) -> ChaoticLimit:
    r"""The limit of a chaotic driver from its covariance ``Σ`` and its one-sided correlation sum ``E``.

    Parameters
    ----------
    Sigma : array_like, shape ``(d, d)``
        Symmetric positive semi-definite (a negative eigenvalue below ``−1e-10 ‖Σ‖`` is refused).
    E : array_like, shape ``(d, d)``

    Returns
    -------
    ChaoticLimit

    Examples
    --------
    >>> import numpy as np
    >>> lim = chaotic_limit(np.eye(2), np.array([[0.0, 0.0], [0.5, 0.0]]))
    >>> lim.levy_perturbation
    array([[ 0.  , -0.25],
           [ 0.25,  0.  ]])
    """
    S = as_float_array(Sigma, "Sigma", ndim=2)
    d = S.shape[0]
    if S.shape != (d, d) or d == 0:
        raise ValueError(f"Sigma must be a square (d, d) matrix with d >= 1, got shape {S.shape}.")
    Em = as_float_array(E, "E", ndim=2)
    if Em.shape != (d, d):
        raise ValueError(f"E must have the shape of Sigma, ({d}, {d}), got {Em.shape}.")
    scale = max(float(np.max(np.abs(S))), 1e-300)
    if float(np.max(np.abs(S - S.T))) > 1e-10 * scale:
        raise ValueError(f"Sigma must be symmetric, but |Sigma - Sigma.T| reaches {float(np.max(np.abs(S - S.T))):.3g}; "
                         f"pass 0.5 * (Sigma + Sigma.T).")
    S = 0.5 * (S + S.T)
    lam, U = np.linalg.eigh(S)
    if lam[0] < -1e-10 * max(scale, float(lam[-1])):
        raise ValueError(f"Sigma must be positive semi-definite, but its smallest eigenvalue is {lam[0]:.4g} "
                         f"(largest {lam[-1]:.4g}). An estimate may be indefinite within its error: check the "
                         f"eigenvalue against the standard error (GreenKuboEstimate.Sigma_se), then use more data, "
                         f"a longer max_lag, or pass the projection U diag(max(lam, 0)) U.T if that is intended.")
    M = (U * np.sqrt(np.clip(lam, 0.0, None))) @ U.T
    s = 0.5 * (Em - Em.T)
    for a in (S, Em, M, s):
        a.setflags(write=False)
    rate = 0.5 * S + s
    rate.setflags(write=False)
    return ChaoticLimit(Sigma=S, E=Em, scaling=M, levy_perturbation=s, area_rate=rate)


def chaotic_limit_path(limit: ChaoticLimit, brownian: RoughPath) -> RoughPath:
    r"""The limit driver ``(M B, M BB Mᵀ + s (t − s))`` from a standard Stratonovich Brownian rough path.

    Parameters
    ----------
    limit : ChaoticLimit
    brownian : RoughPath
        A geometric level-2 lift of a standard ``d``-dimensional Brownian motion (e.g.
        :func:`roughpaths.brownian_rough_path`).

    Returns
    -------
    RoughPath
        Dimension ``d``, geometric; ready for :func:`roughpaths.solve`.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import brownian_rough_path
    >>> lim = chaotic_limit(np.eye(2), np.array([[0.0, 0.0], [0.5, 0.0]]))
    >>> B = brownian_rough_path(np.linspace(0, 1, 11), 2, np.random.default_rng(0), batch_shape=(5,))
    >>> X = chaotic_limit_path(lim, B)
    >>> bool(np.allclose(X.levy_area(0.0, 1.0) - B.levy_area(0.0, 1.0), lim.levy_perturbation))
    True
    """
    if not isinstance(limit, ChaoticLimit):
        raise TypeError(f"limit must be a ChaoticLimit (from chaotic_limit(Sigma, E)), got {type(limit).__name__}.")
    if not isinstance(brownian, RoughPath):
        raise TypeError(f"brownian must be a RoughPath, got {type(brownian).__name__}.")
    d = limit.Sigma.shape[0]
    if brownian.dim != d:
        raise ValueError(f"brownian has dimension {brownian.dim} but Sigma is {d}x{d}; they must match.")
    if brownian.level != 2 or brownian.kind != "geometric":
        raise ValueError(f"brownian must be a geometric (Stratonovich) level-2 rough path, got level "
                         f"{brownian.level}, kind {brownian.kind!r}: the limit is Stratonovich plus Alt(E); "
                         f"build it with brownian_rough_path(..., kind='stratonovich').")
    M = limit.scaling
    base = RoughPath(brownian.increments @ M.T, M @ brownian.areas @ M.T, times=brownian.times,
                     x0=brownian.x0 @ M.T, kind="geometric", check=False)
    return base.perturb(limit.levy_perturbation)


@dataclass(frozen=True)
class GreenKuboEstimate:
    r"""Green–Kubo estimates from orbits (:func:`green_kubo`); every ``*_se`` is a standard error.

    Attributes
    ----------
    E, E_se : ndarray ``(d, d)``
        ``Σ_{m=1}^{M} Ĉ(m)`` and its standard error.
    Sigma, Sigma_se : ndarray ``(d, d)``
        ``Ĉ(0) + Ê + Êᵀ`` and its standard error.
    correlations, correlations_se : ndarray ``(M + 1, d, d)``
        ``Ĉ(m)`` for ``m = 0 … M``.
    tail, tail_se : ndarray ``(d, d)``
        ``Σ_{M/2 < m ≤ M} Ĉ(m)``: the diagnostic of the truncation (for correlations decaying like ``ρ^m``
        the neglected ``Σ_{m>M} C(m)`` is ``ρ^{M/2}/(1 − ρ^{M/2})`` times its mean).
    mean, mean_se : ndarray ``(d,)``
        The sample mean of ``v`` (``∫ v dμ = 0`` is required).
    max_lag, n_orbits, length : int
    """

    E: np.ndarray
    E_se: np.ndarray
    Sigma: np.ndarray
    Sigma_se: np.ndarray
    correlations: np.ndarray
    correlations_se: np.ndarray
    tail: np.ndarray
    tail_se: np.ndarray
    mean: np.ndarray
    mean_se: np.ndarray
    max_lag: int
    n_orbits: int
    length: int

    def limit(self) -> ChaoticLimit:
        """``chaotic_limit(self.Sigma, self.E)``."""
        return chaotic_limit(self.Sigma, self.E)


def green_kubo(values, max_lag: int) -> GreenKuboEstimate:
    r"""Estimate ``C(m)``, ``E = Σ_{m≥1} C(m)`` and ``Σ`` from observable values along independent orbits.

    Parameters
    ----------
    values : array_like, shape ``(..., L, d)``
        ``v(y_j)``, ``j < L``, along orbits started from the invariant measure (the batch axes: independent
        orbits, at least 2), e.g. from :func:`roughpaths.drivers.chaotic.observable_orbits`.
    max_lag : int
        ``M``: lags ``1 … M`` enter ``E`` (``M < L``).

    Returns
    -------
    GreenKuboEstimate

    Notes
    -----
    Per orbit, ``Ĉ_p(m) = (L − m)⁻¹ Σ_{i < L−m} v_i ⊗ v_{i+m}`` (by FFT, zero-padded to ``≥ L + M``); the
    estimates are the means over orbits and the standard errors the standard deviations over orbits
    over ``√P`` (orbits from independent initial points are independent). *Bias*: from a stationary start
    each product has mean ``C(m)``, so ``E[Ê] = Σ_{m≤M} C(m)`` exactly: the bias is the truncation
    ``−Σ_{m>M} C(m)`` alone (zero when the correlations vanish beyond ``M``, as in the cat-map example);
    :attr:`GreenKuboEstimate.tail` shows whether it is negligible. A sample mean that differs from 0 at the
    two-sided level 10⁻⁶ (Student's t over the ``P`` orbit means) is refused: the observable must be centred.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> g = rng.standard_normal((50, 2001, 1))
    >>> v = g[:, 1:] + 0.5 * g[:, :-1]             # MA(1): C(0) = 1.25, C(1) = 0.5
    >>> est = green_kubo(v, 5)
    >>> bool(abs(est.E[0, 0] - 0.5) < 4 * est.E_se[0, 0]), bool(abs(est.Sigma[0, 0] - 2.25) < 4 * est.Sigma_se[0, 0])
    (True, True)
    """
    v = as_float_array(values, "values", min_ndim=3)
    L, d = v.shape[-2], v.shape[-1]
    if d == 0:
        raise ValueError(f"values must have at least one component (shape (..., L, d) with d >= 1), got shape "
                         f"{v.shape}.")
    v = v.reshape(-1, L, d)
    P = v.shape[0]
    M = check_positive_int(max_lag, "max_lag")
    if P < 2:
        raise ValueError(f"values must hold at least 2 independent orbits (batch axes) for a standard error, got "
                         f"shape {np.shape(values)}.")
    if M >= L:
        raise ValueError(f"max_lag must be smaller than the orbit length L = {L}, got max_lag={M}; use longer "
                         f"orbits or a smaller max_lag.")
    mean_p = v.mean(axis=1)
    mean, mean_se = mean_p.mean(axis=0), mean_p.std(axis=0, ddof=1) / np.sqrt(P)
    from scipy.stats import t as student_t                        # (lazy: scipy.stats is slow to import)

    crit = float(student_t.isf(0.5e-6, P - 1))                   # two-sided level 1e-6, P − 1 degrees of freedom
    off = np.abs(mean) > crit * mean_se
    if np.any(off):
        a = int(np.argmax(off))
        raise ValueError(f"values[..., {a}] has sample mean {mean[a]:.4g} ± {mean_se[a]:.2g} (standard error over {P} "
                         f"orbits): not centred (beyond {crit:.3g} standard errors, the two-sided 1e-6 level of "
                         f"Student's t with {P - 1} degrees of freedom). The Green–Kubo sums need ∫ v dμ = 0; "
                         f"subtract the observable's mean under the invariant measure.")
    nfft = _fast_len(L + M)
    per_orbit = 16.0 * (nfft // 2 + 1) * (d + d * d) + 8.0 * nfft * d * d
    check_memory(per_orbit, "the FFT workspace of one orbit", "use shorter orbits")
    chunk = max(1, int((64 << 20) // per_orbit))
    # C and the two temporaries of its standard deviation, and the FFT workspace of a chunk of orbits
    check_memory(3 * 8.0 * P * (M + 1) * d * d + min(P, chunk) * per_orbit,
                 f"the correlations of {P} orbits ({P} x {M + 1} lags x {d} x {d}) and their FFT workspace",
                 "use a smaller max_lag, fewer orbits or fewer components")
    C = np.empty((P, M + 1, d, d))
    norm = 1.0 / (L - np.arange(M + 1))
    for p0 in range(0, P, chunk):
        F = np.fft.rfft(v[p0:p0 + chunk], n=nfft, axis=1)          # (c, nf, d)
        prod = np.conj(F)[:, :, :, None] * F[:, :, None, :]         # (c, nf, d, d): a earlier, b later
        R = np.fft.irfft(prod, n=nfft, axis=1)[:, :M + 1]
        C[p0:p0 + chunk] = R * norm[None, :, None, None]
    E_p = C[:, 1:].sum(axis=1)
    S_p = C[:, 0] + E_p + np.swapaxes(E_p, -1, -2)
    T_p = C[:, M // 2 + 1:].sum(axis=1)

    def est(x):
        return x.mean(axis=0), x.std(axis=0, ddof=1) / np.sqrt(P)

    (E, E_se), (S, S_se), (Cm, C_se), (tail, tail_se) = est(E_p), est(S_p), est(C), est(T_p)
    return GreenKuboEstimate(E=E, E_se=E_se, Sigma=0.5 * (S + S.T), Sigma_se=S_se, correlations=Cm,
                             correlations_se=C_se, tail=tail, tail_se=tail_se, mean=mean, mean_se=mean_se,
                             max_lag=M, n_orbits=P, length=L)


def _fast_len(n: int) -> int:
    """The smallest ``2^a 3^b 5^c >= n`` (a fast FFT length)."""
    best = 1 << int(np.ceil(np.log2(max(n, 1))))
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            p = p35
            while p < n:
                p *= 2
            best = min(best, p)
            p35 *= 3
        p5 *= 5
    return best


class SineObservable:
    r"""``v^a(y) = Σ_r c_{ar} sin(2π k_{ar}·y)`` on the torus, with the exact correlations under a cat map.

    Parameters
    ----------
    frequencies : array_like of int, shape ``(d, R, 2)``
        Non-zero integer frequency vectors ``k_{ar}``.
    coefficients : array_like, shape ``(d, R)``
        ``c_{ar}`` (a zero coefficient pads a component with fewer terms).

    Examples
    --------
    >>> import numpy as np
    >>> A = [[2, 1], [1, 1]]
    >>> v = SineObservable([[[1, 0]], [[2, 1]]], [[1.0], [1.0]])   # v² = v¹∘T: C²¹(1) = ½
    >>> v.correlations(3, A)[1].tolist()
    [[0.0, 0.0], [0.5, 0.0]]
    >>> v(np.array([[0.25, 0.0]])).round(12).tolist()       # (sin(π/2), sin(π))
    [[1.0, 0.0]]
    """

    def __init__(self, frequencies, coefficients):
        k = np.asarray(frequencies)
        if k.ndim != 3 or k.shape[-1] != 2 or k.dtype.kind not in "iu":
            raise ValueError(f"frequencies must be an integer array of shape (d, R, 2), got {k.dtype} {k.shape}.")
        if np.any(np.all(k == 0, axis=-1)):
            raise ValueError("frequencies must be non-zero vectors (sin(0) = 0 adds nothing; drop the term).")
        c = as_float_array(coefficients, "coefficients", ndim=2)
        if c.shape != k.shape[:2]:
            raise ValueError(f"coefficients must have shape (d, R) = {k.shape[:2]}, got {c.shape}.")
        self.frequencies, self.coefficients = k.astype(np.int64), c
        d, R = c.shape
        self._freq = (2.0 * np.pi) * k.reshape(d * R, 2).T.astype(np.float64)     # (2, dR): phases by one matmul
        self._weights = np.zeros((d * R, d))                                      # (dR, d): the sums over r
        self._weights[np.arange(d * R), np.repeat(np.arange(d), R)] = c.ravel()

    def __call__(self, y) -> np.ndarray:
        """``v(y)``, ``y`` of shape ``(..., 2)`` to ``(..., d)``."""
        y = np.asarray(y, dtype=np.float64)
        if y.ndim < 1 or y.shape[-1] != 2:
            raise ValueError(f"y must have shape (..., 2) (points of the 2-torus), got shape {y.shape}; pass "
                             f"cat_map().coordinates(states), or y[None] for one point.")
        return np.sin(y @ self._freq) @ self._weights

    def correlations(self, max_lag: int, matrix=((2, 1), (1, 1))) -> np.ndarray:
        r"""``C(m) = ∫ v ⊗ v∘T^m dy`` for ``m = 0 … max_lag`` under ``y ↦ A y mod 1`` (exact, module docstring).

        Returns
        -------
        ndarray, shape ``(max_lag + 1, d, d)``
        """
        M = check_positive_int(max_lag, "max_lag", minimum=0)
        A = np.asarray(matrix)
        if A.shape != (2, 2) or A.dtype.kind not in "iu":
            raise ValueError(f"matrix must be a 2x2 integer matrix, got {np.asarray(matrix)!r}.")
        k, c = self.frequencies.astype(object), self.coefficients     # Python integers: exact at every lag
        At = A.astype(object)
        d, R = c.shape
        # the result; the comparisons of k with (Aᵀ)^m k ((dR)² objects, bools and floats: 48 bytes a pair); the Python
        # integers of (Aᵀ)^m k, of its product and negation (8 dR of them, m log₂ρ(A) + 64 bits each)
        bits = (M + 1) * math.log2(max(1.0, float(np.max(np.abs(np.linalg.eigvals(A.astype(float))))))) + 64.0
        check_memory(8.0 * (M + 1) * d * d + 48.0 * (d * R) ** 2 + 8.0 * d * R * (32.0 + bits / 7.5),
                     f"the correlations ({M + 1} lags x {d} x {d})", "use a smaller max_lag")
        out = np.zeros((M + 1, d, d))
        moved = k.copy()                                              # (Aᵀ)^m k, as row vectors l ↦ l A
        for m in range(M + 1):
            if m:
                moved = moved @ At
            same = np.all(k[:, :, None, None, :] == moved[None, None, :, :, :], axis=-1)
            opp = np.all(k[:, :, None, None, :] == -moved[None, None, :, :, :], axis=-1)
            out[m] = 0.5 * np.einsum("ar,bs,arbs->ab", c, c, same.astype(float) - opp.astype(float))
        return out
