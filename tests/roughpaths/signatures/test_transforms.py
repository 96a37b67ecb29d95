"""Path transforms (lead–lag, time, basepoint, invisibility reset): against loops written here, against
closed-form signature terms they are known for (the lead–lag area is the quadratic variation), and their
torch and JAX versions against the numpy ones, values and gradients."""

from __future__ import annotations

import math

import zlib

import numpy as np
import pytest

import roughpaths as rp


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own id: its numbers do not depend on which tests ran before it."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


def _paths(rng, batch, n, d):
    return rng.normal(size=batch + (n, d)).cumsum(axis=-2)


# ------------------------------------------------------------------------------ naive constructions
def _naive_lead_lag(x):
    n, d = x.shape
    out = []
    for k in range(n):
        out.append(list(x[k]) + list(x[k]))
        if k + 1 < n:
            out.append(list(x[k + 1]) + list(x[k]))
    return np.array(out).reshape(2 * n - 1, 2 * d)


def _naive_time(x, t):
    return np.array([[t[k]] + list(x[k]) for k in range(x.shape[0])])


def _naive_basepoint(x):
    return np.array([[0.0] * x.shape[1]] + [list(p) for p in x])


def _naive_invisibility_reset(x):
    pts = [[1.0] + list(p) for p in x]
    pts.append([0.0] + list(x[-1]))
    pts.append([0.0] * (x.shape[1] + 1))
    return np.array(pts)


def _each(batch_array, fn, *extra):
    """Apply a one-path function to every path of a batch, by loops."""
    flat = batch_array.reshape(-1, *batch_array.shape[-2:])
    outs = [fn(p, *[e[i] if e is not None and np.ndim(e) > 1 else e for e in extra]) for i, p in enumerate(flat)]
    return np.stack(outs).reshape(batch_array.shape[:-2] + outs[0].shape)


@pytest.mark.parametrize("batch, n, d", [((), 1, 1), ((), 2, 3), ((2, 3), 7, 2), ((4,), 5, 1)])
def test_transforms_match_loops(rng, batch, n, d):
    x = _paths(rng, batch, n, d)
    t_default = [k / max(n - 1, 1) for k in range(n)]
    np.testing.assert_array_equal(rp.lead_lag(x), _each(x, _naive_lead_lag))
    np.testing.assert_array_equal(rp.time_augment(x), _each(x, lambda p: _naive_time(p, t_default)))
    np.testing.assert_array_equal(rp.basepoint(x), _each(x, _naive_basepoint))
    np.testing.assert_array_equal(rp.invisibility_reset(x), _each(x, _naive_invisibility_reset))
    assert rp.lead_lag(x).shape == batch + (2 * n - 1, 2 * d)
    assert rp.time_augment(x).shape == batch + (n, d + 1)
    assert rp.basepoint(x).shape == batch + (n + 1, d)
    assert rp.invisibility_reset(x).shape == batch + (n + 2, d + 1)


def test_time_augment_with_given_times_batched(rng):
    x = _paths(rng, (3,), 6, 2)
    t = np.sort(rng.uniform(size=(3, 6)), axis=-1)
    got = rp.time_augment(x, t)
    for i in range(3):
        np.testing.assert_array_equal(got[i], _naive_time(x[i], t[i]))
    one = np.array([0.0, 0.1, 0.5, 0.7, 2.0, 3.0])
    np.testing.assert_array_equal(rp.time_augment(x, one)[2], _naive_time(x[2], one))


# ------------------------------------------------------------------------------ signature identities
def _shoelace_area(x, i, j):
    """Lévy area ½ ∫ (x^i - x^i_0) dx^j - (x^j - x^j_0) dx^i of a polygon, by the shoelace sum."""
    y = x - x[0]
    return 0.5 * sum(y[k, i] * y[k + 1, j] - y[k, j] * y[k + 1, i] for k in range(len(x) - 1))


def _level2(sig, dim):
    return sig[..., dim:dim + dim * dim].reshape(sig.shape[:-1] + (dim, dim))


@pytest.mark.parametrize("n, d", [(2, 1), (30, 3), (200, 2)])
def test_lead_lag_area_is_half_the_quadratic_variation(rng, n, d):
    """½ (S^{(i, d+j)} - S^{(d+j, i)}) = ½ Σ Δx^i Δx^j + A^{ij}(x): the quadratic (co)variation, plus the
    path's own Lévy area off the diagonal."""
    x = _paths(rng, (), n, d) * 0.3
    S2 = _level2(rp.signature(rp.lead_lag(x), 2), 2 * d)
    dx = np.diff(x, axis=0)
    for i in range(d):
        for j in range(d):
            got = 0.5 * (S2[i, d + j] - S2[d + j, i])
            want = 0.5 * sum(dx[k, i] * dx[k, j] for k in range(n - 1)) + _shoelace_area(x, i, j)
            scale = 1.0 + float(np.sum(np.abs(dx)) ** 2)
            assert abs(got - want) <= 1e-13 * scale, (i, j, got, want)
    qv = 0.5 * np.sum(dx ** 2, axis=0)                           # and the library's log-signature says so
    labels = rp.lyndon_basis(2 * d, 2)
    logsig = rp.logsignature(rp.lead_lag(x), 2)
    for i in range(d):
        assert abs(logsig[labels.index(f"[{i + 1},{d + i + 1}]")] - qv[i]) <= 1e-13 * (1 + qv[i])


