r"""One Brownian path behind every grid: :meth:`BrownianDriver.refine` (a driver on a finer grid, same path).

``BrownianDriver(...).refine(F)`` is a lazy, per-path seeded driver on the grid whose every step is split
into ``F`` equal sub-steps (any integer ``F >= 1``), whose path is the *same* Brownian path as the coarse
driver's: its increments sum (to round-off) to the coarse ones, and the coarse numbers are never
redrawn. Conventions as in :mod:`roughpaths.brownian` (Lévy area with the ½; Chen:
:math:`A_{0,h} = \sum_l A_l + \tfrac12\sum_{l<l'} w_l\wedge w_{l'}`).

The Brownian path inside a coarse step
--------------------------------------
On a step of length ``h`` with increment ``W``, with ``u = t/h``, the path is (Kloeden–Platen–Wright)

.. math:: W_t = uW + \sum_{k\ge1} \sigma_k\bigl[\alpha_k(\cos 2\pi k u - 1) + \beta_k \sin 2\pi k u\bigr],
          \qquad \sigma_k = \frac{\sqrt{h/2}}{\pi k},

with independent standard normal vectors :math:`\alpha_k, \beta_k` (``d`` components each), and its Lévy
area is :math:`A = \sum_k \frac{h}{2\pi k}\alpha_k\wedge\beta_k - S\wedge W` with
:math:`S = \sum_k\sigma_k\alpha_k`. The Fourier samplers of :mod:`roughpaths.levy_area` draw exactly
these: their ``ξ_k, η_k`` are :math:`-\alpha_k, -\beta_k` for the ``n`` retained terms, their ``ψ`` is
the tail sum :math:`\sum_{k>n}\sigma_k\alpha_k` scaled to unit variance, and their pair Gaussian the
tail's own area :math:`\sum_{k>n}\frac{h}{2\pi k}\alpha_k\wedge\beta_k` (replaced by a Gaussian of the
same variance: the approximation of the method).

Refinement of the error-controlled methods (``"fourier"``, ``"mrongowius-rossler"``, ``"wiktorsson"``,
``"auto"``, and ``"exact"``, which has ``n = 0`` retained terms)
-----------------------------------------------------------------------------------------------------
1. The retained terms ``k <= n`` are the coarse step's own normals (regenerated from its stream).
2. The terms ``n < k <= K`` (:math:`K = n + 4F`) are drawn given what the coarse step fixed of them: the
   tail sum ``S`` (if the method stores it) and the coarse Lévy area. The area is bilinear in
   :math:`(\alpha, \beta)`: linear in ``β`` given ``α`` and in ``α`` given ``β``, with the terms beyond
   ``K`` entering as a Gaussian slack (their sum :math:`S_K` and area :math:`R`, variances
   :math:`h\,s_K/(2\pi^2)` and :math:`h^2 s_K/(2\pi^2)`, :math:`s_K = \sum_{k>K}k^{-2}`). Each
   conditional is an exact Gaussian (Matheron) update; :data:`GIBBS_SWEEPS` sweeps alternate them,
   starting from the prior.
3. The path beyond ``K`` at the ``F - 1`` interior sub-grid points is drawn exactly from its Gaussian law
   given :math:`S_K` (covariance in closed form: the bridge kernel :math:`h\,u(1-v)`, ``u <= v``, minus
   the first ``K`` terms :math:`\sum_{k\le K}\sigma_k^2[\cos 2\pi k(u-v) - \cos 2\pi ku - \cos 2\pi kv + 1]`).
   The fine increments are the differences of the path at the sub-grid points.
4. The fine Lévy areas are drawn by the coarse method at the fine step :math:`\delta = h/F` (its own
   error rule; ``"exact"`` uses ``"auto"``), given the fine increments, then shifted by the Gaussian
   (Matheron) update that makes Chen's identity exact: :math:`A_l \leftarrow A_l + C_l Y` with
   :math:`C_l = \mathrm{Var}(A_l\mid w_l) = \tfrac{\delta^2}{12} + \tfrac{\delta}{12}(w_l\text{-terms})`
   and :math:`Y = (\sum_l C_l)^{-1}(A - \text{polygon} - \sum_l A_l)`.

What is exact: the fine increments sum to ``W`` and Chen's identity holds (to round-off, ~1e-15);
the retained terms, and with them the coarse area's explicit part, are the coarse step's; the law of the
fine increments given ``W`` (and given ``S`` where stored) is the Brownian one up to step 2's
conditioning on the area (exact in the limit of many sweeps); given the fine increments, the fine
areas' conditional second moments are Brownian whenever the residual ``A - polygon`` is (Brownian
motion: :math:`\sum_l C_l`). What is approximate: the coarse tail area is a Gaussian (the method's own
approximation), the slack beyond ``K`` is Gaussian, the Gibbs sweeps are finite, and the fine areas have
the fine sampler's law error. Measured: see ``tests/test_brownian_refinement_same_path.py``.

Refinement of ``"davie"`` / ``"foster"``
----------------------------------------
What those samplers draw of the path is linear: the increments and the space-time Lévy areas
:math:`H = \frac1\delta\int(W_r - W_s - \frac{r-s}{\delta}w)\,dr` of their ``m`` sub-steps. The fine path
is the exact Gaussian bridge given them (the fine increments and fine space-time areas, from their
closed-form joint covariance), and the fine areas are drawn by the same method (one sub-step per fine
step): :math:`H_l\wedge w_l` (+ Davie's independent Gaussian of variance :math:`\delta^2/12`). The coarse
area is *not* the area of the refined path (Davie's added Gaussian, or Foster's missing part, is
independent of the path): Chen's identity fails by exactly that amount, which is why "davie" areas give
strong order ½ against Brownian motion.

Streams: path ``i`` draws the refinement's normals from ``SeedSequence(S.entropy, spawn_key=S.spawn_key
+ (i, 2))`` (the coarse driver uses ``(i, 0)`` and ``(i, 1)``), a fixed number per coarse step, steps in
order: invariant under block size, :meth:`select` and executor.
"""

