r"""Plotting helpers behind the paper's figures: the momentum sphere, densities, phase portraits.

Every helper draws on a matplotlib ``Axes`` you pass in and takes plain arrays (points on the unit
sphere ``|Π| = 1`` of shape ``(..., 3)``, and functions ``f(Π)`` evaluated on such arrays), so it
works with any simulation, not only the library's. Figures are built with :func:`new_figure`
(a :class:`matplotlib.figure.Figure` that needs no pyplot and no display). One module per concept:
:mod:`.figure`, :mod:`.sphere`, :mod:`.density`, :mod:`.trajectory`, :mod:`.sphere_fields`; every name is importable
from here.

* :func:`plot_trajectory_3d`, :func:`plot_projected_trajectory`: a trajectory on the sphere, in 3D
  and projected on a coordinate plane, coloured by time; :func:`plot_components`: its components
  against time;
* :func:`plot_density`: the time-density of a projected trajectory with the contours of a
  predicted density overlaid (the paper's Gibbs measure ``∝ exp(−2θh̃/σ²)``), binned the same way
  by :func:`projected_density`;
* :func:`plot_sphere_portrait`: a phase portrait, the level sets of a Hamiltonian on the sphere seen
  from a camera, with the equilibria marked; :func:`sphere_image`, :func:`project` and
  :func:`orthographic_basis` are its geometry;
* beyond the paper (Zeitlin's Euler model on the sphere, :mod:`.sphere_fields`): :func:`plot_field_hemisphere`
  and :func:`plot_field_latlon`, a vorticity field in two projections; :func:`enstrophy_spectrum` and
  :func:`plot_enstrophy_spectrum`; :func:`plot_casimir_drift`.

The conventions of the library (``docs/conventions.md``) do not enter here: the caller passes the
functions to draw (e.g. ``rigid_body(...).modified_hamiltonian`` or ``GibbsMeasure(...).density``).

Examples
--------
>>> import numpy as np
>>> from mechanics.paper.plotting import new_figure, plot_density
>>> rng = np.random.default_rng(0)
>>> xy = 0.05 * rng.standard_normal((2000, 2))                  # samples of (Π1, Π2) near e3
>>> fig = new_figure(figsize=(4, 4))
>>> ax = fig.add_subplot()
>>> H, pred, edges = plot_density(ax, xy, bins=20, extent=((-0.3, 0.3), (-0.3, 0.3)),
...                               density_fn=lambda P: np.exp(-200 * (1 - P[..., 2])), hemisphere=1.0)
>>> H.shape, pred.shape
((20, 20), (20, 20))
"""

from __future__ import annotations

from .density import plot_density, projected_density
from .figure import AXIS_LABELS, new_figure
from .sphere import orthographic_basis, plot_sphere_portrait, project, sphere_image
from .sphere_fields import (enstrophy_spectrum, plot_casimir_drift, plot_enstrophy_spectrum, plot_field_hemisphere,
                            plot_field_latlon)
from .trajectory import plot_components, plot_projected_trajectory, plot_trajectory_3d

__all__ = [
    "AXIS_LABELS", "new_figure", "orthographic_basis", "sphere_image", "project", "projected_density",
    "plot_sphere_portrait", "plot_density", "plot_trajectory_3d", "plot_projected_trajectory", "plot_components",
    "plot_field_hemisphere", "plot_field_latlon", "enstrophy_spectrum", "plot_enstrophy_spectrum", "plot_casimir_drift",
]