def test_lead_lag_quadratic_variation_of_brownian_motion_is_time(rng):
    """On Brownian motion the lead–lag area tends to ½ T (the quadratic variation), one path, fine grid."""
    n, T = 200_001, 2.0
    w = np.concatenate([[0.0], rng.normal(scale=math.sqrt(T / (n - 1)), size=n - 1).cumsum()])[:, None]
    area = rp.logsignature(rp.lead_lag(w), 2)[2]
    assert abs(area - 0.5 * T) < 5 * 0.5 * T * math.sqrt(2.0 / (n - 1))     # sd of ½ Σ Δ² is ½ T sqrt(2/N)


def _exp_segment(v, depth):
    """Signature of one straight segment with increment v: v^{⊗k} / k!, flat."""
    out, p = [], np.ones(1)
    for k in range(1, depth + 1):
        p = np.multiply.outer(p, v).ravel() / k
        out.append(p)
    return np.concatenate(out)


def test_basepoint_signature_is_the_segment_from_the_origin_then_the_path(rng):
    x = _paths(rng, (), 9, 2) + 3.0
    got = rp.signature(rp.basepoint(x), 3)
    want = rp.tensor_product(_exp_segment(x[0], 3), rp.signature(x, 3), 2)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    np.testing.assert_allclose(got[:2], x[-1], rtol=1e-14)
    # the plain signature cannot see a translation; with the basepoint it does
    assert np.allclose(rp.signature(x, 3), rp.signature(x + 1.0, 3))
    assert not np.allclose(rp.signature(rp.basepoint(x), 3), rp.signature(rp.basepoint(x + 1.0), 3))


def test_time_channel_terms(rng):
    """S^{(0, i)} = ∫ (t - t_0) dx^i: on a linear step, Δx^i ((t_k + t_{k+1}) / 2 - t_0)."""
    x = _paths(rng, (), 12, 2)
    t = np.sort(rng.uniform(0, 5, size=12))
    S2 = _level2(rp.signature(rp.time_augment(x, t), 2), 3)
    for i in range(2):
        want = sum((x[k + 1, i] - x[k, i]) * (0.5 * (t[k] + t[k + 1]) - t[0]) for k in range(11))
        assert abs(S2[0, 1 + i] - want) <= 1e-12 * (1 + np.abs(x).max() * t[-1])


def test_invisibility_reset_terms(rng):
    """Level 1 is (-1, -x_0); S^{(0, 1+i)} = x^i_{n-1} (the return while invisible), S^{(1+i, 0)} = -(x_{n-1} - x_0)^i."""
    x = _paths(rng, (), 8, 2) + np.array([2.0, -1.0])
    sig = rp.signature(rp.invisibility_reset(x), 2)
    np.testing.assert_allclose(sig[:3], np.concatenate([[-1.0], -x[0]]), atol=1e-13)
    S2 = _level2(sig, 3)
    for i in range(2):
        assert abs(S2[0, 1 + i] - x[-1, i]) <= 1e-12 * (1 + np.abs(x).max())
        assert abs(S2[1 + i, 0] + (x[-1, i] - x[0, i])) <= 1e-12 * (1 + np.abs(x).max())


# ------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize("call, exc, word", [
    (lambda: rp.lead_lag("path"), TypeError, "paths"),
    (lambda: rp.lead_lag(np.ones(3)), ValueError, "paths"),
    (lambda: rp.basepoint(np.ones((0, 2))), ValueError, "paths"),
    (lambda: rp.invisibility_reset(np.ones((3, 0))), ValueError, "paths"),
    (lambda: rp.lead_lag(np.array([[0.0], [np.nan]])), ValueError, "paths"),
    (lambda: rp.time_augment(np.ones((3, 2)), [0.0, 1.0]), ValueError, "times"),
    (lambda: rp.time_augment(np.ones((3, 2)), [0.0, 1.0, 1.0]), ValueError, "times"),
    (lambda: rp.time_augment(np.ones((3, 2)), np.zeros((2, 3)) + [0, 1, 2]), ValueError, "times"),
    (lambda: rp.time_augment(np.ones((3, 2)), "abc"), TypeError, "times"),
])
def test_bad_input_is_refused(call, exc, word):
    with pytest.raises(exc, match=word):
        call()


