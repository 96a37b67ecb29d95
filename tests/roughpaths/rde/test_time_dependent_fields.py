"""Time-dependent vector fields V(t, y): every solver converges to the known solution at its order.

Statement: for the scalar RDE dY = V_0(t, Y) dt + V_1(t, Y) dX with V_0(t, y) = -t y,
V_1(t, y) = cos(t) y and the smooth driver X_t = t², the solution is
Y_T = Y_0 exp(-T²/2 + 2 (T sin T + cos T - 1)); Euler converges at order 1, Heun, Davie and the
log-ODE method at order 2 (their declared ``smooth_order``), which requires them to evaluate the
fields at the right times inside a step (an autonomous treatment, or left-point times in a
second-order scheme, drops to order 1).
"""

import numpy as np
import pytest

import roughpaths as rp


def drift(t, y):
    return -t * y


def drift_jac(t, y):
    return -t * np.ones(y.shape + (1,))


def field(t, y):
    return (np.cos(t) * y)[..., None]


def field_jac(t, y):
    return (np.cos(t) * np.ones(y.shape))[..., None, :, None]


def _exact(T, y0=1.0):
    return y0 * np.exp(-0.5 * T**2 + 2.0 * (T * np.sin(T) + np.cos(T) - 1.0))


@pytest.mark.parametrize("user_jacobian", [True, False])
@pytest.mark.parametrize("solver", [rp.Euler(), rp.Heun(), rp.Davie(), rp.LogODE()], ids=repr)
def test_time_dependent_fields_converge_at_the_declared_smooth_order(solver, user_jacobian):
    V = rp.VectorFields(field, field_jac if user_jacobian else None, drift=drift,
                        drift_jacobian=drift_jac if user_jacobian else None,
                        dim_state=1, dim_noise=1, time_dependent=True)
    T = 1.5
    ns = np.array([64, 128, 256, 512, 1024])
    errs = []
    for n in ns:
        t = np.linspace(0.0, T, n + 1)
        X = rp.RoughPath.from_path((t**2)[:, None], times=t)
        errs.append(abs(float(rp.solve(V, X, [1.0], solver).final[0]) - _exact(T)))
    slope = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    assert abs(slope - solver.smooth_order) < 0.15, (slope, errs)


def test_time_dependent_family_needs_the_time_and_says_so():
    V = rp.VectorFields(field, dim_state=1, dim_noise=1, time_dependent=True)
    np.testing.assert_allclose(V.fields(np.array([2.0]), t=np.pi), [[-2.0]])
    with pytest.raises(ValueError, match="t is required"):
        V.fields(np.array([2.0]))


def test_two_argument_callable_without_the_flag_gets_a_hint():
    with pytest.raises(TypeError, match="time_dependent=True"):
        rp.VectorFields(field, dim_state=1, dim_noise=1)


def test_friz_oberhauser_drift_of_a_time_dependent_family_is_time_dependent():
    """½ Σ s^{ij}[V_i, V_j](t, y) for V_1 = y rotated by angle t, V_2 = constant: a hand-computed bracket."""
    def fields(t, y):
        c, s_ = np.cos(t), np.sin(t)
        v1 = np.stack([c * y[..., 0] - s_ * y[..., 1], s_ * y[..., 0] + c * y[..., 1]], axis=-1)
        v2 = np.broadcast_to(np.array([1.0, 0.0]), y.shape)
        return np.stack([v1, v2], axis=-1)

    V = rp.VectorFields(fields, dim_state=2, dim_noise=2, time_dependent=True)
    s = np.array([[0.0, 1.0], [-1.0, 0.0]])
    f = V.friz_oberhauser_drift(s)
    t, y = 0.7, np.array([0.3, -0.4])
    # [V_1, V_2] = DV_2·V_1 - DV_1·V_2 = 0 - R(t) e_1;  ½(s^{12}[V_1,V_2] + s^{21}[V_2,V_1]) = [V_1, V_2]
    expected = -np.array([np.cos(t), np.sin(t)])
    np.testing.assert_allclose(f(t, y), expected, atol=1e-8)
