r"""The constant Girsanov shift that turns the Lévy-area correction into a change of the driver's drift.

See :func:`girsanov_shift`; the paper's (LieDepXis) drops the ½ (``convention="paper"`` returns it).
"""

from __future__ import annotations

import numpy as np

from .lie_poisson import CONVENTIONS, LiePoissonSystem

__all__ = ["girsanov_shift"]


def girsanov_shift(system: LiePoissonSystem, *, convention: str = "rp", atol: float = 1e-10) -> np.ndarray:
    r"""Constant Girsanov drift :math:`u\in\mathbb R^m` with :math:`u^k\xi_k = \tfrac12\mathsf s^{ij}[\xi_i,\xi_j]`.

    Then the corrected system driven by :math:`X` equals the uncorrected one (``s = 0``) driven by
    :math:`X_t + u\,t` pathwise, and the two laws are equivalent (Novikov holds: ``u`` is constant).
    For :math:`\xi_k = e_k` (a basis) :math:`u^k = \tfrac12\mathsf s^{ij}c^k_{ij}`; the paper's
    (LieDepXis) drops the ½ — ``convention="paper"`` returns that printed value (twice ours).

    Raises ``ValueError`` if :math:`\ell` is not in the span of the :math:`\xi_k` (no constant shift).
    """
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}.")
    ell = system.levy_velocity
    u, *_ = np.linalg.lstsq(system.xi.T, ell, rcond=None)
    resid = float(np.max(np.abs(system.xi.T @ u - ell))) if ell.size else 0.0
    if resid > atol * max(1.0, float(np.max(np.abs(ell)))):
        raise ValueError(f"the Lévy velocity ½ s^ij [xi_i, xi_j] = {ell} is not a combination of the noise "
                         f"vectors xi (residual {resid:.3g}); no constant Girsanov shift exists.")
    return 2.0 * u if convention == "paper" else u
