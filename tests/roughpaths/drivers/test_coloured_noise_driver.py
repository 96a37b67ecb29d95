"""Claim: the coloured-noise driver samples the exact law of the OU transition and lifts B^ε correctly.

* The Van Loan covariance of ``(y_{t+h}, ∫y, ΔB)`` equals the defining integral
  ``∫_0^h e^{Fr}GGᵀe^{Fᵀr} dr`` (quadrature) and the scalar closed forms.
* The sampler's draws of ``(y_{t+h}, ΔB^ε, ΔB)`` have that law (the ``∫y`` block is obtained in the
  sampler from a pathwise identity, not from Van Loan: two independent derivations).
* The per-step area of the lift (cubic-Hermite sub-steps + Chen) approaches the area of the same
  path resolved much more finely, faster than the chord (piecewise-linear) lift; the Hermite Lévy
  area coefficients agree with a brute-force quadrature of the interpolant.
* Bad input is rejected with messages naming the argument; an unresolved step warns with h/ε².
"""

import warnings

import numpy as np
import pytest
import scipy.integrate as si
import scipy.linalg as sla

from roughpaths import (ResolutionWarning, coloured_noise_limit, iter_coloured_noise,
                                       ou_step_law, sample_coloured_noise)

A2 = np.array([[1.0, 2.0], [-0.5, 1.5]])
D2 = np.array([[1.0, 0.0], [0.3, 0.8]])


def test_van_loan_matches_quadrature():
    A = np.array([[1.0, 2.0, 0.0], [-0.5, 1.5, 0.3], [0.0, 0.1, 0.7]])
    D = np.array([[1.0, 0.0], [0.3, 1.0], [0.0, 0.5]])
    for eps, h in [(1.0, 0.01), (0.3, 0.05), (0.1, 0.2)]:     # h/eps² from 0.01 to 20 (doubling path)
        T, Q = ou_step_law(A, D, eps, h)
        a, d = A / eps ** 2, D / eps
        F = np.zeros((8, 8))
        F[:3, :3] = -a
        F[3:6, :3] = np.eye(3)
        G = np.zeros((8, 2))
        G[:3] = d
        G[6:] = np.eye(2)
        Qq, _ = si.quad_vec(lambda r: sla.expm(F * r) @ G @ G.T @ sla.expm(F.T * r), 0, h,
                            epsabs=1e-14, epsrel=1e-12)
        assert np.max(np.abs(Q - Qq)) <= 1e-9 * np.max(np.abs(Qq))
        assert np.allclose(T[:3], sla.expm(-a * h), atol=1e-12)
        assert np.allclose(T[3:6], np.linalg.solve(a, np.eye(3) - sla.expm(-a * h)), atol=1e-12)


def test_scalar_closed_forms():
    a, s, eps, h = 1.7, 0.6, 0.5, 0.3
    T, Q = ou_step_law([[a]], [[s]], eps, h)
    al, c = a / eps ** 2, s / eps                      # dy = -al y dt + c dB
    e = np.exp(-al * h)
    var_y = c ** 2 * (1 - e ** 2) / (2 * al)
    cov_yI = c ** 2 / al * ((1 - e) / al - (1 - e ** 2) / (2 * al))
    var_I = c ** 2 / al ** 2 * (h - 2 * (1 - e) / al + (1 - e ** 2) / (2 * al))
    cov_yB = c * (1 - e) / al
    cov_IB = c / al * (h - (1 - e) / al)
    assert np.allclose([Q[0, 0], Q[0, 1], Q[1, 1], Q[0, 2], Q[1, 2], Q[2, 2]],
                       [var_y, cov_yI, var_I, cov_yB, cov_IB, h], rtol=1e-10)


