"""Vector-field families: evaluation, Jacobians, the Jacobi–Lie bracket and the Friz–Oberhauser drift.

Claims checked against independent oracles:

* linear fields evaluate to ``M_i y`` and have Jacobian ``M_i`` (naive loops);
* the central-difference Jacobian of a callable without a user Jacobian agrees with the analytic
  Jacobian to the documented accuracy (``~1e-10`` relative, asserted ``< 1e-8``);
* the bracket ``[V, W] = DW·V − DV·W`` is the second-order term of the flow commutator,
  ``φ^W_{-t} φ^V_{-t} φ^W_t φ^V_t (y) = y + t² [V, W](y) + O(t³)`` (flows by RK4, no bracket code),
  and the opposite sign fails that check;
* the Friz–Oberhauser drift equals ``Σ_{i,j} s^{ij} DV_j·V_i = Σ_{i<j} s^{ij}[V_i, V_j]`` (naive sums),
  hypothesis over ``s`` and ``y``; a non-antisymmetric ``s`` is rejected;
* the batched Padé exponential agrees with ``scipy.linalg.expm``.
"""

import numpy as np
from _oracles import rk4_flow
import pytest
import scipy.linalg
from hypothesis import example, given
from hypothesis import strategies as st

from roughpaths import expm_batched, LinearDrift, LinearVectorFields, VectorFields

E, D = 3, 2


def _nonlinear(rng):
    """Non-commuting non-linear fields on R^3: V_i(y) = M_i y + sin(N_i y), with analytic Jacobians."""
    M = 0.7 * rng.standard_normal((D, E, E))
    N = 0.9 * rng.standard_normal((D, E, E))

    def fields(y):
        return np.stack([y @ M[i].T + np.sin(y @ N[i].T) for i in range(D)], axis=-1)

    def jac(y):
        return np.stack([M[i] + np.cos(y @ N[i].T)[..., :, None] * N[i] for i in range(D)], axis=-3)

    return fields, jac


def test_linear_fields_and_jacobians_match_naive_loops(rng):
    M = rng.standard_normal((D, E, E))
    V = LinearVectorFields(M)
    y = rng.standard_normal((4, 5, E))
    F = V.fields(y)
    J = V.jacobians(y)
    assert F.shape == (4, 5, E, D) and J.shape == (4, 5, D, E, E)
    for b in np.ndindex(4, 5):
        for i in range(D):
            np.testing.assert_allclose(F[b][:, i], M[i] @ y[b], rtol=1e-14, atol=1e-14)
            np.testing.assert_array_equal(J[b][i], M[i])
    assert np.all(V.drift(y) == 0) and not V.has_drift


def test_central_difference_jacobian_accuracy(rng):
    fields, jac = _nonlinear(rng)
    V = VectorFields(fields, dim_state=E, dim_noise=D)             # no user Jacobian
    y = rng.standard_normal((50, E))
    err = np.max(np.abs(V.jacobians(y) - jac(y))) / np.max(np.abs(jac(y)))
    assert err < 1e-8, err


_rk4_flow = rk4_flow


