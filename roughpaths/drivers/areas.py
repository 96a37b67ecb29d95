r"""Lévy areas given Brownian increments: one vocabulary and one dispatch over every method.

Every door that samples Brownian areas takes ``levy_area`` (one of :data:`LEVY_AREA_METHODS`, or
``None`` for no area) with the same default, ``"auto"``, and ``levy_area_error`` / ``substeps`` where
they mean something, and refuses them where they would have no effect (``levy_area_error`` with any
method but the Fourier ones and ``"auto"``, ``substeps`` with any but ``"davie"`` and ``"foster"``):
:class:`~roughpaths.BrownianDriver`, :func:`~roughpaths.brownian_rough_path`,
:func:`~roughpaths.brownian_increments_and_areas`, :func:`sample_levy_areas` (this module),
:func:`mechanics.run_ensemble` and the main job's ``--levy-area``.

========================= ======================================================= =====================
``levy_area``             what it samples                                          order vs Brownian
========================= ======================================================= =====================
``"auto"`` (default)      ``"exact"`` for ``d <= 2``; for ``d >= 3`` the            1
                          error-controlled method that needs the fewest normals
                          for ``levy_area_error`` (default ``h^{3/2}``), per step
``"exact"``               ``d <= 2``: the exact conditional law given the           1
                          increment (``d = 1``: the area is 0)
``"mrongowius-rossler"``, Fourier series with a Gaussian tail, per-step L² error   1
``"wiktorsson"``          ``levy_area_error``
``"fourier"``             truncated Fourier series (Milstein)                      1 (more normals)
``"davie"``               exact second moments (Davie), ``substeps``               ½ (fast)
``"foster"``              conditional mean given the substep data                  ½ (fast)
========================= ======================================================= =====================

"Order vs Brownian" is the strong order of the order-1 schemes (Davie, log-ODE, the coadjoint
Heun) against the Brownian motion whose increments are sampled: a per-step area error of ``h^{3/2}``
(or an exact law) keeps order 1; Davie's and Foster's areas, whose per-step error is of order
``h``, bring it down to ½ (tested in ``tests/roughpaths/rde/test_strong_order_against_brownian_motion.py``).
Details, derivations and law errors: :mod:`roughpaths.drivers.brownian` (``"davie"``, ``"foster"``),
:mod:`roughpaths.drivers.levy_area` (the Fourier methods and the ``d = 2`` exact sampler).
"""

from __future__ import annotations

import numbers

import numpy as np

from ..validation import as_float_array, check_positive_int, check_rng
from ._area_kernels import _block_areas, _exact_areas_d2
from ._fourier_kernels import _fourier_areas, step_tables
from ._levy_table import TABLE_STEP, load_table
from ._random import PathStreams
from .levy_area import LEVY_AREA_METHODS, _FOURIER_METHODS, block_areas, step_plan

__all__ = ["sample_levy_areas", "DEFAULT_SUBSTEPS"]

#: Default number of substeps per grid step of ``"davie"`` / ``"foster"``, the same for every door
#: (Davie's own method: exact second moments at the lowest cost).
DEFAULT_SUBSTEPS = 1

#: The methods ``levy_area_error`` applies to: the Fourier methods, whose number of terms it sets, and
#: ``"auto"``, which picks the cheapest method meeting it (``"exact"`` for ``d <= 2``, whose error is zero).
#: Every other ``levy_area`` refuses it, whatever the dimension (it would have no effect).
_ERROR_CONTROLLED = _FOURIER_METHODS + ("auto",)

#: Series terms drawn exactly by the fallback of ``"exact"`` (the rest by a moment-matched Gamma tail).
_EXACT_TERMS = 8
# tail sums of the exact d = 2 series: Σ_{k>K} 1/c_k and Σ_{k>K} 1/c_k², c_k = 2π²k²
_EXACT_T1 = (np.pi ** 2 / 6 - sum(1.0 / k ** 2 for k in range(1, _EXACT_TERMS + 1))) / (2 * np.pi ** 2)
_EXACT_T2 = (np.pi ** 4 / 90 - sum(1.0 / k ** 4 for k in range(1, _EXACT_TERMS + 1))) / (4 * np.pi ** 4)
_NO_STATES = np.empty((0, 4), dtype=np.uint64)


