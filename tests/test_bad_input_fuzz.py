"""Bad input is refused clearly across the public API of ``roughpaths`` and ``mechanics``.

Property (issue 12, items 1 and 2): for every public constructor or function, replacing one argument
of a small valid call by a generated bad value (wrong type: strings, None, complex, object arrays,
bools where counts are expected; NaN/inf; negative, zero or huge sizes and steps; wrong shapes;
non-integer counts such as ``2.5``; callables returning scalars or wrong shapes; lambdas sent to a
process pool) either

* raises ``ValueError`` or ``TypeError`` whose message names the offending argument, or
* (valid odd input) returns a result all of whose floating-point arrays are finite,

and never another exception type, a NaN result, or a hang: anything sized by user input is
estimated and refused before work starts (the test runs every call under ``ROUGHPATHS_MAX_BYTES``
= 1 GiB, ``ROUGHPATHS_MAX_WORK`` = 1e8 path-steps and a 20 s alarm, so a request that is refused only
after it starts shows up as a MemoryError or a hang).

Inputs tried in one default run (``-s`` prints the table in ``test_zz_summary_of_inputs_tried``,
which asserts at least 200): 619 = 600 drawn (300 per package, 61 targets) + the issue's 19 examples.
By kind: string 114, complex 61, wrong shape 60, inf 58, foreign object 53, None 51, NaN 37, object
array 33, negative 25, huge size 24, empty 21, bool 20, non-integer float 19, zero 17, a class or
another wrong type 11, a plain number where an object is expected 6, callables returning scalars /
wrong shapes / NaN 6, lambdas sent to a process pool 2, an option given as a number 1. Outcome: 614
refused with a ValueError/TypeError naming the argument, 5 accepted as valid odd input (finite
results). The ``slow`` run draws 3000 more (3388 in all when measured).
"""

from __future__ import annotations

import collections
import concurrent.futures
import os
import signal
import tempfile
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mechanics as m
import roughpaths as rp

# ----------------------------------------------------------------------------------- small parts
A3, D3 = rp.paper_coloured_noise_matrices(0.5)[:2]
A2 = np.array([[1.0, 0.3], [-0.3, 1.0]])
D2 = np.eye(2)
T4 = np.linspace(0.0, 1.0, 4)
INC = np.array([[0.1, -0.2], [0.05, 0.3], [-0.1, 0.0]])
I3 = (1.0, 2.0, 3.0)
TMP = tempfile.mkdtemp(prefix="fuzz-")


def _bm(batch=()):
    return rp.brownian_rough_path(T4, 2, np.random.default_rng(0), batch_shape=batch)


def _rb():
    return m.rigid_body(I3, sigma=0.3, theta=0.5)


def _field_stack(y):                    # a batched callable field family on R^2 driven by R^2
    return np.stack([y, y[..., ::-1]], axis=-1)


def _obs_first(x):                      # a picklable observable (module level)
    return x[..., :1]


_POOL = None


def _process_pool():
    global _POOL
    if _POOL is None:
        _POOL = concurrent.futures.ProcessPoolExecutor(1)
    return _POOL


# ---------------------------------------------------------------------------- bad values by kind
_LAMBDA_SCALAR = lambda y: 1.0                               # noqa: E731
_LAMBDA_WRONG = lambda y: np.zeros(5)                        # noqa: E731
_LAMBDA_RAISES = lambda y: 1 / 0                             # noqa: E731
_LAMBDA_NAN = lambda y: np.full(np.shape(y), np.nan)         # noqa: E731


def _object_array():
    return np.array([object(), 1.0], dtype=object)


COMMON = [("string", "abc"), ("string", "1"), ("none", None), ("complex", 1 + 2j),
          ("object_array", "OBJ"), ("object", "OBJECT")]
COUNT = COMMON + [("non_integer_float", 2.5), ("non_integer_float", 3.7), ("negative", -1), ("zero", 0),
                  ("bool", True), ("nan", float("nan")), ("inf", float("inf")), ("huge_size", 10 ** 12),
                  ("huge_size", 10 ** 9)]
COUNT0 = [kv for kv in COUNT if kv[0] != "zero"]
REAL = COMMON + [("zero", 0.0), ("negative", -1.0), ("nan", float("nan")), ("inf", float("inf")),
                 ("inf", float("-inf")), ("bool", True), ("wrong_shape", "VEC")]
