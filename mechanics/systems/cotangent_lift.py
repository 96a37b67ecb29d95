r"""The cotangent lift of a Lie–Poisson system: a rough symplectic system on :math:`T^*\mathbb R^N` that reduces to it.

Paper, Section 2.3: a rough Hamiltonian system on phase space whose Hamiltonians are *collective*,
:math:`\mathcal H_0 = h\circ J` and :math:`\mathcal H_k = \xi_k\circ J`, driven by the perturbed rough path
:math:`\widetilde{\mathbf X} = (X, \mathbb X + \mathsf s(t-s))`, is mapped by the momentum map :math:`J` onto
the Lie–Poisson equation *with* the Lévy-area correction driven by :math:`\mathbf X`.
:func:`cotangent_lift` builds that phase-space system for a :class:`~mechanics.LiePoissonSystem` and a
matrix representation :math:`A:\mathfrak g\to\mathfrak{gl}(N)`.

Convention
----------
The library's (``docs/conventions.md``) Lie–Poisson equation is :math:`d\mu = \mathrm{ad}^*_{\nabla\tilde h}\mu\,dt + \mathrm{ad}^*_{\xi_k}\mu\,d\mathbf X^k`
with :math:`\mathrm{ad}^*_\xi\mu = \mathrm{ad}(\xi)^T\mu` (body frame; on so(3) :math:`\Pi\times\xi`): the
*minus* Lie–Poisson bracket :math:`\{f, g\}(\mu) = -\langle\mu, [\nabla f, \nabla g]\rangle`. The momentum
map that is a Poisson map onto it is the cotangent lift of the **right** action
:math:`q\mapsto A(g)^{-1}q` of :math:`G` on :math:`\mathbb R^N` (the paper's :math:`J_R`), whose generators are
:math:`\xi_{\mathbb R^N}(q) = -A_\xi q`:

.. math::

    J(q, p)(\xi) = -\,p\cdot A_\xi q,\qquad
    X_{\mathcal H_\xi}(q, p) = (-A_\xi q,\; A_\xi^T p),\qquad
    X_{\mathcal H_0}(q, p) = X_{\mathcal H_\Omega}(q, p)\big|_{\Omega = \nabla h(J(q, p))},

with Hamilton's equations :math:`\dot q = \partial\mathcal H/\partial p`, :math:`\dot p = -\partial\mathcal H/\partial q`
(:math:`X_{\mathcal H} = \mathbb J\nabla\mathcal H`, :math:`\mathbb J = \begin{pmatrix}0 & I\\ -I & 0\end{pmatrix}`).
Then :math:`dJ\cdot X_{\mathcal H_\xi} = \mathrm{ad}^*_\xi J` and :math:`J` is equivariant,
:math:`J(e^{-A_\eta}q, e^{A_\eta^T}p) = \exp(\mathrm{ad}^*_\eta)J(q, p)`. On so(3) with :math:`A_\xi = \hat\xi`:
:math:`J(q, p) = p\times q` and :math:`X_{\mathcal H_\xi} = (q\times\xi, p\times\xi)`.
(The left-action formulas :math:`J = +p\cdot A_\xi q`, :math:`X = (A_\xi q, -A_\xi^T p)` give the *plus*
bracket, :math:`dJ\cdot X_{\mathcal H_\xi} = -\mathrm{ad}^*_\xi J`: the noise of the opposite sign.)

The Friz–Oberhauser drift of the lifted noise is :math:`\tfrac12\mathsf s^{ij}[X_{\mathcal H_i}, X_{\mathcal H_j}]
= X_{\ell\circ J}` with :math:`\ell = \tfrac12\mathsf s^{ij}[\xi_i,\xi_j]`, so the reduced equation is the
library's :math:`\tilde h = h + \langle\mu, \ell\rangle`. The paper prints
:math:`df = \{f, h - \tfrac12\mathsf s^{ij}\{\xi_i,\xi_j\}\}dt + \{f,\xi_k\}d\mathbf Z^k`; with the minus bracket
above, :math:`-\tfrac12\mathsf s^{ij}\{\xi_i,\xi_j\}(\mu) = +\langle\mu,\ell\rangle`, so Section 2.3's printed sign
agrees with the library (it is the rigid-body formulas (srblevy) etc. that flip it).

What is exact, what is approximate
----------------------------------
Exact (round-off): the noise fields, their Jacobians and brackets (linear), :math:`J`, the
intertwining :math:`dJ\cdot X_{\mathcal H_\xi} = \mathrm{ad}^*_\xi J`, the drift and its Jacobian (given an
exact Hessian of ``h``). Approximate: any numerical solution of the lifted RDE (the drift is cubic,
so :class:`roughpaths.LogODE` uses RK4 inner steps); its image under :math:`J` matches the Lie–Poisson
solution up to the schemes' discretisation errors (strong order 1 on Brownian rough paths).

Only the conservative part is lifted: a system with double-bracket dissipation (``theta > 0``) is
refused (that drift is not Hamiltonian).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughpaths.validation import as_float_array

from .lie_algebra import hat, se3, sl2r
from .lie_poisson import LiePoissonSystem

__all__ = ["CotangentLift", "cotangent_lift", "BUILTIN_REPRESENTATIONS"]

#: Names accepted by :func:`cotangent_lift` for ``representation`` and the space each acts on.
BUILTIN_REPRESENTATIONS = {"so3": "R^3 (A_xi = hat(xi))", "se3": "homogeneous R^4 ([[hat(w), v], [0, 0]])",
                           "sl2": "R^2 (H, E, F)"}


def _builtin(name: str) -> np.ndarray:
    if name == "so3":
        return hat(np.eye(3))
    if name == "se3":
        return np.array(se3().basis, dtype=np.float64)
    return np.array(sl2r().basis, dtype=np.float64)


def _check_representation(rep, algebra, atol=1e-10):
    """The representation matrices ``(n, N, N)`` as float64, or ValueError/TypeError naming the fix."""
    if isinstance(rep, str):
        key = {"sl2r": "sl2"}.get(rep, rep)
        if key not in BUILTIN_REPRESENTATIONS:
            raise ValueError(f"representation={rep!r} is not a built-in one; use one of "
                             f"{sorted(BUILTIN_REPRESENTATIONS)} or pass the matrices of the basis, shape (n, N, N).")
        rep, label = _builtin(key), f"the built-in representation {key!r}"
    else:
        label = "representation"
        arr = np.asarray(rep)
        if arr.dtype.kind == "c":
            raise TypeError("representation must be real matrices (phase space is real); for su(2) use the "
                            "real so(3) representation 'so3'.")
        if arr.dtype.kind not in "biuf":
            raise TypeError(f"representation must be an array of numbers of shape (n, N, N) or a name in "
                            f"{sorted(BUILTIN_REPRESENTATIONS)}, got dtype {arr.dtype}.")
        rep = as_float_array(arr, "representation")
    n = algebra.dim
    if rep.ndim != 3 or rep.shape[1] != rep.shape[2] or rep.shape[0] != n or rep.shape[1] < 1:
        raise ValueError(f"{label} must have shape (n, N, N) = ({n}, N, N): one N x N matrix per basis element "
                         f"of the {n}-dimensional Lie algebra {algebra.name!r}, got shape {rep.shape}.")
    c = algebra.structure_constants
    comm = np.einsum("iab,jbc->ijac", rep, rep) - np.einsum("jab,ibc->ijac", rep, rep)
    want = np.einsum("ijk,kab->ijab", c, rep)
    scale = max(1.0, float(np.max(np.abs(comm))), float(np.max(np.abs(want))))
    defect = float(np.max(np.abs(comm - want)))
    if defect > atol * scale:
        hint = ""
        if float(np.max(np.abs(comm + want))) <= atol * scale:
            hint = (" They satisfy [A_i, A_j] = -c^k_ij A_k: an anti-representation; pass -representation "
                    "(or its transposes with a minus sign, the dual representation) instead.")
        raise ValueError(f"{label} is not a representation of {algebra.name!r}: the matrix commutators "
                         f"[A_i, A_j] must equal sum_k c[i, j, k] A_k with c = algebra.structure_constants "
                         f"(the library's bracket), but differ by up to {defect:.3g}.{hint} If these matrices "
                         f"define your algebra, build it with LieAlgebra.from_matrix_basis(matrices).")
    return rep


class _CollectiveDrift:
    """``y -> K(∇h(J(y))) y`` and its Jacobian: the Hamiltonian field of ``h ∘ J`` (picklable)."""

    def __init__(self, lift):
        self.lift = lift

    def __call__(self, y):
        lift = self.lift
        omega = lift.system.hamiltonian.gradient(lift.momentum_of_state(y))
        return lift.hamiltonian_field(omega, y)

    def jacobian(self, y):
        lift = self.lift
        y = np.asarray(y, dtype=np.float64)
        mu = lift.momentum_of_state(y)
        omega = lift.system.hamiltonian.gradient(mu)
        hess = lift.system.hamiltonian.hessian(mu)                              # (..., n, n)
        gen = lift.generator_matrices                                           # (n, 2N, 2N)
        k_omega = np.einsum("...k,kab->...ab", omega, gen)
        fields_k = np.einsum("kab,...b->...ak", gen, y)                         # (..., 2N, n): K_k y
        grad_j = lift.momentum_gradient(y)                                      # (..., n, 2N)
        domega = hess @ grad_j                                                  # (..., n, 2N)
        return k_omega + fields_k @ domega


@dataclass(frozen=True, eq=False)
class CotangentLift:
    r"""The lifted (phase-space) system of :func:`cotangent_lift`; state ``y = (q, p)``, shape ``(..., 2N)``.

    Attributes
    ----------
    system : LiePoissonSystem
        The reduced system (its ``s`` is the area perturbation to drive the lift with).
    representation : ndarray ``(n, N, N)``
        The matrices :math:`A_k` of the basis of :math:`\mathfrak g`.
    generator_matrices : ndarray ``(n, 2N, 2N)``
        :math:`K_k = \mathrm{diag}(-A_k, A_k^T)`: :math:`X_{\mathcal H_{e_k}}(y) = K_k y`.
    noise_matrices : ndarray ``(m, 2N, 2N)``
        :math:`\xi_i^k K_k`: the driving fields :math:`X_{\mathcal H_{\xi_i}}`.
    vector_fields : roughpaths.LinearVectorFields
        Noise :math:`X_{\mathcal H_{\xi_i}}` (linear) and drift :math:`X_{h\circ J}` with its Jacobian, on
        :math:`\mathbb R^{2N}`. Drive it with :meth:`perturbed` ``(X)``.
    """

    system: LiePoissonSystem
    representation: np.ndarray
    generator_matrices: np.ndarray
    noise_matrices: np.ndarray
    vector_fields: object

    @property
    def dim_config(self) -> int:
        """``N``, the dimension of configuration space (phase space is ``2N``)."""
        return self.representation.shape[1]

    @property
    def symplectic_matrix(self) -> np.ndarray:
        r""":math:`\mathbb J = \begin{pmatrix}0 & I\\ -I & 0\end{pmatrix}` (``(2N, 2N)``), :math:`X_{\mathcal H} = \mathbb J\nabla\mathcal H`."""
        n = self.dim_config
        eye, zero = np.eye(n), np.zeros((n, n))
        return np.block([[zero, eye], [-eye, zero]])

    def _split(self, y):
        y = as_float_array(y, "y", last_dims=(2 * self.dim_config,))
        return y[..., :self.dim_config], y[..., self.dim_config:]

    def momentum(self, q, p) -> np.ndarray:
        r""":math:`J(q, p)_k = -p\cdot A_k q` in the algebra's dual coordinates; ``q, p (..., N)`` → ``(..., n)``."""
        n = self.dim_config
        q = as_float_array(q, "q", last_dims=(n,))
        p = as_float_array(p, "p", last_dims=(n,))
        return -np.einsum("...a,kab,...b->...k", p, self.representation, q)

    def momentum_of_state(self, y) -> np.ndarray:
        """:meth:`momentum` of stacked states ``y = (q, p)``, ``(..., 2N)`` → ``(..., n)``."""
        q, p = self._split(y)
        return self.momentum(q, p)

    def momentum_gradient(self, y) -> np.ndarray:
        r""":math:`\partial J_k/\partial y` as ``[..., k, :]`` (``(..., n, 2N)``): :math:`(-A_k^T p, -A_k q)`."""
        q, p = self._split(y)
        a = self.representation
        return -np.concatenate([np.einsum("kba,...b->...ka", a, p), np.einsum("kab,...b->...ka", a, q)], axis=-1)

    def hamiltonian_field(self, xi, y) -> np.ndarray:
        r""":math:`X_{\mathcal H_\xi}(y) = (-A_\xi q, A_\xi^T p)` for ``xi (..., n)``, ``y (..., 2N)`` → ``(..., 2N)``."""
        xi = as_float_array(xi, "xi", last_dims=(self.system.dim,))
        y = as_float_array(y, "y", last_dims=(2 * self.dim_config,))
        k = np.einsum("...k,kab->...ab", xi, self.generator_matrices)
        return (k @ y[..., None])[..., 0]

    def perturbed(self, X):
        """The driver of the lift: ``X.perturb(system.s)`` (the rough path :math:`\\widetilde{\\mathbf X}`)."""
        return X.perturb(self.system.s)

    def phase_state(self, mu) -> np.ndarray:
        r"""A state ``y = (q, p)`` with :math:`J(q, p) = \mu`, ``mu (..., n)`` → ``(..., 2N)``.

        so(3) (``representation="so3"``): :math:`q` is the unit vector orthogonal to :math:`\mu` built from
        the coordinate axis least aligned with it, and :math:`p = q\times\mu` (then :math:`p\times q = \mu`,
        :math:`|p| = |\mu|`). Otherwise: a fixed list of trial ``q`` (basis vectors, then seeded normals)
        with the least-squares ``p`` of the linear equation :math:`J(q, \cdot) = \mu`; failing that,
        minimum-norm Newton iterations on :math:`J(q, p) = \mu` from seeded starts (deterministic). Raises ValueError if
        :math:`\mu` is not reached (e.g. se(3) on :math:`\mathbb R^4` reaches only :math:`\Pi\cdot\Gamma = 0`):
        pick ``(q, p)`` yourself and start the Lie–Poisson solution at :meth:`momentum` ``(q, p)``.
        """
        mu = as_float_array(mu, "mu", last_dims=(self.system.dim,))
        flat = mu.reshape(-1, mu.shape[-1])
        out = np.stack([self._phase_state_one(m) for m in flat]) if flat.shape[0] else np.zeros((0, 2 * self.dim_config))
        return out.reshape(mu.shape[:-1] + (2 * self.dim_config,))

    def _phase_state_one(self, mu):
        n_cfg, a = self.dim_config, self.representation
        scale = max(1.0, float(np.max(np.abs(mu))))
        if a.shape == (3, 3, 3) and np.array_equal(a, hat(np.eye(3))):
            axis = np.eye(3)[int(np.argmin(np.abs(mu)))]
            q = np.cross(mu, axis)
            q = axis if np.linalg.norm(q) == 0.0 else q / np.linalg.norm(q)
            return np.concatenate([q, np.cross(q, mu)])
        rng = np.random.default_rng(0)
        trials = list(np.eye(n_cfg)) + list(rng.standard_normal((8, n_cfg)))
        for q in trials:                                                        # J(q, .) is linear in p
            m = -np.einsum("kab,b->ka", a, q)
            p, *_ = np.linalg.lstsq(m, mu, rcond=None)
            if float(np.max(np.abs(m @ p - mu))) <= 1e-10 * scale:
                return np.concatenate([q, p])
        for y in rng.standard_normal((8, 2 * n_cfg)):                            # minimum-norm Newton on (q, p)
            for _ in range(60):
                r = self.momentum_of_state(y) - mu
                if float(np.max(np.abs(r))) <= 1e-13 * scale:
                    return y
                y = y - np.linalg.lstsq(self.momentum_gradient(y), r, rcond=None)[0]
        raise ValueError(f"mu = {mu} is not reached by J from the trial configurations (the image of J may be "
                         f"a union of coadjoint orbits only); pick (q, p) yourself and use momentum(q, p).")


