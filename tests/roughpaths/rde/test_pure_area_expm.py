"""A pure-area rough path drives linear fields like the matrix exponential of its bracket.

Claim: the rough path ``X ≡ 0``, ``XX_{s,t} = s (t - s)`` (``s`` antisymmetric; geometric since
``Sym(XX) = 0 = ½ X⊗X``) driving ``dY = M_i Y dX^i`` has the solution

    Y_t = expm(t C) Y_0,   C = Σ_{i,j} s^{ij} M_j M_i = ½ Σ_{i,j} s^{ij} (M_j M_i - M_i M_j),

(the Friz–Oberhauser drift of ``s`` for a zero path). The closed form is written here from the
Davie expansion, not from the library's bracket code, and evaluated with ``scipy.linalg.expm``.

Checks: ``LogODE`` (exact exponential) matches on any grid to round-off; ``LogODE`` on the same
fields given as plain callables (inner RK4, finite-difference Jacobian) matches to ``O(h^4)``;
``Davie`` converges with fitted order 1 (it is Euler for ``Y' = C Y`` here); the transposed
area (``C^T``-type ordering ``M_i M_j``) or a missing ½ in the Lévy-area generator differ by O(1).
For the rigid-body fields ``V_i(Π) = Π × ξ_i`` the solution is the rotation ``Π' = Π × c`` with
``c = ½ Σ s^{ij} ξ_i × ξ_j`` (``docs/conventions.md``).
"""

import numpy as np
import scipy.linalg

from roughpaths import Davie, LinearVectorFields, LogODE, RoughPath, solve, VectorFields


def _pure_area(s, n, T=1.0):
    times = np.linspace(0.0, T, n + 1)
    d = s.shape[0]
    areas = s[None] * np.diff(times)[:, None, None]
    return RoughPath(np.zeros((n, d)), areas, times=times, kind="geometric")


def _s3():
    return np.array([[0.0, 0.8, -0.5], [-0.8, 0.0, 1.2], [0.5, -1.2, 0.0]])


def test_logode_linear_is_exact(rng):
    M = 0.6 * rng.standard_normal((3, 4, 4))
    s = _s3()
    C = sum(s[i, j] * M[j] @ M[i] for i in range(3) for j in range(3))
    y0 = rng.standard_normal((5, 4))
    for n in (1, 7, 64):
        X = _pure_area(s, n, T=1.5)
        sol = solve(LinearVectorFields(M), X, y0, LogODE())
        for k in (0, n // 2, n):
            exact = y0 @ scipy.linalg.expm(sol.times[k] * C).T
            np.testing.assert_allclose(sol.states[:, k], exact, rtol=1e-12, atol=1e-12)
    # wrong conventions are far off: transposed area (M_i M_j) and the paper's ½ Σ_{i≤j}
    exact = y0 @ scipy.linalg.expm(1.5 * C).T
    wrong_t = y0 @ scipy.linalg.expm(1.5 * sum(s[i, j] * M[i] @ M[j] for i in range(3) for j in range(3))).T
    wrong_half = y0 @ scipy.linalg.expm(1.5 * 0.5 * C).T
    assert np.max(np.abs(wrong_t - exact)) > 0.1 * np.max(np.abs(exact))
    assert np.max(np.abs(wrong_half - exact)) > 0.1 * np.max(np.abs(exact))


def test_logode_callable_fields_rk4(rng):
    M = 0.6 * rng.standard_normal((3, 3, 3))
    s = _s3()
    C = sum(s[i, j] * M[j] @ M[i] for i in range(3) for j in range(3))
    V = VectorFields(lambda y: np.einsum("iab,...b->...ai", M, y), dim_state=3, dim_noise=3)  # FD Jacobian
    y0 = rng.standard_normal((4, 3))
    errs = []
    for n in (16, 32):
        sol = solve(V, _pure_area(s, n), y0, LogODE())
        errs.append(np.max(np.abs(sol.final - y0 @ scipy.linalg.expm(C).T)))
    assert errs[1] < 1e-5
    assert errs[0] / errs[1] > 10, errs          # RK4 on y' = C y: 16x expected


def test_davie_converges_at_order_one(rng):
    M = 0.6 * rng.standard_normal((2, 3, 3))
    s = np.array([[0.0, 1.3], [-1.3, 0.0]])
    C = sum(s[i, j] * M[j] @ M[i] for i in range(2) for j in range(2))
    y0 = rng.standard_normal(3)
    exact = scipy.linalg.expm(C) @ y0
    ns = np.array([16, 32, 64, 128])
    errs = [np.linalg.norm(solve(LinearVectorFields(M), _pure_area(s, n), y0, Davie()).final - exact) for n in ns]
    slope = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    assert abs(slope - 1.0) < 0.1, (slope, errs)


def test_rigid_body_pure_area_is_rotation(rng):
    sigma = 0.9
    xi = sigma * np.eye(3)
    s = _s3()

    def fields(P):
        return np.stack([np.cross(P, xi[i]) for i in range(3)], axis=-1)

    def jac(P):
        # d/dP (P × ξ) = -[ξ]_×
        out = []
        for i in range(3):
            x = xi[i]
            K = np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])
            out.append(np.broadcast_to(-K, P.shape[:-1] + (3, 3)))
        return np.stack(out, axis=-3)

    V = VectorFields(fields, jac, dim_state=3, dim_noise=3)
    c = 0.5 * sum(s[i, j] * np.cross(xi[i], xi[j]) for i in range(3) for j in range(3))
    np.testing.assert_allclose(c, sigma ** 2 * np.array([s[1, 2], -s[0, 2], s[0, 1]]))
    Kc = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])   # Π × c = -[c]_× Π
    P0 = rng.standard_normal((3, 3))
    sol = solve(V, _pure_area(s, 40, T=2.0), P0, LogODE(inner_steps=2))
    exact = P0 @ scipy.linalg.expm(-2.0 * Kc).T
    np.testing.assert_allclose(sol.final, exact, atol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(sol.final, axis=-1), np.linalg.norm(P0, axis=-1), rtol=1e-8)
    assert np.max(np.abs(P0 @ scipy.linalg.expm(2.0 * Kc).T - exact)) > 0.1   # the paper's -½ sign fails