def test_sampler_law_matches_van_loan(rng):
    eps, h, P = 0.5, 0.1, 40000
    y0 = np.array([0.7, -0.4])
    with pytest.warns(ResolutionWarning):           # one sub-step: the area is not used here
        s = sample_coloured_noise(A2, D2, eps, [0.0, h], rng=rng, batch_shape=(P,), y0=y0, substeps=1)
    w = np.concatenate([s.y[:, 1], eps * s.path.increments[:, 0], s.brownian.increments[:, 0]], axis=-1)
    T, Q = ou_step_law(A2, D2, eps, h)
    mean = T @ y0
    emp_mean = w.mean(0)
    se_mean = np.sqrt(np.diag(Q) / P)
    assert np.all(np.abs(emp_mean - mean) < 5 * se_mean + 1e-15)
    emp_cov = np.cov(w.T)
    se_cov = np.sqrt((Q ** 2 + np.outer(np.diag(Q), np.diag(Q))) / P)      # Gaussian 4th moments
    assert np.all(np.abs(emp_cov - Q) < 5 * se_cov + 1e-15)
    # a wrong law (transposed A) is detected
    Tw, Qw = ou_step_law(A2.T, D2, eps, h)
    assert np.max(np.abs(emp_cov - Qw) / (se_cov + 1e-15)) > 10


def test_stationary_start_and_geometric(rng):
    lim = coloured_noise_limit(A2, D2)
    s = sample_coloured_noise(A2, D2, 0.3, np.linspace(0, 0.5, 6), rng=rng, batch_shape=(20000,))
    for k in (0, -1):
        C = np.cov(s.y[:, k].T)
        assert np.allclose(C, lim.Sigma, atol=5 * np.sqrt(2 * np.max(lim.Sigma) ** 2 / 20000))
    assert s.path.kind == "geometric" and float(np.max(s.path.geometric_defect())) < 1e-12


def test_reproducible_and_chunk_independent():
    kw = dict(n_paths=7, substeps=3)
    runs = []
    for chunk in (1, 4, 100):
        parts = list(iter_coloured_noise(A2, D2, 0.2, 0.01, 9, rng=np.random.default_rng(3), chunk_steps=chunk, **kw))
        runs.append(np.concatenate([p[1] for p in parts], axis=1))
    assert np.array_equal(runs[0], runs[1]) and np.array_equal(runs[0], runs[2])
    s = sample_coloured_noise(A2, D2, 0.2, np.linspace(0, 0.09, 10), rng=np.random.default_rng(3),
                              batch_shape=(7,), substeps=3)
    assert np.allclose(s.path.areas, runs[0], atol=1e-15)


def _hermite_levy_bruteforce(x, u, v, npts=4001):
    """Lévy area of the cubic Hermite p(0)=0, p(1)=x, p'(0)=u, p'(1)=v by fine polygon (test oracle)."""
    s = np.linspace(0, 1, npts)[:, None]
    p = (-2 * s ** 3 + 3 * s ** 2) * x + (s ** 3 - 2 * s ** 2 + s) * u + (s ** 3 - s ** 2) * v
    dp = np.diff(p, axis=0)
    mid = 0.5 * (p[1:] + p[:-1])
    a = mid.T @ dp
    return 0.5 * (a - a.T)


def _hermite_levy_coarse(y, inc, eps, delta):
    """The formula under test, re-implemented from the module docstring (vectorised)."""
    u, v = eps * delta * y[..., :-1, :], eps * delta * y[..., 1:, :]

    def wedge(a, b):
        return a[..., :, None] * b[..., None, :] - b[..., :, None] * a[..., None, :]
    return -0.1 * wedge(inc, u) + 0.1 * wedge(inc, v) - wedge(u, v) / 60.0


def test_hermite_coefficients_bruteforce(rng):
    x, u, v = rng.normal(size=(3, 3))
    ref = _hermite_levy_bruteforce(x, u, v)
    got = _hermite_levy_coarse(np.stack([u, v]), x[None], 1.0, 1.0)[0]
    assert np.allclose(got, ref, atol=1e-6)


