r"""Fields on the sphere (beyond the paper: Zeitlin's Euler model): two projections, the enstrophy spectrum and
the Casimir drift.

Every helper draws on a matplotlib ``Axes`` you pass in and takes plain arrays: a field sampled on a
latitude–longitude grid (colatitudes ``theta (n_lat,)`` in :math:`(0, \pi)`, longitudes ``phi (n_lon,)`` in
:math:`[0, 2\pi)`, values ``(n_lat, n_lon)``, e.g. from :func:`mechanics.sphere.matrix_to_grid` on
:func:`mechanics.sphere.sphere_grid`), spherical-harmonic coefficients ``omega[..., l*(l+1)+m]``, or time series.

* :func:`plot_field_hemisphere`: an orthographic view of one hemisphere, from above the north pole (screen axes
  :math:`x_1` right, :math:`x_2` up) or from below the south pole (:math:`x_1` right, :math:`-x_2` up, as seen
  from there); the disc's edge is the equator;
* :func:`plot_field_latlon`: the plate carrée projection (longitude, latitude in degrees);
* :func:`enstrophy_spectrum` and :func:`plot_enstrophy_spectrum`: :math:`Z_l = \tfrac12\sum_m|\omega_{lm}|^2`
  per degree (they sum to the enstrophy :math:`\tfrac12\int\omega^2dA`);
* :func:`plot_casimir_drift`: :math:`|C_k(t) - C_k(0)|` relative to a scale, per order, on a log axis.

Examples
--------
>>> import numpy as np
>>> from mechanics.paper.plotting import new_figure
>>> from mechanics.paper.plotting.sphere_fields import enstrophy_spectrum, plot_field_hemisphere
>>> theta = np.linspace(0.05, np.pi - 0.05, 16)
>>> phi = 2 * np.pi * np.arange(32) / 32
>>> field = np.cos(theta)[:, None] * np.ones(32)
>>> ax = new_figure().add_subplot()
>>> mesh = plot_field_hemisphere(ax, theta, phi, field, "north")
>>> omega = np.zeros(9, complex); omega[2] = 2.0     # l = 1, m = 0
>>> enstrophy_spectrum(omega).tolist()
[0.0, 2.0, 0.0]
"""

from __future__ import annotations

import numpy as np

__all__ = ["plot_field_hemisphere", "plot_field_latlon", "enstrophy_spectrum", "plot_enstrophy_spectrum",
           "plot_casimir_drift"]

_VIEWS = ("north", "south")