REAL0 = [kv for kv in REAL if kv[0] != "zero"]
REALANY = [kv for kv in REAL if kv[0] not in ("zero", "negative")]
TINY = REAL + [("tiny_step", 1e-12), ("tiny_step", 1e-9)]
ARRAY = COMMON + [("nan", "NAN"), ("inf", "INF"), ("wrong_shape", "LASTDIM"), ("wrong_shape", "FLAT"),
                  ("empty", "EMPTY"), ("complex", "CPLX"), ("wrong_shape", "SCALAR")]
RNG = COMMON + [("wrong_type", 0), ("wrong_type", "RS")]
SEED = COMMON + [("negative", -1), ("non_integer_float", 2.5), ("nan", float("nan")), ("wrong_type", "GEN")]
CHOICE = [("string", "nonsense"), ("string", ""), ("none_or_number", 3), ("none_or_number", 2.5),
          ("object", "OBJECT"), ("complex", 1j)]
OBJECT = [("string", "abc"), ("none", None), ("number", 3), ("object", "OBJECT"), ("class", "CLASS")]
CALLABLE = [("callable_scalar", _LAMBDA_SCALAR), ("callable_wrong_shape", _LAMBDA_WRONG),
            ("callable_raises", _LAMBDA_RAISES), ("callable_nan", _LAMBDA_NAN), ("string", "abc"),
            ("none", None)]
PICKLE = [("lambda_process_pool", lambda x: x[..., :1]), ("callable_scalar", _LAMBDA_SCALAR),
          ("callable_wrong_shape", _LAMBDA_WRONG)]
SHAPE = [("non_integer_float", 2.5), ("non_integer_float", (2.5,)), ("negative", (-1,)), ("string", "3"),
         ("bool", (True,)), ("complex", 1j), ("object", "OBJECT"), ("nan", float("nan"))]
PATH = [("none", None), ("number", 3), ("object", "OBJECT"), ("missing_file", "MISSING")]

POOLS = {"count": COUNT, "count0": COUNT0, "real": REAL, "real0": REAL0, "realany": REALANY, "tiny": TINY,
         "array": ARRAY, "rng": RNG, "seed": SEED, "choice": CHOICE, "object": OBJECT, "callable": CALLABLE,
         "pickle": PICKLE, "shape": SHAPE, "path": PATH}


def _materialise(token, base):
    """Turn a pool token into a bad value, using the valid ``base`` value for array mutations."""
    if not isinstance(token, str) or token not in {"OBJ", "OBJECT", "VEC", "NAN", "INF", "LASTDIM", "FLAT",
                                                   "EMPTY", "CPLX", "SCALAR", "RS", "GEN", "CLASS", "MISSING"}:
        return token
    if token == "OBJ":
        return _object_array()
    if token == "OBJECT":
        return object()
    if token == "CLASS":
        return type("Nothing", (), {})
    if token == "VEC":
        return np.array([0.1, 0.2])
    if token == "RS":
        return np.random.RandomState(0)
    if token == "GEN":
        return np.random.default_rng(0)
    if token == "MISSING":
        return os.path.join(TMP, "does-not-exist.npz")
    b = np.array(base, dtype=float)
    if token == "NAN":
        b.reshape(-1)[-1] = np.nan
        return b
    if token == "INF":
        b.reshape(-1)[0] = np.inf
        return b
    if token == "LASTDIM":
        return np.concatenate([b, b[..., :1]], axis=-1) if b.ndim else np.ones(3)
    if token == "FLAT":
        return b.reshape(-1)[:-1] if b.size > 1 else np.ones((2, 2, 2, 2, 2))
    if token == "EMPTY":
        return np.zeros((0,) * max(b.ndim, 1))
    if token == "CPLX":
        return b + 1j
    if token == "SCALAR":
        return 1.5 if b.ndim else np.ones((3, 3))
    raise AssertionError(token)


# ------------------------------------------------------------------------------------- targets
# Each target: (name, call(**kwargs), valid kwargs, {argument: kind of bad values}, aliases) where
# aliases lists other words a message may use to name that argument.
def _rm_update(dim, x):
    return m.RunningMoments(dim).update(x)


def _save_load(obj, path):
    p = rp.save(obj, path)
    return rp.load(p)


def _coloured_driver(**kw):
    return rp.ColouredNoiseDriver(**kw).rough_path()


