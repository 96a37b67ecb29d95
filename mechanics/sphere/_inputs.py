"""Input checks shared by the modules of :mod:`mechanics.sphere` (matrix sizes, matrices, coefficient arrays)."""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths.validation import check_memory, check_positive_int

#: The largest matrix size the quantised basis is built for (the basis takes N^3/3 floats while it is built).
MAX_N = 4096


def check_size(N, name: str = "N") -> int:
    """A matrix size ``2 <= N <= MAX_N`` (su(N) needs N >= 2)."""
    if isinstance(N, bool) or not isinstance(N, numbers.Integral):
        raise TypeError(f"{name} must be an integer matrix size (e.g. {name}=32), got {N!r} "
                        f"({type(N).__name__}).")
    n = check_positive_int(N, name)
    if n < 2 or n > MAX_N:
        raise ValueError(f"{name} must satisfy 2 <= {name} <= {MAX_N} (the spin (N-1)/2 representation), "
                         f"got {n}.")
    return n


def as_matrix(W, name: str = "W", *, N: int | None = None) -> np.ndarray:
    """``W`` as a complex128 array of square matrices ``(..., N, N)`` (a copy only when needed)."""
    if isinstance(W, (str, bytes)) or W is None:
        raise TypeError(f"{name} must be an array of N x N matrices, shape (..., N, N), got {W!r}.")
    try:
        arr = np.asarray(W)
    except Exception as exc:  # pragma: no cover - numpy's own errors are clear enough
        raise TypeError(f"{name} must be an array of N x N matrices, got {type(W).__name__}.") from exc
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise TypeError(f"{name} must be a numeric array of N x N matrices, got dtype {arr.dtype}.")
    if arr.ndim < 2 or arr.shape[-1] != arr.shape[-2]:
        raise ValueError(f"{name} must have shape (..., N, N) (batch first, square last two axes), "
                         f"got shape {arr.shape}.")
    if N is not None and arr.shape[-1] != N:
        raise ValueError(f"{name} must be {N} x {N} for this model, got shape {arr.shape}; build it with "
                         f"the same N.")
    check_size(arr.shape[-1], f"{name}.shape[-1]")
    arr = np.asarray(arr, dtype=np.complex128)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} has non-finite entries (NaN or inf); check how it was built.")
    return arr


def as_coefficients(omega, name: str = "omega") -> tuple[np.ndarray, int]:
    """``omega`` as a complex128 array ``(..., L**2)`` of spherical-harmonic coefficients; returns it and L."""
    if isinstance(omega, (str, bytes)) or omega is None:
        raise TypeError(f"{name} must be an array of spherical-harmonic coefficients, shape (..., L**2).")
    arr = np.asarray(omega)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise TypeError(f"{name} must be a numeric array, got dtype {arr.dtype}.")
    if arr.ndim < 1:
        raise ValueError(f"{name} must have shape (..., L**2) (index l*(l+1)+m), got a scalar.")
    n = arr.shape[-1]
    L = int(round(np.sqrt(n)))
    if L < 1 or L * L != n:
        raise ValueError(f"{name} must have a last axis of length L**2 (all l < L, |m| <= l, index "
                         f"l*(l+1)+m), got length {n}; pad with zeros to the next square.")
    arr = np.asarray(arr, dtype=np.complex128)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} has non-finite entries (NaN or inf).")
    return arr, L


def check_bytes(nbytes: float, what: str, fix: str) -> None:
    """Refuse, before allocating, an estimated ``nbytes`` above the library's memory budget."""
    check_memory(float(nbytes), what, fix)
