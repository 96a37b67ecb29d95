"""The compiled so(3) path of the coadjoint solvers is the documented scheme, member by member.

Claims:
* ``roughpaths.solve(rigid_body, X, mu0, LieEuler()/LieHeun())`` on so(3) (compiled kernel, chosen by
  the algebra's type) equals a naive reimplementation written here on the same rough path
  (``np.cross`` for the drift, ``scipy.linalg.expm`` of the hat matrix for ``exp(ad*_sigma)``,
  ``eta = Σ ξ_i X^i + Σ_{i<j} A_ij ξ_i × ξ_j``), with and without the Lévy area, including steps with
  ``|sigma|^2 >= 1e-2`` (the exact trigonometric branch), ``theta = 0`` and the torque in the
  conservative term only;
* driven by a ``BrownianDriver``, the result is bit-identical whatever the block size and whatever
  the batch split (``select``), for every Lévy-area method;
* the implicit midpoint's compiled kernel agrees with the numpy chord iteration (same scheme on an
  so(3) algebra built from its structure constants, which has no compiled path).
"""

import numpy as np
import pytest
from scipy.linalg import expm

from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun
from mechanics.systems.lie_algebra import LieAlgebra, rodrigues_ad_star_exp
from mechanics.systems.lie_poisson import LiePoissonSystem
from mechanics.systems.rigid_body import rigid_body
from roughpaths import BrownianDriver, solve


def _hat(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _naive(inertia, xi, s, theta, mu0, X, heun, area, levy_in_dissipation=True):
    """Independent reimplementation: Pi × W written with np.cross, Ad*exp via expm (Pi -> exp(-hat s) Pi)."""
    m = xi.shape[0]
    qinv = np.linalg.inv(np.diag(inertia))
    c = 0.5 * sum(s[i, j] * np.cross(xi[i], xi[j]) for i in range(m) for j in range(m))

    def vel(p):                               # w(Pi) = grad h~ + theta (Pi × grad h~)  (or Pi × grad h)
        g = qinv @ p + c
        return g + theta * np.cross(p, g if levy_in_dissipation else qinv @ p)

    out = np.array(mu0, dtype=float)
    dts = np.diff(X.times)
    for k, dt in enumerate(dts):
        for p in range(out.shape[0]):
            dw = X.increments[p, k]
            eta = sum(dw[i] * xi[i] for i in range(m))
            if area:
                xx = X.areas[p, k]
                for i in range(m):
                    for j in range(i + 1, m):
                        eta = eta + 0.5 * (xx[i, j] - xx[j, i]) * np.cross(xi[i], xi[j])
            mu = out[p]
            sig = vel(mu) * dt + eta
            if heun:
                a1 = np.cross(mu, sig)
                pred = mu + a1 + 0.5 * np.cross(a1, sig)
                sig = 0.5 * (vel(mu) + vel(pred)) * dt + eta
            out[p] = expm(-_hat(sig)) @ mu                         # exp(ad*_sig) Pi, ad*_s Pi = Pi × s
    return out


S3 = np.array([[0, 2.0, 5.0], [-2.0, 0, -1.0], [-5.0, 1.0, 0]])
CASES = {
    "isotropic, dissipative": {"xi": 0.3 * np.eye(3), "s": S3, "theta": 1.0, "dt": 1e-2},
    "large steps (trig branch), theta=0": {"xi": 1.5 * np.eye(3), "s": np.zeros((3, 3)), "theta": 0.0, "dt": 0.05},
    "torque in the conservative term only": {"xi": 0.3 * np.eye(3), "s": S3, "theta": 1.0, "dt": 1e-2,
                                             "levy_in_dissipation": False},
    "four general noises": {"xi": np.array([[0.3, 0.1, 0.0], [0.0, 0.2, -0.1], [0.1, 0.0, 0.4], [0.2, 0.2, 0.2]]),
                            "s": np.zeros((4, 4)), "theta": 0.5, "dt": 2e-2},
}


@pytest.mark.parametrize("area", [True, False])
@pytest.mark.parametrize("cls", [LieEuler, LieHeun], ids=lambda c: c.__name__)
@pytest.mark.parametrize("case", list(CASES), ids=str)
def test_fast_kernel_equals_naive(case, cls, area):
    kw = CASES[case]
    inertia = np.array([1.0, 2.0, 3.0])
    lid = kw.get("levy_in_dissipation", True)
    rb = rigid_body(inertia, xi=kw["xi"], s=kw["s"], theta=kw["theta"], levy_in_dissipation=lid)
    mu0 = np.random.default_rng(3).standard_normal((5, 3))
    mu0 /= np.linalg.norm(mu0, axis=-1, keepdims=True)
    m = kw["xi"].shape[0]
    X = BrownianDriver(m, seed=11, dt=kw["dt"], n_steps=60, batch_shape=(5,),
                       levy_area="davie" if area else None).rough_path()
    got = solve(rb, X, mu0, cls(), save_at="end").final
    ref = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, X, cls is LieHeun, area, lid)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    if area and kw["s"].any():               # the area matters: the naive scheme without it is far off
        far = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, X, True, False, lid)
        assert np.max(np.abs(got - far)) > 1e-6
    if not lid:                              # the placement matters: the naive h~-dissipated scheme is far off
        other = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, X, cls is LieHeun, area, True)
        assert np.max(np.abs(got - other)) > 1e-6


def test_trig_branch_is_exercised():
    """The 'large steps' case really has steps with |sigma|^2 >= 1e-2 (so the scalar exact path runs)."""
    dt, xi = CASES["large steps (trig branch), theta=0"]["dt"], 1.5
    assert 3 * xi ** 2 * dt > 1e-2          # E|eta|^2 = 3 xi^2 dt


@pytest.mark.parametrize("levy_area", ["davie", "foster", None])
@pytest.mark.parametrize("cls", [LieEuler, LieHeun, ImplicitMidpoint], ids=lambda c: c.__name__)
def test_block_size_and_batch_split_invariance(levy_area, cls):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.2, theta=1.0)
    drv = BrownianDriver(3, seed=5, dt=0.01, n_steps=50, batch_shape=(9,), levy_area=levy_area)
    solver = cls()
    mu0 = [0.0, 0.6, 0.8]
    ref = solve(rb, drv, mu0, solver, save_at=drv.times[::5]).states
    for block in (1, 7, 1000):
        np.testing.assert_array_equal(solve(rb, drv, mu0, solver, save_at=drv.times[::5], block_steps=block).states,
                                      ref)
    for part in ([0, 1, 2, 3], [4], [5, 6, 7, 8], [8, 2]):
        got = solve(rb, drv.select(part), mu0, solver, save_at=drv.times[::5], block_steps=13).states
        np.testing.assert_array_equal(got, ref[part])


def test_implicit_midpoint_kernel_matches_numpy_chord():
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.3, s=S3, theta=1.0)
    generic = LiePoissonSystem(LieAlgebra(rb.algebra.structure_constants, ad_star_exp=rodrigues_ad_star_exp),
                               rb.hamiltonian, rb.xi, s=S3, theta=1.0)
    X = BrownianDriver(3, seed=2, dt=0.02, n_steps=40, batch_shape=(4,)).rough_path()
    mu0 = [0.0, 0.6, 0.8]
    a = solve(rb, X, mu0, ImplicitMidpoint()).states
    b = solve(generic, X, mu0, ImplicitMidpoint()).states
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
