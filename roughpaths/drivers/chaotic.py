r"""Drivers from deterministic chaos: the sums of an observable along the orbits of a map, lifted exactly.

Set-up (Kelly and Melbourne, Ann. Probab. 2016; Chevyrev, Friz, Korepanov, Melbourne and Zhang, arXiv
1712.01343). A map ``T`` of a state space with an invariant probability measure ``μ``, an observable
``v`` with values in ``R^d`` and ``∫ v dμ = 0``, initial points ``y_0 ~ μ``, the orbit ``y_{j+1} = T(y_j)``.
With ``n`` fast steps per unit of slow time, the driver is the path

.. math:: W_n(t) = n^{-1/2} \sum_{j < n t} v(y_j),

whose increments over the fast steps are ``Δ_j = n^{-1/2} v(y_j)``. :class:`ChaoticDriver` delivers it on
a uniform grid whose step ``h`` holds ``m = n h`` fast steps, as a level-2 rough path, lazily in blocks
(the :class:`~roughpaths.drivers.base.Driver` contract), so that :func:`roughpaths.solve` and every norm
take it.

Which lift. Each step carries the exact level-2 lift of the **piecewise-linear** interpolation of the
fast sums (each fast step a straight segment), by Chen's identity over the ``m`` segments:

.. math:: \mathbb{X}_{t_k, t_{k+1}} = \sum_{i < j} Δ_i\otimes Δ_j + \tfrac12 \sum_j Δ_j\otimes Δ_j,

sums over the fast steps ``i, j`` of the grid step (entry ``[a, b]`` pairs the earlier ``Δ^a`` with the
later ``Δ^b``: the library's ``XX[a, b] = ∫ (X^a − X^a_s) dX^b``). It is geometric (kind
``"geometric"``); the iterated sums of the piecewise-*constant* path, ``Σ_{i<j} Δ_i⊗Δ_j``, differ from it
by the symmetric ``½ Σ Δ_j⊗Δ_j``. Which limit each converges to, and why the antisymmetric part is a
Lévy-area drift, is derived in :mod:`roughpaths.drivers.chaotic_limit`.

Maps. A :class:`ChaoticMap` holds a vectorised ``step`` (state ``(P, k)`` to state ``(P, k)``), a
``sample(rng, P)`` of the invariant measure and ``coordinates`` (what the observable sees). Two are
built in:

* :func:`cat_map`: a hyperbolic toral automorphism ``y ↦ A y mod 1`` (``A ∈ SL(2, Z)``) iterated **exactly**
  on the lattice ``(2⁻⁶⁴ Z / Z)²`` in ``uint64`` arithmetic (wrap-around is the reduction mod 1). The
  uniform measure on the lattice is invariant exactly (``A`` is a bijection of the lattice since
  ``det A = ±1`` is odd) and is sampled exactly (``2 × 64`` random bits per point). For integer frequency
  vectors ``k`` with ``0 < |k_i| < 2⁶⁴`` the lattice average of ``e^{2πi k·y}`` is 0, as the Lebesgue
  integral: correlations of trigonometric observables are those of Lebesgue measure, which is what makes
  the closed-form example of :mod:`~roughpaths.drivers.chaotic_limit` exact. In floating point the map
  would be unusable after ~50 steps (every step multiplies the rounding error by the expansion
  ``λ ≈ 2.6``; the doubling map ``2y mod 1`` even collapses to 0 after 53 steps); on the lattice the orbit
  of a point has period ``3·2⁶³`` for the default ``A = [[2, 1], [1, 1]]`` — no orbit here comes near it.
* :func:`lorenz63_map`: the Lorenz-63 flow sampled at a step ``τ`` (classical RK4, ``substeps``
  steps per sample): a continuous-time chaotic system as a map. Its sampler starts near the attractor
  and runs a spin-up: it samples the physical measure only approximately (to the mixing of the spin-up).

Cost (CPU time measured on the 2-core machine of this project, numpy only, 4096 orbits, lift included): the
cat map with the two-sine observable of the tests 0.27 µs per orbit and fast step (4096 orbits × 10⁴ fast
steps: 11 s; 10⁶ fast steps would take about 18 minutes), dominated by the sines (0.14 µs); Lorenz-63 (RK4,
one stage per sample) 0.21 µs. The cat map's orbit is computed for a whole chunk at once from the powers
``A^j mod 2⁶⁴`` (0.03 µs). No compiled kernel: the remaining work is a few vectorised operations over the
orbits, near memory speed already, and a compiled map would add a compile to every first call.
"""

