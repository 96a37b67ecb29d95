"""Lyndon words and the Lyndon basis of the free Lie algebra (private helpers).

Letters are ``0 .. d-1`` (``iisignature`` prints them 1-based). A Lyndon word ``w`` of length > 1
is bracketed by its *standard factorisation* ``w = u v`` with ``v`` the longest proper suffix
that is itself Lyndon: ``P(w) = [P(u), P(v)] = P(u)⊗P(v) - P(v)⊗P(u)``. This is the basis
``iisignature.basis`` lists, in the same order (by length, then lexicographically).

``P(w) = w + (words lexicographically larger than w)``, so the coefficients of the Lyndon words
in a Lie element ``L = sum_v c_v P(v)`` are a unit-triangular transform of the coordinates
``c``; :func:`lyndon_projection` inverts it exactly, giving the coordinates ``iisignature.logsig``
returns (default method). The transform is the identity for small depths (e.g. ``d = 2, m <= 4``)
but not in general (``d = 3, m = 3``: ``P(132) = 132 - 213 + 231 - 312`` contains the Lyndon word 132
only, while ``P(123)`` also contains ``132``).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["lyndon_words", "standard_factorisation", "bracket_string", "lyndon_expansion",
           "lyndon_projection"]


def _is_lyndon(w: tuple) -> bool:
    return all(w < w[i:] for i in range(1, len(w)))


@lru_cache(maxsize=None)
def lyndon_words(dim: int, depth: int) -> tuple:
    """Lyndon words over ``0..dim-1`` of length ``1..depth``, sorted by length then lexicographically.

    Duval's algorithm generates all Lyndon words of length ``<= depth`` in lexicographic order.
    """
    words = []
    w = [-1]
    while w:
        w[-1] += 1
        words.append(tuple(w))
        m = len(w)
        while len(w) < depth:
            w.append(w[len(w) - m])
        while w and w[-1] == dim - 1:
            w.pop()
    return tuple(sorted(words, key=lambda u: (len(u), u)))


def standard_factorisation(w: tuple) -> tuple:
    """``(u, v)`` with ``w = u v`` and ``v`` the longest proper Lyndon suffix of ``w``."""
    for i in range(1, len(w)):
        if _is_lyndon(w[i:]):
            return w[:i], w[i:]
    raise ValueError(f"{w!r} has no proper Lyndon suffix (it has length 1 or is not Lyndon).")


def bracket_string(w: tuple) -> str:
    """The bracketing of ``w`` in ``iisignature.basis`` notation (1-based letters, no spaces)."""
    if len(w) == 1:
        return str(w[0] + 1)
    u, v = standard_factorisation(w)
    return f"[{bracket_string(u)},{bracket_string(v)}]"


@lru_cache(maxsize=None)
def _expand(w: tuple, dim: int) -> np.ndarray:
    """Tensor expansion of ``P(w)`` at level ``len(w)``, flat row-major (``dim**len(w)``,)."""
    if len(w) == 1:
        e = np.zeros(dim)
        e[w[0]] = 1.0
        return e
    u, v = standard_factorisation(w)
    pu, pv = _expand(u, dim), _expand(v, dim)
    return np.multiply.outer(pu, pv).reshape(-1) - np.multiply.outer(pv, pu).reshape(-1)


def _word_index(w: tuple, dim: int) -> int:
    idx = 0
    for letter in w:
        idx = idx * dim + letter
    return idx


@lru_cache(maxsize=None)
def lyndon_expansion(dim: int, depth: int) -> tuple:
    """Per level ``k``: the matrix ``E_k`` (``n_k x dim**k``) whose rows are the ``P(w)``, ``|w| = k``."""
    words = lyndon_words(dim, depth)
    out = []
    for k in range(1, depth + 1):
        wk = [w for w in words if len(w) == k]
        out.append(np.array([_expand(w, dim) for w in wk]).reshape(len(wk), dim ** k))
    return tuple(out)


@lru_cache(maxsize=None)
def lyndon_projection(dim: int, depth: int) -> tuple:
    """Per level ``k``: ``(idx_k, T_k)`` with Lyndon coordinates ``c_k = L_k[..., idx_k] @ T_k``.

    ``idx_k`` are the flat positions of the Lyndon words of length ``k`` and ``T_k`` the
    transpose of the inverse of the unit-triangular matrix ``M[i, j] = <w_i, P(w_j)>``.
    """
    words = lyndon_words(dim, depth)
    exp = lyndon_expansion(dim, depth)
    out = []
    for k in range(1, depth + 1):
        wk = [w for w in words if len(w) == k]
        idx = np.array([_word_index(w, dim) for w in wk], dtype=np.intp)
        m = exp[k - 1][:, idx].T                      # M[i, j] = coefficient of w_i in P(w_j)
        t = np.linalg.solve(m, np.eye(len(wk))).T    # (M^{-1})^T, so c = L[idx] @ T
        t[np.abs(t) < 1e-14] = 0.0                   # integer matrix: clean round-off
        out.append((idx, np.round(t)))
    return tuple(out)
