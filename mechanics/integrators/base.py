r"""Casimir-preserving coadjoint solvers: :class:`LieEuler`, :class:`LieHeun`, :class:`ImplicitMidpoint`.

They follow the solver contract of :class:`roughpaths.Solver`, so a Lie–Poisson system is solved
like any RDE: ``roughpaths.solve(system, X, mu0, LieHeun())`` returns a :class:`roughpaths.Solution`.
Every scheme updates

.. math::  \mu_{n+1} = \exp(\mathrm{ad}^*_{\sigma_n})\,\mu_n,

so :math:`\mu_{n+1}` stays on the coadjoint orbit of :math:`\mu_n` and every Casimir is conserved to
round-off. The Lie-algebra increment is :math:`\sigma_n = \bar w\,\Delta t_n + \eta_n` with the
*stochastic velocity* (:meth:`~mechanics.systems.lie_poisson.LiePoissonSystem.stochastic_velocity`)

.. math::  \eta_n = \sum_i \xi_i X^i_{n} + \tfrac12\sum_{i,j} A^{ij}_n[\xi_i,\xi_j],

built from the step's increment :math:`X_n` and Lévy area :math:`A_n = \tfrac12(\mathbb X_n - \mathbb X_n^T)`
(the level-2 log-signature), and a drift velocity :math:`\bar w` (:math:`w(\mu) = \nabla\tilde h +
\vartheta(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp`, :mod:`mechanics.lie_poisson`):

* :class:`LieEuler`: :math:`\bar w = w(\mu_n)`;
* :class:`LieHeun`: :math:`\bar w = \tfrac12(w(\mu_n) + w(\mu^*))`,
  :math:`\mu^* = (1 + \mathrm{ad}^*_{\sigma^*} + \tfrac12(\mathrm{ad}^*_{\sigma^*})^2)\mu_n`,
  :math:`\sigma^* = w(\mu_n)\Delta t + \eta_n` (the predictor only feeds the drift velocity; its
  :math:`O(|\sigma|^3)` error keeps both orders);
* :class:`ImplicitMidpoint` (the paper's appendix scheme): :math:`\bar w = w(\tfrac12(\mu_n+\mu_{n+1}))`,
  solved per batch member by the chord method (:mod:`mechanics.integrators._chord`).

Why the area term, and why :math:`+\tfrac12`: the noise fields are linear, :math:`V_i\mu = B_i\mu` with
:math:`B_i = \mathrm{ad}^*_{\xi_i}`; Davie's step contains :math:`B_jB_i\mathbb X^{ij} = \tfrac12(B_iX^i)^2 +
\tfrac12A^{ij}(B_jB_i - B_iB_j)`, and :math:`B_jB_i - B_iB_j = \mathrm{ad}^*_{[\xi_i,\xi_j]}`. The second-order
term of :math:`\exp(\mathrm{ad}^*_\sigma)` reproduces both exactly when :math:`\sigma\ni\tfrac12A^{ij}[\xi_i,\xi_j]`.
With the area the schemes have strong order 1 on Brownian rough paths (order 2 in ``dt`` without
noise for Lie–Heun and the midpoint rule); without it (a level-1 driver: zero step area) only
order ½ for non-commuting ``ξ``. The solver holds no flag for this: it reads the level from the
driver. Perturbing the area, :math:`A\mapsto A + \mathsf s\Delta t`,
adds exactly :math:`\ell\Delta t = \tfrac12\mathsf s^{ij}[\xi_i,\xi_j]\Delta t` to :math:`\sigma_n`: the
discrete Proposition 2.1.

Implementation: a system on a :class:`~mechanics.systems.matrix_algebra.MatrixLieAlgebra` (so(n), su(N), ...,
any size) without forces holds the state as its matrix for a whole block and updates it by conjugation,
:math:`M\mapsto e^{-\sigma}Me^{\sigma}` (:mod:`mechanics.integrators._isospectral`; the implicit midpoint by
fixed-point iteration there). Otherwise a system with a quadratic Hamiltonian and no forces runs compiled block
kernels:
for a :class:`~mechanics.systems.lie_algebra.SO3Algebra` the hand-written ones of
:mod:`mechanics.integrators._so3_kernels`, for an :class:`~mechanics.systems.lie_algebra.SE3Algebra` (the heavy
top) and the implicit midpoint rule that of :mod:`mechanics.integrators._se3_kernels` (Lie–Euler and Lie–Heun on se(3) go to the generic kernel's entry point, which runs its se(3) block kernel,
:mod:`mechanics.integrators._se3_block`: the generic kernel's numbers bit for bit in about half its time), and
otherwise the generic kernel of
:mod:`mechanics.integrators._generic_kernels`, compiled once for all algebras (the structure constants are
data: su(2), sl(2, R), so(4), semidirect products, a user's basis). A system on a
:class:`~mechanics.MatrixLieAlgebra` runs the isospectral steps of :mod:`mechanics.integrators._isospectral`
(the state held as a matrix, updated by conjugation); where a quadratic system could run either way (a small
matrix algebra, or a structure-constant algebra with a matrix basis) a cost model picks the cheaper
(:mod:`mechanics.integrators._dispatch`; it depends on the system and the step sizes, never on the batch).
Otherwise (forces, a non-quadratic
Hamiltonian) a batched numpy loop (``Ad*exp`` in closed form for so(3)/se(3), :func:`roughpaths.expm_batched`
per member otherwise). Either way a batch member's result depends on its own data only; a member that
fails is reported through ``first_bad`` (contract item 8).

Steps per member (contract item 10, ``member_times``): ``integrate`` also takes ``times (..., K + 1)``, one grid
per member, and ``step`` a ``dt (..., 1)``; the compiled block kernels take one time grid, so without forces every
member takes a compiled scalar step with its own ``dt`` on a structure-constant algebra
(:func:`._so3_kernels.so3_member_steps`, :func:`._se3_kernels.se3_member_steps`,
:func:`._generic_member_steps.generic_member_steps`), or the numpy path's conjugation of matrices, member by member
in one call, where the cost model predicts that cheaper (``_dispatch.member_system``; at noise 0.4 per component
su(4) and larger, as a matrix algebra or from a matrix basis). Adaptive solves (:func:`roughpaths.solve` with
``step_control=PIController(...)``) use it by default, each member with steps of its own; at ``rtol = 10⁻³``, 1000
paths, one thread, the stochastic rigid body (101 attempts a path) took 0.81-0.86 s of CPU, of which the tree's walk
is about 0.65 s (0.94-1.12 s with the numpy steps), the heavy top 0.42-0.44 s (0.73-1.15 s).

Threads: the compiled kernels split the paths into blocks and run them on numba's threads; set their
number with ``numba.set_num_threads(k)`` (or the environment variable ``NUMBA_NUM_THREADS`` before the
first import). The isospectral steps share blocks of members between as many Python threads (numpy releases
the GIL in its products). The results are bitwise the same for any number of threads.

Forces (``force``, ``noise_forces`` of the system) are added outside the group update, on the numpy
path, by :mod:`mechanics.integrators._forced` (orders and Casimirs stated there); the compiled
kernels, and so systems without forces, are unchanged.
"""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths import Solver
from roughpaths.validation import as_float_array, check_positive_int

