r"""One Brownian path behind every grid: :meth:`BrownianDriver.refine` (a driver on a finer grid, same path).

``BrownianDriver(...).refine(F)`` is a lazy, per-path seeded driver on the grid whose every step is split
into ``F`` equal sub-steps (any integer ``F >= 1``), whose path is the *same* Brownian path as the coarse
driver's: its increments sum (to round-off) to the coarse ones, and the coarse numbers are never
redrawn. Conventions as in :mod:`roughpaths.drivers.brownian` (Lévy area with the ½; Chen:
:math:`A_{0,h} = \sum_l A_l + \tfrac12\sum_{l<l'} w_l\wedge w_{l'}`).

The Brownian path inside a coarse step
--------------------------------------
On a step of length ``h`` with increment ``W``, with ``u = t/h``, the path is (Kloeden–Platen–Wright)

.. math:: W_t = uW + \sum_{k\ge1} \sigma_k\bigl[\alpha_k(\cos 2\pi k u - 1) + \beta_k \sin 2\pi k u\bigr],
          \qquad \sigma_k = \frac{\sqrt{h/2}}{\pi k},

with independent standard normal vectors :math:`\alpha_k, \beta_k` (``d`` components each), and its Lévy
area is :math:`A = \sum_k \frac{h}{2\pi k}\alpha_k\wedge\beta_k - S\wedge W` with
:math:`S = \sum_k\sigma_k\alpha_k`. The Fourier samplers of :mod:`roughpaths.drivers.levy_area` draw exactly
these: their ``ξ_k, η_k`` are :math:`-\alpha_k, -\beta_k` for the ``n`` retained terms, their ``ψ`` is
the tail sum :math:`\sum_{k>n}\sigma_k\alpha_k` scaled to unit variance, and their pair Gaussian the
tail's own area :math:`\sum_{k>n}\frac{h}{2\pi k}\alpha_k\wedge\beta_k` (replaced by a Gaussian of the
same variance: the approximation of the method).

Refinement of the error-controlled methods (``"fourier"``, ``"mrongowius-rossler"``, ``"wiktorsson"``,
``"auto"``, and ``"exact"``, which has ``n = 0`` retained terms)
-----------------------------------------------------------------------------------------------------
1. The retained terms ``k <= n`` are the coarse step's own normals (regenerated from its stream).
2. The terms ``n < k <= K`` (:math:`K = n + 4F`) are drawn given what the coarse step fixed of them: the
   tail sum ``S`` (if the method stores it) and the coarse Lévy area. The area is bilinear in
   :math:`(\alpha, \beta)`: linear in ``β`` given ``α`` and in ``α`` given ``β``, with the terms beyond
   ``K`` entering as a Gaussian slack (their sum :math:`S_K` and area :math:`R`, variances
   :math:`h\,s_K/(2\pi^2)` and :math:`h^2 s_K/(2\pi^2)`, :math:`s_K = \sum_{k>K}k^{-2}`). Each
   conditional is an exact Gaussian (Matheron) update; :data:`GIBBS_SWEEPS` (8) sweeps alternate them,
   starting from the prior (3 were too few: see "What is approximate").
3. The path beyond ``K`` at the ``F - 1`` interior sub-grid points is drawn exactly from its Gaussian law
   given :math:`S_K` (covariance in closed form: the bridge kernel :math:`h\,u(1-v)`, ``u <= v``, minus
   the first ``K`` terms :math:`\sum_{k\le K}\sigma_k^2[\cos 2\pi k(u-v) - \cos 2\pi ku - \cos 2\pi kv + 1]`).
   The fine increments are the differences of the path at the sub-grid points.
4. The fine Lévy areas have the Mrongowius–Rößler form at the fine step :math:`\delta = h/F` with the
   number of terms :math:`n_f` that the coarse method's error rule gives at :math:`\delta` (``"exact"``
   uses ``"auto"``): :math:`A_l = \sum_{k\le n_f}\frac{\delta}{2\pi k}\alpha_{lk}\wedge\beta_{lk}
   - S_l\wedge w_l + R_l` (the fine step's own Fourier terms, tail sum and Gaussian tail area),
   conditioned on Chen's identity
   :math:`\sum_l A_l = A - \tfrac12\sum_{l<l'}w_l\wedge w_{l'}` by the same alternating exact Gaussian
   updates (the constraint is again bilinear), which keeps their non-Gaussian, bilinear structure.

``"fourier"`` dropped the tail's own area (its coarse area is the conditional mean given the drawn terms):
the refinement draws that area, a Gaussian of variance :math:`h^2 s_n/(2\pi^2)`, from its own stream and
conditions on the completed area, so the refined path has the Brownian law but Chen's identity gives the
coarse area *plus* that draw: its L² size is the method's stated error :math:`h/(\sqrt2\pi\sqrt n)`
(``"auto"`` picks ``"fourier"`` for coarse steps, about ``h >= 1/16``).

What is exact: the fine increments sum to ``W`` and, for ``"mrongowius-rossler"``, ``"wiktorsson"``,
``"exact"`` (and ``"auto"`` steps that use them), Chen's identity holds (to round-off, ~1e-15), path by
path; the retained terms, and with them the explicit part of the coarse area, are the coarse step's.
What is approximate, and why: the coarse tail area is a Gaussian (the method's own approximation); the
terms beyond ``K`` enter the conditioning as a Gaussian slack (the path they add at the sub-grid points is
exact given their sum); the Gibbs sweeps are finite; the fine areas have the fine method's law error. So
the joint law of the fine increments and areas is the Brownian one up to the coarse and fine methods'
stated errors. Measured (``tests/roughpaths/drivers/test_brownian_refinement_same_path.py``, 1–2·10⁵ fine areas per case,
coarse error :math:`h^{3/2}/4`): the fine Lévy areas' variance :math:`\delta^2/4` and fourth moment
:math:`5\delta^4/16` are reproduced within 4 standard errors (about 1 % and 3 % of the values) for
factors 2, 3, 8 and 64, ``d = 2, 3``, where the former sequential splits of ``refine(X, F, rng)`` (which
now uses this construction for ``F > 2``) inflated the variance by 7–18 %.

*Finite sweeps* (``tests/roughpaths/drivers/test_brownian_refinement_positions.py``, every method, per
position inside the coarse step): the chain starts from the prior, and its bias is position-dependent.
With the former 3 sweeps, ``"exact"`` refined by 3 (10⁶ coarse steps) gave fine-increment variances
``[1.0060, 0.9943, 1.0032] δ`` (χ² p ≈ 1e-16; fine-area variances p ≈ 6e-7), with 1 sweep ±2.4 %; the
bias shrinks about 2.5-fold per sweep, and with 8 sweeps every method passes (``"exact"``: variances
within sampling error, see the test's docstring for the numbers).

*Few retained terms* (``tests/roughpaths/drivers/test_brownian_refinement_few_terms.py``): with one or two
retained terms of a Gaussian-tail method (``"mrongowius-rossler"``, ``"wiktorsson"``, ``"fourier"``,
``"auto"`` at the default error and ``h`` about 1/16–1/64), the coarse tail's own area is a Gaussian, while
the explicit terms conditioned on it are Brownian (bilinear, heavier-tailed): they explain less of a
Gaussian area than of a Brownian one, the cross terms :math:`\tfrac12\sum_{l<l'}w_l\wedge w_{l'}` are too
little correlated with the coarse area, and Chen's identity puts the rest into the fine areas, which
come out positively correlated (about +0.35–0.45 % between neighbours). The variance of their sum over
a coarse step, Brownian value :math:`h^2/(4F)`, is then high (``F = 8``, "mrongowius-rossler"): see the
table in that test's docstring — +3.4 ± 0.3 % (``d = 3``, ``n = 1``), +2.2 ± 0.5 % (``d = 2``, ``n = 1``),
+0.9–1.0 % (``n = 2``), within sampling error at ``n = 4`` (10⁵ coarse steps each). More sweeps do not remove it (3, 10, 30 sweeps:
+4.0, +3.1, +3.3 % at ``d = 3``, ``n = 1``), and with a Brownian tail area in place of the Gaussian the same
construction is Brownian (+0.9 ± 0.4 %): it is the coarse method's approximation showing. When the fine
areas' joint law matters, ask for ``levy_area_error`` giving ``n >= 4`` terms (or use ``"exact"`` for
``d = 2``). Cost: the refinement's normals per coarse step, e.g. 642 (``"exact"``, ``F = 3``), 3117
(``d = 3``, ``F = 8``), 37509 (``d = 3``, ``F = 64``), 2.4–2.5 times those with 3 sweeps, and ``O(F^2)``
operations; refine by up to ~100 at once.

Refinement of ``"davie"`` / ``"foster"``
----------------------------------------
What those samplers draw of the path is linear: the increments and the space-time Lévy areas
:math:`H = \frac1\delta\int(W_r - W_s - \frac{r-s}{\delta}w)\,dr` of their ``m`` sub-steps. The fine path
is the exact Gaussian bridge given them (the fine increments and fine space-time areas, from their
closed-form joint covariance), and the fine areas are drawn by the same method (one sub-step per fine
step): :math:`H_l\wedge w_l` (+ Davie's independent Gaussian of variance :math:`\delta^2/12`). The coarse
area is *not* the area of the refined path: Davie's added Gaussian is independent of the path, and
Foster's conditional mean lacks the path's own residual. The Chen defect (coarse area minus the Chen sum
of the fine ones) has mean square :math:`h^2/6` (davie) and :math:`h^2(1 - 1/F)/12` (foster) per
component, their stated L² errors, which is why "davie" areas give strong order ½ against Brownian
motion. ``factor = 1`` returns the coarse path itself.

Streams: path ``i`` draws the refinement's normals from ``SeedSequence(S.entropy, spawn_key=S.spawn_key
+ (i, 2))`` (the coarse driver uses ``(i, 0)`` and ``(i, 1)``), a fixed number per coarse step, steps in
order: invariant under block size, :meth:`select` and executor. Refinements by different factors are
each consistent with the coarse driver, not with one another (``refine(4)`` is not a refinement of
``refine(2)``); for nested grids take the finest and restrict it (``RoughPath.restrict``: exact Chen sums).
"""

