"""002 §4-1 screw matrix (4-6), [R], [W], [E] against pin.exp3/exp6/log6 and finite differences."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rate, small, unit3, vec3
from hypothesis import given, settings

from anthroarm.spatial import screw as S

H = settings(max_examples=40, deadline=None)


@H
@given(unit3, angle)
def test_rotation_matrix_002_is_exp3(u, th):
    assert np.allclose(S.rotation_matrix(th, u), pin.exp3(th * u), atol=1e-14)
    assert np.allclose(S.P(u), pin.skew(u)) and np.allclose(S.Q(u), np.outer(u, u))


@H
@given(unit3, angle, small, vec3, vec3)
def test_screw_matrix_4_6_is_exp6_and_steps_4_4_4_5(u, phi, s, p, q1):
    T = S.screw_matrix(phi, s, u, p)
    tw = S.screw_twist(phi, s, u, p)
    assert np.allclose(T, pin.exp6(pin.Motion(tw[:3], tw[3:])).homogeneous, atol=1e-13)
    # (4-4)/(4-5): slide along u then rotate about the moved axis
    R = S.rotation_matrix(phi, u)
    p_new = p + s * u
    q = R @ (q1 + s * u - p_new) + p_new
    assert np.allclose((T @ np.append(q1, 1))[:3], q, atol=1e-12)
    printed = R @ q1 + p + s * u  # the print's [[R, p1' + s u]] acting on (q1'; 1) (lost "- p1'")
    if np.linalg.norm((np.eye(3) - R) @ p) > 1e-6:
        assert not np.allclose(printed, q, atol=1e-9)


@H
@given(unit3, angle, small, vec3)
def test_screw_parameters_round_trip_and_log6(u, phi, s, p):
    T = S.screw_matrix(phi, s, u, p)
    ph, ss, uu, pp = S.screw_parameters(T)
    assert np.allclose(S.screw_matrix(ph, ss, uu, pp), T, atol=1e-9)
    if 1e-3 < abs(phi) < np.pi - 1e-3:
        tw = pin.log6(pin.SE3(T)).vector
        assert np.isclose(ph, np.linalg.norm(tw[3:]), atol=1e-9)
        assert np.isclose(ss, tw[:3] @ tw[3:] / np.linalg.norm(tw[3:]), atol=1e-9)


def test_screw_parameters_pure_translation_and_identity():
    ph, s, u, p = S.screw_parameters(S.screw_matrix(0.0, 0.7, [0, 1.0, 0], [1, 2, 3]))
    assert ph == 0 and np.isclose(s, 0.7) and np.allclose(u, [0, 1, 0])
    assert S.screw_parameters(np.eye(4))[:2] == (0.0, 0.0)


@H
@given(unit3, angle, rate, rate, vec3, vec3)
def test_velocity_and_acceleration_matrices_vs_fd(u, th, thd, thdd, p, q0):
    """q(t) = p + R(θ(t), u)(q0 − p): q̇ = [W](q − p), q̈ = [E](q − p) (002 line 88, (4-13))."""
    th_of = lambda t: th + thd * t + 0.5 * thdd * t * t
    q_of = lambda t: p + S.rotation_matrix(th_of(t), u) @ (q0 - p)
    h = 1e-4
    qd = (q_of(h) - q_of(-h)) / (2 * h)
    qdd = (q_of(h) - 2 * q_of(0) + q_of(-h)) / h**2
    assert np.allclose(S.velocity_matrix(thd, u) @ (q_of(0) - p), qd, atol=1e-6)
    assert np.allclose(S.acceleration_matrix(thd, thdd, u) @ (q_of(0) - p), qdd, atol=1e-4)
    W = S.velocity_matrix(thd, u)
    assert np.allclose(S.angular_velocity_of(W), thd * u)


def test_acceleration_matrix_with_moving_axis_vs_fd():
    rng = np.random.default_rng(2)
    u0 = rng.normal(size=3)
    ud = rng.normal(size=3)
    u_of = lambda t: (u0 + t * ud) / np.linalg.norm(u0 + t * ud)
    # E = φ̈ P + φ̇ Ṗ + φ̇² P²: the derivative of W(t) = φ̇ P(u(t)) plus W² — check Ẇ by differences
    h = 1e-6
    W = lambda t: S.velocity_matrix(1.1, u_of(t))
    Wd = (W(h) - W(-h)) / (2 * h)
    ud0 = (u_of(h) - u_of(-h)) / (2 * h)
    E = S.acceleration_matrix(1.1, 0.0, u_of(0), ud0)
    assert np.allclose(E, Wd + W(0) @ W(0), atol=1e-8)


def test_screw_bad_input():
    with pytest.raises(ValueError, match="zero length"):
        S.screw_matrix(0.1, 0, [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="unit vector"):
        S.velocity_matrix(1.0, [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="point p"):
        S.screw_matrix(0.1, 0, [0, 0, 1], [0, np.nan, 0])
    with pytest.raises(ValueError, match="4x4"):
        S.screw_parameters(np.eye(3))
    with pytest.raises(ValueError, match="phi must be finite"):
        S.screw_twist(np.nan, 0.0, [0, 0, 1.0], [0, 0, 0])
    with pytest.raises(ValueError, match="phi_dot must be finite"):
        S.velocity_matrix(np.nan, [0, 0, 1.0])
    with pytest.raises(ValueError, match="phi_ddot must be finite"):
        S.acceleration_matrix(1.0, np.inf, [0, 0, 1.0])
