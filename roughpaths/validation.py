"""Input checks shared by every public function of ``roughpaths`` and ``mechanics``.

This module is public to the two packages (``from roughpaths.validation import ...``); it is the one
place where argument checks live, so that a mistake gets the same kind of message everywhere.

Every check raises a ``TypeError`` (wrong kind of object) or ``ValueError`` (wrong value) whose
message names the argument, shows the offending value or shape, and says how to fix it.
"""

from __future__ import annotations

import numbers

import numpy as np

from ._threads import parallel_ranges

__all__ = [
    "parallel_ranges",
    "as_float_array",
    "check_times",
    "check_antisymmetric",
    "check_rng",
    "check_seed",
    "check_positive_int",
    "check_positive_real",
    "check_real",
    "check_batch_shape",
    "check_same_batch",
    "check_memory",
    "memory_budget",
    "recorded_memory_estimates",
    "check_work",
    "work_budget",
    "arrays_equal",
]


def check_seed(seed) -> np.random.SeedSequence:
    """``seed`` as a ``SeedSequence``: an int ``>= 0`` or a ``SeedSequence`` (as is); a ``Generator`` is refused with the
    reason (the results would depend on what it drew before), anything else names ``seed`` and what it takes."""
    if isinstance(seed, np.random.SeedSequence):
        return seed
    if isinstance(seed, numbers.Integral) and not isinstance(seed, bool):
        if seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed}.")
        return np.random.SeedSequence(int(seed))
    if isinstance(seed, np.random.Generator):
        raise TypeError("seed must be an int or a numpy.random.SeedSequence, got a Generator: a Generator's "
                        "state would make the paths depend on what was drawn before. Pass seed=<int>.")
    raise TypeError(f"seed must be an int >= 0 or a numpy.random.SeedSequence, got {type(seed).__name__}.")


def arrays_equal(a, b) -> bool:
    """``True`` if ``a`` and ``b`` are both None, or arrays of the same shape with equal entries (NaN equal to
    NaN): the equality of results saved and loaded (``==`` on ``RoughPath``, ``Solution``, ``EnsembleResult``)."""
    if a is None or b is None:
        return a is None and b is None
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=a.dtype.kind == "f"))


def _describe(x) -> str:
    if isinstance(x, np.ndarray):
        return f"array of shape {x.shape} and dtype {x.dtype}"
    text = repr(x)
    return text if len(text) <= 60 else text[:57] + "..."


def _framework_fix(x, name: str) -> str:
    """The fix for an array that numpy cannot read: a torch tensor in a graph or a JAX tracer asks for the
    differentiable front end (``.detach().numpy()`` alone, which torch proposes, would silently drop the gradient)."""
    module = type(x).__module__.split(".")[0]
    if module == "torch":
        return (f"the numpy API does not differentiate: for a gradient call the roughpaths.torch function of the "
                f"same name (signatures, transforms, kernels), for values only pass {name}.detach().numpy().")
    if module in ("jax", "jaxlib"):
        return ("the numpy API cannot run inside jax.jit, grad or vmap: call the roughpaths.jax function of the same "
                "name (signatures, transforms, kernels), or call this one outside the transform on concrete arrays.")
    return "pass a numpy array of floats."