def test_lift_area_converges_pathwise(rng):
    """Coarse lifts built from the exact nodes of one finely resolved path vs that path's area."""
    eps, P, r_fine = 1.0, 400, 64
    H = 1.0                                   # coarse window (fast time units since eps = 1)
    fine = sample_coloured_noise(A2, D2, eps, np.linspace(0, H, r_fine + 1), rng=rng, batch_shape=(P,), substeps=4)
    ref = fine.path.restrict([0.0, H]).step_levy_areas[:, 0]
    errs_h, errs_c, deltas = [], [], []
    for m in (2, 4, 8, 16):
        idx = np.arange(0, r_fine + 1, r_fine // m)
        y = fine.y[:, idx]
        X = fine.path.restrict(fine.path.times[idx])
        inc = X.increments
        delta = H / m
        lev = _hermite_levy_coarse(y, inc, eps, delta)
        chord = X.areas - X.step_levy_areas                 # ½ x⊗x per sub-step
        tot_h = _chen_levy(inc, chord + lev)
        tot_c = _chen_levy(inc, chord)
        errs_h.append(np.sqrt(np.mean((tot_h - ref) ** 2)))
        errs_c.append(np.sqrt(np.mean((tot_c - ref) ** 2)))
        deltas.append(delta)
    slope_h = np.polyfit(np.log(deltas), np.log(errs_h), 1)[0]
    slope_c = np.polyfit(np.log(deltas), np.log(errs_c), 1)[0]
    assert all(eh < 0.5 * ec for eh, ec in zip(errs_h, errs_c))
    print(f"chord slope {slope_c:.2f}, Hermite slope {slope_h:.2f}, errors {errs_h} vs {errs_c}")
    assert slope_c > 1.6 and slope_h > 1.7, (slope_c, slope_h, errs_h, errs_c)


def _chen_levy(inc, areas):
    """Lévy area over all sub-steps by a naive Chen loop (test oracle)."""
    X = np.zeros(inc.shape[:-2] + inc.shape[-1:])
    XX = np.zeros(inc.shape[:-2] + inc.shape[-1:] * 2)
    for k in range(inc.shape[-2]):
        XX = XX + areas[..., k, :, :] + X[..., :, None] * inc[..., k, None, :]
        X = X + inc[..., k, :]
    return 0.5 * (XX - np.swapaxes(XX, -1, -2))


@pytest.mark.parametrize("A, match", [
    (np.array([[0.0, 1.0], [-1.0, 0.0]]), "right half-plane"),
    (np.array([[-1.0, 0.0], [0.0, 2.0]]), "right half-plane"),
])
def test_bad_drift_matrix(A, match, rng):
    with pytest.raises(ValueError, match=match):
        coloured_noise_limit(A, np.eye(2))
    with pytest.raises(ValueError, match=match):
        sample_coloured_noise(A, np.eye(2), 0.1, [0.0, 1.0], rng=rng)


def test_singular_sigma(rng):
    with pytest.raises(ValueError, match="singular"):            # noise misses y2, A diagonal
        coloured_noise_limit(np.diag([1.0, 2.0]), np.array([[1.0], [0.0]]))
    with pytest.raises(ValueError, match="singular"):
        coloured_noise_limit(np.eye(2), np.zeros((2, 2)))
    # rank-one D but controllable (A mixes the components): Sigma is fine
    lim = coloured_noise_limit(np.array([[1.0, 1.0], [-1.0, 1.0]]), np.array([[1.0], [0.0]]))
    assert np.all(np.linalg.eigvalsh(lim.Sigma) > 0)


@pytest.mark.parametrize("eps", [0.0, -0.1, float("nan"), float("inf")])
def test_bad_eps(eps, rng):
    with pytest.raises(ValueError, match="eps"):
        sample_coloured_noise(A2, D2, eps, [0.0, 1.0], rng=rng)


def test_unresolved_step_warns_with_ratio(rng):
    with pytest.warns(ResolutionWarning, match=r"eps\*\*2 = 25") as rec:
        sample_coloured_noise(A2, D2, 0.1, [0.0, 0.5], rng=rng, substeps=2)
    assert "25" in str(rec[0].message)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sample_coloured_noise(A2, D2, 0.1, [0.0, 0.5], rng=rng)      # substeps=None resolves it


def test_other_bad_input(rng):
    with pytest.raises(TypeError, match="rng"):
        sample_coloured_noise(A2, D2, 0.1, [0.0, 1.0], rng=1)
    with pytest.raises(ValueError, match="D must have shape"):
        coloured_noise_limit(A2, np.eye(3))
    with pytest.raises(ValueError, match="y0"):
        sample_coloured_noise(A2, D2, 0.1, [0.0, 0.01], rng=rng, y0=np.zeros(3))
    with pytest.raises(ValueError, match="times"):
        sample_coloured_noise(A2, D2, 0.1, [0.0, 0.0], rng=rng)
