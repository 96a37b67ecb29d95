"""Matrix Lie algebras (mechanics.MatrixLieAlgebra and the classical constructors).

Oracles: dense basis matrices and numpy commutators written here, scipy's ``expm`` of the ``n x n`` coadjoint
matrix, eigenvalues from ``numpy.linalg.eigvals``, and the structure constants that
``LieAlgebra.from_matrix_basis`` solves by least squares (an independent code path).
"""

import pickle
import tracemalloc

import numpy as np
import pytest
import scipy.linalg

import mechanics
from mechanics import LieAlgebra, MatrixLieAlgebra, sl, so, sp, su, u

BUILT = [so(3), so(4), so(5), su(2), su(3), su(4), u(1), u(3), sl(2), sl(3), sp(1), sp(2)]
IDS = [g.name for g in BUILT]


def _dense(g):
    return g.basis                                           # (n, N, N), formed from the sparse basis


def _commutator(A, B):
    return A @ B - B @ A


def _coords(basis, X):
    """Coordinates of ``X`` in ``basis`` by least squares over the reals (the naive oracle)."""
    n = basis.shape[0]
    F = basis.reshape(n, -1).T
    F = np.concatenate([F.real, F.imag])
    rhs = X.reshape(-1)
    rhs = np.concatenate([rhs.real, rhs.imag])
    c, *_ = np.linalg.lstsq(F, rhs, rcond=None)
    return c


