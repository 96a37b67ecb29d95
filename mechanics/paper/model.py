"""The paper's Section 4 set-up shared by its figures and checks.

The stochastic rigid body with inertia ``𝕀 = diag(1, 2, 3)``, isotropic noise ``σ = 0.05``,
dissipation ``θ = 1`` and ``Π(0) = e₃``; antisymmetric Lévy-area perturbations ``s`` written by
their upper entries; the Gibbs mean conditioned on a hemisphere (a trajectory started at ``e₃``
with ``σ = 0.05`` never crosses the equator, so it samples the Gibbs law of its basin).
Conventions: ``docs/conventions.md``. The sizes the figures and checks run at, and their cost, are
in :mod:`mechanics.paper.sizes`.
"""

from __future__ import annotations

import numpy as np

import mechanics

__all__ = ["INERTIA", "SIGMA", "THETA", "PI0", "s_matrix", "s_label", "paper_body", "hemisphere_mean",
           "standard_error"]

#: the paper's inertia 𝕀 = diag(1, 2, 3)
INERTIA = (1.0, 2.0, 3.0)
#: noise amplitude σ of the isotropic noise ξ_i = σ e_i
SIGMA = 0.05
#: dissipation strength θ
THETA = 1.0
#: the initial state Π(0) = e3
PI0 = np.array([0.0, 0.0, 1.0])


def s_matrix(s12: float = 0.0, s13: float = 0.0, s23: float = 0.0) -> np.ndarray:
    """The antisymmetric 3×3 Lévy-area perturbation ``s`` with the given upper entries.

    Examples
    --------
    >>> s_matrix(s13=25.0)[2, 0]
    np.float64(-25.0)
    """
    return np.array([[0.0, s12, s13], [-s12, 0.0, s23], [-s13, -s23, 0.0]])


def s_label(s) -> str:
    """Matplotlib label of the non-zero entries of ``s``, e.g. ``s$^{13}$=25``."""
    parts = [f"s$^{{{i + 1}{j + 1}}}$={s[i, j]:g}" for i, j in ((0, 1), (0, 2), (1, 2)) if s[i, j] != 0]
    return ", ".join(parts) if parts else "s = 0"


def paper_body(s=None, *, sigma=SIGMA, theta=THETA, convention="rp"):
    """The paper's rigid body with Lévy-area perturbation ``s`` (``mechanics.rigid_body``)."""
    return mechanics.rigid_body(INERTIA, sigma=sigma, s=s, theta=theta, convention=convention)


def hemisphere_mean(gibbs, sign: float = 1.0) -> np.ndarray:
    """Mean of a Gibbs measure on the sphere conditioned on ``sign(Π₃) = sign``.

    Parameters
    ----------
    gibbs : mechanics.GibbsMeasure
    sign : {1.0, -1.0}

    Returns
    -------
    ndarray, shape ``(3,)``
    """

    def feats(P):
        ind = (np.sign(P[..., 2:3]) == sign).astype(np.float64)
        return np.concatenate([P * ind, ind], axis=-1)

    e = gibbs.expectation(feats)
    return e[:3] / e[3]


def standard_error(x, axis: int = 0) -> np.ndarray:
    """Standard error of the mean of independent samples along ``axis`` (``ddof = 1``)."""
    x = np.asarray(x, dtype=np.float64)
    return np.std(x, axis=axis, ddof=1) / np.sqrt(x.shape[axis])
