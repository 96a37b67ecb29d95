"""Tutorial: drawing on the momentum sphere with ``mechanics.paper.plotting``.

The plotting helpers behind the paper's figures are public and take plain arrays, so they draw any
simulation: a trajectory on the sphere ``|Π| = 1`` in 3D (``plot_trajectory_3d``), the
time-density of its projection with the Gibbs prediction ``∝ exp(−2θh̃/σ²)`` overlaid
(``plot_density``), and the phase portrait of ``h̃`` with its equilibria (``plot_sphere_portrait``).
Figures are ``matplotlib.figure.Figure`` objects made by ``new_figure`` (no pyplot, no display).

Run: ``python docs/tutorials/plotting_sphere.py`` (writes three PNGs into ``$TUTORIAL_OUTPUT`` or the
current folder). Signs and factors: docs/conventions.md.
"""

import os
from pathlib import Path

import numpy as np

import mechanics
import roughpaths
from mechanics.paper.plotting import new_figure, plot_density, plot_sphere_portrait, plot_trajectory_3d

small = os.environ.get("TUTORIAL_SMALL") == "1"
out = Path(os.environ.get("TUTORIAL_OUTPUT", "."))
inertia, sigma, theta = (1.0, 2.0, 3.0), 0.05, 1.0
s = np.array([[0.0, 0.0, 25.0], [0.0, 0.0, 0.0], [-25.0, 0.0, 0.0]])     # s13 = 25
body = mechanics.rigid_body(inertia, sigma=sigma, s=s, theta=theta)
print("Lévy torque c =", np.round(body.levy_velocity, 4))                 # σ²(s23, −s13, s12)

# 1. one long trajectory from e3, saved every 10 steps
dt, n = 0.005, (20_000 if small else 200_000)
driver = roughpaths.BrownianDriver(3, seed=1, dt=dt, n_steps=n)                # lazy, seeded, block-wise
sol = roughpaths.solve(body, driver, [0.0, 0.0, 1.0], mechanics.LieHeun(), save_at=driver.times[::10])
times, traj = sol.times, sol.states
assert np.allclose(np.linalg.norm(traj, axis=-1), 1.0, atol=1e-12)      # on the sphere

fig = new_figure(figsize=(5, 5))
ax = fig.add_subplot(projection="3d")
plot_trajectory_3d(ax, traj, start=traj[0], times=times, title="a trajectory on |Π| = 1")
ax.view_init(elev=28, azim=-55)
fig.savefig(out / "plot_trajectory_3d.png", dpi=80)

# 2. its time-density in the (Π1, Π2) plane against the Gibbs measure of h̃ (north hemisphere)
gibbs = mechanics.GibbsMeasure(inertia, body.levy_velocity, sigma=sigma, theta=theta)
keep = times >= 10.0                                                        # after a burn-in
fig = new_figure(figsize=(5.5, 4.5), layout="constrained")
H, predicted, (xe, ye) = plot_density(fig.add_subplot(), traj[keep][:, :2], bins=40,
                                      extent=((-0.3, 0.3), (0.1, 0.7)), density_fn=gibbs.density,
                                      hemisphere=1.0, start=traj[0], title="time-density and Gibbs prediction")
fig.savefig(out / "plot_density.png", dpi=80)
# the binned prediction is a density on the plane like the normalised histogram: compare centroids
xc, yc = 0.5 * (xe[1:] + xe[:-1]), 0.5 * (ye[1:] + ye[:-1])
centroid = lambda D: np.array([xc @ D.sum(axis=1), yc @ D.sum(axis=0)]) / D.sum()
print("centroid of the time-density", np.round(centroid(H), 3), "of the Gibbs prediction",
      np.round(centroid(predicted), 3))
assert np.max(np.abs(centroid(H) - centroid(predicted))) < 0.03

# 3. the phase portrait of h̃ (θ = 0: the level sets are the orbits), equilibria from h̃
levels = mechanics.rigid_body_level_sets(inertia, body.levy_velocity, levels=8 if small else 16,
                                         include_separatrices=True)
fig = new_figure(figsize=(5.5, 5.8))
plot_sphere_portrait(fig.add_subplot(), body.modified_hamiltonian, elev=22, azim=35, curves=levels.curves,
                     separatrix=levels.separatrix, equilibria=[(e.point, e.kind) for e in levels.equilibria],
                     n=200 if small else 400, title="level sets of h̃, s13 = 25")
fig.savefig(out / "plot_sphere_portrait.png", dpi=80)
print("equilibria of h̃:", ", ".join(f"{e.kind} at {np.round(e.point, 3)}" for e in levels.equilibria))
print("wrote", ", ".join(p.name for p in sorted(out.glob("plot_*.png"))))
