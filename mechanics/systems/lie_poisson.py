r"""Stochastic Lie–Poisson systems with SALT noise, the Lévy-area correction and double-bracket dissipation.

The rough-path-correct ("rp", default) equation on :math:`\mathfrak g^*`, driven by a geometric rough
path :math:`\mathbf X = (X, \mathbb X)` in :math:`\mathbb R^m`, is

.. math::

    d\mu = \mathrm{ad}^*_{w(\mu)}\mu\,dt + \sum_i \mathrm{ad}^*_{\xi_i}\mu\,d\mathbf X^i,\qquad
    w(\mu) = \nabla\tilde h(\mu) + \vartheta\,\big(\mathrm{ad}^*_{\nabla\tilde h(\mu)}\mu\big)^\sharp,

with the modified Hamiltonian :math:`\tilde h(\mu) = h(\mu) + \langle\mu, \ell\rangle` and the Lévy-area
velocity :math:`\ell = \tfrac12\sum_{i,j}\mathsf s^{ij}[\xi_i,\xi_j]` (``docs/conventions.md``; ``ad*`` as in
:mod:`mechanics.lie_algebra`, i.e. :math:`\mathrm{ad}^*_\xi\Pi = \Pi\times\xi` on so(3)).

Why :math:`+\ell`: the noise fields :math:`V_i(\mu) = \mathrm{ad}^*_{\xi_i}\mu` have Jacobi–Lie bracket
:math:`[V_i, V_j](\mu) = \mathrm{ad}^*_{[\xi_i,\xi_j]}\mu`, so the Friz–Oberhauser drift of the
perturbation :math:`\mathbb X\mapsto\mathbb X + \mathsf s(t-s)` is
:math:`\tfrac12\mathsf s^{ij}[V_i,V_j] = \mathrm{ad}^*_\ell\mu` (Proposition 2.1 with the sign fixed).
For the rigid body this is the torque :math:`\Pi\times c`, :math:`c = +\tfrac12\mathsf s^{ij}\xi_i\times\xi_j`.

The double-bracket term :math:`\vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp}\mu` (built from
:math:`\tilde h`, as Theorem 3.1 requires) is itself of coadjoint form, so the whole drift is
:math:`\mathrm{ad}^*_{w}\mu` and every Casimir is conserved; :math:`\tilde h` decays at the rate
:math:`\vartheta|\mathrm{ad}^*_{\nabla\tilde h}\mu|^2_\sharp`. ``♯`` uses the metric ``metric`` on
:math:`\mathfrak g` (default: the coordinate dot product; for so(3) this gives
:math:`\vartheta\,\Pi\times(\Pi\times\nabla\tilde h)`).

Where the Lévy-area velocity enters (``levy_in_dissipation``):

* ``True`` (default): the model above, Theorem 3.1's equation — :math:`\ell` in both the conservative
  term and the double bracket (both built from :math:`\tilde h`); its Gibbs measure is
  :math:`\propto\exp(-2\vartheta\tilde h/\sigma^2)` for isotropic noise.
* ``False``: :math:`\ell` in the conservative term only,

  .. math::

      d\mu = \mathrm{ad}^*_{\nabla\tilde h}\mu\,dt
            + \vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_{\nabla h}\mu)^\sharp}\mu\,dt
            + \sum_i \mathrm{ad}^*_{\xi_i}\mu\,d\mathbf X^i

  (dissipation built from :math:`h`). Because Friz–Oberhauser turns the perturbation
  :math:`\mathbb X\mapsto\mathbb X + \mathsf s(t-s)` into the drift :math:`\mathrm{ad}^*_\ell\mu` and leaves
  the rest of the drift alone, this is *exactly* the ``s = 0`` system driven by ``X.perturb(s)``
  (Proposition 2.1 with :math:`\vartheta > 0`), e.g. the white-noise limit of the coloured-noise rigid
  body (:mod:`mechanics.limits.wong_zakai`). For :math:`\vartheta > 0` the two models differ by
  :math:`\vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_\ell\mu)^\sharp}\mu`, an ``O(1)`` drift.

Forces (Section 2.2): ``force`` :math:`F^0` and ``noise_forces`` :math:`F^i` add vector fields to the drift and
the driving fields, :math:`d\mu = (\mathrm{ad}^*_{w}\mu + F^0)dt + (\mathrm{ad}^*_{\xi_i}\mu + F^i)d\mathbf X^i`, with the
Lévy term from the :math:`\xi_i` only; Casimirs are conserved only by forces tangent to the orbits
(:mod:`mechanics.systems._forces`).

``convention="paper"`` reproduces the printed equations (srblevy)/(detrigidbodylevy)/(heavytoplevy):
the Lévy torque enters with the opposite sign, :math:`\tilde h_{\rm paper} = h - \langle\mu,\ell\rangle`,
in the conservative term and (with ``levy_in_dissipation=True``) the dissipative term. It is *not* what a rough path with area
:math:`\mathbb X + \mathsf s(t-s)` produces; use it only to reproduce the paper's figures.
"""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths.validation import as_float_array, check_antisymmetric

