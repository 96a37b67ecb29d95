"""Stability of the sleeping Lagrange top (the heavy top spinning upright), in closed form."""

from __future__ import annotations

import numpy as np

from roughpaths.validation import check_positive_real, check_real

__all__ = ["lagrange_top_sleeping_stability"]


def lagrange_top_sleeping_stability(I1, I3, omega3, mgl):
    r"""The sleeping Lagrange top: linear stability of ``Π = (0, 0, I3 ω3)``, ``Γ = e3``.

    Symmetric top ``𝕀 = diag(I1, I1, I3)``, ``h = ½Π·𝕀⁻¹Π + χ·Γ`` with ``χ = M g ℓ e3`` (centre of
    mass on the symmetry axis at distance ``ℓ``), Lie–Poisson equations on se(3)* in the
    ``docs/conventions.md`` form ``Π̇ = Π × Ω + Γ × χ``, ``Γ̇ = Γ × Ω``. The upright spin is an equilibrium
    for every ``ω3``; it is linearly (and, by energy–Casimir, nonlinearly) stable iff
    ``Π3² > 4 I1 M g ℓ`` (the fast-top criterion). The body-frame linearisation has the eigenvalues
    ``± √(4 I1 M g ℓ − Π3²) / (2 I1)`` (each twice) plus two zeros along the Casimir directions.

    Returns
    -------
    dict with ``stable`` (bool), ``margin`` ``Π3² − 4 I1 M g ℓ`` and ``eigenvalues`` (complex, 6).

    Examples
    --------
    >>> lagrange_top_sleeping_stability(1.0, 2.0, 2.0, 1.0)["stable"]
    True
    """
    I1 = check_positive_real(I1, "I1")
    I3 = check_positive_real(I3, "I3")
    p3 = I3 * check_real(omega3, "omega3")
    margin = p3 * p3 - 4.0 * I1 * check_real(mgl, "mgl")
    if not np.isfinite(margin):
        raise ValueError(f"the margin (I3*omega3)**2 - 4*I1*mgl overflows for I1={I1!r}, I3={I3!r}, "
                         f"omega3={omega3!r}, mgl={mgl!r}; rescale the units.")
    lam = np.sqrt(complex(-margin)) / (2.0 * I1)
    return {"stable": bool(margin > 0), "margin": margin,
            "eigenvalues": np.array([lam, lam, -lam, -lam, 0.0, 0.0], dtype=complex)}