# ------------------------------------------------------------------------------ torch and JAX
NP_TRANSFORMS = {"lead_lag": rp.lead_lag, "time_augment": rp.time_augment, "basepoint": rp.basepoint,
                 "invisibility_reset": rp.invisibility_reset}


def _jacobian(fn, shape):
    """The numpy transform's Jacobian, column by column (an affine map: f(e_j) - f(0))."""
    base = fn(np.zeros(shape)).ravel()
    cols = []
    for j in range(int(np.prod(shape))):
        e = np.zeros(int(np.prod(shape)))
        e[j] = 1.0
        cols.append(fn(e.reshape(shape)).ravel() - base)
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("name", sorted(NP_TRANSFORMS))
def test_torch_transforms_values_and_gradients(rng, name):
    torch = pytest.importorskip("torch")
    import roughpaths.torch as rpt

    x = _paths(rng, (2,), 4, 3)
    xt = torch.tensor(x, dtype=torch.float64, requires_grad=True)
    out = getattr(rpt, name)(xt)
    np.testing.assert_array_equal(out.detach().numpy(), NP_TRANSFORMS[name](x))
    w = rng.normal(size=out.shape)
    (out * torch.from_numpy(w)).sum().backward()
    J = _jacobian(NP_TRANSFORMS[name], x.shape)
    np.testing.assert_allclose(xt.grad.numpy().ravel(), J.T @ w.ravel(), rtol=1e-14, atol=1e-14)
    assert getattr(rpt, name)(xt.float()).dtype == torch.float32
    with pytest.raises(TypeError, match="paths"):
        getattr(rpt, name)(torch.ones(3, 2, dtype=torch.int64))
    with pytest.raises(ValueError, match="paths"):
        getattr(rpt, name)(torch.ones(3))


@pytest.mark.parametrize("name", sorted(NP_TRANSFORMS))
def test_jax_transforms_values_and_gradients(rng, name):
    jax = pytest.importorskip("jax")
    import jax.numpy as jnp

    import roughpaths.jax as rpj

    x = _paths(rng, (2,), 4, 3).astype(np.float32)
    fn = getattr(rpj, name)
    np.testing.assert_allclose(np.asarray(fn(jnp.asarray(x))), NP_TRANSFORMS[name](x), rtol=1e-7, atol=1e-7)
    np.testing.assert_array_equal(np.asarray(jax.jit(fn)(jnp.asarray(x))), np.asarray(fn(jnp.asarray(x))))
    w = rng.normal(size=np.shape(fn(jnp.asarray(x)))).astype(np.float32)
    g = jax.grad(lambda z: jnp.sum(fn(z) * w))(jnp.asarray(x))
    J = _jacobian(NP_TRANSFORMS[name], x.shape)
    np.testing.assert_allclose(np.asarray(g).ravel(), J.T @ w.ravel().astype(np.float64), rtol=1e-6, atol=1e-6)
    with pytest.raises(ValueError, match="paths"):
        fn(jnp.ones(3))


