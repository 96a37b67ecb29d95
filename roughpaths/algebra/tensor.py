r"""The truncated tensor algebra :math:`T^{(m)}(\mathbb{R}^d)`, batched, in ``iisignature``'s flat layout.

Layout
------
An element :math:`c_0 + c_1 + \dots + c_m` (:math:`c_k \in (\mathbb{R}^d)^{\otimes k}`) is stored as
a flat float64 vector of length :func:`sigdim` ``= d + d**2 + ... + d**m``: the levels
``1..m`` concatenated, level ``k`` in row-major word order (word :math:`(i_1, \dots, i_k)`,
letters ``0..d-1``, at position :math:`\sum_j i_j d^{k-j}` inside its level). This is exactly the
layout of ``iisignature.sig`` and of ``esig.stream2sig`` without its leading 1. The scalar
level is *implicit*:

* **group-like** elements (signatures; arguments of :func:`tensor_product`,
  :func:`tensor_inverse`, :func:`tensor_log`; results of :func:`tensor_exp`) have ``c_0 = 1``;
* **Lie / nilpotent** elements (log-signatures; argument of :func:`tensor_exp`, result of
  :func:`tensor_log`) have ``c_0 = 0``.

Level 2 is the area in the project's ordering: entry ``[i, j]`` is the word ``(i, j)``, i.e.
:math:`\int (X^i - X^i_s)\,dX^j` for a signature (``docs/conventions.md``); :func:`to_level2` /
:func:`from_level2` convert to and from the pair ``(x, a)`` of :mod:`roughpaths.algebra.level2`.

Every function broadcasts over leading batch axes ``...``; the depth is read from the length of
the last axis and ``dim``.

Examples
--------
>>> import numpy as np
>>> from roughpaths import tensor_exp, tensor_log, tensor_product, tensor_inverse
>>> z = np.array([1.0, 2.0, 0.0, 0.5, -0.5, 0.0])      # d = 2, depth 2: x = (1, 2), A12 = 0.5
>>> g = tensor_exp(z, 2)
>>> bool(np.allclose(tensor_log(g, 2), z))
True
>>> bool(np.allclose(tensor_product(g, tensor_inverse(g, 2), 2), 0.0))
True
"""

from __future__ import annotations

import numpy as np

from .flat import log_flat, lyndon_flat, product_flat
from ._lyndon import (bracket_string, count_lyndon_words, expansion_matrix,
                      lyndon_words)
from ..validation import as_float_array, check_memory, check_positive_int, check_same_batch

__all__ = [
    "sigdim",
    "logsigdim",
    "tensor_product",
    "tensor_inverse",
    "tensor_exp",
    "tensor_log",
    "to_level2",
    "from_level2",
    "lyndon_basis",
    "lyndon_coordinates",
    "from_lyndon_coordinates",
]


#: The largest size counted exactly by :func:`sigdim` / :func:`logsigdim`: ``dim**depth`` of at most
#: this many decimal digits (far beyond any signature that could be stored; larger counts would
#: only spend minutes on big-integer arithmetic).
_MAX_COUNT_DIGITS = 10_000
_MAX_COUNT_DEPTH = 1_000


def _check_count_size(dim: int, depth: int) -> int:
    import math

    digits = depth * math.log10(dim) if dim > 1 else 0.0
    if digits > _MAX_COUNT_DIGITS:
        raise ValueError(f"depth={depth} with dim={dim}: dim**depth has about {digits:.3g} decimal digits, no "
                         f"signature of that size can be stored (the count is refused above "
                         f"{_MAX_COUNT_DIGITS} digits); ask for a smaller depth.")
    if depth > _MAX_COUNT_DEPTH:
        raise ValueError(f"depth={depth} is more than {_MAX_COUNT_DEPTH} levels (Witt's formula costs "
                         f"depth**2 steps and no signature that deep can be stored); ask for a smaller depth.")
    return depth


def sigdim(dim: int, depth: int) -> int:
    """Length ``dim + dim**2 + ... + dim**depth`` of a flat element (no scalar level).

    >>> sigdim(3, 4)
    120
    """
    dim = check_positive_int(dim, "dim")
    depth = _check_count_size(dim, check_positive_int(depth, "depth"))
    return depth if dim == 1 else (dim ** (depth + 1) - dim) // (dim - 1)


