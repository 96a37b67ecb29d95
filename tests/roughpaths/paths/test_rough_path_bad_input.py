"""Bad input to ``RoughPath`` raises ``ValueError``/``TypeError`` naming the argument.

Claim: every invalid argument (non-finite values, wrong shapes or dtypes, non-increasing or
mismatched times, non-antisymmetric ``s``, mismatched batch shapes, query times off the grid,
``s > t``) is refused with an error whose message names the offending argument; none gives a
silent result, a NaN or a numpy-internal error.
"""

import numpy as np
import pytest

from roughpaths import RoughPath, chen_defect

N, D = 4, 2
INC = np.arange(N * D, dtype=float).reshape(N, D) / 10
AREAS = 0.5 * INC[:, :, None] * INC[:, None, :]


def nan_at(a, where):
    a = np.array(a, dtype=float)
    a[where] = np.nan
    return a


CONSTRUCTOR_CASES = [
    # (kwargs, exception, regex naming the argument)
    (dict(increments=nan_at(INC, (1, 0)), areas=AREAS), ValueError, "increments.*non-finite"),
    (dict(increments=np.where(INC > 0.5, np.inf, INC), areas=AREAS), ValueError, "increments.*non-finite"),
    (dict(increments=INC, areas=nan_at(AREAS, (0, 1, 1))), ValueError, "areas.*non-finite"),
    (dict(increments=INC, areas=AREAS, times=nan_at(np.linspace(0, 1, N + 1), 2)), ValueError, "times"),
    (dict(increments=INC, areas=AREAS, x0=[np.nan, 0.0]), ValueError, "x0"),
    (dict(increments=INC.astype(complex), areas=AREAS), TypeError, "increments.*real"),
    (dict(increments=INC, areas=AREAS.astype(complex)), TypeError, "areas.*real"),
    (dict(increments="abc", areas=None), TypeError, "increments"),
    (dict(increments=np.array([["a", "b"], ["c", "d"]]), areas=None), TypeError, "increments"),
    (dict(increments=np.array([[1.0, None]], dtype=object), areas=None), TypeError, "increments"),
    (dict(increments=None, areas=None), TypeError, "increments"),
    (dict(increments=INC[0], areas=None), ValueError, "increments"),               # 1-D
    (dict(increments=np.zeros((0, D)), areas=None), ValueError, "increments"),      # no steps
    (dict(increments=INC, areas=AREAS[:-1]), ValueError, "areas"),                  # N mismatch
    (dict(increments=INC, areas=AREAS[..., :1]), ValueError, "areas"),              # d mismatch
    (dict(increments=INC, areas=np.stack([AREAS, AREAS])), ValueError, "areas.*batch"),
    (dict(increments=INC, areas=AREAS, times=np.linspace(0, 1, N)), ValueError, "times"),
    (dict(increments=INC, areas=AREAS, times=[0.0, 0.2, 0.2, 0.5, 1.0]), ValueError, "times.*increasing"),
    (dict(increments=INC, areas=AREAS, times=[0.0, 0.5, 0.4, 0.6, 1.0]), ValueError, "times.*increasing"),
    (dict(increments=INC, areas=AREAS, times=np.zeros((N + 1, 1))), ValueError, "times"),
    (dict(increments=INC, areas=AREAS, times=np.linspace(0, 1, N + 1) + 0j), TypeError, "times.*real"),
    (dict(increments=INC, areas=AREAS, times="0 1 2 3 4"), TypeError, "times"),
    (dict(increments=INC, areas=AREAS, x0=[0.0, 0.0, 0.0]), ValueError, "x0"),
    (dict(increments=INC, areas=AREAS, x0=np.zeros((3, D))), ValueError, "x0"),     # batch mismatch
    (dict(increments=INC, areas=AREAS, kind="stratonovich"), ValueError, "kind"),
    (dict(increments=INC, areas=AREAS + np.eye(D), kind="geometric"), ValueError, "geometric"),
]


@pytest.mark.parametrize("kwargs, exc, pattern", CONSTRUCTOR_CASES)
def test_constructor_rejects(kwargs, exc, pattern):
    kw = dict(kwargs)
    inc, areas = kw.pop("increments"), kw.pop("areas")
    with pytest.raises(exc, match=pattern):
        RoughPath(inc, areas, **kw)