from __future__ import annotations

import math

import numpy as np

from ._random import PathStreams
from .driver import Driver
from .levy_area import LEVY_AREA_METHODS, levy_area_normals, levy_areas_from_normals, step_plan
from .rough_path import RoughPath
from .validation import check_positive_int

__all__ = ["RefinedBrownianDriver", "GIBBS_SWEEPS", "MODES_PER_SUBSTEP"]

#: Gibbs sweeps that condition the explicit tail terms on the coarse area.
GIBBS_SWEEPS = 3
#: Explicit Fourier terms beyond the retained ones, per fine sub-step (``K = n + MODES_PER_SUBSTEP F``).
MODES_PER_SUBSTEP = 4


def _tail_zeta2(n: int) -> float:
    from scipy.special import polygamma

    return float(polygamma(1, n + 1))


# ------------------------------------------------------------------ antisymmetric (pair) algebra
def _wedge(u, v):
    """``u ∧ v = u vᵀ - v uᵀ``, batched over leading axes."""
    return u[..., :, None] * v[..., None, :] - v[..., :, None] * u[..., None, :]


def _pair_solve(N, v, rhs):
    r"""Solve :math:`YN + NY + vY = \text{rhs}` for antisymmetric ``Y`` (batched; ``N`` symmetric ``(..., d, d)``).

    The operator is the covariance of :math:`\sum_k u_k\wedge\alpha_k + \text{(slack of variance v)}`
    with :math:`N = \sum_k u_k u_k^T`; in pair coordinates ``(i < j)`` its matrix is
    :math:`v\,\delta + \delta_{ik}N_{jl} + \delta_{jl}N_{ik} - \delta_{il}N_{jk} - \delta_{jk}N_{il}`.
    """
    d = N.shape[-1]
    iu, ju = np.triu_indices(d, 1)
    p = iu.size
    I = np.eye(d)
    i, j, k, l = iu[:, None], ju[:, None], iu[None, :], ju[None, :]
    M = (I[i, k] * N[..., j, l] + I[j, l] * N[..., i, k] - I[i, l] * N[..., j, k] - I[j, k] * N[..., i, l])
    M = M + np.asarray(v)[..., None, None] * np.eye(p)
    y = np.linalg.solve(M, rhs[..., iu, ju][..., None])[..., 0]
    Y = np.zeros(rhs.shape)
    Y[..., iu, ju] = y
    return Y - np.swapaxes(Y, -1, -2)


def _pair_gram(X):
    """``Σ_c X_c X_cᵀ`` over the mode axis ``-2`` of ``X (..., M, d)``."""
    return np.swapaxes(X, -1, -2) @ X


def _outer_sum(X, Y):
    """``Σ_m X_m Y_mᵀ`` over the mode axis of ``X, Y (R, M, d)`` (a batched matrix product)."""
    return np.swapaxes(X, -1, -2) @ Y


