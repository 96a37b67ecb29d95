r"""Coloured (Ornstein–Uhlenbeck) noise sampled exactly and lifted to a level-2 rough path.

The process (paper, Section 4.2 and appendix "Coloured noise as a rough path")

.. math::

    dy = -\varepsilon^{-2} A\, y\, dt + \varepsilon^{-1} D\, dB, \qquad
    B^\varepsilon_t = \int_0^t \frac{y_r}{\varepsilon}\, dr,

with ``A`` (n×n) whose eigenvalues have positive real part and ``D`` (n×m), ``B`` an m-dimensional
Brownian motion. ``y`` has the ε-independent stationary covariance ``Σ``, ``AΣ + ΣAᵀ = DDᵀ``.

Its law, the exact ε → 0 limit and the exact transitions (derivation) are in
:mod:`roughpaths.drivers.coloured_noise_law`; the names defined there are re-exported here.

Area of the smooth path (accuracy). On each step ``B^ε`` is C¹, so its area is not determined by
the step's endpoint data. Each grid step is split into ``m`` sub-steps of fast length ``δ`` sampled
exactly as above; on a sub-step the path is replaced by the cubic Hermite interpolant of the exact
data ``B^ε`` increment and end slopes ``ε ỹ_0``, ``ε ỹ_δ`` (for ``A = 0`` this is the conditional mean
of the path given those data), whose Lévy area is, with ``a ∧ b = a⊗b − b⊗a``, ``x`` the increment,
``u = εδỹ_0``, ``v = εδỹ_δ``,

.. math:: -\tfrac1{10}\, x\wedge u + \tfrac1{10}\, x\wedge v - \tfrac1{60}\, u\wedge v,

and sub-steps are combined by Chen sums (exact). The lift is geometric by construction. Its
expected area rate is known exactly (:func:`lift_area_rate`): the relative bias of the Lévy-area
rate is ``O((δ‖A‖)²)`` with the piecewise-linear lift and ``O(10⁻⁵)`` with the Hermite correction
(2.4·10⁻⁵ at ``δ‖A‖ = 0.25`` for the paper's ``A``, computed by :func:`lift_area_rate`). For the
paper's ``A = kI + Λ``, ``D = I`` the chord's bias has a closed form: ``Σ = I/(2k)``, and in the
plane of ``Λ`` the matrices ``Aᵀ``, ``e^{−Aᵀδ}`` act as the complex numbers ``ā``, ``e^{−āδ}``
(``a = k + i``, ``|a| = ‖A‖``), the Lévy-area rate being the imaginary part. The chord's rate
``Alt(ΣA⁻ᵀA⁻ᵀ(I − e^{−Aᵀδ})/δ)`` over the exact ``Alt(ΣA⁻ᵀ)`` is then
``Im f(ā) / Im(1/ā)``, ``f(z) = (1 − e^{−zδ})/(z²δ) = 1/z − δ/2 + zδ²/6 − …``, so the relative
bias is ``1 − |a|² Im f(ā) = (δ‖A‖)²/6 + O(δ³)``: 1.0 % at ``δ‖A‖ = 0.25``. Pathwise, the
Lévy-area error is a mean-zero fluctuation of order ``ε² δ^{5/2}`` per sub-step, i.e. an L² error
``≈ c δ²`` per unit of fast time (measured in ``tests/roughpaths/drivers/test_coloured_noise_driver.py`` for a
non-normal 2×2 ``A``: ``c ≈ 0.3`` with the Hermite correction, ``≈ 1`` for the chord lift). A
:class:`ResolutionWarning` (stating ``h/ε²``) is issued when a sub-step exceeds ``max_substep``
in units of ``ε²/‖A‖``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..validation import (as_float_array, check_batch_shape, check_memory, check_positive_int, check_positive_real,
                         check_rng, check_times, check_work)
from ..paths.rough_path import RoughPath
from ._random import PathStreams
from ._seeded import SeededDriver
from ._coloured_kernels import _ou_lift_kernel
from .coloured_noise_law import ColouredNoiseLimit, _check_AD, _check_eps, _substep_factor, coloured_noise_limit

__all__ = [
    "ColouredNoiseDriver",
    "ResolutionWarning",
    "ColouredNoiseSample",
    "sample_coloured_noise",
    "coloured_noise_limit_path",
    "iter_coloured_noise",
]


class ResolutionWarning(UserWarning):
    """A time step does not resolve the correlation time ``ε²/‖A‖`` of the coloured noise."""


def _path_major(z):
    """Normals are drawn time-major (chunk-independent stream); the kernel reads them path-major."""
    return np.ascontiguousarray(z.transpose(2, 0, 1, 3))


# ------------------------------------------------------------------------------- sampler
@dataclass
class ColouredNoiseSample:
    r"""One draw of the coloured noise on a grid, coupled with its Brownian motion.

    Attributes
    ----------
    path : RoughPath
        Level-2 geometric lift of ``B^ε = ∫ y/ε dt``, batch ``(...)``, dimension ``n``.
    y : ndarray, shape ``(..., N + 1, n)``
        The OU process on the grid.
    brownian : RoughPath
        The driving ``B`` (dimension ``m``) on the same grid, lifted by the piecewise-linear
        (Chen) lift over the sub-steps: its area is the conditional expectation of the
        Stratonovich area given the sub-step increments (variance deficit ``1/substeps`` per step).
    limit : ColouredNoiseLimit
    eps : float
    substeps : int
    """

    path: RoughPath
    y: np.ndarray
    brownian: RoughPath
    limit: ColouredNoiseLimit
    eps: float
    substeps: int

    def limit_path(self) -> RoughPath:
        """The coupled limit driver ``(MB, M BB Mᵀ + N dt)`` built from :attr:`brownian`."""
        return coloured_noise_limit_path(self.limit, self.brownian)


def _resolve_substeps(A, eps, h, substeps, max_substep, *, n_paths=1, n_steps=1):
    """Sub-steps per grid step; warn if the sub-step exceeds ``max_substep · ε²/‖A‖``.

    The automatic count grows like ``h/ε²``: it is estimated first and refused (with the estimate)
    when one sub-stepped block of ``n_paths`` paths would not fit the memory budget.
    """
    max_substep = check_positive_real(max_substep, "max_substep")
    nrm = float(np.linalg.norm(A, 2))
    if substeps is None:
        want = h * nrm / (eps ** 2 * max_substep)
        n = A.shape[0]
        check_memory(8.0 * n * (n + 2) * max(want, 1.0) * n_paths,
                     f"resolving eps={eps:.3g} at step h={h:.3g} needs about {want:.3g} sub-steps per step "
                     f"(h*||A||/(eps**2*max_substep)); one step of {n_paths} path(s)",
                     "use a larger eps or a smaller step h, or pass substeps=<int> explicitly (the Lévy "
                     "area is then biased, see lift_area_rate)")
        return max(1, int(math.ceil(want)))
    m = check_positive_int(substeps, "substeps")
    n = A.shape[0]
    check_memory(8.0 * n * (n + 2) * m * n_paths, f"substeps={m} sub-steps per step for {n_paths} path(s)",
                 "pass fewer substeps (substeps=None resolves eps**2 with the fewest)")
    ratio = h / (m * eps ** 2)
    if ratio * nrm > max_substep * (1 + 1e-12):
        warnings.warn(
            f"the sub-step h/substeps = {h / m:.3g} does not resolve the noise correlation time "
            f"eps**2 = {eps ** 2:.3g}: (h/substeps)/eps**2 = {ratio:.3g} (times ||A|| = {ratio * nrm:.3g} "
            f"> max_substep = {max_substep}); the Lévy area of B^eps is biased (see lift_area_rate). "
            f"Use substeps >= {int(math.ceil(h * nrm / (eps ** 2 * max_substep)))} or substeps=None.",
            ResolutionWarning, stacklevel=3)
    return m


def sample_coloured_noise(A, D, eps, times, *, rng, batch_shape=(), y0="stationary", substeps=None,
                          max_substep: float = 0.5) -> ColouredNoiseSample:
    r"""Sample coloured noise exactly on a grid and lift ``B^ε = ∫ y/ε dt`` to a level-2 rough path.

    Parameters
    ----------
    A : array_like, shape ``(n, n)``
        Drift matrix (eigenvalues in the open right half-plane).
    D : array_like, shape ``(n, m)``
        Noise matrix (``Σ`` non-singular).
    eps : float
        Correlation parameter ``ε > 0`` (correlation time ``ε²/‖A‖``).
    times : array_like, shape ``(N + 1,)``
        Increasing grid.
    rng : numpy.random.Generator
    batch_shape : tuple of int
        Leading batch axes of the output.
    y0 : "stationary" or array_like ``(..., n)``
        Start: a draw from ``N(0, Σ)`` or a given value (broadcast to ``batch_shape``).
    substeps : int or None
        Exact sub-steps per grid step used for the area (module docstring). ``None`` picks the
        smallest number with sub-step ``≤ max_substep · ε²/‖A‖₂``; an explicit coarser choice
        emits a :class:`ResolutionWarning` with the ratio ``(h/substeps)/ε²``.
    max_substep : float
        Resolution target in units of ``ε²/‖A‖₂`` (default 0.5: Lévy-area rate bias below 5e-4 relative, see :func:`lift_area_rate`).

    Returns
    -------
    ColouredNoiseSample
        ``.path`` (the lift, kind ``"geometric"``), ``.y``, the coupled ``.brownian`` and ``.limit``.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import sample_coloured_noise
    >>> A = np.array([[1.0, 1.0], [-1.0, 1.0]])
    >>> s = sample_coloured_noise(A, np.eye(2), 0.1, np.linspace(0, 1, 11), rng=np.random.default_rng(0),
    ...                           batch_shape=(4,))
    >>> s.path.batch_shape, s.path.dim, s.path.kind, s.y.shape
    ((4,), 2, 'geometric', (4, 11, 2))
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    rng = check_rng(rng)
    t = check_times(times)
    lim = coloured_noise_limit(A, D)
    n, m = D.shape
    batch_shape = check_batch_shape(batch_shape)
    P = int(np.prod(batch_shape)) if batch_shape else 1
    N = t.size - 1
    dts = np.diff(t)
    uniform = np.allclose(dts, dts[0], rtol=1e-10, atol=0.0)
    if isinstance(y0, str):
        if y0 != "stationary":
            raise ValueError(f"y0 must be 'stationary' or an array of shape (..., {n}), got {y0!r}.")
        Ls = np.linalg.cholesky(lim.Sigma)
        ystart = rng.standard_normal((P, n)) @ Ls.T
    else:
        yv = as_float_array(y0, "y0", last_dims=(n,))
        try:
            ystart = np.broadcast_to(yv, batch_shape + (n,)).reshape(P, n).copy()
        except ValueError:
            raise ValueError(f"y0 of shape {yv.shape} does not broadcast to batch_shape + (n,) = "
                             f"{batch_shape + (n,)}.") from None
    hmax = float(np.max(dts))
    msub = _resolve_substeps(A, eps, hmax, substeps, max_substep, n_paths=P)
    Ainv = np.linalg.inv(A)
    inc = np.empty((P, N, n))
    area = np.empty((P, N, n, n))
    ygrid = np.empty((P, N, n))
    binc = np.empty((P, N, m))
    barea = np.empty((P, N, m, m))
    y = ystart.copy()
    groups = [(0, N, dts[0])] if uniform else [(i, i + 1, dts[i]) for i in range(N)]
    cache = {}
    for lo, hi, h in groups:
        key = float(h)
        if key not in cache:
            cache[key] = _substep_factor(A, D, h / (msub * eps ** 2))
        Phi, L = cache[key]
        delta = h / (msub * eps ** 2)
        z = _path_major(rng.standard_normal((hi - lo, msub, P, n + m)))
        _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc[:, lo:hi], area[:, lo:hi], ygrid[:, lo:hi],
                        binc[:, lo:hi], barea[:, lo:hi])
    yall = np.concatenate([ystart[:, None, :], ygrid], axis=1)
    shp = batch_shape
    path = RoughPath(inc.reshape(shp + (N, n)), area.reshape(shp + (N, n, n)), times=t, kind="geometric",
                     check=False)
    bro = RoughPath(binc.reshape(shp + (N, m)), barea.reshape(shp + (N, m, m)), times=t, kind="geometric",
                    check=False)
    return ColouredNoiseSample(path=path, y=yall.reshape(shp + (N + 1, n)), brownian=bro, limit=lim,
                               eps=eps, substeps=msub)


