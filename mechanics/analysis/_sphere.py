"""Geometry of the momentum sphere shared by the equilibria and the Gibbs quadrature."""

from __future__ import annotations

import numpy as np


def _tangent_basis(n: np.ndarray) -> np.ndarray:
    """Orthonormal basis (3, 2) of the plane ⟂ n, right-handed: b1 × b2 = n/|n|."""
    u = n / np.linalg.norm(n)
    k = int(np.argmin(np.abs(u)))
    e = np.zeros(3)
    e[k] = 1.0
    b1 = np.cross(u, e)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(u, b1)
    return np.stack([b1, b2], axis=1)
