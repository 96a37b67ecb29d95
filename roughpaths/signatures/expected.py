r"""The expected signature of Brownian motion, in closed form.

For a standard ``d``-dimensional Brownian motion :math:`B` and its Stratonovich (geometric) signature
over :math:`[0, t]`, Fawcett's formula gives

.. math:: \mathbb{E}\, S(B)_{0,t} = \exp\Big(\frac t2 \sum_{i=1}^d e_i \otimes e_i\Big)
          = \sum_{k \ge 0} \frac{(t/2)^k}{k!} \Big(\sum_{i} e_i \otimes e_i\Big)^{\otimes k},

so the odd levels vanish and level :math:`2k` puts :math:`(t/2)^k / k!` on each word
:math:`(i_1 i_1 i_2 i_2 \dots i_k i_k)` and 0 elsewhere.
"""

from __future__ import annotations

import numpy as np

from ..algebra.tensor import sigdim
from ..validation import check_memory, check_positive_int, check_positive_real

__all__ = ["brownian_expected_signature"]


def brownian_expected_signature(dim: int, depth: int, t: float = 1.0) -> np.ndarray:
    r"""Expected Stratonovich signature of ``dim``-dimensional standard Brownian motion on ``[0, t]``.

    Parameters
    ----------
    dim : int
        Dimension ``d >= 1`` of the Brownian motion (independent standard components).
    depth : int
        Truncation level ``m >= 1``.
    t : float
        Length of the time interval (``t >= 0``; default 1).

    Returns
    -------
    ndarray, shape ``(d + d**2 + ... + d**m,)``
        :math:`\mathbb{E}\,S(B)_{0,t}` truncated at level ``m``, in :func:`roughpaths.signature`'s
        layout (levels ``1..m``, row-major words, no leading 1): the closed form
        :math:`\exp(\tfrac t2 \sum_i e_i \otimes e_i)`. Odd levels are exactly zero; level
        :math:`2k` is :math:`(t/2)^k / k!` on the words :math:`(i_1 i_1 \dots i_k i_k)`, zero elsewhere.

    Notes
    -----
    **Stratonovich, not Itô.** This is the expectation of the signature of the geometric
    (Stratonovich) lift, the limit of the signatures of the piecewise-linear interpolations of
    :math:`B` on refining grids (Wong–Zakai), the lift :func:`roughpaths.brownian_rough_path`
    builds. The Itô iterated integrals :math:`\int_{0<s_1<\dots<s_k<t} dB^{i_1}_{s_1} \cdots dB^{i_k}_{s_k}`
    of every level :math:`k \ge 1` are Itô integrals of square-integrable adapted integrands, hence
    martingales started at 0: the expected Itô signature is 1 at level 0 and **exactly 0 at every
    level** :math:`k \ge 1`. At level 2 the two differ by :math:`\tfrac t2 I`, the
    :math:`\mathbb{X}^{\text{Itô}} = \mathbb{X}^{\text{Strat}} - \tfrac12 (t - s) I` of ``docs/conventions.md``;
    at higher levels the Stratonovich iterated integrals add, to the Itô ones, every way of
    contracting adjacent equal letters :math:`(i\,i)` into :math:`\tfrac12\,dt`, and only the full
    contractions survive in expectation, which is the formula above.

    The result is exact (the coefficients :math:`(t/2)^k / k!` are the only arithmetic); the
    size is that of a signature, refused with a ``ValueError`` above the memory budget.

    Examples
    --------
    >>> brownian_expected_signature(2, 2, t=1.0)       # level 1 zero, level 2 = ½ I
    array([0. , 0. , 0.5, 0. , 0. , 0.5])
    >>> e = brownian_expected_signature(2, 4, t=2.0)
    >>> float(e[14 + 0b0011]), float(e[14 + 0b0101])   # words (1 1 2 2), (1 2 1 2): level 4 starts at 2 + 4 + 8
    (0.5, 0.0)
    """
    d = check_positive_int(dim, "dim")
    m = check_positive_int(depth, "depth")
    t = check_positive_real(t, "t", allow_zero=True)
    size = float(sum(float(d) ** k for k in range(1, m + 1)))
    # held at the peak: the result (size entries), the tensor power of the top even level (d^(2k)
    # entries, 2k = m rounded down to even) with the power it is built from (d^(2k-2)) and the pair (d^2),
    # 8 bytes each, plus 8 KiB of Python objects (some twenty array headers and views, a few hundred bytes
    # each: 2-3 KiB measured, the rest a margin for other numpy versions)
    top = 2 * (m // 2)
    power_size = float(d) ** top + float(d) ** max(top - 2, 0) + float(d) ** 2 if top else 0.0
    check_memory(8.0 * (size + power_size) + 8192.0,
                 f"the expected signature (dim={d}, depth={m}: {size:.3g} entries and a working tensor power "
                 f"of {power_size:.3g})", "use a lower depth or a smaller dim")
    out = np.zeros(sigdim(d, m))
    pair = np.eye(d).reshape(-1)                  # Σ_i e_i ⊗ e_i, flat (row-major words)
    power = np.ones(1)                            # (Σ_i e_i ⊗ e_i)^{⊗k}, flat
    start, coeff = 0, 1.0
    for level in range(1, m + 1):
        if level % 2 == 0:
            k = level // 2
            new = np.empty(power.size * pair.size)   # the flat ⊗ power ⊗ pair, one column per letter pair
            cols = new.reshape(power.size, pair.size)  # (a broadcast product would buffer up to 2x its size)
            for j in range(pair.size):
                np.multiply(power, pair[j], out=cols[:, j])
            power = new
            coeff *= 0.5 * t / k
            block = out[start:start + d ** level]
            np.multiply(power, coeff, out=block)          # in place: no temporary
        start += d ** level
    return out
