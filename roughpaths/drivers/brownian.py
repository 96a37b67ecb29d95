r"""Brownian motion lifted to a level-2 rough path (Stratonovich or Itô), sampled on a grid.

Conventions (``docs/conventions.md``)
--------------------------------
* area ``XX[..., i, j]`` over a step ``[s, t]`` is :math:`\int_s^t (W^i_r - W^i_s)\,\circ dW^j_r`
  (``iisignature`` ordering);
* Lévy area :math:`A = \tfrac12(\mathbb{X} - \mathbb{X}^T)` *with* the ½, so that for d = 2
  :math:`A_{12} = \tfrac12\int (W^1 dW^2 - W^2 dW^1)` and :math:`\mathrm{Var}(A_{12}) = h^2/4`;
* Stratonovich: :math:`\mathbb{X} = A + \tfrac12 W\otimes W` (geometric);
  Itô: :math:`\mathbb{X}^{\text{Itô}} = \mathbb{X}^{\text{Strat}} - \tfrac12 h I`.

What is exact and what is approximate
-------------------------------------
The increments are exact in law on every grid (independent :math:`N(0, h I)`). The areas are
sampled by the method ``levy_area`` (the table of :mod:`roughpaths.drivers.areas`); the default,
``"auto"``, is exact in law for ``d <= 2`` (:mod:`roughpaths.drivers.levy_area`) and has per-step L²
error :math:`h^{3/2}` for ``d >= 3``, so the order-1 solvers keep strong order 1 against the Brownian
motion. The fast methods ``"davie"`` and ``"foster"``, of strong order ½ against Brownian motion,
are derived here. The Lévy area of Brownian motion is not Gaussian; for them each step
of size ``h`` is split into ``m = substeps`` equal substeps of size :math:`\delta = h/m`, on which
we draw the Brownian increment :math:`w_k` (a Brownian bridge given the step's increment, so the
step increment is untouched) and the *space-time Lévy area*
:math:`H_k = \frac1\delta\int (W_r - W_{r_k} - \frac{r - r_k}{\delta} w_k)\,dr \sim N(0, \tfrac{\delta}{12} I)`,
independent of :math:`w_k`. Then

* :math:`E[A_k \mid w_k, H_k] = H_k\otimes w_k - w_k\otimes H_k` (Foster, Lyons & Oberhauser 2020;
  re-derived here by integrating the polynomial :math:`r \mapsto u w + 6 u(1-u) H`, ``u`` the
  fraction of the substep), and the conditional residual has variance :math:`\delta^2/12` per
  component, uncorrelated across components and with :math:`(w_k, H_k)`;
* the substep areas are combined exactly by Chen's identity
  :math:`A = \sum_k A_k + \mathrm{Alt}\sum_{k<l} w_k\otimes w_l`.

``levy_area="foster"`` keeps the conditional means only: the result is
:math:`E[A \mid (w_k, H_k)_{k\le m}]`, the best L² approximation given that information. Its
per-step, per-component L² error against the true Lévy area of the same Brownian path is

.. math:: \|\tilde A_{ij} - A_{ij}\|_{L^2} = \frac{h}{\sqrt{12\,m}}, \qquad i \ne j,

(independent of ``d``; the Frobenius error of the whole matrix is ``sqrt(d(d-1)/2)`` times this,
counting each pair ``i < j`` once), and its variance is :math:`h^2/4 - h^2/(12 m)` instead of
:math:`h^2/4`; with the fourth cumulant derived below, its excess kurtosis is
:math:`(2 - \tfrac{2}{3m^3})(\tfrac{3m}{3m-1})^2` (3 for ``m = 1``).

``levy_area="davie"`` adds an independent antisymmetric Gaussian with variance
:math:`h^2/(12 m)` per component (Davie 2014, with Foster's space-time refinement): every second
moment of ``(W, A)`` is then exact, also conditionally on ``W``
(:math:`\mathrm{Var}(A_{ij}\mid W) = h^2/12 + h(W_i^2 + W_j^2)/12`), and so is the
conditional mean; the residual law error is in the fourth and higher cumulants, known exactly.
Derivation: unconditionally the substep data are independent, so :math:`A_{ij} = \delta\,u^T K v + \lambda`
with independent standard Gaussian vectors :math:`u = (w^i_k, \sqrt{12} H^i_k)_{k\le m}/\sqrt\delta`,
``v`` the same for ``j``, :math:`K = \begin{pmatrix} B & -c I \\ c I & 0 \end{pmatrix}`,
:math:`c = 1/\sqrt{12}`, :math:`B_{kl} = \tfrac12\mathrm{sign}(l - k)` (the Chen cross terms) and
:math:`\lambda` the added Gaussian. A bilinear Gaussian form has :math:`\kappa_4 = 6\,\mathrm{tr}((KK^T)^2)
= 6[\mathrm{tr} B^4 + m(m-1)/12 + m/72]`, :math:`\mathrm{tr} B^4 = m(m-1)(m^2+m-3)/48`, and
:math:`\lambda` adds to :math:`\kappa_2 = h^2/4` only: :math:`\kappa_4 = h^4/8 - h^4/(24 m^3)`, excess
kurtosis :math:`2 - 2/(3m^3)` against 2 for the true Lévy area, for every ``d``: **4/3** for the
default ``m = 1`` (Davie's own method; :math:`H^i w^j - w^i H^j` is two independent products of normals,
each :math:`\kappa_4 = 6(h^2/12)^2`, over :math:`\kappa_2^2 = h^4/16`), 23/12 for ``m = 2``, :math:`2 - 1/768`
for ``m = 8``; the sixth cumulant's relative error (:math:`120\,\mathrm{tr}((KK^T)^3)` against
:math:`h^6/4`) is 4/9 at ``m = 1``, falling like :math:`m^{-4}`. Measured (d = 2): a Kolmogorov–Smirnov
test with 4·10⁵ samples cannot tell the ``m = 8`` law from the exact one. The default ``m``,
:data:`DEFAULT_SUBSTEPS` ``= 1``, is the same for every entry point (this module's functions,
:class:`BrownianDriver`); it gives exact second moments at the lowest cost. Its
L² error, had the path been coupled to a true Brownian path, is :math:`h/\sqrt{6 m}` per
component (the added Gaussian is independent of the path).

``levy_area="exact"`` (``d <= 2``) samples the Lévy area from its exact conditional law given the
increment; its derivation, law error and cost are in :mod:`roughpaths.drivers.levy_area`. The
error-controlled ``"fourier"``, ``"mrongowius-rossler"``, ``"wiktorsson"`` and ``"auto"`` are
documented there too.

Cost per step: ``d`` normals for the increment, plus ``m d`` (bridge, only if ``m > 1``),
``m d`` (space-time areas) and ``d(d-1)/2`` (Davie) normals and ``O(m d^2)`` flops for the area.
The normals come from per-path streams (numpy's ziggurat over ``PCG64``, :mod:`roughpaths.drivers._random`)
and the flops from :mod:`roughpaths.drivers._area_kernels`: the time is that of drawing the normals
(``benchmarks/bench_brownian.py``).
``levy_area=None`` returns the increments alone at the cost of ``d`` normals per step.

Every entry point samples the same stream: :class:`BrownianDriver` (lazy, in time blocks) and
the one-shot :func:`brownian_rough_path` / :func:`brownian_increments_and_areas`, which
materialise a driver seeded from their ``rng``.

References: J. Foster, T. Lyons, H. Oberhauser, *An optimal polynomial approximation of Brownian
motion*, SIAM J. Numer. Anal. 58 (2020); A. Davie, *KMT theory applied to approximations of SDE*
(2014); P. Lévy (1951) for the d = 2 law :math:`E[e^{i\lambda A}] = 1/\cosh(\lambda h/2)`.
"""

