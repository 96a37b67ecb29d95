"""Beyond the paper (issue 38): Theorem 3.1's Gibbs state for Zeitlin's model at small N, with the Lévy correction.

Claim (docs/conventions.md; mechanics.systems.lie_poisson): with isotropic SALT noise (xi_i = sigma e_i over an
orthonormal basis e_i of su(N) for the trace form) and double-bracket dissipation built from the modified
Hamiltonian h~ = h + <W, ell>, ell = 1/2 sum_ij s^{ij} [xi_i, xi_j], the stationary law on the coadjoint orbit of
W0 is the Gibbs measure proportional to exp(-2 theta h~ / sigma^2) times the invariant (Liouville) measure of the
orbit. Checked on su(3) (Zeitlin's Hamiltonian at N = 3, physical time; 8 noises, sigma = 0.5, theta = 1,
s^{12} = 1, s^{36} = 1/2) for the observable <W, ell> (the Lévy term of h~):

* measured: time averages over [T/2, T] of independent paths (LieHeun, dt = 0.01, Brownian areas), mean and
  standard error over the paths (each path's average is one sample);
* predicted: the Gibbs mean by self-normalised importance sampling of orbit samples U W0 U^* with Haar U
  (MatrixLieAlgebra.sample_orbit), with its delta-method standard error;
* criteria fixed before the run: within 4 combined SE; the Gibbs means with the wrong sign of ell (-s), without
  the 1/2 (2s) and without the correction (s = 0) each at least 6 combined SE away.

Measured (load 10): 48 paths, T = 8 (the default test): -0.858 +- 0.011 against -0.868 +- 0.004 (0.9 SE), the
Gibbs mean with 2s -1.02 (15 SE), with -s +1.41, with s = 0 +0.005; the slow test runs 256 paths to T = 40.
"""

import numpy as np
import pytest

import roughpaths as rp
from mechanics import LieHeun, su
from mechanics.sphere import zeitlin_system

N, SIGMA, THETA, DT = 3, 0.5, 1.0, 0.01


def _system():
    g = su(N)
    xi = SIGMA * np.asarray(g.basis)
    S = np.zeros((8, 8))
    S[0, 1], S[2, 5] = 1.0, 0.5
    S = S - S.T
    return g, zeitlin_system(N, noise=xi, s=S, theta=THETA), S


def _check(paths, T, seed=5):
    g, system, S = _system()
    assert np.allclose(g.gram, np.eye(g.dim))                       # orthonormal basis: the noise is isotropic
    rng = np.random.default_rng(3)
    A = rng.standard_normal((N, N)) + 1j * rng.standard_normal((N, N))
    A = A - A.conj().T
    y0 = g.matrix_to_dual(A - np.trace(A) / N * np.eye(N))
    ell = system.levy_velocity

    drv = rp.BrownianDriver(8, seed=seed, dt=DT, n_steps=int(round(T / DT)), batch_shape=(paths,))
    ys = rp.solve(system, drv, np.broadcast_to(y0, (paths, g.dim)).copy(), LieHeun(),
                  save_at=np.linspace(T / 2, T, 21)).states
    per_path = (ys @ ell).mean(axis=1)
    meas, se_meas = per_path.mean(), per_path.std(ddof=1) / np.sqrt(paths)

    samples = g.sample_orbit(y0, 100_000, np.random.default_rng(9))
    f = samples @ ell

    def gibbs(factor):
        e = system.with_s(factor * S).modified_hamiltonian(samples)
        w = np.exp(-2.0 * THETA * (e - e.min()) / SIGMA ** 2)
        mean = np.sum(w * f) / np.sum(w)
        return mean, np.sqrt(np.sum(w ** 2 * (f - mean) ** 2)) / np.sum(w)

    pred, se_pred = gibbs(1.0)
    z = (meas - pred) / np.hypot(se_meas, se_pred)
    assert abs(z) <= 4.0, (meas, se_meas, pred, se_pred)
    for factor in (-1.0, 2.0, 0.0):                                  # wrong sign, missing 1/2, no correction
        wrong, se_wrong = gibbs(factor)
        assert abs(meas - wrong) / np.hypot(se_meas, se_wrong) >= 6.0, (factor, meas, wrong)
    return z


def test_gibbs_state_of_the_levy_corrected_model():
    _check(48, 8.0)


@pytest.mark.slow
def test_gibbs_state_of_the_levy_corrected_model_long_run():
    _check(256, 40.0, seed=6)