def test_torch_time_augment_times_and_a_signature_through_it(rng):
    torch = pytest.importorskip("torch")
    import roughpaths.torch as rpt

    x = _paths(rng, (3,), 5, 2)
    t = np.sort(rng.uniform(size=(3, 5)), axis=-1)
    got = rpt.time_augment(torch.from_numpy(x), torch.from_numpy(t)).numpy()
    np.testing.assert_array_equal(got, rp.time_augment(x, t))
    with pytest.raises(ValueError, match="times"):
        rpt.time_augment(torch.from_numpy(x), torch.zeros(5, dtype=torch.float64))
    # the transform composes with the library's differentiable signature: the gradient of the lead–lag
    # area (half the quadratic variation, ½ Σ Δx²) is Δ-differences of the path
    p = torch.tensor(x[0, :, :1], requires_grad=True)
    rpt.logsignature(rpt.lead_lag(p), 2)[2].backward()
    dx = np.diff(x[0, :, 0])
    want = np.concatenate([[-dx[0]], dx[:-1] - dx[1:], [dx[-1]]])
    np.testing.assert_allclose(p.grad.numpy()[:, 0], want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("n", [7, 10, 49, 1001])
def test_jax_default_times_are_the_correctly_rounded_quotients(n):
    """The default time channel is ``k / (n - 1)`` rounded once, as the numpy and torch versions give it
    (the docstring's promise): XLA rewrote the division by the constant ``n - 1`` as a product with its
    reciprocal, which moved some times by one unit in the last place (n = 7: t_2)."""
    jax = pytest.importorskip("jax")
    import jax.numpy as jnp

    import roughpaths.jax as rpj

    want = np.array([k / (n - 1) for k in range(n)])          # Python's division is correctly rounded
    got32 = np.asarray(rpj.time_augment(jnp.zeros((n, 1), dtype=jnp.float32)))[:, 0]
    np.testing.assert_array_equal(got32, want.astype(np.float32))
    np.testing.assert_array_equal(np.asarray(jax.jit(rpj.time_augment)(jnp.zeros((n, 1), dtype=jnp.float32)))[:, 0],
                                  want.astype(np.float32))
    old = jax.config.read("jax_enable_x64")
    jax.config.update("jax_enable_x64", True)
    try:
        got64 = np.asarray(rpj.time_augment(jnp.zeros((n, 1), dtype=jnp.float64)))[:, 0]
    finally:
        jax.config.update("jax_enable_x64", old)
    np.testing.assert_array_equal(got64, want)
    np.testing.assert_array_equal(got64, rp.time_augment(np.zeros((n, 1)))[:, 0])


@pytest.mark.parametrize("t_shape", [(4, 3), (2, 3), (5, 1, 3)])
def test_frontend_times_with_batch_axes_paths_lack_are_refused_naming_times(t_shape):
    """times whose batch axes do not broadcast to those of paths (3 points, shape (3, 2) or (2, 3, 2) here):
    the numpy function refuses them naming ``times``; torch raised its own RuntimeError from ``expand`` and
    JAX a ValueError about broadcast_to that named neither argument."""
    torch = pytest.importorskip("torch")
    jax = pytest.importorskip("jax")
    import jax.numpy as jnp

    import roughpaths.jax as rpj
    import roughpaths.torch as rpt

    times = np.broadcast_to(np.arange(3.0), t_shape).copy()
    paths = np.zeros((3, 2)) if t_shape != (2, 3) else np.zeros((4, 3, 2))
    with pytest.raises(ValueError, match="times"):
        rp.time_augment(paths, times)
    with pytest.raises(ValueError, match=r"times of shape .* does not broadcast"):
        rpt.time_augment(torch.from_numpy(paths), torch.from_numpy(times))
    with pytest.raises(ValueError, match=r"times of shape .* does not broadcast"):
        rpj.time_augment(jnp.asarray(paths, dtype=jnp.float32), jnp.asarray(times, dtype=jnp.float32))
    ok = np.zeros((2, 3, 2))                                      # times (2, 3) against paths (2, 3, 2): accepted
    t2 = np.broadcast_to(np.arange(3.0), (2, 3)).copy()
    np.testing.assert_array_equal(rpt.time_augment(torch.from_numpy(ok), torch.from_numpy(t2)).numpy(),
                                  rp.time_augment(ok, t2))


def test_frontend_times_take_and_refuse_what_the_numpy_function_does():
    """The same ``times`` in the three front ends: integer times are taken (JAX refused them: "pass
    times.astype(jnp.float32)"), NaN and inf refused as non-finite (torch took inf, called NaN "not increasing"),
    a string refused naming ``times`` (torch raised its own "new(): invalid data type 'str'")."""
    torch = pytest.importorskip("torch")
    pytest.importorskip("jax")
    import jax.numpy as jnp

    import roughpaths.jax as rpj
    import roughpaths.torch as rpt

    x = np.arange(10.0).reshape(5, 2)
    want = rp.time_augment(x, [0, 1, 2, 3, 4])
    np.testing.assert_array_equal(rpt.time_augment(torch.from_numpy(x), [0, 1, 2, 3, 4]).numpy(), want)
    np.testing.assert_array_equal(rpt.time_augment(torch.from_numpy(x), torch.arange(5)).numpy(), want)
    np.testing.assert_array_equal(np.asarray(rpj.time_augment(jnp.asarray(x), np.arange(5))), want.astype(np.float32))
    for bad in ([0, 1, np.nan, 3, 4], [0, 1, 2, 3, np.inf]):
        with pytest.raises(ValueError, match="times contains 1 non-finite"):
            rp.time_augment(x, bad)
        with pytest.raises(ValueError, match="times contains 1 non-finite"):
            rpt.time_augment(torch.from_numpy(x), bad)
        with pytest.raises(ValueError, match="times contains 1 non-finite"):
            rpt.time_augment(torch.from_numpy(x), torch.tensor(bad))
    for frontend, arr in ((rpt, torch.from_numpy(x)), (rpj, jnp.asarray(x))):
        with pytest.raises(TypeError, match="times"):
            frontend.time_augment(arr, "abc")
    with pytest.raises(ValueError, match=r"strictly increasing .* at index \(2,\) it goes from 2.0 to 2.0"):
        rpt.time_augment(torch.from_numpy(x), [0, 1, 2, 2, 4])
