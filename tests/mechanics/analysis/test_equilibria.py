"""Equilibria of the modified rigid body ``Π̇ = Π × ∇h̃ + θ Π × (Π × ∇h̃)``, ``h̃ = ½Π·𝕀⁻¹Π + c·Π``.

Claims checked:
* the equilibria on ``|Π| = r`` are exactly the points with ``Π ∥ ∇h̃`` (all of them are found:
  compared with a brute-force multistart root search written here);
* the classical case ``c = 0``, ``𝕀 = diag(1, 2, 3)``: ±e3 minima (centres), ±e2 saddles, ±e1 maxima;
* the Lévy-shifted minimum for ``s13 = 25``, ``σ = 0.05`` is ``(0, 0.375, ±0.927)`` (derived from
  ``h̃``), not the paper's printed ``(0, 3σ²s13, …) = (0, 0.1875, …)``;
* the linearisation eigenvalues agree with finite differences of an independent vector field;
* long deterministic runs (scipy ``solve_ivp`` and the library's coadjoint integrator): minima
  attract with dissipation, saddles and maxima repel, centres stay close without dissipation;
* level sets lie on the sphere and on the level of ``h̃``; the sleeping Lagrange top criterion.
"""

import importlib
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

from mechanics.analysis import (
    isotropic_levy_shift,
    lagrange_top_sleeping_stability,
    rigid_body_equilibria,
    rigid_body_level_sets,
)


def _field(P, A, c, theta):
    """Independent RP vector field (plain cross products)."""
    W = A @ P + c
    return np.cross(P, W) + theta * np.cross(P, np.cross(P, W))


