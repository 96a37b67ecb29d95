"""Beyond the paper (issue 38): Zeitlin's model converges to the Euler equations on the sphere as N grows, like N^-2.

The Rossby–Haurwitz wave lives in one degree and is reproduced exactly at every N (test_euler_sphere_solutions),
so it cannot show a rate. Here the initial vorticity is a smooth random field of degrees 1..4 (order-one
amplitudes: the flow turns over within the run and its spectrum spreads to every degree, falling about 30 times
per 4 degrees at t = 1) and the reference is an independent solution of Euler on the sphere: a dealiased
pseudo-spectral Galerkin solver written in the test (_sphere_oracles.SpectralEuler: scipy's harmonics, a
Gauss-Legendre grid, RK4 with 50 steps), truncated at degree 19: it differs from the solution truncated at
degree 23 by 2e-7 (and that one from degree 31 by 3e-8), far below the differences measured. Zeitlin's
solution W_N(t) (zeitlin_system without noise, physical time, LieHeun with 60 steps: its time error is < 1e-6)
is read back as spherical-harmonic coefficients; the error is the relative L2 norm of the vorticity difference
at t = 1 (all degrees; the degrees >= N that Zeitlin lacks count as error).

Measured (load 10 on 2 cores): 2.7e-2, 6.2e-3, 1.5e-3, 3.7e-4, 9.6e-5 at N = 8, 16, 32, 64, 128 (the last in
the slow test): fitted slope -2.0, the order of the commutator's approximation of the Poisson bracket
(hbar^2 ~ 4/N^2). The field moves by far more: |omega(1) - omega(0)| is about 0.5 relative. The rejected
variants: the Hamiltonian with the other sign (the flow run backwards) and Zeitlin's quantum time (kappa = 1
instead of 1/hbar) are O(1) off.
"""

import numpy as np
import pytest

from _sphere_oracles import SpectralEuler, fitted_slope, smooth_coefficients
import roughpaths as rp
from mechanics import LieHeun
from mechanics.sphere import coefficients_to_matrix, matrix_to_coefficients, zeitlin_system

T, L_REF, STEPS = 1.0, 20, 60
_CACHE = {}


def _initial():
    return 1.5 * smooth_coefficients(np.random.default_rng(5), 4)


def _reference():
    if "ref" not in _CACHE:
        _CACHE["ref"] = SpectralEuler(L_REF).solve(_initial(), T, 50)
    return _CACHE["ref"]


def _zeitlin(N, sign=1.0, time_unit="physical"):
    """Zeitlin's coefficients at T; sign = -1: the flow of the Hamiltonian -h (dW/dt = -kappa [P, W]), which is
    -(the flow of h from -W0) since P is linear in W."""
    system = zeitlin_system(N, amplitudes=0.0, time_unit=time_unit)
    g = system.algebra
    W0 = g.matrix_to_dual(coefficients_to_matrix(sign * _initial(), N))
    X = rp.RoughPath.from_path(np.zeros((STEPS + 1, 3)), times=np.linspace(0.0, T, STEPS + 1))
    return sign * matrix_to_coefficients(g.dual_to_matrix(rp.solve(system, X, W0, LieHeun(), save_at="end").final), N)


def _error(coef, ref):
    n = min(coef.size, ref.size)
    diff = np.concatenate([coef[:n] - ref[:n], ref[n:]])
    return float(np.linalg.norm(diff) / np.linalg.norm(ref))


def _rate(Ns):
    ref = _reference()
    errs = [_error(_zeitlin(N), ref) for N in Ns]
    return fitted_slope(Ns, errs), errs, ref


def test_zeitlin_converges_to_the_spectral_euler_solution_like_N_minus_2():
    Ns = [8, 16, 32, 64]
    slope, errs, ref = _rate(Ns)
    assert -2.3 <= slope <= -1.7, (slope, errs)
    assert errs[-1] <= 5e-4, errs
    init = _initial()
    moved = _error(np.concatenate([init, np.zeros(ref.size - init.size)]), ref)
    assert moved > 0.2 > 100 * errs[-1]                        # the field genuinely evolves
    assert _error(_zeitlin(32, sign=-1.0), ref) > 0.2                # the Hamiltonian with the wrong sign
    assert _error(_zeitlin(32, time_unit="quantum"), ref) > 0.1  # Zeitlin's quantum time is not Euler's


@pytest.mark.slow
def test_convergence_rate_holds_at_N_128():
    slope, errs, _ = _rate([16, 32, 64, 128])
    assert -2.2 <= slope <= -1.8 and errs[-1] <= 1.5e-4, (slope, errs)