from __future__ import annotations

import numbers

import numpy as np

from ..validation import as_float_array, check_memory, check_positive_int, check_seed as _check_seed
from .. import _threads
from ._area_kernels import _scale_accumulate
from ._fourier_kernels import step_tables
from ._random import PathStreams, _fast_streams_ok, _pcg64_normals
from .areas import _Sampler
from ._seeded import SeededDriver, check_batch_shape as _check_batch_shape
from ..paths.rough_path import RoughPath
from .refinement import RefinedBrownianDriver

__all__ = ["BrownianDriver", "brownian_increments_and_areas", "brownian_rough_path"]

_KINDS = ("stratonovich", "ito")


# ---------------------------------------------------------------------------- validation
def _check_kind(kind) -> str:
    if kind not in _KINDS:
        raise ValueError(f"kind must be 'stratonovich' or 'ito', got {kind!r}.")
    return kind


def _check_dt(dt, n_steps: int) -> np.ndarray:
    arr = as_float_array(dt, "dt")
    if arr.ndim == 0:
        arr = np.full(n_steps, float(arr))
    elif arr.ndim != 1 or arr.shape[0] != n_steps:
        raise ValueError(f"dt must be a positive scalar or a 1-D array of n_steps={n_steps} step "
                         f"sizes, got shape {arr.shape}.")
    if np.any(arr <= 0):
        k = int(np.argmax(arr <= 0))
        raise ValueError(f"dt must be > 0, got dt[{k}]={arr[k]!r}; pass positive step sizes "
                         f"(use brownian_rough_path(times, ...) for a grid).")
    return arr


