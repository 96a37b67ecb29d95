r"""Zeitlin's model of 2-D Euler on the unit sphere as a Lie–Poisson system on :math:`\mathfrak{su}(N)^*`:
its Hamiltonian, energy, enstrophy and Casimirs, and SALT noise matrices.

Euler on the sphere (the sign and scale used throughout)
---------------------------------------------------------
Stream function :math:`\psi`, velocity :math:`u = x\times\nabla\psi`, vorticity
:math:`\omega = x\cdot\operatorname{curl}u = \Delta\psi`; the Euler equation :math:`\omega_t + u\cdot\nabla\omega = 0`
reads :math:`\omega_t = \{\omega, \psi\}` with :math:`\{f, g\} = x\cdot(\nabla f\times\nabla g)`
(:math:`\psi = -\Omega\cos\theta` is a solid-body rotation with angular velocity :math:`\Omega` about
:math:`e_3`, vorticity :math:`2\Omega\cos\theta`). The kinetic energy is
:math:`E = \tfrac12\int|u|^2dA = -\tfrac12\int\psi\omega\,dA = \tfrac12\sum_{l\ge1}|\omega_{lm}|^2/(l(l+1))`.

The quantised equation. With :math:`T` of :mod:`.quantisation` (:math:`T(\{f,g\})\approx\frac{1}{i\hbar}[T(f), T(g)]`),
the vorticity matrix :math:`W = iT(\omega)` and the stream matrix :math:`P = iT(\psi) = \Delta_N^{-1}W`
(:mod:`.laplacian`): :math:`\dot W = iT(\{\omega,\psi\})\approx\frac1\hbar[T(\omega), T(\psi)] = \frac1\hbar[P, W]`.
This is Zeitlin's :math:`\dot W = [P, W]` in the time :math:`\tau = t/\hbar` ("quantum time");
:math:`\frac1\hbar[P, W]` in physical time :math:`t` is the one that converges to Euler as :math:`N\to\infty`.

As a Lie–Poisson equation in the library's convention. The pairing is the trace form
:math:`B(A, C) = -\tfrac12\operatorname{Re}\operatorname{tr}(AC)` (positive definite on
:math:`\mathfrak{su}(N)`); then :math:`B(W, [\Omega, X]) = B([W, \Omega], X)`, so
:math:`\operatorname{ad}^*_\Omega W = [W, \Omega]` and the Lie–Poisson equation is
:math:`\dot W = [W, \nabla h(W)]` with :math:`dh = B(dW, \nabla h)`. Take

.. math::

    h(W) = \frac\kappa2 B(W, -P) = \frac\kappa4\operatorname{Re}\operatorname{tr}(WP),\qquad
    \nabla h(W) = -\kappa P,\qquad \dot W = [W, -\kappa P] = \kappa[P, W],

(:math:`\Delta_N^{-1}` is self-adjoint for :math:`B`, so :math:`dh = \kappa B(dW, -P)`). With
:math:`\kappa = 1/\hbar` (``time_unit="physical"``, the default) this is the quantised Euler equation in
physical time; with :math:`\kappa = 1` (``time_unit="quantum"``) it is Zeitlin's :math:`\dot W = [P, W]`.
The sign is the one that makes :math:`h` positive: :math:`\operatorname{tr}(WP) = \langle-\Delta_N P, P\rangle_F\ge0`
(the Frobenius product; :math:`-\Delta_N` is positive semi-definite); :math:`h = \kappa B(W, P)/2`, the
other sign, would run the flow backwards. The value is the kinetic energy up to a positive constant:
:math:`E = \frac{2\pi}{N}\operatorname{Re}\operatorname{tr}(WP)` exactly for the truncated field, so
:math:`h = \kappa\frac{N}{8\pi}E` (:func:`energy` returns :math:`E`).

Casimirs. :math:`C_k(W) = \operatorname{tr}((iW)^k)`, real for skew-Hermitian :math:`W`, conserved by every
isospectral flow. Since :math:`iW = -T(\omega)`, :math:`C_k\approx(-1)^k\frac{N}{4\pi}\int\omega^k dA`; for
:math:`k = 2` exactly :math:`C_2 = \frac{N}{4\pi}\int\omega^2dA`, so the enstrophy is
:math:`\tfrac12\int\omega^2dA = \frac{2\pi}{N}C_2` (:func:`enstrophy`).

SALT noise. The stochastic transport :math:`d\omega = \{\omega,\psi\}dt + \sum_i\{\omega, \zeta_i\}\circ dX^i`
(velocity fields :math:`x\times\nabla\zeta_i`) quantises to
:math:`dW = \frac1\hbar[P, W]dt + \sum_i\frac1\hbar[Z_i, W]\circ dX^i` with :math:`Z_i = iT(\zeta_i)`; in the
library's form :math:`\operatorname{ad}^*_{\xi_i}W = [W, \xi_i]` this is :math:`\xi_i = -\kappa Z_i`, what
:func:`salt_noise` returns (the same :math:`\kappa` as the Hamiltonian: the drift is
:math:`\operatorname{ad}^*_{\nabla h}W` with :math:`\nabla h = -\kappa P`, the stream matrix in the same units).

Examples
--------
>>> import numpy as np
>>> from mechanics.sphere import ZeitlinHamiltonian, energy, real_harmonic_matrix
>>> N = 16
>>> H = ZeitlinHamiltonian(N)
>>> W = -12 * real_harmonic_matrix(N, 3, 2)   # the vorticity of psi = Y^R_32 (Delta psi = -l(l+1) psi)
>>> bool(np.isclose(energy(W), 0.5 * 12**2 / 12))   # E = |omega_lm|^2 / (2 l(l+1))
True
>>> bool(np.isclose(H.value_matrix(W), H.kappa * N / (8 * np.pi) * energy(W)))
True
"""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths.validation import check_work