from ..systems.lie_algebra import LieAlgebra, SE3Algebra, SO3Algebra
from ..systems.lie_poisson import LiePoissonSystem
from ..systems.matrix_algebra import MatrixLieAlgebra
from . import _generic_kernels, _isospectral, _se3_kernels, _so3_kernels
from ._chord import chord_solve
from ._dispatch import choose, member_system
from ._forced import forced_sigma_and_state
from ._generic_member_steps import generic_member_steps

__all__ = ["CoadjointSolver", "LieEuler", "LieHeun", "ImplicitMidpoint", "ChordConvergenceError",
           "check_on_orbit"]


def _member_dt(dt, shape):
    """A step's ``dt``: a float (one step for the batch), or an array ``(..., 1)`` of steps per member broadcast to
    ``shape[:-1] + (1,)`` (contract item 10)."""
    if np.ndim(dt) == 0:
        return float(dt)
    return np.broadcast_to(np.asarray(dt, dtype=np.float64), shape[:-1] + (1,))


class ChordConvergenceError(RuntimeError):
    """The implicit midpoint's chord iteration did not converge (the message names the step and members)."""


class CoadjointSolver(Solver):
    r"""Base class of the coadjoint solvers (contract of :class:`roughpaths.Solver`).

    The driving level is the driver's: a level-2 geometric driver (a Brownian driver with Lévy areas,
    a :class:`~roughpaths.RoughPath`) puts its step Lévy areas into :math:`\sigma_n` (strong order 1);
    a level-1 driver (``BrownianDriver(..., levy_area=None)``, ``X.to_level1()``) drives with the
    increments alone, i.e. zero step Lévy area (strong order ½ for non-commuting ``ξ``).
    ``increment_level = 2`` is what a step consumes at most; :func:`roughpaths.solve` passes no areas
    for a level-1 driver.
    """

    calculus = "stratonovich"
    preserves = ("casimirs",)
    smooth_order = 2.0
    _code = -1

    #: at most increments and areas; a level-1 driver gives increments alone (zero area)
    increment_level = 2
    #: strong order on Brownian rough paths with a level-2 driver (½ with a level-1 driver, non-commuting ξ)
    order = 1.0
    #: steps per member in one call (contract item 10): adaptive steps per member (module docstring)
    member_times = True

    def __init__(self, **unexpected):
        if unexpected:
            raise TypeError(f"{type(self).__name__}() takes no arguments, got {', '.join(sorted(unexpected))}; the "
                            f"driving level is the driver's: for increments only pass a level-1 driver "
                            f"(BrownianDriver(..., levy_area=None) or X.to_level1()).")

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"

    # -------------------------------------------------------------- checks (contract 5-6)
    def check_fields(self, fields):
        """Accept a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` (contract item 5)."""
        if not isinstance(fields, LiePoissonSystem):
            raise TypeError(f"{self!r} integrates a mechanics.LiePoissonSystem (e.g. mechanics.rigid_body(...)), "
                            f"got {type(fields).__name__}; for roughpaths.VectorFields use Davie(), LogODE(), "
                            f"Heun() or Euler().")
        return fields

    def check_driver(self, driver) -> None:
        """Accept a geometric driver of level 2, or a level-1 driver (zero step area) (contract item 6)."""
        level = driver.level
        if level > 2:
            raise ValueError(f"{self!r} uses the driver up to level 2, but the driver is a level-{level} rough "
                             f"path; its higher levels would be dropped. Truncate it deliberately (e.g. "
                             f"RoughPathN.to_rough_path()) or use a level-3 solver on VectorFields.")
        kind = getattr(driver, "kind", "geometric")
        if level == 2 and kind not in ("geometric", "stratonovich"):
            raise ValueError(f"the driver is a {kind!r} rough path; the coadjoint schemes solve the geometric "
                             f"(Stratonovich-type) RDE. Convert an Itô lift with XX + ½(t-s)I first.")

    # -------------------------------------------------------------- the scheme
    def _sigma(self, system, mu, dt, eta):
        """Lie-algebra increment ``sigma (..., n)`` and a convergence mask (``None``: always converged)."""
        raise NotImplementedError

    def _advance(self, system, mu, dt, eta):
        """One step: ``(new mu, ok)``; failed members (non-finite or not converged) are NaN, ``ok`` False."""
        mu, eta = np.broadcast_arrays(np.asarray(mu, dtype=np.float64), np.asarray(eta, dtype=np.float64))
        dt = _member_dt(dt, mu.shape)
        if not isinstance(dt, float) and isinstance(system.algebra, LieAlgebra) \
                and system.hamiltonian.is_quadratic and not system.has_forces:
            # steps per member on structure constants: compiled, the same scheme (._so3_kernels, ._se3_kernels,
            # ._generic_member_steps)
            b, n = mu.shape[:-1], mu.shape[-1]
            steps = (_so3_kernels.so3_member_steps if isinstance(system.algebra, SO3Algebra) else
                     _se3_kernels.se3_member_steps if isinstance(system.algebra, SE3Algebra) else
                     generic_member_steps)
            new, ok, conv = steps(system, self._code, getattr(self, "tol", 1e-13), getattr(self, "max_iter", 1),
                                  mu.reshape(-1, n), dt.reshape(-1), eta.reshape(-1, n))
            return new.reshape(mu.shape), ok.reshape(b), None if conv is None else conv.reshape(b)
        live = np.all(np.isfinite(mu), axis=-1) & np.all(np.isfinite(eta), axis=-1)
        new = np.full(mu.shape, np.nan)
        conv = None
        if np.all(live):                        # members are computed alone or as a subset: same bits
            mu_l, eta_l, dt_l = mu, eta, dt
        else:
            mu_l, eta_l, dt_l = mu[live], eta[live], dt if isinstance(dt, float) else dt[live]
        with np.errstate(all="ignore"):
            sigma, conv_l = self._sigma(system, mu_l, dt_l, eta_l)
            sig_ok = np.all(np.isfinite(sigma), axis=-1)
            if not np.all(sig_ok):
                sigma = np.where(sig_ok[..., None], sigma, 0.0)
            new_l = system.algebra.Ad_star_exp(sigma, mu_l)
        ok_l = np.all(np.isfinite(new_l), axis=-1) & sig_ok
        if conv_l is not None:
            ok_l = ok_l & conv_l
            conv = np.ones(mu.shape[:-1], dtype=bool)
            conv[live] = conv_l
        new[live] = np.where(ok_l[..., None], new_l, np.nan)
        ok = np.zeros(mu.shape[:-1], dtype=bool)
        ok[live] = ok_l
        return new, ok, conv

    def _advance_forced(self, system, mu, dt, eta, dx, dxx):
        """One step of the forced scheme (:mod:`._forced`): ``(new mu, ok, converged)``."""
        n, m = mu.shape[-1], dx.shape[-1]
        batch = np.broadcast_shapes(np.shape(mu)[:-1], np.shape(eta)[:-1], np.shape(dx)[:-1])
        mu = np.broadcast_to(np.asarray(mu, dtype=np.float64), batch + (n,))
        eta = np.broadcast_to(np.asarray(eta, dtype=np.float64), batch + (n,))
        dx = np.broadcast_to(np.asarray(dx, dtype=np.float64), batch + (m,))
        dxx = None if dxx is None else np.broadcast_to(np.asarray(dxx, dtype=np.float64), batch + (m, m))
        live = np.all(np.isfinite(mu), axis=-1) & np.all(np.isfinite(eta), axis=-1) & np.all(np.isfinite(dx), axis=-1)
        sub = (lambda a: a) if np.all(live) else (lambda a: a if a is None or isinstance(a, float) else a[live])
        new = np.full(batch + (n,), np.nan)
        dt = _member_dt(dt, batch + (n,))
        with np.errstate(all="ignore"):
            new_l, conv_l = forced_sigma_and_state(self._code, system, sub(mu), sub(dt), sub(eta), sub(dx), sub(dxx),
                                                   self._sigma)
        ok_l = np.all(np.isfinite(new_l), axis=-1)
        conv = None
        if conv_l is not None:
            ok_l = ok_l & conv_l
            conv = np.ones(batch, dtype=bool)
            conv[live] = conv_l
        new[live] = np.where(ok_l[..., None], new_l, np.nan)
        ok = np.zeros(batch, dtype=bool)
        ok[live] = ok_l
        return new, ok, conv

    @staticmethod
    def _eta(system, dX, dXX):
        areas = None if dXX is None else 0.5 * (dXX - np.swapaxes(dXX, -1, -2))
        return system.stochastic_velocity(dX, areas)

    def step_nbytes(self, fields):
        """Bytes of one step's temporaries per member (contract item 11): ``N × N`` matrices on a matrix algebra
        (the state, the step's increment and the exponential's powers), the generic estimate otherwise."""
        alg = fields.algebra
        if isinstance(alg, MatrixLieAlgebra):
            return 24.0 * alg.matrix_size ** 2 * alg.dtype.itemsize + 8.0 * fields.n_noise ** 2
        return None

    def step(self, fields, y, t, dt, dX, dXX):
        """One step (contract item 7; ``dt`` a scalar, or ``(..., 1)`` per member, item 10); a failed member comes
        back NaN."""
        if fields.has_forces:
            return self._advance_forced(fields, y, dt, self._eta(fields, dX, dXX), dX, dXX)[0]
        system = member_system(fields) if np.ndim(dt) else fields
        return self._advance(system, y, dt, self._eta(system, dX, dXX))[0]

    def integrate(self, fields, y, times, dX, dXX, save, stop_on_failure=True):
        """Advance a block of steps (contract item 8); compiled kernels where they apply (module docstring).

        Raises :class:`ChordConvergenceError` (with ``stop_on_failure``) when a member's chord
        iteration fails; other failures are reported through ``first_bad``.
        """
        system = fields
        n = system.dim
        batch = y.shape[:-1]
        times = np.asarray(times, dtype=np.float64)
        own = times.ndim > 1                    # each member on its own times (contract item 10): the numpy path
        if own:
            times = np.broadcast_to(times, batch + times.shape[-1:])
            system = member_system(system)
        dts = np.diff(times)
        nk = dts.shape[-1]
        nsave = int(np.count_nonzero(save))
        plain = system.hamiltonian.is_quadratic and not system.has_forces and not own     # forces: the numpy path
        matrix = isinstance(system.algebra, MatrixLieAlgebra) and not system.has_forces and not own
        if plain and not isinstance(system.algebra, (SO3Algebra, SE3Algebra)):
            system, matrix = choose(system, dts)     # constants or matrices, by a cost model (._dispatch)
        if matrix:                      # the state held as a matrix, updated by conjugation (._isospectral)
            nb = int(np.prod(batch, dtype=np.int64))
            d = dX.shape[-1]
            dX = np.broadcast_to(dX, batch + (nk, d)).reshape(nb, nk, d)
            if dXX is not None:
                dXX = np.broadcast_to(dXX, batch + (nk, d, d)).reshape(nb, nk, d, d)
            y2, saved, first_bad, reason = _isospectral.integrate_matrix(
                self._code, system, getattr(self, "tol", 1e-13), getattr(self, "max_iter", 1), y.reshape(nb, n), dX,
                dXX, dts, save, stop_on_failure)
            y2, saved, first_bad = y2.reshape(batch + (n,)), saved.reshape(batch + (nsave, n)), first_bad.reshape(batch)
            chord = (reason == _isospectral.CHORD_FAILED).reshape(batch)
        elif plain:
            # so(3): the hand-written kernel; se(3) (the heavy top): the hand-written kernel for the implicit
            # midpoint rule; every other case: the generic one (which runs its se(3) block kernel,
            # ._se3_block, for se(3) Lie-Euler / Lie-Heun)
            if isinstance(system.algebra, SO3Algebra):
                kernels, run = _so3_kernels, _so3_kernels.integrate_so3
            elif isinstance(system.algebra, SE3Algebra) and self._code == 2:
                kernels, run = _se3_kernels, _se3_kernels.integrate_se3
            else:
                kernels, run = _generic_kernels, _generic_kernels.integrate_generic
            nb = int(np.prod(batch, dtype=np.int64))
            d = dX.shape[-1]
            dX = np.ascontiguousarray(np.broadcast_to(dX, batch + (nk, d)).reshape(nb, nk, d), dtype=np.float64)
            if dXX is not None:
                dXX = np.ascontiguousarray(np.broadcast_to(dXX, batch + (nk, d, d)).reshape(nb, nk, d, d),
                                           dtype=np.float64)
            y2, saved, first_bad, reason = run(
                system, self._code, getattr(self, "tol", 1e-13), getattr(self, "max_iter", 1), y.reshape(nb, n), dX,
                dXX, dts, save, stop_on_failure)
            y2, saved, first_bad = y2.reshape(batch + (n,)), saved.reshape(batch + (nsave, n)), first_bad.reshape(batch)
            chord = (reason == kernels.CHORD_FAILED).reshape(batch)
        else:
            saved = np.full(batch + (nsave, n), np.nan)
            first_bad = np.full(batch, -1, dtype=np.int64)
            chord = np.zeros(batch, dtype=bool)
            slot = 0
            y2 = y
            eta = self._eta(system, dX, dXX)                                    # (B_X..., K, n)
            for k in range(nk):
                dt = dts[..., k, None] if own else float(dts[k])
                if system.has_forces:
                    y2, ok, conv = self._advance_forced(system, y2, dt, eta[..., k, :], dX[..., k, :],
                                                        None if dXX is None else dXX[..., k, :, :])
                else:
                    y2, ok, conv = self._advance(system, y2, dt, eta[..., k, :])
                new = ~ok & (first_bad < 0)
                if new.any():
                    first_bad[new] = k
                    if conv is not None:
                        chord |= new & ~np.broadcast_to(conv, batch)
                if save[k]:
                    saved[..., slot, :] = y2
                    slot += 1
                if stop_on_failure and new.any():
                    break
        if stop_on_failure and chord.any():
            raise self._chord_error(np.argwhere(chord), first_bad, times, dts)
        return y2, saved, first_bad

    def _chord_error(self, members, first_bad, times, dts):
        k = int(min(first_bad[tuple(m)] for m in members))
        if times.ndim > 1:                     # times per member: those of the first member that failed at step k
            first = next(tuple(m) for m in members if first_bad[tuple(m)] == k)
            times, dts = times[first], dts[first]
        who = ", ".join(str(tuple(int(i) for i in m)) for m in members[:8])
        return ChordConvergenceError(
            f"implicit midpoint: the chord iteration did not converge at step {k} of the block from "
            f"t = {float(times[0]):.6g} (step from t = {float(times[k]):.6g}, dt = {float(dts[k]):.3g}) for batch "
            f"member(s) {who}: tolerance {self.tol:g} not reached after max_iter = {self.max_iter} iterations. "
            f"Reduce dt (or use LieHeun), or raise max_iter / tol; roughpaths.solve(..., on_failure='mask') "
            f"keeps the other members.")