def _brownian_driver(dim, **kw):
    return rp.BrownianDriver(dim, **kw).rough_path()


def _solve(fields, driver, y0, solver, **kw):
    return rp.solve(fields, driver, y0, solver, **kw).states


def _vector_fields(fields, dim_state, dim_noise):
    vf = rp.VectorFields(fields, dim_state=dim_state, dim_noise=dim_noise)
    return rp.solve(vf, _bm(), np.ones(2), rp.Heun()).states


R = [
    ("RoughPath", lambda **k: rp.RoughPath(**k),
     dict(increments=INC, areas=np.zeros((3, 2, 2)), times=T4),
     dict(increments="array", areas="array", times="array")),
    ("BrownianDriver", _brownian_driver,
     dict(dim=2, seed=1, dt=0.1, n_steps=3, batch_shape=(2,), levy_area="davie", substeps=None, kind="stratonovich"),
     dict(dim="count", seed="seed", dt="real", n_steps="count", batch_shape="shape", levy_area="choice",
          substeps="count", kind="choice")),
    ("ColouredNoiseDriver", _coloured_driver,
     dict(A=A2, D=D2, eps=0.5, seed=1, dt=0.1, n_steps=3, batch_shape=(2,), max_substep=0.5),
     dict(A="array", D="array", eps="tiny", seed="seed", dt="real", n_steps="count", batch_shape="shape",
          max_substep="real", substeps="count")),
    ("sample_coloured_noise", lambda **k: rp.sample_coloured_noise(**k).path.increments,
     dict(A=A2, D=D2, eps=0.5, times=T4, rng=np.random.default_rng(0), batch_shape=(2,), max_substep=0.5),
     dict(A="array", D="array", eps="tiny", times="array", rng="rng", batch_shape="shape", max_substep="real",
          substeps="count")),
    ("iter_coloured_noise", lambda **k: list(rp.iter_coloured_noise(**k)),
     dict(A=A2, D=D2, eps=0.5, h=0.1, n_steps=3, rng=np.random.default_rng(0), n_paths=2),
     dict(eps="tiny", h="real", n_steps="count", n_paths="count", substeps="count", max_substep="real",
          chunk_steps="count")),
    ("expected_area_rate", lambda **k: rp.expected_area_rate(**k),
     dict(A=A2, D=D2, eps=0.5, window=1.0), dict(A="array", D="array", eps="real", window="real")),
    ("ou_step_law", lambda **k: rp.ou_step_law(**k), dict(A=A2, D=D2, eps=0.5, h=0.1),
     dict(eps="real", h="real")),
    ("lift_area_rate", lambda **k: rp.lift_area_rate(**k), dict(A=A2, D=D2, substep=0.1),
     dict(A="array", substep="real")),
    ("solve", _solve,
     dict(fields=rp.LinearVectorFields(np.stack([np.eye(2), np.eye(2)[::-1]])), driver=_bm(), y0=np.ones(2),
          solver=rp.Heun()),
     dict(fields="object", driver="object", y0="array", solver="object", save_at="choice", block_steps="count")),
    ("VectorFields", _vector_fields, dict(fields=_field_stack, dim_state=2, dim_noise=2),
     dict(fields="callable", dim_state="count", dim_noise="count")),
    ("LinearVectorFields", lambda **k: rp.LinearVectorFields(**k).fields(np.ones(2)),
     dict(matrices=np.stack([np.eye(2), np.eye(2)])), dict(matrices="array")),
    ("signature", lambda **k: rp.signature(**k), dict(paths=np.cumsum(INC, 0), depth=3),
     dict(paths="array", depth="count")),
    ("logsignature", lambda **k: rp.logsignature(**k), dict(paths=np.cumsum(INC, 0), depth=3),
     dict(paths="array", depth="count")),
    ("signature_vjp", lambda **k: rp.signature_vjp(**k),
     dict(paths=np.cumsum(INC, 0), depth=2, grad_output=np.ones(6)),
     dict(paths="array", depth="count", grad_output="array")),
    ("logsignature_vjp", lambda **k: rp.logsignature_vjp(**k),
     dict(paths=np.cumsum(INC, 0), depth=2, grad_output=np.ones(3)),
     dict(paths="array", depth="count", grad_output="array")),
    ("rough_path_signature", lambda **k: rp.rough_path_signature(**k), dict(X=_bm(), depth=3),
     dict(X="object", depth="count")),
    ("holder_seminorm", lambda **k: rp.holder_seminorm(**k), dict(X=np.cumsum(INC, 0), alpha=0.4, times=T4[:3]),
     dict(X="array", alpha="real", times="array", max_points="count")),
    ("p_variation", lambda **k: rp.p_variation(**k), dict(X=np.cumsum(INC, 0), p=2.5, times=T4[:3]),
     dict(X="array", p="real", times="array", max_points="count")),
    ("rough_path_p_variation", lambda **k: rp.rough_path_p_variation(**k), dict(X=_bm(), p=2.5),
     dict(X="object", p="real")),
    ("level2_mul", lambda **k: rp.level2_mul(**k),
     dict(x=np.ones(2), a=np.zeros((2, 2)), y=np.ones(2), b=np.zeros((2, 2))),
     dict(x="array", a="array", y="array", b="array")),
    ("level2_exp", lambda **k: rp.level2_exp(**k), dict(x=np.ones(2), A=np.zeros((2, 2))),
     dict(x="array", A="array")),
    ("level2_log", lambda **k: rp.level2_log(**k), dict(x=np.ones(2), a=np.ones((2, 2)) * 0.5),
     dict(x="array", a="array")),
    ("level2_inv", lambda **k: rp.level2_inv(**k), dict(x=np.ones(2), a=np.ones((2, 2)) * 0.5),
     dict(x="array", a="array")),
    ("tensor_exp", lambda **k: rp.tensor_exp(**k), dict(z=np.ones(6) * 0.1, dim=2), dict(z="array", dim="count")),
    ("tensor_log", lambda **k: rp.tensor_log(**k), dict(a=np.ones(6) * 0.1, dim=2), dict(a="array", dim="count")),
    ("tensor_product", lambda **k: rp.tensor_product(**k), dict(a=np.ones(6), b=np.ones(6), dim=2),
     dict(a="array", b="array", dim="count")),
    ("sigdim", lambda **k: rp.sigdim(**k), dict(dim=3, depth=4), dict(dim="count", depth="count")),
    ("logsigdim", lambda **k: rp.logsigdim(**k), dict(dim=3, depth=4), dict(dim="count", depth="count")),
    ("lyndon_basis", lambda **k: rp.lyndon_basis(**k), dict(dim=2, depth=3), dict(dim="count", depth="count")),
    ("expm_batched", lambda **k: rp.expm_batched(**k), dict(A=np.eye(3) * 0.1), dict(A="array")),
    ("sample_levy_areas", lambda **k: rp.sample_levy_areas(**k),
     dict(increments=INC, h=0.1, rng=np.random.default_rng(0), levy_area="auto"),
     dict(increments="array", h="real", rng="rng", levy_area="choice", levy_area_error="real", substeps="count")),
    ("fbm", lambda **k: rp.fbm(**k), dict(n_steps=8, hurst=0.3, rng=np.random.default_rng(0), T=1.0, dim=2),
     dict(n_steps="count", hurst="real", rng="rng", T="real", dim="count", batch_shape="shape", method="choice")),
    ("fbm_rough_path", lambda **k: rp.fbm_rough_path(**k).increments,
     dict(n_steps=4, hurst=0.4, rng=np.random.default_rng(0), substeps=4),
     dict(n_steps="count", hurst="real", substeps="count", level="count")),
    ("fgn_autocovariance", lambda **k: rp.fgn_autocovariance(**k), dict(hurst=0.3, n=5),
     dict(hurst="real", n="count")),
    ("refine", lambda **k: rp.refine(**k).increments, dict(X=_bm((2,)), factor=2, rng=np.random.default_rng(0)),
     dict(X="object", factor="count", rng="rng")),
    ("brownian_rough_path", lambda **k: rp.brownian_rough_path(**k).increments,
     dict(times=T4, dim=2, rng=np.random.default_rng(0), batch_shape=(2,), substeps=2, levy_area="davie"),
     dict(times="array", dim="count", rng="rng", batch_shape="shape", substeps="count", levy_area="choice",
          kind="choice")),
    ("brownian_increments_and_areas", lambda **k: rp.brownian_increments_and_areas(**k),
     dict(rng=np.random.default_rng(0), n_steps=3, dt=0.1, dim=2),
     dict(rng="rng", n_steps="count", dt="real", dim="count", batch_shape="shape")),
    ("piecewise_linear_lift", lambda **k: rp.piecewise_linear_lift(**k).increments,
     dict(values=np.cumsum(np.ones((5, 2)), 0), substeps=2, level=2),
     dict(values="array", substeps="count", level="count")),
    ("save_load", _save_load, dict(obj=_bm(), path=os.path.join(TMP, "x.npz")),
     dict(obj="object", path="path")),
]