def logsigdim(dim: int, depth: int) -> int:
    r"""Number of Lyndon words of length ``1..depth`` over ``dim`` letters (free Lie algebra dimension).

    Witt's formula :math:`\sum_{k=1}^{m} \frac1k \sum_{e \mid k} \mu(e)\, d^{k/e}` in exact
    integer arithmetic (nothing is enumerated, so large depths are instant).

    >>> logsigdim(3, 4)
    32
    >>> logsigdim(2, 60) > 10 ** 16
    True
    """
    dim = check_positive_int(dim, "dim")
    depth = _check_count_size(dim, check_positive_int(depth, "depth"))
    return sum(count_lyndon_words(dim, k) for k in range(1, depth + 1))


# ------------------------------------------------------------------------------ internals
def _depth_of(length: int, dim: int, name: str) -> int:
    total, k = 0, 0
    while total < length:
        k += 1
        total += dim ** k
    if total != length or k == 0:
        valid = ", ".join(str(sum(dim ** j for j in range(1, m + 1))) for m in range(1, 5))
        raise ValueError(f"{name} has last-axis length {length}, which is not d + d**2 + ... + d**m "
                         f"for d={dim} (valid lengths: {valid}, ...); pass the flat layout of "
                         f"iisignature.sig and the right dim.")
    return k


def _check_element(a, name: str, dim) -> tuple:
    dim = check_positive_int(dim, "dim")
    arr = as_float_array(a, name, min_ndim=1)
    depth = _depth_of(arr.shape[-1], dim, name)
    return arr, dim, depth


def _split(a: np.ndarray, dim: int, depth: int) -> list:
    out, start = [], 0
    for k in range(1, depth + 1):
        out.append(a[..., start:start + dim ** k])
        start += dim ** k
    return out


def _join(levels: list) -> np.ndarray:
    return np.concatenate(levels, axis=-1)


def _mul(A: list, B: list, depth: int) -> list:
    """Truncated product of ``A`` and ``B`` (level lists without scalar parts)."""
    batch = np.broadcast_shapes(A[0].shape[:-1], B[0].shape[:-1])
    out = []
    for k in range(1, depth + 1):
        c = np.zeros(batch + (A[k - 1].shape[-1],))
        for i in range(1, k):
            c += (A[i - 1][..., :, None] * B[k - i - 1][..., None, :]).reshape(c.shape)   # not -1: batch may be empty
        out.append(c)
    return out


def _power_series(Z: list, coeffs: list, depth: int) -> list:
    """``sum_{n>=1} coeffs[n] Z^n`` truncated (``Z`` nilpotent: no scalar level)."""
    total = [coeffs[1] * z for z in Z]
    power = Z
    for n in range(2, depth + 1):
        power = _mul(power, Z, depth)
        if coeffs[n]:
            total = [t + coeffs[n] * p for t, p in zip(total, power)]
    return total


# ------------------------------------------------------------------------------ group operations
def tensor_product(a, b, dim: int) -> np.ndarray:
    r"""Chen product :math:`(1 + a)\otimes(1 + b) - 1` of two group-like elements.

    Parameters
    ----------
    a, b : array_like, shape ``(..., sigdim(dim, m))``
        Flat elements with implicit scalar 1 (e.g. signatures); batch axes broadcast.
    dim : int
        Dimension ``d`` of the underlying space.

    Returns
    -------
    ndarray, shape ``(broadcast(...), sigdim(dim, m))``
        Level ``k`` is :math:`a_k + b_k + \sum_{0<i<k} a_i \otimes b_{k-i}`. For signatures this is
        Chen's identity :math:`S(X)_{s,u} \otimes S(X)_{u,t} = S(X)_{s,t}`.

    Examples
    --------
    >>> import numpy as np
    >>> tensor_product(np.array([1.0, 0.0, 0.5, 0.0, 0.0, 0.0]),      # exp(e_1), d = 2
    ...                np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.5]), 2)   # exp(e_2)
    array([1. , 1. , 0.5, 1. , 0. , 0.5])
    """
    a, dim, depth = _check_element(a, "a", dim)
    b = as_float_array(b, "b", min_ndim=1)
    if b.shape[-1] != a.shape[-1]:
        raise ValueError(f"a and b must have the same depth: last axes {a.shape[-1]} and {b.shape[-1]} "
                         f"differ; truncate the deeper one (e.g. b[..., :{a.shape[-1]}]).")
    check_same_batch(a.shape[:-1], b.shape[:-1], "a", "b")
    return product_flat(a, b, dim, depth)