def test_from_path_rejects():
    with pytest.raises(ValueError, match="values"):
        RoughPath.from_path(np.zeros((1, D)))
    with pytest.raises(ValueError, match="values.*non-finite"):
        RoughPath.from_path(np.array([[0.0, 1.0], [np.nan, 2.0]]))
    with pytest.raises(TypeError, match="values"):
        RoughPath.from_path(np.zeros((3, D), dtype=complex))
    with pytest.raises(ValueError, match="values"):
        RoughPath.from_path(np.zeros(5))
    with pytest.raises(ValueError, match="times"):
        RoughPath.from_path(np.zeros((3, D)), times=[0.0, 1.0, 0.5])
    with pytest.raises(ValueError, match="times"):
        RoughPath.from_path(np.zeros((3, D)), times=[0.0, 1.0])


@pytest.fixture
def X():
    return RoughPath(INC, AREAS, times=np.linspace(0.0, 1.0, N + 1))


def test_queries_off_grid_and_reversed(X):
    with pytest.raises(ValueError, match=r"s=0\.1 is not a grid time"):
        X.area(0.1, 1.0)
    with pytest.raises(ValueError, match=r"t=0\.6 is not a grid time"):
        X.increment(0.0, 0.6)
    with pytest.raises(ValueError, match="t=2.0"):
        X.levy_area(0.0, 2.0)
    with pytest.raises(ValueError, match="s=-0.25"):
        X.area(-0.25, 0.5)
    with pytest.raises(ValueError, match="s must not exceed t"):
        X.area(0.75, 0.25)
    with pytest.raises(ValueError, match="s must not exceed t"):
        X.increment(np.array([0.0, 0.75]), np.array([0.5, 0.25]))
    with pytest.raises(ValueError, match="s.*non-finite"):
        X.area(np.nan, 1.0)
    with pytest.raises(TypeError, match="t"):
        X.area(0.0, "1.0")
    with pytest.raises(TypeError, match="s"):
        X.area(0.0 + 0.5j, 1.0)


def test_restrict_rejects(X):
    with pytest.raises(ValueError, match="times=0.3 is not a grid time"):
        X.restrict([0.0, 0.3, 1.0])
    with pytest.raises(ValueError, match="times.*increasing"):
        X.restrict([0.0, 0.5, 0.25])
    with pytest.raises(ValueError, match="times.*same grid point"):
        X.restrict([0.0, 1e-12, 1.0])
    with pytest.raises(ValueError, match="times"):
        X.restrict([0.5])


def test_perturb_rejects(X):
    with pytest.raises(ValueError, match="s must be antisymmetric"):
        X.perturb(np.array([[0.0, 1.0], [1.0, 0.0]]))
    with pytest.raises(ValueError, match="s must be antisymmetric"):
        X.perturb(np.eye(D))
    with pytest.raises(ValueError, match="s must be 2x2"):
        X.perturb(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="s must be square"):
        X.perturb(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="s.*non-finite"):
        X.perturb(np.array([[0.0, np.inf], [-np.inf, 0.0]]))
    with pytest.raises(TypeError, match="s"):
        X.perturb(np.zeros((2, 2), dtype=complex))
    J = np.array([[0.0, 1.0], [-1.0, 0.0]])
    Xb = RoughPath(np.stack([INC] * 3), np.stack([AREAS] * 3))
    with pytest.raises(ValueError, match="s has batch shape"):
        Xb.perturb(np.stack([J, J]))


def test_other_methods_reject(X):
    with pytest.raises(TypeError, match="other"):
        X.concatenate(INC)
    Xb = RoughPath(np.stack([INC] * 3), np.stack([AREAS] * 3))
    with pytest.raises(ValueError, match="batch shape"):
        X.concatenate(Xb)
    Y3 = RoughPath(np.ones((N, 3)), None)
    with pytest.raises(ValueError, match="d=3"):
        X.concatenate(Y3)
    with pytest.raises(IndexError):
        X[0]
    with pytest.raises(IndexError):
        Xb[3]
    with pytest.raises(TypeError, match="fine and coarse"):
        chen_defect(X, INC)


def test_level2_group_operations_refuse_bad_elements():
    from roughpaths import level2_exp, level2_inv, level2_log, level2_mul

    x, a = np.ones(2), np.zeros((2, 2))
    with pytest.raises(ValueError, match="non-finite"):
        level2_mul(x, a, np.array([np.nan, 0.0]), a)
    with pytest.raises(ValueError, match=r"a must have shape \(\.\.\., d, d\) = \(\.\.\., 2, 2\)"):
        level2_inv(x, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="same dimension d"):
        level2_mul(x, a, np.ones(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="do not broadcast"):
        level2_mul(np.ones((4, 2)), np.zeros((4, 2, 2)), np.ones((3, 2)), np.zeros((3, 2, 2)))
    with pytest.raises(TypeError, match="real"):
        level2_exp(np.ones(2, dtype=complex), a)
    with pytest.raises(ValueError, match="non-finite"):
        level2_log(x, np.full((2, 2), np.inf))
