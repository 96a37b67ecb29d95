r"""Hölder and p-variation norms of rough paths on a grid, and the rough-path distance.

The Hölder quantities live in :mod:`roughpaths.norms.holder`, the p-variation in :mod:`roughpaths.norms.p_variation`;
this module gathers them and states what they share.

All quantities are computed **exactly over the grid**: the suprema run over every pair of grid
times ``s < t`` (Hölder) or over every partition whose points are grid times (p-variation). No
dyadic restriction and no coarsening is ever applied; what is returned is the norm of the
piecewise data as sampled on :attr:`RoughPath.times`. (For a piecewise-linear path the level-1
Hölder seminorm over grid pairs equals the seminorm of the continuous interpolant when
``α = 1``, and is a lower bound of it otherwise.)

Tensor norms
------------
* level 1: the Euclidean norm :math:`|x| = (\sum_i x_i^2)^{1/2}` on :math:`\mathbb{R}^d`;
* level 2: the Frobenius (Hilbert–Schmidt) norm :math:`|a| = (\sum_{ij} a_{ij}^2)^{1/2}` on
  :math:`\mathbb{R}^{d\times d} = \mathbb{R}^d\otimes\mathbb{R}^d`, i.e. the Hilbert tensor norm
  (admissible; equivalent to the projective norm up to a factor depending on ``d`` only).

Areas follow ``docs/conventions.md``: :math:`\mathbb{X}^{ij}_{s,t} = \int_s^t (X^i_r - X^i_s)\,dX^j_r`,
combined over pairs by Chen's identity.

Definitions (``X`` a rough path on the grid :math:`t_0 < \dots < t_N`)
-------------------------------------------------------------------------------
* :func:`holder_seminorm`: :math:`\|X\|_\alpha = \sup_{s<t} |X_{s,t}| / (t-s)^\alpha`;
* :func:`area_holder_seminorm`: :math:`\|\mathbb{X}\|_{2\alpha} = \sup_{s<t} |\mathbb{X}_{s,t}| / (t-s)^{2\alpha}`;
* :func:`rough_path_holder_norm`: the homogeneous norm :math:`\|X\|_\alpha + \|\mathbb{X}\|_{2\alpha}^{1/2}`;
* :func:`p_variation`: :math:`\|X\|_{p\text{-var}} = (\sup_{\mathcal P} \sum_{[s,t]\in\mathcal P} |X_{s,t}|^p)^{1/p}`;
* :func:`area_p_variation`: :math:`\|\mathbb{X}\|_{p/2\text{-var}} = (\sup_{\mathcal P} \sum |\mathbb{X}_{s,t}|^{p/2})^{2/p}`;
* :func:`rough_path_p_variation`: the homogeneous :math:`\|X\|_{p\text{-var}} + \|\mathbb{X}\|_{p/2\text{-var}}^{1/2}`
  (the two suprema are taken separately, each over its own optimal partition);
* :func:`holder_distance`: the inhomogeneous distance
  :math:`\rho_\alpha(X, Y) = \sup |X_{s,t} - Y_{s,t}|/(t-s)^\alpha + \sup |\mathbb{X}_{s,t} - \mathbb{Y}_{s,t}|/(t-s)^{2\alpha}`.

Scale
-----
Every quantity is computed on a rescaled copy: each batch member's increments by a power of two
``c`` near its largest entry (areas by ``c²``, the dilation of the rough path), and the grid by a
power of two near its length when that length lies outside ``[2⁻⁶⁴, 2⁶⁴]``; the result is scaled
back at the end. Powers of two divide exactly, so nothing changes for moderate inputs, and a path
scaled by ``1e160`` or ``1e-170`` gets its norm scaled by the same factor instead of overflowing to
``inf`` or underflowing to ``0`` (the squared norms the kernels accumulate would otherwise leave the
float64 range). Only a result that itself lies outside that range is ``inf`` or ``0``.

Cost
----
Hölder quantities visit all :math:`N(N+1)/2` grid pairs: time :math:`O(N^2 d)` (level 1) or
:math:`O(N^2 d^2)` (level 2) per path, memory :math:`O(N d + d^2)` (no :math:`N\times N` array).
The exact p-variation is a dynamic programme over the grid, :math:`O(N^2)` pairs in the worst case;
at level 1 a branch-and-bound on bounding boxes (see :func:`p_variation` and
:func:`holder_seminorm`) skips candidates that provably cannot win, without changing the result
(typically 10-100× faster on Brownian-like paths of 10⁴ points). As a guide, a single-core pass over
:math:`10^8` pairs takes about a second at level 1. To bound run time, every function refuses
paths with more than ``max_points`` grid points (default 100 001) with an error; pass
``max_points=None`` to lift the limit, or compute the norm of an explicitly coarsened path
(``X.restrict(coarser_times)``), which is then a different — smaller — quantity.
"""

from __future__ import annotations

from .holder import area_holder_seminorm, holder_distance, holder_seminorm, rough_path_holder_norm
from .p_variation import area_p_variation, p_variation, rough_path_p_variation

__all__ = [
    "holder_seminorm",
    "area_holder_seminorm",
    "rough_path_holder_norm",
    "p_variation",
    "area_p_variation",
    "rough_path_p_variation",
    "holder_distance",
]
