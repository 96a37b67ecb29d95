"""Strong order of the coadjoint schemes on a Brownian rough path.

Claim: with σ_n ∋ ½ Σ A^{ij}[ξ_i, ξ_j] (A the step Lévy area, with the ½) Lie–Heun, Lie–Euler and the
implicit midpoint converge with strong order 1 to the solution on the same rough path; dropping the
area (or flipping its sign) gives order ½ for the non-commuting isotropic rigid-body noise.

Set-up: a fine piecewise-linear lift of a Brownian path (2¹² steps on [0, 1]) is the driving geometric
rough path; coarse drivers are its Chen restrictions (exact increments and areas); the reference is
the Lie–Heun solution on the fine grid. The slope of log(RMS error) against log(dt) is fitted.
"""

import numpy as np
import pytest

from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun
from mechanics.systems.rigid_body import rigid_body
from roughpaths import RoughPath, solve

N_FINE = 2 ** 12
LEVELS = [2 ** k for k in range(4, 9)]     # coarse steps per unit time


_CACHE = {}


def _driver(rng, n_paths=32):
    if "X" in _CACHE:
        return _CACHE["X"]
    dw = rng.standard_normal((n_paths, N_FINE, 3)) * np.sqrt(1.0 / N_FINE)
    vals = np.concatenate([np.zeros((n_paths, 1, 3)), np.cumsum(dw, axis=1)], axis=1)
    _CACHE["X"] = RoughPath.from_path(vals, times=np.linspace(0.0, 1.0, N_FINE + 1))
    return _CACHE["X"]


def _fit(system, X, method, transform=None):
    if "ref" not in _CACHE:
        _CACHE["ref"] = solve(system, X, [0.0, 0.6, 0.8], LieHeun(), save_at="end").final
    ref = _CACHE["ref"]
    errs = []
    for n in LEVELS:
        Xc = X.restrict(X.times[:: N_FINE // n])
        if transform is not None:
            Xc = transform(Xc)
        y = solve(system, Xc, [0.0, 0.6, 0.8], method).states
        errs.append(np.sqrt(np.mean(np.sum((y[:, -1] - ref) ** 2, axis=-1))))
    slope = np.polyfit(np.log(1.0 / np.array(LEVELS)), np.log(errs), 1)[0]
    return slope, errs


def _drop_area(Xc):
    return RoughPath.from_path(Xc.path, times=Xc.times)       # same trace, zero Lévy area per step


def _flip_area(Xc):
    sym = 0.5 * (Xc.areas + np.swapaxes(Xc.areas, -1, -2))
    return RoughPath(Xc.increments, sym - Xc.step_levy_areas, times=Xc.times)


SYSTEM = rigid_body([1.0, 2.0, 3.0], sigma=1.0, s=np.array([[0, 1.0, 0], [-1.0, 0, 0], [0, 0, 0]]), theta=0.5)


@pytest.mark.parametrize("method", [LieHeun(), LieEuler(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_strong_order_one_with_area(method, rng):
    slope, errs = _fit(SYSTEM, _driver(rng), method)
    assert 0.85 <= slope <= 1.3, (slope, errs)


@pytest.mark.parametrize("transform", [_drop_area, _flip_area], ids=["no_area", "flipped_area"])
def test_order_one_half_without_correct_area(transform, rng):
    slope, errs = _fit(SYSTEM, _driver(rng), LieHeun(), transform)
    assert 0.35 <= slope <= 0.65, (slope, errs)
