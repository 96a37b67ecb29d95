"""Lie algebra axioms, for every algebra the library builds.

Claims: the bracket is antisymmetric and satisfies Jacobi; ``ad(x) @ y == [x, y]``; the coadjoint
operator is the transpose, ⟨ad*_ξ μ, η⟩ = ⟨μ, [ξ, η]⟩ (coordinate pairing, no minus sign); it is an
anti-homomorphism, [ad*_ξ, ad*_η] = -ad*_{[ξ,η]}; matrix bases represent the bracket as the
commutator; Ad*_{exp σ} = expm(ad*_σ) (closed forms checked against scipy's expm) preserves the
Casimirs; the Killing form matches its closed form. Model: generic group tests of jaxlie/geomstats.
"""

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from mechanics.systems.lie_algebra import LieAlgebra, hat, se3, sl2r, so3, su2, vee

FACTORIES = {"so3": so3, "su2": su2, "se3": se3, "sl2r": sl2r}


def _so4():
    basis = []
    for i in range(4):
        for j in range(i + 1, 4):
            m = np.zeros((4, 4))
            m[i, j], m[j, i] = 1.0, -1.0
            basis.append(m)
    return LieAlgebra.from_matrix_basis(np.array(basis), name="so4")


ALGEBRAS = dict(FACTORIES, so4=_so4)


def _vecs(n):
    return arrays(np.float64, (3, n), elements=st.floats(-3, 3, allow_nan=False, allow_infinity=False))


@pytest.fixture(params=sorted(ALGEBRAS))
def algebra(request):
    return ALGEBRAS[request.param]()


def _naive_bracket(c, x, y):
    n = len(x)
    out = np.zeros(n)
    for i in range(n):
        for j in range(n):
            for k in range(n):
                out[k] += x[i] * y[j] * c[i, j, k]
    return out


def test_bracket_antisymmetry_jacobi_and_ad(algebra, rng):
    n = algebra.dim
    c = algebra.structure_constants
    for _ in range(20):
        x, y, z = rng.standard_normal((3, n))
        b = algebra.bracket
        np.testing.assert_allclose(b(x, y), -b(y, x), atol=1e-13)
        jac = b(b(x, y), z) + b(b(y, z), x) + b(b(z, x), y)
        np.testing.assert_allclose(jac, 0.0, atol=1e-11)
        np.testing.assert_allclose(b(x, y), _naive_bracket(c, x, y), atol=1e-13)
        np.testing.assert_allclose(algebra.ad(x) @ y, b(x, y), atol=1e-13)


@given(v=_vecs(3))
def test_so3_bracket_is_cross_product(v):
    x, y, _ = v
    np.testing.assert_allclose(so3().bracket(x, y), np.cross(x, y), atol=1e-12)
    np.testing.assert_allclose(so3().ad_star(x, y), np.cross(y, x), atol=1e-12)   # ad*_ξ Π = Π × ξ


@pytest.mark.parametrize("name", sorted(ALGEBRAS))
def test_ad_star_duality_hypothesis(name):
    alg = ALGEBRAS[name]()

    @given(v=_vecs(alg.dim))
    def check(v):
        xi, mu, eta = v
        lhs = alg.ad_star(xi, mu) @ eta
        rhs = mu @ alg.bracket(xi, eta)
        assert abs(lhs - rhs) <= 1e-10 * (1 + abs(lhs))
        # the opposite sign convention would fail unless both vanish
        if abs(rhs) > 1e-6:
            assert abs(lhs + rhs) > 1e-8

    check()


def test_ad_star_is_antihomomorphism_and_bracket_of_noise_fields(algebra, rng):
    n = algebra.dim
    x, y, mu = rng.standard_normal((3, n))
    ax, ay = algebra.ad_star_matrix(x), algebra.ad_star_matrix(y)
    np.testing.assert_allclose(ax @ ay - ay @ ax, -algebra.ad_star_matrix(algebra.bracket(x, y)), atol=1e-12)
    # Jacobi–Lie bracket of V_x = ad*_x μ and V_y (docs/conventions.md: [V,W] = DW V - DV W) = ad*_{[x,y]} μ
    vw = ay @ (ax @ mu) - ax @ (ay @ mu)
    np.testing.assert_allclose(vw, algebra.ad_star(algebra.bracket(x, y), mu), atol=1e-12)
    np.testing.assert_allclose(algebra.coadjoint_orbit_tangent(mu) @ x, algebra.ad_star(x, mu), atol=1e-13)


def test_matrix_basis_represents_the_bracket(algebra, rng):
    if algebra.basis is None:
        pytest.skip("no matrix basis")
    x, y = rng.standard_normal((2, algebra.dim))
    X, Y = algebra.to_matrix(x), algebra.to_matrix(y)
    np.testing.assert_allclose(algebra.to_matrix(algebra.bracket(x, y)), X @ Y - Y @ X, atol=1e-12)