# ------------------------------------------------------------------ plans (per coarse step length)
class _FourierPlan:
    """Constants of the Fourier-path refinement of steps of length ``h`` into ``F`` sub-steps."""

    def __init__(self, h, F, d, method, n, stores_s, fine):
        self.h, self.F, self.d, self.n, self.method, self.stores_s = h, F, d, n, method, stores_s
        K = n + MODES_PER_SUBSTEP * F
        self.K = K
        k = np.arange(1, K + 1, dtype=float)
        self.sigma = math.sqrt(h / 2.0) / (math.pi * k)
        self.gamma = h / (2.0 * math.pi * k)
        sK = _tail_zeta2(K)
        self.var_SK = h * sK / (2 * math.pi ** 2)
        self.var_R = h * h * sK / (2 * math.pi ** 2)
        u = np.arange(1, F) / F
        self.u = u
        ang = 2 * math.pi * np.outer(k, u)
        self.Ccos = self.sigma[:, None] * (np.cos(ang) - 1.0)         # (K, F-1)
        self.Csin = self.sigma[:, None] * np.sin(ang)
        # the path beyond K at the sub-grid points, given S_K
        uu, vv = np.minimum.outer(u, u), np.maximum.outer(u, u)
        cov = h * uu * (1 - vv)
        for kk in range(1, K + 1):
            s2 = self.sigma[kk - 1] ** 2
            cov -= s2 * (np.cos(2 * math.pi * kk * (u[:, None] - u[None, :])) - np.cos(2 * math.pi * kk * u)[:, None]
                         - np.cos(2 * math.pi * kk * u)[None, :] + 1.0)
        c = h * (u * u - u) / 2 - (self.sigma[:, None] ** 2 * (np.cos(ang) - 1.0)).sum(axis=0)
        self.rem_gain = c / self.var_SK if F > 1 else c
        cond = cov - np.outer(c, c) / self.var_SK if F > 1 else cov
        lam, V = np.linalg.eigh(cond) if F > 1 else (np.zeros(0), np.zeros((0, 0)))
        self.rem_sqrt = V * np.sqrt(np.clip(lam, 0.0, None))
        self.fine = fine                                                # (method, n, width) at δ = h/F
        M = K - n
        p = d * (d - 1) // 2
        self.M = M
        self.width = (M * d) + GIBBS_SWEEPS * (2 * M * d + d + 2 * p) + (F - 1) * d + _fine_width(F, d, fine[1])


class _BridgePlan:
    """Constants of the Davie/Foster refinement: fine (w, H) given coarse sub-step (w, H), per component."""

    def __init__(self, h, F, d, m, davie):
        self.h, self.F, self.d, self.m, self.davie = h, F, d, m, davie
        L = math.lcm(m, F)
        edges = np.arange(L + 1) / L * h
        x, wq = np.polynomial.legendre.leggauss(2)
        a, b = edges[:-1, None], edges[1:, None]
        nodes = (0.5 * (b - a) * x + 0.5 * (a + b)).ravel()
        weights = (0.5 * (b - a) * wq).ravel()

        def funcs(cnt):
            s = np.arange(cnt)[:, None] * h / cnt
            t = s + h / cnt
            inside = (nodes[None, :] >= s) & (nodes[None, :] < t)
            inc = inside.astype(float)
            H = inside * (0.5 - (nodes[None, :] - s) / (h / cnt))
            return inc, H

        ci, cH = funcs(m)
        fi, fH = funcs(F)
        coarse = np.vstack([ci, cH])                      # (2m, nodes)
        fine = np.vstack([fi[:-1], fH])                   # (2F - 1, nodes): the last increment is W - Σ
        Scc = (coarse * weights) @ coarse.T
        Sfc = (fine * weights) @ coarse.T
        Sff = (fine * weights) @ fine.T
        self.gain = np.linalg.solve(Scc, Sfc.T).T          # (2F-1, 2m)
        cond = Sff - self.gain @ Sfc.T
        lam, V = np.linalg.eigh(0.5 * (cond + cond.T))
        self.sqrt = V * np.sqrt(np.clip(lam, 0.0, None))
        p = d * (d - 1) // 2
        self.width = (2 * F - 1) * d + (F * p if davie else 0)


# ------------------------------------------------------------------ the refinements of a batch of steps
class _Normals:
    """Consumes a row block ``z (R, width)`` of standard normals left to right."""

    def __init__(self, z):
        self.z, self.pos = z, 0

    def take(self, shape):
        cnt = int(np.prod(shape, dtype=np.int64))
        out = self.z[:, self.pos:self.pos + cnt].reshape((self.z.shape[0],) + tuple(shape))
        self.pos += cnt
        return out

    def antisym(self, lead, d):
        """Antisymmetric ``(R, *lead, d, d)`` with independent standard normals above the diagonal."""
        iu, ju = np.triu_indices(d, 1)
        Y = np.zeros((self.z.shape[0],) + tuple(lead) + (d, d))
        Y[..., iu, ju] = self.take(tuple(lead) + (iu.size,))
        return Y - np.swapaxes(Y, -1, -2)


