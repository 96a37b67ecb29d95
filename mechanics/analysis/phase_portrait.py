r"""Phase portraits of the modified rigid body: level sets of :math:`\tilde h` on the sphere ``|Π| = r``.

:math:`\tilde h(\Pi) = \tfrac12\Pi\cdot\mathbb I^{-1}\Pi + c\cdot\Pi` is conserved by the conservative
flow and decreased by the double bracket; its level curves on the sphere are the trajectories of
the undamped body. The separatrices pass through the saddles found by
:func:`mechanics.analysis.equilibria.rigid_body_equilibria`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from roughpaths.validation import as_float_array, check_memory, check_positive_int

from ._inputs import _as_c, _check_radius
from .equilibria import rigid_body_equilibria
from .modified_energy import _modified_hamiltonian, as_inverse_inertia

__all__ = ["LevelSets", "rigid_body_level_sets"]


@dataclass
class LevelSets:
    """Level curves of ``h̃`` on the sphere ``|Π| = r`` (for phase portraits).

    Attributes
    ----------
    levels : ndarray (L,)
        The energy values.
    curves : list of list of ndarray
        ``curves[k]`` holds the polylines (each of shape ``(m, 3)``, on the sphere to round-off,
        projected onto the exact level set) of ``h̃ = levels[k]``; closed curves repeat their first
        point at the end.
    separatrix : ndarray of bool (L,)
        True for the levels of saddle equilibria (the separatrices).
    equilibria : list of Equilibrium
        All equilibria, with type (see :func:`rigid_body_equilibria`).
    radius : float
    """

    levels: np.ndarray
    curves: list
    separatrix: np.ndarray
    equilibria: list
    radius: float = 1.0
    energy_range: tuple = field(default=(0.0, 0.0))


def _join_polylines(lines, tol):
    """Join polylines whose end points coincide (the φ seam of the chart), in 3-D."""
    lines = [np.asarray(l) for l in lines if len(l) >= 2]
    changed = True
    while changed:
        changed = False
        for i in range(len(lines)):
            for j in range(len(lines)):
                if i == j:
                    continue
                a, b = lines[i], lines[j]
                if np.linalg.norm(a[-1] - b[0]) <= tol:
                    new = np.concatenate([a, b[1:]])
                elif np.linalg.norm(a[-1] - b[-1]) <= tol:
                    new = np.concatenate([a, b[::-1][1:]])
                else:
                    continue
                lines = [l for k, l in enumerate(lines) if k not in (i, j)] + [new]
                changed = True
                break
            if changed:
                break
    out = []
    for l in lines:
        if np.linalg.norm(l[0] - l[-1]) <= tol and len(l) > 2:
            l = np.concatenate([l[:-1], l[:1]])
        out.append(l)
    return out


#: At most this many levels per call: each level is a contour pass over the whole grid (10⁶ levels
#: took about 20 minutes), and a phase portrait with more curves is unreadable anyway.
MAX_LEVELS = 10_000


def _check_level_count(n: int) -> int:
    if n > MAX_LEVELS:
        raise ValueError(f"levels asks for {n} level curves, more than MAX_LEVELS = {MAX_LEVELS} (each is a "
                         f"contour pass over the n_theta x n_phi grid; 10**6 levels take ~20 minutes); "
                         f"ask for fewer levels.")
    return n


def rigid_body_level_sets(inertia, c=None, *, radius=1.0, levels=12, include_separatrices=True,
                          n_theta=181, n_phi=361, theta=0.0, project=True):
    r"""Level curves of ``h̃ = ½Π·𝕀⁻¹Π + c·Π`` on the sphere ``|Π| = r``, with the equilibria.

    The rigid body's (modified) phase portrait: the conservative orbits are exactly these curves.
    Contouring is done by ``contourpy`` (matplotlib's engine) on a (colatitude, longitude) grid,
    seam pieces are joined in 3-D and every vertex is projected onto the exact level set (Newton
    along the tangential gradient, then back to the sphere).

    Parameters
    ----------
    inertia, c, radius, theta
        As in :func:`rigid_body_equilibria` (RP sign of ``c``). The paper's Fig. surf2 caption
        (``h̃ = ½Π·𝕀⁻¹Π + 0.0625 Π·e2`` for ``s13 = 25``, σ = 0.05) uses its printed sign: in the RP
        convention that case is ``c = (0, −0.0625, 0)``; surf4/surf5 (``+0.0625, −0.0625, −0.125``
        for ``s12 = −50, s13 = s23 = 25``) already agree with RP.
    levels : int or array_like
        Number of equally spaced interior levels between min and max of ``h̃`` on the sphere, or the
        level values themselves.
    include_separatrices : bool
        Add the energies of the saddle equilibria (flagged in ``separatrix``).
    n_theta, n_phi : int
        Contouring grid.
    project : bool
        Project the vertices onto the exact level set (default True).

    Returns
    -------
    LevelSets

    Examples
    --------
    >>> ls = rigid_body_level_sets([1.0, 2.0, 3.0], levels=[0.2, 0.4])
    >>> ls.levels.tolist(), ls.separatrix.tolist()    # the saddle level 1/4 is added
    ([0.2, 0.25, 0.4], [False, True, False])
    >>> [len(cs) for cs in ls.curves]   # ovals around ±e3, the two separatrix circles, ovals around ±e1
    [2, 2, 2]
    >>> bool(np.allclose(np.linalg.norm(ls.curves[0][0], axis=1), 1.0))
    True
    """
    import contourpy

    A = as_inverse_inertia(inertia)
    c = _as_c(c)
    r = _check_radius(radius)
    eqs = rigid_body_equilibria(np.linalg.inv(A), c, radius=r, theta=theta)
    emin, emax = eqs[0].energy, eqs[-1].energy
    if np.ndim(levels) == 0 and not isinstance(levels, (str, bytes)):
        n = check_positive_int(levels, "levels")
        lv = list(np.linspace(emin, emax, _check_level_count(n) + 2)[1:-1])
    else:
        lv = list(as_float_array(levels, "levels", ndim=1))
        _check_level_count(len(lv))
    sep = [False] * len(lv)
    if include_separatrices:
        for e in eqs:
            if e.kind == "saddle" and not any(abs(e.energy - x) <= 1e-12 * (abs(emax) + abs(emin) + 1) for x in lv):
                lv.append(e.energy)
                sep.append(True)
    order = np.argsort(lv)
    lv = np.array(lv)[order]
    sep = np.array(sep)[order]

    n_theta = check_positive_int(n_theta, "n_theta", minimum=3)
    n_phi = check_positive_int(n_phi, "n_phi", minimum=3)
    check_memory(8.0 * 12 * n_theta * n_phi, f"the contour grid (n_theta={n_theta} x n_phi={n_phi})",
                 "use a coarser grid (the defaults 181 x 361 resolve curves to ~1e-5 after projection)")
    th = np.linspace(0.0, np.pi, n_theta)
    ph = np.linspace(-np.pi, np.pi, n_phi)
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    P = r * np.stack([np.sin(TH) * np.cos(PH), np.sin(TH) * np.sin(PH), np.cos(TH)], axis=-1)
    H = _modified_hamiltonian(P, A, c)
    gen = contourpy.contour_generator(ph, th, H, line_type="Separate")
    curves = []
    for level in lv:
        pieces = []
        for seg in gen.lines(float(level)):
            phs, ths = seg[:, 0], seg[:, 1]
            xyz = r * np.stack([np.sin(ths) * np.cos(phs), np.sin(ths) * np.sin(phs), np.cos(ths)], axis=-1)
            if project:
                xyz = _project_to_level(xyz, A, c, r, float(level))
            pieces.append(xyz)
        curves.append(_join_polylines(pieces, tol=1e-6 * r))
    return LevelSets(levels=lv, curves=curves, separatrix=sep, equilibria=eqs, radius=r,
                     energy_range=(emin, emax))


def _project_to_level(x, A, c, r, level, iters=4):
    for _ in range(iters):
        g = x @ A.T + c
        n = x / np.linalg.norm(x, axis=-1, keepdims=True)
        gt = g - np.sum(g * n, axis=-1, keepdims=True) * n
        f = _modified_hamiltonian(x, A, c) - level
        g2 = np.sum(gt * gt, axis=-1)
        ok = g2 > 1e-20 * (1.0 + float(np.max(g2, initial=0.0)))
        step = np.where(ok, f / np.where(ok, g2, 1.0), 0.0)
        step = np.clip(step, -0.05 * r / np.sqrt(np.maximum(g2, 1e-300)), 0.05 * r / np.sqrt(np.maximum(g2, 1e-300)))
        x = x - step[..., None] * gt
        x = r * x / np.linalg.norm(x, axis=-1, keepdims=True)
    return x

