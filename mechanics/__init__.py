"""mechanics: stochastic geometric mechanics on geometric rough paths.

Lie–Poisson / Euler–Poincaré equations with SALT noise, the Lévy-area correction, double-bracket
dissipation, Casimir-preserving integrators, the stochastic rigid body and heavy top, Gibbs measures,
and the coloured-noise Wong–Zakai anomaly, built on :mod:`roughpaths`.
"""

__version__ = "0.1.0"

__all__: list[str] = []
