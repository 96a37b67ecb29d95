"""The heavy top (se(3)*): Lie–Euler and Lie–Heun run the generic kernel's entry point (which runs its se(3)
block kernel, ``test_se3_block_kernel.py``), the implicit midpoint rule the hand-written one; each agrees with
the numpy scheme (``Solver.integrate``'s step loop) and keeps both Casimirs, |Γ|² and Π·Γ."""

import numpy as np
import pytest

from mechanics import ImplicitMidpoint, LieEuler, LieHeun, heavy_top
from mechanics.integrators import _generic_kernels, _se3_kernels
from roughpaths import BrownianDriver, Solver, solve


@pytest.mark.parametrize("solver, kernel", [(LieEuler(), "generic"), (LieHeun(), "generic"),
                                            (ImplicitMidpoint(), "se3")], ids=repr)
def test_heavy_top_kernel_and_numbers(solver, kernel, monkeypatch):
    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.3)
    calls = []
    for mod, name in ((_generic_kernels, "integrate_generic"), (_se3_kernels, "integrate_se3")):
        real = getattr(mod, name)
        monkeypatch.setattr(mod, name, lambda *a, _r=real, _n=name: calls.append(_n) or _r(*a))
    mu0 = np.random.default_rng(0).standard_normal((6, 6))
    X = BrownianDriver(3, seed=1, dt=0.01, n_steps=40, batch_shape=(6,)).rough_path()
    ours = solve(top, X, mu0, solver).states[:, 1:]
    assert calls == ["integrate_generic" if kernel == "generic" else "integrate_se3"]
    _, ref, _ = Solver.integrate(solver, top, mu0.copy(), X.times, X.increments, X.areas, np.ones(40, dtype=bool))
    assert np.max(np.abs(ours - ref) / np.maximum(1.0, np.abs(ref))) < 1e-11
    c0 = top.casimirs(mu0)[:, None]
    assert np.max(np.abs(top.casimirs(ours) - c0) / np.maximum(1.0, np.abs(c0))) < 1e-12
