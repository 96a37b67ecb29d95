r"""Finite-dimensional real Lie algebras in coordinates, with the coadjoint action.

Conventions
-----------
* Structure constants ``c[i, j, k]``: :math:`[e_i, e_j] = c^k_{ij}\, e_k`, so
  ``bracket(x, y)[k] = x[i] y[j] c[i, j, k]``.
* ``ad(x)`` is the matrix of :math:`\mathrm{ad}_x y = [x, y]`: ``ad(x)[k, j] = x[i] c[i, j, k]``.
* The dual :math:`\mathfrak g^*` is identified with :math:`\mathbb R^n` through the coordinate pairing
  :math:`\langle \mu, \eta\rangle = \mu_k \eta^k` (dual basis). The coadjoint operator is the
  transpose, :math:`\langle \mathrm{ad}^*_\xi \mu, \eta\rangle = \langle \mu, \mathrm{ad}_\xi \eta\rangle`,
  i.e. ``ad_star(xi, mu) = ad(xi).T @ mu`` (no minus sign). For so(3) ≅ (R³, ×) this gives
  :math:`\mathrm{ad}^*_\xi \Pi = \Pi \times \xi`, so the rigid body reads
  :math:`\dot\Pi = \mathrm{ad}^*_{\nabla h}\Pi = \Pi\times\Omega`.
* With this convention :math:`\mu \mapsto \mathrm{ad}^*_\xi \mu` is an anti-homomorphism:
  :math:`[\mathrm{ad}^*_\xi, \mathrm{ad}^*_\eta] = -\mathrm{ad}^*_{[\xi,\eta]}` (matrix commutator), and the
  linear vector fields :math:`V_i(\mu) = \mathrm{ad}^*_{\xi_i}\mu` have Jacobi–Lie bracket
  (``docs/conventions.md``: :math:`[V,W] = DW\,V - DV\,W`) :math:`[V_i, V_j](\mu) = \mathrm{ad}^*_{[\xi_i,\xi_j]}\mu`.
* ``Ad_star_exp(sigma, mu)`` is :math:`\exp(\mathrm{ad}^*_\sigma)\,\mu = \mathrm{Ad}_{\exp\sigma}^{T}\mu`: the
  time-1 flow of :math:`\dot\mu = \mathrm{ad}^*_\sigma\mu`. It maps every coadjoint orbit to itself, so
  it preserves every Casimir exactly (up to round-off).

Every method accepts leading batch axes ``(..., n)`` and broadcasts them.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from roughpaths.validation import as_float_array, check_memory
from roughpaths import expm_batched

from ._structure_constants import (_KillingCasimir, _antisymmetry_defect, _constructor_bytes, _jacobi_defect,
                                   _killing)

__all__ = ["LieAlgebra", "SO3Algebra", "SE3Algebra", "so3", "su2", "se3", "sl2r", "hat", "vee",
           "rodrigues_ad_star_exp", "se3_ad_star_exp"]


def hat(x) -> np.ndarray:
    """Skew matrix of ``x`` (shape ``(..., 3)`` → ``(..., 3, 3)``): ``hat(x) @ y == cross(x, y)``."""
    x = as_float_array(x, "x", last_dims=(3,))
    z = np.zeros(x.shape[:-1])
    return np.stack([np.stack([z, -x[..., 2], x[..., 1]], -1),
                     np.stack([x[..., 2], z, -x[..., 0]], -1),
                     np.stack([-x[..., 1], x[..., 0], z], -1)], -2)


def vee(m) -> np.ndarray:
    """Inverse of :func:`hat` (reads the antisymmetric part), shape ``(..., 3, 3)`` → ``(..., 3)``."""
    m = as_float_array(m, "m", last_dims=(3, 3))
    return 0.5 * np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                           m[..., 1, 0] - m[..., 0, 1]], -1)


#: The one small-angle switch of the exponential coefficients: below ``t² < SMALL_ANGLE2`` the Taylor
#: polynomials of :func:`taylor_coefficients` (to ``t⁸``; truncation ``< t¹⁰/11! < 3e-18``, exact in
#: float64) replace the trigonometric formulas. The compiled kernels use the same switch and polynomials.
SMALL_ANGLE2 = 1e-2


def taylor_coefficients(t2):
    r"""Taylor polynomials (to :math:`t^8`) of :math:`a = \sin t/t`, :math:`b = (1-\cos t)/t^2` and
    :math:`c = (t - \sin t)/t^3` in ``t2 = t²``; plain arithmetic (scalars, arrays, numba)."""
    a = 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * (1.0 / 20.0) * (1.0 - t2 * (1.0 / 42.0) * (1.0 - t2 * (1.0 / 72.0))))
    b = 0.5 - t2 * (1.0 / 24.0) * (1.0 - t2 * (1.0 / 30.0) * (1.0 - t2 * (1.0 / 56.0) * (1.0 - t2 * (1.0 / 90.0))))
    c = (1.0 / 6.0) - t2 * (1.0 / 120.0) * (1.0 - t2 * (1.0 / 42.0) * (1.0 - t2 * (1.0 / 72.0)
                                                                        * (1.0 - t2 * (1.0 / 110.0))))
    return a, b, c


def _sinc_coeffs(t2: np.ndarray):
    """``a = sin(t)/t``, ``b = (1 - cos t)/t²`` and ``c = (t - sin t)/t³`` from ``t2 = t²`` (one switch)."""
    t2 = np.asarray(t2, dtype=np.float64)
    small = t2 < SMALL_ANGLE2
    ts = np.sqrt(np.where(small, 1.0, t2))
    ta, tb, tc = taylor_coefficients(t2)
    sin = np.sin(ts)
    a = np.where(small, ta, sin / ts)
    half = np.sin(0.5 * ts)
    b = np.where(small, tb, 2.0 * half * half / (ts * ts))
    c = np.where(small, tc, (ts - sin) / (ts * ts * ts))
    return a, b, c


def _cross(a, b) -> np.ndarray:
    """``np.cross(a, b)`` for shapes ``(..., 3)``, broadcast: the same operations per component (so the same
    bits), without ``np.cross``'s axis handling, which costs ~10 µs a call on the small batches of a step."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def rodrigues_ad_star_exp(sigma, mu) -> np.ndarray:
    r""":math:`\exp(\mathrm{ad}^*_\sigma)\mu` on so(3)* ≅ R³ in closed form (Rodrigues).

    :math:`\mathrm{ad}^*_\sigma\mu = \mu\times\sigma = -\sigma\times\mu`, so the result is the rotation of
    ``mu`` about ``sigma`` by the angle :math:`-|\sigma|`:
    :math:`\mu - a\,\sigma\times\mu + b\,\sigma\times(\sigma\times\mu)` with :math:`a = \sin t/t`,
    :math:`b = (1-\cos t)/t^2`, :math:`t = |\sigma|`. Shapes ``(..., 3)``, broadcast.
    """
    sigma = np.asarray(sigma, dtype=np.float64)
    mu = np.asarray(mu, dtype=np.float64)
    a, b, _ = _sinc_coeffs(np.einsum("...i,...i->...", sigma, sigma))
    sxm = _cross(sigma, mu)
    return mu - a[..., None] * sxm + b[..., None] * _cross(sigma, sxm)


