r"""The mathematics of refinement (private; see :mod:`roughpaths.drivers.refinement`).

:meth:`roughpaths.BrownianDriver.refine` and :func:`roughpaths.refine` share it.

Per coarse step length: a plan of constants (:class:`_FourierPlan`, :class:`_BridgePlan`); per batch of
coarse steps (rows), deterministic functions of the coarse data and a row block of standard normals
(consumed left to right, a fixed number per step): :func:`_refine_fourier`, :func:`_refine_bridge`.
Antisymmetric matrices are the Lévy areas (with the ½); ``u ∧ v = u vᵀ - v uᵀ``.
"""

from __future__ import annotations

import math

import numpy as np

from ..algebra.level2 import outer
from ..paths.rough_path import RoughPath
from ..validation import memory_budget
from .levy_area import _tail_zeta2, step_plan

#: Gibbs sweeps that condition the explicit tail terms on the coarse area (and the fine areas on Chen's
#: identity). The chain starts from the prior, so a finite number of sweeps leaves a bias: with 3 the fine
#: increments of ``"exact"`` refined by 3 had variances [1.0033, 0.9956, 1.0026] δ (χ² p ≈ 4e-8 on 10⁶
#: steps); with 1 sweep ±2.4 %. The bias shrinks by about 2.5 per sweep; 6 and 8 sweeps are within
#: sampling error at 10⁶ steps (χ² p = 0.7, 0.15). 8 leaves a margin.
GIBBS_SWEEPS = 8
#: Explicit Fourier terms beyond the retained ones, per fine sub-step (``K = n + MODES_PER_SUBSTEP F``).
MODES_PER_SUBSTEP = 4


# ------------------------------------------------------------------ antisymmetric (pair) algebra
def _wedge(u, v):
    """``u ∧ v = u vᵀ - v uᵀ``, batched over leading axes."""
    return outer(u, v) - outer(v, u)


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


def _psd_sqrt(lam, V):
    """``V diag(√λ)`` with round-off eigenvalues (below 1e-12 of the largest) set to zero: the directions a
    conditioning fixes exactly (e.g. sums of fine increments) get no noise."""
    top = float(lam.max()) if lam.size else 0.0
    return V * np.sqrt(np.where(lam > 1e-12 * top, lam, 0.0))


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
        self.rem_sqrt = _psd_sqrt(lam, V)
        self.fine = fine                                                # (method, n, width) at δ = h/F
        M = K - n
        p = d * (d - 1) // 2
        self.M = M
        # "fourier" dropped the tail's own area: the refinement draws it (the coarse area is then not Chen's sum)
        self.draws_tail_area = method == "fourier"
        self.width = (p if self.draws_tail_area else 0) + (M * d) + GIBBS_SWEEPS * (2 * M * d + d + 2 * p) + (F - 1) * d + _fine_width(F, d, fine[1])


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
        self.sqrt = _psd_sqrt(lam, V)
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
    if plan.draws_tail_area:
        G = zc.antisym((), d) * (h * math.sqrt(_tail_zeta2(n) / (2 * math.pi ** 2)))
        A_tail, A = A_tail + G, A + G
    beta = zc.take((M, d))
    alpha = S_K = None
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
        else:
            alpha, S_K = _alpha_block_with_s(plan, W, u, N, a0, sk0, area0, A_tail, S, sig)
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