def _fine_width(F, d, nf) -> int:
    p = d * (d - 1) // 2
    return F * nf * d + GIBBS_SWEEPS * F * (2 * nf * d + d + 2 * p)


def _refine_fourier(plan, W, A, xi, eta, S, z):
    """Fine increments ``(R, F, d)`` and Lévy areas ``(R, F, d, d)`` of ``R`` coarse steps (module docstring).

    ``W (R, d)``, ``A (R, d, d)`` coarse Lévy areas, ``xi, eta (R, d, n)`` the retained normals (or
    ``None`` for ``n = 0``), ``S (R, d)`` the stored tail sum or None, ``z (R, plan.width)`` normals.
    """
    h, F, d, n, M = plan.h, plan.F, plan.d, plan.n, plan.M
    R = W.shape[0]
    p = d * (d - 1) // 2
    sig, gam = plan.sigma[n:], plan.gamma[n:]
    zc = _Normals(z)

    # the tail's part of the coarse area (retained terms removed)
    A_tail = A.copy()
    if n:
        g0 = plan.gamma[:n]
        Q = np.einsum("rik,rjk,k->rij", xi, eta, g0)
        A_tail -= Q - np.swapaxes(Q, -1, -2)                     # Σ γ_k ξ_k ∧ η_k
        S_ret = -(xi * plan.sigma[:n]).sum(axis=-1)              # Σ σ_k α_k, α = -ξ
        A_tail -= _wedge(W, S_ret)                               # - S_ret ∧ W
    beta = zc.take((M, d))
    alpha = S_K = Rr = None
    for _ in range(GIBBS_SWEEPS):
        # α-block (α, S_K, R) given β: area Σ u_k∧α_k + W∧S_K + R = A_tail [, Σσα + S_K = S]
        u = sig[None, :, None] * W[:, None, :] - gam[None, :, None] * beta          # (R, M, d)
        a0 = zc.take((M, d))
        sk0 = zc.take((d,)) * math.sqrt(plan.var_SK)
        r0 = zc.antisym((), d) * math.sqrt(plan.var_R)
        Q = _outer_sum(u, a0)
        area0 = (Q - np.swapaxes(Q, -1, -2)) + _wedge(W, sk0) + r0
        N = _pair_gram(u) + plan.var_SK * W[:, :, None] * W[:, None, :]
        if S is None:
            Y = _pair_solve(N, plan.var_R, A_tail - area0) if p else np.zeros((R, d, d))
            alpha = a0 - u @ np.swapaxes(Y, 1, 2)
            S_K = sk0 - plan.var_SK * (Y @ W[..., None])[..., 0]
            Rr = r0 + plan.var_R * Y
        else:
            alpha, S_K, Rr = _alpha_block_with_s(plan, W, u, N, a0, sk0, r0, area0, A_tail, S, sig)
        # β-block (β, R) given α: Σ γ_k α_k∧β_k + R = A_tail - W∧S_tail
        S_tail = (alpha * sig[None, :, None]).sum(axis=1) + S_K
        target = A_tail - _wedge(W, S_tail)
        b0 = zc.take((M, d))
        r0 = zc.antisym((), d) * math.sqrt(plan.var_R)
        ga = gam[None, :, None] * alpha
        Q = _outer_sum(ga, b0)
        lin0 = (Q - np.swapaxes(Q, -1, -2)) + r0
        if p:
            Y = _pair_solve(_pair_gram(ga), plan.var_R, target - lin0)
            beta = b0 - ga @ np.swapaxes(Y, 1, 2)
            Rr = r0 + plan.var_R * Y
        else:
            beta = b0
    # the path at the interior sub-grid points
    X = plan.u[None, None, :] * W[:, :, None]                                    # (R, d, F-1)
    if n:
        X = X - xi @ plan.Ccos[:n] - eta @ plan.Csin[:n]
    X = X + np.swapaxes(alpha, 1, 2) @ plan.Ccos[n:] + np.swapaxes(beta, 1, 2) @ plan.Csin[n:]
    zr = zc.take((d, F - 1))
    X = X + S_K[:, :, None] * plan.rem_gain[None, None, :] + zr @ plan.rem_sqrt.T
    pts = np.concatenate([np.zeros((R, d, 1)), X, W[:, :, None]], axis=2)
    w = np.swapaxes(np.diff(pts, axis=2), 1, 2)                                  # (R, F, d)
    return w, _fine_areas_gibbs(plan.h / F, plan.fine, w, A, zc)