from .hamiltonian import check_inertia, hamiltonian_from
from ._forces import ForcesMixin
from ._matrix_states import MatrixStatesMixin
from .lie_algebra import LieAlgebra
from .matrix_algebra import MatrixLieAlgebra

__all__ = [
    "LiePoissonSystem",
    "levy_velocity",
    "CONVENTIONS",
]

CONVENTIONS = ("rp", "paper")


def levy_velocity(s, xi, algebra=None) -> np.ndarray:
    r"""The Lévy-area velocity :math:`\ell = \tfrac12\sum_{i,j}\mathsf s^{ij}[\xi_i,\xi_j]` (rough-path sign, with the ½).

    The one formula for it: :attr:`LiePoissonSystem.levy_velocity`, the rigid body's torque
    :math:`c = \tfrac12\mathsf s^{ij}\xi_i\times\xi_j` and the Wong–Zakai limits all use it.

    Parameters
    ----------
    s : array_like ``(m, m)``
        Antisymmetric area perturbation, in the coordinates of the driver of ``ξ``.
    xi : array_like ``(m, n)``
        Noise vectors (rows).
    algebra : LieAlgebra or MatrixLieAlgebra, optional
        Default so(3) (``[x, y] = x × y``, ``n = 3``).

    Examples
    --------
    >>> s = np.zeros((3, 3)); s[0, 2], s[2, 0] = 1.0, -1.0
    >>> levy_velocity(s, 2.0 * np.eye(3))      # σ² (s23, -s13, s12)
    array([ 0., -4.,  0.])
    """
    from .lie_algebra import so3

    alg = so3() if algebra is None else algebra
    s = as_float_array(s, "s", ndim=2)
    if s.shape[0] != s.shape[1]:
        raise ValueError(f"s must be square, got shape {s.shape}.")
    xi = as_float_array(xi, "xi", ndim=2, last_dims=(s.shape[0], alg.dim))
    return _levy_velocity(s, _brackets(xi, alg))


def _brackets(xi, algebra):
    """``[ξ_i, ξ_j]``, shape ``(m, m, n)``: from the structure constants, or as commutators of matrices."""
    if isinstance(algebra, MatrixLieAlgebra):
        return algebra.bracket(xi[:, None, :], xi[None, :, :])
    return np.einsum("ia,jb,abk->ijk", xi, xi, algebra._c)


def _levy_velocity(s, brackets):
    return 0.5 * np.einsum("ij,ijk->k", s, brackets)


