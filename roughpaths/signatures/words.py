r"""Chosen coefficients of the signature, without the rest of it.

The coefficient of a word :math:`w = (i_1, \dots, i_k)` is :math:`\langle S(X)_{0,T}, e_{i_1} \otimes
\dots \otimes e_{i_k}\rangle = \int_{0<t_1<\dots<t_k<T} dX^{i_1}_{t_1} \cdots dX^{i_k}_{t_k}`, the entry
of :func:`roughpaths.signature` at the word's row-major position. The full signature has
``d + ... + d**k`` entries; a few words of a long word over many letters need only their own
prefixes: writing :math:`P_j` for the coefficient of the prefix :math:`(i_1, \dots, i_j)` of the path
up to the current point (:math:`P_0 = 1`), Chen's identity across a linear step with increment
:math:`\delta` gives

.. math:: P_j \leftarrow P_j + \sum_{l=0}^{j-1} P_l \, \frac{\delta^{i_{l+1}} \cdots \delta^{i_j}}{(j-l)!},

evaluated for ``j = k, ..., 1`` (so the right side uses the old values) in Horner form. This is the
first row of the product of the steps' ``(k+1) x (k+1)`` upper triangular matrices
:math:`M[l, j] = \langle \exp(\delta), e_{i_{l+1}} \cdots e_{i_j}\rangle` (the representation of the
tensor algebra on the word's prefixes). Cost: ``k (k + 1) / 2`` multiply-adds per step and word, so
``O(n Σ_w |w|²)`` for ``n`` points; memory ``O(|w|)`` per word.

When it pays: the full signature costs about ``d^k`` multiply-adds per step (vectorised), a word
``k (k + 1) / 2`` (scalar). For ``d = 3``, ``k = 4`` the full depth-4 signature of 10^6 points (120
entries) took 0.12-0.14 s and 10 words of length 4 0.6 s, so there one computes the signature and picks
its entries; for ``d = 10``, ``k = 6`` (10^6 entries a path) a handful of words is thousands of times
cheaper, and needs no memory for the rest of the signature.
"""

from __future__ import annotations

import numbers

import numpy as np
from numba import njit

from .. import _threads
from ..validation import as_float_array, check_memory, check_work

__all__ = ["signature_coefficients"]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _word_rows(x, letters, lengths, lo, hi, out):
    """``out[b, w]`` for the rows ``r = b * W + w`` in ``lo..hi-1``: the Horner recursion of the module.

    ``x`` (B, n, d) float64, ``letters`` (W, K) int64 (row ``w`` padded after ``lengths[w]``), ``out``
    (B, W). Scalar code, about 50 ns per step for a word of length 4 (measured on a loaded machine;
    advancing 8 words together to overlap their chains gained nothing measurable, so it does not).
    One kernel, one specialisation (float64 / int64 C arrays); compiling it took 1.4 s of CPU time (fresh
    cache, loaded machine), cached on
    disk afterwards.
    """
    n_words = letters.shape[0]
    n = x.shape[1]
    kmax = letters.shape[1]
    p = np.empty(kmax + 1)
    delta = np.empty(kmax + 1)
    inv = np.empty(kmax + 2)
    for m in range(1, kmax + 2):
        inv[m] = 1.0 / m
    for r in range(lo, hi):
        b = r // n_words
        w = r - b * n_words
        k = lengths[w]
        p[0] = 1.0
        for j in range(1, k + 1):
            p[j] = 0.0
        for s in range(n - 1):
            for j in range(1, k + 1):
                c = letters[w, j - 1]
                delta[j] = x[b, s + 1, c] - x[b, s, c]
            for j in range(k, 0, -1):
                acc = p[0]
                for m in range(1, j):
                    acc = p[m] + acc * delta[m] * inv[j - m + 1]
                p[j] += acc * delta[j]
        out[b, w] = p[k]