from __future__ import annotations

import math

import numpy as np

from ..paths.rough_path import RoughPath
from ..validation import (as_float_array, check_batch_shape, check_memory, check_positive_int, check_positive_real,
                          check_seed, check_work)
from ._seeded import SeededDriver

__all__ = ["ChaoticMap", "cat_map", "lorenz63_map", "ChaoticDriver", "observable_orbits"]

_TWO64 = 2.0 ** 64


class ChaoticMap:
    r"""A deterministic map with a sampler of its invariant measure, vectorised over orbits.

    Parameters
    ----------
    step : callable
        ``step(state) -> state``: one application of ``T`` to a state array of shape ``(P, k)``; it may
        update ``state`` in place and return it.
    sample : callable
        ``sample(rng, P) -> state`` of shape ``(P, k)``: ``P`` independent draws from the invariant
        measure, using only the ``numpy.random.Generator`` ``rng``.
    dim : int
        ``k``, the dimension of a state.
    coordinates : callable, optional
        ``coordinates(states) -> float array`` of the same shape ``(..., k)``: what the observable is
        evaluated on (default: the states as float64).
    name : str
        Shown in messages.
    orbit : callable, optional
        ``orbit(state, c, out) -> state``: store ``c`` consecutive states, the first being ``state``, in
        ``out[:, :c]`` (shape ``(P, ≥c, k)``) and return the state after them. Default: ``c`` calls of
        ``step``; a map with a closed form for ``T^j`` (the cat map) vectorises over ``j`` instead.

    Examples
    --------
    >>> import numpy as np
    >>> rot = ChaoticMap(lambda y: (y + 0.5) % 1.0, lambda rng, P: rng.random((P, 1)), dim=1, name="rotation")
    >>> rot.step(np.array([[0.25]]))
    array([[0.75]])
    """

    def __init__(self, step, sample, *, dim, coordinates=None, name: str = "user map", orbit=None):
        for arg, f in (("step", step), ("sample", sample)):
            if not callable(f):
                raise TypeError(f"{arg} must be a callable, got {type(f).__name__}; see ChaoticMap's docstring.")
        if coordinates is not None and not callable(coordinates):
            raise TypeError(f"coordinates must be a callable or None, got {type(coordinates).__name__}.")
        self.step, self.sample, self.dim = step, sample, check_positive_int(dim, "dim")
        self.coordinates = coordinates if coordinates is not None else (lambda s: np.asarray(s, dtype=np.float64))
        self.name = str(name)
        if orbit is not None and not callable(orbit):
            raise TypeError(f"orbit must be a callable or None, got {type(orbit).__name__}.")
        self._orbit = orbit

    def orbit(self, state, c: int, out):
        """Fill ``out[:, :c]`` with ``c`` consecutive states from ``state``; return the next state."""
        if self._orbit is not None:
            return self._orbit(state, c, out)
        for j in range(c):
            out[:, j] = state
            state = self.step(state)
            if state.shape != out.shape[:1] + out.shape[2:]:
                raise ValueError(f"the step of {self.name} returned shape {state.shape} for states of shape "
                                 f"{out.shape[:1] + out.shape[2:]}; it must keep the shape (P, k).")
        return state

    def __repr__(self) -> str:
        return f"ChaoticMap({self.name!r}, dim={self.dim})"

    def initial_states(self, rng, n: int) -> np.ndarray:
        """``n`` draws of the sampler, checked: shape ``(n, k)``, finite if floating."""
        s = np.asarray(self.sample(rng, n))
        if s.shape != (n, self.dim):
            raise ValueError(f"the sampler of {self.name} returned shape {s.shape} for {n} points; it must "
                             f"return ({n}, {self.dim}) (sample(rng, P) -> (P, dim)).")
        if s.dtype.kind == "f" and not np.all(np.isfinite(s)):
            raise ValueError(f"the sampler of {self.name} returned non-finite states; it must draw from "
                             f"the invariant measure.")
        return s