def as_float_array(x, name: str, *, min_ndim: int = 0, ndim: int | None = None,
                   last_dims: tuple | None = None, allow_nonfinite: bool = False) -> np.ndarray:
    """Convert ``x`` to a float64 array and check its rank, trailing shape and finiteness.

    Parameters
    ----------
    x : array_like
        Real numbers (integer or float; bool arrays count as 0/1, a lone bool is rejected); complex and
        object arrays are rejected, and so are masked arrays (``numpy.ma``: their mask would be dropped).
        Other ndarray subclasses are read as their values.
    name : str
        The argument's name, used in error messages.
    min_ndim, ndim : int, optional
        Required minimum / exact number of axes.
    last_dims : tuple of (int or None), optional
        Required sizes of the trailing axes (``None`` leaves one free).
    allow_nonfinite : bool
        If false (default) NaN and inf raise ``ValueError``.
    """
    if isinstance(x, (str, bytes)) or x is None:
        raise TypeError(f"{name} must be an array of real numbers, got {_describe(x)}; "
                        f"pass a numpy array (or nested lists) of floats.")
    if isinstance(x, (bool, np.bool_)):          # a lone True/False is a flag passed in the wrong place
        raise TypeError(f"{name} must be a real number or an array of them, got the bool {x!r}; "
                        f"pass a float.")
    if isinstance(x, np.ma.MaskedArray):         # np.asarray would drop the mask and use the values under it
        masked = int(np.count_nonzero(np.ma.getmaskarray(x)))
        raise TypeError(f"{name} is a numpy masked array with {masked} masked value(s) of {x.size}; the mask would be "
                        f"dropped and the values under it used. Fill or drop the masked points first: "
                        f"{name}.filled(value) (or interpolate them), or keep the unmasked points "
                        f"(for points along axis -2: "
                        f"{name}.data[~np.ma.getmaskarray({name}).any(axis=-1)]); with nothing masked, pass {name}.data.")
    try:
        arr = np.asarray(x)
    except Exception as exc:  # pragma: no cover - exotic inputs
        raise TypeError(f"{name} could not be converted to an array ({exc}); "
                        f"{_framework_fix(x, name)}") from None
    if arr.dtype.kind == "c":
        raise TypeError(f"{name} must be real, got a complex {_describe(arr)}; "
                        f"pass its real part (np.real) if the imaginary part is zero.")
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold real numbers, got {_describe(arr)}; "
                        f"convert it with np.asarray({name}, dtype=float).")
    arr = np.asarray(arr, dtype=np.float64)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} axes, got shape {arr.shape}.")
    if arr.ndim < min_ndim:
        hint = (f"{name}[:, None] for one path of {arr.shape[0]} points in one dimension, or {name}[None] for "
                f"one point in {arr.shape[0]} dimensions" if arr.ndim == 1 and min_ndim == 2 else f"{name}[None]")
        raise ValueError(f"{name} must have at least {min_ndim} axes, got shape {arr.shape}; "
                         f"add the missing axes (e.g. {hint}).")
    if last_dims is not None:
        k = len(last_dims)
        if arr.ndim < k:
            raise ValueError(f"{name} must have at least {k} axes, got shape {arr.shape}.")
        for want, got in zip(last_dims, arr.shape[arr.ndim - k:]):
            if want is not None and want != got:
                expect = "(..., " + ", ".join("*" if w is None else str(w) for w in last_dims) + ")"
                raise ValueError(f"{name} must have trailing shape {expect}, got shape {arr.shape}.")
    if not allow_nonfinite and arr.size and not np.all(np.isfinite(arr)):
        bad = int(np.count_nonzero(~np.isfinite(arr)))
        first = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(f"{name} contains {bad} non-finite value(s) (NaN or inf), the first at "
                         f"index {first}; remove or interpolate them before calling.")
    return arr


def check_times(times, name: str = "times", *, n: int | None = None) -> np.ndarray:
    """Check a 1-D, finite, strictly increasing time grid (of length ``n`` if given)."""
    t = as_float_array(times, name, ndim=1)
    if n is not None and t.shape[0] != n:
        raise ValueError(f"{name} must have {n} entries to match the data, got {t.shape[0]}.")
    if t.shape[0] < 2:
        raise ValueError(f"{name} needs at least 2 points, got {t.shape[0]}.")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise ValueError(f"{name} must be strictly increasing, but {name}[{k}]={t[k]!r} >= "
                         f"{name}[{k + 1}]={t[k + 1]!r}; sort the grid and drop repeated times.")
    return t


def check_antisymmetric(s, name: str = "s", *, dim: int | None = None, atol: float = 1e-12) -> np.ndarray:
    """Check that ``s`` (shape ``(..., d, d)``) is antisymmetric, to ``atol`` relative to its size."""
    arr = as_float_array(s, name, min_ndim=2)
    if arr.shape[-1] != arr.shape[-2]:
        raise ValueError(f"{name} must be square in its last two axes, got shape {arr.shape}.")
    if dim is not None and arr.shape[-1] != dim:
        raise ValueError(f"{name} must be {dim}x{dim} to match the path dimension d={dim}, "
                         f"got shape {arr.shape}.")
    sym = 0.5 * (arr + np.swapaxes(arr, -1, -2))
    scale = max(1.0, float(np.max(np.abs(arr))) if arr.size else 1.0)
    err = float(np.max(np.abs(sym))) if sym.size else 0.0
    if err > atol * scale:
        raise ValueError(f"{name} must be antisymmetric ({name}.T == -{name}); its symmetric part has "
                         f"size {err:.3g}. A symmetric perturbation of the area breaks geometricity; "
                         f"pass 0.5 * ({name} - {name}.T) if you meant its antisymmetric part.")
    return arr