def tensor_inverse(a, dim: int) -> np.ndarray:
    r"""Inverse :math:`(1 + a)^{-1} - 1 = \sum_{n=1}^m (-a)^{\otimes n}` of a group-like element.

    For a signature this is the signature of the reversed path. Shape ``(..., sigdim)``.
    """
    a, dim, depth = _check_element(a, "a", dim)
    coeffs = [0.0] + [(-1.0) ** n for n in range(1, depth + 1)]
    return _join(_power_series(_split(a, dim, depth), coeffs, depth))


def tensor_exp(z, dim: int) -> np.ndarray:
    r"""Truncated exponential :math:`\exp(z) - 1 = \sum_{n=1}^m z^{\otimes n}/n!` of ``z`` (scalar part 0).

    Parameters
    ----------
    z : array_like, shape ``(..., sigdim(dim, m))``
        Flat element with implicit scalar 0 (e.g. a log-signature, expanded in tensor coordinates).
    dim : int

    Returns
    -------
    ndarray, shape ``(..., sigdim(dim, m))``
        Group-like element (implicit scalar 1).
    """
    z, dim, depth = _check_element(z, "z", dim)
    coeffs = [0.0] + [1.0 / float(np.prod(np.arange(1, n + 1))) for n in range(1, depth + 1)]
    return _join(_power_series(_split(z, dim, depth), coeffs, depth))


def tensor_log(a, dim: int) -> np.ndarray:
    r"""Truncated logarithm :math:`\log(1 + a) = \sum_{n=1}^m (-1)^{n+1} a^{\otimes n}/n`.

    For a signature the result (implicit scalar 0) is the expanded log-signature, an element of
    the free Lie algebra; its level 2 is the Lévy area :math:`\tfrac12(\mathbb{X} - \mathbb{X}^T)`.
    Shape ``(..., sigdim)``.
    """
    a, dim, depth = _check_element(a, "a", dim)
    flat = np.ascontiguousarray(a.reshape(-1, a.shape[-1]))
    return log_flat(flat, dim, depth).reshape(a.shape)


# ------------------------------------------------------------------------------ level 2
def to_level2(a, dim: int) -> tuple:
    """Levels 1 and 2 of a flat element as the pair ``(x (..., d), a (..., d, d))`` of :mod:`roughpaths.algebra.level2`.

    Higher levels are dropped (truncation is a group morphism).

    >>> import numpy as np
    >>> x, aa = to_level2(np.arange(1.0, 7.0), 2)
    >>> aa
    array([[3., 4.],
           [5., 6.]])
    """
    a, dim, depth = _check_element(a, "a", dim)
    if depth < 2:
        raise ValueError(f"a has depth 1 (last axis {a.shape[-1]} = d); level 2 needs depth >= 2.")
    return a[..., :dim].copy(), a[..., dim:dim + dim * dim].reshape(a.shape[:-1] + (dim, dim)).copy()


def from_level2(x, a) -> np.ndarray:
    """The flat depth-2 element ``(..., d + d*d)`` of a level-2 pair ``(x (..., d), a (..., d, d))``.

    >>> import numpy as np
    >>> from_level2(np.array([1.0, 2.0]), np.array([[3.0, 4.0], [5.0, 6.0]]))
    array([1., 2., 3., 4., 5., 6.])
    """
    x = as_float_array(x, "x", min_ndim=1)
    d = x.shape[-1]
    a = as_float_array(a, "a", last_dims=(d, d))
    batch = check_same_batch(x.shape[:-1], a.shape[:-2], "x", "a")
    x = np.broadcast_to(x, batch + (d,))
    a = np.broadcast_to(a, batch + (d, d)).reshape(batch + (d * d,))
    return np.concatenate([x, a], axis=-1)