@pytest.mark.parametrize("g", BUILT, ids=IDS)
def test_dimension_defining_conditions_and_gram(g):
    N, n = g.matrix_size, g.dim
    expected = {"so": N * (N - 1) // 2, "su": N * N - 1, "u": N * N, "sl": N * N - 1, "sp": (N // 2) * (N + 1)}
    assert n == expected[g.name.split("(")[0]]
    E = _dense(g)
    if g.name.startswith(("so", "su", "u(")):
        np.testing.assert_allclose(E + np.conj(np.swapaxes(E, 1, 2)), 0.0, atol=1e-15)   # skew(-Hermitian)
    if g.name.startswith(("su", "sl", "sp")):
        np.testing.assert_allclose(np.trace(E, axis1=1, axis2=2), 0.0, atol=1e-14)
    if g.name.startswith("sp"):
        h = N // 2
        J = np.block([[np.zeros((h, h)), np.eye(h)], [-np.eye(h), np.zeros((h, h))]])
        np.testing.assert_allclose(np.swapaxes(E, 1, 2) @ J + J @ E, 0.0, atol=1e-15)
    gram = -0.5 * np.einsum("iab,jba->ij", E, E).real
    np.testing.assert_allclose(gram, g.gram, atol=1e-14)
    np.testing.assert_allclose(np.abs(np.diag(gram)), 1.0, atol=1e-14)    # orthonormal up to sign
    assert g.compact == bool(np.all(np.diag(gram) > 0))
    assert np.linalg.matrix_rank(np.concatenate([E.reshape(n, -1).real, E.reshape(n, -1).imag], 1)) == n


@pytest.mark.parametrize("g", BUILT, ids=IDS)
def test_bracket_is_the_commutator_and_closes(g):
    rng = np.random.default_rng(7)
    E = _dense(g)
    x, y = rng.standard_normal((2, g.dim))
    X, Y = np.einsum("i,iab->ab", x, E), np.einsum("i,iab->ab", y, E)
    C = _commutator(X, Y)
    np.testing.assert_allclose(g.bracket(x, y), _coords(E, C), atol=1e-12)
    np.testing.assert_allclose(g.to_matrix(g.bracket(x, y)), C, atol=1e-12)       # closed: no residual
    np.testing.assert_allclose(g.from_matrix(X), x, atol=1e-13)


@pytest.mark.parametrize("g", [so(4), su(3), sl(3), sp(2)], ids=["so4", "su3", "sl3", "sp4"])
def test_structure_constants_match_the_least_squares_solution(g):
    ref = LieAlgebra.from_matrix_basis(_dense(g), check=True)
    np.testing.assert_allclose(g.structure_constants, ref.structure_constants, atol=1e-12)


@pytest.mark.parametrize("g", BUILT, ids=IDS)
def test_coadjoint_operator_and_its_flow(g):
    """<ad*_xi mu, eta> = <mu, [xi, eta]> (the library's sign), and exp(ad*_sigma) mu is the conjugation."""
    rng = np.random.default_rng(3)
    xi, eta, mu = rng.standard_normal((3, g.dim))
    np.testing.assert_allclose(g.ad_star(xi, mu) @ eta, mu @ g.bracket(xi, eta), atol=1e-12)
    c = g.structure_constants
    np.testing.assert_allclose(g.ad_star_matrix(xi), np.einsum("i,ijk->jk", xi, c), atol=1e-12)
    sigma = 0.4 * xi
    flow = scipy.linalg.expm(np.einsum("i,ijk->jk", sigma, c)) @ mu                   # oracle: n x n expm
    np.testing.assert_allclose(g.Ad_star_exp(sigma, mu), flow, atol=1e-12)
    np.testing.assert_allclose(g.casimirs(g.Ad_star_exp(sigma, mu)), g.casimirs(mu), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("g", [so(5), su(4), sl(3), sp(2)], ids=["so5", "su4", "sl3", "sp4"])
def test_casimirs_are_the_eigenvalue_power_sums(g):
    mu = np.random.default_rng(11).standard_normal((2, g.dim))
    M = g.dual_to_matrix(mu)
    lam = np.linalg.eigvals(1j * M if g.compact else M)
    ref = np.stack([np.sum(lam ** k, axis=-1).real for k in range(2, min(g.matrix_size, 6) + 1)], -1)
    np.testing.assert_allclose(g.casimirs(mu), ref, rtol=1e-12, atol=1e-12)
    assert g.casimir_names[0] == ("tr((iM)^2)" if g.compact else "tr(M^2)")


def test_dual_matrix_holds_the_pairing():
    """B(M(mu), X(eta)) = <mu, eta> for a basis that is not orthonormal (a user basis with a dense Gram matrix)."""
    E = su(3).basis.copy()
    E[0] = 2.0 * E[0] + E[1]
    E[5] *= 0.5
    g = MatrixLieAlgebra(E, name="skewed su3")
    rng = np.random.default_rng(2)
    mu, eta = rng.standard_normal((2, 8))
    assert g.compact
    np.testing.assert_allclose(g.pairing(g.dual_to_matrix(mu), g.to_matrix(eta)), mu @ eta, atol=1e-12)
    np.testing.assert_allclose(g.matrix_to_dual(g.dual_to_matrix(mu)), mu, atol=1e-12)
    ref = LieAlgebra.from_matrix_basis(E)
    np.testing.assert_allclose(g.ad_star(eta, mu), ref.ad_star(eta, mu), atol=1e-12)


def test_user_basis_refusals():
    E = su(3).basis
    with pytest.raises(ValueError, match="not closed under the commutator"):
        MatrixLieAlgebra(E[:2])
    with pytest.raises(ValueError, match="degenerate.*from_matrix_basis"):
        MatrixLieAlgebra(mechanics.se3().basis)                       # se(3): the trace form is degenerate
    with pytest.raises(ValueError, match="degenerate"):
        MatrixLieAlgebra(np.concatenate([E, E[:1]]))                  # dependent
    with pytest.raises(ValueError, match=r"shape \(n, N, N\)"):
        MatrixLieAlgebra(np.zeros((3, 2, 3)))
    with pytest.raises(TypeError, match="real or complex"):
        MatrixLieAlgebra(np.array([[["a"]]]))
    with pytest.raises(ValueError, match="N must be an integer >= 2"):
        su(1)
    with pytest.raises(ValueError, match="compact"):
        sl(3).sample_orbit(np.ones(8), 2, np.random.default_rng(0))


@pytest.mark.parametrize("g", [so(4), su(3), u(2), sp(2)], ids=["so4", "su3", "u2", "sp4"])
def test_pickle_round_trip(g):
    h = pickle.loads(pickle.dumps(g))
    x = np.arange(g.dim) / 7.0
    assert h.name == g.name and h.compact == g.compact
    np.testing.assert_array_equal(h.to_matrix(x), g.to_matrix(x))
    X = g.to_matrix(x) + 1e-9
    np.testing.assert_array_equal(h._project(X), g._project(X))


def test_orbit_samples_stay_on_the_orbit():
    g = su(4)
    mu = np.random.default_rng(0).standard_normal(g.dim)
    draws = g.sample_orbit(mu, 50, np.random.default_rng(1))
    np.testing.assert_allclose(g.casimirs(draws), np.broadcast_to(g.casimirs(mu), (50, 3)), rtol=1e-11, atol=1e-11)
    assert np.std(draws[:, 0]) > 0.1                                  # not one point


def test_large_algebras_form_nothing_of_size_n_squared():
    """su(64) has n = 4095: an n x n array is 134 MB, the structure constants 549 GB. Building it and mapping a
    batch of states stays small."""
    tracemalloc.start()
    g = su(64)
    mu = np.random.default_rng(0).standard_normal((4, g.dim))
    M = g.dual_to_matrix(mu)
    back = g.matrix_to_dual(M)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    np.testing.assert_allclose(back, mu, atol=1e-12)
    assert peak < 20e6, peak
    with pytest.raises(ValueError, match=r"structure constants of su\(64\).*512 GiB.*matrix operations"):
        g.structure_constants


@pytest.mark.parametrize("make, size, arg", [(su, 512, "N"), (u, 512, "N"), (so, 1024, "n"), (sl, 512, "n"),
                                             (sp, 256, "n")], ids=["su", "u", "so", "sl", "sp"])
def test_a_basis_above_the_memory_budget_is_refused_before_it_is_built(monkeypatch, make, size, arg):
    """The sparse bases are built as Python lists first (about 250 bytes a non-zero entry at the peak, 2.5 N^2
    entries for su(N)): su(512) took 153 MiB and 2 s, su(4096) would take 10 GiB and minutes, with no check."""
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(2**25))
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match=rf"basis of .* at {arg} = {size} \(.* non-zero entries.*\) would take "
                                             rf".* memory budget .*; use a smaller {arg}\."):
            make(size)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**20, peak