def _brute_force_equilibria(A, c, r, rng, n_starts=60):
    found = []
    for _ in range(n_starts):
        x0 = rng.standard_normal(3)

        def res(x):
            P = r * x / np.linalg.norm(x)
            return np.cross(P, A @ P + c)

        sol = least_squares(res, x0, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        P = r * sol.x / np.linalg.norm(sol.x)
        if np.linalg.norm(res(sol.x)) < 1e-10 and not any(np.linalg.norm(P - q) < 1e-6 for q in found):
            found.append(P)
    return found


def test_classical_rigid_body_types():
    eqs = rigid_body_equilibria([1.0, 2.0, 3.0], theta=0.5)
    pts = {tuple(np.round(e.point, 12)): e for e in eqs}
    assert len(eqs) == 6
    for k, kind, cons, dis in [(2, "minimum", "centre", "stable"), (1, "saddle", "saddle", "saddle"),
                               (0, "maximum", "centre", "unstable")]:
        for sgn in (1.0, -1.0):
            p = np.zeros(3)
            p[k] = sgn
            e = pts[tuple(p)]
            assert e.kind == kind and e.conservative_type == cons
            assert e.dissipative_type.startswith(dis)
            assert e.stable == (kind == "minimum")
    # without dissipation both definite extrema are Lyapunov-stable centres
    eqs0 = rigid_body_equilibria([1.0, 2.0, 3.0], theta=0.0)
    assert sorted(e.stable for e in eqs0) == [False, False, True, True, True, True]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_all_equilibria_found_against_multistart(seed):
    rng = np.random.default_rng(seed)
    M = rng.standard_normal((3, 3))
    inertia = M @ M.T + 0.5 * np.eye(3)                 # generic SPD, not diagonal
    A = np.linalg.inv(inertia)
    r = 1.7
    c = 0.3 * rng.standard_normal(3)
    eqs = rigid_body_equilibria(inertia, c, radius=r)
    brute = _brute_force_equilibria(A, c, r, rng)
    assert len(eqs) == len(brute) and len(eqs) in (2, 4, 6)
    for e in eqs:
        assert np.isclose(np.linalg.norm(e.point), r, rtol=1e-14)
        assert np.linalg.norm(np.cross(e.point, A @ e.point + c)) < 1e-12
        assert min(np.linalg.norm(e.point - q) for q in brute) < 1e-7
        assert np.allclose(A @ e.point + c, e.multiplier * e.point, atol=1e-12)
    # on a sphere a smooth function has #min - #saddle + #max = 2 (Euler characteristic)
    kinds = [e.kind for e in eqs]
    assert kinds.count("minimum") - kinds.count("saddle") + kinds.count("maximum") == 2


def test_tiny_shift_is_resolved():
    """A Lévy shift of 1e-9 moves the equilibria by O(1e-9): found to full relative accuracy."""
    c = np.array([1e-9, 0.0, 0.0])
    eqs = rigid_body_equilibria([1.0, 2.0, 3.0], c)
    assert len(eqs) == 6
    A = np.diag([1.0, 0.5, 1 / 3])
    for e in eqs:
        assert np.linalg.norm(np.cross(e.point, A @ e.point + c)) < 1e-16
    top = [e for e in eqs if e.point[2] > 0.5][0]
    # (A - λ)Π = -c with λ = 1/3 exactly, Π1 = -c1 / (1 - 1/3)
    assert np.isclose(top.point[0], -1.5e-9, rtol=1e-9)


def test_shifted_minimum_paper_figure_parameters():
    s = np.zeros((3, 3))
    s[0, 2], s[2, 0] = 25.0, -25.0
    c = isotropic_levy_shift(0.05, s)
    assert np.allclose(c, [0.0, -0.0625, 0.0])
    mins = [e for e in rigid_body_equilibria([1.0, 2.0, 3.0], c, theta=1.0) if e.kind == "minimum"]
    assert len(mins) == 2
    # derived by hand from h̃: λ = a3 = 1/3, Π2 = -c2 / (a2 - a3) = 0.0625 / (1/6) = 0.375
    for e in mins:
        assert np.allclose(e.point, [0.0, 0.375, np.sign(e.point[2]) * np.sqrt(1 - 0.375 ** 2)], atol=1e-14)
        assert e.dissipative_type.startswith("stable")
        assert not np.isclose(e.point[1], 3 * 0.05 ** 2 * 25.0)      # the paper's printed value
    # the paper convention flips the torque: the minima move to Π2 = -0.375
    cp = isotropic_levy_shift(0.05, s, convention="paper")
    mins_p = [e for e in rigid_body_equilibria([1.0, 2.0, 3.0], cp) if e.kind == "minimum"]
    assert all(np.isclose(e.point[1], -0.375) for e in mins_p)


def test_s12_keeps_poles():
    """Paper's remark: a pure s12 perturbation keeps ±e3 as equilibria with the same stability."""
    s = np.zeros((3, 3))
    s[0, 1], s[1, 0] = 10.0, -10.0
    c = isotropic_levy_shift(0.05, s)
    eqs = rigid_body_equilibria([1.0, 2.0, 3.0], c)
    for sgn in (1.0, -1.0):
        e = [q for q in eqs if np.allclose(q.point, [0, 0, sgn], atol=1e-14)]
        assert len(e) == 1 and e[0].kind == "minimum"


@pytest.mark.parametrize("theta", [0.0, 0.7])
def test_linearisation_matches_finite_differences(theta):
    inertia = np.diag([1.0, 2.0, 3.0])
    A = np.linalg.inv(inertia)
    c = np.array([0.0625, -0.0625, -0.125])
    for e in rigid_body_equilibria(inertia, c, theta=theta):
        P = e.point
        J = np.zeros((3, 3))
        h = 1e-6
        for k in range(3):
            d = np.zeros(3)
            d[k] = h
            J[:, k] = (_field(P + d, A, c, theta) - _field(P - d, A, c, theta)) / (2 * h)
        n = P / np.linalg.norm(P)
        B = np.linalg.svd(np.eye(3) - np.outer(n, n))[0][:, :2]
        ev = np.sort_complex(np.linalg.eigvals(B.T @ J @ B))
        assert np.allclose(ev, np.sort_complex(e.jacobian_eigenvalues), atol=1e-7)


def _run(P0, A, c, theta, T):
    sol = solve_ivp(lambda t, y: _field(y, A, c, theta), (0.0, T), P0, rtol=1e-10, atol=1e-12,
                    method="DOP853")
    return sol.y.T


def test_long_deterministic_runs_scipy():
    inertia = np.diag([1.0, 2.0, 3.0])
    A = np.linalg.inv(inertia)
    c = np.array([0.0625, -0.0625, -0.125])
    rng = np.random.default_rng(5)
    eqs = rigid_body_equilibria(inertia, c, theta=1.0)
    for e in eqs:
        P0 = e.point + 1e-3 * rng.standard_normal(3)
        P0 /= np.linalg.norm(P0)
        traj = _run(P0, A, c, 1.0, 40.0)
        dist = np.linalg.norm(traj[-1] - e.point)
        if e.kind == "minimum":
            assert dist < 1e-8                       # asymptotically stable
        else:
            assert dist > 0.1                        # saddle / maximum repel
    # without dissipation: centres (both minima and maxima of h̃) keep nearby orbits nearby,
    # saddles do not
    for e in rigid_body_equilibria(inertia, c, theta=0.0):
        P0 = e.point + 1e-3 * rng.standard_normal(3)
        P0 /= np.linalg.norm(P0)
        traj = _run(P0, A, c, 0.0, 200.0)
        maxdist = np.max(np.linalg.norm(traj - e.point, axis=1))
        if e.conservative_type == "centre":
            assert maxdist < 2e-2
        else:
            assert maxdist > 0.1


def test_long_deterministic_runs_library_integrator():
    """The coadjoint integrator (zero noise) lands on the computed stable equilibrium."""
    integ = importlib.import_module("mechanics.integrators")
    from roughpaths import RoughPath, solve
    from mechanics.systems.lie_algebra import so3
    from mechanics.systems.lie_poisson import LiePoissonSystem

    s = np.zeros((3, 3))
    s[0, 1], s[0, 2], s[1, 2] = -50.0, 25.0, 25.0
    s = s - s.T
    sysm = LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.05 * np.eye(3), s=s, theta=1.0)
    c = sysm.levy_velocity
    assert np.allclose(c, [0.0625, -0.0625, -0.125])           # surf4/surf5 parameters
    eqs = rigid_body_equilibria([1.0, 2.0, 3.0], c, theta=1.0)
    target = [e for e in eqs if e.kind == "minimum"][0]
    N, T = 4000, 40.0
    X = RoughPath(np.zeros((N, 3)), np.zeros((N, 3, 3)), times=np.linspace(0, T, N + 1))
    sad = [e for e in eqs if e.kind == "saddle"][0]
    P0 = np.stack([[0.0, 0.0, 1.0], sad.point + 1e-4 * np.array([0.3, -0.2, 0.5])])
    P0 /= np.linalg.norm(P0, axis=1, keepdims=True)
    traj = solve(sysm, X, P0, integ.LieHeun(), save_at=X.times[::N]).states
    assert np.linalg.norm(traj[0, -1] - target.point) < 1e-6
    assert np.linalg.norm(traj[1, -1] - sad.point) > 0.1