class LieAlgebra:
    r"""A real Lie algebra of dimension ``n`` given by its structure constants.

    Parameters
    ----------
    structure_constants : array_like, shape ``(n, n, n)``
        ``c[i, j, k]`` with :math:`[e_i, e_j] = c^k_{ij} e_k`. Checked for antisymmetry in ``(i, j)``
        and the Jacobi identity.
    name : str, optional
        Label used in ``repr`` and messages.
    basis : array_like, shape ``(n, N, N)``, optional
        A faithful matrix representation ``E_i`` of the basis (real or complex). Enables
        :meth:`to_matrix` and :meth:`exp`.
    casimirs : callable, optional
        ``mu (..., n) -> (..., k)``: Casimir functions (constant on coadjoint orbits). Default for a
        semisimple algebra: the quadratic Casimir :math:`\mu^T K^{-1}\mu` (``K`` the Killing form).
    casimir_names : sequence of str, optional
        Names of the Casimirs, for messages.
    ad_star_exp : callable, optional
        Closed-form ``(sigma, mu) -> exp(ad*_sigma) mu``; default: the batched matrix exponential
        :func:`roughpaths.expm_batched` of the ``ad*`` matrices.

    Examples
    --------
    >>> import numpy as np
    >>> from mechanics.systems.lie_algebra import so3
    >>> g = so3()
    >>> g.bracket([1.0, 0, 0], [0, 1.0, 0])     # [e1, e2] = e3
    array([0., 0., 1.])
    >>> g.ad_star([0, 0, 1.0], [1.0, 0, 0])      # ad*_xi mu = mu x xi
    array([ 0., -1.,  0.])
    """

    def __init__(self, structure_constants, *, name: str = "g", basis=None, casimirs=None,
                 casimir_names=None, ad_star_exp=None, check: bool = True, atol: float = 1e-10):
        c = as_float_array(structure_constants, "structure_constants", ndim=3)
        n = c.shape[0]
        if c.shape != (n, n, n) or n < 1:
            raise ValueError(f"structure_constants must have shape (n, n, n), got {c.shape}.")
        check_memory(_constructor_bytes(n), f"the Lie algebra of dimension n={n} (its structure constants, "
                     f"their checks and the Killing form)", "use a smaller algebra")
        if check:
            scale = max(1.0, float(np.max(np.abs(c))))
            asym = _antisymmetry_defect(c)
            if asym > atol * scale:
                raise ValueError(f"structure_constants must be antisymmetric in (i, j) "
                                 f"(c[i,j,k] == -c[j,i,k]); the defect is {asym:.3g}. Pass "
                                 f"0.5 * (c - c.transpose(1, 0, 2)) if that was intended.")
            jac = _jacobi_defect(c)
            if jac > atol * scale * scale:
                raise ValueError(f"structure_constants violate the Jacobi identity (defect {jac:.3g}, more than "
                                 f"atol * max|c|**2 = {atol * scale * scale:.3g}); they do not define a Lie "
                                 f"algebra.")
        self._c = c.copy() if c is structure_constants else c       # frozen below: never the caller's array
        self._c.setflags(write=False)
        self.name = name
        self._basis = None if basis is None else np.asarray(basis)
        if self._basis is not None and (self._basis.ndim != 3 or self._basis.shape[0] != n):
            raise ValueError(f"basis must have shape (n={n}, N, N), got {self._basis.shape}.")
        self._ad_star_exp = ad_star_exp
        self._casimirs = casimirs
        self._casimir_names = tuple(casimir_names) if casimir_names is not None else None
        self._killing = _killing(c)
        if casimirs is None and self.is_semisimple:
            self._casimirs = _KillingCasimir(np.linalg.inv(self._killing))
            self._casimir_names = ("quadratic Casimir mu.K^-1.mu",)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_matrix_basis(cls, basis, *, name: str = "g", atol: float = 1e-10, **kwargs) -> "LieAlgebra":
        r"""The algebra spanned by matrices ``E_i`` (shape ``(n, N, N)``, real or complex) under the
        commutator :math:`[A, B] = AB - BA`.

        The structure constants are solved from :math:`[E_i, E_j] = c^k_{ij} E_k` (least squares
        over the real span); a basis that is not closed under the commutator, or not linearly
        independent, is rejected.
        """
        b = np.asarray(basis)
        if b.ndim != 3 or b.shape[1] != b.shape[2] or b.shape[0] < 1:
            raise ValueError(f"basis must have shape (n, N, N), got {b.shape}.")
        if b.dtype.kind not in "biufc":
            raise TypeError(f"basis must hold numbers, got dtype {b.dtype}.")
        n = b.shape[0]
        flat = b.reshape(n, -1).T                                   # (N², n)
        real = np.concatenate([flat.real, flat.imag], axis=0).astype(np.float64)
        if np.linalg.matrix_rank(real) < n:
            raise ValueError("basis matrices are linearly dependent over the reals; pass a basis.")
        comm = np.einsum("iab,jbc->ijac", b, b) - np.einsum("jab,ibc->ijac", b, b)
        rhs = comm.reshape(n * n, -1).T
        rhs = np.concatenate([rhs.real, rhs.imag], axis=0).astype(np.float64)
        sol, *_ = np.linalg.lstsq(real, rhs, rcond=None)            # (n, n*n)
        resid = float(np.max(np.abs(real @ sol - rhs))) if rhs.size else 0.0
        if resid > atol * max(1.0, float(np.max(np.abs(rhs)))):
            raise ValueError(f"the span of basis is not closed under the commutator (residual "
                             f"{resid:.3g}); it is not a Lie algebra basis.")
        c = sol.T.reshape(n, n, n)
        near = np.round(c)
        c = np.where(np.abs(c - near) < 1e-12 * max(1.0, float(np.max(np.abs(c)))), near, c)
        return cls(c, name=name, basis=b, **kwargs)

    # ------------------------------------------------------------------ basic attributes
    @property
    def dim(self) -> int:
        """Dimension ``n``."""
        return self._c.shape[0]

    @property
    def structure_constants(self) -> np.ndarray:
        """``c[i, j, k]`` with :math:`[e_i, e_j] = c^k_{ij} e_k` (a copy), shape ``(n, n, n)``."""
        return self._c.copy()

    @property
    def basis(self) -> np.ndarray | None:
        """Matrix representation of the basis, shape ``(n, N, N)``, or ``None``."""
        return self._basis

    @property
    def is_semisimple(self) -> bool:
        """Cartan's criterion: the Killing form is non-degenerate (``|det K| > 1e-9 max(1, max|K|)^n``, in logs)."""
        sign, logdet = np.linalg.slogdet(self._killing)       # det overflowed from n ~ 200 (so(25): 28^300)
        return bool(sign != 0 and logdet > np.log(1e-9) + self.dim * np.log(max(1.0, float(np.max(np.abs(
            self._killing))))))

    @property
    def casimir_names(self) -> tuple:
        """Names of the Casimirs returned by :meth:`casimirs`."""
        return self._casimir_names or ()

    @property
    def has_casimirs(self) -> bool:
        """Whether :meth:`casimirs` is available (given, or the Killing-form Casimir)."""
        return self._casimirs is not None

    def __repr__(self) -> str:
        return f"LieAlgebra(name={self.name!r}, dim={self.dim})"

    def _vec(self, x, name):
        return as_float_array(x, name, last_dims=(self.dim,))

    # ------------------------------------------------------------------ operations
    def bracket(self, x, y) -> np.ndarray:
        r""":math:`[x, y]^k = x^i y^j c^k_{ij}`, shapes ``(..., n)`` broadcast."""
        x, y = self._vec(x, "x"), self._vec(y, "y")
        return np.einsum("...i,...j,ijk->...k", x, y, self._c)

    def ad(self, x) -> np.ndarray:
        """Matrix of :math:`\\mathrm{ad}_x = [x, \\cdot]`, shape ``(..., n, n)`` (``ad(x) @ y == [x, y]``)."""
        x = self._vec(x, "x")
        return np.einsum("...i,ijk->...kj", x, self._c)

    def ad_star(self, xi, mu) -> np.ndarray:
        r""":math:`\mathrm{ad}^*_\xi\mu` with :math:`\langle\mathrm{ad}^*_\xi\mu,\eta\rangle = \langle\mu,[\xi,\eta]\rangle`:
        ``(ad_star(xi, mu))[j] = xi[i] mu[k] c[i, j, k]``, shapes ``(..., n)`` broadcast."""
        xi, mu = self._vec(xi, "xi"), self._vec(mu, "mu")
        return self._ad_star_unchecked(xi, mu)

    def _ad_star_unchecked(self, xi, mu):
        return np.einsum("...i,...k,ijk->...j", xi, mu, self._c)

    def ad_star_matrix(self, xi) -> np.ndarray:
        r"""Matrix of :math:`\mu\mapsto\mathrm{ad}^*_\xi\mu` (``= ad(xi).T``), shape ``(..., n, n)``."""
        xi = self._vec(xi, "xi")
        return np.einsum("...i,ijk->...jk", xi, self._c)

    def coadjoint_orbit_tangent(self, mu) -> np.ndarray:
        r"""Matrix of :math:`\delta\mapsto\mathrm{ad}^*_\delta\mu` (the orbit's tangent map at ``mu``),
        ``L[j, i] = mu[k] c[i, j, k]``, shape ``(..., n, n)``."""
        mu = self._vec(mu, "mu")
        return np.einsum("...k,ijk->...ji", mu, self._c)

    def killing_form(self, x=None, y=None):
        r"""Killing form :math:`K_{ij} = \mathrm{tr}(\mathrm{ad}_{e_i}\mathrm{ad}_{e_j}) = c^n_{im}c^m_{jn}`.

        With no arguments, the ``(n, n)`` matrix; with ``x, y`` (``(..., n)``), :math:`x^T K y`.
        """
        if x is None and y is None:
            return self._killing.copy()
        if x is None or y is None:
            raise TypeError("killing_form takes no arguments (the matrix) or both x and y.")
        x, y = self._vec(x, "x"), self._vec(y, "y")
        return np.einsum("...i,ij,...j->...", x, self._killing, y)

    def casimirs(self, mu) -> np.ndarray:
        """Casimir functions at ``mu`` (``(..., n)`` → ``(..., k)``); see :attr:`casimir_names`."""
        if self._casimirs is None:
            raise ValueError(f"the Lie algebra {self.name!r} has no known Casimirs (it is not "
                             f"semisimple); pass casimirs=callable to LieAlgebra.")
        mu = self._vec(mu, "mu")
        return np.asarray(self._casimirs(mu), dtype=np.float64)

    def to_matrix(self, x) -> np.ndarray:
        """``sum_i x[i] E_i`` in the matrix basis, shape ``(..., N, N)``."""
        if self._basis is None:
            raise ValueError(f"the Lie algebra {self.name!r} has no matrix basis; build it with "
                             f"LieAlgebra.from_matrix_basis to use to_matrix/exp.")
        x = self._vec(x, "x")
        return np.einsum("...i,iab->...ab", x, self._basis)

    def exp(self, x) -> np.ndarray:
        """Group exponential ``expm(sum_i x[i] E_i)`` in the matrix representation, batched."""
        return scipy.linalg.expm(self.to_matrix(x))

    def Ad_star_exp(self, sigma, mu) -> np.ndarray:  # noqa: N802 (mathematical name)
        r""":math:`\exp(\mathrm{ad}^*_\sigma)\,\mu`, the coadjoint action of :math:`\exp\sigma` used by the
        integrators (time-1 flow of :math:`\dot\mu = \mathrm{ad}^*_\sigma\mu`). Shapes ``(..., n)``
        broadcast. Closed form where the factory provides one (so(3): Rodrigues), else
        :func:`roughpaths.expm_batched` of the batched ``ad*`` matrices.
        """
        sigma, mu = self._vec(sigma, "sigma"), self._vec(mu, "mu")
        return self._ad_star_exp_unchecked(sigma, mu)

    def _ad_star_exp_unchecked(self, sigma, mu):
        if self._ad_star_exp is not None:
            return self._ad_star_exp(sigma, mu)
        shape = np.broadcast_shapes(sigma.shape, mu.shape)
        m = expm_batched(np.einsum("...i,ijk->...jk", sigma, self._c))
        return np.broadcast_to(np.einsum("...jk,...k->...j", m, mu), shape)


