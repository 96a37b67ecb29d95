r"""A two-sample test for laws of paths: the unbiased MMD² of the signature kernel with a permutation p-value.

Given samples ``X`` (``a`` paths) and ``Y`` (``b`` paths), the statistic is the unbiased estimator

.. math::

    \widehat{\mathrm{MMD}}{}^2_u = \frac{1}{a(a-1)}\sum_{i\ne j} k(x_i, x_j)
        + \frac{1}{b(b-1)}\sum_{i\ne j} k(y_i, y_j) - \frac{2}{ab}\sum_{i,j} k(x_i, y_j)

of the squared maximum mean discrepancy of the signature kernel ``k`` (zero iff the expected signatures
agree, for a characteristic static kernel or laws determined by their signature moments). Under the null
hypothesis (same law) the pooled sample is exchangeable, so the statistic of a random relabelling of the
pooled sample has the null distribution: the p-value ``(1 + #{perm >= observed}) / (1 + n_permutations)``
is valid (``P(p <= α) <= α``) at every sample size. The Gram matrix of the pooled sample is computed once
(its three blocks, each symmetric block's upper triangle only); permutations only relabel it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

from ..validation import check_memory, check_positive_int, check_seed, check_work
from .kernel import _pairs_kernel, _scaled, _setup

__all__ = ["MMDTestResult", "sig_mmd_test"]


@dataclass(frozen=True)
class MMDTestResult:
    """The result of :func:`sig_mmd_test`.

    Attributes
    ----------
    statistic : float
        The unbiased MMD² estimate (may be slightly negative under the null).
    p_value : float
        ``(1 + #{permuted statistic >= statistic}) / (1 + n_permutations)``.
    n_permutations : int
        Number of random relabellings of the pooled sample.
    null_statistics : ndarray, shape ``(n_permutations,)``
        The statistics of the relabelled samples.

    The repr is short: the statistic, the p-value, the number of permutations and a summary of the null
    (mean, standard deviation, 95 % quantile, maximum); the values themselves are in ``null_statistics``.

    Examples
    --------
    >>> import numpy as np
    >>> MMDTestResult(statistic=0.25, p_value=0.2, n_permutations=4,
    ...               null_statistics=np.array([-0.5, 0.0, 0.5, 1.0]))
    MMDTestResult(statistic=0.25, p_value=0.2, n_permutations=4, null_statistics=<4 values: mean 0.25, sd 0.559017, q95 0.925, max 1>)
    """

    statistic: float
    p_value: float
    n_permutations: int
    null_statistics: np.ndarray

    def __repr__(self) -> str:
        null = np.asarray(self.null_statistics, dtype=np.float64).ravel()
        if null.size == 0:
            summary = "<0 values>"
        else:
            summary = (f"<{null.size} values: mean {null.mean():.6g}, sd {null.std():.6g}, "
                       f"q95 {np.quantile(null, 0.95):.6g}, max {null.max():.6g}>")
        return (f"{type(self).__name__}(statistic={self.statistic:.6g}, p_value={self.p_value:.6g}, "
                f"n_permutations={self.n_permutations}, null_statistics={summary})")


@nb.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _mmd_stats(K, labels, a, b):
    """Unbiased MMD² for each labelling (``labels[r, i] = 1``: pooled path ``i`` in the first sample).

    Sums run over the pooled indices in their fixed order, so a labelling's statistic depends on the
    labelling only (equal partitions give bitwise equal statistics: ties are counted exactly).
    """
    n = K.shape[0]
    out = np.empty(labels.shape[0])
    for r in range(labels.shape[0]):
        sxx = 0.0
        syy = 0.0
        sxy = 0.0
        for i in range(n):
            li = labels[r, i]
            for j in range(i + 1, n):
                lj = labels[r, j]
                if li == 1 and lj == 1:
                    sxx += K[i, j]
                elif li == 0 and lj == 0:
                    syy += K[i, j]
                else:
                    sxy += K[i, j]
        out[r] = 2.0 * sxx / (a * (a - 1.0)) + 2.0 * syy / (b * (b - 1.0)) - 2.0 * sxy / (a * b)
    return out


def _pooled_gram(X: np.ndarray, Y: np.ndarray, rbf: bool, order: int) -> np.ndarray:
    """Pooled Gram matrix (off-diagonal entries; the diagonal is never read) of scaled samples."""
    a, b = X.shape[0], Y.shape[0]
    K = np.zeros((a + b, a + b))
    for Z, off in ((X, 0), (Y, a)):
        i, j = np.triu_indices(Z.shape[0], 1)
        k = _pairs_kernel(Z, Z, i.astype(np.int64), j.astype(np.int64), rbf, order)
        K[off + i, off + j] = k
        K[off + j, off + i] = k
    i = np.repeat(np.arange(a, dtype=np.int64), b)
    j = np.tile(np.arange(b, dtype=np.int64), a)
    k = _pairs_kernel(X, Y, i, j, rbf, order)
    K[i, a + j] = k
    K[a + j, i] = k
    return K


#: Relabellings drawn and evaluated per block: the labels take ``_PERM_BLOCK * (a + b)`` bytes (twice,
#: while a block is permuted) whatever ``n_permutations`` is.
_PERM_BLOCK = 4096


def _memory_estimate(a: int, b: int, n_permutations: int) -> float:
    """Bytes :func:`sig_mmd_test` holds at its peak for samples of ``a`` and ``b`` paths (the estimate it checks).

    The pooled Gram matrix ``8 (a + b)²``; while its largest block of ``P = max(ab, a(a-1)/2, b(b-1)/2)``
    pairs is computed, about ``10`` arrays of ``P`` 8-byte entries (the pair indices, their padded copies,
    the kernels and the scatter's index temporaries); the null statistics ``8 (n_permutations + 1)``; and
    one block of labels (``2 * min(n_permutations, 4096) * (a + b)`` bytes).
    """
    pairs = max(float(a) * b, float(a) * (a - 1) / 2, float(b) * (b - 1) / 2)
    block = min(float(n_permutations), float(_PERM_BLOCK)) + 1.0
    return 8.0 * (a + b) ** 2 + 80.0 * pairs + 8.0 * (n_permutations + 1.0) + 2.0 * block * (a + b)


def sig_mmd_test(X, Y, *, seed, n_permutations: int = 1000, dyadic_order: int = 0,
                 static_kernel=None) -> MMDTestResult:
    r"""Permutation two-sample test of "``X`` and ``Y`` are drawn from the same law of paths".

    Parameters
    ----------
    X : array_like, shape ``(a, n, d)``
        First sample: ``a >= 2`` paths of ``n`` points.
    Y : array_like, shape ``(b, m, d)``
        Second sample: ``b >= 2`` paths of ``m`` points in the same ``R^d`` (``m`` may differ from ``n``).
    seed : int or numpy.random.SeedSequence
        Seed of the ``numpy.random.Generator`` that draws the permutations (the result is a function of
        the data and the seed).
    n_permutations : int
        Number of random relabellings (default 1000; the smallest attainable p-value is
        ``1 / (1 + n_permutations)``).
    dyadic_order, static_kernel
        As for :func:`~roughpaths.signature_kernel`.

    Returns
    -------
    MMDTestResult
        ``statistic`` (unbiased MMD²), ``p_value``, ``n_permutations``, ``null_statistics``.

    Notes
    -----
    The signature kernel of the raw paths compares their expected signatures; paths that start at
    the same point and whose laws differ only in how the variance is spread in time (Brownian motion
    against fBM on ``[0, 1]``) are told apart much better after adding time as a coordinate
    (``np.concatenate([paths, t[:, None] * ones], axis=-1)``) or with an :class:`~roughpaths.RBFKernel`.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(size=(20, 9, 2)).cumsum(axis=1) * 0.3
    >>> Y = rng.normal(size=(20, 9, 2)).cumsum(axis=1) * 0.3 + np.linspace(0, 1, 9)[:, None]   # a drift
    >>> sig_mmd_test(X, Y, seed=1, n_permutations=199).p_value < 0.05
    True
    """
    X, Y, order, rbf, factor = _setup(X, Y, dyadic_order, static_kernel, ("X", "Y"), 3)
    for Z, name in ((X, "X"), (Y, "Y")):
        if Z.ndim != 3:
            raise ValueError(f"{name} must have shape (samples, points, d), got shape {Z.shape}; the test "
                             f"compares two samples of paths (stack them along the first axis).")
        if Z.shape[0] < 2:
            raise ValueError(f"{name} holds {Z.shape[0]} path(s); the unbiased MMD² needs at least 2 paths "
                             f"in each sample.")
    n_perm = check_positive_int(n_permutations, "n_permutations")
    rng = np.random.default_rng(check_seed(seed))        # an int >= 0 or a SeedSequence, named if not
    a, b = X.shape[0], Y.shape[0]
    check_memory(_memory_estimate(a, b, n_perm), f"the permutation test of {a} against {b} paths with "
                 f"n_permutations={n_perm} (the pooled Gram matrix of {a + b} x {a + b} kernels and "
                 f"{n_perm + 1} statistics)", "use fewer permutations or smaller samples")
    check_work(float(n_perm + 1) * (a + b) * (a + b - 1) / 2, f"the permutation test: {n_perm} relabelling(s) of "
               f"{a + b} pooled paths, each summing the {(a + b) * (a + b - 1) // 2} pairs of the Gram matrix",
               "use fewer permutations (n_permutations=999 resolves p-values down to 0.001) or smaller samples")
    K = _pooled_gram(_scaled(X, 2, factor), _scaled(Y, 2, factor), rbf, order)
    stats = np.empty(n_perm + 1)
    first = np.zeros((1, a + b), dtype=np.int8)
    first[0, :a] = 1
    stats[:1] = _mmd_stats(K, first, float(a), float(b))
    for lo in range(1, n_perm + 1, _PERM_BLOCK):          # one stream: the same draws whatever the block
        labels = np.zeros((min(_PERM_BLOCK, n_perm + 1 - lo), a + b), dtype=np.int8)
        labels[:, :a] = 1
        labels = rng.permuted(labels, axis=1)
        stats[lo:lo + labels.shape[0]] = _mmd_stats(K, labels, float(a), float(b))
    if not np.all(np.isfinite(stats)):
        top = float(np.max(np.abs(K)))
        raise ValueError(f"the MMD statistics overflow float64: the kernels reach {top:.3g} and their sums over "
                         f"the {(a + b) * (a + b - 1) // 2} pairs leave float64; scale the paths down (e.g. "
                         f"static_kernel=LinearKernel(scale=0.5), or normalise the paths) so that the kernels stay "
                         f"far below 1e300.")
    observed, null = float(stats[0]), stats[1:]
    p = (1.0 + np.count_nonzero(null >= observed)) / (1.0 + n_perm)
    return MMDTestResult(statistic=observed, p_value=float(p), n_permutations=n_perm, null_statistics=null)