def _check_words(words, d: int) -> tuple:
    """``(letters (W, K) int64, lengths (W,) int64)`` of a list of words over ``0..d-1``."""
    if isinstance(words, (str, bytes)) or words is None:
        raise TypeError(f"words must be a list of words, each a sequence of letters 0..{d - 1}, got {words!r}; "
                        f"pass e.g. words=[(0,), (0, 1)].")
    try:
        rows = [list(w) for w in words]
    except TypeError:
        raise TypeError(f"words must be a list of words, each a sequence of letters 0..{d - 1}, got "
                        f"{type(words).__name__}; pass e.g. words=[(0,), (0, 1)] (a single word is [(0, 1)]).") from None
    if not rows:
        raise ValueError("words is empty; pass at least one word, e.g. words=[(0, 1)].")
    for i, w in enumerate(rows):
        if len(w) == 0:
            raise ValueError(f"words[{i}] is the empty word, whose coefficient is 1 for every path; leave it out.")
        for c in w:
            if isinstance(c, (bool, np.bool_)) or not isinstance(c, numbers.Integral):
                raise TypeError(f"words[{i}] = {tuple(w)!r} holds {c!r}, not an integer letter; letters are the "
                                f"0-based channels 0..{d - 1}.")
            if not 0 <= c < d:
                raise ValueError(f"words[{i}] = {tuple(w)!r} holds the letter {int(c)}, outside 0..{d - 1} (paths "
                                 f"have d = {d} channels; letters are 0-based).")
    lengths = np.array([len(w) for w in rows], dtype=np.int64)
    letters = np.zeros((len(rows), int(lengths.max())), dtype=np.int64)
    for i, w in enumerate(rows):
        letters[i, :len(w)] = [int(c) for c in w]
    return letters, lengths


def signature_coefficients(paths, words) -> np.ndarray:
    r"""The signature's coefficients of chosen words, each computed from its own prefixes only.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
        ``n >= 1`` points (linearly interpolated); leading axes are batch axes.
    words : sequence of sequences of int
        ``W`` non-empty words, letters ``0..d-1`` (0-based, as the positions of
        :func:`roughpaths.signature`; :func:`roughpaths.lyndon_basis` prints letters 1-based). Words may
        have different lengths.

    Returns
    -------
    ndarray, shape ``(..., W)``
        Entry ``w`` is :math:`\int_{t_1 < \dots < t_k} dX^{i_1}_{t_1} \cdots dX^{i_k}_{t_k}`, the entry of
        ``signature(paths, k)`` at the word's position (``iisignature.sig``'s). Cost ``O(n Σ_w |w|²)``,
        compiled, split over threads by path and word; the result does not depend on the number of threads.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])   # the L-shaped path
    >>> signature_coefficients(x, [(0,), (0, 1), (1, 0), (0, 0, 1)])
    array([1. , 1. , 0. , 0.5])
    """
    x = as_float_array(paths, "paths", min_ndim=2)
    batch, (n, d) = x.shape[:-2], x.shape[-2:]
    if n < 1 or d < 1:
        raise ValueError(f"paths must have shape (..., n, d) with n >= 1 and d >= 1, got shape {x.shape}.")
    letters, lengths = _check_words(words, d)
    n_paths = float(np.prod(batch, dtype=float))
    n_words = letters.shape[0]
    # the coefficients and their finiteness mask; a C-contiguous copy of paths that are not (a strided view); the
    # words' letters with three temporaries of their lengths, and 64 KiB for the call's own bookkeeping
    copy = 0.0 if x.flags.c_contiguous else 8.0 * float(x.size)
    what = f"the coefficients ({batch} paths x {n_words} words)" + (" and a copy of the paths" if copy else "")
    check_memory(n_paths * n_words * 9.0 + copy + 8.0 * letters.size + 32.0 * n_words + 65536.0, what,
                 "ask for fewer words or paths at a time" + (" (or pass C-contiguous paths)" if copy else ""))
    # a word of length k costs k (k + 1) / 2 multiply-adds a step (the Horner recursion), not k: counting
    # the total length let one long word (k = 10^4 on 10^5 points) pass as 10^9 units and run for hours
    steps_cost = float(np.sum(lengths * (lengths + 1) / 2.0))
    check_work(n_paths * float(n) * steps_cost,
               f"the coefficients of {n_words} words (total length {int(lengths.sum())}, {steps_cost:.3g} "
               f"multiply-adds a step) along {n} points", "ask for fewer or shorter words, or fewer points")
    flat = np.ascontiguousarray(x.reshape(-1, n, d))
    out = np.zeros((flat.shape[0], n_words))
    rows = flat.shape[0] * n_words
    if rows and n > 1:
        work = float(n) * float(np.mean(lengths * (lengths + 1) // 2 + lengths))
        _threads.run(lambda lo, hi: _word_rows(flat, letters, lengths, lo, hi, out), _threads.ranges(rows, work))
    if not np.all(np.isfinite(out)):
        raise ValueError("paths gives a non-finite coefficient: the iterated integrals overflow float64 (values "
                         f"up to {float(np.max(np.abs(flat))):.3g}); rescale the paths (the coefficient of a word "
                         "of length k scales as the k-th power).")
    return out.reshape(batch + (n_words,))