def test_ad_star_exp_is_expm_and_preserves_casimirs(algebra, rng):
    n = algebra.dim
    sig = 0.7 * rng.standard_normal((5, n))
    mu = rng.standard_normal((5, n))
    ref = np.stack([scipy.linalg.expm(algebra.ad_star_matrix(s)) @ m for s, m in zip(sig, mu)])
    got = algebra.Ad_star_exp(sig, mu)
    np.testing.assert_allclose(got, ref, atol=1e-12)
    np.testing.assert_allclose(algebra.casimirs(got), algebra.casimirs(mu), atol=1e-12)
    # tiny sigma: the series branch of the closed forms
    small = algebra.Ad_star_exp(1e-7 * sig, mu)
    np.testing.assert_allclose(small, mu + algebra.ad_star(1e-7 * sig, mu), atol=1e-13)


def test_casimirs_are_casimirs(algebra, rng):
    """dC(μ)·ad*_ξ μ = 0 for every ξ (Casimirs are constant on coadjoint orbits)."""
    mu = rng.standard_normal(algebra.dim)
    for _ in range(5):
        xi = rng.standard_normal(algebra.dim)
        eps = 1e-6
        d = (algebra.casimirs(mu + eps * algebra.ad_star(xi, mu)) - algebra.casimirs(mu - eps * algebra.ad_star(xi, mu))) / (2 * eps)
        np.testing.assert_allclose(d, 0.0, atol=1e-7)


def test_killing_forms_closed_form():
    np.testing.assert_allclose(so3().killing_form(), -2 * np.eye(3), atol=1e-13)
    np.testing.assert_allclose(su2().killing_form(), -2 * np.eye(3), atol=1e-13)
    k = sl2r().killing_form()    # basis H, E, F: K(H,H) = 8, K(E,F) = 4
    np.testing.assert_allclose(k, [[8, 0, 0], [0, 0, 4], [0, 4, 0]], atol=1e-13)
    assert so3().is_semisimple and sl2r().is_semisimple and not se3().is_semisimple
    # trace form cross-check: K(x, y) = tr(ad_x ad_y)
    g, x, y = sl2r(), np.array([0.3, -1.2, 0.5]), np.array([1.1, 0.4, -0.7])
    assert abs(g.killing_form(x, y) - np.trace(g.ad(x) @ g.ad(y))) < 1e-12


def test_group_exp_matches_ad_star_exp_so3(rng):
    """so(3): exp(hat σ) is the rotation R(σ); Ad*_{exp σ} μ = R(σ)ᵀ μ."""
    g = so3()
    sig, mu = rng.standard_normal((2, 3))
    R = g.exp(sig)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-13)
    np.testing.assert_allclose(g.Ad_star_exp(sig, mu), R.T @ mu, atol=1e-13)
    np.testing.assert_allclose(vee(hat(sig)), sig)


def test_bad_algebras_rejected():
    c = so3().structure_constants
    with pytest.raises(ValueError, match="antisymmetric"):
        LieAlgebra(np.abs(c))
    bad = c.copy()
    bad[0, 1, 0], bad[1, 0, 0] = 1.0, -1.0          # antisymmetric but breaks Jacobi
    bad[0, 2, 2], bad[2, 0, 2] = 0.5, -0.5
    with pytest.raises(ValueError, match="Jacobi"):
        LieAlgebra(bad)
    with pytest.raises(ValueError, match="closed"):
        LieAlgebra.from_matrix_basis(np.array([[[0.0, 1.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]]]))
    with pytest.raises(ValueError, match="dependent"):
        LieAlgebra.from_matrix_basis(np.array([hat([1.0, 0, 0]), hat([2.0, 0, 0])]))
    with pytest.raises(ValueError, match="trailing shape"):
        so3().bracket(np.ones(4), np.ones(4))
    with pytest.raises(ValueError, match="no known Casimirs"):
        LieAlgebra(se3().structure_constants).casimirs(np.ones(6))


def test_algebras_from_constants_pickle_with_their_casimir():
    """sl(2, R) from constants (its quadratic Casimir from the Killing form) pickles: systems on it go to
    checkpoints and process executors like any other."""
    import pickle

    from mechanics import LiePoissonSystem, sl2r

    g = sl2r()
    h = pickle.loads(pickle.dumps(LiePoissonSystem(g, np.eye(3), 0.1 * np.eye(3)))).algebra
    mu = np.array([0.3, -1.2, 2.0])
    np.testing.assert_array_equal(h.casimirs(mu), g.casimirs(mu))
    np.testing.assert_allclose(g.casimirs(mu), [mu @ np.linalg.inv(g.killing_form()) @ mu], rtol=1e-14)