class LieEuler(CoadjointSolver):
    r"""Explicit Lie–Euler: :math:`\sigma_n = w(\mu_n)\Delta t + \eta_n`.

    Declared orders: strong order 1 on Brownian rough paths with the Lévy area (½ without), order 1
    in ``dt`` on smooth drivers. Preserves the Casimirs.
    """

    smooth_order = 1.0
    _code = 0

    def _sigma(self, system, mu, dt, eta):
        return system.drift_velocity(mu) * dt + eta, None


class LieHeun(CoadjointSolver):
    r"""Explicit Lie–Heun (predictor–corrector on the drift velocity; the noise part is additive in
    :math:`\mathfrak g`, so it enters predictor and corrector alike).

    Declared orders: strong order 1 on Brownian rough paths with the Lévy area (½ without), order 2
    in ``dt`` on smooth drivers. Preserves the Casimirs.
    """

    smooth_order = 2.0
    _code = 1

    def _sigma(self, system, mu, dt, eta):
        alg = system.algebra
        w0 = system.drift_velocity(mu)
        sig0 = w0 * dt + eta
        fin = np.all(np.isfinite(sig0), axis=-1, keepdims=True)     # a non-finite member fails alone
        sig0 = np.where(fin, sig0, 0.0)
        a = alg.ad_star(sig0, mu)
        mu_p = mu + a + 0.5 * alg.ad_star(sig0, a)                  # predictor: 2nd-order Taylor of exp
        fin = fin & np.all(np.isfinite(mu_p), axis=-1, keepdims=True)  # an overflowed predictor fails too
        mu_p = np.where(fin, mu_p, 0.0)
        sigma = 0.5 * (w0 + system.drift_velocity(mu_p)) * dt + eta
        return np.where(fin, sigma, np.nan), None