def _seed_from_rng(rng) -> np.random.SeedSequence:
    """The driver seed of the wrappers: drawn from a Generator (2 draws), or an int/SeedSequence as is."""
    if isinstance(rng, np.random.Generator):
        return np.random.SeedSequence([int(v) for v in rng.integers(0, 2**63, size=2, dtype=np.int64)])
    if isinstance(rng, np.random.SeedSequence) or (isinstance(rng, numbers.Integral) and not isinstance(rng, bool)):
        return _check_seed(rng)
    raise TypeError(f"rng must be a numpy.random.Generator (or an int seed / SeedSequence), got "
                    f"{type(rng).__name__}; pass rng=numpy.random.default_rng(seed).")


# ---------------------------------------------------------------------------- public API
def brownian_increments_and_areas(rng, n_steps, dt, dim, *, batch_shape=(), levy_area="auto",
                                  substeps=None, kind="stratonovich", levy_area_error=None):
    r"""Sample Brownian increments and step areas: the low-level, streaming-friendly sampler.

    Parameters
    ----------
    rng : numpy.random.Generator, int or numpy.random.SeedSequence
        Source of randomness. The numbers are those of :class:`BrownianDriver` (see its *Stream*)
        with ``seed = SeedSequence([a, b])``, ``a, b = rng.integers(0, 2**63, size=2)`` (one call
        advances ``rng`` by these two draws only); an int or ``SeedSequence`` is used as the
        driver's seed directly.
    n_steps : int
        Number of steps ``N >= 1``.
    dt : float or array_like, shape ``(N,)``
        Step size(s), all ``> 0``.
    dim : int
        Dimension ``d >= 1`` of the Brownian motion.
    batch_shape : tuple of int, optional
        Leading batch axes (independent paths), default ``()``.
    levy_area : str or None
        Lévy-area method, any of :data:`roughpaths.LEVY_AREA_METHODS` (table in
        :mod:`roughpaths.drivers.areas`), default ``"auto"``: exact in law for ``d <= 2``, per-step L²
        error ``levy_area_error`` for ``d >= 3`` (strong order 1 against Brownian motion).
        ``"davie"`` matches every second moment of ``(W, A)`` exactly, ``"foster"`` is the
        conditional mean given the substep information (best L² approximation, variance short by
        ``h²/(12 m)``); both are fast and of strong order ½ against Brownian motion. ``"exact"``
        (``d <= 2``) is exact in law; ``"fourier"``, ``"mrongowius-rossler"``, ``"wiktorsson"`` meet
        the per-step L² error ``levy_area_error``. ``None`` (or ``"none"``) returns ``areas=None`` and
        draws only the increments.
    substeps : int, optional
        Substeps ``m >= 1`` per step for ``"davie"`` / ``"foster"`` (default
        :data:`DEFAULT_SUBSTEPS`). The increments do not depend on it. L² error per component:
        ``h / sqrt(12 m)`` (foster).
    kind : {"stratonovich", "ito"}
        Stratonovich areas :math:`A + \tfrac12 W\otimes W`, or Itô areas
        :math:`A + \tfrac12 W\otimes W - \tfrac12 h I`.
    levy_area_error : float, optional
        Per-step L² error of the error-controlled methods (default ``h^{3/2}``), as for
        :class:`BrownianDriver`: accepted with the Fourier methods and ``"auto"``, refused with every
        other ``levy_area``.

    Returns
    -------
    dW : ndarray, shape ``(*batch_shape, N, d)``
        Independent :math:`N(0, h_k I)` increments (exact in law).
    areas : ndarray, shape ``(*batch_shape, N, d, d)``, or None
        Per-step areas ``XX[..., k, i, j]`` (``iisignature`` ordering).

    Notes
    -----
    The increments and the areas come from separate per-path streams (:class:`BrownianDriver`),
    so for the same seed ``dW`` is identical whatever ``levy_area``, ``substeps`` or ``kind``;
    chunking a long horizon into several calls with one generator gives independent, exactly
    distributed chunks (for a stream that does not depend on the chunking, iterate
    ``BrownianDriver(...).blocks()``).

    Examples
    --------
    >>> import numpy as np
    >>> dW, XX = brownian_increments_and_areas(np.random.default_rng(0), 4, 0.01, 2,
    ...                                        batch_shape=(3,))
    >>> dW.shape, XX.shape
    ((3, 4, 2), (3, 4, 2, 2))
    >>> bool(np.allclose(XX + np.swapaxes(XX, -1, -2), dW[..., :, None] * dW[..., None, :]))
    True
    >>> dW2, none = brownian_increments_and_areas(np.random.default_rng(0), 4, 0.01, 2,
    ...                                           batch_shape=(3,), levy_area=None)
    >>> bool(np.array_equal(dW, dW2)), none is None
    (True, True)
    """
    seed = _seed_from_rng(rng)
    n_steps = check_positive_int(n_steps, "n_steps")
    dim = check_positive_int(dim, "dim")
    batch_shape = _check_batch_shape(batch_shape)
    check_memory(8.0 * 3 * float(np.prod(batch_shape, dtype=float)) * n_steps * (dim + dim * dim),
                 f"the increments and areas ({batch_shape} paths x n_steps={n_steps} x dim={dim})",
                 "sample fewer steps or paths at a time (BrownianDriver(...).blocks() streams them)")
    h = _check_dt(dt, n_steps)
    drv = BrownianDriver(dim, seed=seed, times=np.concatenate([[0.0], np.cumsum(h)]), batch_shape=batch_shape,
                         levy_area=levy_area, substeps=substeps, kind=kind, levy_area_error=levy_area_error)
    drv._h = h                               # the given step sizes exactly (not differences of their sums)
    drv._sampler = _Sampler(levy_area, dim, h, substeps, levy_area_error)       # planned for those sizes
    X = drv.rough_path()
    return X.increments, X.areas