from ._inputs import as_matrix, check_bytes, check_size
from .grid import function_to_matrix, grid_to_matrix
from .laplacian import inverse_laplacian
from .quantisation import _harmonic_matrices, hbar

__all__ = ["ZeitlinHamiltonian", "energy", "enstrophy", "casimirs", "real_harmonic_matrix", "salt_noise"]

_TIME_UNITS = ("physical", "quantum")


def _time_scale(N: int, time_unit) -> float:
    if not isinstance(time_unit, str):            # an array ['physical'] passed `in` elementwise, and was kept
        raise TypeError(f"time_unit must be the string 'physical' or 'quantum', got {type(time_unit).__name__} "
                        f"{time_unit!r}.")
    if time_unit not in _TIME_UNITS:
        raise ValueError(f"time_unit must be 'physical' (t, the default: kappa = 1/hbar) or 'quantum' "
                         f"(Zeitlin's tau = t/hbar: kappa = 1), got {time_unit!r}.")
    return 1.0 / hbar(N) if time_unit == "physical" else 1.0


def _re_trace_product(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``Re tr(A C)`` per member, ``(...)``: an elementwise sum over each member's own contiguous block."""
    n = A.shape[-1]
    prod = np.ascontiguousarray((A * np.swapaxes(C, -1, -2)).real)
    return prod.reshape(prod.shape[:-2] + (n * n,)).sum(axis=-1)


class ZeitlinHamiltonian:
    r"""The energy Hamiltonian of Euler on the sphere on :math:`\mathfrak{su}(N)^*`, for matrix-state solvers.

    :math:`h(W) = \frac\kappa4\operatorname{Re}\operatorname{tr}(WP)`, :math:`P = \Delta_N^{-1}W`, with
    :math:`\nabla h = -\kappa P`, so that the library's Lie–Poisson equation
    :math:`\dot W = [W, \nabla h]` is :math:`\dot W = \kappa[P, W]` (module docstring).

    Parameters
    ----------
    N : int
        Matrix size.
    time_unit : {"physical", "quantum"}
        ``"physical"``: :math:`\kappa = 1/\hbar`, time is the time of the Euler equation on the unit
        sphere; ``"quantum"``: :math:`\kappa = 1`, Zeitlin's :math:`\dot W = [P, W]`.

    Attributes
    ----------
    N : int
    hbar : float
        :math:`2/\sqrt{N^2-1}`.
    kappa : float
        The time scale :math:`\kappa`.
    """

    def __init__(self, N: int, *, time_unit: str = "physical"):
        self.N = check_size(N)
        self.hbar = hbar(self.N)
        self.kappa = _time_scale(self.N, time_unit)
        self.time_unit = time_unit

    def __repr__(self) -> str:
        return f"ZeitlinHamiltonian(N={self.N}, time_unit={self.time_unit!r})"

    def stream_matrix(self, W) -> np.ndarray:
        """:math:`P = \\Delta_N^{-1}W`, shape ``(..., N, N)`` (trace-free; :math:`O(N^2)`)."""
        return inverse_laplacian(as_matrix(W, N=self.N))

    def value_matrix(self, W) -> np.ndarray:
        """:math:`h(W) = \\frac\\kappa4\\operatorname{Re}\\operatorname{tr}(WP) \\ge 0`, shape ``(...)``."""
        arr = as_matrix(W, N=self.N)
        return 0.25 * self.kappa * _re_trace_product(arr, inverse_laplacian(arr))

    def gradient_matrix(self, W) -> np.ndarray:
        """:math:`\\nabla h(W) = -\\kappa P`, shape ``(..., N, N)``, in su(N) (:math:`dh = B(dW, \\nabla h)`)."""
        return -self.kappa * inverse_laplacian(as_matrix(W, N=self.N))

    def vector_field(self, W) -> np.ndarray:
        """:math:`\\dot W = [W, \\nabla h(W)] = \\kappa[P, W]`, shape ``(..., N, N)`` (:math:`O(N^3)`)."""
        arr = as_matrix(W, N=self.N)
        grad = -self.kappa * inverse_laplacian(arr)
        return arr @ grad - grad @ arr


def energy(W) -> np.ndarray:
    r"""The kinetic energy :math:`E = \tfrac12\int|u|^2dA = \frac{2\pi}{N}\operatorname{Re}\operatorname{tr}(WP)` of the
    flow whose vorticity matrix is ``W`` (shape ``(..., N, N)`` -> ``(...)``); exactly
    :math:`\tfrac12\sum_{l\ge1}|\omega_{lm}|^2/(l(l+1))`."""
    arr = as_matrix(W)
    return 2.0 * np.pi / arr.shape[-1] * _re_trace_product(arr, inverse_laplacian(arr))


def enstrophy(W) -> np.ndarray:
    r"""The enstrophy :math:`\tfrac12\int\omega^2dA = \frac{2\pi}{N}\operatorname{Re}\operatorname{tr}((iW)^2)`,
    ``(..., N, N)`` -> ``(...)`` (exact for the truncated field; the l = 0 part counts too)."""
    arr = as_matrix(W)
    return -2.0 * np.pi / arr.shape[-1] * _re_trace_product(arr, arr)


def casimirs(W, orders=(2, 3, 4, 5, 6)) -> np.ndarray:
    r"""The Casimirs :math:`C_k = \operatorname{Re}\operatorname{tr}((iW)^k)`, shape ``(..., len(orders))``.

    Conserved by the exact flow and by isospectral schemes; :math:`C_k\approx(-1)^k\frac{N}{4\pi}\int\omega^kdA`.
    Computed by repeated products: :math:`k_{max} - 1` batched products, :math:`O(k_{max}N^3)` per matrix, three
    stacks of matrices in memory; both are checked against the budgets before the first product. For
    :math:`N\times N` matrices the :math:`C_k` with :math:`k > N` are polynomials in :math:`C_1, \dots, C_N`
    (Newton's identities).
    """
    arr = as_matrix(W)
    ks = _check_orders(orders)
    n = arr.shape[-1]
    b = arr.size // (n * n)
    k_max = float(min(max(ks), 10**300))
    seconds = (k_max - 1.0) * _product_seconds(b, n)
    check_work(seconds * _UNITS_PER_SECOND, f"orders up to k = {max(ks)}: {k_max - 1.0:.3g} products of {b} "
               f"matrices of size {n} (about {seconds:.3g} s of one core)", f"ask for lower orders (for {n} x {n} "
               f"matrices the C_k with k > {n} follow from those with k <= {n}), or pass fewer matrices at a time")
    # iW, the current power and the next one; the traces, and small arrays
    check_bytes(48.0 * arr.size + 8.0 * b * (len(ks) + 2) + 2.0 ** 14, f"the powers (iW)^k of {b} matrices of size {n}",
                "pass fewer matrices at a time")
    m = 1j * arr
    out = np.empty(arr.shape[:-2] + (len(ks),))
    power, have = m, 1
    for pos, k in sorted(enumerate(ks), key=lambda item: item[1]):
        while have < k:
            power, have = power @ m, have + 1
        out[..., pos] = np.trace(power, axis1=-2, axis2=-1).real
    return out


#: The work budget's units per second of one core, by its own calibration (1e12 units, about a day).
_UNITS_PER_SECOND = 1e12 / 86400.0


def _product_seconds(b: int, n: int) -> float:
    """An upper estimate of the CPU time of one step ``power @ m`` of :func:`casimirs`' loop, for ``b`` matrices of
    size ``n``: 2.5 us per step whatever the size, 0.5 us per matrix of the stack and 0.4 ns per complex
    multiply-add (``n^3`` per matrix). Measured on two shared cores: 1.7-1.9 us a step at b = 1, n = 2 (2.8-3.2 us
    at n = 16); 0.26-0.31 us a matrix at b = 1000, n = 2 (0.4-0.7 us at n = 8); 0.2-0.4 ns of CPU time a
    multiply-add at n >= 128 (two BLAS threads)."""
    return 2.5e-6 + b * (0.5e-6 + 0.4e-9 * float(n) ** 3)


def _check_amplitudes(amplitudes) -> np.ndarray:
    """``amplitudes`` as float64, after refusing bools, text and complex numbers (``np.asarray`` would take a
    bool as 1.0 and raise its own errors for the others)."""
    try:
        items = np.asarray(amplitudes, dtype=object).ravel()
    except ValueError:
        items = [amplitudes]
    for a in items:
        if isinstance(a, (bool, np.bool_)) or not isinstance(a, numbers.Real):
            raise TypeError(f"amplitudes must be real numbers (a float, or one per noise field), got {a!r} in "
                            f"{amplitudes!r}; pass e.g. amplitudes=0.1.")
    return np.asarray(amplitudes, dtype=np.float64)


def _check_orders(orders) -> list:
    """``orders`` as a list of Python ints ``>= 1``: integers, or floats with integer values (bools refused)."""
    hint = "pass e.g. orders=(2, 3, 4, 5, 6)"
    if isinstance(orders, (str, bytes)):
        raise TypeError(f"orders must be positive integers, got the string {orders!r}; {hint}.")
    arr = np.atleast_1d(np.asarray(orders, dtype=object))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"orders must be positive integers, a non-empty 1-D sequence, got {orders!r}; {hint}.")
    ks = []
    for o in arr:
        if isinstance(o, (bool, np.bool_)) or not isinstance(o, numbers.Real):
            raise TypeError(f"orders must be positive integers, got {o!r} in {orders!r}; {hint}.")
        if not isinstance(o, numbers.Integral) and (not np.isfinite(float(o)) or float(o) != int(o)) or int(o) < 1:
            raise ValueError(f"orders must be positive integers (e.g. (2, 3, 4, 5, 6)), got {orders!r}.")
        ks.append(int(o))
    return ks


