r"""Path transforms applied before a signature: lead–lag, time, basepoint and invisibility reset.

Each transform maps sampled paths ``(..., n, d)`` (leading axes are batch axes) to new sampled paths,
which are then read as piecewise linear like every path of :func:`roughpaths.signature`. They are the
augmentations of Chevyrev and Kormilitzin, *A primer on the signature method in machine learning*
(2016), and of Morrill, Fermanian, Kidger and Lyons, *A generalised signature method for multivariate
time series feature extraction* (2020); the conventions below (which copy leads, where the new channel
goes) are those of ``sktime``'s signature transformer, so features line up with it:

================================  =====================  ===========================================================
transform                         shape out              points
================================  =====================  ===========================================================
:func:`lead_lag`                  ``(..., 2n-1, 2d)``    ``(x_k, x_k)`` at ``2k``, ``(x_{k+1}, x_k)`` at ``2k+1``:
                                                         lead channels first, the lead moves first
:func:`time_augment`              ``(..., n, d+1)``      ``(t_k, x_k)``, time first, ``t_k = k / (n - 1)`` or given
:func:`basepoint`                 ``(..., n+1, d)``      ``0, x_0, ..., x_{n-1}``
:func:`invisibility_reset`        ``(..., n+2, d+1)``    ``(1, x_k)``, then ``(0, x_{n-1})``, then ``(0, 0)``
================================  =====================  ===========================================================

What they add to the signature:

* **lead–lag**: the Lévy area between a lead channel and a lag channel is a quadratic variation.
  Lead copy ``i``, lag copy ``d + i``: ``S^{(i, d+i)} - S^{(d+i, i)} = Σ_k (Δx^i_k)²``, so the Lévy area
  (with the ½ of ``docs/conventions.md``) is ``½ Σ_k (Δx^i_k)²``. Across two channels,
  ``½ (S^{(i, d+j)} - S^{(d+j, i)}) = ½ Σ_k Δx^i_k Δx^j_k + A^{ij}``, the quadratic covariation plus
  the Lévy area ``A^{ij}`` of the path itself.
* **time**: a strictly increasing channel makes the signature determine the sampled path (no
  tree-like cancellations), and levels carry time-weighted integrals (``S^{(0, i)} = ∫ t dx^i``...).
* **basepoint**: the signature is invariant under translation; starting from the origin makes it
  see ``x_0`` (level 1 is then ``x_{n-1}``, the path's value, not its increment).
* **invisibility reset**: the same information as the basepoint, through a visibility channel: level 1 is
  ``(-1, -x_0)`` (the path is sent home at the end, so its coordinates there read the start, not the
  increment), and ``S^{(0, 1+i)} = x^i_{n-1}``, ``S^{(1+i, 0)} = -(x_{n-1} - x_0)^i`` carry the end point
  and the increment.

The transforms are linear in the path (plus constants), so they are differentiable; the framework
front ends have the same four functions written in torch and JAX operations
(``roughpaths.torch.lead_lag``, ``roughpaths.jax.lead_lag``, ...), whose gradients are the frameworks'
own. Compose them as functions: ``lead_lag(time_augment(x))`` lead-lags the time channel too,
``time_augment(lead_lag(x))`` adds one time channel increasing along the ``2n - 1`` points.
"""

from __future__ import annotations

import numpy as np

from .._frontends import check_times_batch
from ..validation import as_float_array, check_memory

__all__ = ["lead_lag", "time_augment", "basepoint", "invisibility_reset"]


def _check(paths, n_out: int, d_out: int, copies: int = 1) -> np.ndarray:
    """``paths`` as a finite float64 ``(..., n, d)`` array with ``n, d >= 1``; the memory is checked: the output
    and the ``copies - 1`` output-sized pieces a transform concatenates (lead–lag's lead and lag halves,
    invisibility reset's visible points), plus one input-sized temporary (the finiteness check's mask, the
    zeros and the time channel's broadcast)."""
    x = as_float_array(paths, "paths", min_ndim=2)
    n, d = x.shape[-2:]
    if n < 1 or d < 1:
        raise ValueError(f"paths must have shape (..., n, d) with n >= 1 points and d >= 1 channels, got shape "
                         f"{x.shape}; pass at least one point of at least one channel.")
    n_new, d_new = n_out(n), d_out(d)
    batch = float(np.prod(x.shape[:-2], dtype=float))
    size = batch * (copies * n_new * d_new + n * (d + 1)) * 8.0
    check_memory(size, f"the transformed paths ({x.shape[:-2]} x {n_new} points x {d_new} channels, and "
                 f"{copies - 1} output-sized temporaries)" if copies > 1 else f"the transformed paths "
                 f"({x.shape[:-2]} x {n_new} points x {d_new} channels)", "transform fewer or shorter paths at a time")
    return x