def cat_map(matrix=((2, 1), (1, 1))) -> ChaoticMap:
    r"""A hyperbolic toral automorphism ``y ↦ A y mod 1``, iterated exactly on the lattice ``(2⁻⁶⁴Z/Z)²``.

    Parameters
    ----------
    matrix : array_like of int, shape ``(2, 2)``
        ``A`` with ``det A = ±1`` and ``|tr A| > 2`` (hyperbolic: the map is mixing for Lebesgue measure).
        Default Arnold's cat map ``[[2, 1], [1, 1]]``.

    Returns
    -------
    ChaoticMap
        States ``uint64`` of shape ``(P, 2)`` (the lattice point ``y = state · 2⁻⁶⁴``); ``coordinates``
        gives ``y`` in ``[0, 1]`` (float64, rounded); ``sample`` draws the uniform lattice measure, which
        is invariant (module docstring).

    Examples
    --------
    >>> import numpy as np
    >>> T = cat_map()
    >>> s = np.array([[2**63, 2**62]], dtype=np.uint64)        # y = (1/2, 1/4)
    >>> T.coordinates(T.step(s.copy())).tolist()               # (2·½ + ¼, ½ + ¼) mod 1
    [[0.25, 0.75]]
    """
    A = np.asarray(matrix)
    if A.shape != (2, 2) or A.dtype.kind not in "iu":
        raise ValueError(f"matrix must be a 2x2 integer matrix, got {np.asarray(matrix)!r}.")
    a_, b_, c_, d_ = (int(x) for x in A.ravel())                    # Python integers: int64 products can wrap
    det, tr = a_ * d_ - b_ * c_, a_ + d_
    A = A.astype(np.int64)
    if abs(det) != 1 or abs(tr) <= 2:
        raise ValueError(f"matrix must have det = ±1 and |trace| > 2 (a hyperbolic toral automorphism), got "
                         f"det = {det}, trace = {tr}; e.g. [[2, 1], [1, 1]].")
    a = [[np.uint64(int(c) % 2**64) for c in row] for row in A]      # two's complement: A mod 2^64

    def step(s):
        x, y = s[:, 0].copy(), s[:, 1]
        s[:, 0] = a[0][0] * x + a[0][1] * y                           # uint64 arithmetic wraps: mod 2^64
        s[:, 1] = a[1][0] * x + a[1][1] * y
        return s

    if A.tolist() == [[2, 1], [1, 1]]:
        def step(s):                                                  # noqa: F811 - the default, 2 additions
            s[:, 1] += s[:, 0]
            s[:, 0] += s[:, 1]
            return s

    powers = {}

    def orbit(s, c, out):
        """``T^j s`` for ``j < c`` at once: ``A^j mod 2^64`` (exact Python integers) times ``s``, wrapping."""
        if c not in powers:
            P_ = [[1, 0], [0, 1]]
            rows = []
            for _ in range(c + 1):
                rows.append([[v % 2**64 for v in r] for r in P_])
                P_ = [[sum(int(A[i, l]) * P_[l][j] for l in range(2)) % 2**64 for j in range(2)] for i in range(2)]
            powers[c] = np.array(rows, dtype=np.uint64)                   # (c + 1, 2, 2)
        pw = powers[c]
        x, y = s[:, None, 0], s[:, None, 1]
        out[:, :c, 0] = pw[None, :c, 0, 0] * x + pw[None, :c, 0, 1] * y
        out[:, :c, 1] = pw[None, :c, 1, 0] * x + pw[None, :c, 1, 1] * y
        nxt = np.empty_like(s)
        nxt[:, 0] = pw[c, 0, 0] * s[:, 0] + pw[c, 0, 1] * s[:, 1]
        nxt[:, 1] = pw[c, 1, 0] * s[:, 0] + pw[c, 1, 1] * s[:, 1]
        return nxt

    def sample(rng, P):
        return rng.integers(0, 2**64, size=(P, 2), dtype=np.uint64)

    def coordinates(s):
        return np.asarray(s).astype(np.float64) * (1.0 / _TWO64)

    return ChaoticMap(step, sample, dim=2, coordinates=coordinates, name=f"cat map {A.tolist()}", orbit=orbit)