def real_harmonic_matrix(N: int, l: int, m: int) -> np.ndarray:
    r"""The vorticity matrix :math:`iT(Y^{\mathbb R}_{lm})` of a real spherical harmonic, shape ``(N, N)``, in su(N).

    :math:`Y^{\mathbb R}_{l0} = Y_{l0}`, :math:`Y^{\mathbb R}_{lm} = \sqrt2(-1)^m\operatorname{Re}Y_{lm}`,
    :math:`Y^{\mathbb R}_{l,-m} = \sqrt2(-1)^m\operatorname{Im}Y_{lm}` (:math:`m > 0`; orthonormal, and
    :math:`Y^{\mathbb R}_{11}\propto x_1`, :math:`Y^{\mathbb R}_{1,-1}\propto x_2`).
    """
    return _real_harmonic_matrices(check_size(N), [(l, m)])[0]


def _real_harmonic_matrices(n: int, modes) -> list:
    """:func:`real_harmonic_matrix` of every ``(l, m)`` of ``modes``, from one pass over the quantised basis."""
    for l, m in modes:
        if isinstance(l, bool) or isinstance(m, bool) or not isinstance(l, numbers.Integral) \
                or not isinstance(m, numbers.Integral):
            raise TypeError(f"l and m must be integers, got l={l!r}, m={m!r}.")
        if not 1 <= l < n or abs(m) > l:
            raise ValueError(f"(l, m) must satisfy 1 <= l < N = {n} (l = 0 is the identity, not in su(N)) "
                             f"and |m| <= l, got ({l}, {m}).")
    pairs = []
    for l, m in modes:
        pairs += [(int(l), 0)] if m == 0 else [(int(l), abs(int(m))), (int(l), -abs(int(m)))]
    mats = iter(_harmonic_matrices(n, pairs))
    out = []
    for l, m in modes:
        if m == 0:
            out.append(1j * next(mats))
            continue
        plus, minus = next(mats), next(mats)
        sign = (-1.0) ** abs(int(m))
        if m > 0:  # sqrt2 (-1)^m Re Y_lm = ((-1)^m Y_lm + Y_{l,-m}) / sqrt2
            out.append(1j * (sign * plus + minus) / np.sqrt(2.0))
        else:
            out.append((sign * plus - minus) / np.sqrt(2.0))  # i * ((-1)^m Y_lm - Y_{l,-m}) / (sqrt2 i)
    return out


