r"""Rough integral of a controlled path against a level-2 rough path (compensated Riemann sums).

For a path :math:`Y` with values in :math:`L(\mathbb{R}^d, \mathbb{R}^m)` controlled by :math:`X` with
Gubinelli derivative :math:`Y'` (:math:`Y_t - Y_s = Y'_s X_{s,t} + O(|t-s|^{2\alpha})`),

.. math:: \int_{t_0}^{t_N} Y\,d\mathbf{X} = \lim \sum_k Y_{t_k} X_{t_k,t_{k+1}}
          + Y'_{t_k}\,\mathbb{X}_{t_k,t_{k+1}}, \qquad
          (Y'\mathbb{X})^a = \sum_{i,j} Y'^{\,a}_{j\,i}\,\mathbb{X}^{ij},

with the area :math:`\mathbb{X}^{ij} = \int (X^i - X^i_s)\,dX^j` (``docs/conventions.md``). Index layout:
``Y[..., a, j]`` is the coefficient of :math:`dX^j` in component ``a``; ``Yp[..., a, j, i]`` is
:math:`\partial Y^a_j / \partial X^i`. For :math:`Y = F(X)`, :math:`Y' = DF(X)`.

With a Stratonovich (geometric) lift the sums converge to the Stratonovich integral, with an Itô
lift (:math:`\mathbb{X}^{\text{Itô}} = \mathbb{X}^{\text{Strat}} - \tfrac12 (t - s) I`) to the Itô integral.
"""

from __future__ import annotations

import numpy as np

from ..validation import as_float_array
from .rough_path import RoughPath

__all__ = ["rough_integral"]


def rough_integral(Y, Y_prime, X: RoughPath, *, cumulative: bool = False) -> np.ndarray:
    r"""Compensated Riemann sum :math:`\sum_k Y_{t_k} X_{t_k,t_{k+1}} + Y'_{t_k}\mathbb{X}_{t_k,t_{k+1}}`.

    Parameters
    ----------
    Y : array_like, shape ``(..., N + 1, m, d)`` or ``(..., N + 1, d)``
        The integrand at the grid times (``(..., N + 1, d)`` means ``m = 1``: a scalar integral
        :math:`\int Y_j\,dX^j`). Only the first ``N`` samples enter the sums.
    Y_prime : array_like, shape ``(..., N + 1, m, d, d)`` or ``(..., N + 1, d, d)``
        Gubinelli derivative, ``Y_prime[..., a, j, i] = ∂Y^a_j/∂X^i``.
    X : RoughPath
        Level-2 driver (``N`` steps, dimension ``d``); its batch broadcasts against ``Y``'s.
    cumulative : bool
        If True return the integral from ``t_0`` to every grid time (``(..., N + 1, m)``, starting at 0),
        else only over the whole grid (``(..., m)``). Scalar layouts drop the ``m`` axis.

    Examples
    --------
    :math:`\int W\circ dW = \tfrac12 W^2` (exact here: the compensated sums telescope):

    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> from roughpaths import rough_integral
    >>> W = np.concatenate([[0.0], np.cumsum(np.random.default_rng(1).normal(0, 0.1, 100))])[:, None]
    >>> X = RoughPath.from_path(W)
    >>> I = rough_integral(W, np.ones((101, 1, 1)), X)
    >>> bool(np.isclose(I, 0.5 * W[-1, 0] ** 2))
    True
    """
    if not isinstance(X, RoughPath):
        raise TypeError(f"X must be a RoughPath, got {type(X).__name__}.")
    if X.level < 2:
        raise ValueError("the rough integral needs a level-2 driver (the compensation term uses the "
                         "area), but X is level 1; lift it (e.g. RoughPath.from_path) first.")
    n, d = X.n_steps, X.dim
    y = as_float_array(Y, "Y", min_ndim=2)
    yp = as_float_array(Y_prime, "Y_prime", min_ndim=3)
    # Decide the layout from Y_prime's rank relative to Y: Y' always has exactly one more axis.
    if yp.ndim != y.ndim + 1:
        raise ValueError(f"Y_prime must have one more axis than Y (Y: {y.shape}, Y_prime: {yp.shape}); "
                         f"Y (..., N+1, m, d) pairs with Y_prime (..., N+1, m, d, d).")
    if y.shape[-1] != d or yp.shape[-2:] != (d, d):
        raise ValueError(f"Y must end in d={d} (got {y.shape}) and Y_prime in (d, d) = ({d}, {d}) "
                         f"(got {yp.shape}) to match the driver's dimension.")
    if yp.shape[:-1] != y.shape:
        raise ValueError(f"Y_prime {yp.shape} must be Y's shape {y.shape} plus a trailing axis of size {d}.")
    at2 = y.shape[-2] == n + 1
    at3 = y.ndim >= 3 and y.shape[-3] == n + 1
    if at2 and at3:
        raise ValueError(f"Y of shape {y.shape} is ambiguous: both axis -2 and axis -3 have N + 1 = {n + 1} "
                         f"entries; add an explicit m axis (Y[..., None, :]) to use the (..., N+1, m, d) layout "
                         f"with a time axis at -3.")
    if not (at2 or at3):
        raise ValueError(f"Y must have N + 1 = {n + 1} samples on its time axis (axis -3 for "
                         f"(..., N+1, m, d), -2 for (..., N+1, d)), got shape {y.shape}.")
    scalar = at2
    if scalar:
        y, yp = y[..., None, :], yp[..., None, :, :]
    inc, area = X.increments, X.areas
    first = np.einsum("...kaj,...kj->...ka", y[..., :-1, :, :], inc)
    second = np.einsum("...kaji,...kij->...ka", yp[..., :-1, :, :, :], area)
    terms = first + second                                         # (..., N, m)
    if cumulative:
        out = np.concatenate([np.zeros(terms.shape[:-2] + (1, terms.shape[-1])),
                              np.cumsum(terms, axis=-2)], axis=-2)
    else:
        out = terms.sum(axis=-2)
    return out[..., 0] if scalar else out

