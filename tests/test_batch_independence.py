"""Batch members do not affect each other.

Statement: for every batched computation of the library, the result for a healthy batch member
is, bit for bit, the result of computing that member alone, whatever the other members hold
(members scaled by up to 1e12, non-finite members where the API allows them); a non-finite member
is reported by its own index and step and never spoils the others.

Oracle: the same public function called on the single member (an independent evaluation, not a
building block of the batched one).
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import roughpaths as rp
from _oracles import poly_fields, poly_jacobians

SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@st.composite
def batches(draw, shape_tail, max_members=6, poison=True):
    """A batch whose members have random scales 10^[-6, 12], one of them possibly NaN/inf."""
    b = draw(st.integers(2, max_members))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((b,) + shape_tail)
    scales = 10.0 ** rng.uniform(-6.0, 12.0, size=b)
    x *= scales.reshape((b,) + (1,) * len(shape_tail))
    poison = draw(st.sampled_from([None, np.nan, np.inf])) if poison else None
    bad = None
    if poison is not None:
        bad = int(rng.integers(b))
        x[(bad,) + tuple(int(rng.integers(n)) for n in shape_tail)] = poison
    return x, bad


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


@SETTINGS
@given(batches((4, 4)))
def test_expm_batched_members_independent(data):
    A, bad = data
    R = rp.expm_batched(A)
    for i in range(A.shape[0]):
        assert _same(R[i], rp.expm_batched(A[i])), f"member {i}"
    if bad is not None:
        assert np.isnan(R[bad]).all()
        healthy = [i for i in range(A.shape[0]) if i != bad]
        assert np.isfinite(R[healthy]).all() or np.max(np.abs(A[healthy])) > 100


def test_expm_batched_issue_example():
    """The issue's reproduction: a huge or NaN neighbour no longer moves B's exponential."""
    from scipy.linalg import expm

    B = np.array([[0.1, 1.0], [-1.0, 0.2]])
    for big in (1e6, 1e10, 1e14, np.nan):
        A = np.stack([B, [[0.0, big], [0.0, 0.0]]])
        assert np.max(np.abs(rp.expm_batched(A)[0] - expm(B))) < 1e-15


def _fields(kind, rng):
    if kind == "linear":
        return rp.LinearVectorFields(0.5 * rng.standard_normal((2, 3, 3)),
                                     drift=0.3 * rng.standard_normal((3, 3)))

    return rp.VectorFields(poly_fields, poly_jacobians, dim_state=3, dim_noise=2, drift=lambda y: -0.1 * y)


@pytest.mark.parametrize("kind", ["linear", "polynomial"])
@pytest.mark.parametrize("solver", [rp.Euler(), rp.Heun(), rp.Davie(), rp.LogODE()], ids=repr)
@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), scale_exp=st.floats(0.0, 12.0), poison=st.booleans())
def test_solve_members_independent(kind, solver, seed, scale_exp, poison):
    rng = np.random.default_rng(seed)
    V = _fields(kind, rng)
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 33), dim=2, rng=rng, batch_shape=(4,))
    inc, areas = X.increments.copy(), X.areas.copy()
    inc[1] *= 10.0 ** scale_exp                                  # a member far out of scale
    areas[1] *= 10.0 ** (2 * scale_exp)
    if poison:
        inc[3, 7, 0] = np.nan                                    # a poisoned member
    with np.errstate(all="ignore"):
        Y = rp.RoughPath(inc, areas, times=X.times, kind="general", check=False)
        sol = rp.solve(V, Y, np.ones(3), solver, on_failure="mask")
        for i in range(4):
            alone = rp.solve(V, rp.RoughPath(inc[i], areas[i], times=X.times, kind="general", check=False),
                             np.ones(3), solver, on_failure="mask")
            assert _same(sol.states[i], alone.states), f"member {i}"
            assert sol.failed_step[i] == alone.failed_step
    if poison:
        assert sol.failed_step[3] == 7
    if kind == "linear":                                         # members 0 and 2 stay healthy
        assert sol.failed_step[0] == -1 and sol.failed_step[2] == -1


def test_solve_failure_names_the_failing_members():
    rng = np.random.default_rng(3)
    V = _fields("linear", rng)
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 33), dim=2, rng=rng, batch_shape=(2, 3))
    inc = X.increments.copy()
    inc[1, 2, 5] = np.inf
    inc[0, 1, 9] = np.nan
    Y = rp.RoughPath(inc, X.areas, times=X.times, kind="general", check=False)
    with pytest.raises(rp.NonFiniteStateError, match=r"at step 5 .* batch member \(1, 2\)") as info:
        with np.errstate(all="ignore"):
            rp.solve(V, Y, np.ones(3), rp.Davie())
    # raise mode stops at the first failing step: only the member failing there is named
    assert info.value.members == ((1, 2),) and info.value.steps == (5,)
    with np.errstate(all="ignore"):
        sol = rp.solve(V, Y, np.ones(3), rp.Davie(), on_failure="mask")
    assert sol.failed_step.tolist() == [[-1, 9, -1], [-1, -1, 5]]
    assert np.isnan(sol.states[1, 2, 6:]).all() and np.isfinite(sol.states[1, 2, :6]).all()
    assert np.isfinite(sol.states[0, 0]).all()


@SETTINGS
@given(batches((12, 3), max_members=5, poison=False), st.integers(1, 4))   # NaN paths are refused
def test_signature_members_independent(data, depth):
    paths, _ = data
    paths = np.cumsum(paths, axis=-2)
    s = rp.signature(paths, depth)
    for i in range(paths.shape[0]):
        assert _same(s[i], rp.signature(paths[i], depth)), f"member {i}"


@SETTINGS
@given(batches((rp.sigdim(3, 3),), max_members=5, poison=False))
def test_tensor_algebra_members_independent(data):
    z, _ = data
    z = z / (1.0 + np.max(np.abs(z), axis=-1, keepdims=True))      # keep exp finite
    g = rp.tensor_exp(z, 3)
    for name, f in [("exp", lambda a: rp.tensor_exp(a, 3)),
                    ("log", lambda a: rp.tensor_log(rp.tensor_exp(a, 3), 3)),
                    ("inverse", lambda a: rp.tensor_inverse(rp.tensor_exp(a, 3), 3))]:
        batch = f(z)
        for i in range(z.shape[0]):
            assert _same(batch[i], f(z[i])), f"{name}, member {i}"
    prod = rp.tensor_product(g, g[::-1], 3)
    for i in range(z.shape[0]):
        assert _same(prod[i], rp.tensor_product(g[i], g[::-1][i], 3)), f"product, member {i}"


@SETTINGS
@given(batches((12, 3), max_members=5, poison=False), st.integers(1, 5))
def test_logsignature_members_independent(data, depth):
    paths, _ = data
    paths = np.cumsum(paths, axis=-2)
    s = rp.logsignature(paths, depth)
    for i in range(paths.shape[0]):
        assert _same(s[i], rp.logsignature(paths[i], depth)), f"member {i}"


@pytest.mark.parametrize("depth, n", [(2, 40_000), (3, 2_500), (4, 2_100)])
def test_long_path_members_independent(depth, n):
    """Long paths are cut into chunks glued by Chen's identity; the cut must depend on the path's length
    only, so a member alone and the same member among 1 or 40 others get the same bits."""
    rng = np.random.default_rng(depth)
    paths = np.cumsum(rng.standard_normal((40, n, 3)) * 0.05, axis=-2)
    alone = [rp.signature(paths[i], depth) for i in (0, 17, 39)]
    for batch in (paths[:2], paths):
        s = rp.signature(batch, depth)
        for j, i in enumerate((0, 17, 39)):
            if i < batch.shape[0]:
                assert _same(s[i], alone[j]), f"member {i} in a batch of {batch.shape[0]}"
    ls = rp.logsignature(paths[:2], depth)
    assert _same(ls[0], rp.logsignature(paths[0], depth))