def _alpha_block_with_s(plan, W, u, N, a0, sk0, r0, area0, A_tail, S, sig):
    """The α-block update with the stored tail sum ``S`` as a further (``d``-row) constraint."""
    R, M, d = a0.shape
    iu, ju = np.triu_indices(d, 1)
    p = iu.size
    vS = plan.var_SK
    # covariance of the stacked constraint (area pairs, S), built column by column from the operators
    E_cols = np.zeros((p, d, d))
    E_cols[np.arange(p), iu, ju] = 1.0
    E_cols[np.arange(p), ju, iu] = -1.0
    CAA = np.empty((R, p, p))
    for q in range(p):
        Yq = E_cols[q]
        col = Yq @ N + N @ Yq + plan.var_R * Yq
        CAA[:, :, q] = col[:, iu, ju]
    v = (sig[None, :, None] * u).sum(axis=1) + vS * W                            # (R, d)
    CAS = _wedge_rows(v, iu, ju)                                                 # (R, p, d)
    CSS = (float((sig ** 2).sum()) + vS) * np.eye(d)
    C = np.zeros((R, p + d, p + d))
    C[:, :p, :p] = CAA
    C[:, :p, p:] = CAS
    C[:, p:, :p] = np.swapaxes(CAS, 1, 2)
    C[:, p:, p:] = CSS
    s0 = (a0 * sig[None, :, None]).sum(axis=1) + sk0
    rhs = np.concatenate([(A_tail - area0)[:, iu, ju], S - s0], axis=1)
    y = np.linalg.solve(C, rhs[..., None])[..., 0]
    YA = np.zeros((R, d, d))
    YA[:, iu, ju] = y[:, :p]
    YA = YA - np.swapaxes(YA, 1, 2)
    YS = y[:, p:]
    alpha = a0 - u @ np.swapaxes(YA, 1, 2) + sig[None, :, None] * YS[:, None, :]
    S_K = sk0 + vS * (YS - (YA @ W[..., None])[..., 0])
    return alpha, S_K, r0 + plan.var_R * YA


def _wedge_rows(v, iu, ju):
    """The ``(p, d)`` matrix of ``x ↦ (v ∧ x)`` in pair coordinates, batched: row ``(i,j)`` has ``v_i`` at ``j``, ``-v_j`` at ``i``."""
    R, d = v.shape
    E = np.zeros((R, iu.size, d))
    E[:, np.arange(iu.size), ju] = v[:, iu]
    E[:, np.arange(iu.size), iu] = -v[:, ju]
    return E