M = [
    ("rigid_body", lambda **k: m.rigid_body(**k).xi,
     dict(inertia=I3, sigma=0.1, theta=0.5),
     dict(inertia="array", sigma="real0", theta="real0", s="array", convention="choice")),
    ("heavy_top", lambda **k: m.heavy_top(**k), dict(inertia=I3, chi=(0.0, 0.0, 1.0), sigma=0.1),
     dict(inertia="array", chi="array", sigma="real0", theta="real0")),
    ("isotropic_xi", lambda **k: m.isotropic_xi(**k), dict(sigma=0.1, dim=3), dict(sigma="real0", dim="count")),
    ("run_ensemble", lambda **k: m.run_ensemble(**k).final.mean,
     dict(system=_rb(), mu0=(0.0, 0.0, 1.0), dt=0.01, n_steps=4, n_paths=3, seed=1, chunk_size=2),
     dict(system="object", mu0="array", dt="real", n_steps="count", n_paths="count", seed="seed",
          observable="callable", burn_in="count0", average_every="count", record_every="count",
          chunk_size="count", block_steps="count", executor="object", levy_area="choice")),
    ("run_ensemble_process_pool", lambda **k: m.run_ensemble(executor=_process_pool(), **k).final.mean,
     dict(system=_rb(), mu0=(0.0, 0.0, 1.0), dt=0.01, n_steps=2, n_paths=2, seed=1, observable=_obs_first),
     dict(observable="pickle")),
    ("RunningMoments", _rm_update, dict(dim=2, x=np.ones((3, 2))), dict(dim="count", x="array")),
    ("rigid_body_equilibria", lambda **k: [e.point for e in m.rigid_body_equilibria(**k)],
     dict(inertia=I3, radius=1.0, theta=0.0), dict(inertia="array", c="array", radius="real", theta="real0")),
    ("rigid_body_level_sets", lambda **k: m.rigid_body_level_sets(**k).levels,
     dict(inertia=I3, levels=3, n_theta=31, n_phi=61), dict(inertia="array", levels="count", n_theta="count",
                                                           n_phi="count", radius="real")),
    ("gibbs_beta", lambda **k: m.gibbs_beta(**k), dict(sigma=0.5, theta=1.0), dict(sigma="real", theta="real")),
    ("GibbsMeasure", lambda **k: m.GibbsMeasure(**k).beta, dict(inertia=I3, beta=1.0),
     dict(inertia="array", beta="real", radius="real", rtol="real", c="array")),
    ("simulate_wong_zakai_rigid_body", lambda **k: {n: s.final for n, s in m.simulate_wong_zakai_rigid_body(**k).items()},
     dict(A=A3, D=D3, eps=0.5, sigma=0.1, T=0.05, n_paths=2, rng=np.random.default_rng(0), systems=("limit",)),
     dict(A="array", eps="tiny", sigma="real0", T="real", h="real", n_paths="count", rng="rng",
          systems="choice", save_every="count", Pi0="array", inertia="array")),
    ("planar_example", lambda **k: m.planar_example(**k).A, dict(alpha=1.0), dict(alpha="realany", gamma="realany")),
    ("planar_limit_moments", lambda **k: m.planar_limit_moments(**k),
     dict(ex=m.planar_example(), x0=(1.0, 0.0), T=1.0), dict(ex="object", x0="array", T="real0")),
    ("PlanarExample.driver", lambda **k: m.planar_example().driver(**k).rough_path().areas,
     dict(eps=0.5, T=0.05, seed=0, batch_shape=(2,)), dict(eps="tiny", T="real", seed="seed", h="real")),
    ("hat", lambda **k: m.hat(**k), dict(x=(1.0, 2.0, 3.0)), dict(x="array")),
    ("vee", lambda **k: m.vee(**k), dict(m=np.zeros((3, 3))), dict(m="array")),
    ("modified_hamiltonian", lambda **k: m.modified_hamiltonian(**k), dict(Pi=(0.0, 0.0, 1.0), inertia=I3),
     dict(Pi="array", inertia="array", c="array")),
    ("levy_velocity", lambda **k: m.levy_velocity(**k), dict(s=np.zeros((3, 3)), xi=np.eye(3)),
     dict(s="array", xi="array")),
    ("lagrange_top_sleeping_stability", lambda **k: m.lagrange_top_sleeping_stability(**k),
     dict(I1=1.0, I3=2.0, omega3=3.0, mgl=1.0), dict(I1="real", I3="real", omega3="realany", mgl="realany")),
    ("rigid_body_wong_zakai_limit", lambda **k: m.rigid_body_wong_zakai_limit(**k).torque,
     dict(A=A3, D=D3, sigma=0.1), dict(A="array", D="array", sigma="real0")),
]