def coloured_noise_limit_path(limit, brownian: RoughPath) -> RoughPath:
    r"""The limit driver ``(M B, M BB Mᵀ + N (t − s))`` in B^ε coordinates.

    Parameters
    ----------
    limit : ColouredNoiseLimit or tuple ``(A, D)``
    brownian : RoughPath
        A level-2 (Stratonovich, geometric) lift of an ``m``-dimensional Brownian motion, e.g.
        :attr:`ColouredNoiseSample.brownian` (coupled with a coloured sample) or any Brownian lift.

    Returns
    -------
    RoughPath
        Dimension ``n``, geometric: the scaled Brownian rough path perturbed by ``N``.
    """
    if not isinstance(limit, ColouredNoiseLimit):
        limit = coloured_noise_limit(*limit)
    if not isinstance(brownian, RoughPath):
        raise TypeError(f"brownian must be a RoughPath, got {type(brownian).__name__}.")
    M = limit.scaling
    if brownian.dim != M.shape[1]:
        raise ValueError(f"brownian has dimension {brownian.dim} but D has {M.shape[1]} columns; they "
                         f"must match.")
    if brownian.level != 2:
        raise ValueError("brownian must be a level-2 rough path (with its area); the limit's area "
                         "M BB M^T + N dt needs it.")
    inc = brownian.increments @ M.T
    area = M @ brownian.areas @ M.T
    base = RoughPath(inc, area, times=brownian.times, x0=brownian.x0 @ M.T, kind=brownian.kind, check=False)
    return base.perturb(limit.levy_perturbation)


