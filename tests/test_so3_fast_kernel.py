"""The fast so(3) path of ``simulate_brownian`` is the documented scheme on the documented random stream.

Claims:
* the bulk normal sampler (numpy's ziggurat over raw 64-bit words) returns exactly
  ``rng.standard_normal`` — same values and same generator end state — for every bit generator;
* ``simulate_brownian`` on so(3) with a quadratic Hamiltonian equals a naive same-seed
  reimplementation written here (normals in C order of shape ``(n_steps, P, w)``: dW (m), H (m),
  lambda (m(m-1)/2); Davie area ``A_ij = H_i dW_j - dW_i H_j + lambda_ij``; Lie–Euler / Lie–Heun with
  ``scipy.linalg.expm`` of the hat matrix), including steps with ``|sigma|^2 >= 1e-2`` (the exact
  trigonometric branch) and ``theta = 0``;
* the result is bit-identical whatever ``chunk_steps`` is, and the generator is left where drawing
  the same normals with numpy leaves it.
"""

import numpy as np
import pytest
from scipy.linalg import expm

from mechanics.integrators import (
    LieEuler,
    LieHeun,
    _standard_normal_into,
    simulate_brownian,
)
from mechanics.rigid_body import rigid_body

BITGENS = [np.random.PCG64, np.random.PCG64DXSM, np.random.SFC64, np.random.Philox, np.random.MT19937]


@pytest.mark.parametrize("bitgen", BITGENS, ids=lambda b: b.__name__)
@pytest.mark.parametrize("n", [1, 5, 4099, 200_003])
def test_bulk_normals_equal_numpy(bitgen, n):
    a, b = np.random.Generator(bitgen(2024)), np.random.Generator(bitgen(2024))
    out = np.empty(n)
    _standard_normal_into(a, out)
    np.testing.assert_array_equal(out, b.standard_normal(n))
    assert a.bit_generator.random_raw() == b.bit_generator.random_raw()     # same end state


