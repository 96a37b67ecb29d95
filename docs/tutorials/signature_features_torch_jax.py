"""Tutorial: signature features inside a torch model and a JAX model — telling Brownian motion from fBM.

Run with ``python docs/tutorials/signature_features_torch_jax.py`` (``TUTORIAL_SMALL=1`` for reduced
sizes). Needs the ``torch`` and ``jax`` extras (``pip install -e '.[torch,jax]'``).

Brownian motion and fractional Brownian motion with ``H = 0.4`` have the same variance at every time
(``E|B_t|² = t`` at ``t = 1``) and both are centred Gaussian; what differs is roughness: fBM's
increments over a step ``h`` have size ``h^H``, larger than ``h^½``. A classifier on signature features
learns this from samples. The signature is a layer of the model: a learned linear map mixes the
channels of each path before the signature, so the gradient of the loss flows through
``roughpaths.torch.signature`` (and ``roughpaths.jax.signature``) back to that map.
"""

# %%
import os
import time

import numpy as np

import roughpaths as rp

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")

# %% [markdown]
# ## 1. Data: Brownian paths (label 0) and fBM paths with H = 0.4 (label 1)
# `roughpaths.fbm` samples both exactly on a grid of `[0, 1]` (`H = 0.5` is Brownian motion), in 2
# dimensions. Each path is then augmented by the library's transforms: `rp.lead_lag` (each point
# repeated, the lead copy moving one half-step before the lag copy: `n` points become `2n - 1`, `d`
# channels `2d`), whose level-2 Lévy area between a channel's lead and lag copies is half the path's
# quadratic variation, the roughness the classifier needs, as a signature term; then `rp.time_augment`,
# a time channel `k / (2n - 2)` in front. 2 path channels give `1 + 2 + 2 = 5` channels.

# %%
n_train = 128 if SMALL else 2000
n_steps = 32 if SMALL else 64
depth, width = 3, 3


def sample(n, seed):
    """``n`` Brownian and ``n`` fBM (H = 0.4) paths on ``n_steps`` steps, and their labels."""
    rng = np.random.default_rng(seed)
    bm = rp.fbm(n_steps, 0.5, rng=rng, dim=2, batch_shape=(n,))
    fb = rp.fbm(n_steps, 0.4, rng=rng, dim=2, batch_shape=(n,))
    return np.concatenate([bm, fb]), np.concatenate([np.zeros(n), np.ones(n)])


def augment(x):
    """``(B, n, d)`` paths -> ``(B, 2n - 1, 1 + 2d)``: time, the leading copy, the lagging copy."""
    return rp.time_augment(rp.lead_lag(x))


x_train, y_train = sample(n_train, seed=1)
x_test, y_test = sample(n_train, seed=2)
z_train, z_test = augment(x_train), augment(x_test)
print(f"{len(z_train)} training paths, {len(z_test)} test paths, augmented shape {z_train.shape[1:]}")
# the lead–lag area, read from the library's log-signature, is half the quadratic variation
qv = 0.5 * np.sum(np.diff(x_train[:, :, 0], axis=1) ** 2, axis=1)
area = rp.logsignature(rp.lead_lag(x_train[:, :, :1]), 2)[:, 2]
print(f"lead–lag area vs ½ Σ Δx²: largest difference {np.abs(area - qv).max():.1e}; mean ½ QV of the "
      f"Brownian paths {qv[y_train == 0].mean():.3f} (½ T = 0.5), of the fBM paths {qv[y_train == 1].mean():.3f}")
assert np.allclose(area, qv, rtol=1e-12, atol=1e-14)

# %% [markdown]
# ## 2. The model in torch
# `roughpaths.torch.logsignature` is a `torch.autograd.Function`: forward `roughpaths.logsignature`,
# backward `roughpaths.logsignature_vjp` (the library's compiled kernels; float32 tensors are computed in
# float64 and rounded back; `roughpaths.torch.signature` is the same for the signature). The model:
# a learned channel mixing `5 → 3` at every point, the depth-3 log-signature of the mixed path
# (`3 + 3 + 8 = 14` Lyndon coordinates), each coordinate standardised over the batch, a linear read-out.
# The level-2 coordinates of the mixed path are `W A Wᵀ`, `A` the Lévy-area matrix of the augmented
# path, which holds the lead–lag area: the mixing has to learn to keep it. (Normalising each path's
# features on their own, as a layer norm does, would divide out the very scale that tells the two apart.)

# %%
import torch  # noqa: E402

import roughpaths.torch as rpt  # noqa: E402

torch.manual_seed(0)
torch.set_num_threads(1)   # the model's own tensors are tiny; the signature kernels have their own threads
n_features = rp.logsigdim(width, depth)


class LogSignatureClassifier(torch.nn.Module):
    def __init__(self, channels):
        super().__init__()
        self.mix = torch.nn.Linear(channels, width, bias=False)
        self.norm = torch.nn.BatchNorm1d(n_features, affine=False)
        self.readout = torch.nn.Linear(n_features, 1)

    def forward(self, z):
        return self.readout(self.norm(rpt.logsignature(self.mix(z), depth))).squeeze(-1)


