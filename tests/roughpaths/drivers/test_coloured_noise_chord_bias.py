r"""Claim: the chord lift's Lévy-area-rate bias for the paper's ``A`` has the closed form of the docstring.

:mod:`roughpaths.drivers.coloured_noise` derives, for ``A = kI + Λ`` (``Λ13 = 1 = −Λ31``), ``D = I``,
that the piecewise-linear (chord) lift's relative bias of the Lévy-area rate is
``1 − |a|² Im f(ā)``, ``a = k + i``, ``f(z) = (1 − e^{−zδ})/(z²δ)``, i.e. ``(δ‖A‖)²/6 + O(δ³)``:
1.0 % at ``δ‖A‖ = 0.25`` (the docstring used to say 0.4 %). The tests compare the closed form with
:func:`roughpaths.lift_area_rate` (matrix exponentials, no complex numbers) for several ``k`` and ``δ``,
check the leading term, and that the docstring states the derived value.

Peers: none of the peer suites (iisignature, signatory, pySigLib, LevyArea.jl) covers coloured noise;
this extends ``test_coloured_noise_limit.py::test_lift_bias_small_at_default_resolution``, which only
bounds the bias, to its exact value.
"""

import numpy as np
import pytest

import roughpaths.drivers.coloured_noise as coloured_noise
from roughpaths import coloured_noise_limit, lift_area_rate, paper_coloured_noise_matrices


def _closed_form_bias(k, delta):
    a = complex(k, 1.0)
    ab = a.conjugate()
    f = (1.0 - np.exp(-ab * delta)) / (ab * ab * delta)
    return 1.0 - abs(a) ** 2 * f.imag


def _lift_bias(k, delta, hermite):
    A, D = paper_coloured_noise_matrices(k)
    exact = coloured_noise_limit(A, D).N[0, 2]
    r = lift_area_rate(A, D, delta, hermite=hermite)
    return (exact - 0.5 * (r - r.T)[0, 2]) / exact


@pytest.mark.parametrize("k", [0.05, 0.5, 2.0])
@pytest.mark.parametrize("x", [0.5, 0.25, 0.1, 0.02])
def test_chord_bias_closed_form(k, x):
    delta = x / np.hypot(k, 1.0)                              # δ‖A‖ = x (‖A‖₂ = |k + i|)
    A, _ = paper_coloured_noise_matrices(k)
    assert np.linalg.norm(A, 2) == pytest.approx(np.hypot(k, 1.0), rel=1e-12)
    assert _lift_bias(k, delta, hermite=False) == pytest.approx(_closed_form_bias(k, delta), rel=1e-8, abs=1e-14)


def test_leading_term_and_the_stated_values():
    for x in (0.05, 0.02):
        assert _closed_form_bias(0.05, x / np.hypot(0.05, 1.0)) / (x * x / 6) == pytest.approx(1.0, abs=0.02)
    delta = 0.25 / np.hypot(0.05, 1.0)
    chord = _lift_bias(0.05, delta, hermite=False)
    assert round(100 * chord, 1) == 1.0                       # "1.0 % at δ‖A‖ = 0.25"
    assert _lift_bias(0.05, delta, hermite=True) == pytest.approx(2.4e-5, rel=0.05)   # "2.4·10⁻⁵"


def test_docstring_states_the_derived_value():
    doc = coloured_noise.__doc__
    assert "1.0 % at ``δ‖A‖ = 0.25``" in doc and "(δ‖A‖)²/6" in doc
    assert "0.4 %" not in doc
