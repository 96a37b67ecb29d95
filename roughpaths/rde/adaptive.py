r"""Adaptive steps on a :class:`~roughpaths.BrownianTree`: :class:`PIController` and the loop behind ``solve``.

``solve(fields, tree, y0, solver, step_control=PIController(rtol, atol))`` integrates on ``[tree.t0,
tree.t1]`` with steps chosen from an error estimate. The tree answers the increment and area on any
interval, so a rejected step asks the same tree again on a shorter interval: the Brownian path is fixed
by the seed, and rejection introduces no bias (no resampling, no conditioning on the rejection).

The error estimate (step doubling)
----------------------------------
An attempt on ``[t, t + h]`` takes one step of the solver over the whole interval, ``y_1``, and two over
its halves, ``y_2``, with the increments and areas of the same tree (the whole step's are the Chen product
of the halves', so both see the same path). The local error of an order-1 scheme on non-commuting noise is
its missing level-3 term, of size :math:`h^{3/2}`; ``y_2 - y_1`` is of that size and estimates it. The
two-step value ``y_2`` is kept. Random local errors add in mean square, so ``N = T/h`` steps of local
error :math:`\epsilon` give a global error :math:`\sqrt{T/h}\,\epsilon`; the controller therefore bounds

.. math:: r = \sqrt{\tfrac{T}{h}}\;\max_{\text{members}}\Bigl(\tfrac1e\sum_a
          \Bigl(\frac{y_2^a - y_1^a}{\mathrm{atol} + \mathrm{rtol}\max(|y^a|, |y_2^a|)}\Bigr)^2\Bigr)^{1/2}
          \le 1,

the predicted global error in units of the tolerance (``T = t1 - t0``). Since :math:`r \propto h`, the
steps shrink in proportion to the tolerance and the strong error of an order-1 scheme is proportional to
``rtol`` (an error-per-step rule, :math:`\epsilon \le \mathrm{tol}`, would give ``rtol^(2/3)``).
The steps are shared by the batch: the norm is the maximum over its members (for steps of its own,
solve member ``i`` on ``tree.select([i])``, which answers bitwise as member ``i`` does).

The step size
-------------
The next step is :math:`h\,\min(f_{\max}, \max(f_{\min}, s\,r_n^{-(\beta_I + \beta_P)}\,r_{n-1}^{\beta_P}))`
(``safety`` ``s``, ``icoeff`` :math:`\beta_I`, ``pcoeff`` :math:`\beta_P`; :math:`f_{\max} = 1` right
after a rejection). Step ends are snapped to the dyadic grid of spacing at most ``h/8`` (a relative change
of at most 1/16), so a query walks only about :math:`\log_2(T/h) + 4` levels of the tree. Save times and
``t1`` are never stepped over.

What is exact and what is approximate
-------------------------------------
Exact: the increments and areas of every attempt come from the tree (Chen's identity between a step and
its halves to round-off); the answer depends only on the tree's seed, ``y0`` and the controller. The step
sizes depend on the path (they are not stopping times of the Brownian filtration); this is the usual
setting of pathwise adaptive schemes and, with a fixed path, costs no bias. Approximate: the law of the
tree itself (see :mod:`roughpaths.drivers.tree`); the error estimate (of the right size, not a bound).
"""

from __future__ import annotations

import contextlib
import math
import time as _time

import numpy as np

from ..progress import progress_reporter
from ..validation import check_memory, check_positive_int, check_positive_real
from .base import Solver
from .solution import NonFiniteStateError, Solution, _failure_message

__all__ = ["PIController"]


