"""Tutorial: adaptive steps at strong order 1, on one Brownian path queried at every resolution.

Run with ``python docs/tutorials/adaptive_steps.py`` (``TUTORIAL_SMALL=1`` for reduced sizes).

A `roughpaths.BrownianTree` holds one Brownian path per batch member and answers its increment and
Lévy area on any interval. ``solve(..., step_control=PIController(rtol, atol))`` uses that: it tries a
step, estimates its error by step doubling, and on rejection asks the same tree about a shorter interval.
The path never changes, so the error is measured against a fine fixed-step solve on the same tree.
"""

# %%
import os

import numpy as np

import roughpaths as rp

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
PATHS = 16 if SMALL else 64
M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))      # two non-commuting linear fields
Y0 = np.ones(3)


def rms(a, b):
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


# %% [markdown]
# ## 1. One path, any interval
# The tree's answers depend on the seed and the interval only. Chen's identity holds across any
# subdivision, so a step and its two halves see the same path.

# %%
tree = rp.BrownianTree(2, seed=7, batch_shape=(PATHS,))
s, u, t = 0.2, 0.2 + 1e-3 * np.pi, 0.5
x1, a1 = tree.increment(s, u), tree.area(s, u)
x2, a2 = tree.increment(u, t), tree.area(u, t)
chen = tree.area(s, t) - (a1 + a2 + x1[:, :, None] * x2[:, None, :])
print(f"Chen's identity on [{s}, {u:.5f}, {t}]: max defect {np.abs(chen).max():.1e}")
assert np.abs(chen).max() < 1e-12

# %% [markdown]
# ## 2. Strong error proportional to the tolerance
# ``dY = Σ_i M_i Y ∘dW^i`` with non-commuting ``M_i``: Davie's scheme, adaptive, against a fixed-step
# solve with 2^12 steps on the same tree. The controller bounds the *predicted global* error, so the
# error falls like ``rtol`` (not ``rtol^(2/3)``, what bounding the error per step would give). By default
# ``Davie`` on autonomous fields gives every path steps of its own. A path's error estimate is one random
# draw, so at these coarse tolerances (tens to hundreds of steps a path) the error is heavy-tailed, up to ten
# times ``rtol`` (``docs/adaptive-steps.md``). Shared steps (``shared_steps=True``: the error ratio is the
# maximum over the paths) follow the most demanding path: far more steps, a smaller error, printed last.

# %%
V = rp.LinearVectorFields(M)
ref = rp.solve(V, tree.rough_path(np.linspace(0.0, 1.0, 2 ** 12 + 1)), Y0, rp.Davie(), save_at="end").final
rtols = [3e-2, 1e-2, 3e-3] if SMALL else [3e-2, 1e-2, 3e-3, 1e-3]
errors = []
for rtol in rtols:
    sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(rtol, rtol), save_at="end")
    errors.append(rms(sol.final, ref))
    print(f"rtol {rtol:.0e}: error {errors[-1]:.2e}, {sol.stats['accepted'].mean():.0f} steps accepted on average "
          f"(from {sol.stats['accepted'].min()} to {sol.stats['accepted'].max()}), "
          f"{sol.stats['rejected'].mean():.0f} rejected")
slope = np.polyfit(np.log(rtols), np.log(errors), 1)[0]
print(f"error ~ rtol^{slope:.2f}")
assert 0.8 < slope < 1.5          # about 1; 2/3 (an error bound per step) is ruled out
shared = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(rtols[-1], rtols[-1]), save_at="end",
                  shared_steps=True)
print(f"shared steps at rtol {rtols[-1]:.0e}: error {rms(shared.final, ref):.2e}, {shared.stats['accepted']} steps")

# %% [markdown]
# ## 3. A burst of noise
# Now the noise is 16 times stronger for a few hundredths of the interval:
# ``σ(t) = 0.2 + 3 exp(-((t - 0.5)/0.02)²)``. The adaptive solve spends its steps there; a uniform grid
# with as many steps cannot. ``dt_max`` keeps the first steps from jumping over the burst (the error
# estimate only sees the fields where it evaluates them). These fields take the time as a float, so the
# batch shares its steps (``shared_steps=None`` picks that; declare ``batched_time=True`` on fields that
# broadcast an array of times, and each path takes its own steps, as in ``benchmarks/bench_adaptive_steps.py``).

# %%
def sigma(t):
    return 0.2 + 3.0 * np.exp(-((t - 0.5) / 0.02) ** 2)


burst = rp.VectorFields(lambda t, y: sigma(t) * np.einsum("iab,...b->...ai", M, y),
                        lambda t, y: np.broadcast_to(sigma(t) * M, y.shape[:-1] + M.shape),
                        dim_state=3, dim_noise=2, time_dependent=True)
inner, tol = (14, 1e-2) if SMALL else (17, 3e-3)
grid = np.unique(np.concatenate([np.linspace(0, 1, 2 ** 12 + 1), np.arange(0.375, 0.625, 2.0 ** -inner)]))
ref = rp.solve(burst, tree.rough_path(grid), Y0, rp.Davie(), save_at="end").final
sol = rp.solve(burst, tree, Y0, rp.Davie(), step_control=rp.PIController(tol, tol, dt_max=1 / 64))
h = np.diff(sol.times)
mid = 0.5 * (sol.times[1:] + sol.times[:-1])
print(f"median step inside the burst {np.median(h[np.abs(mid - 0.5) < 0.02]):.1e}, "
      f"outside {np.median(h[np.abs(mid - 0.5) > 0.1]):.1e}")
n = sol.stats["accepted"]
even = np.round(np.linspace(0, 1, n + 1) * 2.0 ** 24) / 2.0 ** 24   # n uniform steps, ends on the 2^-24 grid
uniform = rp.solve(burst, tree.rough_path(even), Y0, rp.Davie(), save_at="end").final
e_adapt, e_unif = rms(sol.final, ref), rms(uniform, ref)
print(f"{n} steps: adaptive error {e_adapt:.2e}, uniform grid {e_unif:.2e} ({e_unif / e_adapt:.1f}x larger)")
assert e_unif > 2 * e_adapt

# %% [markdown]
# ## 4. The stochastic rigid body
# The coadjoint ``LieHeun`` of ``mechanics`` takes the same ``step_control``, with steps per path by default;
# the Casimir ``|Π|`` is kept to round-off whatever the steps.

# %%
from mechanics import LieHeun, rigid_body  # noqa: E402

body = rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0)
tree3 = rp.BrownianTree(3, seed=8, batch_shape=(PATHS,))
sol = rp.solve(body, tree3, np.array([0.0, 0.0, 1.0]), LieHeun(), step_control=rp.PIController(1e-3, 1e-3))
drift = np.abs(np.linalg.norm(sol.states, axis=-1) - 1.0).max()
acc = sol.stats["accepted"]                       # per path: each path took steps of its own
print(f"rigid body: {acc.min()} to {acc.max()} steps per path, max ||Π| - 1| = {drift:.1e}")
assert drift < 1e-12