def lead_lag(paths) -> np.ndarray:
    r"""The lead–lag transform: each point twice, the lead copy moving one half-step before the lag copy.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
        ``n >= 1`` points in :math:`\mathbb{R}^d`; leading axes are batch axes.

    Returns
    -------
    ndarray, shape ``(..., 2n - 1, 2d)``
        Point ``2k`` is ``(x_k, x_k)``, point ``2k + 1`` is ``(x_{k+1}, x_k)``: channels ``0..d-1`` are
        the lead, ``d..2d-1`` the lag. The Lévy area of lead channel ``i`` against lag channel ``d + i``
        is half the quadratic variation ``½ Σ_k (x^i_{k+1} - x^i_k)^2``.

    Examples
    --------
    >>> import numpy as np
    >>> lead_lag(np.array([[0.0], [1.0], [3.0]]))
    array([[0., 0.],
           [1., 0.],
           [1., 1.],
           [3., 1.],
           [3., 3.]])
    >>> from roughpaths import logsignature
    >>> float(logsignature(lead_lag(np.array([[0.0], [1.0], [3.0]])), 2)[2])   # ½ (1² + 2²)
    2.5
    """
    x = _check(paths, lambda n: 2 * n - 1, lambda d: 2 * d, copies=2)      # the lead and lag halves, then joined
    k = np.arange(2 * x.shape[-2] - 1)
    return np.concatenate([x[..., (k + 1) // 2, :], x[..., k // 2, :]], axis=-1)


def time_augment(paths, times=None) -> np.ndarray:
    r"""Add time as the first channel.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
    times : array_like, shape ``(n,)`` or ``(..., n)``, optional
        The time of each point, strictly increasing along the last axis; its leading axes broadcast
        against the batch axes of ``paths``. Default ``t_k = k / (n - 1)`` (``[0]`` for one point),
        computed by one division per point (the torch and JAX versions give the same numbers).

    Returns
    -------
    ndarray, shape ``(..., n, d + 1)``
        Point ``k`` is ``(t_k, x_k)``.

    Examples
    --------
    >>> import numpy as np
    >>> time_augment(np.array([[5.0], [7.0], [6.0]]))
    array([[0. , 5. ],
           [0.5, 7. ],
           [1. , 6. ]])
    """
    x = _check(paths, lambda n: n, lambda d: d + 1)
    n = x.shape[-2]
    if times is None:
        t = np.arange(n) / max(n - 1, 1)
    else:
        t = as_float_array(times, "times", min_ndim=1)
        if t.shape[-1] != n:
            raise ValueError(f"times must have {n} entries on its last axis (one per point of paths, shape "
                             f"{x.shape}), got shape {t.shape}.")
        steps = np.diff(t, axis=-1)
        if steps.size and not np.all(steps > 0):
            where = tuple(int(i) for i in np.argwhere(~(steps > 0))[0])
            raise ValueError(f"times must be strictly increasing along its last axis, but at index {where} it "
                             f"goes from {t[where[:-1] + (where[-1],)]!r} to {t[where[:-1] + (where[-1] + 1,)]!r}; "
                             f"sort the points by time and drop repeated times.")
    check_times_batch(t.shape, x.shape)
    return np.concatenate([np.broadcast_to(t, x.shape[:-1])[..., None], x], axis=-1)


def basepoint(paths) -> np.ndarray:
    r"""Prepend the origin: the signature then sees the starting point.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``

    Returns
    -------
    ndarray, shape ``(..., n + 1, d)``
        The points ``0, x_0, ..., x_{n-1}``; level 1 of its signature is ``x_{n-1}``.

    Examples
    --------
    >>> import numpy as np
    >>> basepoint(np.array([[1.0, 2.0], [3.0, 4.0]]))
    array([[0., 0.],
           [1., 2.],
           [3., 4.]])
    """
    x = _check(paths, lambda n: n + 1, lambda d: d)
    return np.concatenate([np.zeros(x.shape[:-2] + (1, x.shape[-1])), x], axis=-2)


def invisibility_reset(paths) -> np.ndarray:
    r"""The invisibility-reset transform: a visibility channel, then the path is lifted off and sent home.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``

    Returns
    -------
    ndarray, shape ``(..., n + 2, d + 1)``
        Points ``(1, x_0), ..., (1, x_{n-1})``, then ``(0, x_{n-1})`` (visibility off), then
        ``(0, 0, ..., 0)`` (back to the origin while invisible). Level 1 of its signature is
        ``(-1, -x_0)``: unlike the signature of the path itself, it depends on the starting point
        (as with :func:`basepoint`).

    Examples
    --------
    >>> import numpy as np
    >>> invisibility_reset(np.array([[1.0, 2.0], [3.0, 4.0]]))
    array([[1., 1., 2.],
           [1., 3., 4.],
           [0., 3., 4.],
           [0., 0., 0.]])
    """
    x = _check(paths, lambda n: n + 2, lambda d: d + 1, copies=2)          # the visible points, then joined
    batch, d = x.shape[:-2], x.shape[-1]
    seen = np.concatenate([np.ones(x.shape[:-1] + (1,)), x], axis=-1)
    off = np.concatenate([np.zeros(batch + (1, 1)), x[..., -1:, :]], axis=-1)
    return np.concatenate([seen, off, np.zeros(batch + (1, d + 1))], axis=-2)