def iter_coloured_noise(A, D, eps, h, n_steps, *, rng, n_paths=1, y0="stationary", substeps=None,
                        max_substep: float = 0.5, chunk_steps=None):
    r"""Stream the lift of ``B^ε`` (and of ``B``) in time chunks, in constant memory.

    Same law, sub-stepping and area construction as :func:`sample_coloured_noise` on the uniform
    grid ``h·(0, …, n_steps)``; random numbers are drawn in time-major order, so the output does
    not depend on ``chunk_steps`` (and equals :func:`sample_coloured_noise` with the same seed).

    Parameters
    ----------
    A, D, eps : as in :func:`sample_coloured_noise`
    h : float
        Grid step.
    n_steps : int
    rng : numpy.random.Generator
    n_paths : int
    y0 : "stationary" or array_like ``(n_paths, n)`` / ``(n,)``
    substeps, max_substep : as in :func:`sample_coloured_noise`
    chunk_steps : int, optional
        Grid steps per chunk (default: about 2·10⁶ random numbers per chunk).

    Yields
    ------
    inc : ndarray ``(n_paths, S, n)``
        Increments of ``B^ε``.
    area : ndarray ``(n_paths, S, n, n)``
        Step areas of ``B^ε`` (geometric).
    b_inc, b_area : ndarrays ``(n_paths, S, m)``, ``(n_paths, S, m, m)``
        The coupled Brownian ``B`` and its piecewise-linear (sub-step Chen) areas.
    y : ndarray ``(n_paths, S, n)``
        ``y`` at the end of each step.
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    rng = check_rng(rng)
    h = check_positive_real(h, "h")
    n_steps = check_positive_int(n_steps, "n_steps")
    P = check_positive_int(n_paths, "n_paths")
    lim = coloured_noise_limit(A, D)
    n, m = D.shape
    check_memory(8.0 * 4 * P * (n + m) * (n + m), f"the state of n_paths={P} paths", "use fewer paths")
    if isinstance(y0, str):
        if y0 != "stationary":
            raise ValueError(f"y0 must be 'stationary' or an array of shape (n_paths, {n}), got {y0!r}.")
        y = rng.standard_normal((P, n)) @ np.linalg.cholesky(lim.Sigma).T
    else:
        y = np.array(np.broadcast_to(as_float_array(y0, "y0", last_dims=(n,)), (P, n)))
    msub = _resolve_substeps(A, eps, h, substeps, max_substep, n_paths=P)
    check_work(float(P) * n_steps * msub, f"n_paths={P} x n_steps={n_steps} x {msub} sub-steps",
               "use fewer paths or steps (or a larger eps)")
    Phi, L = _substep_factor(A, D, h / (msub * eps ** 2))
    delta = h / (msub * eps ** 2)
    Ainv = np.linalg.inv(A)
    if chunk_steps is None:
        chunk_steps = max(1, int(2_000_000 // (P * msub * (n + m))))
    chunk_steps = check_positive_int(chunk_steps, "chunk_steps")
    done = 0
    while done < n_steps:
        S = min(chunk_steps, n_steps - done)
        z = _path_major(rng.standard_normal((S, msub, P, n + m)))
        inc = np.empty((P, S, n))
        area = np.empty((P, S, n, n))
        yg = np.empty((P, S, n))
        binc = np.empty((P, S, m))
        barea = np.empty((P, S, m, m))
        _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc, area, yg, binc, barea)
        done += S
        yield inc, area, binc, barea, yg


# ------------------------------------------------------------------------------- driver
class ColouredNoiseDriver(SeededDriver):
    r"""The lift of ``B^ε = ∫ y/ε dt`` as a lazily generated, per-path seeded driver.

    Same law, sub-stepping and Hermite area as :func:`sample_coloured_noise`; consumed by
    :func:`roughpaths.solve` like the ``RoughPath`` that :meth:`rough_path` returns
    (dimension ``n``, kind ``"geometric"``).

    Parameters
    ----------
    A, D, eps : as in :func:`sample_coloured_noise`
    seed : int or numpy.random.SeedSequence
        Root of the per-path streams (see *Stream*).
    times : array_like, shape ``(N + 1,)``, optional
        Increasing grid; or ``dt`` and ``n_steps`` (uniform, from ``t0``).
    dt, n_steps, t0 : optional
        Uniform grid ``t0 + dt * arange(n_steps + 1)``.
    batch_shape : tuple of int
        Independent paths; path ``i`` is the ``i``-th in C order.
    y0 : "stationary" or array_like ``(..., n)``
        Start: a draw from ``N(0, Σ)`` (from the path's stream) or a given value.
    substeps, max_substep : as in :func:`sample_coloured_noise` (``substeps`` resolved from the
        largest step).
    block_bytes : int
        Target memory of one block (default 2 MiB); never changes the numbers.

    Notes
    -----
    **Stream.** With ``S = SeedSequence(seed)`` and ``i`` the path's flat index, path ``i`` draws
    the standard normals of ``Generator(PCG64(SeedSequence(S.entropy, spawn_key=S.spawn_key +
    (i,))))``: first ``n`` for a stationary start (``y0 = L z``, ``LLᵀ = Σ``), then per step and
    per sub-step ``n + m`` normals (the exact ``(ỹ_δ, ΔB̃)`` draw of the sub-step). The numbers of
    a path depend only on ``seed``, ``i`` and the model (``A``, ``D``, ``ε``, grid, ``substeps``):
    not on the block size, :meth:`select`, or the process.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[1.0, 1.0], [-1.0, 1.0]])
    >>> drv = ColouredNoiseDriver(A, np.eye(2), 0.1, seed=3, dt=0.05, n_steps=20, batch_shape=(4,))
    >>> X = drv.rough_path()
    >>> X.batch_shape, X.dim, X.kind, drv.substeps
    ((4,), 2, 'geometric', 15)
    >>> Y = np.concatenate([b.areas for b in drv.blocks(max_steps=3)], axis=1)
    >>> bool(np.array_equal(Y, X.areas))
    True
    """

    def __init__(self, A, D, eps, *, seed, times=None, dt=None, n_steps=None, t0=0.0, batch_shape=(),
                 y0="stationary", substeps=None, max_substep: float = 0.5, block_bytes=2 << 20):
        A, D = _check_AD(A, D)
        self.eps = _check_eps(eps)
        self._init_common(A.shape[0], seed, times, dt, n_steps, t0, batch_shape, block_bytes)
        self.A, self.D = A, D
        self.limit = coloured_noise_limit(A, D)
        self.level = 2
        self.noise_dim = D.shape[1]
        self.substeps = _resolve_substeps(A, self.eps, float(self._h.max()), substeps, max_substep,
                                          n_paths=max(1, int(np.prod(self.batch_shape))))
        if isinstance(y0, str):
            if y0 != "stationary":
                raise ValueError(f"y0 must be 'stationary' or an array of shape (..., {self.dim}), got {y0!r}.")
            self._y0 = None
        else:
            self._y0 = self._check_start(y0, "y0", self.dim)

    def _starts(self) -> dict:
        return {"_y0": self.dim}

    def _bytes_per_path_step(self) -> int:
        n, m = self.dim, self.noise_dim
        return 8 * (2 * n + n * n + m + m * m + self.substeps * (n + m))

    def __repr__(self) -> str:
        return (f"ColouredNoiseDriver(n={self.dim}, m={self.noise_dim}, eps={self.eps}, n_steps={self.n_steps}, "
                f"batch_shape={self.batch_shape}, substeps={self.substeps})")

    def _start(self):
        """The path streams and the start ``y0`` ``(P, n)`` (its normals drawn first if stationary)."""
        n, P = self.dim, self.n_paths
        streams = PathStreams(self.seed_sequence, self.path_indices[:, None])
        if self._y0 is None:
            z0 = np.empty((P, n))
            streams.fill(z0)
            return streams, z0 @ np.linalg.cholesky(self.limit.Sigma).T
        return streams, np.array(self._flat(self._y0, n))

    def initial_state(self) -> np.ndarray:
        """The start ``y0`` of every path, shape ``(*batch_shape, n)`` (the stationary draw or the given value)."""
        return self._start()[1].reshape(self.batch_shape + (self.dim,))

    def blocks(self, max_steps=None):
        """Yield consecutive ``RoughPath`` blocks of ``B^ε`` (see :meth:`blocks_with_brownian`)."""
        for path, _, _ in self.blocks_with_brownian(max_steps):
            yield path

    def blocks_with_brownian(self, max_steps=None):
        """Yield ``(path, brownian, y)`` per block: the lift of ``B^ε``, the coupled ``B`` and ``y``.

        ``brownian`` is the level-2 piecewise-linear (sub-step Chen) lift of the driving ``B``
        (dimension ``m``); ``y`` has shape ``(*batch_shape, k, n)``, the OU state at the end of
        each step of the block. The numbers do not depend on ``max_steps``.
        """
        K = self._block_size(max_steps)
        N, n, m, P, ms = self.n_steps, self.dim, self.noise_dim, self.n_paths, self.substeps
        streams, y = self._start()
        Ainv = np.linalg.inv(self.A)
        cache = {}
        bshape = self.batch_shape
        xb, xw = np.zeros((P, n)), np.zeros((P, m))
        zbuf = np.empty(P * min(K, N) * ms * (n + m))
        for k0 in range(0, N, K):
            k1 = min(N, k0 + K)
            k = k1 - k0
            z = zbuf[:P * k * ms * (n + m)].reshape(P, k, ms, n + m)
            streams.fill(z.reshape(P, -1))
            inc, area = np.empty((P, k, n)), np.empty((P, k, n, n))
            yg, binc, barea = np.empty((P, k, n)), np.empty((P, k, m)), np.empty((P, k, m, m))
            h = self._h[k0:k1]
            lo = 0
            while lo < k:                     # runs of equal step size share one transition factor
                hi = lo + 1
                while hi < k and h[hi] == h[lo]:
                    hi += 1
                key = float(h[lo])
                delta = key / (ms * self.eps ** 2)
                if key not in cache:
                    cache[key] = _substep_factor(self.A, self.D, delta)
                Phi, L = cache[key]
                _ou_lift_kernel(y, z[:, lo:hi], Phi, L, Ainv, self.D, self.eps, delta, inc[:, lo:hi],
                                area[:, lo:hi], yg[:, lo:hi], binc[:, lo:hi], barea[:, lo:hi])
                lo = hi
            t = self.times[k0:k1 + 1]
            path = RoughPath(inc.reshape(bshape + (k, n)), area.reshape(bshape + (k, n, n)), times=t,
                             x0=xb.reshape(bshape + (n,)).copy(), kind="geometric", check=False)
            bro = RoughPath(binc.reshape(bshape + (k, m)), barea.reshape(bshape + (k, m, m)), times=t,
                            x0=xw.reshape(bshape + (m,)).copy(), kind="geometric", check=False)
            xb += inc.sum(axis=1)
            xw += binc.sum(axis=1)
            yield path, bro, yg.reshape(bshape + (k, n))
