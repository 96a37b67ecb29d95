r"""Closed-form solutions of Euler on the non-rotating unit sphere: the Rossby–Haurwitz wave.

Derivation (the conventions of :mod:`.euler`: :math:`\omega = \Delta\psi`, :math:`\omega_t = \{\omega, \psi\}`,
:math:`\{f, g\} = x\cdot(\nabla f\times\nabla g)`, :math:`\{x_3, f\} = -\partial_\phi f`). Take a solid-body
rotation with angular velocity :math:`\Omega` about :math:`e_3` plus a wave of one degree :math:`l\ge1`:

.. math::

    \psi = -\Omega x_3 + \psi_l,\quad \Delta\psi_l = -l(l+1)\psi_l,\qquad
    \omega = 2\Omega x_3 - l(l+1)\psi_l .

Then :math:`\{\omega, \psi\} = -2\Omega\{x_3, \psi_l\} + l(l+1)\Omega\{\psi_l, x_3\} - l(l+1)\{\psi_l, \psi_l\}
= \Omega\,(l(l+1) - 2)\{\psi_l, x_3\} = \Omega\,(l(l+1) - 2)\,\partial_\phi\psi_l`, while the ansatz
:math:`\psi_l(\theta, \phi - \lambda t)` gives :math:`\omega_t = l(l+1)\lambda\,\partial_\phi\psi_l`. Hence the
wave pattern rotates rigidly about :math:`e_3` with angular velocity

.. math::

    \lambda = \Omega\Bigl(1 - \frac{2}{l(l+1)}\Bigr),

slower than the background flow (Haurwitz's speed with the planetary rotation set to zero; for
:math:`l = 1` the "wave" only tilts the rotation axis, and :math:`\lambda = 0`: steady). In coefficients,
:math:`\omega_{lm}(t) = \omega_{lm}(0)e^{-im\lambda t}` and :math:`\omega_{10} = 2\Omega\sqrt{4\pi/3}`.

In Zeitlin's model this solution is exact for every :math:`N > l`, not only in the limit: the
degree-:math:`l` part is one spin-:math:`l` block, :math:`\Delta_N` is exactly :math:`-l(l+1)` on it, and the
only bracket left, with :math:`T(x_3) = \hbar S_3`, is the exact rotation generator
(:math:`\frac{1}{i\hbar}[\hbar S_3, T] = -i\operatorname{ad}_{S_3}T\leftrightarrow -iL_3 = -\partial_\phi`).
The same holds for every rotated copy (axis :math:`n` instead of :math:`e_3`) by the exact
:math:`SU(2)`-equivariance of the quantisation. Zonal flows (:math:`\omega` a function of
:math:`\theta` only) are steady in both: their matrices are diagonal.

Examples
--------
>>> import numpy as np
>>> from mechanics.sphere import RossbyHaurwitzWave
>>> wave = RossbyHaurwitzWave(4, {(4, 1): 0.3}, rotation=1.0)
>>> wave.speed   # 1 - 2/20
0.9
>>> v0 = wave.vorticity(np.array([1.0]), np.array([0.2]), 0.0)
>>> bool(np.allclose(wave.vorticity(np.array([1.0]), np.array([0.2 + 0.9 * 2.0]), 2.0), v0))
True
"""

from __future__ import annotations

import numbers

import numpy as np

from roughpaths.validation import as_float_array, check_real

from ._inputs import check_bytes
from .quantisation import coefficients_to_matrix, lm_index

__all__ = ["RossbyHaurwitzWave"]


def _is_int(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))