def check_rng(rng, name: str = "rng") -> np.random.Generator:
    """Require an explicit ``numpy.random.Generator``."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"{name} must be a numpy.random.Generator, got {_describe(rng)}; "
                        f"pass {name}=numpy.random.default_rng(seed).")
    return rng


def check_positive_int(value, name: str, *, minimum: int = 1) -> int:
    """Check an integer ``>= minimum`` (bools rejected)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {_describe(value)}.")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}.")
    return int(value)


def check_positive_real(value, name: str, *, allow_zero: bool = False) -> float:
    """Check a finite real scalar ``> 0`` (``>= 0`` with ``allow_zero``); bools, strings, complex rejected.

    A wrong kind of object raises ``TypeError``; NaN, inf or a value out of range ``ValueError``.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.ndarray)):
        raise TypeError(f"{name} must be a real number, got {_describe(value)}; pass a float.")
    if isinstance(value, np.ndarray):
        if value.ndim != 0 or value.dtype.kind not in "iuf":
            raise TypeError(f"{name} must be a real scalar, got {_describe(value)}; pass a float.")
        value = value.item()
    v = float(value)
    bound = ">= 0" if allow_zero else "> 0"
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}.")
    return v


def check_real(value, name: str) -> float:
    """Check a finite real scalar of any sign (bools, strings, complex and arrays rejected)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
            value = value.item()
        else:
            raise TypeError(f"{name} must be a real number, got {_describe(value)}; pass a float.")
    v = float(value)
    if not np.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}.")
    return v


def check_batch_shape(batch_shape, name: str = "batch_shape") -> tuple:
    """Check a batch shape: an integer or a tuple of non-negative integers (``2.5`` or ``(2.5,)`` rejected)."""
    if isinstance(batch_shape, numbers.Integral) and not isinstance(batch_shape, (bool, np.bool_)):
        batch_shape = (batch_shape,)
    if isinstance(batch_shape, (str, bytes)):
        raise TypeError(f"{name} must be a tuple of integers, got {batch_shape!r}; pass e.g. {name}=(1000,).")
    try:
        shape = tuple(batch_shape)
    except TypeError:
        raise TypeError(f"{name} must be a tuple of integers, got {_describe(batch_shape)}; "
                        f"pass e.g. {name}=(1000,).") from None
    for n in shape:
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral):
            raise TypeError(f"{name} must be a tuple of integers, got {shape!r}; pass e.g. {name}=(1000,).")
        if n < 0:
            raise ValueError(f"{name} must hold non-negative integers, got {shape!r}.")
    return tuple(int(n) for n in shape)


def check_same_batch(shape_a: tuple, shape_b: tuple, name_a: str, name_b: str) -> tuple:
    """Broadcast two batch shapes, or raise naming both arguments."""
    try:
        return tuple(np.broadcast_shapes(tuple(shape_a), tuple(shape_b)))
    except ValueError:
        raise ValueError(f"batch shapes of {name_a} {tuple(shape_a)} and {name_b} {tuple(shape_b)} "
                         f"do not broadcast; give them the same leading axes.") from None


def memory_budget() -> int:
    """The number of bytes a single array allocation may take before it is refused.

    ``ROUGHPATHS_MAX_BYTES`` (an integer, bytes) if set; otherwise three quarters of the memory
    currently available (``MemAvailable`` on Linux, else of the physical memory), so that a request
    that would push the machine into swap or the OOM killer is refused with an estimate instead.
    """
    import os

    env = os.environ.get("ROUGHPATHS_MAX_BYTES")
    if env:
        try:
            value = int(float(env))
        except ValueError:
            raise ValueError(f"ROUGHPATHS_MAX_BYTES must be a number of bytes, got {env!r}.") from None
        if value <= 0:
            raise ValueError(f"ROUGHPATHS_MAX_BYTES must be positive, got {env!r}.")
        return value
    avail = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except OSError:
        pass
    if avail is None:
        try:
            avail = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (ValueError, OSError, AttributeError):
            avail = 8 * 2**30
    return int(0.75 * avail)