def lorenz63_map(tau: float = 0.05, *, sigma: float = 10.0, rho: float = 28.0, beta: float = 8.0 / 3.0,
                 substeps: int = 1, spinup: float = 50.0) -> ChaoticMap:
    r"""The Lorenz-63 flow ``ẋ = σ(y − x), ẏ = x(ρ − z) − y, ż = xy − βz`` sampled every ``tau``.

    Parameters
    ----------
    tau : float
        Sampling step (fast time per map step).
    sigma, rho, beta : float
        The parameters (default the classical 10, 28, 8/3).
    substeps : int
        RK4 steps per sample (step ``tau/substeps``).
    spinup : float
        Flow time run by the sampler from ``(x, y, z) = (8 g₁, 8 g₂, 25 + 8 g₃)``, ``g`` standard normal,
        before returning the points: an approximate sample of the physical measure.

    Returns
    -------
    ChaoticMap
        Float states ``(x, y, z)``, shape ``(P, 3)``. The map and the sampler commute with the symmetry
        ``(x, y, z) ↦ (−x, −y, z)`` (RK4 is equivariant under linear symmetries), so odd observables such
        as ``x`` and ``y`` have mean zero. For the flow's normalisation ``ε ∫ v dt`` with ``n = 1/(ε² τ)``,
        multiply the observable by ``√τ``.

    Examples
    --------
    >>> import numpy as np
    >>> L = lorenz63_map(0.01, spinup=1.0)
    >>> y = L.initial_states(np.random.default_rng(0), 4)
    >>> y.shape, bool(np.all(np.abs(y[:, 2] - 25) < 30))
    ((4, 3), True)
    """
    tau = check_positive_real(tau, "tau")
    sigma, rho, beta = (check_positive_real(v, nm) for v, nm in ((sigma, "sigma"), (rho, "rho"), (beta, "beta")))
    substeps = check_positive_int(substeps, "substeps")
    spinup = check_positive_real(spinup, "spinup", allow_zero=True)
    h = tau / substeps

    def f(u):
        x, y, z = u[:, 0], u[:, 1], u[:, 2]
        return np.stack([sigma * (y - x), x * (rho - z) - y, x * y - beta * z], axis=1)

    def step(u):
        with np.errstate(over="ignore", invalid="ignore"):       # a divergence is reported below
            for _ in range(substeps):
                k1 = f(u)
                k2 = f(u + (0.5 * h) * k1)
                k3 = f(u + (0.5 * h) * k2)
                k4 = f(u + h * k3)
                u = u + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if not np.all(np.isfinite(u)):
            raise ValueError(f"the Lorenz-63 RK4 step tau/substeps = {h:g} diverged; use a smaller tau or more "
                             f"substeps.")
        return u

    def sample(rng, P):
        steps = int(math.ceil(spinup / tau))
        check_work(float(P) * steps * substeps, f"the Lorenz-63 spin-up ({P} points x {steps} samples x {substeps} "
                   f"RK4 steps)", "use a shorter spinup or a larger tau")
        # the state, the four RK4 stages and their temporaries: 7-9 arrays of P x 3 floats measured, 10 counted
        check_memory(8.0 * 3 * 10 * P, f"the Lorenz-63 spin-up of {P} points (10 x {P} x 3 floats)", "use fewer orbits")
        u = 8.0 * rng.standard_normal((P, 3)) + np.array([0.0, 0.0, 25.0])
        for _ in range(steps):
            u = step(u)
        return u

    return ChaoticMap(step, sample, dim=3, name=f"Lorenz-63 (sigma={sigma:g}, rho={rho:g}, beta={beta:g}) "
                                                f"sampled every tau={tau:g}")