# ---------------------------------------------------------------------- factories
def _levi_civita() -> np.ndarray:
    e = np.zeros((3, 3, 3))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        e[i, j, k], e[j, i, k] = 1.0, -1.0
    return e


def _sphere_casimir(mu):
    return np.einsum("...i,...i->...", mu, mu)[..., None]


class SO3Algebra(LieAlgebra):
    r"""so(3) ≅ (R³, ×) in the basis ``hat(e_i)`` (``c = ε_{ijk}``), with the Rodrigues exponential.

    A type, so that solvers can choose their compiled so(3) kernels by ``isinstance`` (an
    implementation detail behind :func:`roughpaths.solve`). Build it with :func:`so3`.
    """

    def __init__(self):
        super().__init__(_levi_civita(), name="so3", basis=hat(np.eye(3)), casimirs=_sphere_casimir,
                         casimir_names=("|mu|^2",), ad_star_exp=rodrigues_ad_star_exp)

    def __reduce__(self):
        return (SO3Algebra, ())

    def _ad_star_unchecked(self, xi, mu):
        """``ad*_ξ μ = μ × ξ``: the two non-zero terms of the structure-constant sum per component, in one product
        and one difference each (the sum's bits; a third of its time on the batches of a numpy step)."""
        return _cross(mu, xi)


