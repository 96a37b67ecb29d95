"""Beyond the paper (issue 38): SALT Euler on the sphere with adaptive steps on a Brownian tree.

Claim: ``solve(zeitlin_system(...), BrownianTree, W0, LieHeun(), step_control=PIController(rtol, rtol))`` (the
areas of each step read from the tree, Chen-consistently) has a strong error at t = 1 proportional to ``rtol``
against a fixed-step LieHeun solve with 2^11 steps on the same tree (fitted slope of log error against log rtol
in [0.8, 1.4]; with steps per member, the default, 0.92, 0.95 and 1.04 on the trees of seeds 9, 10, 11 over
rtol = 3e-5 .. 3e-6, where members take about 20 to 190 steps), and keeps every Casimir tr((iW)^k), k = 2..6,
to 1e-12 relative whatever the steps (the step sizes change, the update stays a conjugation). N = 16, three
non-commuting SALT modes of amplitude 0.3, s^{12} = 1, four paths.
"""

import numpy as np

from _sphere_oracles import power_traces, smooth_coefficients
import roughpaths as rp
from mechanics import LieHeun
from mechanics.sphere import coefficients_to_matrix, zeitlin_system


def test_adaptive_error_proportional_to_rtol_and_casimirs_kept():
    N = 16
    system = zeitlin_system(N, amplitudes=0.3, s=np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    g = system.algebra
    W0 = coefficients_to_matrix(0.5 * smooth_coefficients(np.random.default_rng(1), 3), N)
    y0 = g.matrix_to_dual(W0)
    tree = rp.BrownianTree(3, seed=9, batch_shape=(4,))
    ref = rp.solve(system, tree.rough_path(np.linspace(0.0, 1.0, 2 ** 11 + 1)), y0, LieHeun(), save_at="end").final
    c0, scale = power_traces(W0)
    rtols = [3e-5, 1e-5, 3e-6]
    errors, steps = [], []
    for rtol in rtols:
        sol = rp.solve(system, tree, y0, LieHeun(), step_control=rp.PIController(rtol, rtol), save_at="end")
        errors.append(float(np.sqrt(np.mean(np.sum((sol.final - ref) ** 2, axis=-1)))))
        steps.append(float(np.mean(sol.stats["accepted"])))
        for M in g.dual_to_matrix(sol.final):
            assert np.max(np.abs(power_traces(M)[0] - c0) / scale) <= 1e-12
    slope = float(np.polyfit(np.log(rtols), np.log(errors), 1)[0])
    assert 0.8 <= slope <= 1.4, (slope, errors, steps)
    assert steps[0] < steps[-1]