def _human(nbytes: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if nbytes >= size:
            return f"{nbytes / size:.3g} {unit}"
    return f"{nbytes:.0f} B"


class _Recorders:
    """The lists that :func:`recorded_memory_estimates` collects into (innermost last), per thread."""

    def __init__(self):
        import threading

        self._local = threading.local()

    @property
    def stack(self) -> list:
        st = getattr(self._local, "stack", None)
        if st is None:
            st = self._local.stack = []
        return st


_RECORDERS = _Recorders()


class recorded_memory_estimates:  # noqa: N801 (a context manager used like a function)
    """Collect every estimate that :func:`check_memory` receives inside a ``with`` block.

    The estimates a call checks are the ones that would refuse it; collecting them lets a test compare
    them with what the call really allocates (``tests/test_memory_estimates.py``), so that the number
    that refuses a request is the number that is tested. Each entry is ``(nbytes, what)``; entries are
    collected whether or not they fit the budget (a refused call raises after its entry is recorded).
    Blocks nest (each collects what happens inside it) and are per thread.

    Examples
    --------
    >>> with recorded_memory_estimates() as est:
    ...     check_memory(8.0 * 1000, "a vector of 1000 floats", "use fewer")
    >>> est.total, est.entries[0][1]
    (8000.0, 'a vector of 1000 floats')
    """

    def __init__(self):
        self.entries: list = []

    @property
    def total(self) -> float:
        """The sum of the collected estimates, in bytes."""
        return float(sum(nbytes for nbytes, _ in self.entries))

    def __enter__(self):
        _RECORDERS.stack.append(self)
        return self

    def __exit__(self, *exc):
        _RECORDERS.stack.remove(self)
        return False

    def __repr__(self) -> str:
        return f"recorded_memory_estimates(total={_human(self.total)}, entries={len(self.entries)})"


def check_memory(nbytes, what: str, fix: str, *, max_bytes=None) -> None:
    """Refuse, before allocating, a request of ``nbytes`` bytes above the budget.

    The one door for sizes: every constructor and call that allocates in proportion to its arguments
    estimates the bytes it is about to hold and passes the estimate here before it allocates, so that a
    request that cannot fit is refused at once with the estimate in the message (instead of swapping, an
    out-of-memory kill, or a hang). The estimate covers the arrays the call holds at its peak (the result
    and its working arrays); :func:`recorded_memory_estimates` collects the estimates a call makes, and
    the test of the library compares them with the measured peak.

    Parameters
    ----------
    nbytes : int or float
        The estimated size (compute it in floating point so it cannot overflow); NaN is refused too.
    what : str
        What would be allocated, e.g. ``"the saved states (1000 paths x 10001 times x 3)"``.
    fix : str
        How to stay within the budget, e.g. ``"save fewer times (save_at='end')"``.
    max_bytes : int, optional
        The budget; default :func:`memory_budget`.

    Examples
    --------
    >>> check_memory(8.0 * 10**6, "a vector of 10**6 floats", "use fewer", max_bytes=2**30)
    >>> check_memory(8.0 * 10**12, "a vector of 10**12 floats", "use fewer", max_bytes=2**30)
    Traceback (most recent call last):
    ...
    ValueError: a vector of 10**12 floats would take 7.28 TiB, more than the memory budget of 1 GiB (three \
quarters of the available memory, or ROUGHPATHS_MAX_BYTES); use fewer.
    """
    nbytes = float(nbytes)
    for rec in _RECORDERS.stack:
        rec.entries.append((nbytes, what))
    budget = memory_budget() if max_bytes is None else max_bytes
    if not nbytes <= budget:
        raise ValueError(f"{what} would take {_human(nbytes)}, more than the memory budget of "
                         f"{_human(budget)} (three quarters of the available memory, or "
                         f"ROUGHPATHS_MAX_BYTES); {fix}.")


def work_budget() -> float:
    """The number of path-steps (or comparable units of work) one call may do before it is refused.

    ``ROUGHPATHS_MAX_WORK`` if set; otherwise ``1e12`` (about a day of single-core work at the
    fastest kernels). Streamed computations use constant memory, so :func:`check_memory` cannot
    catch a request that would merely run for ever (e.g. ``T / eps**2`` steps with a tiny ``eps``).
    """
    import os

    env = os.environ.get("ROUGHPATHS_MAX_WORK")
    if env:
        try:
            value = float(env)
        except ValueError:
            raise ValueError(f"ROUGHPATHS_MAX_WORK must be a number, got {env!r}.") from None
        if not value > 0:
            raise ValueError(f"ROUGHPATHS_MAX_WORK must be positive, got {env!r}.")
        return value
    return 1e12


def check_work(units, what: str, fix: str, *, max_units=None) -> None:
    """Refuse, before starting, a computation of ``units`` path-steps above :func:`work_budget`.

    ``units`` is an estimate computed in floating point (so it cannot overflow); the message
    states it, ``what`` says what it counts and ``fix`` how to reduce it.
    """
    budget = work_budget() if max_units is None else float(max_units)
    if not float(units) <= budget:
        raise ValueError(f"{what}: about {float(units):.3g} path-steps, more than the work budget of "
                         f"{budget:.3g} (ROUGHPATHS_MAX_WORK); {fix}.")