def _check_fast(fast_map, observable):
    if not isinstance(fast_map, ChaoticMap):
        raise TypeError(f"fast_map must be a ChaoticMap (e.g. cat_map() or lorenz63_map()), got "
                        f"{type(fast_map).__name__}; wrap your own T and sampler in ChaoticMap(step, sample, dim=k).")
    if not callable(observable):
        raise TypeError(f"observable must be a callable v(y) mapping coordinates (..., {fast_map.dim}) to "
                        f"(..., d), got {type(observable).__name__}.")


def _observe(fast_map, observable, states, d=None) -> np.ndarray:
    """``v`` on a chunk of states ``(P, c, k)`` (or ``(P, k)``), checked: shape ``(..., d)``, finite, float64."""
    v = np.asarray(observable(fast_map.coordinates(states)))
    if v.dtype.kind not in "biuf":
        kind = "complex" if v.dtype.kind == "c" else "not numbers"
        raise TypeError(f"observable must return real numbers, got dtype {v.dtype} ({kind}); return e.g. the real "
                        f"and imaginary parts as separate components.")
    v = np.asarray(v, dtype=np.float64)
    want = states.shape[:-1]
    if v.ndim != len(want) + 1 or v.shape[:-1] != want or (d is not None and v.shape[-1] != d):
        raise ValueError(f"observable returned shape {v.shape} for coordinates of shape {states.shape}; it "
                         f"must return {want + ((d,) if d else ('d',))} (vectorised over the leading axes).")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"observable returned non-finite values on orbits of {fast_map.name}; check the "
                         f"map and the observable.")
    return v