class SE3Algebra(LieAlgebra):
    r"""se(3) = so(3) ⋉ R³ in coordinates ``(omega, v)``, with its closed-form coadjoint exponential.

    A type (see :class:`SO3Algebra`). Build it with :func:`se3`.
    """

    def __init__(self):
        basis = np.zeros((6, 4, 4))
        basis[:3, :3, :3] = hat(np.eye(3))
        for i in range(3):
            basis[3 + i, i, 3] = 1.0
        alg = LieAlgebra.from_matrix_basis(basis, name="se3")
        super().__init__(alg._c, name="se3", basis=basis, casimirs=_se3_casimirs,
                         casimir_names=("|Gamma|^2", "Pi.Gamma"), ad_star_exp=se3_ad_star_exp, check=False)

    def __reduce__(self):
        return (SE3Algebra, ())


def so3() -> SO3Algebra:
    r"""so(3) ≅ (R³, ×): :math:`[x, y] = x\times y`, ``c = ε_{ijk}``; matrix basis ``hat(e_i)``.

    Casimir :math:`|\mu|^2`; :meth:`LieAlgebra.Ad_star_exp` in closed form (Rodrigues).
    """
    return SO3Algebra()


def su2() -> LieAlgebra:
    r"""su(2) with basis :math:`e_k = -\tfrac{i}{2}\sigma_k` (Pauli matrices), from the complex matrix basis.

    :math:`[e_j, e_k] = \varepsilon_{jkl} e_l`, isomorphic to so(3); Casimir :math:`|\mu|^2`. The
    structure constants are computed from the matrices (a check of :meth:`LieAlgebra.from_matrix_basis`).
    """
    pauli = np.array([[[0, 1], [1, 0]], [[0, -1j], [1j, 0]], [[1, 0], [0, -1]]], dtype=complex)
    return LieAlgebra.from_matrix_basis(-0.5j * pauli, name="su2", casimirs=_sphere_casimir,
                                        casimir_names=("|mu|^2",))