def test_level_sets_on_sphere_and_level():
    c = np.array([0.0, -0.0625, 0.0])
    ls = rigid_body_level_sets([1.0, 2.0, 3.0], c, radius=2.0, levels=8)
    A = np.diag([1.0, 0.5, 1 / 3])
    assert ls.separatrix.sum() == 2                        # two saddles at different energies now
    sad = sorted(e.energy for e in ls.equilibria if e.kind == "saddle")
    assert np.allclose(sorted(ls.levels[ls.separatrix]), sad)
    for level, curves in zip(ls.levels, ls.curves):
        assert curves, f"no curve at level {level}"
        for xyz in curves:
            assert np.allclose(np.linalg.norm(xyz, axis=1), 2.0, rtol=1e-13)
            h = 0.5 * np.einsum("ki,ij,kj->k", xyz, A, xyz) + xyz @ c
            assert np.max(np.abs(h - level)) < 1e-9
    assert ls.energy_range[0] < ls.levels.min() and ls.levels.max() < ls.energy_range[1]


def test_lagrange_top_criterion_against_numerical_linearisation():
    I = np.array([1.0, 1.0, 2.0])
    mgl = 1.0
    chi = np.array([0.0, 0.0, mgl])

    def F(x):
        P, G = x[:3], x[3:]
        W = P / I
        return np.concatenate([np.cross(P, W) + np.cross(G, chi), np.cross(G, W)])

    for om3 in (0.5, 0.9, 1.1, 2.0):
        x = np.array([0, 0, I[2] * om3, 0, 0, 1.0])
        assert np.allclose(F(x), 0.0)
        J = np.zeros((6, 6))
        for k in range(6):
            d = np.zeros(6)
            d[k] = 1e-6
            J[:, k] = (F(x + d) - F(x - d)) / 2e-6
        ev = np.sort_complex(np.linalg.eigvals(J))
        out = lagrange_top_sleeping_stability(I[0], I[2], om3, mgl)
        assert out["stable"] == (np.max(ev.real) < 1e-6)
        assert np.allclose(ev, np.sort_complex(out["eigenvalues"]), atol=1e-6)


@pytest.mark.parametrize("kwargs, exc, word", [
    (dict(inertia=[[1, 0.1, 0], [0, 2, 0], [0, 0, 3]]), ValueError, "symmetric"),
    (dict(inertia=[1.0, -2.0, 3.0]), ValueError, "positive"),
    (dict(inertia=np.diag([1.0, 2.0, -3.0])), ValueError, "positive definite"),
    (dict(inertia=[1.0, 2.0]), ValueError, "shape"),
    (dict(inertia=[1.0, 2.0, 3.0], c=[1.0, 2.0]), ValueError, "c must"),
    (dict(inertia=[1.0, 2.0, 3.0], theta=-1.0), ValueError, "theta"),
    (dict(inertia=[1.0, 2.0, 3.0], radius=0.0), ValueError, "radius"),
    (dict(inertia=[1.0, np.nan, 3.0]), ValueError, "non-finite"),
])
def test_bad_input(kwargs, exc, word):
    with pytest.raises(exc, match=word):
        rigid_body_equilibria(**kwargs)


def test_bad_levy_matrix():
    with pytest.raises(ValueError, match="antisymmetric"):
        isotropic_levy_shift(0.1, np.ones((3, 3)))
    with pytest.raises(ValueError, match="convention"):
        isotropic_levy_shift(0.1, np.zeros((3, 3)), convention="ito")


def test_sleeping_top_is_an_equilibrium_of_the_library_heavy_top():
    ht = importlib.import_module("mechanics.systems.heavy_top")
    I1, I3, mgl = 1.0, 2.0, 1.0
    for om3 in (0.9, 2.0):
        top = ht.heavy_top([I1, I1, I3], [0.0, 0.0, mgl])
        mu = np.array([0.0, 0.0, I3 * om3, 0.0, 0.0, 1.0])
        assert np.allclose(top.drift(mu), 0.0, atol=1e-14)
        ev = np.sort_complex(np.linalg.eigvals(top.drift_jacobian(mu)))
        out = lagrange_top_sleeping_stability(I1, I3, om3, mgl)
        assert np.allclose(ev, np.sort_complex(out["eigenvalues"]), atol=1e-10)