def _fine_areas_gibbs(delta, fine, w, A, zc):
    r"""Fine Lévy areas ``(R, F, d, d)`` of the Mrongowius–Rößler form, conditioned on Chen's identity.

    Each fine step's area is :math:`\sum_{k\le n_f}\gamma_k\alpha_{lk}\wedge\beta_{lk} - S_l\wedge w_l + R_l`
    (:math:`S_l = \sum_k\sigma_k\alpha_{lk} + S'_l`, the tail sum, and :math:`R_l` the Gaussian tail area; no
    :math:`R_l` for ``"fourier"``). Their sum must be ``D = A - polygon(w)``; the constraint is linear in
    :math:`(\alpha, S', R)` given :math:`\beta` and in :math:`(\beta, R)` given :math:`\alpha`: Gibbs
    sweeps of exact Gaussian updates, so the areas keep their bilinear (non-Gaussian) structure.
    """
    R, F, d = w.shape
    method, nf, _ = fine
    if d == 1:
        return np.zeros((R, F, 1, 1))
    k = np.arange(1, nf + 1, dtype=float)
    sig = (math.sqrt(delta / 2.0) / (math.pi * k))[:, None]
    gam = (delta / (2.0 * math.pi * k))[:, None]
    s_n = _tail_zeta2(nf)
    vS = delta * s_n / (2 * math.pi ** 2)
    vR = 0.0 if method == "fourier" else delta * delta * s_n / (2 * math.pi ** 2)
    S_ex = np.cumsum(w, axis=1) - w
    Q = _outer_sum(S_ex, w)
    D = A - 0.5 * (Q - np.swapaxes(Q, -1, -2))
    wl = w[:, :, None, :]                                                        # (R, F, 1, d)
    Nw = _pair_gram(w)
    beta = zc.take((F, nf, d))
    for _ in range(GIBBS_SWEEPS):
        u = sig * wl - gam * beta                                                # (R, F, nf, d)
        a0 = zc.take((F, nf, d))
        s0 = zc.take((F, d)) * math.sqrt(vS)
        r0 = zc.antisym((F,), d) * math.sqrt(vR)
        uu = u.reshape(R, F * nf, d)
        Q = _outer_sum(uu, a0.reshape(R, F * nf, d)) + _outer_sum(w, s0)
        area0 = (Q - np.swapaxes(Q, -1, -2)) + r0.sum(axis=1)
        Y = _pair_solve(_pair_gram(uu) + vS * Nw, F * vR, D - area0)
        YT = np.swapaxes(Y, 1, 2)[:, None]
        alpha = a0 - u @ YT
        S = (sig * alpha).sum(axis=2) + s0 - vS * (w @ np.swapaxes(Y, 1, 2))
        Rl = r0 + vR * Y[:, None]
        Q = _outer_sum(S, w)
        target = D + (Q - np.swapaxes(Q, -1, -2))                                # Σ_l (Σ γ α∧β + R_l)
        b0 = zc.take((F, nf, d))
        r0 = zc.antisym((F,), d) * math.sqrt(vR)
        ga = (gam * alpha).reshape(R, F * nf, d)
        Q = _outer_sum(ga, b0.reshape(R, F * nf, d))
        lin0 = (Q - np.swapaxes(Q, -1, -2)) + r0.sum(axis=1)
        Y = _pair_solve(_pair_gram(ga), F * vR, target - lin0)
        beta = b0 - (gam * alpha) @ np.swapaxes(Y, 1, 2)[:, None]
        Rl = r0 + vR * Y[:, None]
    Q = np.swapaxes(gam * alpha, -1, -2) @ beta                                  # (R, F, d, d)
    Sw = S[..., :, None] * w[..., None, :]
    return (Q - np.swapaxes(Q, -1, -2)) - (Sw - np.swapaxes(Sw, -1, -2)) + Rl


def _refine_bridge(plan, Wsub, Hsub, z):
    """Davie/Foster: fine ``(w, A)`` given the coarse sub-step increments and space-time areas ``(R, m, d)``."""
    R, m, d = Wsub.shape
    F = plan.F
    coarse = np.concatenate([Wsub, Hsub], axis=1)                          # (R, 2m, d)
    zz = z[:, :(2 * F - 1) * d].reshape(R, 2 * F - 1, d)
    fine = np.einsum("fc,rcd->rfd", plan.gain, coarse) + np.einsum("fg,rgd->rfd", plan.sqrt, zz)
    w = np.empty((R, F, d))
    w[:, :F - 1] = fine[:, :F - 1]
    w[:, F - 1] = Wsub.sum(axis=1) - fine[:, :F - 1].sum(axis=1)
    H = fine[:, F - 1:]
    A = _wedge(H, w)
    if plan.davie and d > 1:
        p = d * (d - 1) // 2
        iu, ju = np.triu_indices(d, 1)
        lam = np.zeros((R, F, d, d))
        lam[:, :, iu, ju] = z[:, (2 * F - 1) * d:].reshape(R, F, p) * (plan.h / F / math.sqrt(12.0))
        A = A + lam - np.swapaxes(lam, -1, -2)
    return w, A


# ------------------------------------------------------------------ the driver
_ROWS = 1024           # coarse path-steps refined at once (bounds the temporaries, never the numbers)