class PIController:
    r"""Adaptive step sizes for :func:`~roughpaths.solve` on a :class:`~roughpaths.BrownianTree`.

    Parameters
    ----------
    rtol, atol : float
        Relative and absolute tolerances (``rtol >= 0``, ``atol >= 0``, not both 0). They bound the
        *predicted global* error (module docstring): the strong error of an order-1 scheme is about
        proportional to them.
    dt0 : float, optional
        First step tried (default ``(t1 - t0) / 64``).
    dt_min : float, optional
        Smallest step (default ``(t1 - t0) · 2^-30``). A step at ``dt_min`` whose error still exceeds the
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
        Integral and proportional exponents :math:`\beta_I`, :math:`\beta_P` (defaults 0.7 and 0.3). The
        error ratio is proportional to the step, so :math:`\beta_I + \beta_P = 1` is the dead-beat sum;
        ``icoeff=1, pcoeff=0`` is the plain integral controller (``docs/adaptive-steps.md`` compares them).
    max_steps : int
        Most attempts (accepted plus rejected) before ``solve`` gives up with a ``ValueError`` (default
        10⁵): a bound on the work of tolerances that can be met (one that cannot fails at ``dt_min``).

    Examples
    --------
    >>> import numpy as np
    >>> import roughpaths as rp
    >>> M = np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])
    >>> tree = rp.BrownianTree(2, seed=0, batch_shape=(4,))
    >>> sol = rp.solve(rp.LinearVectorFields(M), tree, np.ones(2), rp.Davie(),
    ...                step_control=rp.PIController(rtol=1e-2, atol=1e-2), save_at="end")
    >>> sol.final.shape, sol.stats["accepted"] > 0, float(sol.times[-1])
    ((4, 2), True, 1.0)
    """

    def __init__(self, rtol, atol, dt0=None, *, dt_min=None, dt_max=None, safety=0.8, factor_min=0.2,
                 factor_max=5.0, icoeff=0.7, pcoeff=0.3, max_steps=100_000):
        self.rtol = check_positive_real(rtol, "rtol", allow_zero=True)
        self.atol = check_positive_real(atol, "atol", allow_zero=True)
        if self.rtol == 0.0 and self.atol == 0.0:
            raise ValueError("rtol and atol are both 0: no error can be met; give a positive tolerance, e.g. "
                             "PIController(rtol=1e-3, atol=1e-6).")
        self.dt0 = None if dt0 is None else check_positive_real(dt0, "dt0")
        self.dt_min = None if dt_min is None else check_positive_real(dt_min, "dt_min")
        self.dt_max = None if dt_max is None else check_positive_real(dt_max, "dt_max")
        if self.dt_min is not None and self.dt_max is not None and self.dt_min > self.dt_max:
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

    def _factor(self, r, r_prev, after_reject):
        """Ratio of the next step to this one, from the error ratios ``r`` (this step) and ``r_prev``."""
        if not math.isfinite(r):
            return self.factor_min
        r = max(r, 1e-10)
        f = self.safety * r ** -(self.icoeff + self.pcoeff) * max(r_prev, 1e-10) ** self.pcoeff
        hi = 1.0 if after_reject else self.factor_max
        return min(hi, max(self.factor_min, f))


def _areas(W, A):
    """Stratonovich areas ``A + ½ W ⊗ W`` from increments ``W (..., d)`` and Lévy areas ``A (..., d, d)``."""
    return A + 0.5 * W[..., :, None] * W[..., None, :]


def _whole_step(W, XX):
    """Increment and area of a step from those of its halves ``W (..., 2, d)``, ``XX (..., 2, d, d)``, by Chen:
    ``X = X_1 + X_2``, ``XX = XX_1 + XX_2 + X_1 ⊗ X_2``; shapes ``(..., 1, d)`` and ``(..., 1, d, d)``."""
    W1, W2 = W[..., 0, :], W[..., 1, :]
    XXw = XX[..., 0, :, :] + XX[..., 1, :, :] + W1[..., :, None] * W2[..., None, :]
    return (W1 + W2)[..., None, :], XXw[..., None, :, :]


