"""Main-job check of the paper's conclusion: deterministic chaos homogenises to "neither Itô nor Stratonovich".

Registered by :mod:`mechanics.paper.checks` as ``chaos``. A fast cat map (iterated exactly on its lattice)
with the two sine observables of ``tests/roughpaths/drivers/test_chaotic_fast_slow.py`` has correlations
that vanish after two lags, so ``E = Σ_{m≥1} ∫ v ⊗ v∘T^m`` is known exactly and has a non-zero antisymmetric
part. The check compares, with criteria fixed before the run and margins from the sample sizes:

* the Green–Kubo estimate of ``E`` from orbits with the closed form (within 4 standard errors);
* the mean Lévy area of the driver's lift over ``[0, 1]`` with its exact finite-``n`` value
  ``Alt(Σ_m (n − m) C(m))/n`` (within 4 SE);
* ``E[x_1]`` of the fast–slow system ``x' = n^{1/2} b(x) v(y_j)``, ``b_γ(x) = B_γ x`` rotations about ``e₁``
  and ``e₂`` (solved by ``roughpaths.solve`` on the :class:`roughpaths.ChaoticDriver`, exact per fast step),
  with the homogenised limit ``exp(Σ K^{βγ} B_γ B_β) x₀``, ``K = E + ½C(0)`` (within 4 SE), and with the
  wrong guesses "Stratonovich without the area" (``K = ½Σ``) and "Itô without E" (``K = 0``), which must be
  at least 6 SE away; the same mean from ``solve`` on :func:`roughpaths.chaotic_limit_path`;
* on Lorenz-63 (``v = (x, y)/30``, sampled every 0.05), where ``E`` is **estimated**: the fast–slow mean
  against the prediction from the estimate (4 combined SE, the prediction's SE from 8 groups of orbits).
Derivation: :mod:`roughpaths.drivers.chaotic_limit`; tutorial ``docs/tutorials/deterministic-chaos.md``.

Sizes: ``chaos.n_paths`` (cat-map orbits; tiny 300, default 6000, full 20000; Lorenz uses a third) and
``chaos.n_steps`` (fast steps per unit time; 40, 200, 1000; Lorenz twice as many); the Green–Kubo orbits
follow the number of paths. At tiny sizes the wrong guess "Stratonovich without the area" is within the
noise (the check may fail there, as the tiny run allows).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

import roughpaths

from .report import CheckResult

__all__ = ["check_chaos"]

_A = np.array([[2, 1], [1, 1]])
_K, _Q = np.array([1, 0]), np.array([0, 1])
_B = np.array([[[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
               [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]])
_X0 = np.array([0.0, 0.6, 0.8])


def _mean(K):
    """``exp(Σ K^{βγ} B_γ B_β) x₀``: the mean at time 1 of the limit whose area drift is ``K``."""
    return expm(sum(K[b, g] * _B[g] @ _B[b] for b in range(2) for g in range(2))) @ _X0


def _z(x, pred, extra_se=0.0):
    se = np.sqrt((x.std(axis=0, ddof=1) / np.sqrt(x.shape[0])) ** 2 + np.asarray(extra_se) ** 2)
    return np.abs(x.mean(axis=0) - pred) / se


def _fast_slow_final(driver):
    V = roughpaths.LinearVectorFields(_B)
    return roughpaths.solve(V, driver, _X0, solver="logode", save_at="end").final


def check_chaos(ctx) -> CheckResult:
    v = roughpaths.SineObservable([[_K, _A @ _A @ _Q], [_A @ _K, _Q]], [[1.0, 0.5], [1.0, 1.0]])
    P = ctx.size("chaos.n_paths", tiny=300, default=6000, full=20000)
    n = ctx.size("chaos.n_steps", tiny=40, default=200, full=1000)
    G, LG = max(16, min(256, P // 50)), 8 * max(2, min(64, P // 320))  # Green–Kubo orbits: cat map, Lorenz (8 groups)
    LP, Ln = max(200, P // 3), 2 * n                                      # Lorenz fast–slow paths and steps
    C = v.correlations(8)
    E = C[1:].sum(axis=0)
    Sig = C[0] + E + E.T
    notes, ok = [], []
    # 1. Green–Kubo against the closed form
    gk = roughpaths.green_kubo(roughpaths.observable_orbits(roughpaths.cat_map(), v, 4000, seed=ctx.seed_for("chaos.gk"),
                                                             batch_shape=(G,)), 8)
    z_gk = float(np.max(np.abs(gk.E - E) / gk.E_se))
    ok.append(z_gk <= 4)
    notes.append(f"Green–Kubo E = {np.round(gk.E, 4).tolist()} ± {np.round(gk.E_se, 4).tolist()} (closed form "
                 f"{E.tolist()}; max {z_gk:.2f} SE)")
    # 2. the Lévy area of the lift and 3. the fast–slow mean, on the same orbits
    drv = roughpaths.ChaoticDriver(roughpaths.cat_map(), v, n, seed=ctx.seed_for("chaos.cat"), dt=1.0 / n, n_steps=n,
                                   batch_shape=(P,))
    area = drv.rough_path().levy_area(0.0, 1.0)[:, 0, 1]
    alt = sum((n - m) * C[m] for m in range(1, 9)) / n
    a_pred = 0.5 * (alt - alt.T)[0, 1]
    z_area = float(abs(area.mean() - a_pred) / (area.std(ddof=1) / np.sqrt(P)))
    ok.append(z_area <= 4)
    notes.append(f"Lévy area over [0, 1]: {area.mean():.4f} (predicted {a_pred:.4f}, {z_area:.2f} SE)")
    x = _fast_slow_final(drv)
    pred = _mean(E + 0.5 * C[0])
    z_ok = float(np.max(_z(x, pred)))
    z_strat = float(np.max(_z(x, _mean(0.5 * Sig))))
    z_ito = float(np.max(_z(x, _mean(0.0 * E))))
    ok += [z_ok <= 4, z_strat >= 6, z_ito >= 6]
    notes.append(f"fast–slow E[x_1] = {np.round(x.mean(axis=0), 4).tolist()} (limit {np.round(pred, 4).tolist()}, "
                 f"max {z_ok:.2f} SE; Stratonovich without area {z_strat:.1f} SE, Itô without E {z_ito:.1f} SE away)")
    lim = roughpaths.chaotic_limit(Sig, E)
    brown = roughpaths.brownian_rough_path(np.linspace(0.0, 1.0, 65), 2, ctx.rng("chaos.limit"), batch_shape=(P,),
                                           levy_area=ctx.levy_area_for(2))
    xl = _fast_slow_final(roughpaths.chaotic_limit_path(lim, brown))
    z_lim = float(np.max(_z(xl, pred)))
    ok.append(z_lim <= 4)
    notes.append(f"solve on chaotic_limit_path: {np.round(xl.mean(axis=0), 4).tolist()} ({z_lim:.2f} SE)")
    # 4. Lorenz-63: E estimated
    L = roughpaths.lorenz63_map(0.05)

    def obs(y):
        return y[..., :2] / 30.0

    vals = roughpaths.observable_orbits(L, obs, 6000, seed=ctx.seed_for("chaos.lorenz_gk"), batch_shape=(LG,))
    est = roughpaths.green_kubo(vals, 200)
    groups = [roughpaths.green_kubo(g, 200) for g in np.split(vals, 8)]
    p_se = np.array([_mean(g.E + 0.5 * g.correlations[0]) for g in groups]).std(axis=0, ddof=1) / np.sqrt(8)
    ldrv = roughpaths.ChaoticDriver(L, obs, Ln, seed=ctx.seed_for("chaos.lorenz"), dt=1.0 / Ln, n_steps=Ln,
                                    batch_shape=(LP,))
    xL = _fast_slow_final(ldrv)
    lpred = _mean(est.E + 0.5 * est.correlations[0])
    z_L = float(np.max(_z(xL, lpred, p_se)))
    z_L_ito = float(np.max(_z(xL, _mean(0.0 * est.E), p_se)))
    ok += [z_L <= 4, z_L_ito >= 6]
    notes.append(f"Lorenz-63: Ê = {np.round(est.E, 3).tolist()} ± {float(est.E_se.max()):.3f}, Alt(Ê)12 = "
                 f"{0.5 * (est.E[0, 1] - est.E[1, 0]):.3f}; E[x_1] = {np.round(xL.mean(axis=0), 4).tolist()} against "
                 f"{np.round(lpred, 4).tolist()} ({z_L:.2f} combined SE; Itô without E {z_L_ito:.1f} SE)")
    return CheckResult(
        "chaos",
        "Conclusion (Kelly–Melbourne): sums of an observable along a fast chaotic map converge to Brownian motion "
        "whose area carries the drift Alt(E), E = Σ_{m≥1} ∫ v⊗v∘T^m dμ; fast–slow systems converge to the "
        "Stratonovich equation plus the Lévy-area drift, neither Itô nor Stratonovich (cat map with E exact; "
        "Lorenz-63 with E estimated).",
        predicted=pred, measured=x.mean(axis=0),
        tolerance="each comparison within 4 SE; the wrong guesses (Stratonovich without area, Itô without E) "
                  "at least 6 SE away",
        passed=all(ok), details=f"{P} orbits, n = {n} fast steps per unit time; " + "; ".join(notes))
