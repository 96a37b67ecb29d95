"""The quantisation converges to the Poisson algebra of the sphere as N grows.

Statement checked: with T(f) = sum f_lm T_lm (mechanics.sphere, Hermitian convention) and hbar = 2/sqrt(N^2-1),
for fixed harmonics Y_a, Y_b (relative Frobenius errors, fitted in log-log over N = 16..64):

* T_a T_b - T(Y_a Y_b) = O(1/N)                           (measured slope -1.00),
* (T_a T_b + T_b T_a)/2 - T(Y_a Y_b) = O(1/N^2)           (measured slope -2.0),
* [T_a, T_b]/(i hbar) - T({Y_a, Y_b}) = O(1/N^2)         (measured slope -2.0), exact when l_a = 1,

with {f, g} = x.(grad f x grad g). The opposite sign of the bracket stays O(1) away (error -> 2). Oracles: scipy's
sph_harm_y, the textbook identity for d/dtheta Y_lm, Gauss quadrature from numpy.
"""

import numpy as np
import pytest

from _sphere_oracles import Field, bracket, fitted_slope, project
from mechanics.sphere import harmonic_matrix, hbar

PAIRS = [((2, 1), (3, -2)), ((3, 0), (2, 2)), ((4, -1), (2, 0))]
NS = [8, 16, 32, 64]


def quantise(coeffs, N):
    out = np.zeros((N, N), dtype=complex)
    for (l, m), c in coeffs.items():
        if l < N and abs(c) > 1e-15:
            out += c * harmonic_matrix(N, l, m)
    return out


def rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


@pytest.mark.parametrize("a, b", PAIRS)
def test_products_and_brackets_converge(a, b):
    fa, fb = Field({a: 1.0}), Field({b: 1.0})
    L = a[0] + b[0] + 1
    prod = project(lambda th, ph: fa(th, ph) * fb(th, ph), L)
    brk = project(bracket(fa, fb), L)
    errs = {"prod": [], "sym": [], "bracket": [], "wrong sign": []}
    for N in NS:
        Ta, Tb = harmonic_matrix(N, *a), harmonic_matrix(N, *b)
        P, B = quantise(prod, N), quantise(brk, N)
        com = (Ta @ Tb - Tb @ Ta) / (1j * hbar(N))
        errs["prod"].append(rel(Ta @ Tb, P))
        errs["sym"].append(rel(0.5 * (Ta @ Tb + Tb @ Ta), P))
        errs["bracket"].append(rel(com, B))
        errs["wrong sign"].append(rel(-com, B))
    # slopes over N = 16..64 (N = 8 is pre-asymptotic for degree-4 products)
    assert -1.15 < fitted_slope(NS[1:], errs["prod"][1:]) < -0.9
    assert -2.2 < fitted_slope(NS[1:], errs["sym"][1:]) < -1.8
    assert -2.2 < fitted_slope(NS[1:], errs["bracket"][1:]) < -1.8
    assert errs["bracket"][-1] < 3e-3
    assert min(errs["wrong sign"]) > 1.8


@pytest.mark.parametrize("b", [(4, 3), (3, -2), (5, 0)])
def test_brackets_with_degree_one_are_exact(b):
    """{x_a, .} is the rotation generator; its quantisation ad_{S_a} is exact at every N."""
    fb = Field({b: 1.0})
    for a in [(1, 0), (1, 1), (1, -1)]:
        fa = Field({a: 1.0})
        brk = project(bracket(fa, fb), a[0] + b[0] + 1)
        for N in (6, 13):
            Ta, Tb = harmonic_matrix(N, *a), harmonic_matrix(N, *b)
            com = (Ta @ Tb - Tb @ Ta) / (1j * hbar(N))
            np.testing.assert_allclose(com, quantise(brk, N), atol=1e-12)


@pytest.mark.slow
def test_bracket_rate_up_to_n_256():
    a, b = (3, 1), (5, -2)
    fa, fb = Field({a: 1.0}), Field({b: 1.0})
    brk = project(bracket(fa, fb), a[0] + b[0] + 1)
    ns = [16, 32, 64, 128, 256]
    errs = []
    for N in ns:
        Ta, Tb = harmonic_matrix(N, *a), harmonic_matrix(N, *b)
        errs.append(rel((Ta @ Tb - Tb @ Ta) / (1j * hbar(N)), quantise(brk, N)))
    assert -2.1 < fitted_slope(ns, errs) < -1.9