def _unmet_message(unmet, batch, t, h, r, control):
    """The message of a step at ``dt_min`` whose error exceeds the tolerance (``on_failure="raise"``)."""
    first = tuple(int(v) for v in np.argwhere(unmet)[0])
    return (f"the error tolerance cannot be met: the step [{t:.6g}, {t + h:.6g}] at dt_min = {h:.3g} still has "
            f"{r:.3g} times the error {control!r} allows, for {int(unmet.sum())} batch member(s) (first {first}); "
            f"loosen rtol/atol, lower dt_min (PIController(dt_min=...)), or pass on_failure='mask' to mark these "
            f"members failed (Solution.failed) and finish the others.")


def solve_adaptive(fields, tree, y, solver: Solver, control: PIController, save_at, on_failure, batch, progress=None):
    """The adaptive loop of :func:`~roughpaths.solve` (arguments already checked there; ``y`` broadcast).
    ``progress`` reports the time reached, ``t - t0`` of ``t1 - t0``, after every accepted step."""
    if not isinstance(control, PIController):
        raise TypeError(f"step_control must be a roughpaths.PIController, got {type(control).__name__}; "
                        f"e.g. step_control=PIController(rtol=1e-3, atol=1e-6).")
    if solver.order < 1.0 or solver.increment_level < 2:
        raise ValueError(f"adaptive steps assume a strong order-1 scheme that uses the area (the error estimate "
                         f"and the step rule are built for it), got {solver!r} (order {solver.order}); use "
                         f"Davie(), LogODE() or a coadjoint LieHeun().")
    L, t0, t1 = tree.resolution, tree.t0, tree.t1
    T = t1 - t0
    n_cells = 1 << L
    cell = T / n_cells
    end = n_cells
    # targets: the grid indices of the save times (the loop never steps over them) and t1
    if isinstance(save_at, str):
        if save_at not in ("all", "end"):
            raise ValueError(f"save_at must be 'all', 'end' or an array of times in [t0, t1], got {save_at!r}.")
        targets = [end]
    else:
        st = np.asarray(save_at, dtype=np.float64).ravel()
        if st.size == 0 or not np.all(np.isfinite(st)) or st.min() < t0 or st.max() > t1:
            raise ValueError(f"save_at times must be finite and lie in the tree's [t0, t1] = [{t0}, {t1}], got "
                             f"{save_at!r}.")
        snapped = {min(int(round((v - t0) / T * n_cells)), end) for v in st}
        marks = np.array(sorted(snapped | {0, end}))
        if np.any(np.diff(marks) < 2):
            raise ValueError(f"save_at has times closer than two cells of the tree's grid ((t1 - t0)·2^-{L - 1}) to "
                             f"each other or to t0, t1; a step between them cannot be halved. Drop the near "
                             f"duplicates.")
        targets = sorted(snapped - {0} | {end})
    save_all = isinstance(save_at, str) and save_at == "all"
    save_idx = ({end} if save_at == "end" else set()) if isinstance(save_at, str) else snapped
    dt_min = control.dt_min if control.dt_min is not None else T * 2.0 ** -30
    dt_max = min(control.dt_max, T) if control.dt_max is not None else T
    h = min(control.dt0 if control.dt0 is not None else T / 64, dt_max)
    min_cells = max(2, int(math.ceil(dt_min / cell)))
    e = y.shape[-1]
    members = int(np.prod(batch, dtype=np.int64))

    saved_t = [t0] if (save_all or 0 in save_idx) else []
    saved_y = [y.copy()] if saved_t else []
    failed_step = np.full(batch, -1, dtype=np.int64)
    healthy = np.ones(batch, dtype=bool)
    i, k_target, t_acc = 0, 0, [t0]
    accepted = rejected = at_min = 0
    r_prev, after_reject = 1.0, False
    t_start = _time.perf_counter()
    no_save = np.zeros(2, dtype=bool)
    report = progress_reporter(progress, T, desc="solve (adaptive)", unit="time")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"), (report or contextlib.nullcontext()):
        while i < end:
            if accepted + rejected >= control.max_steps:
                raise ValueError(f"adaptive solve took {control.max_steps} attempts and reached t = "
                                 f"{t0 + i * cell:.6g} of [{t0}, {t1}] ({accepted} accepted, {rejected} rejected); "
                                 f"loosen rtol/atol or raise PIController(max_steps=...).")
            while targets[k_target] <= i:
                k_target += 1
            target = targets[k_target]
            # snap the step end to a dyadic grid of spacing <= h/8, never past the next target
            depth = min(L, max(0, int(math.ceil(math.log2(T / h))) + 3))
            unit = 1 << (L - depth)
            j = int(round((i + h / cell) / unit)) * unit
            j = max(j, i + min_cells, (i // unit + 1) * unit)
            if j >= target or target - j < min_cells:
                j = target
            at_floor = (j - i) <= min_cells or (j - i) * cell <= dt_min * (1 + 1e-12)
            ts = t0 + cell * np.array([i, (i + j) // 2, j], dtype=np.float64)
            W, A = tree.increments_and_levy_areas(ts)
            W, XX = np.broadcast_to(W, batch + W.shape[-2:]), np.broadcast_to(_areas(W, A), batch + A.shape[-3:])
            y2, _, _ = solver.integrate(fields, y, ts, W, XX, no_save, stop_on_failure=False)
            y1, _, _ = solver.integrate(fields, y, ts[[0, 2]], *_whole_step(W, XX), no_save[:1],
                                        stop_on_failure=False)
            hstep = (j - i) * cell
            scale = control.atol + control.rtol * np.maximum(np.abs(y), np.abs(y2))
            err = np.sqrt(np.mean(((y2 - y1) / scale) ** 2, axis=-1))
            bad = ~np.all(np.isfinite(y2), axis=-1) & healthy
            ok = healthy & ~bad
            err = err * math.sqrt(T / hstep)
            r = float(err[ok].max()) if ok.any() else 0.0
            if bad.any():
                r = math.inf
            if at_floor and not r <= 1.0:           # the tolerance cannot be met at dt_min: fail, never crawl
                unmet = ok & ~(err <= 1.0)
                at_min += int(unmet.sum())
                if on_failure == "raise" and unmet.any():
                    raise ValueError(_unmet_message(unmet, batch, ts[0], hstep, float(np.max(err[unmet])), control))
                failed_step[unmet] = accepted
                healthy &= ~unmet
                r = math.inf if bad.any() else float(np.max(err[ok & healthy], initial=0.0))
            if r <= 1.0 or at_floor:
                accepted += 1
                if bad.any():
                    failed_step[bad] = accepted - 1
                    if on_failure == "raise":
                        msg, mem, steps = _failure_message(failed_step, np.array(t_acc + [ts[2]]), batch)
                        raise NonFiniteStateError(msg, mem, steps)
                    healthy &= ~bad
                y = np.where(healthy[..., None], y2, np.nan)
                i = j
                t_acc.append(t0 + i * cell if i < end else t1)
                if save_all or i in save_idx:
                    saved_t.append(t_acc[-1])
                    saved_y.append(y.copy())
                    if len(saved_t) & (len(saved_t) - 1) == 0:       # at every doubling: the budget read is slow
                        check_memory(16.0 * members * e * len(saved_t), f"the saved states ({len(saved_t)} times "
                                     f"so far, and growing)", "save fewer times (save_at='end' or an array of times)")
                f = control._factor(r, r_prev, after_reject)
                r_prev, after_reject = max(r, 1e-10), False
                if report is not None:
                    report.update(i * cell)        # exact: cell = T / 2^L, and end * cell == T
            else:
                rejected += 1
                f = control._factor(r, r_prev, True)
                after_reject = True
            h = min(dt_max, max(dt_min, hstep * f))
    stats = {"solver": repr(solver), "step_control": repr(control), "n_steps": accepted, "accepted": accepted,
             "rejected": rejected, "at_dt_min": at_min, "batch_shape": batch,
             "wall_time": _time.perf_counter() - t_start}
    states = np.stack(saved_y, axis=-2) if saved_y else np.empty(batch + (0, e))
    return Solution(times=np.array(saved_t), states=states, failed_step=failed_step, stats=stats)
