r"""Static kernels for the signature kernel: the inner product the paths' increments are compared with.

The signature kernel :math:`k(x, y) = \langle S(x), S(y)\rangle` lifts a kernel :math:`κ` on the
state space :math:`\mathbb{R}^d` (the *static* kernel) to paths: the Goursat PDE is driven by
:math:`\partial_s\partial_t κ(x_s, y_t)`, which on a cell of two piecewise-linear paths is the double
difference :math:`κ(x_{p+1}, y_{q+1}) - κ(x_{p+1}, y_q) - κ(x_p, y_{q+1}) + κ(x_p, y_q)`.

- :class:`LinearKernel` ``(scale)``: :math:`κ(u, v) = \mathrm{scale}^2\,\langle u, v\rangle`, i.e. the
  untruncated signature inner product of the paths multiplied by ``scale``. ``static_kernel=None`` is
  ``LinearKernel(1.0)``.
- :class:`RBFKernel` ``(sigma)``: :math:`κ(u, v) = \exp(-|u - v|^2 / (2σ^2))`, σ a length in the units
  of the paths. (pysiglib's and sigkernel's ``RBFKernel(s)`` is :math:`\exp(-|u - v|^2/s)`, i.e. ours
  with :math:`s = 2σ^2`.)
"""

from __future__ import annotations

from dataclasses import dataclass

from ..validation import check_positive_real

__all__ = ["LinearKernel", "RBFKernel"]


@dataclass(frozen=True)
class LinearKernel:
    """The linear static kernel ``κ(u, v) = scale² <u, v>`` (the plain signature kernel of ``scale · x``).

    Parameters
    ----------
    scale : float
        Positive factor applied to both paths (default 1). ``k(x, y)`` with ``LinearKernel(s)`` equals
        ``k(s x, s y)`` with the default kernel.

    Examples
    --------
    >>> LinearKernel(2.0)
    LinearKernel(scale=2.0)
    """

    scale: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "scale", _positive(self.scale, "scale", "the factor applied to both paths"))


@dataclass(frozen=True)
class RBFKernel:
    """The Gaussian (RBF) static kernel ``κ(u, v) = exp(-|u - v|² / (2 sigma²))``.

    Parameters
    ----------
    sigma : float
        Positive length scale, in the units of the paths' values.

    Examples
    --------
    >>> RBFKernel(0.5)
    RBFKernel(sigma=0.5)
    """

    sigma: float

    def __post_init__(self):
        object.__setattr__(self, "sigma", _positive(self.sigma, "sigma", "the RBF length scale, in the units of "
                                                      "the paths' values"))


def _positive(value, name: str, what: str) -> float:
    try:
        return check_positive_real(value, name)
    except ValueError as exc:
        raise ValueError(f"{exc} Pass a positive float: {name} is {what}.") from None


def _resolve(static_kernel) -> tuple:
    """``(rbf, factor)``: the compiled kernels see the paths multiplied by ``factor``."""
    if static_kernel is None:
        return False, 1.0
    if isinstance(static_kernel, LinearKernel):
        return False, static_kernel.scale
    if isinstance(static_kernel, RBFKernel):
        return True, 1.0 / static_kernel.sigma
    hint = ""
    if isinstance(static_kernel, str):
        hint = " (a name is not accepted: pass an instance)"
    raise TypeError(f"static_kernel must be None (linear), LinearKernel(scale) or RBFKernel(sigma) from "
                    f"roughpaths, got {static_kernel!r}{hint}; e.g. static_kernel=roughpaths.RBFKernel(sigma=1.0).")
