"""Strong order of the isospectral Lie–Heun step on su(N) against Brownian motion.

Claim: on a matrix Lie algebra (the state held as the matrix M, updated by M -> e^-σ M e^σ) Lie–Heun with
σ ∋ Σ_{i<j} A^{ij}[ξ_i, ξ_j] (A the step Lévy area) converges with strong order 1 for non-commuting noise;
driven by the increments alone (a level-1 driver: zero step area) the order drops to ½.

Set-up: one Brownian rough path on a fine grid (``BrownianDriver`` with its default Lévy areas, 2^J steps on
[0, 1]); the coarse drivers are its Chen restrictions (exact increments and areas of the same path), so every
scheme sees the same Brownian motion; the reference is Lie–Heun on the fine grid. Strong error: root mean
square over the paths of the coordinate error at T = 1; order: least-squares slope of log error against log h.
The system: su(3) (su(4) in the slow run), a diagonal Hamiltonian, double-bracket dissipation, three dense
random noise vectors. The isospectral path is forced (the solver's cost model may otherwise run su(3) on the
compiled structure-constant kernel, a different code path for the same equations).
"""

import numpy as np
import pytest

import mechanics
import mechanics.integrators.base as coadjoint_base
from mechanics import LieHeun, LiePoissonSystem, MatrixLieAlgebra
from roughpaths import BrownianDriver, solve


@pytest.fixture
def matrix_path(monkeypatch):
    """Run every MatrixLieAlgebra system on the isospectral steps (no dispatch to the constants kernel)."""
    monkeypatch.setattr(coadjoint_base, "choose", lambda system, dts: (system, isinstance(system.algebra,
                                                                                          MatrixLieAlgebra)))


def _system(N, seed=7):
    rng = np.random.default_rng(seed)
    alg = mechanics.su(N)
    n = alg.dim
    xi = 0.7 * rng.standard_normal((3, n)) / np.sqrt(n) * np.sqrt(N)
    return LiePoissonSystem(alg, 1.0 + rng.random(n), xi, theta=0.5), rng


def _orders(N, fine_exp, levels, paths, seed=7):
    system, rng = _system(N, seed)
    X = BrownianDriver(3, seed=seed, dt=2.0 ** -fine_exp, n_steps=2 ** fine_exp, batch_shape=(paths,)).rough_path()
    mu0 = rng.standard_normal((paths, system.dim)) / np.sqrt(N)
    ref = solve(system, X, mu0, LieHeun(), save_at="end").final
    errs = {"area": [], "no area": []}
    for j in levels:
        Xc = X.restrict(X.times[:: 2 ** (fine_exp - j)])
        for key, drv in (("area", Xc), ("no area", Xc.to_level1())):
            y = solve(system, drv, mu0, LieHeun(), save_at="end").final
            errs[key].append(float(np.sqrt(np.mean(np.sum((y - ref) ** 2, axis=-1)))))
    h = 2.0 ** -np.asarray(levels, dtype=float)
    return {k: (float(np.polyfit(np.log(h), np.log(e), 1)[0]), e) for k, e in errs.items()}


def _check(orders):
    slope, errs = orders["area"]
    assert 0.85 <= slope <= 1.2, ("with the Levy area", slope, errs)
    slope, errs = orders["no area"]
    assert 0.35 <= slope <= 0.65, ("level-1 driver", slope, errs)
    assert orders["no area"][1][-1] > 3.0 * orders["area"][1][-1]       # the area matters at the finest level


def test_strong_order_one_with_area_one_half_without(matrix_path):
    _check(_orders(3, 10, range(3, 8), 24))


@pytest.mark.slow
def test_strong_order_one_su4_two_decades(matrix_path):
    _check(_orders(4, 13, range(3, 10), 64))