TARGETS = R + M
BY = {t[0]: t for t in TARGETS}
ALIASES = {("iter_coloured_noise", "h"): ("step",), ("solve", "driver"): ("driver", "X"),
           ("save_load", "path"): ("path", "file", "such file"), ("save_load", "obj"): ("obj", "save")}

TRIED = collections.Counter()         # (kind) -> inputs tried

# The summary at the end counts what the tests before it tried in this process: with two workers
# (./test.sh runs pytest-xdist, --dist loadgroup) the whole module runs on one of them, in order.
pytestmark = pytest.mark.xdist_group("bad-input-fuzz")
OUTCOME = collections.Counter()       # (refused | accepted) -> count


class Hang(Exception):
    pass


def _alarm(*_):
    raise Hang("call did not return within 20 s")


def _finite(obj, depth=0):
    if depth > 3:
        return True
    if isinstance(obj, np.ndarray):
        return obj.dtype.kind not in "fc" or bool(np.all(np.isfinite(obj)))
    if isinstance(obj, float):
        return np.isfinite(obj)
    if isinstance(obj, (tuple, list)):
        return all(_finite(o, depth + 1) for o in obj)
    if isinstance(obj, dict):
        return all(_finite(o, depth + 1) for o in obj.values())
    return True


def _check_one(name, call, base, arg, kind, value):
    kwargs = dict(base)
    kwargs[arg] = value
    TRIED[kind] += 1
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(20)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = call(**kwargs)
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        words = (arg,) + ALIASES.get((name, arg), ())
        assert any(w in msg for w in words), (
            f"{name}({arg}={value!r}) [{kind}] raised {type(exc).__name__} not naming {arg!r}: {msg}")
        OUTCOME["refused"] += 1
        return
    except Hang:
        pytest.fail(f"{name}({arg}={value!r}) [{kind}] did not return within 20 s")
    except Exception as exc:   # noqa: BLE001 - the property under test
        pytest.fail(f"{name}({arg}={value!r}) [{kind}] raised {type(exc).__name__}: {exc}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    assert _finite(out), f"{name}({arg}={value!r}) [{kind}] returned a non-finite result"
    OUTCOME["accepted"] += 1


@st.composite
def bad_calls(draw, targets):
    name, call, base, args = draw(st.sampled_from(targets))
    arg = draw(st.sampled_from(sorted(args)))
    kind, token = draw(st.sampled_from(POOLS[args[arg]]))
    if name == "expm_batched" and kind in ("nan", "inf"):
        kind, token = "wrong_shape", "LASTDIM"     # documented: a NaN member gives a NaN result for itself
    return name, call, base, arg, kind, _materialise(token, base.get(arg, np.ones(3)))


@pytest.fixture(autouse=True)
def _memory_budget(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(2 ** 30))
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", "1e8")


_FAST = settings(max_examples=300, deadline=None, derandomize=True, database=None,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                        HealthCheck.data_too_large])
_SLOW = settings(_FAST, max_examples=3000, derandomize=False)