def _se3_casimirs(mu):
    pi, gam = mu[..., :3], mu[..., 3:]
    return np.stack([np.einsum("...i,...i->...", gam, gam), np.einsum("...i,...i->...", pi, gam)], -1)


def se3_ad_star_exp(sigma, mu) -> np.ndarray:
    r""":math:`\exp(\mathrm{ad}^*_\sigma)\mu` on se(3)* in closed form.

    For ``sigma = (omega, v)`` and ``mu = (Pi, Gamma)``, with :math:`T = e^{-\hat\omega}` (rotation by
    :math:`-|\omega|` about :math:`\omega`) and :math:`J = \int_0^1 e^{s\hat\omega}ds`:
    :math:`\Gamma' = T\Gamma`, :math:`\Pi' = T(\Pi - (Jv)\times\Gamma)`. Both Casimirs are preserved
    structurally. Shapes ``(..., 6)``, broadcast.
    """
    sigma = np.asarray(sigma, dtype=np.float64)
    mu = np.asarray(mu, dtype=np.float64)
    w, v = sigma[..., :3], sigma[..., 3:]
    pi, gam = mu[..., :3], mu[..., 3:]
    _, b, c = _sinc_coeffs(np.einsum("...i,...i->...", w, w))
    wxv = _cross(w, v)
    jv = v + b[..., None] * wxv + c[..., None] * _cross(w, wxv)
    p = pi - _cross(jv, gam)
    return np.concatenate([rodrigues_ad_star_exp(w, p), rodrigues_ad_star_exp(w, gam)], axis=-1)