class ImplicitMidpoint(CoadjointSolver):
    r"""The paper's implicit midpoint Munthe-Kaas step, :math:`\bar w = w(\tfrac12(\mu_n+\mu_{n+1}))`.

    Solved for :math:`\sigma_n` per batch member by the chord method:
    :math:`\sigma\leftarrow\sigma - J^{-1}F(\sigma)`,
    :math:`F(\sigma) = \sigma - w(\tfrac12(\mu_n + e^{\mathrm{ad}^*_\sigma}\mu_n))\Delta t - \eta_n`,
    :math:`J = I - \tfrac{\Delta t}2 Dw(\mu_n) L(\mu_n)` with :math:`L(\mu)\delta = \mathrm{ad}^*_\delta\mu`
    (frozen for the step). A member stops when :math:`\max|\Delta\sigma| \le` ``tol``
    :math:`(1 + |\sigma|_\infty)`; one that has not after ``max_iter`` iterations fails
    (:class:`ChordConvergenceError`, or marked with ``on_failure="mask"``).

    Declared orders: strong order 1 with the Lévy area (½ without), order 2 in ``dt`` on smooth
    drivers. Preserves the Casimirs.
    """

    smooth_order = 2.0
    _code = 2

    def __init__(self, tol: float = 1e-13, max_iter: int = 50):
        if isinstance(tol, bool) or not isinstance(tol, numbers.Real) or not np.isfinite(tol) or tol <= 0:
            raise ValueError(f"tol must be a positive finite number, got {tol!r}.")
        self.tol = float(tol)
        self.max_iter = check_positive_int(max_iter, "max_iter")

    def __repr__(self) -> str:
        return f"ImplicitMidpoint(tol={self.tol:g}, max_iter={self.max_iter})"

    def _sigma(self, system, mu, dt, eta):
        return chord_solve(system, mu, dt, eta, self.tol, self.max_iter)


