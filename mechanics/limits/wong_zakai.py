r"""The Wong–Zakai anomaly: mechanics driven by coloured noise and its white-noise limit.

Rigid body (paper eq. (srbcoloured), **no added drift**): with :math:`\Omega = \mathbb I^{-1}\Pi`,

.. math::

    d\Pi = \Pi\times\Omega\,dt + \vartheta\,\Pi\times(\Pi\times\Omega)\,dt
          + \sum_i \Pi\times\xi_i\, dB^{\varepsilon,i}, \qquad \xi_i = \sigma e_i,

driven by the (smooth) coloured noise ``B^ε = ∫ y/ε dt`` of :class:`roughpaths.ColouredNoiseDriver`.

Limit (Friz–Oberhauser, ``docs/conventions.md``). ``B^ε`` converges as a rough path to
``(MB, M BB^{Strat} Mᵀ + N(t−s))`` with ``M = A⁻¹D`` and ``N = Alt(ΣA⁻ᵀ)`` (**B^ε coordinates**).
Driving the fields :math:`V_i(\Pi) = \Pi\times\xi_i` by ``MB`` is driving the fields
:math:`\Pi\times\xi'_k` by ``B`` with ``ξ'_k = Σ_i M_{ik} ξ_i = σ M[:, k]`` (the columns of ``σA⁻¹D``);
the perturbation ``N`` adds the drift :math:`\tfrac12\sum_{ij}N^{ij}[V_i,V_j](\Pi) = \Pi\times c` with

.. math:: c = \tfrac12\sum_{i,j} N^{ij}\,\xi_i\times\xi_j = \sigma^2 (N_{23}, -N_{13}, N_{12})

(the Lévy torque, built from the *original* ``ξ_i = σe_i`` because ``N`` lives in B^ε coordinates;
equivalently ``s_B = M⁻¹NM⁻ᵀ`` paired with the ``ξ'_k``). The limit is therefore

.. math::

    d\Pi = \Pi\times(\Omega + c)\,dt + \vartheta\,\Pi\times(\Pi\times\Omega)\,dt
          + \sum_k \Pi\times\xi'_k\circ dB^k :

the torque enters the conservative part only. The dissipation of (srbcoloured) is built from
``h``, not ``h̃``, and Friz–Oberhauser does not touch the drift ``V_0``, so the limit is *not* the
paper's (srblevy) (whose dissipation uses ``h̃``) — :func:`rigid_body_wong_zakai_limit` exposes both
(``dissipation_shift``) and the tests tell them apart.

The paper's planar example (2dexample) is in :mod:`mechanics.limits.planar`.

Integrators. All systems are :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` rigid bodies (the
limit with ``levy_in_dissipation=False``: torque in the conservative term only) integrated by the
shared Casimir-preserving coadjoint schemes of :mod:`mechanics.integrators` (Lie–Heun by default):
``Π ↦ exp(ad*_σ)Π`` with ``σ = w̄Δt + η`` and the step's level-2 log-signature
``η = Σ ξ_i X^i + ½ Σ L^{ij} ξ_i×ξ_j`` (``L`` the step Lévy area). Each grid step of the coloured
driver carries the exact Chen-summed area of ``B^ε``, so steps of order ``ε²`` suffice (the paper
used steps far below ``ε²``); see ``benchmarks/bench_coloured_paper_scale.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughpaths import ColouredNoiseLimit, RoughPath, Solution, coloured_noise_limit, iter_coloured_noise, solve
from roughpaths.validation import (as_float_array, check_memory, check_positive_int, check_positive_real, check_rng,
                                   check_work)

from ..integrators import CoadjointSolver, LieHeun
from ..systems.hamiltonian import check_inertia
from ..systems.lie_poisson import levy_velocity
from ..systems.rigid_body import rigid_body

__all__ = [
    "RigidBodyWongZakai",
    "rigid_body_wong_zakai_limit",
    "simulate_wong_zakai_rigid_body",
]


@dataclass(frozen=True)
class RigidBodyWongZakai:
    r"""Coloured rigid body (srbcoloured) and its white-noise limit.

    Attributes
    ----------
    limit : ColouredNoiseLimit
        ``Σ``, ``M = A⁻¹D``, ``N`` (B^ε coordinates).
    sigma : float
    coloured_xi : ndarray ``(n, 3)``
        ``σ e_i``: noise vectors of the coloured system (driven by ``B^ε``; here ``n = 3``).
    limit_xi : ndarray ``(m, 3)``
        ``σ M[:, k]`` (rows): noise vectors of the limit, driven by the Brownian ``B``.
    torque : ndarray ``(3,)``
        ``c = ½ Σ N^{ij} ξ_i×ξ_j`` with ``ξ_i = σe_i``.
    perturbation_B : ndarray ``(m, m)`` or None
        ``M⁻¹ N M⁻ᵀ`` (``M`` square invertible): the same perturbation in ``B`` coordinates, i.e.
        ``levy_velocity(perturbation_B, limit_xi) == torque``.
    """

    limit: ColouredNoiseLimit
    sigma: float
    coloured_xi: np.ndarray
    limit_xi: np.ndarray
    torque: np.ndarray
    perturbation_B: np.ndarray | None


def rigid_body_wong_zakai_limit(A, D, sigma) -> RigidBodyWongZakai:
    r"""Noise vectors and Lévy torque of the white-noise limit of the coloured rigid body.

    Parameters
    ----------
    A : array_like ``(3, 3)``
    D : array_like ``(3, m)``
    sigma : float
        Noise amplitude of (srbcoloured): ``ξ_i = σ e_i``.

    Examples
    --------
    The paper's case ``A = kI + Λ`` (``Λ13 = 1``), ``k = 0.05``, ``σ = 0.05``:

    >>> from roughpaths import paper_coloured_noise_matrices
    >>> wz = rigid_body_wong_zakai_limit(*paper_coloured_noise_matrices(0.05), 0.05)
    >>> wz.torque.round(6)                       # σ² (N23, -N13, N12)
    array([ 0.      , -0.024938,  0.      ])
    >>> wz.limit_xi.round(4)[1]                  # σ A⁻¹D e_2 = σ/k e_2
    array([0., 1., 0.])
    """
    lim = coloured_noise_limit(A, D)
    if lim.A.shape[0] != 3:
        raise ValueError(f"the rigid body needs 3-dimensional coloured noise (A of shape (3, 3)), got "
                         f"A of shape {lim.A.shape}.")
    sg = check_positive_real(sigma, "sigma", allow_zero=True)
    cxi = sg * np.eye(3)
    lxi = (sg * lim.scaling).T.copy()
    c = levy_velocity(lim.levy_perturbation, cxi)
    M = lim.scaling
    sB = None
    if M.shape[0] == M.shape[1] and np.linalg.cond(M) < 1e12:
        Mi = np.linalg.inv(M)
        sB = Mi @ lim.levy_perturbation @ Mi.T
        sB = 0.5 * (sB - sB.T)
    return RigidBodyWongZakai(limit=lim, sigma=sg, coloured_xi=cxi, limit_xi=lxi, torque=c, perturbation_B=sB)


# ------------------------------------------------------------------------------- input checks
def _check_inertia3(inertia):
    return check_inertia(inertia, "inertia", dim=3)


def _check_method(method):
    if method is None:
        return LieHeun()
    if not isinstance(method, CoadjointSolver):
        raise TypeError(f"method must be a coadjoint solver instance (LieEuler(), LieHeun(), ImplicitMidpoint()), "
                        f"got {method!r}" + (f"; did you mean {method.__name__}()?" if isinstance(method, type)
                                             else "."))
    return method


def simulate_wong_zakai_rigid_body(A, D, eps, sigma, *, inertia=(1.0, 2.0, 3.0), theta=1.0, Pi0=(0.0, 0.0, 1.0),
                                   T=1.0, h=None, n_paths=1, rng, substeps=None, save_every=1,
                                   systems=("coloured", "limit", "no_torque"), chunk_steps=None, method=None):
    r"""Coloured rigid body (srbcoloured) and its limits, coupled through the same Brownian motion.

    Streams the exact coloured noise (:func:`roughpaths.iter_coloured_noise`) in time
    chunks (constant memory) and integrates, on the same draws, with the shared coadjoint
    integrators (:func:`roughpaths.solve` on each chunk's :class:`~roughpaths.RoughPath`):

    * ``"coloured"``: (srbcoloured), ``ξ_i = σe_i`` driven by the level-2 lift of ``B^ε``;
    * ``"limit"``: the white-noise limit, ``ξ'_k = σ(A⁻¹D)[:, k]`` driven by ``B`` with the Lévy torque
      ``c`` in the conservative part only (exact limit): ``rigid_body(..., s=s_B,
      levy_in_dissipation=False)`` with ``s_B = M⁻¹NM⁻ᵀ`` (for a non-invertible ``M = A⁻¹D``: the
      same RDE in B^ε coordinates, ``ξ_i = σe_i``, ``s = N``, driven by ``(MB, M𝔹Mᵀ)``);
    * ``"no_torque"``: the same without the torque (plain Stratonovich Wong–Zakai guess);
    * ``"srblevy"``: torque in both parts (dissipation from ``h̃``, the paper's (srblevy) model:
      ``levy_in_dissipation=True``).

    The limit systems use ``B``'s piecewise-linear lift over the sub-steps (its Lévy area is the
    conditional expectation given the sub-step increments).

    Parameters
    ----------
    A, D : array_like ``(3, 3)``, ``(3, m)``
    eps, sigma : float
    inertia, theta, Pi0 : rigid body data (``Pi0`` shape ``(3,)``)
    T : float
        Final time.
    h : float, optional
        Grid step (default ``ε²/(2‖A‖₂)``: the Chen-summed area makes steps of order ``ε²`` enough).
    n_paths : int
    rng : numpy.random.Generator
    substeps : int, optional
        Exact OU sub-steps per grid step (default: resolve ``ε²/‖A‖`` to ``0.5``).
    save_every : int
    systems : tuple of str
    chunk_steps : int, optional
    method : LieEuler() | LieHeun() | ImplicitMidpoint(...), optional
        Default ``LieHeun()``.

    Returns
    -------
    dict of str to roughpaths.Solution
        Per system in ``systems``, a :class:`~roughpaths.Solution` (as :func:`roughpaths.solve`
        returns): ``times`` every ``save_every``-th grid time and ``T``, ``states`` ``(n_paths, K, 3)``,
        ``final`` the states at ``T``; ``stats`` holds ``h``, ``n_steps`` and the solver.
    """
    wz = rigid_body_wong_zakai_limit(A, D, sigma)
    rng = check_rng(rng)
    known = ("coloured", "limit", "no_torque", "srblevy")
    if isinstance(systems, str):
        raise TypeError(f"systems must be a tuple of system names, got the string {systems!r}; pass "
                        f"systems=({systems!r},).")
    try:
        systems = tuple(systems)
    except TypeError:
        raise TypeError(f"systems must be a tuple of names from {known}, got {systems!r}.") from None
    for name in systems:
        if name not in known:
            raise ValueError(f"systems: unknown system {name!r}; choose from {known}.")
    nrm = float(np.linalg.norm(wz.limit.A, 2))
    n_paths = check_positive_int(n_paths, "n_paths")
    n_steps, h = _coloured_grid(eps, T, h, nrm, n_paths)
    save_every = check_positive_int(save_every, "save_every")
    K = n_steps // save_every + 1 + (n_steps % save_every > 0)   # every save_every-th step, and always T
    check_memory(8.0 * 3 * n_paths * K * (len(systems) + 1),
                 f"the saved states ({len(systems)} system(s) x {n_paths} paths x {K} times x 3)",
                 "save fewer times (a larger save_every) or use fewer paths")
    method = _check_method(method)
    inertia = _check_inertia3(inertia)
    P0 = as_float_array(Pi0, "Pi0", ndim=1, last_dims=(3,))
    saved_idx = np.append(np.arange(0, n_steps + 1, save_every), n_steps)[:K]   # T is saved (Solution.final)
    M = wz.limit.scaling
    if wz.perturbation_B is not None:          # the limit's noise vectors σ M[:, k], driven by B
        lxi, ls, lmap = wz.limit_xi, wz.perturbation_B, None
    else:                                      # B^ε coordinates: σ e_i driven by MB (same RDE)
        lxi, ls, lmap = wz.coloured_xi, wz.limit.levy_perturbation, M

    def body(xi, s=None, lid=True):
        return rigid_body(inertia, xi=xi, s=s, theta=theta, levy_in_dissipation=lid)

    cfg = {
        "coloured": (body(wz.coloured_xi), False),
        "limit": (body(lxi, ls, False), True),
        "no_torque": (body(lxi), True),
        "srblevy": (body(lxi, ls, True), True),
    }
    state = {k: np.tile(P0, (n_paths, 1)) for k in systems}
    out = {k: np.empty((n_paths, K, 3)) for k in systems}
    for k in systems:
        out[k][:, 0] = P0
    done = 0
    for inc, area, binc, barea, _ in iter_coloured_noise(wz.limit.A, wz.limit.D, eps, h, n_steps, rng=rng,
                                                         n_paths=n_paths, substeps=substeps,
                                                         chunk_steps=chunk_steps):
        S = inc.shape[1]
        times = (done + np.arange(S + 1)) * h
        X = RoughPath(inc, area, times=times, kind="geometric", check=False)
        if any(cfg[k][1] for k in systems):
            if lmap is not None:
                binc, barea = binc @ lmap.T, lmap @ barea @ lmap.T
            XB = RoughPath(binc, barea, times=times, kind="geometric", check=False)
        j = np.arange(done + 1, done + S + 1)
        keep = (j % save_every == 0) | (j == n_steps)
        slots = np.searchsorted(saved_idx, j[keep])
        for k in systems:
            system, use_b = cfg[k]
            st = solve(system, XB if use_b else X, state[k], method).states          # (P, S + 1, 3)
            out[k][:, slots] = st[:, 1:][:, keep]
            state[k] = st[:, -1].copy()
        done += S
    times = saved_idx * h
    stats = {"solver": repr(method), "n_steps": n_steps, "h": h, "batch_shape": (n_paths,)}
    return {k: Solution(times=times, states=out[k], failed_step=np.full(n_paths, -1), stats=dict(stats))
            for k in systems}


def _coloured_grid(eps, T, h, nrm, n_paths):
    """Check ``eps``, ``T``, ``h`` and return ``(n_steps, h)``, refusing an ε-driven step count
    (``T/h`` with the default ``h = ε²/(2‖A‖)``) that would run for ever."""
    eps = check_positive_real(eps, "eps")
    T = check_positive_real(T, "T")
    h = eps ** 2 / (2.0 * nrm) if h is None else check_positive_real(h, "h")
    steps = max(1.0, T / h)
    check_work(steps * n_paths, f"T={T:.3g} with step h={h:.3g} (eps={eps:.3g}) is {steps:.3g} steps for "
               f"n_paths={n_paths}", "use fewer paths, a larger eps, a larger h or a shorter T")
    n_steps = max(1, int(round(steps)))
    return n_steps, T / n_steps