def se3() -> SE3Algebra:
    r"""se(3) = so(3) ⋉ R³, coordinates ``x = (omega, v)`` (6-vector), the heavy top's algebra.

    Matrix basis: :math:`\begin{pmatrix}\hat\omega & v\\ 0 & 0\end{pmatrix}` (4×4), so
    :math:`[(\omega_1,v_1),(\omega_2,v_2)] = (\omega_1\times\omega_2,\ \omega_1\times v_2 - \omega_2\times v_1)`.
    On the dual, ``mu = (Pi, Gamma)`` and
    :math:`\mathrm{ad}^*_{(\omega, v)}(\Pi,\Gamma) = (\Pi\times\omega + \Gamma\times v,\ \Gamma\times\omega)`.
    Casimirs :math:`|\Gamma|^2` and :math:`\Pi\cdot\Gamma` (not semisimple).
    """
    return SE3Algebra()


def sl2r() -> LieAlgebra:
    r"""sl(2, R) with basis ``H = diag(1, -1)``, ``E = [[0, 1], [0, 0]]``, ``F = [[0, 0], [1, 0]]``.

    :math:`[H, E] = 2E`, :math:`[H, F] = -2F`, :math:`[E, F] = H`. Semisimple, non-compact: the
    quadratic Casimir :math:`\mu^T K^{-1}\mu` (Killing form ``K``) is indefinite.
    """
    basis = np.array([[[1.0, 0.0], [0.0, -1.0]], [[0.0, 1.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]]])
    return LieAlgebra.from_matrix_basis(basis, name="sl2r")
