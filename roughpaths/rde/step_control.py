r"""Step control for :func:`~roughpaths.solve`: the :class:`StepController` contract, :class:`FixedSteps` and :class:`PIController`.

:func:`~roughpaths.solve` runs one time loop: the controller proposes the next step of each *lane* (a
batch member with steps of its own, or the whole batch when the steps are shared), the driver answers the
increments and areas of the attempted steps, the solver integrates them, and the controller accepts or
rejects each lane's attempt and sizes its next step. The controller never sees the solver or the driver:
only times, step sizes and error ratios, all arrays over lanes (elementwise, so a lane's steps depend on
its own data only). A controller is any object that follows the numbered contract of :class:`StepController`:

1. ``adaptive`` (bool): whether an attempt needs an error estimate. ``False``: every proposed step is
   accepted, the solver takes one step per attempt and no error is estimated (a schedule of steps).
   ``True``: the solver's declared estimate (``Solver.error_estimate``, step doubling by default) is
   computed and its error ratio passed to ``adapt``.
2. ``init(t0, t1, lanes, error_order)``: a fresh state (a ``dict``, never stored on the controller, so one
   controller serves any number of solves) holding at least ``"h"``, the first step of every lane
   (``(lanes,)`` floats). ``error_order`` is the solver's declared strong order: the error ratio of
   :meth:`error_ratio` scales as ``h ** error_order``.
3. ``error_ratio(y, y_new, y_err, h, span)`` (adaptive controllers): the error of each member in units of
   the tolerance, ``<= 1`` meaning acceptable; ``y``, ``y_new``, ``y_err`` have shape ``(..., e)``,
   ``h`` broadcasts against the batch, ``span = t1 - t0``. The loop reduces it over a lane's members (one
   member per lane with per-member steps; the maximum over the batch with shared steps).
4. ``adapt(state, t, h, r)``: given the attempted steps ``[t, t + h]`` and their error ratios ``r``
   (``(lanes,)``, ``inf`` for an attempt that became non-finite; ``None`` for a non-adaptive controller),
   return the boolean ``accept`` per lane and store the next step of every lane in ``state["h"]`` (after an
   acceptance the step from ``t + h``, after a rejection the retry from ``t``).
5. ``dt_min(span)``, ``dt_max(span)``, ``max_steps``: the smallest and largest steps and the most attempts
   per lane. A step at ``dt_min`` whose error ratio exceeds 1 is a failure of its members (by
   ``on_failure``), never accepted, so an unreachable tolerance fails fast.

The loop owns everything else: snapping step ends to the driver's grid, never stepping over save times,
the failure policy, the saved states and the statistics.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from numba import njit

from ..validation import check_positive_int, check_positive_real

__all__ = ["StepController", "FixedSteps", "PIController"]


class StepController:
    """Base class of step controllers: the numbered contract of the module docstring (defaults: no adaptivity)."""

    adaptive: bool = False
    max_steps: int = 100_000

    def init(self, t0, t1, lanes, error_order):  # pragma: no cover - abstract
        """A fresh state ``{"h": (lanes,) first steps, ...}`` (contract item 2)."""
        raise NotImplementedError(f"{type(self).__name__} does not define init()")

    def error_ratio(self, y, y_new, y_err, h, span):  # pragma: no cover - abstract
        """Error per member in units of the tolerance (contract item 3)."""
        raise NotImplementedError(f"{type(self).__name__} is not adaptive: it defines no error_ratio()")

    def adapt(self, state, t, h, r):  # pragma: no cover - abstract
        """``accept (lanes,)``; the next steps in ``state["h"]`` (contract item 4)."""
        raise NotImplementedError(f"{type(self).__name__} does not define adapt()")

    def dt_min(self, span) -> float:
        """The smallest step (contract item 5; default ``span · 2^-30``)."""
        return span * 2.0 ** -30

    def dt_max(self, span) -> float:
        """The largest step (contract item 5; default ``span``)."""
        return span


class FixedSteps(StepController):
    """Fixed steps: the default controller of :func:`~roughpaths.solve`.

    On a grid driver (a ``RoughPath`` or a lazy ``Driver``) the steps are the grid's. On a driver that answers
    on any times (a :class:`~roughpaths.BrownianTree`) they are ``dt`` long (the last one shortened to end at
    ``t1`` or a save time), with their ends snapped to the tree's dyadic grid (spacing at most ``dt/8``: a step
    of 0.3 on ``[0, 1]`` is 0.3125 long; a dyadic ``dt`` is kept exactly). A ``dt`` shorter than 8 cells of the
    tree's grid is refused, naming the resolution that resolves it.

    Parameters
    ----------
    dt : float, optional
        The step on a driver without a grid; ``None`` (default) for a grid driver's own steps.

    Examples
    --------
    >>> import numpy as np
    >>> import roughpaths as rp
    >>> M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    >>> tree = rp.BrownianTree(2, seed=0, batch_shape=(4,))
    >>> sol = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(), step_control=rp.FixedSteps(0.125))
    >>> sol.times.shape, bool((sol.times == np.arange(9) / 8).all())      # every path: its own row of times
    ((4, 9), True)
    """

    def __init__(self, dt=None):
        self.dt = None if dt is None else check_positive_real(dt, "dt")

    def __repr__(self) -> str:
        return f"FixedSteps(dt={self.dt!r})"

    def init(self, t0, t1, lanes, error_order):
        if self.dt is None:
            raise ValueError("FixedSteps() takes the driver's grid, but this driver has none (a BrownianTree): pass "
                             "FixedSteps(dt=...), an adaptive PIController(rtol, atol), or driver=tree.rough_path(times).")
        if (t1 - t0) / self.dt > self.max_steps:      # else max_steps attempts of a crawl, then a ValueError
            raise ValueError(f"FixedSteps(dt={self.dt!r}) needs {(t1 - t0) / self.dt:.3g} steps on [t0, t1] = [{t0}, "
                             f"{t1}], more than max_steps = {self.max_steps} (the most attempts of a lane); take a "
                             f"longer dt, or solve on a grid of that step: driver=tree.rough_path(times).")
        return {"h": np.full(lanes, float(self.dt))}

    def adapt(self, state, t, h, r):
        return np.ones(np.shape(h), dtype=bool)


class PIController(StepController):
    r"""Adaptive step sizes: a proportional–integral controller of the predicted global error.

    Parameters
    ----------
    rtol, atol : float
        Relative and absolute tolerances (``rtol >= 0``, ``atol >= 0``, not both 0). They bound the
        *predicted global* error (below): the strong error of an order-1 scheme is about proportional to them.
    dt0 : float, optional
        First step tried (default ``(t1 - t0) / 64``).
    dt_min : float, optional
        Smallest step (default ``(t1 - t0) · 2^-30``, or ``dt_max`` if that is smaller). A step at ``dt_min`` whose error still exceeds the
        tolerance is a failure of the members concerned, counted in ``Solution.stats["at_dt_min"]``: by
        ``solve(..., on_failure=...)`` it raises a ``ValueError`` at once naming the fix (``"raise"``), or marks
        those members failed and finishes the others (``"mask"``). An unreachable tolerance thus fails after
        about ``log(dt0 / dt_min) / log(1 / factor_min)`` attempts.
    dt_max : float, optional
        Largest step (default ``t1 - t0``).
    safety : float
        Factor applied to the predicted step (default 0.8).
    factor_min, factor_max : float
        Bounds on the ratio of consecutive steps (defaults 0.2 and 5).
    icoeff, pcoeff : float
        Integral and proportional exponents :math:`\beta_I`, :math:`\beta_P` (defaults 0.3 and 0.1, the gains
        diffrax recommends for SDEs). The error ratio is proportional to ``h ** error_order`` (the solver's
        strong order), so :math:`\beta_I + \beta_P = 1` is the dead-beat sum; ``icoeff=1, pcoeff=0`` is the
        plain integral controller. A path's error estimate is one draw of a random local error, so smaller
        gains, which let the steps vary less, give less error for the same work (``docs/adaptive-steps.md``
        compares settings).
    max_steps : int
        Most attempts of a lane (accepted plus rejected) before ``solve`` gives up with a ``ValueError``
        (default 10⁵): a bound on the work of tolerances that can be met (one that cannot fails at ``dt_min``).

    Notes
    -----
    The error ratio of a member (:meth:`error_ratio`) is the RMS over its ``e`` components, as in diffrax and
    scipy, times :math:`\sqrt{T/h}` (random local errors add in mean square, so this is the predicted global
    error; ``docs/adaptive-steps.md``):

    .. math:: r = \sqrt{\tfrac{T}{h}}\,\Bigl(\tfrac1e\sum_a\Bigl(\frac{\mathrm{err}^a}
              {\mathrm{atol} + \mathrm{rtol}\max(|y^a|, |y_{\mathrm{new}}^a|)}\Bigr)^2\Bigr)^{1/2}.

    The next step is :math:`h\,\min(f_{\max}, \max(f_{\min}, s\,r_n^{-(\beta_I + \beta_P)/q}\,
    r_{n-1}^{\beta_P/q}))` with ``q = error_order`` and :math:`f_{\max} = 1` right after a rejection.

    Examples
    --------
    >>> import numpy as np
    >>> import roughpaths as rp
    >>> M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    >>> tree = rp.BrownianTree(2, seed=0, batch_shape=(4,))
    >>> sol = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(),
    ...                step_control=rp.PIController(rtol=1e-2, atol=1e-2), save_at="end")
    >>> sol.final.shape, bool((sol.stats["accepted"] > 0).all()), float(sol.times[-1])
    ((4, 2), True, 1.0)
    """

    adaptive = True

    def __init__(self, rtol, atol, dt0=None, *, dt_min=None, dt_max=None, safety=0.8, factor_min=0.2,
                 factor_max=5.0, icoeff=0.3, pcoeff=0.1, max_steps=100_000):
        self.rtol = check_positive_real(rtol, "rtol", allow_zero=True)
        self.atol = check_positive_real(atol, "atol", allow_zero=True)
        if self.rtol == 0.0 and self.atol == 0.0:
            raise ValueError("rtol and atol are both 0: no error can be met; give a positive tolerance, e.g. "
                             "PIController(rtol=1e-3, atol=1e-6).")
        self.dt0 = None if dt0 is None else check_positive_real(dt0, "dt0")
        self._dt_min = None if dt_min is None else check_positive_real(dt_min, "dt_min")
        self._dt_max = None if dt_max is None else check_positive_real(dt_max, "dt_max")
        if self._dt_min is not None and self._dt_max is not None and self._dt_min > self._dt_max:
            raise ValueError(f"dt_min={dt_min!r} exceeds dt_max={dt_max!r}; swap them.")
        self.safety = check_positive_real(safety, "safety")
        if self.safety > 1.0:
            raise ValueError(f"safety must lie in (0, 1], got {safety!r}; the default is 0.8.")
        self.factor_min = check_positive_real(factor_min, "factor_min")
        self.factor_max = check_positive_real(factor_max, "factor_max")
        if not self.factor_min < 1.0 < self.factor_max:
            raise ValueError(f"need factor_min < 1 < factor_max, got factor_min={factor_min!r}, "
                             f"factor_max={factor_max!r}; the defaults are 0.2 and 5.")
        self.icoeff = check_positive_real(icoeff, "icoeff")
        self.pcoeff = check_positive_real(pcoeff, "pcoeff", allow_zero=True)
        self.max_steps = check_positive_int(max_steps, "max_steps")

    def __repr__(self) -> str:
        return (f"PIController(rtol={self.rtol!r}, atol={self.atol!r}, dt0={self.dt0!r}, icoeff={self.icoeff!r}, "
                f"pcoeff={self.pcoeff!r})")

    def dt_min(self, span) -> float:
        # the default never exceeds a given dt_max: on a long interval (t1 - t0 = 1e5, dt_max=1e-5) span · 2^-30 did,
        # and the steps were silently held at that dt_min, above dt_max
        return self._dt_min if self._dt_min is not None else min(span * 2.0 ** -30, self.dt_max(span))

    def dt_max(self, span) -> float:
        return min(self._dt_max, span) if self._dt_max is not None else span

    def init(self, t0, t1, lanes, error_order):
        span = t1 - t0
        h = min(self.dt0 if self.dt0 is not None else span / 64, self.dt_max(span))
        return {"h": np.full(lanes, h), "r_prev": np.ones(lanes), "rejected": np.zeros(lanes, dtype=bool),
                "q": float(error_order), "span": span}

    def error_ratio(self, y, y_new, y_err, h, span):
        scale = self.atol + self.rtol * np.maximum(np.abs(y), np.abs(y_new))
        ms = np.add.reduce((y_err / scale) ** 2, axis=-1) / y.shape[-1]    # np.mean's sum and division, unwrapped
        return np.sqrt(ms) * np.sqrt(span / h)

    def adapt(self, state, t, h, r):
        r, h = (np.ascontiguousarray(v, dtype=np.float64).reshape(-1) for v in (r, h))
        if not r.size == h.size == state["h"].size:          # the kernel writes the state in place, unchecked
            raise ValueError(f"adapt needs one step h and one error ratio r per lane of the state ({state['h'].size}), "
                             f"got {h.size} and {r.size}; pass arrays of shape (lanes,) as init(t0, t1, lanes, ...) made.")
        accept = np.empty(r.size, dtype=bool)
        span = state["span"]
        _pi_adapt_nb(r, h, state["h"], state["r_prev"], state["rejected"], accept, state["q"], self.safety,
                     self.icoeff, self.pcoeff, self.factor_min, self.factor_max, self.dt_min(span), self.dt_max(span))
        return accept


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _pi_adapt_nb(r, h, h_next, r_prev, rejected, accept, q, safety, icoeff, pcoeff, factor_min, factor_max, dt_min,
                 dt_max):
    """:meth:`PIController.adapt` per lane: accept ``r <= 1``; the next step ``h · f`` (within ``[dt_min, dt_max]``)
    with ``f = safety · r^(-(β_I + β_P)/q) · r_prev^(β_P/q)`` within ``[factor_min, factor_max]`` (``factor_max``
    1 right after a rejection; ``factor_min`` for a NaN or infinite ratio); ``r`` is kept as ``r_prev`` if
    accepted. Compiling: about 0.2 s (first adaptive solve, empty cache)."""
    for k in range(r.size):
        a = r[k] <= 1.0
        rr = max(math.inf if r[k] != r[k] else r[k], 1e-10)
        if rr == math.inf:
            f = factor_min
        else:
            f = safety * rr ** (-(icoeff + pcoeff) / q) * r_prev[k] ** (pcoeff / q)
            f = min(factor_max if a and not rejected[k] else 1.0, max(factor_min, f))
        if a:
            r_prev[k] = rr
        rejected[k] = not a
        h_next[k] = min(dt_max, max(dt_min, h[k] * f))
        accept[k] = a


# The loop's checks of a controller's answers, where it reads them (contract items 2-5): a controller written by a
# user gets a message naming the item it broke, never a bare KeyError, a silent broadcast or a crawl.

def _one_each(value, n, dtype, what):
    """``value`` as a contiguous ``(n,)`` array of ``dtype`` for the compiled bookkeeping (no bounds checks there):
    one entry for all is repeated, as numpy broadcast it; another count is refused, naming ``what``."""
    v = np.asarray(value, dtype=dtype)
    if v.shape == (n,) and v.flags.c_contiguous:
        return v
    if v.size != 1:
        raise ValueError(f"{what} has {v.size} entries for {n} lane(s) or member(s); give one each, shape ({n},), "
                         f"or one for all.")
    return np.full(n, v.reshape(-1)[0], dtype=dtype)


def _checked_init(control, t0, t1, lanes, error_order):
    """``(state, dt_min, dt_max)``: ``control.init``'s state, holding ``"h"`` (item 2), ``dt_min`` a finite number
    ``>= 0``, at most ``dt_max``, and ``dt_max`` long enough for ``max_steps`` to reach ``t1`` (item 5)."""
    name, T = type(control).__name__, t1 - t0
    state = control.init(t0, t1, lanes, error_order)
    if not isinstance(state, dict) or "h" not in state:     # else a bare KeyError or TypeError in the loop
        raise TypeError(f"{name}.init returned {type(state).__name__}"
                        f"{' without the key h' if isinstance(state, dict) else ''}; it must return a fresh dict "
                        f"holding at least 'h', the first step of each of the {lanes} lane(s) (contract item 2).")
    dt_min = control.dt_min(T)
    if isinstance(dt_min, (bool, np.bool_)) or not isinstance(dt_min, (numbers.Real, np.floating, np.integer)) \
            or not 0 <= dt_min < math.inf:         # the loop's smallest cell count is ceil(dt_min / cell)
        raise ValueError(f"{name}.dt_min({T!r}) returned {dt_min!r}; the smallest step must be a finite number >= 0 "
                         f"(contract item 5; StepController's default is span * 2**-30).")
    dt_max = control.dt_max(T)
    if not dt_min <= dt_max:                  # the steps would be held at dt_min, above dt_max, silently
        raise ValueError(f"{name}: dt_min({T!r}) = {float(dt_min)!r} exceeds dt_max({T!r}) = {dt_max!r} on the tree's "
                         f"[t0, t1] = [{t0}, {t1}] (dt_max is at most t1 - t0); pass dt_min <= dt_max.")
    if not (dt_max > 0 and T / dt_max <= control.max_steps):  # else a crawl to max_steps, blamed on the tolerance
        raise ValueError(f"{name}: dt_max({T!r}) = {dt_max!r} needs at least "
                         f"{T / dt_max if dt_max > 0 else math.inf:.3g} steps on the tree's [t0, t1] = [{t0}, {t1}], "
                         f"more than max_steps = {control.max_steps} (the most attempts of a lane); raise dt_max or "
                         f"max_steps.")
    return state, float(dt_min), float(dt_max)


def _checked_steps(control, state, live, t0, i, span, L):
    """``state["h"]`` as ``(lanes,)`` floats, each step of a ``live`` lane finite and ``> 0``; a schedule's step
    (not adaptive) at least 8 cells of the tree's grid (``span · 2^-L``), which its snapping moves by at most 1/16
    (a shorter one was silently rounded, to 2 cells at least). ``t0 + i · cell`` are the lanes' times."""
    name, cell = type(control).__name__, span / (1 << L)
    h = state["h"] = _one_each(state["h"], live.size, np.float64, f'the step control\'s state["h"] ({name})')
    # the snapping kernel takes log2(span / h): NaN, 0 or < 0 there gave one step to t1 or a division by zero
    if not (h.min() > 0 and h.max() < math.inf) and (bad := live & ~((h > 0) & (h < math.inf))).any():
        k = int(np.argmax(bad))
        raise ValueError(f'the step control\'s state["h"] ({name}) holds the step {h[k]!r} for lane {k} at t = '
                         f"{t0 + int(i[k]) * cell:.6g}; a step must be a finite number > 0 (t1 - t0 = {span!r} for "
                         f"one step to the end): fix the controller's init or adapt.")
    if not control.adaptive and (live & (h < 8 * cell)).any():
        k = int(np.argmax(live & (h < 8 * cell)))
        need = min(62, L + max(1, math.ceil(math.log2(8 * cell / h[k]))))
        raise ValueError(f"{name} proposes the step {h[k]!r} (lane {k}), shorter than 8 cells of the tree's grid "
                         f"((t1 - t0)·2^-{L} = {cell:.3g}), whose step ends it would move by more than 1/16 of the "
                         f"step (to 2 cells at least); build the BrownianTree with resolution={need} or more, or take "
                         f"steps of at least {8 * cell:.3g}.")
    return h