from __future__ import annotations

import math

import numpy as np

from ..paths.rough_path import RoughPath
from ..validation import check_memory, check_positive_int, check_rng
from ._bridge import (GIBBS_SWEEPS, MODES_PER_SUBSTEP, _assemble, _BridgePlan, _FourierPlan, _refine_bridge,
                      _refine_by_fourier_path, _refine_fourier, _split, refine_bytes)
from ._random import PathStreams
from ._seeded import SeededDriver
from .base import Driver
from .levy_area import _tail_zeta2, step_plan

__all__ = ["refine", "RefinedBrownianDriver", "GIBBS_SWEEPS", "MODES_PER_SUBSTEP"]


# ------------------------------------------------------------------ a given sample
def refine(X: RoughPath, factor, rng) -> RoughPath:
    r"""Refine a Brownian rough path: split every step into ``factor`` equal substeps, Chen-consistently.

    The fine path restricts back exactly: ``refine(X, m, rng).restrict(X.times)`` equals ``X``
    to round-off (``chen_defect`` ~ 1e-16 relative), for every sample.

    Parameters
    ----------
    X : RoughPath
        A Brownian rough path (``kind`` ``"geometric"`` for Stratonovich, ``"ito"``, or level 1),
        e.g. from :func:`brownian_rough_path`.
    factor : int
        Substeps per step, ``>= 1`` (``1`` returns ``X`` unchanged).
    rng : numpy.random.Generator
        Source of randomness, drawn from directly (not the driver's per-path streams: the
        refined path depends on the whole batch and on ``factor``'s sequence of splits).

    Returns
    -------
    RoughPath
        Same kind, batch shape and ``x0``, on the grid with ``factor`` equal substeps per step.

    Notes
    -----
    ``factor = 2``: one split. A split of a
    step with increment ``W`` and Lévy area ``L`` draws the bridge point
    ``b = w_1 - ρW ~ N(0, ρ(1-ρ)h I)`` and Davie-type Lévy areas ``L_k = H_k ∧ w_k + λ_k`` for both
    parts, then corrects ``(b, L_1, L_2)`` by the linear (Matheron / Kalman) update
    ``Y ← Y + Cov(Y, Z | W) Var(Z | W)^{-1} (L - Z(Y))`` for the constraint
    ``Z(Y) = L_1 + L_2 + ½ b ∧ W = L``, which is linear in ``(b, L_1, L_2)`` given ``W``, with the
    exact Brownian conditional covariances ``Var(L | W) = h²/12 + h (W⊗W-terms)/12``; its inverse
    is in closed form (no linear solves).

    What is exact:

    * Chen: the refined path restricts to ``X`` exactly (to round-off), path by path;
    * for ``factor = 2``: every second moment of the fine ``(w_1, L_1, w_2, L_2)``, jointly with the
      coarse ``(W, L)`` and conditionally on ``W``, equals the Brownian one, provided the coarse
      ``L`` has the Brownian conditional variance given ``W`` (true for :func:`brownian_rough_path`
      with ``levy_area="davie"``); in particular the fine increments have mean ``W/2`` and
      covariance ``h/4 I`` given ``W`` (the bridge), and fine Lévy areas variance ``(h/2)²/4``.

    What is approximate:

    * the fine increments are not exactly Gaussian given ``W`` (they are correlated with the coarse
      area, as in the true conditional law given ``(W, L)``, which is not Gaussian either);
    * higher moments (the fine Lévy areas are lighter-tailed than Brownian ones);
    * for ``factor > 2`` the steps are refined in one go by the construction of
      ``roughpaths.drivers.refinement`` for a step whose only data are ``(W, L)`` (as for
      ``levy_area="exact"``: Fourier terms drawn given the area by Gibbs sweeps of exact Gaussian
      updates, fine areas conditioned on Chen's identity the same way), which keeps the fine Lévy-area
      variance and fourth moment Brownian within sampling error
      (``tests/roughpaths/drivers/test_brownian_refinement_same_path.py``); the former sequential splits inflated the
      variance by 7 % (factor 3) to 18 % (factor 8). Repeated halving (``refine`` by 2, again and
      again) still compounds the factor-2 split's approximation: +12 % at 4, +21 % at 8; refine by the
      whole factor at once instead.

    Itô paths are converted to Stratonovich (``+ ½ h I``), refined, and converted back.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import brownian_rough_path
    >>> from roughpaths import chen_defect
    >>> rng = np.random.default_rng(2)
    >>> X = brownian_rough_path(np.linspace(0, 1, 5), 2, rng, batch_shape=(10,))
    >>> Y = refine(X, 3, rng)
    >>> Y.n_steps, chen_defect(Y, X) < 1e-13
    (12, True)
    """
    if not isinstance(X, RoughPath):
        raise TypeError(f"X must be a RoughPath, got {type(X).__name__}; build one with "
                        f"brownian_rough_path(times, dim, rng).")
    m = check_positive_int(factor, "factor")
    rng = check_rng(rng, "rng")
    if X.level == 2 and X.kind not in ("geometric", "ito"):
        raise ValueError(f"X.kind must be 'geometric' (Stratonovich) or 'ito' to refine as Brownian "
                         f"motion, got {X.kind!r}; build X with brownian_rough_path.")
    d = X.increments.shape[-1]
    check_memory(refine_bytes(X, m), f"refining {X.increments.shape[:-1]} steps by "
                 f"factor={m} (the refined increments and areas, with temporaries)",
                 "use a smaller factor, or refine a shorter or smaller batch of paths")
    if m == 1:
        return X
    t, h = X.times, X.dt
    N, d, batch = X.n_steps, X.dim, X.batch_shape
    with_area = X.level == 2
    W = X.increments.reshape(-1, d)
    hr = np.broadcast_to(h, batch + (N,)).reshape(-1)
    L = X.step_levy_areas.reshape(-1, d, d) if with_area else None
    if m > 2 and with_area:
        dw, A = _refine_by_fourier_path(W, L, hr, m, rng)
        dw = dw.reshape(batch + (N * m, d))
        A = A.reshape(batch + (N * m, d, d))
        fine_t = np.append((t[:-1, None] + h[:, None] * (np.arange(m) / m)).reshape(-1), t[-1])
        return _assemble(dw, A, fine_t, X, d)
    ws, Ls = [], []
    rest_W, rest_L, rest_h = W, L, hr
    for j in range(m - 1):
        rho = 1.0 / (m - j)
        w1, L1, rest_W, rest_L = _split(rng, rest_W, rest_L, rest_h, rho, with_area)
        rest_h = (1.0 - rho) * rest_h
        ws.append(w1)
        Ls.append(L1)
    ws.append(rest_W)
    Ls.append(rest_L)
    dw = np.stack(ws, axis=1).reshape(batch + (N * m, d))
    fine_t = np.append((t[:-1, None] + h[:, None] * (np.arange(m) / m)).reshape(-1), t[-1])
    if not with_area:
        return RoughPath(dw, None, times=fine_t, x0=X.x0, check=False)
    A = np.stack(Ls, axis=1).reshape(batch + (N * m, d, d))
    return _assemble(dw, A, fine_t, X, d)


