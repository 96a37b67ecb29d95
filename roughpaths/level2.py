r"""The step-2 group :math:`G^2(\mathbb{R}^d)` of level-2 elements ``(x, a)``.

An element is a pair ``x`` of shape ``(..., d)`` (level 1) and ``a`` of shape ``(..., d, d)``
(level 2), standing for :math:`1 + x + a` in the tensor algebra truncated at depth 2.
All functions broadcast over leading batch axes.

Conventions (``docs/conventions.md``):

* product :math:`(x, a)\cdot(y, b) = (x + y,\; a + b + x\otimes y)` (Chen's identity);
* inverse :math:`(x, a)^{-1} = (-x,\; -a + x\otimes x)`;
* logarithm :math:`\log(1 + x + a) = x + (a - \tfrac12 x\otimes x)`; for a geometric element
  the level-2 part of the log is the Lévy area :math:`\mathrm{Alt}(a) = \tfrac12(a - a^T)`;
* exponential :math:`\exp(x + A) = 1 + x + (A + \tfrac12 x\otimes x)`.

Examples
--------
>>> import numpy as np
>>> from roughpaths.level2 import level2_mul, level2_inv
>>> x, a = np.array([1.0, 2.0]), np.array([[0.5, 1.5], [0.5, 2.0]])
>>> y, b = level2_mul(x, a, *level2_inv(x, a))
>>> bool(np.allclose(y, 0) and np.allclose(b, 0))
True
"""

from __future__ import annotations

import numpy as np

__all__ = ["level2_mul", "level2_inv", "level2_exp", "level2_log", "outer"]


def outer(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Batched tensor product ``x ⊗ y``: shape ``(..., d)`` × ``(..., d)`` → ``(..., d, d)``."""
    return x[..., :, None] * y[..., None, :]


def level2_mul(x, a, y, b):
    """Chen product ``(x, a)·(y, b) = (x + y, a + b + x ⊗ y)``, broadcast over batch axes."""
    x, a, y, b = (np.asarray(v, dtype=np.float64) for v in (x, a, y, b))
    return x + y, a + b + outer(x, y)


def level2_inv(x, a):
    """Group inverse ``(x, a)^{-1} = (-x, -a + x ⊗ x)``."""
    x, a = np.asarray(x, dtype=np.float64), np.asarray(a, dtype=np.float64)
    return -x, -a + outer(x, x)


def level2_exp(x, A):
    """Exponential of the Lie element ``x + A``: returns ``(x, A + ½ x ⊗ x)``.

    ``A`` (shape ``(..., d, d)``) is the level-2 Lie part; it is antisymmetric for elements of the
    free step-2 nilpotent Lie algebra (the result is then geometric), but any matrix is accepted.
    """
    x, A = np.asarray(x, dtype=np.float64), np.asarray(A, dtype=np.float64)
    return x, A + 0.5 * outer(x, x)


def level2_log(x, a):
    """Truncated logarithm: returns ``(x, a - ½ x ⊗ x)``.

    For a geometric element the second entry is the Lévy area ``½(a - aᵀ)``.
    """
    x, a = np.asarray(x, dtype=np.float64), np.asarray(a, dtype=np.float64)
    return x, a - 0.5 * outer(x, x)