class _Sampler:
    """A resolved ``levy_area``: ``kind`` in ``None`` (no area), ``"bridge"`` (davie/foster), ``"exact"``,
    ``"fourier"``; ``width`` the area normals per step (the widest step for ``"fourier"``)."""

    def __init__(self, levy_area, dim, steps, substeps, levy_area_error):
        if levy_area == "none":
            levy_area = None
        if levy_area is not None and levy_area not in LEVY_AREA_METHODS:
            raise ValueError(f"levy_area must be one of {LEVY_AREA_METHODS} or None (increments only), "
                             f"got {levy_area!r}.")
        if levy_area_error is not None and not callable(levy_area_error):
            if (isinstance(levy_area_error, bool) or not isinstance(levy_area_error, numbers.Real)
                    or not np.isfinite(levy_area_error) or levy_area_error <= 0):
                raise ValueError(f"levy_area_error must be a positive number or a callable h -> error, got "
                                 f"{levy_area_error!r}; the default is h^1.5.")
        self.name, self.dim = levy_area, dim
        self.substeps = DEFAULT_SUBSTEPS if substeps is None else check_positive_int(substeps, "substeps")
        self.levy_area_error = levy_area_error
        self.plan = None
        if levy_area is None:
            self.kind = None
        elif levy_area in ("davie", "foster"):
            self.kind = "bridge"
        elif levy_area == "exact" or (levy_area == "auto" and dim <= 2):
            if dim > 2:
                raise ValueError(f"levy_area='exact' is available for dim <= 2 only, got dim={dim}; use "
                                 f"levy_area='auto' (error-controlled, strong order 1) for d > 2.")
            self.kind = "exact"
        else:
            self.kind = "fourier"
            self.plan = step_plan(levy_area, dim, steps, levy_area_error)
        if substeps is not None and self.kind != "bridge":
            raise ValueError(f"substeps={substeps!r} applies to levy_area='davie' or 'foster' only; "
                             f"levy_area={levy_area!r} sets its accuracy by levy_area_error (default h^1.5); "
                             f"leave substeps unset.")
        if levy_area_error is not None and levy_area not in _ERROR_CONTROLLED:
            why = {None: "which draws no area", "exact": "which samples the exact law (no error to set)",
                   "davie": "whose accuracy is set by substeps", "foster": "whose accuracy is set by substeps"}
            raise ValueError(f"levy_area_error applies to the error-controlled methods {_ERROR_CONTROLLED} only; "
                             f"levy_area={levy_area!r}, {why[levy_area]}, would ignore levy_area_error="
                             f"{levy_area_error!r}. Leave levy_area_error unset, or pick one of those methods.")

    def block_width(self, fast: bool) -> int:
        """Area normals per path-step held in a block buffer: none when the kernels draw them (``fast``)."""
        return 0 if fast and self.kind == "fourier" else self.width

    @property
    def width(self) -> int:
        d, m = self.dim, self.substeps
        if self.kind == "bridge":
            return (m * d if m > 1 else 0) + m * d + (d * (d - 1) // 2 if self.name == "davie" else 0)
        if self.kind == "fourier":
            return max(w for _, _, w in self.plan.values())
        return 0

    def fill_rows(self, dW, h, states, ito, zbuf, out, tables=None) -> bool:
        """Write the areas of the paths ``dW (p, k, d)`` with PCG64 ``states (p, 4)`` (advanced) into ``out``
        ``(p, k, d, d)``; False (nothing done) for no area and for exact areas at ``d != 2``. A path's areas
        depend on its own increments and stream only, so any split of the paths into row ranges gives the
        same numbers (:class:`~roughpaths.BrownianDriver` samples ranges on threads). ``tables``: the
        block's ``step_tables`` for ``"fourier"`` (computed here if omitted)."""
        d = dW.shape[2]
        if self.kind == "fourier":
            _fourier_areas(dW, h, *(tables if tables is not None else step_tables(self.plan, h)), states, ito, out)
            return True
        if self.kind == "bridge":
            na = self.width
            _block_areas(dW, h, zbuf[:na].reshape(1, 1, na), states, self.substeps, self.name == "davie" and d > 1,
                         ito, out)
            return True
        if self.kind == "exact" and d == 2:
            _exact_areas_d2(dW, h, states, load_table(), TABLE_STEP, _EXACT_TERMS, _EXACT_T1, _EXACT_T2, ito, out)
            return True
        return False

    def fill(self, dW, h, streams, ito, zbuf):
        """Areas ``(P, k, d, d)`` of a block ``dW (P, k, d)``, steps ``h (k,)``, from ``streams`` (advanced)."""
        P, k, d = dW.shape
        states = streams.states
        out = np.empty((P, k, d, d))
        if states is not None and self.fill_rows(dW, h, states, ito, zbuf, out):
            return out                                # the kernels draw each step's normals from the states
        if self.kind == "fourier":
            widths = [self.plan[float(hk)][2] for hk in h]
            z = np.empty((P, int(sum(widths))))
            streams.fill(z)                          # each path's stream: the block's steps in order
            return block_areas(dW, h, self.plan, z, ito)
        if self.kind == "exact":
            if d == 1:
                out[..., 0, 0] = 0.5 * dW[..., 0] ** 2 - (0.5 * h if ito else 0.0)
                return out
            # only if numpy's algorithms change (the numba streams' self-check failed)
            raise RuntimeError("levy_area='exact' needs the numba PCG64 streams, whose self-check against "
                               "numpy failed in this process; use levy_area='mrongowius-rossler'.")
        na = self.width                              # the bridge methods on numpy streams
        z = np.empty((P, k * na))
        streams.fill(z)
        _block_areas(dW, h, z.reshape(P, k, na), _NO_STATES, self.substeps, self.name == "davie" and d > 1, ito, out)
        return out


def sample_levy_areas(increments, h: float, rng, *, levy_area="auto", levy_area_error=None, substeps=None):
    r"""Sample Lévy areas given Brownian increments, by any method of :data:`~roughpaths.LEVY_AREA_METHODS`.

    Parameters
    ----------
    increments : array_like, shape ``(..., d)``
        Brownian increments over steps of length ``h`` (each ``N(0, h I)``); every leading index is
        one step of its own.
    h : float
        Step length.
    rng : numpy.random.Generator
        Source of randomness: two draws, ``a, b = rng.integers(0, 2**63, size=2)``, seed the members'
        streams; member ``i`` (C order of the leading axes) uses the area stream of path ``i`` of a
        :class:`~roughpaths.BrownianDriver` with ``seed = SeedSequence([a, b])``, so each member's
        area depends on its own increment and stream only.
    levy_area : str
        Method (module table), default ``"auto"``: exact in law for ``d <= 2``, per-step L² error
        ``levy_area_error`` for ``d >= 3``.
    levy_area_error : float, optional
        Per-component L² error per step of the error-controlled methods; default ``h^{3/2}``. Refused
        with ``"exact"``, ``"davie"``, ``"foster"`` (and ``None``), where it would have no effect.
    substeps : int, optional
        Substeps of ``"davie"`` / ``"foster"`` (default 1).

    Returns
    -------
    ndarray, shape ``(..., d, d)``
        Antisymmetric Lévy areas (``docs/conventions.md``: with the ½, ``Var(A_12) = h²/4``).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> h = 0.01
    >>> w = rng.normal(0.0, np.sqrt(h), size=(100_000, 2))
    >>> A = sample_levy_areas(w, h, rng)
    >>> round(float(np.var(A[:, 0, 1]) / (h * h / 4)), 2)     # Var(A_12) = h²/4
    1.0
    >>> A3 = sample_levy_areas(w[:10, :1].repeat(3, axis=1), h, rng, levy_area="mrongowius-rossler")
    >>> A3.shape
    (10, 3, 3)
    """
    w = as_float_array(increments, "increments", min_ndim=1)
    rng = check_rng(rng)
    d = w.shape[-1]
    if d == 0:
        raise ValueError(f"increments must have at least one component (shape (..., d) with d >= 1), got "
                         f"shape {w.shape}.")
    if isinstance(h, bool) or not isinstance(h, numbers.Real) or not np.isfinite(h) or h <= 0:
        raise ValueError(f"h must be a positive finite step length, got {h!r}.")
    if levy_area is None:
        raise ValueError("levy_area=None samples no area; pass a method of LEVY_AREA_METHODS (default 'auto').")
    sampler = _Sampler(levy_area, d, [float(h)], substeps, levy_area_error)
    batch = w.shape[:-1]
    P = int(np.prod(batch, dtype=np.int64))
    if P == 0:
        return np.zeros(batch + (d, d))
    seed = np.random.SeedSequence([int(v) for v in rng.integers(0, 2**63, size=2, dtype=np.int64)])
    keys = np.stack([np.arange(P, dtype=np.int64), np.ones(P, dtype=np.int64)], axis=1)
    dW = np.ascontiguousarray(w.reshape(P, 1, d))
    areas = sampler.fill(dW, np.array([float(h)]), PathStreams(seed, keys), False, np.empty(max(sampler.width, 1)))
    return (0.5 * (areas - np.swapaxes(areas, -1, -2))).reshape(batch + (d, d))