def _grid(theta, phi, values):
    theta = np.asarray(theta, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    if theta.ndim != 1 or phi.ndim != 1 or values.shape != (theta.size, phi.size):
        raise ValueError(f"values must have shape (len(theta), len(phi)) = ({theta.size}, {phi.size}) with 1-D "
                         f"theta and phi, got theta {theta.shape}, phi {phi.shape}, values {values.shape}.")
    # close the longitude circle (the last column repeats the first, at phi + 2 pi)
    return theta, np.append(phi, phi[0] + 2.0 * np.pi), np.concatenate([values, values[:, :1]], axis=1)


def _with_poles(th, val):
    """Close the caps at the poles with the mean of the nearest ring (the grid's colatitudes avoid the poles)."""
    if th[0] > 0.0:
        th, val = np.append(0.0, th), np.concatenate([np.full((1, val.shape[1]), val[0].mean()), val])
    if th[-1] < np.pi:
        th, val = np.append(th, np.pi), np.concatenate([val, np.full((1, val.shape[1]), val[-1].mean())])
    return th, val


def plot_field_hemisphere(ax, theta, phi, values, view: str = "north", *, vmin=None, vmax=None, cmap="RdBu_r",
                          title: str | None = None):
    """An orthographic view of one hemisphere of a field on the sphere; returns the ``QuadMesh``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    theta, phi : array_like, shapes ``(n_lat,)`` and ``(n_lon,)``
        Colatitudes and longitudes (radians) of the grid.
    values : array_like, shape ``(n_lat, n_lon)``
    view : {"north", "south"}
        The hemisphere, seen from outside above its pole.
    vmin, vmax : float, optional
        Colour limits (default: symmetric about 0, the field's largest magnitude).
    cmap : str
    title : str, optional
    """
    if view not in _VIEWS:
        raise ValueError(f"view must be 'north' or 'south', got {view!r}.")
    th, ph, val = _grid(theta, phi, values)
    th, val = _with_poles(th, val)
    keep = th <= np.pi / 2 if view == "north" else th >= np.pi / 2
    if np.count_nonzero(keep) < 2:
        raise ValueError(f"the grid has no colatitude in the {view}ern hemisphere.")
    th, val = th[keep], val[keep]
    T, P = np.meshgrid(th, ph, indexing="ij")
    x, y = np.sin(T) * np.cos(P), np.sin(T) * np.sin(P)
    if view == "south":
        y = -y
    lim = float(np.max(np.abs(val))) or 1.0
    mesh = ax.pcolormesh(x, y, val, shading="gouraud", cmap=cmap,
                         vmin=-lim if vmin is None else vmin, vmax=lim if vmax is None else vmax)
    circle = np.linspace(0.0, 2.0 * np.pi, 200)
    ax.plot(np.cos(circle), np.sin(circle), color="0.3", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title if title is not None else f"{view}ern hemisphere", fontsize=9)
    return mesh


def plot_field_latlon(ax, theta, phi, values, *, vmin=None, vmax=None, cmap="RdBu_r", title: str | None = None):
    """The field in the plate carrée projection (longitude and latitude in degrees); returns the ``QuadMesh``.

    Parameters as for :func:`plot_field_hemisphere`.
    """
    th, ph, val = _grid(theta, phi, values)
    th, val = _with_poles(th, val)
    lim = float(np.max(np.abs(val))) or 1.0
    mesh = ax.pcolormesh(np.degrees(ph), 90.0 - np.degrees(th), val, shading="gouraud", cmap=cmap,
                         vmin=-lim if vmin is None else vmin, vmax=lim if vmax is None else vmax)
    ax.set_xlim(0.0, 360.0)
    ax.set_ylim(-90.0, 90.0)
    ax.set_xticks([0, 90, 180, 270, 360])
    ax.set_yticks([-90, -45, 0, 45, 90])
    ax.set_xlabel("longitude (°)", fontsize=8)
    ax.set_ylabel("latitude (°)", fontsize=8)
    ax.tick_params(labelsize=7)
    if title is not None:
        ax.set_title(title, fontsize=9)
    return mesh


def enstrophy_spectrum(omega) -> np.ndarray:
    r"""The enstrophy per degree, :math:`Z_l = \tfrac12\sum_{m=-l}^{l}|\omega_{lm}|^2`, shape ``(..., L)``.

    ``omega`` has shape ``(..., L**2)``, flat as ``omega[..., l*(l+1)+m]`` (orthonormal harmonics:
    :math:`\sum_l Z_l = \tfrac12\int\omega^2dA`).
    """
    omega = np.asarray(omega)
    L = int(round(np.sqrt(omega.shape[-1])))
    if omega.ndim < 1 or L * L != omega.shape[-1]:
        raise ValueError(f"omega must have a last axis of length L**2 (degrees l < L), got shape {omega.shape}.")
    power = 0.5 * np.abs(omega) ** 2
    degree = np.repeat(np.arange(L), 2 * np.arange(L) + 1)
    out = np.zeros(omega.shape[:-1] + (L,))
    for l in range(L):
        out[..., l] = power[..., degree == l].sum(axis=-1)
    return out


def plot_enstrophy_spectrum(ax, spectra: dict):
    """Enstrophy spectra ``{label: Z_l (L,)}`` against the degree ``l >= 1`` on a log axis (zeros left out)."""
    for label, z in spectra.items():
        z = np.asarray(z, dtype=np.float64)
        ax.semilogy(np.arange(1, z.size), np.where(z[1:] > 0, z[1:], np.nan), marker=".", ms=3, lw=1, label=label)
    ax.set_xlabel("degree l", fontsize=8)
    ax.set_ylabel(r"$Z_l = \frac{1}{2}\sum_m |\omega_{lm}|^2$", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)


def plot_casimir_drift(ax, times, drift, orders, *, label_prefix: str = "", linestyle="-", floor: float = 1e-18):
    """Relative Casimir drifts ``drift (n_times, len(orders))`` against ``times`` on a log axis, one line per order."""
    drift = np.asarray(drift, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    if drift.shape != (times.size, len(orders)):
        raise ValueError(f"drift must have shape (len(times), len(orders)) = ({times.size}, {len(orders)}), "
                         f"got {drift.shape}.")
    for j, k in enumerate(orders):
        ax.semilogy(times, np.maximum(drift[:, j], floor), lw=1, linestyle=linestyle,
                    label=f"{label_prefix}k = {k}")
    ax.set_xlabel("t", fontsize=8)
    ax.set_ylabel(r"$|C_k(t) - C_k(0)| / \sum_j |\lambda_j|^k$", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
