r"""The checks and derived data of :class:`~mechanics.systems.lie_algebra.LieAlgebra` given by structure constants.

Antisymmetry, the Jacobi identity (randomised, ``O(n⁴)`` flops and ``O(n²)`` memory), the Killing form, the
quadratic Casimir from it, and the memory the constructor checks before any of them.
"""

from __future__ import annotations

import numpy as np


class _KillingCasimir:
    r"""The quadratic Casimir :math:`\mu^T K^{-1}\mu` as a picklable callable (a lambda made every semisimple
    algebra from constants, sl(2, R) included, unpicklable: refused by checkpoints and process executors)."""

    def __init__(self, kinv):
        self.kinv = kinv

    def __call__(self, mu):
        return np.einsum("...i,ij,...j->...", mu, self.kinv, mu)[..., None]


def _constructor_bytes(n: int) -> float:
    """Bytes :class:`LieAlgebra` holds at its peak for dimension ``n`` (the estimate it checks).

    The structure constants ``8 n³`` (the float64 copy the algebra keeps and freezes), one ``n³``
    temporary at a time (the antisymmetry check; the transposed copy the Killing form's product reads),
    and ``O(n²)`` for the Jacobi check (at most four arrays of ``16 n²`` floats, a block of
    :func:`_jacobi_defect`) and the Killing form: ``8 (2 n³ + 72 n²)`` bytes.
    """
    return 8.0 * (2.0 * float(n) ** 3 + 72.0 * float(n) ** 2)


def _antisymmetry_defect(c: np.ndarray) -> float:
    """``max |c[i, j, k] + c[j, i, k]|`` with one ``n³`` temporary."""
    t = c + np.swapaxes(c, 0, 1)
    return float(np.max(np.abs(t, out=t)))


def _killing(c: np.ndarray) -> np.ndarray:
    """Killing form ``K[i, j] = c[i, m, n] c[j, n, m]``: one matrix product (``einsum``'s loop: 1.2 s at n = 120)."""
    n = c.shape[0]
    return c.reshape(n, n * n) @ np.ascontiguousarray(np.swapaxes(c, 1, 2)).reshape(n, n * n).T


#: Random vectors ``z`` of the Jacobi check, drawn from a fixed seed (the check is deterministic).
_JACOBI_DRAWS = 2
_JACOBI_SEED = 0x1AC0B1
#: Rows ``i`` checked together: three matrix products per block of 16 (row by row, ``c`` was read once per
#: row, 0.55 s at ``n = 120``, and ``3 n`` small products each paid the BLAS threads' start-up).
_JACOBI_BLOCK = 16


def _jacobi_defect(c: np.ndarray) -> float:
    r"""Largest entry of the Jacobiator :math:`J(e_i, e_j, z)` over all basis pairs ``(i, j)``, for random ``z``.

    The Jacobi identity says that every :math:`\mathrm{ad}_x` is a derivation:
    :math:`J(x, y, z) = [x, [y, z]] - [y, [x, z]] - [[x, y], z] = 0`. ``J`` is trilinear, so it vanishes iff
    the ``n²`` vectors :math:`R_{ij} = J(e_i, e_j, z)`, linear in ``z``, vanish for every ``z``. With
    ``V[j] = [e_j, z]`` (``O(n³)``), for each ``i`` (antisymmetry ``c[j, l, m] = -c[l, j, m]`` checked first):

    ``R_i = V @ c[i] + (V[i] @ c.reshape(n, n²)).reshape(n, n) - c[i] @ V``,

    three ``n × n``-sized products: ``O(n⁴)`` flops per ``z`` and ``O(n²)`` extra memory, against ``O(n⁵)``
    flops and ``n⁴`` floats for the full tensor :math:`J_{ijk}{}^m` (4.7 GB and 88 s at ``n = 120``, measured).
    Each entry :math:`R_{ij}{}^m = \sum_k J_{ijk}{}^m z_k` is, for standard normal ``z``, a centred normal of
    standard deviation :math:`\|J_{ij\cdot}{}^m\|_2 \ge \max_k |J_{ijk}{}^m|`. So a violation is seen with
    probability one in exact arithmetic, and one whose largest entry is ``D`` stays below a threshold ``τ``
    in one draw with probability at most :math:`\sqrt{2/\pi}\,τ/D`, in all ``_JACOBI_DRAWS = 2`` independent
    draws at most :math:`(2/\pi)(τ/D)^2` (``D = 10 τ``: 0.64 %; ``D = 100 τ``: 6.4e-5), the check's
    false-negative probability. The seed is fixed: the verdict on given constants is reproducible.
    """
    n = c.shape[0]
    flat = c.reshape(n, n * n)
    rng = np.random.default_rng(_JACOBI_SEED)
    worst = 0.0
    for _ in range(_JACOBI_DRAWS):
        z = rng.standard_normal(n)
        V = np.einsum("jkm,k->jm", c, z)                 # V[j] = [e_j, z]
        for lo in range(0, n, _JACOBI_BLOCK):           # a block of b rows i: three (n x n x bn) products
            cb = c[lo:lo + _JACOBI_BLOCK]
            b = cb.shape[0]
            R = (V[lo:lo + b] @ flat).reshape(b, n, n)                    # -[e_j, [e_i, z]]
            cbt = np.ascontiguousarray(cb.transpose(1, 0, 2)).reshape(n, b * n)
            R += (V @ cbt).reshape(n, b, n).transpose(1, 0, 2)           # [e_i, [e_j, z]]
            R -= (cb.reshape(b * n, n) @ V).reshape(b, n, n)             # [[e_i, e_j], z]
            worst = max(worst, float(np.max(np.abs(R, out=R))))
    return worst