def observable_orbits(fast_map, observable, length: int, *, seed, batch_shape=()) -> np.ndarray:
    r"""The observable along orbits from the invariant measure: ``v(y_j)`` for ``j < length``.

    The data of the Green–Kubo estimator :func:`~roughpaths.drivers.chaotic_limit.green_kubo`.

    Parameters
    ----------
    fast_map : ChaoticMap
    observable : callable
        ``v``: coordinates ``(..., k)`` to values ``(..., d)``.
    length : int
        Fast steps per orbit.
    seed : int or numpy.random.SeedSequence
        Seeds the sampler of the initial points (the dynamics is deterministic).
    batch_shape : tuple of int
        Independent orbits.

    Returns
    -------
    ndarray, shape ``(*batch_shape, length, d)``

    Examples
    --------
    >>> import numpy as np
    >>> v = observable_orbits(cat_map(), lambda y: np.sin(2 * np.pi * y), 5, seed=1, batch_shape=(3,))
    >>> v.shape
    (3, 5, 2)
    """
    _check_fast(fast_map, observable)
    length = check_positive_int(length, "length")
    shape = check_batch_shape(batch_shape)
    P = int(np.prod(shape, dtype=np.int64))
    check_memory(8.0 * P * length * (fast_map.dim + 8), f"the orbits ({P} x {length} fast steps)",
                 "use fewer or shorter orbits")
    state = fast_map.initial_states(np.random.default_rng(check_seed(seed)), P)
    d = _observe(fast_map, observable, state[:, None, :]).shape[-1]
    check_memory(8.0 * P * length * d + (4 << 20) * (2.0 + 2.0 * d / fast_map.dim),
                 f"the orbits ({P} x {length} fast steps x {d} components) and a chunk of states",
                 "use fewer or shorter orbits")
    out = np.empty((P, length, d))
    c = max(1, min(length, (4 << 20) // max(1, 8 * P * fast_map.dim)))
    buf = np.empty((P, c, fast_map.dim), dtype=state.dtype)
    for j0 in range(0, length, c):
        cc = min(c, length - j0)
        state = fast_map.orbit(state, cc, buf)
        out[:, j0:j0 + cc] = _observe(fast_map, observable, buf[:, :cc], d)
    return out.reshape(shape + (length, d))


class ChaoticDriver(SeededDriver):
    r"""The normalised sums ``n^{-1/2} Σ_{j<nt} v(y_j)`` of an observable along chaotic orbits, lifted.

    Parameters
    ----------
    fast_map : ChaoticMap
        The map ``T`` and its sampler (:func:`cat_map`, :func:`lorenz63_map` or your own).
    observable : callable
        ``v``: coordinates ``(..., k)`` to ``(..., d)``, vectorised, with ``∫ v dμ = 0``.
    n : float
        Fast steps per unit of time; ``n · dt`` must be a positive integer ``m`` (fast steps per grid step).
    seed : int or numpy.random.SeedSequence
        Seeds the initial points (drawn once for the whole batch with ``default_rng(seed)``).
    times : array_like, optional
        A uniform grid; or ``dt`` and ``n_steps`` (from ``t0``).
    dt, n_steps, t0 : optional
    batch_shape : tuple of int
        Independent orbits.
    block_bytes : int
        Target memory of one block of fast steps (default 4 MiB); changes the numbers at most by rounding.

    Notes
    -----
    Increments ``Σ Δ_j`` and areas ``Σ_{i<j} Δ_i⊗Δ_j + ½ Σ Δ_j⊗Δ_j`` over the ``m`` fast steps of each grid
    step (the piecewise-linear lift, geometric; module docstring), ``Δ_j = n^{-1/2} v(y_j)``. The work
    (``P · n_steps · m`` fast steps) is checked against the work budget before anything runs, the memory
    of a block against the memory budget. :meth:`select` keeps the drawn initial points of the chosen
    orbits (the same orbits, equal to rounding).

    Examples
    --------
    >>> import numpy as np
    >>> v = lambda y: np.sin(2 * np.pi * y)
    >>> drv = ChaoticDriver(cat_map(), v, 400, seed=0, dt=0.05, n_steps=20, batch_shape=(3,))
    >>> X = drv.rough_path()
    >>> X.batch_shape, X.dim, X.kind, drv.fast_steps_per_step
    ((3,), 2, 'geometric', 20)
    """

    def __init__(self, fast_map, observable, n, *, seed, times=None, dt=None, n_steps=None, t0=0.0, batch_shape=(),
                 block_bytes=4 << 20):
        _check_fast(fast_map, observable)
        self.n = check_positive_real(n, "n")
        self.fast_map, self.observable = fast_map, observable
        self._init_common(1, seed, times, dt, n_steps, t0, batch_shape, block_bytes)
        h = self._h
        if not np.allclose(h, h[0], rtol=1e-10, atol=0.0):
            raise ValueError("times must be a uniform grid for a ChaoticDriver (every step holds the same number "
                             "of fast steps); pass dt=... and n_steps=....")
        m = self.n * float(h[0])
        if not (0.5 <= m < math.inf and abs(m - round(m)) <= 1e-9 * max(1.0, m)):
            raise ValueError(f"n * dt must be a positive integer (fast steps per grid step), got n={n!r}, "
                             f"dt={float(h[0])!r}: n * dt = {m!r}; choose dt = m / n for an integer m.")
        self.fast_steps_per_step = int(round(m))
        P = self.n_paths
        check_memory(8.0 * P * (3 * fast_map.dim + 4), f"the initial points of {P} orbits", "use fewer orbits")
        check_work(float(P) * self.n_steps * self.fast_steps_per_step,
                   f"{P} orbits x {self.n_steps} steps x {self.fast_steps_per_step} fast steps",
                   "use fewer orbits, fewer steps or a smaller n")
        rng = np.random.default_rng(self.seed_sequence)
        self._y0 = fast_map.initial_states(rng, P)
        d = _observe(fast_map, observable, self._y0[:1, None, :]).shape[-1]      # at one point: the values' size
        check_memory(8.0 * P * d, f"the observable's values at the {P} initial points ({P} x {d})", "use fewer orbits")
        self.dim = _observe(fast_map, observable, self._y0[:, None, :], d).shape[-1]
        # batch-shaped, as blocks() and select() read the starts of a seeded driver (_flat)
        self._y0 = self._y0.reshape(self.batch_shape + (fast_map.dim,))
        self.level = 2
        # fast steps per chunk, fixed by the whole batch (select keeps it): pieces never depend on max_steps
        self._chunk = max(1, int(self.block_bytes // max(1, 8 * max(P, 1) * (fast_map.dim + 2 * self.dim))))

    def _starts(self) -> dict:
        return {"_y0": self.fast_map.dim}

    def _bytes_per_path_step(self) -> int:
        d = self.dim
        return 8 * (d + d * d) + 8 * min(self.fast_steps_per_step, self._chunk) * (self.fast_map.dim + 2 * d)

    def __repr__(self) -> str:
        return (f"ChaoticDriver({self.fast_map.name}, d={self.dim}, n={self.n:g}, n_steps={self.n_steps}, "
                f"fast_steps_per_step={self.fast_steps_per_step}, batch_shape={self.batch_shape})")

    def initial_state(self) -> np.ndarray:
        """The initial points of the orbits, shape ``(*batch_shape, k)``."""
        return np.asarray(self._y0).reshape(self.batch_shape + (self.fast_map.dim,)).copy()

    def _pieces(self, state, n_steps_block, buf):
        """``(state, inc (P, K, d), area (P, K, d, d))`` of ``n_steps_block`` grid steps."""
        fm, m, d, P = self.fast_map, self.fast_steps_per_step, self.dim, state.shape[0]
        scale = 1.0 / math.sqrt(self.n)
        inc, area = np.empty((P, n_steps_block, d)), np.empty((P, n_steps_block, d, d))
        if m <= self._chunk:                                  # whole grid steps per chunk
            per = max(1, self._chunk // m)
            for k0 in range(0, n_steps_block, per):
                kk = min(per, n_steps_block - k0)
                state = fm.orbit(state, kk * m, buf)
                dl = scale * _observe(fm, self.observable, buf[:, :kk * m], d).reshape(P, kk, m, d)
                g = np.cumsum(dl, axis=2) - 0.5 * dl          # Σ_{i<j} Δ_i + ½ Δ_j
                inc[:, k0:k0 + kk] = dl.sum(axis=2)
                area[:, k0:k0 + kk] = np.swapaxes(g, -1, -2) @ dl     # Σ_j g_j ⊗ Δ_j
            return state, inc, area
        for k in range(n_steps_block):                        # each grid step in pieces, joined by Chen
            x, a = np.zeros((P, d)), np.zeros((P, d, d))
            for j0 in range(0, m, self._chunk):
                cc = min(self._chunk, m - j0)
                state = fm.orbit(state, cc, buf)
                dl = scale * _observe(fm, self.observable, buf[:, :cc], d)
                g = np.cumsum(dl, axis=1) - 0.5 * dl
                xp = dl.sum(axis=1)
                a += np.swapaxes(g, -1, -2) @ dl + x[:, :, None] * xp[:, None, :]
                x += xp
            inc[:, k], area[:, k] = x, a
        return state, inc, area

    def blocks(self, max_steps=None):
        """Yield consecutive ``RoughPath`` blocks (kind ``"geometric"``) covering the grid."""
        K = self._block_size(max_steps)
        N, d, P, shape = self.n_steps, self.dim, self.n_paths, self.batch_shape
        state = np.array(self._flat(self._y0, self.fast_map.dim))
        buf = np.empty((P, min(self._chunk, max(self._chunk // self.fast_steps_per_step, 1)
                               * self.fast_steps_per_step), self.fast_map.dim), dtype=state.dtype)
        x0 = np.zeros((P, d))
        for k0 in range(0, N, K):
            k = min(N, k0 + K) - k0
            state, inc, area = self._pieces(state, k, buf)
            yield RoughPath(inc.reshape(shape + (k, d)), area.reshape(shape + (k, d, d)),
                            times=self.times[k0:k0 + k + 1], x0=x0.reshape(shape + (d,)).copy(), kind="geometric",
                            check=False)
            x0 += inc.sum(axis=1)