def brownian_rough_path(times, dim, rng, *, batch_shape=(), kind="stratonovich", levy_area="auto",
                        substeps=None, x0=None, levy_area_error=None) -> RoughPath:
    r"""Brownian motion lifted to a level-2 rough path on exactly the grid ``times``.

    Parameters
    ----------
    times : array_like, shape ``(N + 1,)``
        Strictly increasing grid (non-uniform allowed).
    dim : int
        Dimension ``d``.
    rng : numpy.random.Generator, int or numpy.random.SeedSequence
        Source of randomness: the path is ``BrownianDriver(dim, seed=..., times=times, ...)
        .rough_path()`` with the seed derived as in :func:`brownian_increments_and_areas`.
    batch_shape : tuple of int, optional
        Independent paths, default ``()``.
    kind : {"stratonovich", "ito"}
        Stratonovich (geometric, ``RoughPath.kind == "geometric"``) or Itô
        (``kind == "ito"``, :math:`\mathbb{X}^{\text{Itô}} = \mathbb{X}^{\text{Strat}} - \tfrac12 (t-s) I`).
    levy_area, substeps, levy_area_error
        Area sampler, see :func:`brownian_increments_and_areas`; ``levy_area=None`` gives a
        level-1 path (increments only).
    x0 : array_like, shape ``(d,)`` or ``(*batch_shape, d)``, optional
        Starting point (default 0).

    Returns
    -------
    RoughPath
        Increments exact in law on ``times``; areas as documented in this module.

    Examples
    --------
    >>> import numpy as np
    >>> X = brownian_rough_path([0.0, 0.1, 0.3, 1.0], 3, np.random.default_rng(1), batch_shape=(5,))
    >>> X.kind, X.batch_shape, X.n_steps
    ('geometric', (5,), 3)
    >>> float(X.geometric_defect().max()) < 1e-15
    True
    """
    seed = _seed_from_rng(rng)
    return BrownianDriver(dim, seed=seed, times=times, batch_shape=batch_shape, kind=kind, levy_area=levy_area,
                          substeps=substeps, x0=x0, levy_area_error=levy_area_error).rough_path()


