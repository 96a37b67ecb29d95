r"""The truncated tensor algebra, the level-2 group and the Lyndon basis.

* :mod:`~roughpaths.algebra.tensor`: elements of :math:`T^m(\mathbb{R}^d)` in iisignature's flat layout,
  their product, inverse, exponential and logarithm, Lyndon coordinates.
* :mod:`~roughpaths.algebra.level2`: the level-2 group :math:`(x, \mathbb{X})` in the pair form used by
  :class:`~roughpaths.RoughPath`.
* :mod:`~roughpaths.algebra.flat`: the flat layout's compiled operations, the low-level door of
  :mod:`roughpaths.signatures`.
"""

from .level2 import level2_exp, level2_inv, level2_log, level2_mul
from .tensor import (from_level2, from_lyndon_coordinates, logsigdim, lyndon_basis, lyndon_coordinates,
                     sigdim, tensor_exp, tensor_inverse, tensor_log, tensor_product, to_level2)

__all__ = [
    "level2_exp", "level2_inv", "level2_log", "level2_mul", "from_level2", "from_lyndon_coordinates",
    "logsigdim", "lyndon_basis", "lyndon_coordinates", "sigdim", "tensor_exp", "tensor_inverse", "tensor_log",
    "tensor_product", "to_level2",
]
