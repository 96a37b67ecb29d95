"""Claim: a Lie–Euler or Lie–Heun solve gives the same bits whichever kernel variant it starts with.

The compiled coadjoint kernels (so(3), a user algebra's generic kernel, se(3)) come in two variants: the
vectorised loop alone, which returns at a step past the vectorised exponential so that the rare-step kernel does
it before the solve goes on with the other variant, and the loop with the exact step inline. Which one a solve
starts with is process state (``_soa_rows.starts_full``). Here the same solve, with a member that passes the
vectorised exponential in the middle of the run (and one that becomes non-finite), is run from each start and
the results, failures and saved states compared bit for bit; the solve must also really take the exact step
(its result differs from a run where that member's noise is small).
"""

import numpy as np
import pytest

from mechanics import heavy_top, rigid_body
from mechanics.integrators import LieEuler, LieHeun, _soa_rows
from mechanics.systems.lie_algebra import su2
from mechanics.systems.lie_poisson import LiePoissonSystem
from roughpaths import BrownianDriver, RoughPath, solve

SYSTEMS = {
    "so3": lambda: rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5),
    "generic su2": lambda: LiePoissonSystem(su2(), np.eye(3), 0.3 * np.eye(3), theta=0.5),
    "se3": lambda: heavy_top([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], sigma=0.3),
}


def _path(nb):
    Y = BrownianDriver(3, seed=7, dt=0.01, n_steps=40, batch_shape=(nb,), levy_area="davie").rough_path()
    inc = np.array(Y.increments)
    inc[1, 20:23] *= 60.0                 # member 1: three steps past the vectorised exponential, mid-run
    inc[2, 30, 0] = np.nan                # member 2: non-finite from step 30
    return RoughPath(inc, Y.areas, times=Y.times, kind="geometric", check=False)


class _Forced(dict):
    """The kernels' start state, forced: every kernel starts with ``full``; a solve that needs the exact step
    records the start it had (``saw_rare_step``)."""

    def __init__(self, full, record):
        super().__init__()
        self.full, self.record = full, record

    def __contains__(self, key):
        return True

    def __getitem__(self, key):
        return self.full

    def __setitem__(self, key, value):
        self.record.append(self.full)


@pytest.mark.parametrize("solver", [LieEuler(), LieHeun()], ids=repr)
@pytest.mark.parametrize("name", list(SYSTEMS))
def test_both_starts_give_the_same_bits(name, solver, monkeypatch):
    system = SYSTEMS[name]()
    nb = 5
    X = _path(nb)
    mu0 = np.tile(np.eye(system.dim)[-1], (nb, 1)) + 0.1
    runs, turned_on = [], []
    for start_full in (False, True):
        monkeypatch.setattr(_soa_rows, "_STARTS", _Forced(start_full, turned_on))
        with np.errstate(all="ignore"):
            runs.append(solve(system, X, mu0, solver, on_failure="mask"))
    a, b = runs
    assert turned_on == [False]           # the first run did start vectorised and met the rare step
    assert a.states.tobytes() == b.states.tobytes()
    assert np.array_equal(a.failed, b.failed) and a.failed.tolist() == [False, False, True, False, False]
    # the exact step was taken: member 1's result is not that of the same run with its burst left out
    calm = np.array(X.increments)
    calm[1, 20:23] /= 60.0
    Xc = RoughPath(calm, X.areas, times=X.times, kind="geometric", check=False)
    with np.errstate(all="ignore"):
        c = solve(system, Xc, mu0, solver, on_failure="mask")
    assert np.all(np.isfinite(a.final[1])) and not np.allclose(a.final[1], c.final[1])
    assert a.final[0].tobytes() == c.final[0].tobytes()          # the other members are their own