# ---------------------------------------------------------------------------- the driver
_BLOCK_BYTES = 16 << 20


class BrownianDriver(SeededDriver):
    r"""Brownian motion lifted to a level-2 rough path, generated lazily in time blocks, per-path seeded.

    :func:`roughpaths.solve` consumes it exactly like the ``RoughPath`` that :meth:`rough_path`
    returns, one block of ``~block_bytes`` at a time. The areas are sampled as documented in this
    module (``levy_area`` and ``substeps``; ``None`` gives a level-1 driver).

    Parameters
    ----------
    dim : int
        Dimension ``d >= 1``.
    seed : int or numpy.random.SeedSequence
        Root of the random streams (see *Stream* below). A ``Generator`` is refused: its state
        would make the paths depend on earlier draws.
    times : array_like, shape ``(N + 1,)``, optional
        Strictly increasing grid (non-uniform allowed). Or give ``dt`` and ``n_steps``.
    dt : float, optional
        Uniform step (grid ``t0 + dt * arange(n_steps + 1)``).
    n_steps : int, optional
        Number of uniform steps.
    t0 : float
        Start of the uniform grid (default 0).
    batch_shape : tuple of int
        Independent paths, default ``()``; path ``i`` is the ``i``-th in C order of the batch.
    levy_area : {"davie", "foster", "exact", "fourier", "mrongowius-rossler", "wiktorsson", "auto"} or None
        Area method, table in :mod:`roughpaths.drivers.areas`. Default ``"auto"``: ``"exact"`` (the
        exact law given the increment) for ``d <= 2``, and for ``d >= 3`` the error-controlled Fourier
        sampler of :mod:`roughpaths.drivers.levy_area` that needs the fewest normals for
        ``levy_area_error``, per step size; strong order 1 against Brownian motion. ``"davie"``
        (exact second moments) and ``"foster"``: fast, strong order ½. ``None``: increments only
        (``level == 1``).
    substeps : int
        Substeps ``m`` per step of the ``"davie"``/``"foster"`` sampler, default
        :data:`DEFAULT_SUBSTEPS` ``= 1`` (Davie's own method). Larger ``m`` lowers the L² error
        (``h/√(6m)`` for davie, ``h/√(12m)`` for foster) at ``~2 m d`` more normals per step.
    kind : {"stratonovich", "ito"}
        Stratonovich (``RoughPath.kind == "geometric"``) or Itô areas.
    x0 : array_like, shape ``(d,)`` or ``(*batch_shape, d)``, optional
        Starting point (default 0).
    levy_area_error : float or callable h -> float, optional
        Per-component L² error per step for the Fourier samplers; default ``h^1.5`` (the accuracy at
        which the order-1 schemes keep order 1 against Brownian motion). One rule at every door: it is
        accepted where it sets the accuracy, with the Fourier methods and with ``"auto"`` (which meets
        it with ``"exact"``, error zero, for ``d <= 2``), and refused (``ValueError``) with ``"exact"``,
        ``"davie"``, ``"foster"`` and ``None``, where it would have no effect.
    block_bytes : int
        Target memory of one block (increments, areas and random buffers), default 16 MiB (at
        least one step per block); it sets the default of :meth:`blocks`, never the numbers.
        Measured (the rigid body with Davie areas, 1000 paths x 5000 steps, d = 3, CPU time per
        path-step): 2 MiB 144 ns, 8 MiB 119 ns, 16 MiB 109 ns, 64 MiB 108 ns; small blocks
        pay the per-block Python overhead of the driver and the solver (~0.2 ms).

    Notes
    -----
    **Stream.** Let ``S = SeedSequence(seed)`` (or the given one) and ``i`` the flat index of a
    path in ``batch_shape`` (C order). Path ``i`` uses two independent standard-normal streams,

    * increments: ``Generator(PCG64(SeedSequence(S.entropy, spawn_key=S.spawn_key + (i, 0))))``;
      step ``k`` takes the next ``d`` normals, times ``√h_k``;
    * areas: the same with ``spawn_key=S.spawn_key + (i, 1)``; step ``k`` takes the next
      ``(m d if m > 1) + m d + (d(d-1)/2 if davie)`` normals: the bridge normals, the
      space-time normals and Davie's normals, in this order (see
      :mod:`roughpaths.drivers._area_kernels`); for ``"exact"`` (``d = 2``) one normal (and,
      with probability 3·10⁻¹¹, the series sampler's normals after it, in the order documented
      in ``_area_kernels._exact_areas_d2``; ``d = 1``: none); for the Fourier samplers
      ``levy_area_normals(method, d, n)`` normals with the ``(method, n)`` of the step's length, in the
      order of :func:`roughpaths.levy_areas_from_normals`.

    So a path's numbers depend only on ``seed``, ``i``, and (for the areas) ``levy_area`` and
    ``substeps``: not on the block size, on which paths are generated together (:meth:`select`),
    on the executor or process, nor on ``kind``; the increments do not depend on ``levy_area``
    or ``substeps`` either. The normals are numpy's, bit for bit (numpy's ziggurat over
    ``PCG64``), generated by a numba kernel over all paths (:mod:`roughpaths.drivers._random`).

    Examples
    --------
    >>> import numpy as np
    >>> drv = BrownianDriver(2, seed=7, dt=0.01, n_steps=100, batch_shape=(4,))
    >>> drv.n_steps, drv.batch_shape, drv.level
    (100, (4,), 2)
    >>> X = drv.rough_path()
    >>> blocks = list(drv.blocks(max_steps=30))
    >>> [b.n_steps for b in blocks]
    [30, 30, 30, 10]
    >>> bool(np.array_equal(np.concatenate([b.areas for b in blocks], axis=1), X.areas))
    True
    >>> bool(np.array_equal(drv.select([1, 3]).rough_path().increments, X.increments[[1, 3]]))
    True
    """

    def __init__(self, dim, *, seed, times=None, dt=None, n_steps=None, t0=0.0, batch_shape=(),
                 levy_area="auto", substeps=None, kind="stratonovich", x0=None, block_bytes=_BLOCK_BYTES,
                 levy_area_error=None):
        self._init_common(dim, seed, times, dt, n_steps, t0, batch_shape, block_bytes)
        self._sampler = _Sampler(levy_area, self.dim, self._h, substeps, levy_area_error)
        self.kind = _check_kind(kind)
        self.level = 1 if self.levy_area is None else 2
        self._x0 = np.zeros(self.dim) if x0 is None else self._check_start(x0, "x0", self.dim)
        check_memory(4.0 * self._bytes_per_path_step(),        # paths are selected lazily: one path's step
                     f"one step of one path with dim={self.dim}, substeps={self.substeps} and "
                     f"levy_area={self.levy_area!r}", "use fewer substeps")

    def _starts(self) -> dict:
        return {"_x0": self.dim}

    # the area method, as resolved by the one dispatch (roughpaths.drivers.areas)
    levy_area = property(lambda self: self._sampler.name, doc="The Lévy-area method (None: increments only).")
    substeps = property(lambda self: self._sampler.substeps, doc="Substeps of 'davie' / 'foster'.")
    levy_area_error = property(lambda self: self._sampler.levy_area_error,
                               doc="The per-step L² error asked of the error-controlled methods (None: h^1.5).")

    # ------------------------------------------------------------------ layout
    @property
    def _n_area_normals(self) -> int:
        return self._sampler.block_width(self.seed_sequence.pool_size == 4 and _fast_streams_ok())

    def _bytes_per_path_step(self) -> int:
        d = self.dim
        return 8 * (2 * d + (d * d + self._n_area_normals if self.level == 2 else 0))

    def __repr__(self) -> str:
        return (f"BrownianDriver(dim={self.dim}, n_steps={self.n_steps}, batch_shape={self.batch_shape}, "
                f"levy_area={self.levy_area!r}, substeps={self.substeps}, kind={self.kind!r})")

    def refine(self, factor):
        """The same Brownian path with every step split into ``factor`` equal sub-steps: a lazy driver whose
        exactness, per ``levy_area``, is stated in ``roughpaths.drivers.refinement`` (own per-path streams)."""
        return RefinedBrownianDriver(self, factor)

    # ------------------------------------------------------------------ generation
    def _sample_rows(self, dW, h, x, inc_streams, area_streams, zbuf):
        """Fill the block ``dW (P, k, d)`` (scaled; ``x`` advanced to its end) and, where the sampler can,
        its areas, on numba's threads over ranges of paths (:mod:`roughpaths._threads`). Every path's
        numbers come from its own streams, so the split never changes them. Returns the areas, ``False``
        (increments done, areas left to :meth:`_Sampler.fill`) or ``None`` (nothing done: numpy streams)."""
        if inc_streams.states is None or (area_streams is not None and area_streams.states is None):
            return None
        P, k, d = dW.shape
        sqh = np.sqrt(h)
        ito = self.kind == "ito"
        kind = self._sampler.kind
        rows = self.level == 2 and (kind in ("bridge", "fourier") or (kind == "exact" and d == 2))
        areas = np.empty((P, k, d, d)) if rows else None
        tables = step_tables(self._sampler.plan, h) if rows and kind == "fourier" else None
        flat = dW.reshape(P, k * d)

        def sample(lo, hi):
            _pcg64_normals(inc_streams.states[lo:hi], flat[lo:hi])
            _scale_accumulate(dW[lo:hi], sqh, x[lo:hi])
            if rows:
                self._sampler.fill_rows(dW[lo:hi], h, area_streams.states[lo:hi], ito, zbuf, areas[lo:hi], tables)

        per_path = k * (d + (self._sampler.width + d * d if rows else 0)) * 16.0
        _threads.run(sample, _threads.ranges(P, per_path))
        return areas if rows else False

    def blocks(self, max_steps=None):
        """Yield consecutive ``RoughPath`` blocks of at most ``max_steps`` steps covering the grid.

        The numbers do not depend on ``max_steps`` (see *Stream*); default
        :meth:`default_block_steps`. Each call starts the streams afresh.
        """
        K = self._block_size(max_steps)
        N, d, P = self.n_steps, self.dim, self.n_paths
        ss = self.seed_sequence
        keys = np.zeros((P, 2), dtype=np.int64)
        keys[:, 0] = self.path_indices
        inc_streams = PathStreams(ss, keys)
        area_streams = None
        if self.level == 2:
            keys = keys.copy()
            keys[:, 1] = 1
            area_streams = PathStreams(ss, keys)
        rp_kind = None if self.level == 1 else ("geometric" if self.kind == "stratonovich" else "ito")
        h_all = self._h
        x = np.array(self._flat(self._x0, d))
        zbuf = np.empty(max(self._sampler.width, 1))    # one step's normals (the kernels draw them per step)
        for k0 in range(0, N, K):
            k1 = min(N, k0 + K)
            k = k1 - k0
            h = np.ascontiguousarray(h_all[k0:k1])
            dW = np.empty((P, k, d))
            x_start = x.copy()
            sampled = self._sample_rows(dW, h, x, inc_streams, area_streams, zbuf)
            if sampled is None:                     # the numpy streams: the whole block at once
                inc_streams.fill(dW.reshape(P, k * d))
                _scale_accumulate(dW, np.sqrt(h), x)    # x: the position at the end of the block
            if self.level == 1:
                areas = None
            elif sampled is None or sampled is False:
                areas = self._sampler.fill(dW, h, area_streams, self.kind == "ito", zbuf)
            else:
                areas = sampled
            block = RoughPath(dW.reshape(self.batch_shape + (k, d)),
                              None if areas is None else areas.reshape(self.batch_shape + (k, d, d)),
                              times=self.times[k0:k1 + 1], x0=x_start.reshape(self.batch_shape + (d,)),
                              kind=rp_kind, check=False)
            yield block