class RefinedBrownianDriver(Driver):
    r"""A :class:`~roughpaths.BrownianDriver` on a grid ``factor`` times finer, carrying the same Brownian path.

    Built by :meth:`roughpaths.BrownianDriver.refine`; see :mod:`roughpaths.brownian_refined` for what is
    exact and what is approximate for each ``levy_area`` method. Lazy (time blocks), per-path seeded:
    a path's numbers depend only on the coarse driver's seed, the path's index, ``factor`` and the
    method, never on the block size, :meth:`select` or the executor.

    Parameters
    ----------
    coarse : BrownianDriver
        The driver to refine (its numbers are regenerated, never changed).
    factor : int
        Equal sub-steps per coarse step, ``>= 1``.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import BrownianDriver
    >>> from roughpaths.rough_path import chen_defect
    >>> drv = BrownianDriver(2, seed=3, dt=0.25, n_steps=4, batch_shape=(5,), levy_area="mrongowius-rossler")
    >>> fine = drv.refine(3)
    >>> fine.n_steps, fine.batch_shape
    (12, (5,))
    >>> X, Y = drv.rough_path(), fine.rough_path()
    >>> bool(chen_defect(Y, X) < 1e-13), bool(np.allclose(Y.restrict(X.times).increments, X.increments))
    (True, True)
    """

    def __init__(self, coarse, factor):
        from .brownian import BrownianDriver

        if not isinstance(coarse, BrownianDriver):
            raise TypeError(f"coarse must be a BrownianDriver, got {type(coarse).__name__}; call "
                            f"BrownianDriver(...).refine(factor).")
        self.factor = check_positive_int(factor, "factor")
        self.coarse = coarse
        self.dim, self.level, self.kind = coarse.dim, coarse.level, coarse.kind
        F = self.factor
        t = coarse.times
        fine = (t[:-1, None] + coarse._h[:, None] * (np.arange(F) / F)).ravel()
        self.times = np.append(fine, t[-1])
        self.times.setflags(write=False)
        self._plans = {}

    @property
    def batch_shape(self) -> tuple:
        return self.coarse.batch_shape

    @property
    def n_paths(self) -> int:
        return self.coarse.n_paths

    @property
    def path_indices(self) -> np.ndarray:
        return self.coarse.path_indices

    def __repr__(self) -> str:
        return f"RefinedBrownianDriver({self.coarse!r}, factor={self.factor})"

    def select(self, paths):
        """The refinement of ``coarse.select(paths)``: bitwise equal to those paths of this driver."""
        new = RefinedBrownianDriver(self.coarse.select(paths), self.factor)
        new._plans = self._plans
        return new

    def default_block_steps(self) -> int:
        """Fine steps per block when :meth:`blocks` gets no ``max_steps`` (whole coarse steps)."""
        return self.factor * max(1, self.coarse.default_block_steps() // self.factor)

    # ------------------------------------------------------------------ per step length
    def _plan(self, h: float):
        plan = self._plans.get(h)
        if plan is not None:
            return plan
        c, F, d = self.coarse, self.factor, self.dim
        if c.levy_area is None:
            plan = ("bridge1", F * d)
        elif c.levy_area in ("davie", "foster"):
            plan = _BridgePlan(h, F, d, c.substeps, c.levy_area == "davie")
        else:
            if c.levy_area == "exact":
                method, n, stores_s, fine_method, err = "exact", 0, False, "auto", None
            else:
                method, n, _ = c._fourier_plan[h]
                stores_s = method in ("fourier", "mrongowius-rossler")
                fine_method, err = c.levy_area, c.levy_area_error
            delta = h / F
            fine = step_plan(fine_method, d, [delta], err)[float(delta)] if d > 1 else ("fourier", 1, 0)
            plan = _FourierPlan(h, F, d, method, n, stores_s, fine)
        self._plans[h] = plan
        return plan

    def _area_width(self, h: float) -> int:
        c = self.coarse
        if c.levy_area in LEVY_AREA_METHODS + ("auto",):
            return c._fourier_plan[h][2]
        if c.levy_area in ("davie", "foster"):
            return c._n_area_normals
        return 0

    def _refine_rows(self, h, W, A, za, zr):
        """Fine ``(w, Lévy areas)`` of rows ``W (R, d)``, ``A (R, d, d)`` with their area and refinement normals."""
        plan, d, F = self._plan(h), self.dim, self.factor
        R = W.shape[0]
        c = self.coarse
        if c.levy_area is None:
            z = zr.reshape(R, F, d)
            return W[:, None, :] / F + math.sqrt(h / F) * (z - z.mean(axis=1, keepdims=True)), None
        if isinstance(plan, _BridgePlan):
            m = plan.m
            if m == 1:
                Wsub, zeta = W[:, None, :], za[:, :d].reshape(R, 1, d)
            else:
                zb = za[:, :m * d].reshape(R, m, d)
                Wsub = math.sqrt(h / m) * (zb - zb.mean(axis=1, keepdims=True)) + W[:, None, :] / m
                zeta = za[:, m * d:2 * m * d].reshape(R, m, d)
            Hsub = math.sqrt(h / m / 12.0) * zeta
            return _refine_bridge(plan, Wsub, Hsub, zr)
        n = plan.n
        xi = za[:, :d * n].reshape(R, d, n) if n else None
        eta = za[:, d * n:2 * d * n].reshape(R, d, n) if n else None
        S = None
        if plan.stores_s:
            psi = za[:, 2 * d * n:2 * d * n + d]
            S = -math.sqrt(h * _tail_zeta2(n) / (2 * math.pi ** 2)) * psi
        return _refine_fourier(plan, W, A, xi, eta, S, zr)

    def _refine_width(self, h: float) -> int:
        plan = self._plan(h)
        return plan[1] if isinstance(plan, tuple) else plan.width

    # ------------------------------------------------------------------ generation
    def blocks(self, max_steps=None):
        """Yield consecutive ``RoughPath`` blocks of at most ``max_steps`` fine steps covering the fine grid.

        The numbers do not depend on ``max_steps`` (default :meth:`default_block_steps`).
        """
        F, d, c = self.factor, self.dim, self.coarse
        K = self.default_block_steps() if max_steps is None else check_positive_int(max_steps, "max_steps")
        kc = max(1, K // F)
        P = self.n_paths
        keys = np.zeros((P, 2), dtype=np.int64)
        keys[:, 0] = self.path_indices
        keys[:, 1] = 1
        area_streams = None
        if c.levy_area in ("davie", "foster") + LEVY_AREA_METHODS + ("auto",):
            area_streams = PathStreams(c.seed_sequence, keys)        # the coarse area normals, regenerated
        keys = keys.copy()
        keys[:, 1] = 2
        ref_streams = PathStreams(c.seed_sequence, keys)
        rp_kind = None if self.level == 1 else ("geometric" if self.kind == "stratonovich" else "ito")
        fine_t = self.times
        if F == 1:                                  # the coarse path itself
            yield from c.blocks(K)
            return
        kf = 0
        for k0, cb in zip(range(0, c.n_steps, kc), c.blocks(kc)):
            k = cb.n_steps
            h = c._h[k0:k0 + k]
            W = cb.increments.reshape(P, k, d)
            L = None if cb.areas is None else 0.5 * (cb.areas - np.swapaxes(cb.areas, -1, -2)).reshape(P, k, d, d)
            aw = np.array([self._area_width(float(x)) for x in h], dtype=np.int64)
            rw = np.array([self._refine_width(float(x)) for x in h], dtype=np.int64)
            za = np.empty((P, int(aw.sum())))
            if area_streams is not None and za.shape[1]:
                area_streams.fill(za)
            zr = np.empty((P, int(rw.sum())))
            ref_streams.fill(zr)
            ao, ro = np.concatenate([[0], np.cumsum(aw)]), np.concatenate([[0], np.cumsum(rw)])
            w = np.empty((P, k, F, d))
            A = None if L is None else np.empty((P, k, F, d, d))
            for hv in np.unique(h):
                idx = np.flatnonzero(h == hv)
                a_cols = ao[idx][:, None] + np.arange(aw[idx[0]])
                r_cols = ro[idx][:, None] + np.arange(rw[idx[0]])
                Wr = W[:, idx].reshape(-1, d)
                Lr = None if L is None else L[:, idx].reshape(-1, d, d)
                zar = za[:, a_cols].reshape(Wr.shape[0], -1)
                zrr = zr[:, r_cols].reshape(Wr.shape[0], -1)
                wr = np.empty((Wr.shape[0], F, d))
                Ar = None if L is None else np.empty((Wr.shape[0], F, d, d))
                for r0 in range(0, Wr.shape[0], _ROWS):
                    s = slice(r0, r0 + _ROWS)
                    wi, Ai = self._refine_rows(float(hv), Wr[s], None if Lr is None else Lr[s], zar[s], zrr[s])
                    wr[s] = wi
                    if Ar is not None:
                        Ar[s] = Ai
                w[:, idx] = wr.reshape(P, idx.size, F, d)
                if A is not None:
                    A[:, idx] = Ar.reshape(P, idx.size, F, d, d)
            w = w.reshape(P, k * F, d)
            if A is not None:
                A = A.reshape(P, k * F, d, d) + 0.5 * w[..., :, None] * w[..., None, :]
                if self.kind == "ito":
                    dh = np.repeat(h / F, F)
                    A[..., np.arange(d), np.arange(d)] -= 0.5 * dh[:, None]
            x = cb.x0.reshape(P, d).copy()
            for s0 in range(0, k * F, K):
                s1 = min(k * F, s0 + K)
                yield RoughPath(w[:, s0:s1].reshape(self.batch_shape + (s1 - s0, d)),
                                None if A is None else A[:, s0:s1].reshape(self.batch_shape + (s1 - s0, d, d)),
                                times=fine_t[kf + s0:kf + s1 + 1], x0=x.reshape(self.batch_shape + (d,)),
                                kind=rp_kind, check=False)
                x = x + w[:, s0:s1].sum(axis=1)
            kf += k * F
