r"""The step-2 group :math:`G^2(\mathbb{R}^d)` of level-2 elements ``(x, a)``.

An element is a pair ``x`` of shape ``(..., d)`` (level 1) and ``a`` of shape ``(..., d, d)``
(level 2), standing for :math:`1 + x + a` in the tensor algebra truncated at depth 2.
All functions broadcast over leading batch axes and check their input: real, finite entries,
``x`` ending in ``d`` and ``a`` ending in ``(d, d)`` with the same ``d``, batch axes that broadcast
(anything else is a ``TypeError`` / ``ValueError`` naming the argument).

Conventions (``docs/conventions.md``):

* product :math:`(x, a)\cdot(y, b) = (x + y,\; a + b + x\otimes y)` (Chen's identity);
* inverse :math:`(x, a)^{-1} = (-x,\; -a + x\otimes x)`;
* logarithm :math:`\log(1 + x + a) = x + (a - \tfrac12 x\otimes x)`; for a geometric element
  the level-2 part of the log is the Lévy area :math:`\mathrm{Alt}(a) = \tfrac12(a - a^T)`;
* exponential :math:`\exp(x + A) = 1 + x + (A + \tfrac12 x\otimes x)`.

Examples
--------
>>> import numpy as np
>>> from roughpaths import level2_mul, level2_inv
>>> x, a = np.array([1.0, 2.0]), np.array([[0.5, 1.5], [0.5, 2.0]])
>>> y, b = level2_mul(x, a, *level2_inv(x, a))
>>> bool(np.allclose(y, 0) and np.allclose(b, 0))
True
"""

from __future__ import annotations

import numpy as np

from ..validation import as_float_array

__all__ = ["level2_mul", "level2_inv", "level2_exp", "level2_log", "outer"]


def outer(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Batched tensor product ``x ⊗ y``: shape ``(..., d)`` × ``(..., d)`` → ``(..., d, d)``."""
    return x[..., :, None] * y[..., None, :]


def _element(x, a, nx="x", na="a"):
    """Validate one element ``(x, a)``: finite, ``x`` of shape ``(..., d)``, ``a`` of ``(..., d, d)``."""
    x = as_float_array(x, nx, min_ndim=1)
    d = x.shape[-1]
    a = as_float_array(a, na, min_ndim=2)
    if a.shape[-2:] != (d, d):
        raise ValueError(f"{na} must have shape (..., d, d) = (..., {d}, {d}) to match {nx} of shape "
                         f"{x.shape} (d = {d}), got shape {a.shape}.")
    try:
        np.broadcast_shapes(x.shape[:-1], a.shape[:-2])
    except ValueError:
        raise ValueError(f"the batch axes of {nx} {x.shape[:-1]} and {na} {a.shape[:-2]} do not broadcast; "
                         f"give them the same leading shape.") from None
    return x, a


def _batches(*pairs):
    try:
        return np.broadcast_shapes(*(v.shape[:-k] for v, k in pairs))
    except ValueError:
        shapes = ", ".join(str(v.shape) for v, _ in pairs)
        raise ValueError(f"the two elements' batch axes do not broadcast (shapes {shapes}); give them "
                         f"matching leading shapes.") from None


def level2_mul(x, a, y, b):
    """Chen product ``(x, a)·(y, b) = (x + y, a + b + x ⊗ y)``, broadcast over batch axes."""
    x, a = _element(x, a, "x", "a")
    y, b = _element(y, b, "y", "b")
    if y.shape[-1] != x.shape[-1]:
        raise ValueError(f"x and y must have the same dimension d, got x.shape[-1] = {x.shape[-1]} and "
                         f"y.shape[-1] = {y.shape[-1]}.")
    _batches((x, 1), (a, 2), (y, 1), (b, 2))
    return x + y, a + b + outer(x, y)


def level2_inv(x, a):
    """Group inverse ``(x, a)^{-1} = (-x, -a + x ⊗ x)``."""
    x, a = _element(x, a)
    return -x, -a + outer(x, x)


def level2_exp(x, A):
    """Exponential of the Lie element ``x + A``: returns ``(x, A + ½ x ⊗ x)``.

    ``A`` (shape ``(..., d, d)``) is the level-2 Lie part; it is antisymmetric for elements of the
    free step-2 nilpotent Lie algebra (the result is then geometric), but any matrix is accepted.
    """
    x, A = _element(x, A, "x", "A")
    return x, A + 0.5 * outer(x, x)


def level2_log(x, a):
    """Truncated logarithm: returns ``(x, a - ½ x ⊗ x)``.

    For a geometric element the second entry is the Lévy area ``½(a - aᵀ)``.
    """
    x, a = _element(x, a)
    return x, a - 0.5 * outer(x, x)