def cotangent_lift(system, representation) -> CotangentLift:
    r"""Lift a Lie–Poisson system to the rough symplectic system on :math:`T^*\mathbb R^N` it is the reduction of.

    Parameters
    ----------
    system : LiePoissonSystem
        Algebra :math:`\mathfrak g` (dimension ``n``), Hamiltonian ``h``, noise vectors ``xi (m, n)``,
        Lévy parameter ``s (m, m)``; ``theta`` must be 0 (dissipation is not Hamiltonian).
    representation : str or array_like ``(n, N, N)``
        Matrices :math:`A_k` of the basis with :math:`[A_i, A_j] = c^k_{ij}A_k` (checked, with the
        library's bracket), or a built-in name: ``"so3"`` (:math:`\mathbb R^3`), ``"se3"`` (homogeneous
        :math:`\mathbb R^4`), ``"sl2"`` (:math:`\mathbb R^2`).

    Returns
    -------
    CotangentLift
        ``vector_fields`` (noise :math:`X_{\xi_i\circ J}(q, p) = (-A_{\xi_i}q, A_{\xi_i}^Tp)`, drift
        :math:`X_{h\circ J}`), ``momentum(q, p)`` (:math:`J(q, p)_k = -p\cdot A_kq`), ``phase_state(mu)``,
        ``perturbed(X)``. Signs: module docstring (right-action momentum map; the library's minus
        Lie–Poisson bracket).

    Examples
    --------
    >>> import numpy as np
    >>> from mechanics.systems import rigid_body, cotangent_lift
    >>> lift = cotangent_lift(rigid_body([1.0, 2.0, 3.0], sigma=0.5), "so3")
    >>> q, p = np.array([1.0, 2.0, 0.0]), np.array([0.0, 1.0, 3.0])
    >>> lift.momentum(q, p)                        # J(q, p) = p x q
    array([-6.,  3., -1.])
    >>> y = np.concatenate([q, p])
    >>> dJ = lift.momentum_gradient(y)              # dJ . X_{xi_i o J} = ad*_{xi_i} J = J x xi_i
    >>> bool(np.allclose(dJ @ lift.vector_fields.fields(y), lift.system.noise(lift.momentum(q, p))))
    True
    """
    from roughpaths import LinearVectorFields

    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a LiePoissonSystem (e.g. mechanics.rigid_body(...)), got "
                        f"{type(system).__name__}.")
    if system.theta != 0.0:
        raise ValueError(f"system has double-bracket dissipation (theta={system.theta}), which is not a "
                         f"Hamiltonian vector field and has no symplectic lift; pass a system with theta=0.")
    if not isinstance(representation, str) and not hasattr(representation, "__len__") \
            and not hasattr(representation, "__array__"):
        raise TypeError(f"representation must be a name in {sorted(BUILTIN_REPRESENTATIONS)} or an array of "
                        f"shape (n, N, N), got {type(representation).__name__}.")
    rep = _check_representation(representation, system.algebra)
    gen = np.stack([np.block([[-a, np.zeros_like(a)], [np.zeros_like(a), a.T]]) for a in rep])
    noise = np.einsum("ik,kab->iab", system.xi, gen)
    for arr in (rep, gen, noise):
        arr.setflags(write=False)
    lift = CotangentLift(system, rep, gen, noise, None)
    drift = _CollectiveDrift(lift)
    object.__setattr__(lift, "vector_fields", LinearVectorFields(noise, drift=drift, drift_jacobian=drift.jacobian))
    return lift