class RossbyHaurwitzWave:
    r"""A Rossby–Haurwitz wave of degree :math:`l` on a solid-body rotation (non-rotating sphere).

    Parameters
    ----------
    degree : int
        :math:`l\ge1`.
    wave : dict
        Vorticity coefficients of the wave, ``{(l, m): value}`` (all with the given degree; complex for
        :math:`m\neq0`). The partner :math:`(l, -m)` is filled in as :math:`(-1)^m\bar\omega_{lm}` so that the
        field is real; giving both, they must agree. ``m = 0`` entries must be real.
    rotation : float
        :math:`\Omega`, the angular velocity of the background flow about :math:`e_3` (vorticity
        :math:`2\Omega\cos\theta`).

    Attributes
    ----------
    speed : float
        :math:`\lambda = \Omega(1 - 2/(l(l+1)))`, the angular velocity of the wave pattern.
    """

    def __init__(self, degree: int, wave: dict, rotation: float):
        if isinstance(degree, bool) or not isinstance(degree, numbers.Integral) or degree < 1:
            raise ValueError(f"degree must be an integer l >= 1, got {degree!r}.")
        if isinstance(rotation, (bool, np.bool_)) or not isinstance(rotation, numbers.Real):
            raise TypeError(f"rotation must be a real number (the angular velocity Omega), got {rotation!r}; "
                            f"pass a float.")
        if not np.isfinite(rotation):
            raise ValueError(f"rotation must be a finite real angular velocity, got {rotation!r}.")
        if not isinstance(wave, dict) or not wave:
            raise TypeError(f"wave must be a non-empty dict {{(l, m): coefficient}}, got {wave!r}.")
        l = int(degree)
        check_bytes(17.0 * (2 * l + 1) + 8192.0, f"the coefficients of a wave of degree {l}", "use a smaller degree")
        coef = np.zeros(2 * l + 1, dtype=np.complex128)  # index m + l
        given = np.zeros(2 * l + 1, dtype=bool)
        for key, value in wave.items():
            if not (isinstance(key, tuple) and len(key) == 2 and key[0] == l and _is_int(key[1]) and abs(key[1]) <= l):
                raise ValueError(f"wave keys must be (l, m) with l = degree = {l} and an integer |m| <= l, "
                                 f"got {key!r}.")
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Number):
                raise TypeError(f"wave[{key!r}] must be a number (a complex coefficient), got {value!r}; "
                                f"pass a float or a complex.")
            if not np.isfinite(complex(value)):
                raise ValueError(f"wave[{key!r}] must be a finite coefficient, got {value!r}.")
            coef[int(key[1]) + l] = complex(value)
            given[key[1] + l] = True
        for m in range(0, l + 1):
            a, b = coef[m + l], coef[-m + l]
            partner = (-1) ** m * np.conj(a)
            if given[m + l] and given[-m + l] and not np.isclose(b, partner, rtol=1e-12, atol=1e-15):
                raise ValueError(f"wave[({l}, {-m})] = {b} must be (-1)^m conj(wave[({l}, {m})]) = {partner} "
                                 f"for a real field; give one of the two.")
            if given[m + l]:
                coef[-m + l] = partner
            elif given[-m + l]:
                coef[m + l] = (-1) ** m * np.conj(b)
        self.degree, self.rotation = l, float(rotation)
        self.wave = coef
        self.speed = self.rotation * (1.0 - 2.0 / (l * (l + 1)))

    def __repr__(self) -> str:
        return f"RossbyHaurwitzWave(degree={self.degree}, rotation={self.rotation}, speed={self.speed})"

    def coefficients(self, t: float, L: int) -> np.ndarray:
        r"""The vorticity coefficients at time ``t``, ``omega[l*(l+1)+m]``, shape ``(L**2,)`` (``L > degree``)."""
        if not _is_int(L):
            raise TypeError(f"L must be an integer number of degrees (the modes l < L), got {L!r}; "
                            f"pass e.g. L={self.degree + 1}.")
        L = int(L)
        t = check_real(t, "t")
        if L <= self.degree:
            raise ValueError(f"L must exceed the degree {self.degree} (the modes l < L are returned), got {L}.")
        # the result and, for the wave's 2 degree + 1 modes, a few arrays of that size
        check_bytes(16.0 * L * L + 64.0 * (2 * self.degree + 1) + 8192.0, f"the coefficients l < L = {L}",
                    "use a smaller L")
        out = np.zeros(L * L, dtype=np.complex128)
        m = np.arange(-self.degree, self.degree + 1)
        out[lm_index(self.degree, m)] = self.wave * np.exp(-1j * m * self.speed * t)
        out[lm_index(1, 0)] += 2.0 * self.rotation * np.sqrt(4.0 * np.pi / 3.0)
        return out

    def matrix(self, t: float, N: int) -> np.ndarray:
        """The vorticity matrix at time ``t``, shape ``(N, N)``, in su(N) (``N > degree``)."""
        return coefficients_to_matrix(self.coefficients(t, N), N)

    def vorticity(self, theta, phi, t: float) -> np.ndarray:
        r""":math:`\omega(\theta, \phi, t) = 2\Omega\cos\theta + \sum_m\omega_{lm}Y_{lm}(\theta, \phi - \lambda t)`
        (real; ``theta``, ``phi`` broadcast)."""
        from scipy.special import sph_harm_y  # imported here: 0.14 s that `import mechanics` need not pay

        t = check_real(t, "t")
        theta, phi = np.broadcast_arrays(as_float_array(theta, "theta"), as_float_array(phi, "phi"))
        shifted = np.mod(phi - self.speed * t, 2.0 * np.pi)
        out = 2.0 * self.rotation * np.cos(theta) + 0j
        for m in range(-self.degree, self.degree + 1):
            out = out + self.wave[m + self.degree] * sph_harm_y(self.degree, m, theta, shifted)
        return out.real