def _checked_ratios(control, err, m, adaptive):
    """``error_ratio``'s result for ``m`` members as ``(m,)`` floats (item 3); ``None`` only without estimate."""
    if err is None and adaptive:       # read as 'no estimate': every step accepted at zero error, silently
        raise TypeError(f"{type(control).__name__}.error_ratio returned None; an adaptive controller must return the "
                        f"error ratio of each member (contract item 3), e.g. an array of shape ({m},).")
    return None if err is None else _one_each(err, m, np.float64, f"{type(control).__name__}.error_ratio's result")


def _checked_verdict(control, state, t, h, r):
    """``control.adapt``'s verdict on the attempts ``[t, t + h]`` as a fresh ``(lanes,)`` bool array (item 4);
    the controller gets copies, and may keep what it returns (the loop writes its copy)."""
    verdict = control.adapt(state, t.copy(), h.copy(), None if r is None else r.copy())
    if verdict is None:            # np.asarray(None, bool) is False: every attempt rejected until max_steps
        raise TypeError(f"{type(control).__name__}.adapt returned None; it must return whether each lane's attempt is "
                        f"accepted (contract item 4), e.g. np.ones(lanes, dtype=bool) for a schedule.")
    return _one_each(verdict, t.size, bool, f"{type(control).__name__}.adapt's result").copy()
