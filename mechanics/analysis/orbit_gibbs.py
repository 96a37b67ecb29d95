r"""The Gibbs measure of Theorem 3.1 on a coadjoint orbit of a compact matrix Lie algebra, by importance sampling.

Theorem 3.1 beyond the rigid body
---------------------------------
Let :math:`\mathfrak g` be a compact :class:`~mechanics.MatrixLieAlgebra` (so(n), su(N), u(N)) in a basis
orthonormal for the trace form :math:`B(A, C) = -\tfrac12\mathrm{Re}\,\mathrm{tr}(AC)` (the built-in bases are),
so that the coordinate dot product is Ad-invariant and the dissipation's ``♯`` (the default metric of
:class:`~mechanics.LiePoissonSystem`) is the identity. The equation of Theorem 3.1 in the library's form
(``docs/conventions.md``),

.. math::

    d\mu = \mathrm{ad}^*_{\nabla\tilde h}\mu\,dt + \vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp}
           \mu\,dt + \sum_i\mathrm{ad}^*_{\xi_i}\mu\circ dW^i,\qquad
    \tilde h = h + \langle\mu, \ell\rangle,\quad \ell = \tfrac12\mathsf s^{ij}[\xi_i, \xi_j],

with isotropic noise, :math:`\sum_i\xi_i\xi_i^T = \sigma^2 I` (e.g. :math:`\xi_i = \sigma e_i`), has on each
coadjoint orbit :math:`\mathcal O` the invariant law

.. math::  p(\mu)\,\nu(d\mu) = Z^{-1}e^{-\beta\tilde h(\mu)}\,\nu(d\mu),\qquad \beta = 2\vartheta/\sigma^2,

with :math:`\nu` the uniform (Ad-invariant) measure on :math:`\mathcal O`. Derivation: write
:math:`V_i(\mu) = \mathrm{ad}^*_{\xi_i}\mu`. The :math:`V_i` generate the group action, which preserves
:math:`\nu`, so they are divergence-free for it and :math:`V_i^* = -V_i` on :math:`L^2(\nu)`. Next
:math:`V_i\tilde h = \langle\mu, [\xi_i, \nabla\tilde h]\rangle = -\xi_i\cdot v` with
:math:`v = \mathrm{ad}^*_{\nabla\tilde h}\mu`, so :math:`\sum_i (V_i\tilde h)V_i =
-\mathrm{ad}^*_{(\sum_i\xi_i\xi_i^T)v}\mu = -\sigma^2\,\mathrm{ad}^*_{v}\mu`: the dissipation is
:math:`-(\vartheta/\sigma^2)\sum_i(V_i\tilde h)V_i`. The Hamiltonian field
:math:`\mathrm{ad}^*_{\nabla\tilde h}\mu` preserves both :math:`\nu` (Liouville) and :math:`\tilde h`. The
Fokker–Planck operator for a density :math:`p` w.r.t. :math:`\nu` is therefore
:math:`\sum_i V_i\big(\tfrac{\sigma^2}{2}V_ip + \vartheta(V_i\tilde h)p\big) - \{\ldots\}`, and
:math:`p = e^{-\beta\tilde h}` makes every bracket vanish iff :math:`\beta = 2\vartheta/\sigma^2`. On so(3) with
:math:`\xi_i = \sigma e_i` this is the rigid body's :func:`~mechanics.analysis.gibbs.gibbs_beta`. The printed
:math:`\tilde h = h - \langle\mu, \tfrac12\mathsf s^{ij}[\xi_i,\xi_j]\rangle` of the paper has the wrong sign
(``docs/conventions.md``).

The importance-sampling oracle
------------------------------
:class:`OrbitGibbsMeasure` estimates expectations under :math:`p\,\nu` by self-normalised importance sampling
from exact samples of :math:`\nu` (:meth:`MatrixLieAlgebra.sample_orbit`: :math:`UMU^{-1}` with Haar :math:`U`), weights
:math:`w_k\propto e^{-\beta\tilde h(\mu_k)}`. The estimate :math:`\hat f = \sum_k w_kf(\mu_k)/\sum_k w_k` has the
delta-method standard error :math:`\big(\sum_k w_k^2(f(\mu_k) - \hat f)^2\big)^{1/2}/\sum_k w_k` and effective
sample size :math:`(\sum_k w_k)^2/\sum_k w_k^2`; both are reported. This is independent of any SDE solver: it
uses only the orbit's uniform law and the energy. Its cost is one Haar matrix per sample (``O(N³)``); its
accuracy degrades when :math:`\beta` times the spread of :math:`\tilde h` over the orbit is large (the effective
sample size falls like :math:`e^{-\beta\,\mathrm{spread}}`), where a quadrature or MCMC is needed instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughpaths.validation import as_float_array, check_memory, check_positive_int, check_rng

from ..ensemble import moment_observable
from ..systems import LiePoissonSystem, MatrixLieAlgebra

__all__ = ["OrbitGibbsMeasure", "OrbitExpectation", "orbit_gibbs_beta", "isotropic_sigma"]

#: How far from ``σ² I`` the noise covariance ``Σ ξ_i ξ_iᵀ`` may be (relative) and still count as isotropic.
_ISOTROPY_RTOL = 1e-10
#: Haar samples drawn per batch (the QR temporaries are a few times this many ``N × N`` matrices).
_CHUNK = 20_000


@dataclass(frozen=True)
class OrbitExpectation:
    """An importance-sampling estimate of a Gibbs expectation on an orbit (:meth:`OrbitGibbsMeasure.expectation`).

    Attributes
    ----------
    mean : ndarray, shape ``(p,)`` (or ``()`` for a scalar function)
        The estimate of :math:`E_p[f]`.
    standard_error : ndarray, same shape
        Its delta-method standard error.
    effective_sample_size : float
        :math:`(\\sum w)^2/\\sum w^2` (the number of independent samples the estimate is worth).
    n_samples : int
        Number of uniform orbit samples used.
    """

    mean: np.ndarray
    standard_error: np.ndarray
    effective_sample_size: float
    n_samples: int


def isotropic_sigma(xi) -> float:
    r"""The amplitude :math:`\sigma > 0` of isotropic noise, :math:`\sum_i\xi_i\xi_i^T = \sigma^2 I` (else ``ValueError``).

    Parameters
    ----------
    xi : array_like, shape ``(m, n)``
        Noise vectors (rows), in a basis orthonormal for the invariant form.

    Examples
    --------
    >>> isotropic_sigma(0.5 * np.eye(8))
    0.5
    >>> q, _ = np.linalg.qr(np.random.default_rng(0).standard_normal((4, 4)))
    >>> round(isotropic_sigma(0.3 * q), 12)          # any orthogonal frame times σ
    0.3
    """
    xi = as_float_array(xi, "xi", ndim=2)
    cov = xi.T @ xi
    n = cov.shape[0]
    s2 = float(np.trace(cov)) / n
    if not s2 > 0 or np.max(np.abs(cov - s2 * np.eye(n))) > _ISOTROPY_RTOL * s2:
        raise ValueError(f"the Gibbs measure exp(-2θh̃/σ²) needs isotropic noise, Σ_i ξ_i ξ_iᵀ = σ² I (e.g. xi = σ·I); "
                         f"this xi (shape {xi.shape}) has Σ ξ_i ξ_iᵀ with eigenvalues "
                         f"{np.round(np.linalg.eigvalsh(cov), 6).tolist()}.")
    return float(np.sqrt(s2))


def _check_orthonormal_compact(algebra) -> None:
    if not isinstance(algebra, MatrixLieAlgebra):
        raise TypeError(f"algebra must be a compact MatrixLieAlgebra (mechanics.so(n), su(N), u(N)), got "
                        f"{type(algebra).__name__}; for the rigid body on so3() use mechanics.GibbsMeasure.")
    if not algebra.compact:
        raise ValueError(f"{algebra.name} is not compact: its orbits carry no finite invariant measure, and "
                         f"there is no Gibbs measure of Theorem 3.1 on them.")
    n = algebra.dim
    check_memory(8.0 * n * n, f"the Gram matrix of {algebra.name}", "use an algebra of smaller dimension")
    if np.max(np.abs(algebra.gram - np.eye(n))) > 1e-12:
        raise ValueError(f"the basis of {algebra.name} is not orthonormal for the trace form (Gram matrix ≠ I); "
                         f"Theorem 3.1's β = 2θ/σ² is stated in an orthonormal basis (the built-in so/su/u are).")


def orbit_gibbs_beta(system) -> float:
    r"""Inverse temperature :math:`\beta = 2\vartheta/\sigma^2` of Theorem 3.1 for a system on a compact matrix algebra.

    Checks the hypotheses of the derivation in the module docstring and raises ``ValueError`` naming the one
    that fails: compact algebra in an orthonormal basis, isotropic noise :math:`\sum_i\xi_i\xi_i^T = \sigma^2 I`,
    the default (identity) metric of the dissipation, no forces, and — when :math:`\vartheta > 0` and
    :math:`\ell\ne 0` — the dissipation built from :math:`\tilde h` (``levy_in_dissipation=True``).

    Examples
    --------
    >>> import mechanics
    >>> sys_ = mechanics.LiePoissonSystem(mechanics.su(3), np.ones(8), 0.5 * np.eye(8), theta=1.0)
    >>> orbit_gibbs_beta(sys_)
    8.0
    """
    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a mechanics.LiePoissonSystem, got {type(system).__name__}.")
    _check_orthonormal_compact(system.algebra)
    sigma = isotropic_sigma(system.xi)
    data = system.quadratic_velocity_data()
    if data is not None and np.max(np.abs(data["metric_inv"] - np.eye(system.dim))) > 0:
        raise ValueError("the system's dissipation uses a metric other than the trace form (metric=...); "
                         "β = 2θ/σ² holds for the default metric only.")
    if system.force is not None or system.noise_forces is not None:
        raise ValueError("the system has forces; Theorem 3.1's Gibbs measure is for the unforced equation.")
    if system.theta > 0 and not system.levy_in_dissipation and np.any(system.torque_velocity):
        raise ValueError("the Gibbs density exp(-2θh̃/σ²) is the invariant law of Theorem 3.1's model, whose "
                         "dissipation is built from h̃; this system has levy_in_dissipation=False. Build it with "
                         "levy_in_dissipation=True, or estimate its law by simulation.")
    return 2.0 * system.theta / sigma ** 2


class OrbitGibbsMeasure:
    r"""The law :math:`Z^{-1}e^{-\beta E(\mu)}\nu(d\mu)` on the coadjoint orbit of ``mu`` (``ν`` uniform), by
    self-normalised importance sampling of exact orbit samples (module docstring).

    Parameters
    ----------
    algebra : MatrixLieAlgebra
        Compact, with a basis orthonormal for the trace form (so(n), su(N), u(N)).
    mu : array_like, shape ``(n,)``
        A point of the orbit (dual coordinates).
    energy : callable
        ``E``: ``(..., n) → (...)``, e.g. a system's :meth:`~mechanics.LiePoissonSystem.modified_hamiltonian`.
    beta : float
        Inverse temperature, ``>= 0`` (``0``: the uniform law).
    n_samples : int
        Number of uniform orbit samples (held: ``n_samples × n`` floats).
    rng : numpy.random.Generator
        Source of the samples (drawn at construction; :meth:`reweighted` reuses them).

    Notes
    -----
    The samples are drawn once; :meth:`reweighted` gives the law of another energy or ``β`` on the *same*
    samples (common random numbers: the difference of two estimates is then much more precise than either).
    The weights are formed relative to the smallest energy seen, so no ``β`` overflows.

    Examples
    --------
    >>> import mechanics
    >>> g = mechanics.su(2)                      # orbits are round spheres: E[μ] for a linear energy is closed-form
    >>> a = np.array([0.0, 0.0, 1.0])
    >>> gm = OrbitGibbsMeasure(g, [0.0, 0.0, 1.0], lambda m: m @ a, beta=2.0, n_samples=40_000,
    ...                        rng=np.random.default_rng(1))
    >>> est = gm.expectation(lambda m: m[..., 2])
    >>> exact = -(1.0 / np.tanh(2.0) - 1.0 / 2.0)    # −(coth κ − 1/κ), κ = β r |a|
    >>> bool(abs(est.mean - exact) < 4 * est.standard_error)
    True
    """

    def __init__(self, algebra, mu, energy, *, beta, n_samples=100_000, rng):
        _check_orthonormal_compact(algebra)
        mu = as_float_array(mu, "mu", ndim=1, last_dims=(algebra.dim,))
        if not callable(energy):
            raise TypeError(f"energy must be a callable mu (..., n) -> (...), got {type(energy).__name__}.")
        beta = float(as_float_array(beta, "beta", ndim=0))
        if not beta >= 0:
            raise ValueError(f"beta must be >= 0 (beta = 2*theta/sigma**2), got {beta!r}.")
        n_samples = check_positive_int(n_samples, "n_samples", minimum=2)
        rng = check_rng(rng)
        n, N = algebra.dim, algebra.matrix_size
        check_memory(8.0 * n_samples * n + 16.0 * 6 * min(n_samples, _CHUNK) * N * N,
                     f"{n_samples} orbit samples of {algebra.name} (n = {n})", "use fewer samples (n_samples)")
        self.algebra, self.mu, self.beta = algebra, mu, beta
        self.samples = np.concatenate([algebra.sample_orbit(mu, min(_CHUNK, n_samples - k), rng)
                                       for k in range(0, n_samples, _CHUNK)])
        self.samples.setflags(write=False)
        self._set_energy(energy)

    def _set_energy(self, energy):
        e = np.asarray(energy(self.samples), dtype=np.float64)
        if e.shape != (self.samples.shape[0],) or not np.all(np.isfinite(e)):
            raise ValueError(f"energy must map mu of shape (k, {self.algebra.dim}) to k finite numbers, got shape "
                             f"{e.shape}" + ("" if e.shape != (self.samples.shape[0],) else " with non-finite values")
                             + ".")
        self.energy = energy
        logw = -self.beta * (e - e.min())
        w = np.exp(logw)
        self._weights = w / w.sum()

    @classmethod
    def from_system(cls, system, mu, *, n_samples=100_000, rng, shift=None) -> "OrbitGibbsMeasure":
        r"""Theorem 3.1's invariant law of ``system`` on the orbit of ``mu``: :math:`E = \tilde h`, ``β`` from
        :func:`orbit_gibbs_beta`.

        ``shift`` replaces the velocity in :math:`\tilde h = h + \langle\mu, \ell\rangle` (default: the system's
        :attr:`~mechanics.LiePoissonSystem.torque_velocity`, the one in its drift); e.g. ``-ℓ`` or ``2ℓ`` give
        the predictions of the paper's printed sign and of the missing ½.
        """
        beta = orbit_gibbs_beta(system)
        ell = system.torque_velocity if shift is None else as_float_array(shift, "shift", ndim=1,
                                                                          last_dims=(system.dim,))
        return cls(system.algebra, mu, _ShiftedEnergy(system, ell), beta=beta, n_samples=n_samples, rng=rng)

    def reweighted(self, energy=None, *, beta=None) -> "OrbitGibbsMeasure":
        """The law of another ``energy`` and/or ``beta`` on the same orbit samples (defaults: this law's)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        if beta is not None:
            b = float(as_float_array(beta, "beta", ndim=0))
            if not b >= 0:
                raise ValueError(f"beta must be >= 0, got {b!r}.")
            new.beta = b
        new._set_energy(self.energy if energy is None else energy)
        return new

    @property
    def n_samples(self) -> int:
        """Number of uniform orbit samples."""
        return self.samples.shape[0]

    @property
    def effective_sample_size(self) -> float:
        r""":math:`1/\sum_k w_k^2` for the normalised weights."""
        return float(1.0 / np.sum(self._weights ** 2))

    @property
    def weights(self) -> np.ndarray:
        """The normalised importance weights of :attr:`samples`, shape ``(n_samples,)`` (sum 1)."""
        return self._weights.copy()

    def expectation(self, f=moment_observable) -> OrbitExpectation:
        r""":math:`E[f(\mu)]` with its standard error; ``f`` maps ``(k, n)`` to ``(k,)`` or ``(k, p)`` (default
        :func:`mechanics.moment_observable`: the means and second moments, in the order of
        :func:`mechanics.run_ensemble`'s statistics)."""
        # one pass over chunks of samples (f's values are never all held), sums of w (f - c), w² (f - c), w² (f - c)²
        # about c = the first chunk's weighted mean (so the variance sum does not cancel)
        sums, c = None, None
        for k in range(0, self.n_samples, _CHUNK):
            x = self.samples[k:k + _CHUNK]
            vals = np.asarray(f(x), dtype=np.float64)
            if vals.shape[:1] != (x.shape[0],) or vals.ndim > 2:
                raise ValueError(f"f must map mu of shape (k, n) to (k,) or (k, p), got shape {vals.shape} for "
                                 f"k = {x.shape[0]}.")
            w = self._weights[k:k + _CHUNK].reshape((-1,) + (1,) * (vals.ndim - 1))
            if c is None:
                c = np.sum(w * vals, axis=0) / max(float(np.sum(w)), 1e-300)
            d = vals - c
            part = (np.sum(w * d, axis=0), np.sum(w * w * d, axis=0), np.sum(w * w * d * d, axis=0))
            sums = part if sums is None else tuple(a + b for a, b in zip(sums, part))
        s1, s2, s3 = sums
        w2 = float(np.sum(self._weights ** 2))
        mean = c + s1                                   # the weights sum to 1
        se = np.sqrt(np.maximum(s3 - 2.0 * s1 * s2 + s1 * s1 * w2, 0.0))
        return OrbitExpectation(mean=mean, standard_error=se, effective_sample_size=self.effective_sample_size,
                                n_samples=self.n_samples)

    def __repr__(self) -> str:
        return (f"OrbitGibbsMeasure(algebra={self.algebra.name!r}, beta={self.beta:g}, n_samples={self.n_samples}, "
                f"ess={self.effective_sample_size:.0f})")


class _ShiftedEnergy:
    r""":math:`h(\mu) + \langle\mu, \ell\rangle` for a system's ``h`` (picklable, unlike a closure)."""

    def __init__(self, system, ell):
        self.system, self.ell = system, np.asarray(ell, dtype=np.float64)

    def __call__(self, mu):
        return self.system.energy(mu) + np.asarray(mu) @ self.ell