def test_bracket_is_the_flow_commutator(rng):
    fields, jac = _nonlinear(rng)
    V = VectorFields(fields, jac, dim_state=E, dim_noise=D)
    v0 = lambda y: fields(y)[..., 0]
    v1 = lambda y: fields(y)[..., 1]
    y = rng.standard_normal((6, E))
    est = {}
    for t in (4e-3, 2e-3):
        z = _rk4_flow(v0, y, t)
        z = _rk4_flow(v1, z, t)
        z = _rk4_flow(v0, z, -t)
        z = _rk4_flow(v1, z, -t)
        est[t] = (z - y) / t ** 2
    richardson = 2 * est[2e-3] - est[4e-3]                          # removes the O(t) term
    br = V.bracket(0, 1)(y)
    scale = np.max(np.abs(br))
    assert np.max(np.abs(richardson - br)) < 1e-3 * scale
    assert np.max(np.abs(richardson + br)) > 0.5 * scale            # the opposite sign fails
    # all brackets at once, antisymmetric, consistent with bracket(i, j)
    B = V.brackets(y)
    np.testing.assert_allclose(B[..., 0, 1, :], br, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(B, -np.swapaxes(B, -2, -3), atol=1e-14)


def test_linear_bracket_is_matrix_commutator(rng):
    M = rng.standard_normal((3, E, E))
    V = LinearVectorFields(M)
    y = rng.standard_normal(E)
    for i in range(3):
        for j in range(3):
            np.testing.assert_allclose(V.bracket(i, j)(y), (M[j] @ M[i] - M[i] @ M[j]) @ y,
                                       rtol=1e-12, atol=1e-12)
    # the generic (finite-difference) path gives the same brackets for the same linear fields
    W = VectorFields(lambda y: np.einsum("iab,...b->...ai", M, y), dim_state=E, dim_noise=3)
    np.testing.assert_allclose(W.brackets(y), V.brackets(y), atol=1e-8)


@given(st.lists(st.floats(-2, 2), min_size=3, max_size=3), st.lists(st.floats(-2, 2), min_size=3, max_size=3))
def test_friz_oberhauser_drift_equals_naive_sums(svals, yvals):
    rng = np.random.default_rng(5)
    fields, jac = _nonlinear_d3(rng)
    V = VectorFields(fields, jac, dim_state=E, dim_noise=3)
    s = np.zeros((3, 3))
    s[0, 1], s[0, 2], s[1, 2] = svals
    s = s - s.T
    y = np.array(yvals)
    F, J = fields(y), jac(y)
    naive = sum(s[i, j] * J[j] @ F[:, i] for i in range(3) for j in range(3))
    upper = sum(s[i, j] * (J[j] @ F[:, i] - J[i] @ F[:, j]) for i in range(3) for j in range(i + 1, 3))
    fo = V.friz_oberhauser_drift(s)(y)
    np.testing.assert_allclose(fo, naive, atol=1e-12)
    np.testing.assert_allclose(fo, upper, atol=1e-12)


def _nonlinear_d3(rng):
    M = 0.7 * rng.standard_normal((3, E, E))

    def fields(y):
        return np.stack([np.tanh(y @ M[i].T) for i in range(3)], axis=-1)

    def jac(y):
        return np.stack([(1 - np.tanh(y @ M[i].T) ** 2)[..., :, None] * M[i] for i in range(3)], axis=-3)

    return fields, jac


def test_linear_friz_oberhauser_drift_is_linear(rng):
    M = rng.standard_normal((3, E, E))
    V = LinearVectorFields(M)
    s = np.array([[0.0, 0.3, -1.1], [-0.3, 0.0, 0.4], [1.1, -0.4, 0.0]])
    fo = V.friz_oberhauser_drift(s)
    assert isinstance(fo, LinearDrift)
    naive = sum(s[i, j] * M[j] @ M[i] for i in range(3) for j in range(3))
    np.testing.assert_allclose(fo.matrix, naive, atol=1e-12)
    with pytest.raises(ValueError, match="antisymmetric"):
        V.friz_oberhauser_drift(s + np.eye(3))


def test_with_drift_returns_new_family(rng):
    M = rng.standard_normal((D, E, E))
    A = rng.standard_normal((E, E))
    V = LinearVectorFields(M)
    W = V.with_drift(A)
    assert W is not V and not V.has_drift and W.is_linear
    y = rng.standard_normal((4, E))
    np.testing.assert_allclose(W.drift(y), y @ A.T)
    U = W.with_drift(lambda y: y ** 2)                              # non-linear extra drift
    assert not U.is_linear
    np.testing.assert_allclose(U.drift(y), y @ A.T + y ** 2)
    np.testing.assert_allclose(U.drift_jacobian(y)[0], A + 2 * np.diag(y[0]), atol=1e-8)
    fields, jac = _nonlinear(rng)
    G = VectorFields(fields, jac, dim_state=E, dim_noise=D).with_drift(A)
    np.testing.assert_allclose(G.drift(y), y @ A.T)
    np.testing.assert_allclose(G.jacobians(y), jac(y))


@given(st.floats(-6, 1.5), st.integers(1, 5))
@example(1.27734375, 2)
def test_expm_batched_matches_scipy(log_scale, n):
    """Normwise, matrix by matrix: scipy's expm is itself accurate only normwise. At ``(1.27734375, 2)`` (a norm of
    40, entries up to 4e10) its [0, 1] entry is 2.2e-11 off relative to itself (1.8e-12 of the norm, against a
    50-digit mpmath reference), while ours is 8.6e-15 off; an elementwise tolerance failed on scipy's error."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((7, n, n)) * 10.0 ** log_scale
    ref = np.stack([scipy.linalg.expm(a) for a in A])
    err = np.max(np.abs(expm_batched(A) - ref), axis=(1, 2))
    assert np.all(err <= 1e-11 * np.max(np.abs(ref), axis=(1, 2))), err / np.max(np.abs(ref), axis=(1, 2))


def test_linear_fast_paths_agree_with_generic_fields(rng):
    """Davie/LogODE use matrix shortcuts for LinearVectorFields; the generic callable path must agree."""
    from roughpaths import RoughPath
    from roughpaths import solve
    from roughpaths import Davie, LogODE

    M = 0.5 * rng.standard_normal((3, E, E))
    A = 0.3 * rng.standard_normal((E, E))
    lin = LinearVectorFields(M, drift=A)
    gen = VectorFields(lambda y: np.einsum("iab,...b->...ai", M, y),
                       lambda y: np.broadcast_to(M, y.shape[:-1] + M.shape),
                       drift=lambda y: y @ A.T, drift_jacobian=lambda y: np.broadcast_to(A, y.shape + (E,)),
                       dim_state=E, dim_noise=3)
    W = np.cumsum(0.15 * rng.standard_normal((5, 33, 3)), axis=-2)
    X = RoughPath.from_path(W).restrict(np.linspace(0, 1, 9)).perturb(np.array([[0, 1., 0], [-1, 0, 2], [0, -2, 0]]))
    y0 = rng.standard_normal(E)
    np.testing.assert_allclose(solve(lin, X, y0, Davie()).states, solve(gen, X, y0, Davie()).states,
                               rtol=1e-12, atol=1e-12)
    # LogODE: exact exponential vs 32 inner RK4 steps of the same generator
    np.testing.assert_allclose(solve(lin, X, y0, LogODE()).states, solve(gen, X, y0, LogODE(inner_steps=32)).states,
                               rtol=1e-8, atol=1e-8)


def _expm_longdouble(a):
    """A naive oracle: Taylor series in 80-bit long double with scaling and squaring."""
    A = np.asarray(a, dtype=np.longdouble)
    s = max(0, int(np.ceil(np.log2(max(float(np.abs(A).sum(axis=0).max()), 1e-300)))) + 4)
    A = A / np.longdouble(2) ** s
    term = np.eye(A.shape[0], dtype=np.longdouble)
    out = term.copy()
    for k in range(1, 40):
        term = term @ A / k
        out = out + term
    for _ in range(s):
        out = out @ out
    return out.astype(np.float64)


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 0.03, 0.3, 1.0, 5.0, 20.0])
def test_expm_2x2_closed_form_against_a_long_double_series(scale):
    """2x2 members take a closed form (cosh/sinh or cos/sin of sqrt(q), a series near q = 0); it must be
    accurate to a few ulps of the largest entry on both sides of every branch switch."""
    rng = np.random.default_rng(int(scale * 1e3) + 1)
    A = rng.standard_normal((40, 2, 2)) * scale
    # members on both sides of the series switch |q| = 1e-3 and at q = 0 exactly (nilpotent N)
    A[0] = [[0.0, 1.0], [0.0, 0.0]]
    A[1] = [[0.5, 2e-4 * 0.999], [1.0, 0.5]]
    A[2] = [[0.5, 2e-4 * 1.001], [1.0, 0.5]]
    A[3] = [[0.5, -2e-4 * 1.001], [1.0, 0.5]]
    got = expm_batched(A)
    for a, g in zip(A, got):
        ref = _expm_longdouble(a)
        assert np.max(np.abs(g - ref)) <= 8e-16 * max(1.0, np.max(np.abs(ref))) * max(1.0, np.abs(a).sum()), a
