"""Adaptive coadjoint steps: LieHeun on a BrownianTree keeps the Casimir and converges at order 1 in rtol.

Claim: ``solve(rigid_body, tree, mu0, LieHeun(), step_control=PIController(rtol, rtol))`` keeps ``|Π|`` to
round-off whatever steps the controller takes, and its strong error against a fine fixed-step LieHeun solve
on the same tree falls in proportion to ``rtol`` (fitted slope near 1, not the 2/3 of an error-per-step rule).
"""

import numpy as np

import roughpaths as rp
from mechanics import LieHeun, rigid_body

MU0 = np.array([0.0, 0.0, 1.0])


def test_adaptive_lie_heun_keeps_the_casimir_and_converges_in_rtol():
    body = rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0)
    tree = rp.BrownianTree(3, seed=5, batch_shape=(16,))
    ref = rp.solve(body, tree.rough_path(np.linspace(0.0, 1.0, 2 ** 12 + 1)), MU0, LieHeun(), save_at="end").final
    rtols = [1e-2, 3e-3, 1e-3]
    errs = []
    for rtol in rtols:
        sol = rp.solve(body, tree, MU0, LieHeun(), step_control=rp.PIController(rtol, rtol))
        assert np.max(sol.stats["accepted"]) * 8 <= 2 ** 12
        assert np.abs(np.linalg.norm(sol.states, axis=-1) - 1.0).max() < 1e-12
        errs.append(float(np.sqrt(np.mean(np.sum((sol.final - ref) ** 2, axis=-1)))))
    slope = np.polyfit(np.log(rtols), np.log(errs), 1)[0]
    assert 0.8 <= slope <= 1.3, (slope, errs)