@_FAST
@given(bad_calls(R))
def test_roughpaths_refuses_bad_input(case):
    _check_one(*case)


@_FAST
@given(bad_calls(M))
def test_mechanics_refuses_bad_input(case):
    _check_one(*case)


@pytest.mark.slow
@_SLOW
@given(bad_calls(TARGETS))
def test_public_api_refuses_bad_input_long(case):
    _check_one(*case)


@pytest.mark.parametrize("name, call, base, arg, kind, value", [
    ("BrownianDriver", _brownian_driver, BY["BrownianDriver"][2], "batch_shape", "non_integer_float", 2.5),
    ("ColouredNoiseDriver", _coloured_driver, BY["ColouredNoiseDriver"][2], "max_substep", "negative", -1),
    ("ColouredNoiseDriver", _coloured_driver, BY["ColouredNoiseDriver"][2], "max_substep", "zero", 0),
    ("expected_area_rate", BY["expected_area_rate"][1], BY["expected_area_rate"][2], "window", "zero", 0),
    ("expected_area_rate", BY["expected_area_rate"][1], BY["expected_area_rate"][2], "window", "negative", -1),
    ("planar_limit_moments", BY["planar_limit_moments"][1], BY["planar_limit_moments"][2], "T", "negative", -1),
    ("hat", BY["hat"][1], BY["hat"][2], "x", "wrong_shape", [1, 2]),
    ("simulate_wong_zakai_rigid_body", BY["simulate_wong_zakai_rigid_body"][1], BY["simulate_wong_zakai_rigid_body"][2], "systems", "string", "limit"),
    ("simulate_wong_zakai_rigid_body", BY["simulate_wong_zakai_rigid_body"][1], BY["simulate_wong_zakai_rigid_body"][2], "T", "negative", -1),
    ("simulate_wong_zakai_rigid_body", BY["simulate_wong_zakai_rigid_body"][1], BY["simulate_wong_zakai_rigid_body"][2], "eps", "zero", 0.0),
    ("simulate_wong_zakai_rigid_body", BY["simulate_wong_zakai_rigid_body"][1], BY["simulate_wong_zakai_rigid_body"][2], "eps", "nan", float("nan")),
    ("rigid_body", BY["rigid_body"][1], BY["rigid_body"][2], "sigma", "string", "0.1"),
    ("RunningMoments", _rm_update, BY["RunningMoments"][2], "x", "nan", np.array([[np.nan, 1.0]])),
    ("run_ensemble", BY["run_ensemble"][1], BY["run_ensemble"][2], "observable", "callable_scalar", _LAMBDA_SCALAR),
    ("run_ensemble_process_pool", BY["run_ensemble_process_pool"][1], BY["run_ensemble_process_pool"][2], "observable", "lambda_process_pool", lambda x: x),
    ("refine", BY["refine"][1], BY["refine"][2], "factor", "huge_size", 10 ** 9),
    ("run_ensemble", lambda **k: m.run_ensemble(**dict(k, n_steps=10 ** 12)).final.mean, BY["run_ensemble"][2], "n_paths",
     "huge_size", 10 ** 12),
    ("rigid_body_level_sets", BY["rigid_body_level_sets"][1], BY["rigid_body_level_sets"][2], "levels", "huge_size", 10 ** 6),
    ("rigid_body_level_sets", BY["rigid_body_level_sets"][1], BY["rigid_body_level_sets"][2], "levels", "nan", float("nan")),
])
def test_issue_examples_are_refused(name, call, base, arg, kind, value):
    """The issue's own examples, each refused with a ValueError/TypeError naming the argument."""
    before = OUTCOME["refused"]
    _check_one(name, call, base, arg, kind, value)
    assert OUTCOME["refused"] == before + 1, f"{name}({arg}={value!r}) was accepted"


def test_zz_summary_of_inputs_tried(capsys):
    """Counts of the inputs tried by kind in this run (``-s`` shows them); at least 200 bad inputs.

    The count is this process's: where the module's two fuzz tests did not run here (a ``-k`` selection, or
    a pytest-xdist worker that got only part of the module), they are run here first.
    """
    if sum(TRIED.values()) < 200:
        test_roughpaths_refuses_bad_input()
        test_mechanics_refuses_bad_input()
    lines = [f"  {k:22s} {v:5d}" for k, v in sorted(TRIED.items(), key=lambda kv: -kv[1])]
    with capsys.disabled():
        print("\nbad inputs tried by kind:\n" + "\n".join(lines)
              + f"\n  total {sum(TRIED.values())}: refused {OUTCOME['refused']}, accepted (finite) "
                f"{OUTCOME['accepted']}")
    assert sum(TRIED.values()) >= 200
    if _POOL is not None:
        _POOL.shutdown()