def _alpha_block_with_s(plan, W, u, N, a0, sk0, area0, A_tail, S, sig):
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
    return alpha, S_K


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
    (:math:`S_l = \sum_k\sigma_k\alpha_{lk} + S'_l`, the tail sum, and :math:`R_l` the Gaussian tail area). Their sum must be ``D = A - polygon(w)``; the constraint is linear in
    :math:`(\alpha, S', R)` given :math:`\beta` and in :math:`(\beta, R)` given :math:`\alpha`: Gibbs
    sweeps of exact Gaussian updates, so the areas keep their bilinear (non-Gaussian) structure.
    """
    R, F, d = w.shape
    nf = fine[1]
    if d == 1:
        return np.zeros((R, F, 1, 1))
    k = np.arange(1, nf + 1, dtype=float)
    sig = (math.sqrt(delta / 2.0) / (math.pi * k))[:, None]
    gam = (delta / (2.0 * math.pi * k))[:, None]
    s_n = _tail_zeta2(nf)
    vS = delta * s_n / (2 * math.pi ** 2)
    vR = delta * delta * s_n / (2 * math.pi ** 2)
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


# ------------------------------------------------------------------ refine(X, factor, rng): a given sample
def _antisym_normal(rng: np.random.Generator, rows: int, d: int) -> np.ndarray:
    """Antisymmetric ``(rows, d, d)`` with iid N(0, 1) entries above the diagonal, drawn from ``rng``."""
    return _Normals(rng.standard_normal((rows, d * (d - 1) // 2))).antisym((), d)


def _split(rng, W, L, h, rho, with_area: bool):
    r"""Split steps ``(W, L)`` of length ``h`` into a first part of length ``rho h`` and the rest.

    ``W (R, d)``, ``L (R, d, d)`` (Lévy areas) or None, ``h (R,)``. Returns
    ``(w1, L1, w2, L2)`` with ``w1 + w2 = W`` and ``L1 + L2 + ½ (w1 ∧ w2 ... ) = L`` exactly
    (the cross term of the split is ``Alt(w1 ⊗ w2) = ½ b ∧ W`` with ``b = w1 - rho W``).
    """
    R, d = W.shape
    q = rho * (1.0 - rho)
    hc = h[:, None]
    b = rng.standard_normal((R, d)) * np.sqrt(q * hc)
    if not with_area:
        return rho * W + b, None, (1.0 - rho) * W - b, None
    h1, h2 = rho * h, (1.0 - rho) * h
    # prior: Davie-type pieces built on the prior increments (exact conditional second moments)
    w1, w2 = rho * W + b, (1.0 - rho) * W - b
    H1 = rng.standard_normal((R, d)) * np.sqrt(h1 / 12.0)[:, None]
    H2 = rng.standard_normal((R, d)) * np.sqrt(h2 / 12.0)[:, None]
    L1 = _wedge(H1, w1) + _antisym_normal(rng, R, d) * (h1 / np.sqrt(12.0))[:, None, None]
    L2 = _wedge(H2, w2) + _antisym_normal(rng, R, d) * (h2 / np.sqrt(12.0))[:, None, None]
    # Matheron update: Y <- Y + Cov(Y, Z | W) Var(Z | W)^{-1} (L - Z(Y)), Z(Y) = L1 + L2 + ½ b∧W
    r = L - (L1 + L2 + 0.5 * _wedge(b, W))
    hh = h[:, None, None]
    u = np.einsum("...ij,...j->...i", r, W)
    norm2 = np.einsum("...i,...i->...", W, W)[:, None, None]
    v = (12.0 / hh ** 2) * (r - _wedge(u, W) / (hh + norm2))       # Var(Z|W)^{-1} r
    vW = np.einsum("...ij,...j->...i", v, W)
    T = _wedge(vW, W)                                                # v N + N v, N = W Wᵀ
    b = b + 0.5 * q * hc * vW
    L1 = L1 + (h1[:, None, None] ** 2 / 12.0) * v + (h1[:, None, None] / 12.0) * (rho ** 2 * T + 2 * q * hh * v)
    L2 = L2 + (h2[:, None, None] ** 2 / 12.0) * v + (h2[:, None, None] / 12.0) * ((1 - rho) ** 2 * T + 2 * q * hh * v)
    return rho * W + b, L1, (1.0 - rho) * W - b, L2


def _assemble(dw, A, fine_t, X, d):
    areas = A + 0.5 * outer(dw, dw)
    if X.kind == "ito":
        fine_h = np.diff(fine_t)
        areas[..., np.arange(d), np.arange(d)] -= 0.5 * fine_h[:, None]
    return RoughPath(dw, areas, times=fine_t, x0=X.x0, kind=X.kind, check=False)


def _refine_by_fourier_path(W, L, h, m, rng):
    """``factor > 2``: the construction of ``roughpaths.drivers.refinement`` with no stored Fourier terms.

    Rows ``W (R, d)``, Lévy areas ``L (R, d, d)``, step lengths ``h (R,)``; returns ``(R, m, d)`` increments
    and ``(R, m, d, d)`` Lévy areas. The normals are drawn from ``rng`` per distinct step length, in row order.
    """
    R, d = W.shape
    w = np.empty((R, m, d))
    A = np.empty((R, m, d, d))
    for hv in np.unique(h):
        idx = np.flatnonzero(h == hv)
        delta = float(hv) / m
        fine = step_plan("auto", d, [delta])[delta] if d > 1 else ("fourier", 1, 0)
        plan = _FourierPlan(float(hv), m, d, "exact", 0, False, fine)
        z = rng.standard_normal((idx.size, plan.width))
        w[idx], A[idx] = _refine_fourier(plan, W[idx], L[idx], None, None, None, z)
    return w, A


# ------------------------------------------------------------------ what a refinement holds
def refine_bytes(X: RoughPath, m: int) -> float:
    """Bytes :func:`~roughpaths.drivers.refinement.refine` holds at its peak, for ``R`` rows (paths x steps) of dimension ``d``, 8 bytes each.

    Splits (``factor <= 2`` or level 1): the pieces and their stack (``2 m R (d + d²)``), the assembly with
    ``½ w⊗w`` (three ``R m d²``), the Lévy areas (``R d²``) and one split's temporaries (twelve ``(R, d, d)``
    and eight ``(R, d)``); at level 1 ``2 m R d + 8 R d``. The Fourier path (``factor > 2`` at level 2), per
    step length with ``R_h`` rows and its plan (``width`` normals per row, ``M`` coarse and ``n_f`` fine
    explicit modes): the normals ``R_h width`` of two step lengths at once (one is released when the next is
    drawn), six coarse-mode arrays ``(R_h, M, d)`` and six fine-mode arrays ``(R_h, m, n_f, d)`` of a Gibbs
    sweep, eight ``(R_h, m, d, d)`` area arrays; plus the Lévy areas ``R d²``, the output ``R m (d + d²)``
    and the assembly's two ``R m d²`` temporaries; and the plans themselves, about ``8 (3 K (m - 1) + 8 (m - 1)²)``
    bytes each with ``K = 4 m`` modes, sized before any is built.
    """
    inc = X.increments
    d = inc.shape[-1]
    R = float(inc.size // d) if d else 0.0
    if X.level != 2:
        return 8.0 * (2.0 * m * R * d + 8.0 * R * d) + 4096.0
    if m <= 2 or R == 0:
        return 8.0 * (2.0 * m * R * (d + d * d) + 3.0 * R * m * d * d + 13.0 * R * d * d + 8.0 * R * d) + 4096.0
    h, counts = np.unique(np.broadcast_to(X.dt, inc.shape[:-1]).reshape(-1), return_counts=True)
    # A plan of m sub-steps holds K = MODES_PER_SUBSTEP m modes: three (K, m - 1) arrays and about eight
    # (m - 1, m - 1) ones while it is built. Where that (with the output) cannot fit, the estimate stops here,
    # before any plan is built (building one to size it allocated 30 GiB for factor=10**9).
    K = float(MODES_PER_SUBSTEP) * m
    plan_bytes = 8.0 * (3.0 * K * (m - 1) + 8.0 * (m - 1.0) ** 2) * len(h)
    floor = 8.0 * R * m * (d + 3.0 * d * d) + plan_bytes + 4096.0
    if not floor <= memory_budget():
        return floor
    normals, work = [0.0, 0.0], 0.0
    for hv, Rh in zip(h, counts.astype(float)):
        delta = float(hv) / m
        fine = step_plan("auto", d, [delta])[delta] if d > 1 else ("fourier", 1, 0)
        plan = _FourierPlan(float(hv), m, d, "exact", 0, False, fine)
        normals = sorted(normals + [Rh * plan.width])[-2:]
        work = max(work, Rh * (6.0 * plan.M * d + 6.0 * m * fine[1] * d + 8.0 * m * d * d))
    return 8.0 * (sum(normals) + work + R * d * d + R * m * (d + 3.0 * d * d)) + plan_bytes + 4096.0
