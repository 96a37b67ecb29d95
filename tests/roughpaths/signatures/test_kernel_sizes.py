"""Claim: the signature-kernel calls and the MMD test check their sizes before any work, with the estimate in
the message; the permutations are drawn in blocks of bounded memory without changing a single draw.

Oracles: the memory budget set through ``ROUGHPATHS_MAX_BYTES``; the null statistics recomputed here from
all relabellings drawn at once (``Generator.permuted`` of the whole label matrix, as a direct implementation
would) and a naive Gram matrix of plain loops.
"""

import time

import numpy as np
import pytest

import roughpaths as rp
from _oracles import naive_signature_kernel


def test_a_trillion_permutations_are_refused_at_once_with_the_estimate():
    X = np.random.default_rng(0).normal(size=(6, 5, 2)).cumsum(axis=1)
    t = time.perf_counter()
    with pytest.raises(ValueError, match=r"n_permutations=1000000000000.* would take 7\.\d+ TiB"):
        rp.sig_mmd_test(X[:3], X[3:], seed=0, n_permutations=10 ** 12)
    assert time.perf_counter() - t < 5.0                     # refused before any kernel or permutation


def test_the_gram_matrix_is_checked_against_the_budget(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(50 * 2 ** 20))
    X = np.zeros((1500, 2, 1))            # (3000 x 3000) Gram matrix: 69 MiB, plus the pair buffers
    with pytest.raises(ValueError, match=r"permutation test of 1500 against 1500 paths.* would take \d+ MiB"):
        rp.sig_mmd_test(X, X, seed=0, n_permutations=9)


def test_permutation_blocks_draw_exactly_the_relabellings_of_one_matrix():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(3, 4, 2)).cumsum(axis=1) * 0.5
    Y = rng.normal(size=(2, 5, 2)).cumsum(axis=1) * 0.5 + 0.2
    n_perm = 5000                          # more than one block of 4096
    res = rp.sig_mmd_test(X, Y, seed=11, n_permutations=n_perm)
    Z = list(X) + list(Y)
    K = np.array([[naive_signature_kernel(u, v, 0) for v in Z] for u in Z])
    labels = np.zeros((n_perm, 5), dtype=np.int8)
    labels[:, :3] = 1
    labels = np.random.default_rng(11).permuted(labels, axis=1)
    off = ~np.eye(5, dtype=bool)
    for r in (0, 1, 4095, 4096, 4097, n_perm - 1):
        inx = labels[r].astype(bool)
        xx = K[np.ix_(inx, inx)][off[np.ix_(inx, inx)]].sum() / 6
        yy = K[np.ix_(~inx, ~inx)][off[np.ix_(~inx, ~inx)]].sum() / 2
        want = xx + yy - 2 * K[np.ix_(inx, ~inx)].sum() / 6
        assert res.null_statistics[r] == pytest.approx(want, rel=1e-12, abs=1e-14), r


def test_kernel_work_is_refused_before_it_starts(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", "1e6")
    x = np.zeros((4, 100, 2))
    with pytest.raises(ValueError, match="signature kernel of 4 pair"):
        rp.signature_kernel(x, x, dyadic_order=3)


@pytest.mark.parametrize("call", [
    lambda X: rp.signature_kernel_gram(X, X),
    lambda X: rp.signature_kernel(X[:, None], X[None]),                   # the same pairs by broadcasting
    lambda X: rp.signature_kernel_gram_vjp(X, X, np.ones((X.shape[0], X.shape[0]))),
])
def test_many_pairs_of_short_paths_are_checked_before_their_indices_are_built(monkeypatch, call):
    # 2000 x 2000 pairs of 2-point paths: little PDE work, but every pair holds two indices, their padded
    # copies and its kernel (~40 bytes, 160 MB here); only the PDE rows were counted (25 KB), so a Gram matrix
    # of 10^5 short paths (10^10 pairs) went on to allocate its index arrays, hundreds of GB
    X = np.random.default_rng(0).normal(size=(2000, 2, 1)) * 0.1
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(100 * 2 ** 20))
    with pytest.raises(ValueError, match=r"4000000 pair\(s\).* would take \d+ MiB.*split the batch"):
        call(X)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(2 ** 30))
    assert call(X[:50])[0].shape[0] == 50