def _hat(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _naive(inertia, xi, s, theta, mu0, dt, n_steps, seed, heun, area, levy_in_dissipation=True):
    """Independent reimplementation: Pi × W written with np.cross, Ad*exp via expm (Pi -> exp(-hat s) Pi)."""
    m = xi.shape[0]
    iu = np.triu_indices(m, 1)
    w = 2 * m + iu[0].size if (area and m > 1) else m
    z = np.random.default_rng(seed).standard_normal((n_steps, mu0.shape[0], w))
    qinv = np.linalg.inv(np.diag(inertia))
    c = 0.5 * sum(s[i, j] * np.cross(xi[i], xi[j]) for i in range(m) for j in range(m))

    def vel(p):                               # w(Pi) = grad h~ + theta (Pi × grad h~)  (or Pi × grad h)
        g = qinv @ p + c
        return g + theta * np.cross(p, g if levy_in_dissipation else qinv @ p)

    out = np.array(mu0, dtype=float)
    for k in range(n_steps):
        for p in range(out.shape[0]):
            dw = z[k, p, :m] * np.sqrt(dt)
            eta = dw @ xi
            if w > m:
                h = z[k, p, m:2 * m] * np.sqrt(dt / 12.0)
                for r, (i, j) in enumerate(zip(*iu)):
                    a_ij = h[i] * dw[j] - dw[i] * h[j] + z[k, p, 2 * m + r] * dt / np.sqrt(12.0)
                    eta = eta + a_ij * np.cross(xi[i], xi[j])        # ½ Σ_ij A_ij [ξ_i, ξ_j]
            mu = out[p]
            sig = vel(mu) * dt + eta
            if heun:
                a1 = np.cross(mu, sig)
                pred = mu + a1 + 0.5 * np.cross(a1, sig)
                sig = 0.5 * (vel(mu) + vel(pred)) * dt + eta
            out[p] = expm(-_hat(sig)) @ mu                         # exp(ad*_sig) Pi, ad*_s Pi = Pi × s
    return out


CASES = {
    "isotropic, dissipative": {"xi": 0.3 * np.eye(3), "s": np.array([[0, 2.0, 5.0], [-2.0, 0, -1.0], [-5.0, 1.0, 0]]),
                                   "theta": 1.0, "dt": 1e-2},
    "large steps (trig branch), theta=0": {"xi": 1.5 * np.eye(3), "s": np.zeros((3, 3)), "theta": 0.0, "dt": 0.05},
    "torque in the conservative term only": {"xi": 0.3 * np.eye(3), "s": np.array([[0, 2.0, 5.0], [-2.0, 0, -1.0],
                                                                                  [-5.0, 1.0, 0]]),
                                             "theta": 1.0, "dt": 1e-2, "levy_in_dissipation": False},
    "four general noises": {"xi": np.array([[0.3, 0.1, 0.0], [0.0, 0.2, -0.1], [0.1, 0.0, 0.4], [0.2, 0.2, 0.2]]),
                                "s": np.zeros((4, 4)), "theta": 0.5, "dt": 2e-2},
}


@pytest.mark.parametrize("area", [True, False])
@pytest.mark.parametrize("method", [LieEuler(), LieHeun()], ids=lambda m: type(m).__name__)
@pytest.mark.parametrize("case", list(CASES), ids=str)
def test_fast_kernel_equals_naive_same_seed(case, method, area):
    kw = CASES[case]
    inertia = np.array([1.0, 2.0, 3.0])
    lid = kw.get("levy_in_dissipation", True)
    rb = rigid_body(inertia, xi=kw["xi"], s=kw["s"], theta=kw["theta"], levy_in_dissipation=lid)
    mu0 = np.random.default_rng(3).standard_normal((5, 3))
    mu0 /= np.linalg.norm(mu0, axis=-1, keepdims=True)
    n = 60
    _, got = simulate_brownian(rb, mu0, kw["dt"], n, np.random.default_rng(11), method=method, levy_area=area,
                               save_every=n)
    ref = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, kw["dt"], n, 11, isinstance(method, LieHeun), area, lid)
    np.testing.assert_allclose(got[:, -1], ref, rtol=0, atol=1e-12)
    if area and kw["s"].any():               # the area matters: the naive scheme without it is far off
        far = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, kw["dt"], n, 11, True, False, lid)
        assert np.max(np.abs(got[:, -1] - far)) > 1e-6
    if not lid:                              # the placement matters: the naive h~-dissipated scheme is far off
        other = _naive(inertia, kw["xi"], kw["s"], kw["theta"], mu0, kw["dt"], n, 11, isinstance(method, LieHeun),
                       area, True)
        assert np.max(np.abs(got[:, -1] - other)) > 1e-6


def test_trig_branch_is_exercised():
    """The 'large steps' case really has steps with |sigma|^2 >= 1e-2 (so the scalar exact path runs)."""
    dt, xi = CASES["large steps (trig branch), theta=0"]["dt"], 1.5
    assert 3 * xi ** 2 * dt > 1e-2          # E|eta|^2 = 3 xi^2 dt


@pytest.mark.parametrize("area", [True, False])
def test_chunking_and_generator_state(area):
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.2, theta=1.0)
    runs, states = [], []
    for chunk in (None, 1, 7, 1000):
        rng = np.random.default_rng(5)
        runs.append(simulate_brownian(rb, [0.0, 0.6, 0.8], 0.01, 50, rng, n_paths=9, levy_area=area,
                                      save_every=5, chunk_steps=chunk)[1])
        states.append(rng.bit_generator.random_raw())
    for r in runs[1:]:
        np.testing.assert_array_equal(r, runs[0])
    rng = np.random.default_rng(5)
    rng.standard_normal(50 * 9 * (9 if area else 3))
    assert set(states) == {rng.bit_generator.random_raw()}
