r"""The summed fine Lévy areas of a refined coarse step, with few retained Fourier terms.

Claim (Brownian closed form). A Brownian step of length ``h`` split into ``F`` sub-steps of length
:math:`\delta = h/F` has independent fine Lévy areas, each of variance :math:`\delta^2/4` per component, so
the Chen sum :math:`\Sigma = \sum_l A_l = A - \tfrac12\sum_{l<l'} w_l\wedge w_{l'}` has
:math:`\mathrm{Var}(\Sigma^{ij}) = F\delta^2/4 = h^2/(4F)` (the coarse area's :math:`h^2/4` minus the
:math:`h^2(1 - 1/F)/4` that the cross terms carry). The closed form is checked against an independent fine
simulation (a fine ``BrownianDriver`` with ``"exact"`` areas at step δ).

* With the coarse area drawn from its exact law (``levy_area="exact"``, ``d = 2``), the refinement
  reproduces :math:`h^2/(4F)` within 4 standard errors (``F = 8``).
* With ``n`` retained terms of the Mrongowius–Rößler sampler the coarse tail's own area is a Gaussian (the
  method's approximation); the refinement conditions Brownian (bilinear, heavier-tailed) explicit terms on
  it, they explain less of it than of a Brownian tail area, and the fine areas inherit the rest through
  Chen's identity as a positive neighbour correlation. Measured (the ``slow`` test: ``F = 8``, ``h = 1``,
  10⁵ coarse steps per case; relative excess of :math:`\mathrm{Var}(\Sigma)` over :math:`h^2/(4F)`, ± one
  standard error), with the former 3 Gibbs sweeps and with the present 8:

  ======  ===================  ===================  ===================  ===================
  ``n``   d = 2, 3 sweeps      d = 2, 8 sweeps      d = 3, 3 sweeps      d = 3, 8 sweeps
  ======  ===================  ===================  ===================  ===================
  1       +2.17 ± 0.47 %       +2.23 ± 0.47 %       +3.81 ± 0.28 %       +3.36 ± 0.28 %
  2       +0.82 ± 0.47 %       +0.98 ± 0.46 %       +0.86 ± 0.27 %       +0.93 ± 0.27 %
  4       +0.60 ± 0.47 %       +0.03 ± 0.47 %       -0.06 ± 0.28 %       +0.08 ± 0.28 %
  ======  ===================  ===================  ===================  ===================

  More sweeps do not remove it (d = 3, n = 1, 10⁵ steps: +4.0, +3.1, +3.3 % with 3, 10, 30 sweeps), and
  with a Brownian tail area in place of the Gaussian (fed to the same construction) the excess is
  +0.9 ± 0.4 %: it is the coarse method's approximation, not the conditioning. The test checks the
  documented bound (excess below ``_BOUND[n]`` = 6 %, 2.5 %, 1 % within 4 standard errors) and records, as
  a strict ``xfail``, that ``n = 1`` is not Brownian: the open part of the refinement's error budget.
"""

import math

import numpy as np
import pytest

from roughpaths import BrownianDriver

_MR_C = {2: math.sqrt(2) / (math.sqrt(12) * math.pi), 3: math.sqrt(3) / (math.sqrt(12) * math.pi)}
#: documented bound on the relative excess of Var(Σ) (module docstring of roughpaths.drivers.refinement)
_BOUND = {1: 0.06, 2: 0.025, 4: 0.01}


def _summed_fine_areas(method, d, F, paths, steps, seed, n=None, h=1.0):
    kw = {}
    if n is not None:           # the error at which levy_area_terms gives exactly n terms
        kw["levy_area_error"] = _MR_C[d] * h / n * (1 + 1e-7)
    drv = BrownianDriver(d, seed=seed, dt=h, n_steps=steps, batch_shape=(paths,), levy_area=method, **kw)
    fine = drv.refine(F)
    if n is not None:
        assert fine._plan(h).n == n
    A = fine.rough_path().step_levy_areas.reshape(-1, F, d, d)
    iu, ju = np.triu_indices(d, 1)
    return A.sum(axis=1)[:, iu, ju]                                  # (steps, pairs)


def _relative_excess(S, target):
    """Relative excess of E[Σ²] over ``target`` and its standard error (per-step statistic, pairs averaged)."""
    x = (S ** 2).mean(axis=1) / target
    return float(x.mean() - 1.0), float(x.std(ddof=1) / math.sqrt(x.size))


def test_closed_form_matches_an_independent_fine_simulation():
    F, h, paths, steps = 8, 1.0, 200, 400
    fine = BrownianDriver(2, seed=1, dt=h / F, n_steps=steps * F, batch_shape=(paths,), levy_area="exact")
    A = fine.rough_path().step_levy_areas[..., 0, 1].reshape(-1, F).sum(axis=1)
    ex, se = _relative_excess(A[:, None], h * h / (4 * F))
    assert abs(ex) < 4 * se, (ex, se)


def test_exact_coarse_area_gives_the_brownian_sum_variance():
    F = 8
    S = _summed_fine_areas("exact", 2, F, paths=200, steps=200, seed=3)
    ex, se = _relative_excess(S, 1.0 / (4 * F))
    assert abs(ex) < 4 * se, (ex, se)


@pytest.mark.parametrize("n, d", [(1, 2), (2, 2), (4, 2), (2, 3),                     # d = 3, n = 1, 4: slow
                                  pytest.param(1, 3, marks=pytest.mark.slow), pytest.param(4, 3, marks=pytest.mark.slow)])
def test_few_terms_excess_within_the_documented_bound(n, d):
    F = 8
    S = _summed_fine_areas("mrongowius-rossler", d, F, paths=100, steps=150, seed=10 * n + d, n=n)
    ex, se = _relative_excess(S, 1.0 / (4 * F))
    assert -4 * se < ex < _BOUND[n] + 4 * se, (n, d, ex, se)


@pytest.mark.slow                      # a 14 s statistical run: the open case is tracked in the slow suite
@pytest.mark.xfail(strict=True, reason="open: with one retained term the Gaussian coarse tail area makes the "
                                       "summed fine areas' variance ~4 % high (d = 3); see the module docstring")
def test_one_term_is_brownian():
    F, d = 8, 3
    S = _summed_fine_areas("mrongowius-rossler", d, F, paths=200, steps=250, seed=7, n=1)
    ex, se = _relative_excess(S, 1.0 / (4 * F))
    assert abs(ex) < 4 * se, (ex, se)


@pytest.mark.slow
@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("n", [1, 2, 4])
def test_few_terms_excess_full(n, d):
    F = 8
    S = _summed_fine_areas("mrongowius-rossler", d, F, paths=500, steps=200, seed=100 + 10 * n + d, n=n)
    ex, se = _relative_excess(S, 1.0 / (4 * F))
    print(f"MR d={d} n={n}: relative excess {ex:+.4f} ± {se:.4f}")
    assert -4 * se < ex < _BOUND[n] + 4 * se, (n, d, ex, se)
