r"""The paper's planar example (2dexample): a linear system driven by coloured noise, and its limit.

.. math::

    dx = Qx\,dt + P(x)\,\frac{y}{\varepsilon}\,dt, \qquad
    dy = -\varepsilon^{-2}(\alpha I + \gamma J)\,y\,dt + \varepsilon^{-1}\sqrt\delta\,dB,

with ``Q = diag(λ, μ)``, ``J = [[0, 1], [−1, 0]]`` and the columns of ``P(x)`` the linear fields
``V_1 = (0, x_1) = E_1 x``, ``V_2 = (x_2, 0) = E_2 x``; ``[V_1, V_2] = Sx``, ``S = diag(1, −1)``.
Written as an RDE driven by ``B^ε = ∫ y/ε dt`` (:class:`roughpaths.ColouredNoiseDriver`) it is
solved like any other: :meth:`PlanarExample.vector_fields` gives the fields and the drift,
:meth:`PlanarExample.driver` the coloured driver, and

``roughpaths.solve(ex.vector_fields(), ex.driver(eps, T, seed=0, batch_shape=(P,)), x0, LogODE())``

returns a :class:`roughpaths.Solution`. ``LogODE`` is exact for linear fields given the step's
level-2 log-signature (``exp(Qh + X^iE_i + A^{12}S)``, ``A`` the step Lévy area), and the driver
carries the exact Chen-summed area of ``B^ε`` on each step, so grid steps of order ``ε²`` suffice.

Limit (Friz–Oberhauser, ``docs/conventions.md``): ``M = A⁻¹D = √(δ/(α²+γ²)) R`` with ``R`` a
rotation, so ``MB = √(δ/(α²+γ²)) W`` with ``W = RB`` a Brownian motion (the paper's scaling is right),
and the limit is ``dX = (Q + N_{12}S)X dt + Σ_k G_k X∘dB^k``, ``G_k = Σ_i M_{ik}E_i``, with
``N_{12} = δγ/(2α(α²+γ²))`` (:meth:`PlanarExample.limit_vector_fields`, :func:`planar_limit_moments`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from roughpaths import ColouredNoiseDriver, ColouredNoiseLimit, LinearVectorFields, coloured_noise_limit
from roughpaths.validation import as_float_array, check_batch_shape, check_positive_real, check_real

from .wong_zakai import _coloured_grid

__all__ = ["PlanarExample", "planar_example", "planar_limit_moments"]


@dataclass(frozen=True)
class PlanarExample:
    r"""The paper's planar example (2dexample) and its homogenised limit.

    Attributes
    ----------
    alpha, gamma, delta, lam, mu : float
    A, D : ndarray ``(2, 2)``
        ``αI + γJ`` (``J = [[0, 1], [−1, 0]]``) and ``√δ I``.
    limit : ColouredNoiseLimit
    N12 : float
        ``N[0, 1]`` computed from ``Alt(ΣA⁻ᵀ)``; equals ``δγ/(2α(α²+γ²))`` (:attr:`paper_constant`).
    paper_constant : float
        ``δγ/(2α(α²+γ²))`` (the paper's formula).
    limit_scale : float
        ``√(δ/(α²+γ²))``: ``A⁻¹D = limit_scale · R`` with ``R`` a rotation.
    drift : ndarray ``(2, 2)``
        ``Q + N12 S``, ``S = diag(1, −1) = [V_1, V_2]``: the limit's drift matrix.
    noise_matrices : ndarray ``(2, 2, 2)``
        ``E_1, E_2`` with ``V_i(x) = E_i x`` (columns of ``P(x)``).
    """

    alpha: float
    gamma: float
    delta: float
    lam: float
    mu: float
    A: np.ndarray
    D: np.ndarray
    limit: ColouredNoiseLimit
    N12: float
    paper_constant: float
    limit_scale: float
    drift: np.ndarray
    noise_matrices: np.ndarray

    def vector_fields(self) -> LinearVectorFields:
        r"""The coloured system's fields ``V_i(x) = E_i x`` (driven by ``B^ε``) and drift ``V_0(x) = Qx``.

        Returns
        -------
        LinearVectorFields
            ``e = 2`` states, ``d = 2`` driving components (those of :meth:`driver`).
        """
        return LinearVectorFields(self.noise_matrices, np.diag([self.lam, self.mu]))

    def limit_vector_fields(self, *, torque: bool = True) -> LinearVectorFields:
        r"""The white-noise limit's fields ``G_k x`` (driven by ``B``) and drift ``(Q + N12 S)x``.

        ``G_k = Σ_i M_{ik} E_i`` with ``M = A⁻¹D``; ``torque=False`` drops ``N12 S`` (the plain
        Stratonovich Wong–Zakai guess). Drive it with a Brownian rough path of dimension 2 (e.g.
        :class:`roughpaths.BrownianDriver`) or with the ``brownian`` blocks of
        :meth:`roughpaths.ColouredNoiseDriver.blocks_with_brownian` (the coupled ``B``).
        """
        if not isinstance(torque, (bool, np.bool_)):
            raise TypeError(f"torque must be True (the limit, with N12 S) or False (the plain Stratonovich guess), "
                            f"got {torque!r}.")
        G = np.einsum("ik,iab->kab", self.limit.scaling, self.noise_matrices)
        return LinearVectorFields(G, self.drift if torque else np.diag([self.lam, self.mu]))

    def driver(self, eps, T, *, seed, batch_shape=(), h=None, substeps=None, max_substep: float = 0.5,
               y0="stationary") -> ColouredNoiseDriver:
        r"""The coloured driver ``B^ε`` of this example on the uniform grid of ``[0, T]``.

        Parameters
        ----------
        eps : float
            Correlation parameter ``ε > 0``.
        T : float
            Final time.
        seed : int or numpy.random.SeedSequence
            Root of the per-path streams (see :class:`roughpaths.ColouredNoiseDriver`).
        batch_shape : tuple of int
            Independent paths.
        h : float, optional
            Grid step, rounded so that it divides ``T`` (default ``ε²/(2‖A‖₂)``: the driver's
            Chen-summed areas make steps of order ``ε²`` enough).
        substeps, max_substep, y0 : as in :class:`roughpaths.ColouredNoiseDriver`.

        Examples
        --------
        >>> import numpy as np
        >>> from roughpaths import LogODE, solve
        >>> ex = planar_example(alpha=1.0, gamma=1.0, delta=2.0, lam=-0.2)
        >>> sol = solve(ex.vector_fields(), ex.driver(0.2, 1.0, seed=0, batch_shape=(4,)), [1.0, 1.0],
        ...             LogODE(), save_at="end")
        >>> sol.final.shape, sol.times
        ((4, 2), array([1.]))
        """
        shape = check_batch_shape(batch_shape)
        n_paths = max(1, int(np.prod(shape, dtype=np.int64)))
        n_steps, step = _coloured_grid(eps, T, h, float(np.linalg.norm(self.A, 2)), n_paths)
        return ColouredNoiseDriver(self.A, self.D, eps, seed=seed, dt=step, n_steps=n_steps, batch_shape=shape,
                                   substeps=substeps, max_substep=max_substep, y0=y0)


def planar_example(alpha=1.0, gamma=1.0, delta=1.0, lam=0.0, mu=0.0) -> PlanarExample:
    r"""Build the planar example ``dx = Qx dt + P(x) y/ε dt``, ``dy = −ε⁻²(αI + γJ)y dt + ε⁻¹√δ dB``.

    Examples
    --------
    >>> ex = planar_example(alpha=1.0, gamma=2.0, delta=3.0)
    >>> round(ex.N12, 12) == round(ex.paper_constant, 12) == round(3 * 2 / (2 * 1 * 5), 12)
    True
    """
    vals = []
    for name, v in (("alpha", alpha), ("gamma", gamma), ("delta", delta), ("lam", lam), ("mu", mu)):
        vals.append(check_real(v, name))
    alpha, gamma, delta, lam, mu = vals
    if alpha <= 0 or delta <= 0:
        raise ValueError(f"alpha and delta must be > 0 (alpha is the OU damping, delta the noise variance), "
                         f"got alpha={alpha!r}, delta={delta!r}.")
    J = np.array([[0.0, 1.0], [-1.0, 0.0]])
    A = alpha * np.eye(2) + gamma * J
    D = math.sqrt(delta) * np.eye(2)
    lim = coloured_noise_limit(A, D)
    N12 = float(lim.levy_perturbation[0, 1])
    E = np.array([[[0.0, 0.0], [1.0, 0.0]], [[0.0, 1.0], [0.0, 0.0]]])
    S = np.diag([1.0, -1.0])
    return PlanarExample(alpha=alpha, gamma=gamma, delta=delta, lam=lam, mu=mu, A=A, D=D, limit=lim, N12=N12,
                         paper_constant=delta * gamma / (2 * alpha * (alpha ** 2 + gamma ** 2)),
                         limit_scale=math.sqrt(delta / (alpha ** 2 + gamma ** 2)),
                         drift=np.diag([lam, mu]) + N12 * S, noise_matrices=E)


def _check_example(ex):
    if not isinstance(ex, PlanarExample):
        raise TypeError(f"ex must be a PlanarExample (from planar_example(...)), got {type(ex).__name__}.")


def planar_limit_moments(ex: PlanarExample, x0, T, *, torque: bool = True):
    r"""Exact ``E[X_T]`` and ``E[X_T X_Tᵀ]`` of the limit ``dX = (Q + N12 S)X dt + Σ_k G_k X∘dB^k``.

    ``G_k = Σ_i M_{ik} E_i`` (``M = A⁻¹D``, :meth:`PlanarExample.limit_vector_fields`). Itô drift
    ``B = Q + N12 S + ½ Σ_k G_k²``; ``E[X_T] = e^{BT}x0``; ``vec E[XXᵀ]`` solves
    ``d/dt vec P = (I⊗B + B⊗I + Σ_k G_k⊗G_k) vec P``. ``torque=False`` drops ``N12 S`` (the plain
    Stratonovich guess).
    """
    _check_example(ex)
    x0 = as_float_array(x0, "x0", ndim=1, last_dims=(2,))
    T = check_positive_real(T, "T", allow_zero=True)
    V = ex.limit_vector_fields(torque=torque)
    G = V.matrices
    B = V.drift_matrix + 0.5 * np.einsum("kab,kbc->ac", G, G)
    import scipy.linalg as sla                                 # lazy: keeps import mechanics light

    mean = sla.expm(B * T) @ x0
    I2 = np.eye(2)
    L = np.kron(I2, B) + np.kron(B, I2) + sum(np.kron(g, g) for g in G)
    P = (sla.expm(L * T) @ np.outer(x0, x0).reshape(-1)).reshape(2, 2)
    return mean, P
