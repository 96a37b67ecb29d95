"""Argument checks shared by the analysis modules (equilibria, phase portraits, Gibbs measures)."""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array


def _as_c(c, name: str = "c") -> np.ndarray:
    if c is None:
        return np.zeros(3)
    return as_float_array(c, name, ndim=1, last_dims=(3,))


def _check_radius(radius) -> float:
    r = float(as_float_array(radius, "radius", ndim=0))
    if not r > 0:
        raise ValueError(f"radius must be > 0 (the Casimir |Π| of the orbit), got {r!r}.")
    return r


def _check_theta(theta) -> float:
    th = float(as_float_array(theta, "theta", ndim=0))
    if th < 0:
        raise ValueError(f"theta must be >= 0 (a dissipation rate), got {th!r}; "
                         f"theta < 0 is anti-dissipation and has no Gibbs measure.")
    return th