model = LogSignatureClassifier(z_train.shape[-1])
opt = torch.optim.Adam(model.parameters(), lr=0.1)
Z, Y = torch.from_numpy(z_train).float(), torch.from_numpy(y_train).float()
n_epochs = 40 if SMALL else 300
start = time.process_time()
for epoch in range(n_epochs):
    opt.zero_grad()
    loss = torch.nn.functional.binary_cross_entropy_with_logits(model(Z), Y)
    loss.backward()
    opt.step()
with torch.no_grad():   # (the test batch, balanced, is standardised with its own statistics)
    acc_torch = float(((model(torch.from_numpy(z_test).float()) > 0).float() == torch.from_numpy(y_test)).float()
                      .mean())
print(f"torch: final training loss {loss.item():.3f}, test accuracy {acc_torch:.3f} "
      f"({n_epochs} Adam steps, {time.process_time() - start:.1f} s CPU)")
assert model.mix.weight.grad is not None and model.mix.weight.grad.abs().sum() > 0   # gradients reached the mixing
assert acc_torch > 0.85, acc_torch                                                     # chance is 0.5

# %% [markdown]
# ## 3. The same model in JAX
# `roughpaths.jax.logsignature` is a `jax.custom_vjp` whose passes are host calls of the same numpy
# functions (on the CPU an XLA FFI custom call, elsewhere a `jax.pure_callback`): it runs under `jit`
# (the whole training step below is one compiled function, the log-signature a host call inside it),
# `grad` and `vmap`. Same architecture, Adam written out.

# %%
import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402

import roughpaths.jax as rpj  # noqa: E402


def init(key, channels):
    return {"mix": jax.random.normal(key, (channels, width)) / np.sqrt(channels),
            "w": jnp.zeros(n_features), "b": jnp.zeros(())}


def logits(params, z):
    f = rpj.logsignature(z @ params["mix"], depth)
    f = (f - f.mean(0)) / (f.std(0) + 1e-5)           # standardised over the batch, as BatchNorm does
    return f @ params["w"] + params["b"]


def loss_fn(params, z, y):
    lg = logits(params, z)
    return jnp.mean(jnp.maximum(lg, 0) - lg * y + jnp.log1p(jnp.exp(-jnp.abs(lg))))


@jax.jit
def adam_step(params, m, v, k, z, y, lr=0.1, b1=0.9, b2=0.999):
    loss, g = jax.value_and_grad(loss_fn)(params, z, y)
    m = jax.tree_util.tree_map(lambda a, b: b1 * a + (1 - b1) * b, m, g)
    v = jax.tree_util.tree_map(lambda a, b: b2 * a + (1 - b2) * b * b, v, g)
    params = jax.tree_util.tree_map(lambda p, a, b: p - lr * (a / (1 - b1 ** k)) / (jnp.sqrt(b / (1 - b2 ** k)) + 1e-8),
                                    params, m, v)
    return params, m, v, loss


params = init(jax.random.PRNGKey(0), z_train.shape[-1])
m = jax.tree_util.tree_map(jnp.zeros_like, params)
v = jax.tree_util.tree_map(jnp.zeros_like, params)
zj, yj = jnp.asarray(z_train, jnp.float32), jnp.asarray(y_train, jnp.float32)
start = time.process_time()
for k in range(1, n_epochs + 1):
    params, m, v, loss = adam_step(params, m, v, k, zj, yj)
acc_jax = float(jnp.mean((logits(params, jnp.asarray(z_test, jnp.float32)) > 0) == (y_test > 0)))
print(f"jax:   final training loss {float(loss):.3f}, test accuracy {acc_jax:.3f} "
      f"({n_epochs} Adam steps, {time.process_time() - start:.1f} s CPU)")
assert acc_jax > 0.85, acc_jax

# %% [markdown]
# ## 4. One kernel underneath
# Both front ends call the same numpy function, so with the same mixing weights they give the same
# features, and the same as `roughpaths.signature` itself; `vmap` over paths is one batched call.

# %%
W = np.asarray(params["mix"], dtype=np.float64)
mixed = z_test[:8] @ W
f_np = rp.signature(mixed, depth)
f_torch = rpt.signature(torch.from_numpy(mixed), depth).numpy()
f_jax = np.asarray(jax.vmap(lambda p: rpj.signature(p, depth))(jnp.asarray(mixed)))
print(f"max |torch − numpy| = {np.abs(f_torch - f_np).max():.1e}, max |jax − numpy| = {np.abs(f_jax - f_np).max():.1e}"
      f" (JAX without x64 rounds to float32)")
assert np.abs(f_torch - f_np).max() == 0.0
assert np.abs(f_jax - f_np).max() < 1e-5 * (1 + np.abs(f_np).max())