# ------------------------------------------------------------------------------ Lyndon basis
def lyndon_basis(dim: int, depth: int) -> list:
    """The Lyndon basis as bracket strings, e.g. ``'[1,[1,2]]'``, in ``iisignature.basis`` order.

    Letters are printed 1-based in decimal: letter ``i`` (0-based) is the number ``i + 1``. A
    bracket is ``[A,B]``, so every letter is a maximal run of digits delimited by ``[``, ``,``,
    ``]`` or the ends of the string, and a label names exactly one bracketed Lyndon word for every
    ``dim`` (``'[1,10]'`` is the bracket of letters 1 and 10). For ``2 <= dim <= 9`` the labels
    are exactly ``iisignature.basis``'s (iisignature refuses ``dim = 1``). For letters 10 and
    above they differ: ``iisignature`` prints every such letter as ``'?'`` (its ``'[1,?]'`` is
    our ``'[1,10]'``), which is still one-to-one at ``dim = 10`` but not from ``dim = 11`` on
    (``'[1,?]'`` there stands for both ``[1,10]`` and ``[1,11]``); we keep the number. The words,
    their order and the coordinates are iisignature's for every ``dim``. Coordinate ``i`` of
    :func:`lyndon_coordinates` (and of :func:`roughpaths.logsignature`) multiplies basis element ``i``.

    Parameters
    ----------
    dim : int
        Number of letters ``d >= 1``.
    depth : int
        Largest word length ``m >= 1``.

    Returns
    -------
    list of str
        ``logsigdim(dim, depth)`` labels, ordered by length, then lexicographically.

    Examples
    --------
    >>> lyndon_basis(2, 3)
    ['1', '2', '[1,2]', '[1,[1,2]]', '[[1,2],2]']
    >>> lyndon_basis(11, 2)[-3:]            # iisignature: '[9,?]', '[9,?]', '[?,?]'
    ['[9,10]', '[9,11]', '[10,11]']
    """
    dim = check_positive_int(dim, "dim")
    depth = check_positive_int(depth, "depth")
    n = logsigdim(dim, depth)
    check_memory(float(n) * (120.0 + 8 * depth), f"the Lyndon basis ({n} words up to length {depth} over "
                 f"{dim} letters)", "ask for a smaller depth or dimension (logsigdim(dim, depth) counts the "
                 "words without listing them)")
    return [bracket_string(w) for w in lyndon_words(dim, depth)]


def lyndon_coordinates(z, dim: int) -> np.ndarray:
    r"""Coordinates in the Lyndon basis of a Lie element given in expanded (tensor) form.

    Parameters
    ----------
    z : array_like, shape ``(..., sigdim(dim, m))``
        A Lie element, e.g. :func:`tensor_log` of a signature.
    dim : int

    Returns
    -------
    ndarray, shape ``(..., logsigdim(dim, m))``
        ``c`` with :math:`z = \sum_w c_w P(w)` over Lyndon words ``w`` (standard bracketing, see
        :func:`lyndon_basis`). Same coordinates as ``iisignature.logsig`` (default method).
        Only the Lyndon-word entries of ``z`` are read, so ``z`` must really be Lie.
    """
    z, dim, depth = _check_element(z, "z", dim)
    flat = np.ascontiguousarray(z.reshape(-1, z.shape[-1]))
    out = lyndon_flat(flat, dim, depth)
    return out.reshape(z.shape[:-1] + out.shape[-1:])          # not -1: an empty batch has no size to infer


def from_lyndon_coordinates(c, dim: int, depth: int) -> np.ndarray:
    r"""Expanded (tensor) form :math:`\sum_w c_w P(w)` of Lyndon coordinates; inverse of :func:`lyndon_coordinates`.

    Parameters
    ----------
    c : array_like, shape ``(..., logsigdim(dim, depth))``
    dim, depth : int

    Returns
    -------
    ndarray, shape ``(..., sigdim(dim, depth))``
    """
    dim = check_positive_int(dim, "dim")
    depth = check_positive_int(depth, "depth")
    n = logsigdim(dim, depth)
    c = as_float_array(c, "c", last_dims=(n,))
    flat = c.reshape(-1, n)
    out, start = [], 0
    for k in range(1, depth + 1):
        e = expansion_matrix(dim, k)                       # sparse (n_k, dim**k)
        out.append(np.asarray((e.T @ flat[:, start:start + e.shape[0]].T).T))
        start += e.shape[0]
    return np.concatenate(out, axis=-1).reshape(c.shape[:-1] + (sigdim(dim, depth),))   # not -1: batch may be empty
