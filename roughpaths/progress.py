r"""Progress and time left for long work: the one meaning of ``progress=`` in both packages.

:func:`~roughpaths.solve` (fixed steps and adaptive steps) and :func:`mechanics.run_ensemble` take
``progress=``, with the same values everywhere:

* ``None`` or ``False`` (the default): silent. No reporter is made, and the loops test one ``None``.
* ``True``: a bar on standard error, drawn by ``tqdm`` if it is importable (the optional extra
  ``pip install 'roughpaths-mechanics[progress]'``; never required), else a plain line updated in place
  (``\r``), redrawn at most every 0.2 s and at the end.
* a callable: called once per unit of progress with a :class:`ProgressRecord` ``(done, total, elapsed,
  eta)``; an exception it raises stops the work and propagates (a way to cancel).

What ``done`` counts is the caller's (each documents it): steps of every batch member for ``solve`` on a
grid (per block of steps), the time reached since ``t0`` for adaptive steps (per accepted step), paths for
``run_ensemble`` (per chunk). ``done`` never decreases and the last report has ``done == total``.
Reporting reads the results, never changes them.

The time left is the linear extrapolation ``eta = elapsed · (total − done) / (done − initial)``, where
``initial`` is the work already done when the reporter started (e.g. the chunks a resumed
``run_ensemble`` takes from its checkpoint): finite in every report, ``0`` at the end.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Callable, NamedTuple

import numpy as np

__all__ = ["ProgressRecord", "Progress", "progress_reporter"]

#: Fewest seconds between two redraws of the plain line (the last report is always drawn).
REDRAW_INTERVAL = 0.2


class ProgressRecord(NamedTuple):
    """One report of long work, passed to a ``progress=`` callable.

    Attributes
    ----------
    done : float
        Work done so far (in the caller's unit: steps, time or paths); never decreases.
    total : float
        Work in all; the last report has ``done == total``.
    elapsed : float
        Seconds since the work started (``time.perf_counter``).
    eta : float
        Estimated seconds left, ``elapsed · (total − done) / (done − initial)``; ``0.0`` at the end.
    """

    done: float
    total: float
    elapsed: float
    eta: float


def _number(x: float) -> str:
    """A count as an integer (12000, not 1.2e+04), anything else to 4 significant digits."""
    return f"{x:.0f}" if x.is_integer() else f"{x:.4g}"


def _clock(seconds: float) -> str:
    if not math.isfinite(seconds):
        return "?"
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    return f"{hours}:{rest // 60:02d}:{rest % 60:02d}" if hours else f"{rest // 60:02d}:{rest % 60:02d}"


class Progress:
    """A running report of one piece of long work; made by :func:`progress_reporter`.

    Parameters
    ----------
    sink : callable or None
        Called with each :class:`ProgressRecord`; ``None`` draws a bar (``tqdm`` if importable, else a
        plain line on ``sys.stderr``).
    total : float
        Work in all (``>= 0``, finite).
    desc : str
        What is running, shown in front of the bar.
    unit : str
        What ``done`` counts, shown after the numbers.
    initial : float
        Work already done when the reporter starts (``0 <= initial <= total``).

    Examples
    --------
    >>> seen = []
    >>> report = Progress(seen.append, 4.0, desc="demo", unit="steps")
    >>> for done in (1, 3, 4):
    ...     report.update(done)
    >>> report.close()
    >>> [(r.done, r.total) for r in seen], all(r.eta >= 0 for r in seen), seen[-1].eta
    ([(1.0, 4.0), (3.0, 4.0), (4.0, 4.0)], True, 0.0)
    """

    def __init__(self, sink: Callable | None, total: float, *, desc: str, unit: str, initial: float = 0.0):
        total, initial = float(total), float(initial)
        if not (math.isfinite(total) and total >= 0.0):
            raise ValueError(f"total must be finite and >= 0, got {total!r}.")
        if not 0.0 <= initial <= total:
            raise ValueError(f"initial must lie in [0, total] = [0, {total!r}], got {initial!r}.")
        self.total, self.initial, self.desc, self.unit = total, initial, desc, unit
        self.done = initial
        self._sink = sink
        self._bar = None
        self._width = 0
        self._drawn = -math.inf
        self._closed = False
        self._start = time.perf_counter()
        if sink is None:
            try:
                from tqdm import tqdm
            except ImportError:
                self._line()
            else:
                self._bar = tqdm(total=total, initial=initial, desc=desc, unit=unit, file=sys.stderr,
                                 unit_scale=True, bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                                                             "{n_fmt}/{total_fmt} {unit} [{elapsed}<{remaining}]")

    def record(self) -> ProgressRecord:
        """The report of the work done so far."""
        elapsed = time.perf_counter() - self._start
        left = self.total - self.done
        if left <= 0.0:
            eta = 0.0
        elif self.done > self.initial:
            eta = elapsed * left / (self.done - self.initial)
        else:
            eta = math.inf
        return ProgressRecord(self.done, self.total, elapsed, eta)

    def update(self, done: float) -> None:
        """Report that ``done`` (a cumulative count, not an increment) of the work is finished."""
        done = min(float(done), self.total)
        step, self.done = done - self.done, done
        if self._sink is not None:
            self._sink(self.record())
        elif self._bar is not None:
            self._bar.update(step)
        else:
            self._line()

    def _line(self, final: bool = False) -> None:
        now = time.perf_counter()
        if not final and self.done < self.total and now - self._drawn < REDRAW_INTERVAL:
            return
        self._drawn = now
        r = self.record()
        pct = 100.0 * r.done / r.total if r.total > 0 else 100.0
        text = (f"{self.desc}: {pct:3.0f}% {_number(r.done)}/{_number(r.total)} {self.unit} "
                f"[{_clock(r.elapsed)} elapsed, {_clock(r.eta)} left]")
        pad = max(0, self._width - len(text))
        self._width = len(text)
        sys.stderr.write("\r" + text + " " * pad + ("\n" if final else ""))
        sys.stderr.flush()

    def close(self) -> None:
        """End the report: close the bar (or end the plain line); a callable is not called again."""
        if self._closed:
            return
        self._closed = True
        if self._bar is not None:
            self._bar.close()
        elif self._sink is None:
            self._line(final=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def progress_reporter(progress, total, *, desc: str, unit: str, initial=0.0) -> Progress | None:
    """The reporter for a ``progress=`` argument, or ``None`` when it asks for silence.

    Parameters
    ----------
    progress : None, bool or callable
        ``None``/``False``: silent (returns ``None``); ``True``: a bar on standard error (``tqdm`` if
        importable, else a plain line); a callable: called with a :class:`ProgressRecord` per report.
    total : float
        Work in all (finite, ``>= 0``), in the unit ``unit``.
    desc, unit : str
        Shown in the bar: what runs and what ``done`` counts.
    initial : float
        Work already done at the start (e.g. taken from a checkpoint).

    Returns
    -------
    Progress or None

    Raises
    ------
    TypeError
        ``progress`` is none of ``None``, ``False``, ``True`` or a callable.

    Examples
    --------
    >>> progress_reporter(None, 10, desc="solve", unit="steps") is None
    True
    >>> progress_reporter(1, 10, desc="solve", unit="steps")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    TypeError: progress must be None, False, True or a callable taking a ProgressRecord, got 1 (int); ...
    """
    if isinstance(progress, np.bool_):
        progress = bool(progress)
    if progress is None or progress is False:
        return None
    if progress is True:
        return Progress(None, total, desc=desc, unit=unit, initial=initial)
    if callable(progress):
        return Progress(progress, total, desc=desc, unit=unit, initial=initial)
    raise TypeError(f"progress must be None, False, True or a callable taking a ProgressRecord, got {progress!r} "
                    f"({type(progress).__name__}); use progress=True for a bar or progress=print for the records.")