class LiePoissonSystem(ForcesMixin, MatrixStatesMixin):
    r"""A stochastic Lie–Poisson (Euler–Poincaré) system on :math:`\mathfrak g^*` with SALT noise.

    Parameters
    ----------
    algebra : LieAlgebra or MatrixLieAlgebra
        Structure constants (small and user algebras) or a matrix algebra (:func:`~mechanics.su`,
        :func:`~mechanics.so`, ... any size: the solvers then hold the state as a matrix and update it by
        conjugation, :mod:`mechanics.integrators`); the equations are the same.
    hamiltonian : array_like ``(n, n)`` inertia tensor, or Hamiltonian, or callable
        An inertia tensor gives :math:`h = \tfrac12\mu\cdot\mathbb I^{-1}\mu` (symmetric positive
        definite, checked). A callable ``h(mu)`` needs ``hamiltonian_gradient=`` (and optionally
        ``hamiltonian_hessian=``).
    xi : array_like, shape ``(m, n)``
        Noise vectors :math:`\xi_i\in\mathfrak g` (rows).
    s : array_like, shape ``(m, m)``, optional
        Antisymmetric Lévy-area perturbation (default 0).
    theta : float
        Double-bracket dissipation rate :math:`\vartheta\ge 0`.
    convention : {"rp", "paper"}
        ``"rp"`` (default): rough-path-correct signs. ``"paper"``: the Lévy torque with the printed
        (wrong) sign; see the module docstring.
    metric : array_like ``(n, n)``, optional
        Symmetric positive-definite metric on :math:`\mathfrak g` defining ``♯`` in the dissipation
        (default identity).
    levy_in_dissipation : bool
        Where the Lévy-area velocity :math:`\ell` enters (module docstring). ``True`` (default):
        conservative term and double bracket, both from :math:`\tilde h` (Theorem 3.1's model).
        ``False``: conservative term only, dissipation from :math:`h` — the exact equation of the
        ``s = 0`` system driven by ``X.perturb(s)`` (and of the coloured-noise limit). The two
        coincide when ``theta == 0`` or ``s == 0``.
    force, noise_forces : callable, optional
        :math:`F^0`: ``mu (..., n) -> (..., n)``; :math:`(F^1..F^m)`: ``mu -> (..., n, m)`` (column ``i`` is
        :math:`F^i`); see :mod:`mechanics.systems._forces` (signs, Lévy term, Casimirs).
    force_jacobian, noise_forces_jacobian : callable, optional
        ``mu -> (..., n, n)`` (``[..., a, b] = ∂F^0_a/∂μ_b``) and ``mu -> (..., n, m, n)``
        (``[..., a, i, b] = ∂F^i_a/∂μ_b``); central differences if omitted.

    Examples
    --------
    >>> import numpy as np
    >>> from mechanics.systems.lie_algebra import so3
    >>> from mechanics.systems.lie_poisson import LiePoissonSystem
    >>> s = np.zeros((3, 3)); s[0, 2], s[2, 0] = 25.0, -25.0
    >>> sys_ = LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.05 * np.eye(3), s=s, theta=1.0)
    >>> sys_.levy_velocity          # ½ s^{ij} ξ_i × ξ_j = σ² (s23, -s13, s12)
    array([ 0.    , -0.0625,  0.    ])
    >>> Pi = np.array([0.6, 0.0, 0.8])
    >>> lim = LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.05 * np.eye(3), s=s, theta=1.0,
    ...                        levy_in_dissipation=False)
    >>> bool(np.allclose(lim.conservative_drift(Pi), sys_.conservative_drift(Pi)))
    True
    >>> bool(np.allclose(lim.dissipation(Pi), sys_.with_s(np.zeros((3, 3))).dissipation(Pi)))
    True
    """

    def __init__(self, algebra: LieAlgebra, hamiltonian, xi, s=None, theta=0.0, convention: str = "rp",
                 *, hamiltonian_gradient=None, hamiltonian_hessian=None, metric=None,
                 levy_in_dissipation: bool = True, force=None, noise_forces=None, force_jacobian=None,
                 noise_forces_jacobian=None):
        if not isinstance(algebra, (LieAlgebra, MatrixLieAlgebra)):
            raise TypeError(f"algebra must be a LieAlgebra (e.g. mechanics.so3()) or a MatrixLieAlgebra (e.g. "
                            f"mechanics.su(4)), got {type(algebra).__name__}.")
        self.algebra = algebra
        n = algebra.dim
        self.hamiltonian = hamiltonian_from(hamiltonian, hamiltonian_gradient, hamiltonian_hessian, n,
                                            diagonal_vector=isinstance(algebra, MatrixLieAlgebra))
        xi = as_float_array(xi, "xi")
        if xi.ndim != 2 or xi.shape[1] != n or xi.shape[0] < 1:
            raise ValueError(f"xi must have shape (m, n) = (number of noises, {n}) with one noise "
                             f"vector of the {n}-dimensional Lie algebra {algebra.name!r} per row, "
                             f"got shape {xi.shape}.")
        m = xi.shape[0]
        if s is None:
            s = np.zeros((m, m))
        s = check_antisymmetric(s, "s")
        if s.shape != (m, m):
            raise ValueError(f"s must be {m}x{m} to match the {m} noise vectors in xi, got shape {s.shape}.")
        if isinstance(theta, bool) or not isinstance(theta, numbers.Real):
            raise TypeError(f"theta must be a real number, got {theta!r}.")
        theta = float(theta)
        if not np.isfinite(theta) or theta < 0:
            raise ValueError(f"theta must be a finite number >= 0 (the dissipation rate), got {theta!r}; "
                             f"a negative rate would pump energy in and destabilise the dynamics.")
        if convention not in CONVENTIONS:
            raise ValueError(f"convention must be one of {CONVENTIONS} ('rp' is the rough-path-correct "
                             f"default, 'paper' reproduces the printed sign slips), got {convention!r}.")
        if not isinstance(levy_in_dissipation, (bool, np.bool_)):
            raise TypeError(f"levy_in_dissipation must be True (Lévy velocity in the conservative term and the "
                            f"double bracket, Theorem 3.1's model) or False (conservative term only: the "
                            f"s = 0 system driven by X.perturb(s)), got {levy_in_dissipation!r}.")
        self.levy_in_dissipation = bool(levy_in_dissipation)
        if metric is None:
            self._metric_inv = None
        else:
            mtr = check_inertia(metric, "metric", dim=n)
            self._metric_inv = np.linalg.inv(mtr)
        self.xi, self.s, self.theta, self.convention = xi, s, theta, convention
        self._xi_brackets = _brackets(xi, algebra)
        self._levy_velocity = _levy_velocity(s, self._xi_brackets)
        self._shift = self._levy_velocity if convention == "rp" else -self._levy_velocity
        # velocity shift inside the double bracket: the same as _shift, or none (dissipation from h)
        self._shift_dissipation = self._shift if self.levy_in_dissipation else np.zeros(n)
        self._matrix = isinstance(algebra, MatrixLieAlgebra)
        # B_i = ad*_{ξ_i}, (m, n, n): formed now from structure constants, on first use for a matrix algebra
        self._noise_matrices = None if self._matrix else np.einsum("ia,ajk->ijk", xi, algebra._c)
        for arr in (self.xi, self.s, self._xi_brackets, self._levy_velocity, self._noise_matrices,
                    self._shift_dissipation):
            if arr is not None:
                arr.setflags(write=False)
        self._set_forces(force, noise_forces, force_jacobian, noise_forces_jacobian)

    # ------------------------------------------------------------------ attributes
    @property
    def dim(self) -> int:
        """Dimension ``n`` of the Lie algebra."""
        return self.algebra.dim

    @property
    def n_noise(self) -> int:
        """Number ``m`` of noise vectors (dimension of the driving rough path)."""
        return self.xi.shape[0]

    @property
    def dim_state(self) -> int:
        """Dimension ``n`` of the state (for :func:`roughpaths.solve`; equals :attr:`dim`)."""
        return self.algebra.dim

    @property
    def dim_noise(self) -> int:
        """Dimension ``m`` of the driver (for :func:`roughpaths.solve`; equals :attr:`n_noise`)."""
        return self.xi.shape[0]

    def quadratic_velocity_data(self):
        r"""Constants of :math:`w(\mu)` for a quadratic Hamiltonian :math:`h = \tfrac12\mu\cdot Q\mu + b\cdot\mu`.

        :math:`w(\mu) = g + \vartheta M^{-1}(\mathrm{ad}^*_{g + f}\mu)` with :math:`g = Q\mu + b + \ell'`
        (:math:`\ell'` the torque velocity), :math:`f` the change of the gradient inside the double
        bracket (``0``, or :math:`-\ell'` with ``levy_in_dissipation=False``). Used by compiled kernels.

        Returns
        -------
        dict with ``q (n, n)``, ``linear (n,)`` (:math:`b + \ell'`), ``dissipation_change (n,)`` (:math:`f`),
        ``metric_inv (n, n)`` (identity by default) and ``theta``; ``None`` if ``h`` is not quadratic.
        """
        h = self.hamiltonian
        if not h.is_quadratic:
            return None
        n = self.dim
        minv = np.eye(n) if self._metric_inv is None else self._metric_inv
        return {"q": np.ascontiguousarray(h.q, dtype=np.float64),
                "linear": np.asarray(h.linear + self._shift, dtype=np.float64),
                "dissipation_change": np.asarray(self._shift_dissipation - self._shift, dtype=np.float64),
                "metric_inv": np.ascontiguousarray(minv, dtype=np.float64), "theta": self.theta}

    @property
    def levy_velocity(self) -> np.ndarray:
        r""":math:`\ell = \tfrac12\sum_{i,j}\mathsf s^{ij}[\xi_i,\xi_j]` (rough-path-correct sign, with the ½), shape ``(n,)``."""
        return self._levy_velocity

    @property
    def torque_velocity(self) -> np.ndarray:
        r"""The velocity shift actually used in :math:`\tilde h`: ``levy_velocity`` ("rp") or its negative ("paper")."""
        return self._shift

    @property
    def xi_brackets(self) -> np.ndarray:
        r""":math:`[\xi_i,\xi_j]`, shape ``(m, m, n)``."""
        return self._xi_brackets

    @property
    def noise_matrices(self) -> np.ndarray:
        r"""Matrices ``B_i`` of :math:`\mu\mapsto\mathrm{ad}^*_{\xi_i}\mu`, shape ``(m, n, n)`` (for a matrix
        algebra formed on first use: ``m n²`` floats, which its solvers never need)."""
        if self._noise_matrices is None:
            self._noise_matrices = self.algebra.ad_star_matrix(self.xi)
            self._noise_matrices.setflags(write=False)
        return self._noise_matrices

    def with_s(self, s) -> "LiePoissonSystem":
        """A copy with another Lévy-area perturbation ``s`` (everything else shared)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.pop("_stack", None)
        LiePoissonSystem.__init__(new, self.algebra, self.hamiltonian, self.xi, s, self.theta,
                                  self.convention, metric=None, levy_in_dissipation=self.levy_in_dissipation,
                                  force=self.force, noise_forces=self.noise_forces,
                                  force_jacobian=self.force_jacobian,
                                  noise_forces_jacobian=self.noise_forces_jacobian)
        new._metric_inv = self._metric_inv
        return new

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(algebra={self.algebra.name!r}, n={self.dim}, m={self.n_noise}, "
                f"theta={self.theta}, convention={self.convention!r}"
                + ("" if self.levy_in_dissipation else ", levy_in_dissipation=False")
                + (", force" if self.force is not None else "") + (", noise_forces" if self.noise_forces is not None else "")
                + ")")

    # ------------------------------------------------------------------ Hamiltonians
    def _mu(self, mu):
        return as_float_array(mu, "mu", last_dims=(self.dim,))

    def energy(self, mu) -> np.ndarray:
        """The Hamiltonian :math:`h(\\mu)`, shape ``(...)``."""
        return self.hamiltonian.value(self._mu(mu))

    def modified_hamiltonian(self, mu) -> np.ndarray:
        r""":math:`\tilde h(\mu) = h(\mu) + \langle\mu,\ell\rangle` ("rp"; ``- ⟨μ, ℓ⟩`` for "paper"), shape ``(...)``."""
        mu = self._mu(mu)
        return self.hamiltonian.value(mu) + mu @ self._shift

    def modified_hamiltonian_gradient(self, mu) -> np.ndarray:
        r""":math:`\nabla\tilde h = \nabla h + \ell`, shape ``(..., n)``."""
        return self._grad_tilde(self._mu(mu))

    def _grad_tilde(self, mu):
        return self.hamiltonian.gradient(mu) + self._shift

    def _grad_dissipation(self, mu, grad_tilde=None):
        """Gradient inside the double bracket: ``∇h̃`` (levy_in_dissipation) or ``∇h``."""
        if self.levy_in_dissipation:
            return self._grad_tilde(mu) if grad_tilde is None else grad_tilde
        return self.hamiltonian.gradient(mu) + self._shift_dissipation

    def _sharp(self, v):
        return v if self._metric_inv is None else (self._metric_inv.T @ v[..., None])[..., 0]

    def casimirs(self, mu) -> np.ndarray:
        """Casimirs of the algebra at ``mu``, shape ``(..., k)``."""
        return self.algebra.casimirs(self._mu(mu))

    # ------------------------------------------------------------------ vector fields
    def _ad_star(self, x, mu):
        if self._matrix:
            x, mu = np.broadcast_arrays(x, mu)
        return self.algebra._ad_star_unchecked(x, mu)

    def _ad_star_op(self, x):
        """``[..., j, k] = ∂(ad*_x μ)_j / ∂μ_k``, shape ``(..., n, n)``."""
        if self._matrix:
            return self.algebra.ad_star_matrix(x)
        return np.einsum("...i,ijk->...jk", x, self.algebra._c)

    def _orbit_tangent(self, mu):
        """``[..., j, i] = (ad*_{e_i} μ)_j``, shape ``(..., n, n)``."""
        if self._matrix:
            return self.algebra.coadjoint_orbit_tangent(mu)
        return np.einsum("...k,ijk->...ji", mu, self.algebra._c)

    def conservative_drift(self, mu) -> np.ndarray:
        r""":math:`\mathrm{ad}^*_{\nabla\tilde h}\mu` (Hamiltonian part plus Lévy torque), shape ``(..., n)``."""
        mu = self._mu(mu)
        return self._ad_star(self._grad_tilde(mu), mu)

    def dissipation(self, mu) -> np.ndarray:
        r""":math:`\vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp}\mu`, shape ``(..., n)``.
        For so(3): :math:`\vartheta\,\Pi\times(\Pi\times\nabla\tilde h)`. With
        ``levy_in_dissipation=False``, :math:`\nabla h` replaces :math:`\nabla\tilde h` here."""
        mu = self._mu(mu)
        v = self._ad_star(self._grad_dissipation(mu), mu)
        return self.theta * self._ad_star(self._sharp(v), mu)

    def drift_velocity(self, mu) -> np.ndarray:
        r""":math:`w(\mu) = \nabla\tilde h + \vartheta(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp\in\mathfrak g`, the drift is
        :math:`\mathrm{ad}^*_{w(\mu)}\mu` (with ``levy_in_dissipation=False`` the second
        :math:`\nabla\tilde h` is :math:`\nabla h`). Shape ``(..., n)``."""
        return self._w(self._mu(mu))

    def drift_velocity_jacobian(self, mu) -> np.ndarray:
        r""":math:`Dw(\mu)`, shape ``(..., n, n)`` (``[..., a, b] = ∂w_a/∂μ_b``)."""
        return self._w_jacobian(self._mu(mu))

    def _w(self, mu):
        g = self._grad_tilde(mu)
        if self.theta == 0.0:
            return g
        return g + self.theta * self._sharp(self._ad_star(self._grad_dissipation(mu, g), mu))

    def _w_jacobian(self, mu):
        hess = self.hamiltonian.hessian(mu)
        if self.theta == 0.0:
            return np.array(hess, dtype=np.float64)
        g = self._grad_dissipation(mu)                             # the gradient inside the bracket
        a_g = self._ad_star_op(g)                                # ad*_g
        lmu = self._orbit_tangent(mu)                            # δ ↦ ad*_δ μ
        d = a_g + lmu @ hess
        if self._metric_inv is not None:
            d = self._metric_inv.T @ d
        return hess + self.theta * d

    def drift(self, mu) -> np.ndarray:
        r"""Total drift :math:`\mathrm{ad}^*_{w(\mu)}\mu + F^0(\mu)` (conservative + Lévy torque + dissipation
        + ``force``), ``(..., n)``."""
        mu = self._mu(mu)
        out = self._ad_star(self._w(mu), mu)
        return out if self.force is None else out + self._f0(mu)

    def drift_jacobian(self, mu) -> np.ndarray:
        """Jacobian of :meth:`drift`, shape ``(..., n, n)`` (``[..., a, b] = ∂drift_a/∂μ_b``)."""
        mu = self._mu(mu)
        w = self._w(mu)
        out = self._ad_star_op(w) + self._orbit_tangent(mu) @ self._w_jacobian(mu)
        return out if self.force is None else out + self._f0_jacobian(mu)

    def noise(self, mu) -> np.ndarray:
        r"""Noise fields as columns: ``[..., :, i]`` is :math:`\mathrm{ad}^*_{\xi_i}\mu + F^i(\mu)`, shape ``(..., n, m)``."""
        mu = self._mu(mu)
        out = np.einsum("iab,...b->...ai", self.noise_matrices, mu)
        return out if self.noise_forces is None else out + self._fi(mu)

    def noise_jacobian(self, mu) -> np.ndarray:
        """``[..., a, i, b] = ∂ V_i^a / ∂ μ_b`` (constant without ``noise_forces``: the fields are linear), shape
        ``(..., n, m, n)``."""
        mu = self._mu(mu)
        jac = np.transpose(self.noise_matrices, (1, 0, 2))
        if self.noise_forces is not None:
            return jac + self._fi_jacobian(mu)
        return np.broadcast_to(jac, mu.shape[:-1] + jac.shape)

    def vector_fields(self):
        r"""The fields in the form :func:`roughpaths.solve` accepts.

        Returns a ``roughpaths.LinearVectorFields`` with the noise matrices :math:`B_i`
        (:math:`V_i(\mu) = B_i\mu = \mathrm{ad}^*_{\xi_i}\mu`) and the (non-linear) drift
        :meth:`drift` with its Jacobian. The drift contains the Lévy torque of ``s`` — drive it with
        ``X``; the uncorrected system (``with_s(0)``) driven by ``X.perturb(s)`` is the same RDE
        (Proposition 2.1) — but only without ``noise_forces`` (with them, driving by ``X.perturb(s)`` adds the
        brackets of the :math:`F^i` as well; module docstring).

        With ``force`` the drift contains :math:`F^0`; with ``noise_forces`` the family is a
        ``roughpaths.VectorFields`` with the fields :meth:`noise` and their Jacobians :meth:`noise_jacobian`.
        """
        from roughpaths import LinearVectorFields, VectorFields

        if self.noise_forces is None:
            return LinearVectorFields(self.noise_matrices, drift=self.drift, drift_jacobian=self.drift_jacobian)
        return VectorFields(self.noise, self._noise_jacobians_rp, drift=self.drift,
                            drift_jacobian=self.drift_jacobian, dim_state=self.dim, dim_noise=self.n_noise)

    # ------------------------------------------------------------------ log-signature → algebra
    def stochastic_velocity(self, increments, levy_areas=None) -> np.ndarray:
        r"""Push a level-2 log-signature into :math:`\mathfrak g`:
        :math:`\xi_i X^i + \tfrac12\sum_{i,j} A^{ij}[\xi_i,\xi_j]`.

        Parameters
        ----------
        increments : array_like, shape ``(..., m)``
        levy_areas : array_like, shape ``(..., m, m)``, optional
            Step Lévy areas :math:`A = \tfrac12(\mathbb X - \mathbb X^T)` (with the ½). ``None``: no area term.

        Notes
        -----
        This is the noise part of the coadjoint step :math:`\sigma_n`: for linear fields
        :math:`V_i = B_i\mu` the Davie term :math:`B_jB_i\mathbb X^{ij}` equals
        :math:`\tfrac12(B_iX^i)^2 + \tfrac12A^{ij}(B_jB_i - B_iB_j)` and
        :math:`B_jB_i - B_iB_j = \mathrm{ad}^*_{[\xi_i,\xi_j]}`, so
        :math:`\exp(\mathrm{ad}^*_\sigma)` matches it with :math:`\sigma \ni \tfrac12A^{ij}[\xi_i,\xi_j]`.
        Replacing :math:`A` by :math:`A + \mathsf s\,\Delta t` adds exactly :math:`\ell\,\Delta t`.
        """
        inc = np.asarray(increments, dtype=np.float64)
        out = (self.xi.T @ inc[..., None])[..., 0]                # stacked mat-vec: no coupling across the batch
        if levy_areas is not None:
            a = np.asarray(levy_areas, dtype=np.float64)
            m = self.n_noise
            brk = self._xi_brackets.reshape(m * m, self.dim).T
            out = out + 0.5 * (brk @ a.reshape(a.shape[:-2] + (m * m, 1)))[..., 0]
        return out
