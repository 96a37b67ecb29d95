"""Main-job checks beyond the rigid body: Proposition 2.1, Proposition 3.1 and Theorem 3.1 on su(3) and so(5).

Registered by :mod:`mechanics.paper.checks` as ``matrix_prop21``, ``matrix_uniform`` and ``matrix_gibbs``, after the
rigid-body checks. The paper proves its Sections 2–3 for any Lie algebra and checks them on the rigid body (so(3));
these checks run the same claims on the matrix algebras su(3) (dimension 8) and so(5) (dimension 10), whose states
the library holds as matrices and updates by conjugation (:class:`mechanics.MatrixLieAlgebra`). Criteria are fixed
before the run; each prints predicted against measured:

* ``matrix_prop21`` (Proposition 2.1 in Friz–Oberhauser form): the system with ``s = 0`` driven by the Brownian
  rough path ``X.perturb(s)`` equals the system with the Lévy velocity ``ℓ = ½ Σ s^{ij}[ξ_i, ξ_j]`` driven by ``X``
  (``levy_in_dissipation=False`` when θ > 0), pathwise to round-off (≤ 1e-10 relative), for θ = 0 and θ = 0.5 and
  four random, non-isotropic noise vectors; the printed sign (``−s``) and the missing ½ (``2s``) are at least
  1e-3 away; along the corrected solution the spectrum of ``iM`` (the orbit) moves by ≤ 1e-12 relative.
* ``matrix_uniform`` (Proposition 3.1): exact uniform samples of an orbit (``U M₀ U⁻¹``, Haar ``U``), evolved without
  dissipation (with a large Lévy correction) for ``T = 1.5``, against fresh exact samples: every moment feature
  (``μ_a``, ``μ_a μ_b``) within 4 two-sample SE and the Kolmogorov–Smirnov p-value of the law of ``h`` ≥ 1e-4; the
  same statistic must reject (≥ 10 SE) the law reached with dissipation (θ = 1.5), so the check can fail.
* ``matrix_gibbs`` (Theorem 3.1, ``β = 2θ/σ²`` derived in :mod:`mechanics.analysis.orbit_gibbs`): time averages of
  the moment features over ``(1.5, T]`` of paths started from uniform orbit samples against the Gibbs law
  ``∝ exp(−β h̃)`` on the orbit by importance sampling of exact orbit samples (:class:`mechanics.OrbitGibbsMeasure`,
  independent of the solver): within 4 combined SE; the Gibbs laws of the printed sign (``h − ⟨μ, ℓ⟩``) and of the
  missing ½ (``h + 2⟨μ, ℓ⟩``) at least 6 SE away.

Sizes (:data:`mechanics.paper.sizes.SIZES`): ``matrix_prop21.n_paths``/``n_steps``, ``matrix_uniform.n_paths``,
``matrix_gibbs.n_paths``/``n_samples``/``T``/``dt``. At ``--tiny`` the statistical checks have little power (the
power requirements may fail there, as a tiny run allows).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import ks_2samp

import mechanics
import roughpaths

from .report import CheckResult

__all__ = ["check_matrix_prop21", "check_matrix_uniform", "check_matrix_gibbs", "MATRIX_CHECKS"]

_BEYOND = "Beyond the rigid body"


def _blocks(N, angles):
    M = np.zeros((N, N))
    for k, a in enumerate(angles):
        M[2 * k, 2 * k + 1], M[2 * k + 1, 2 * k] = a, -a
    return M


def _algebras():
    """``(label, algebra, a point of a generic orbit)`` for su(3) and so(5)."""
    su3, so5 = mechanics.su(3), mechanics.so(5)
    return [("su(3)", su3, su3.matrix_to_dual(1j * np.diag([1.0, 0.3, -1.3]))),
            ("so(5)", so5, so5.matrix_to_dual(_blocks(5, [1.2, 0.5])))]


def _spectrum(g, mu):
    return np.linalg.eigvalsh(1j * g.dual_to_matrix(mu))        # iM is Hermitian on so(n) and su(N)


def _isotropic_system(g, *, sigma, theta, s_entries, convention="rp"):
    n = g.dim
    s = np.zeros((n, n))
    for (i, j), v in s_entries.items():
        s[i, j] = v / sigma ** 2
    return mechanics.LiePoissonSystem(g, np.linspace(0.6, 2.0, n), sigma * np.eye(n), s=s - s.T, theta=theta,
                                      convention=convention)


def _s_entries(n):
    return {(0, 1): 1.0, (2, 5): -0.7, (3, n - 1): 0.5}


# ------------------------------------------------------------------------------------------ Proposition 2.1
def check_matrix_prop21(ctx) -> CheckResult:
    P = ctx.size("matrix_prop21.n_paths")
    n_steps = ctx.size("matrix_prop21.n_steps")
    rng = ctx.rng("matrix_prop21")
    m = 4
    gaps, wrong, drift, lines = [], [], [], []
    for label, g, mu0 in _algebras():
        n = g.dim
        xi = 0.7 * rng.standard_normal((m, n)) / np.sqrt(n)
        s = 1.5 * rng.standard_normal((m, m))
        s = s - s.T
        inertia = np.linspace(0.7, 1.8, n)
        X = roughpaths.brownian_rough_path(np.linspace(0.0, 1.0, n_steps + 1), m, rng, batch_shape=(P,),
                                           levy_area=ctx.levy_area_for(m))
        scale = float(np.linalg.norm(mu0))
        for theta in (0.0, 0.5):
            def corrected(factor):
                return mechanics.LiePoissonSystem(g, inertia, xi, s=factor * s, theta=theta, levy_in_dissipation=False)

            plain = mechanics.LiePoissonSystem(g, inertia, xi, theta=theta)
            a = roughpaths.solve(plain, X.perturb(s), mu0, mechanics.LieHeun()).states
            b = roughpaths.solve(corrected(1.0), X, mu0, mechanics.LieHeun()).states
            gap = float(np.max(np.abs(a - b))) / scale
            w = {f: float(np.max(np.abs(roughpaths.solve(corrected(f), X, mu0, mechanics.LieHeun()).states - a)))
                 / scale for f in (-1.0, 2.0)}
            lam0 = _spectrum(g, mu0)
            d = float(np.max(np.abs(_spectrum(g, b) - lam0))) / float(np.max(np.abs(lam0)))
            gaps.append(gap)
            wrong.append(min(w.values()))
            drift.append(d)
            ell = float(np.linalg.norm(corrected(1.0).levy_velocity))
            lines.append(f"{label}, θ = {theta:g}: gap {gap:.2e}; printed sign (−s) {w[-1.0]:.3g}, missing ½ (2s) "
                         f"{w[2.0]:.3g}; spectrum drift {d:.1e}; |ℓ| = {ell:.3f}")
    tol = 1e-10
    passed = max(gaps) <= tol and min(wrong) >= 1e-3 and max(drift) <= 1e-12
    return CheckResult(
        "matrix_prop21",
        f"{_BEYOND}, Proposition 2.1 (Friz–Oberhauser form) on su(3) and so(5): the Lie–Poisson system with s = 0 "
        "driven by X.perturb(s) equals the system with the Lévy velocity ℓ = +½ Σ s^{ij}[ξ_i, ξ_j] driven by X "
        "(dissipation from h when θ > 0), pathwise; the corrected solution stays on its coadjoint orbit. Four random "
        "non-isotropic ξ_i, random s, Lie–Heun on matrix states, Brownian rough paths on [0, 1].",
        predicted=0.0, measured=max(gaps),
        tolerance=f"max |difference| / |μ₀| ≤ {tol:g}; −s and 2s at least 1e-3 away; spectrum of iM kept to 1e-12",
        passed=passed, details=f"{P} paths x {n_steps} steps; " + "; ".join(lines))


# ------------------------------------------------------------------------------------------ Proposition 3.1
def _two_sample(system, final, fresh):
    a, b = mechanics.moment_observable(final), mechanics.moment_observable(fresh)
    se = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
    z = float(np.max(np.abs(a.mean(axis=0) - b.mean(axis=0)) / se))
    return z, float(ks_2samp(system.energy(final), system.energy(fresh)).pvalue)


def check_matrix_uniform(ctx) -> CheckResult:
    P = ctx.size("matrix_uniform.n_paths")
    T, dt, sigma = 1.5, 0.025, 0.6
    ok, lines, zs = True, [], []
    for label, g, mu0 in _algebras():
        start = g.sample_orbit(mu0, P, ctx.rng(f"matrix_uniform.start.{label}"))
        fresh = g.sample_orbit(mu0, P, ctx.rng(f"matrix_uniform.fresh.{label}"))
        ents = {(0, 1): 2.0, (1, 3): -1.5, (2, g.dim - 1): 1.0}
        out = {}
        for theta in (0.0, 1.5):
            system = _isotropic_system(g, sigma=sigma, theta=theta, s_entries=ents)
            res = mechanics.run_ensemble(system, start, dt=dt, n_steps=int(round(T / dt)), n_paths=P,
                                         seed=ctx.seed_for(f"matrix_uniform.{label}"), keep_final=True,
                                         chunk_size=min(P, 2048))
            out[theta] = _two_sample(system, res.final_states, fresh)
        (z, p), (z_d, p_d) = out[0.0], out[1.5]
        ok &= z <= 4 and p >= 1e-4 and z_d >= 10
        zs.append(z)
        n_feat = g.dim + g.dim * (g.dim + 1) // 2
        lines.append(f"{label}: max |z| = {z:.2f} over {n_feat} features, KS p(h) = {p:.3g}; with dissipation "
                     f"θ = 1.5 (must be rejected): max |z| = {z_d:.1f}, KS p = {p_d:.2g}")
    return CheckResult(
        "matrix_uniform",
        f"{_BEYOND}, Proposition 3.1 on su(3) and so(5): without dissipation the uniform law on a coadjoint orbit is "
        "invariant, with a large Lévy correction (isotropic ξ_i = 0.6 e_i). Exact uniform samples U M₀ U⁻¹ (Haar U) "
        f"evolved for T = {T:g} (Lie–Heun, dt = {dt:g}) against fresh exact samples.",
        predicted="law at T = uniform law (two-sample z = 0)", measured=f"max |z| = {max(zs):.2f}",
        tolerance="every moment feature within 4 two-sample SE and KS p(h) ≥ 1e-4; the dissipative law ≥ 10 SE away",
        passed=bool(ok), details=f"{P} paths and {P} fresh samples per algebra; " + "; ".join(lines))


# ------------------------------------------------------------------------------------------ Theorem 3.1
def check_matrix_gibbs(ctx) -> CheckResult:
    P = ctx.size("matrix_gibbs.n_paths")
    n_samples = ctx.size("matrix_gibbs.n_samples")
    T = ctx.size("matrix_gibbs.T")
    dt = ctx.size("matrix_gibbs.dt")
    burn, sigma, theta = 1.5, 1.0, 1.0
    ok, lines, preds, meas = True, [], [], []
    for label, g, mu0 in _algebras():
        system = _isotropic_system(g, sigma=sigma, theta=theta, s_entries=_s_entries(g.dim))
        ell = system.levy_velocity
        gibbs = mechanics.OrbitGibbsMeasure.from_system(system, mu0, n_samples=n_samples,
                                                        rng=ctx.rng(f"matrix_gibbs.oracle.{label}"))
        right = gibbs.expectation()
        variants = {"printed sign h − ⟨μ, ℓ⟩": -ell, "missing ½ h + 2⟨μ, ℓ⟩": 2.0 * ell}
        wrong = {k: gibbs.reweighted(_Shifted(system, v)).expectation() for k, v in variants.items()}
        start = g.sample_orbit(mu0, P, ctx.rng(f"matrix_gibbs.start.{label}"))
        with ctx.progress.bar(f"matrix_gibbs {label}: {P} paths x {int(round(T / dt)):,} steps", 1) as bar:
            ta = mechanics.run_ensemble(system, start, dt=dt, n_steps=int(round(T / dt)), n_paths=P,
                                        seed=ctx.seed_for(f"matrix_gibbs.{label}"), burn_in=int(round(burn / dt)),
                                        chunk_size=min(P, 2048)).time_average
            bar.update(1)

        def zmax(pred):
            se = np.sqrt(ta.standard_error ** 2 + pred.standard_error ** 2)
            return float(np.max(np.abs(ta.mean - pred.mean) / se))

        z = zmax(right)
        zw = {k: zmax(v) for k, v in wrong.items()}
        ok &= z <= 4 and min(zw.values()) >= 6
        n = g.dim
        preds.append(right.mean[:n])
        meas.append(ta.mean[:n])
        lines.append(f"{label} (β = {gibbs.beta:g}, IS effective sample size {right.effective_sample_size:.0f}): "
                     f"E[μ] measured {np.round(ta.mean[:n], 4).tolist()} ± ≤ {ta.standard_error[:n].max():.4f}, "
                     f"predicted {np.round(right.mean[:n], 4).tolist()} ± ≤ {right.standard_error[:n].max():.4f}; "
                     f"max |z| over all {len(right.mean)} features {z:.2f}; "
                     + ", ".join(f"{k}: {v:.1f} SE away" for k, v in zw.items()))
    return CheckResult(
        "matrix_gibbs",
        f"{_BEYOND}, Theorem 3.1 on su(3) and so(5): with double-bracket dissipation θ = 1 and isotropic noise "
        "ξ_i = σ e_i (σ = 1) the invariant law on the coadjoint orbit is ∝ exp(−2θh̃/σ²), h̃ = h + ⟨μ, ℓ⟩, "
        "ℓ = +½ Σ s^{ij}[ξ_i, ξ_j]. Time averages of μ and μμᵀ over (1.5, T] of paths started from uniform orbit samples "
        "(mechanics.run_ensemble) against the Gibbs law by importance sampling of exact Haar orbit samples "
        "(mechanics.OrbitGibbsMeasure).",
        predicted=np.concatenate(preds), measured=np.concatenate(meas),
        tolerance="every feature within 4 combined SE; the printed sign and the missing ½ at least 6 SE away",
        passed=bool(ok),
        details=f"{P} paths x T = {T:g}, dt = {dt:g}, burn-in {burn:g}; {n_samples} orbit samples per algebra\n"
                + "\n".join(lines))


class _Shifted:
    """``h + ⟨μ, v⟩`` for a system's ``h``."""

    def __init__(self, system, v):
        self.system, self.v = system, np.asarray(v)

    def __call__(self, mu):
        return self.system.energy(mu) + mu @ self.v


#: ``(name, title, check)`` in report order, registered by :mod:`mechanics.paper.checks`.
MATRIX_CHECKS = (
    ("matrix_prop21", f"{_BEYOND}: Proposition 2.1 on su(3), so(5) — X.perturb(s) = corrected system, pathwise",
     check_matrix_prop21),
    ("matrix_uniform", f"{_BEYOND}: Proposition 3.1 on su(3), so(5) — the uniform orbit law is invariant",
     check_matrix_uniform),
    ("matrix_gibbs", f"{_BEYOND}: Theorem 3.1 on su(3), so(5) — the Gibbs law exp(−2θh̃/σ²) on the orbit",
     check_matrix_gibbs),
)