def salt_noise(N: int, modes=None, *, fields=None, amplitudes=1.0, time_unit: str = "physical") -> np.ndarray:
    r"""SALT noise matrices :math:`\xi_i = -\kappa\,iT(a_i\zeta_i)`, shape ``(k, N, N)``, in su(N).

    The noise term :math:`\operatorname{ad}^*_{\xi_i}W\circ dX^i = [W, \xi_i]\circ dX^i` is then the quantised
    transport of the vorticity by the velocity field :math:`x\times\nabla(a_i\zeta_i)` (module docstring).

    Parameters
    ----------
    N : int
        Matrix size.
    modes : sequence of (l, m), optional
        Stream functions :math:`\zeta_i = Y^{\mathbb R}_{lm}` (real spherical harmonics, :math:`1\le l<N`;
        see :func:`real_harmonic_matrix`).
    fields : sequence of callables or array, optional
        Stream functions given by the user: callables ``f(theta, phi)`` (colatitude, longitude; quadrature
        on an oversampled grid, :func:`~mechanics.sphere.grid.function_to_matrix`) or grid values
        ``(k, n_lat, n_lon)`` on :func:`~mechanics.sphere.grid.sphere_grid` with ``n_lat >= N``,
        ``n_lon >= 2N - 1``. Real fields; their mean (the :math:`l = 0` part, which transports nothing)
        is dropped. Modes come first, then fields.
    amplitudes : float or array_like, shape ``(k,)``
        The factors :math:`a_i`.
    time_unit : {"physical", "quantum"}
        As for :class:`ZeitlinHamiltonian` (use the same for both).
    """
    n = check_size(N)
    kappa = _time_scale(n, time_unit)
    amps = _check_amplitudes(amplitudes)
    try:
        modes = [] if modes is None else list(modes)
    except TypeError:
        raise TypeError(f"modes must be a sequence of (l, m) pairs, e.g. [(1, 0), (2, 1)], got {modes!r}.") from None
    if fields is not None and (callable(fields) or (isinstance(fields, np.ndarray) and fields.ndim == 2)):
        fields = [fields]
    if fields is not None and not isinstance(fields, np.ndarray):
        try:
            fields = list(fields)
        except TypeError:
            raise TypeError(f"fields must be callables f(theta, phi) or grid values (k, n_lat, n_lon), got "
                            f"{type(fields).__name__}; pass e.g. fields=[lambda theta, phi: np.cos(theta)].") from None
    k = len(modes) + (0 if fields is None else len(fields))
    # the matrices, their stack and the skew-Hermitian part (with its temporary)
    check_bytes(4 * 16.0 * k * n * n, f"the {k} noise matrices of size {n}", "use fewer modes or fields, or a smaller N")
    for item in modes:
        if not isinstance(item, (tuple, list)) or len(item) != 2:
            raise ValueError(f"modes must be a sequence of (l, m) pairs, e.g. [(1, 0), (2, 1)], got item {item!r}.")
    mats = _real_harmonic_matrices(n, modes)                  # one pass over the basis for all modes
    if fields is not None:
        if isinstance(fields, np.ndarray):
            mats.extend(list(grid_to_matrix(np.asarray(fields, dtype=np.float64), n)))
        else:
            for f in fields:
                if callable(f):
                    mats.append(function_to_matrix(f, n))
                else:
                    mats.append(grid_to_matrix(np.asarray(f, dtype=np.float64), n))
    if not mats:
        raise ValueError("salt_noise needs modes=[(l, m), ...] or fields=[...]: got neither.")
    out = np.stack(mats)
    out = 0.5 * (out - np.conj(np.swapaxes(out, -1, -2)))  # the real part of each field (skew-Hermitian)
    idx = np.arange(n)
    out[:, idx, idx] -= np.trace(out, axis1=-2, axis2=-1)[:, None] / n
    if amps.ndim == 0:
        amps = np.full(out.shape[0], float(amps))
    if amps.shape != (out.shape[0],) or not np.all(np.isfinite(amps)):
        raise ValueError(f"amplitudes must be a finite scalar or have shape ({out.shape[0]},) (one per noise "
                         f"field), got {np.shape(amplitudes)}.")
    return -kappa * amps[:, None, None] * out
