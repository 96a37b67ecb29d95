r"""The quantile table of the exact d = 2 Lévy-area sampler (private to :mod:`roughpaths.drivers`).

For planar Brownian motion over a step of length ``h`` with increment ``w``, the scaled area
``a = A/h`` given ``w`` depends on one scalar, ``μ = |w|²/h``; its characteristic function is

.. math:: \varphi_\mu(\lambda) = \frac{x}{\sinh x}\exp\Bigl(-\frac{\mu}{2}(x\coth x - 1)\Bigr),
          \qquad x = \lambda/2

(Lévy 1951; ``docs/conventions.md`` area with the ½, so :math:`\mathrm{Var}(a\mid\mu) = (1 + \mu)/12`).
The sampler draws one standard normal ``z`` and returns ``a = g(√μ, |z|) sign(z)``, where
``g(s, ·)`` is the quantile function of ``a`` given ``μ = s²`` composed with the normal CDF,
``F_{s²}(g(s, z)) = Φ(z)``. The table holds ``g`` and ``∂g/∂z = φ_N(z)/f(g)`` on the grid
``s, z ∈ {0, 0.05, …, 7}``; the kernel interpolates by cubic Hermite in ``z`` (exact derivatives)
and 4-point Lagrange in ``s`` (``g`` is even in ``s``: the row ``s = -0.05`` is the row ``0.05``).

How the table is computed (:func:`build_table`): ``F_μ`` and its density by Gil-Pelaez inversion,
:math:`F(a) = \tfrac12 + \pi^{-1}\int_0^\infty \sin(\lambda a)\varphi_\mu(\lambda)\lambda^{-1}d\lambda`,
with the trapezoid rule at step 0.04 (exact up to aliasing from distance ``2π/0.04 ≈ 157``, where
the density is below 1e-300) truncated where ``|φ| < 1e-17``; checked against the logistic law at
``μ = 0`` to 3e-16. Newton's method then solves ``F(g) = Φ(z)`` to 1e-15 in ``F``.

Law error of the sampler, measured as the Kolmogorov distance between the sampled and the exact
conditional law, ``sup_z |F_μ(g̃(√μ, z)) − Φ(z)|`` (``g̃`` is increasing in ``z``, so this is exactly
that distance): at most 6·10⁻⁸ over the table (largest for ``μ < 0.3``, below 4·10⁻⁹ for
``μ > 4``; measured at the cell midpoints, ``tests/roughpaths/drivers/test_levy_area_table.py``).
Outside the table (``μ > 49``, probability ``e^{-24.5} ≈ 2·10⁻¹¹``, or ``|z| > 7``, probability
2.6·10⁻¹²) the kernel draws the area from the series sampler instead (law error below 5·10⁻⁷),
which adds at most 3·10⁻¹¹ to the distance. No statistical test with fewer than ~10¹⁴ samples can
tell the sampled law from the exact one.

The table ships with the package (``_data/levy_area_d2.npy``, 318 KB) and is checked against its
SHA-256 on load; :func:`build_table` regenerates it (~10 s).
"""

from __future__ import annotations

import hashlib
import os

import numpy as np

#: grid step and end of both table axes, ``s = √μ`` and ``z``
TABLE_STEP = 0.05
TABLE_MAX = 7.0
_N = int(round(TABLE_MAX / TABLE_STEP)) + 1
_PATH = os.path.join(os.path.dirname(__file__), "_data", "levy_area_d2.npy")
_SHA256 = "882fa2b1813f88f9ecfbcf09463f992e32bc037c0fa9eb24525615369ac7d233"
_D_LAMBDA = 0.04
_CACHE = []


def _lambda_grid(mu: float) -> np.ndarray:
    top = 80.0 / (1.0 + 0.5 * mu) + 10.0               # |φ_μ(λ)| < 1e-17 beyond
    return np.arange(1, int(top / _D_LAMBDA) + 1) * _D_LAMBDA


def conditional_cdf_pdf(a, mu: float):
    """``(F, f)``: CDF and density of ``a = A/h`` given ``μ = |w|²/h`` at the points ``a`` (Gil-Pelaez)."""
    a = np.asarray(a, dtype=np.float64)
    lam = _lambda_grid(mu)
    x = 0.5 * lam
    phi = x / np.sinh(x) * np.exp(-0.5 * mu * (x / np.tanh(x) - 1.0))
    arg = np.multiply.outer(a, lam)
    F = 0.5 + _D_LAMBDA / np.pi * (0.5 * a + (np.sin(arg) * (phi / lam)).sum(-1))
    f = _D_LAMBDA / np.pi * (0.5 + (np.cos(arg) * phi).sum(-1))
    return F, f


def _quantile_row(mu: float, z: np.ndarray):
    from scipy.special import ndtr

    p = ndtr(z)
    a = np.sqrt((1.0 + mu) / 12.0) * z                # the Gaussian guess
    for _ in range(60):
        F, f = conditional_cdf_pdf(a, mu)
        if np.abs(F - p).max() < 1e-15:
            break
        a = a - (F - p) / f
    F, f = conditional_cdf_pdf(a, mu)
    return a, np.exp(-0.5 * z * z) / np.sqrt(2.0 * np.pi) / f


def build_table(rows=None) -> np.ndarray:
    """The table ``(2, 141, 141)``: ``[0, i, j] = g(s_i, z_j)``, ``[1, i, j] = ∂g/∂z``; ``rows`` picks rows ``i``."""
    idx = range(_N) if rows is None else rows
    z = TABLE_STEP * np.arange(_N)
    out = np.empty((2, len(idx), _N))
    for r, i in enumerate(idx):
        s = TABLE_STEP * i
        out[0, r], out[1, r] = _quantile_row(s * s, z)
    return out


def load_table() -> np.ndarray:
    """The shipped table, checked against its SHA-256 (a damaged file is refused, not used)."""
    if not _CACHE:
        try:
            with open(_PATH, "rb") as fh:
                raw = fh.read()
        except OSError as exc:
            raise RuntimeError(f"the d = 2 Lévy-area table {_PATH} is missing ({exc}); reinstall the package "
                               f"or use levy_area='mrongowius-rossler'.") from None
        if hashlib.sha256(raw).hexdigest() != _SHA256:
            raise RuntimeError(f"the d = 2 Lévy-area table {_PATH} is damaged (SHA-256 mismatch); reinstall "
                               f"the package or use levy_area='mrongowius-rossler'.")
        with open(_PATH, "rb") as fh:
            table = np.load(fh, allow_pickle=False)
        if table.shape != (2, _N, _N) or table.dtype != np.float64:
            raise RuntimeError(f"the d = 2 Lévy-area table {_PATH} has shape {table.shape}; reinstall.")
        _CACHE.append(np.ascontiguousarray(table))
    return _CACHE[0]