# ---------------------------------------------------------------------- orbit checks
def check_on_orbit(system: LiePoissonSystem, mu, orbit, *, rtol: float = 1e-10, name: str = "mu0"):
    """Require ``system.casimirs(mu) == orbit`` (relative tolerance ``rtol``) for every batch entry.

    ``orbit`` has shape ``(k,)`` or broadcasts against ``(..., k)``. Raises ``ValueError`` naming the
    Casimir, the worst batch index, the value and the expected value.
    """
    cas = system.casimirs(mu)
    target = as_float_array(orbit, "orbit")
    if target.ndim == 0:
        target = target[None]
    try:
        target = np.broadcast_to(target, cas.shape)
    except ValueError:
        raise ValueError(f"orbit must give the {cas.shape[-1]} Casimir value(s) "
                         f"{system.algebra.casimir_names}, got shape {np.shape(orbit)}.") from None
    err = np.abs(cas - target) / np.maximum(1.0, np.abs(target))
    if np.any(err > rtol):
        flat = int(np.argmax(err))
        idx = np.unravel_index(flat, err.shape)
        k = idx[-1]
        names = system.algebra.casimir_names
        label = names[k] if k < len(names) else f"Casimir {k}"
        raise ValueError(f"{name} is off the coadjoint orbit: {label} = {float(cas[idx])!r} at batch index "
                         f"{tuple(int(i) for i in idx[:-1])}, expected {float(target[idx])!r} (relative error "
                         f"{err[idx]:.3g} > {rtol:g}). A Casimir-preserving method keeps the orbit of the "
                         f"initial state; project {name} onto the orbit (e.g. normalise |Pi|) or pass the "
                         f"orbit it lies on.")