# ------------------------------------------------------------------ the driver
_ROWS = 1024           # coarse path-steps refined at once (bounds the temporaries, never the numbers)


class RefinedBrownianDriver(Driver):
    r"""A :class:`~roughpaths.BrownianDriver` on a grid ``factor`` times finer, carrying the same Brownian path.

    Built by :meth:`roughpaths.BrownianDriver.refine`; see :mod:`roughpaths.drivers.refinement` for what is
    exact and what is approximate for each ``levy_area`` method. Lazy (time blocks), per-path seeded:
    a path's numbers depend only on the coarse driver's seed, the path's index, ``factor`` and the
    method, never on the block size, :meth:`select` or the executor.

    Parameters
    ----------
    coarse : BrownianDriver
        The driver to refine (its numbers are regenerated, never changed).
    factor : int
        Equal sub-steps per coarse step, ``>= 1``.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import BrownianDriver
    >>> from roughpaths import chen_defect
    >>> drv = BrownianDriver(2, seed=3, dt=0.25, n_steps=4, batch_shape=(5,), levy_area="mrongowius-rossler")
    >>> fine = drv.refine(3)
    >>> fine.n_steps, fine.batch_shape
    (12, (5,))
    >>> X, Y = drv.rough_path(), fine.rough_path()
    >>> bool(chen_defect(Y, X) < 1e-13), bool(np.allclose(Y.restrict(X.times).increments, X.increments))
    (True, True)
    """

    def __init__(self, coarse, factor):
        # a BrownianDriver (checked by what is used of it: brownian.py imports this module, not the reverse)
        if not (isinstance(coarse, SeededDriver) and hasattr(coarse, "levy_area") and hasattr(coarse, "substeps")):
            raise TypeError(f"coarse must be a BrownianDriver, got {type(coarse).__name__}; call "
                            f"BrownianDriver(...).refine(factor).")
        self.factor = check_positive_int(factor, "factor")
        self.coarse = coarse
        self.dim, self.level, self.kind = coarse.dim, coarse.level, coarse.kind
        F = self.factor
        t = coarse.times
        check_memory(8.0 * 3 * (float(coarse.n_steps) * F + 1),     # the fine grid and its temporaries
                     f"the refined grid ({coarse.n_steps} steps x factor={F})",
                     "refine by a smaller factor (refine twice, or by up to ~100 at once)")
        fine = (t[:-1, None] + coarse._h[:, None] * (np.arange(F) / F)).ravel()
        self.times = np.append(fine, t[-1])
        self.times.setflags(write=False)
        self._plans = {}

    @property
    def batch_shape(self) -> tuple:
        return self.coarse.batch_shape

    @property
    def n_paths(self) -> int:
        return self.coarse.n_paths

    @property
    def path_indices(self) -> np.ndarray:
        return self.coarse.path_indices

    def __repr__(self) -> str:
        return f"RefinedBrownianDriver({self.coarse!r}, factor={self.factor})"

    def select(self, paths):
        """The refinement of ``coarse.select(paths)``: bitwise equal to those paths of this driver."""
        new = RefinedBrownianDriver(self.coarse.select(paths), self.factor)
        new._plans = self._plans
        return new

    def default_block_steps(self) -> int:
        """Fine steps per block when :meth:`blocks` gets no ``max_steps``: whole coarse steps, as many as keep
        :meth:`block_nbytes` within the coarse driver's ``block_bytes`` (at least one).

        Sized by this driver's own bytes per coarse step (the refinement normals and the ``factor`` fine steps),
        not the coarse driver's: sized by the coarse steps, a block of 200 paths refined by 16 with
        Mrongowius–Rößler areas held 3.5 GiB against a 16 MiB ``block_bytes`` (measured).
        """
        c, F = self.coarse, self.factor
        lo, hi = 1, c.n_steps                     # block_nbytes grows with the block: the largest that fits
        if self.block_nbytes(F * hi) <= c.block_bytes:
            return F * hi
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if self.block_nbytes(F * mid) <= c.block_bytes else (lo, mid)
        return F * lo

    def block_nbytes(self, max_steps=None) -> float:
        """Bytes one block of :meth:`blocks` (``max_steps`` fine steps, default :meth:`default_block_steps`) holds
        while it is made, 8 bytes each: the coarse block of ``k = max(1, K // factor)`` steps
        (``coarse.block_nbytes(k)``); the area and refinement normals of its ``P`` paths and their per-step-length
        gathered copies (``2 P k (a + r)``, ``a`` and ``r`` the widest per-step widths); the fine increments and
        areas and their per-step-length copies (``2 P k F (d + d²)``), the assembly's two ``P k F d²``
        temporaries, and the temporaries of a chunk of at most 1024 rows being refined (four arrays of a
        row's normals and fine values). A consumer that keeps a block while the next is made holds two.
        """
        F, d, c = self.factor, self.dim, self.coarse
        K = self.default_block_steps() if max_steps is None else check_positive_int(max_steps, "max_steps")
        if F == 1:
            return c.block_nbytes(K)
        kc = min(max(1, K // F), c.n_steps)
        widths = [self._area_width(float(x)) + self._refine_width(float(x)) for x in np.unique(c._h)]
        P = float(self.n_paths)
        rows = min(P * kc, float(_ROWS))
        return (c.block_nbytes(kc)
                + 8.0 * P * kc * (2.0 * max(widths) + 2.0 * F * (d + d * d) + 2.0 * F * d * d)
                + 8.0 * rows * 4.0 * (max(widths) + F * (d + d * d)))

    # ------------------------------------------------------------------ per step length
    def _plan(self, h: float):
        plan = self._plans.get(h)
        if plan is not None:
            return plan
        c, F, d = self.coarse, self.factor, self.dim
        if c.levy_area is None:
            plan = ("bridge1", F * d)
        elif c.levy_area in ("davie", "foster"):
            plan = _BridgePlan(h, F, d, c.substeps, c.levy_area == "davie")
        else:
            if c._sampler.kind == "exact":
                method, n, stores_s, fine_method, err = "exact", 0, False, "auto", None
            else:
                method, n, _ = c._sampler.plan[h]
                stores_s = method in ("fourier", "mrongowius-rossler")
                fine_method, err = c.levy_area, c.levy_area_error
            delta = h / F
            fine = step_plan(fine_method, d, [delta], err)[float(delta)] if d > 1 else ("fourier", 1, 0)
            plan = _FourierPlan(h, F, d, method, n, stores_s, fine)
        self._plans[h] = plan
        return plan

    def _area_width(self, h: float) -> int:
        c = self.coarse
        if c._sampler.kind == "fourier":
            return c._sampler.plan[h][2]
        if c.levy_area in ("davie", "foster"):
            return c._n_area_normals
        return 0

    def _refine_rows(self, h, W, A, za, zr):
        """Fine ``(w, Lévy areas)`` of rows ``W (R, d)``, ``A (R, d, d)`` with their area and refinement normals."""
        plan, d, F = self._plan(h), self.dim, self.factor
        R = W.shape[0]
        c = self.coarse
        if c.levy_area is None:
            z = zr.reshape(R, F, d)
            return W[:, None, :] / F + math.sqrt(h / F) * (z - z.mean(axis=1, keepdims=True)), None
        if isinstance(plan, _BridgePlan):
            m = plan.m
            if m == 1:
                Wsub, zeta = W[:, None, :], za[:, :d].reshape(R, 1, d)
            else:
                zb = za[:, :m * d].reshape(R, m, d)
                Wsub = math.sqrt(h / m) * (zb - zb.mean(axis=1, keepdims=True)) + W[:, None, :] / m
                zeta = za[:, m * d:2 * m * d].reshape(R, m, d)
            Hsub = math.sqrt(h / m / 12.0) * zeta
            return _refine_bridge(plan, Wsub, Hsub, zr)
        n = plan.n
        xi = za[:, :d * n].reshape(R, d, n) if n else None
        eta = za[:, d * n:2 * d * n].reshape(R, d, n) if n else None
        S = None
        if plan.stores_s:
            psi = za[:, 2 * d * n:2 * d * n + d]
            S = -math.sqrt(h * _tail_zeta2(n) / (2 * math.pi ** 2)) * psi
        return _refine_fourier(plan, W, A, xi, eta, S, zr)

    def _refine_width(self, h: float) -> int:
        plan = self._plan(h)
        return plan[1] if isinstance(plan, tuple) else plan.width

    # ------------------------------------------------------------------ generation
    def blocks(self, max_steps=None):
        """Yield consecutive ``RoughPath`` blocks of at most ``max_steps`` fine steps covering the fine grid.

        The numbers do not depend on ``max_steps`` (default :meth:`default_block_steps`).
        """
        F, d, c = self.factor, self.dim, self.coarse
        K = self.default_block_steps() if max_steps is None else check_positive_int(max_steps, "max_steps")
        kc = max(1, K // F)
        P = self.n_paths
        keys = np.zeros((P, 2), dtype=np.int64)
        keys[:, 0] = self.path_indices
        keys[:, 1] = 1
        area_streams = None
        if c._sampler.kind in ("bridge", "fourier"):
            area_streams = PathStreams(c.seed_sequence, keys)        # the coarse area normals, regenerated
        keys = keys.copy()
        keys[:, 1] = 2
        ref_streams = PathStreams(c.seed_sequence, keys)
        rp_kind = None if self.level == 1 else ("geometric" if self.kind == "stratonovich" else "ito")
        fine_t = self.times
        if F == 1:                                  # the coarse path itself
            yield from c.blocks(K)
            return
        kf = 0
        for k0, cb in zip(range(0, c.n_steps, kc), c.blocks(kc)):
            k = cb.n_steps
            h = c._h[k0:k0 + k]
            W = cb.increments.reshape(P, k, d)
            L = None if cb.areas is None else 0.5 * (cb.areas - np.swapaxes(cb.areas, -1, -2)).reshape(P, k, d, d)
            aw = np.array([self._area_width(float(x)) for x in h], dtype=np.int64)
            rw = np.array([self._refine_width(float(x)) for x in h], dtype=np.int64)
            za = np.empty((P, int(aw.sum())))
            if area_streams is not None and za.shape[1]:
                area_streams.fill(za)
            zr = np.empty((P, int(rw.sum())))
            ref_streams.fill(zr)
            ao, ro = np.concatenate([[0], np.cumsum(aw)]), np.concatenate([[0], np.cumsum(rw)])
            w = np.empty((P, k, F, d))
            A = None if L is None else np.empty((P, k, F, d, d))
            for hv in np.unique(h):
                idx = np.flatnonzero(h == hv)
                a_cols = ao[idx][:, None] + np.arange(aw[idx[0]])
                r_cols = ro[idx][:, None] + np.arange(rw[idx[0]])
                Wr = W[:, idx].reshape(-1, d)
                Lr = None if L is None else L[:, idx].reshape(-1, d, d)
                zar = za[:, a_cols].reshape(Wr.shape[0], a_cols.shape[1])      # explicit widths: P may be 0
                zrr = zr[:, r_cols].reshape(Wr.shape[0], r_cols.shape[1])
                wr = np.empty((Wr.shape[0], F, d))
                Ar = None if L is None else np.empty((Wr.shape[0], F, d, d))
                for r0 in range(0, Wr.shape[0], _ROWS):
                    s = slice(r0, r0 + _ROWS)
                    wi, Ai = self._refine_rows(float(hv), Wr[s], None if Lr is None else Lr[s], zar[s], zrr[s])
                    wr[s] = wi
                    if Ar is not None:
                        Ar[s] = Ai
                w[:, idx] = wr.reshape(P, idx.size, F, d)
                if A is not None:
                    A[:, idx] = Ar.reshape(P, idx.size, F, d, d)
            w = w.reshape(P, k * F, d)
            if A is not None:
                A = A.reshape(P, k * F, d, d) + 0.5 * w[..., :, None] * w[..., None, :]
                if self.kind == "ito":
                    dh = np.repeat(h / F, F)
                    A[..., np.arange(d), np.arange(d)] -= 0.5 * dh[:, None]
            x = cb.x0.reshape(P, d).copy()
            for s0 in range(0, k * F, K):
                s1 = min(k * F, s0 + K)
                yield RoughPath(w[:, s0:s1].reshape(self.batch_shape + (s1 - s0, d)),
                                None if A is None else A[:, s0:s1].reshape(self.batch_shape + (s1 - s0, d, d)),
                                times=fine_t[kf + s0:kf + s1 + 1], x0=x.reshape(self.batch_shape + (d,)),
                                kind=rp_kind, check=False)
                x = x + w[:, s0:s1].sum(axis=1)
            kf += k * F
