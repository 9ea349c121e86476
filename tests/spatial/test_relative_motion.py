"""002 §4-1 relative motion (4-1)-(4-17) against a Pinocchio chain and finite differences;
the printed (4-9), (4-14), (4-16) forms fail."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rate, unit3, vec3
from hypothesis import given, settings

from anthroarm.mechanisms.relative_motion import (
    RelativeMotionGeometry,
    pinocchio_model,
    relative_acceleration,
    relative_position,
    relative_velocity,
)
from anthroarm.spatial.rotations import skew

H = settings(max_examples=40, deadline=None)
LWA = pin.LOCAL_WORLD_ALIGNED


@H
@given(unit3, vec3, unit3, vec3, vec3, angle, rate, rate, angle, rate, rate, vec3)
def test_against_pinocchio_frame_velocity_and_classical_acceleration(
    u0, p0, u1, p1, q1, th, thd, thdd, ph, phd, phdd, svec
):
    s, sd, sdd = svec
    g = RelativeMotionGeometry(u0, p0, u1, p1, q1)
    pos = relative_position(g, th, ph, s)
    v = relative_velocity(g, th, thd, ph, phd, s, sd)
    a = relative_acceleration(g, th, thd, thdd, ph, phd, phdd, s, sd, sdd)
    model, fid = pinocchio_model(g)
    data = model.createData()
    pin.forwardKinematics(
        model, data, np.array([th, s, ph]), np.array([thd, sd, phd]), np.array([thdd, sdd, phdd])
    )
    pin.updateFramePlacements(model, data)
    assert np.allclose(pos.q, data.oMf[fid].translation, atol=1e-12)
    assert np.allclose(v.total, pin.getFrameVelocity(model, data, fid, LWA).linear, atol=1e-11)
    assert np.allclose(
        a.total, pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear, atol=1e-10
    )
    # transport velocity = velocity of the coincident point of link 2 (joint 1 only)
    pin.forwardKinematics(
        model, data, np.array([th, s, ph]), np.array([thd, 0, 0]), np.array([thdd, 0, 0])
    )
    pin.updateFramePlacements(model, data)
    assert np.allclose(v.transport, pin.getFrameVelocity(model, data, fid, LWA).linear, atol=1e-11)
    assert np.allclose(
        a.transport, pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear, atol=1e-10
    )


@H
@given(unit3, vec3, unit3, vec3, vec3, angle, rate, angle, rate, vec3)
def test_against_finite_differences(u0, p0, u1, p1, q1, th, thd, ph, phd, svec):
    s, sd, sdd = svec
    g = RelativeMotionGeometry(u0, p0, u1, p1, q1)
    thdd, phdd = 0.3, -0.7
    traj = lambda t: (
        th + thd * t + 0.5 * thdd * t * t,
        ph + phd * t + 0.5 * phdd * t * t,
        s + sd * t + 0.5 * sdd * t * t,
    )
    q = lambda t: relative_position(g, *traj(t)).q
    h = 1e-4
    v = relative_velocity(g, th, thd, ph, phd, s, sd)
    a = relative_acceleration(g, th, thd, thdd, ph, phd, phdd, s, sd, sdd)
    assert np.allclose(v.total, (q(h) - q(-h)) / (2 * h), atol=1e-6)
    assert np.allclose(a.total, (q(h) - 2 * q(0) + q(-h)) / h**2, atol=1e-4)


def test_printed_forms_fail():
    rng = np.random.default_rng(7)
    u0, u1 = (x / np.linalg.norm(x) for x in rng.normal(size=(2, 3)))
    g = RelativeMotionGeometry(u0, rng.normal(size=3), u1, rng.normal(size=3), rng.normal(size=3))
    th, thd, thdd, ph, phd, phdd, s, sd, sdd = 0.4, 1.2, -0.5, -0.8, 0.9, 0.6, 0.3, 0.7, -0.4
    pos = relative_position(g, th, ph, s)
    v = relative_velocity(g, th, thd, ph, phd, s, sd)
    a = relative_acceleration(g, th, thd, thdd, ph, phd, phdd, s, sd, sdd)
    W0, Wu = thd * skew(g.u0), phd * skew(pos.u)
    P0, Pu = skew(g.u0), skew(pos.u)
    # (4-9) printed: q̇_r = [W_{φ̇,u0}](q − p) + s u
    printed_qr = phd * skew(g.u0) @ (pos.q - pos.p) + s * pos.u
    assert not np.allclose(printed_qr, v.relative, atol=1e-6)
    # (4-14) printed: q̈_r = [E_{φ̇,φ̈,u}](q − p) + ṡ u
    Eu = phdd * Pu + phd**2 * Pu @ Pu
    assert not np.allclose(Eu @ (pos.q - pos.p) + sd * pos.u, a.relative, atol=1e-6)
    # (4-16) printed: q̈_k = 2[W_θ][W_φ](q − p) + ṡ u (the bracket misplaced)
    assert not np.allclose(2 * W0 @ Wu @ (pos.q - pos.p) + sd * pos.u, a.coriolis, atol=1e-6)
    # (4-17) as printed is right
    E0 = thdd * P0 + thd**2 * P0 @ P0
    printed_417 = (
        E0 @ (pos.q - g.p0)
        + Eu @ (pos.q - pos.p)
        + sdd * pos.u
        + 2 * W0 @ (sd * pos.u)
        + 2 * W0 @ Wu @ (pos.q - pos.p)
    )
    assert np.allclose(printed_417, a.total, atol=1e-12)


def test_coriolis_vanishes_without_transport_rotation_or_relative_motion():
    g = RelativeMotionGeometry([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0], [0.5, 0, 0], [0.5, 0.2, 0.1])
    a = relative_acceleration(g, 0.3, 0.0, 0.4, 0.2, 1.0, 0.0, 0.1, 0.5, 0.0)
    assert np.allclose(a.coriolis, 0)
    a = relative_acceleration(g, 0.3, 1.0, 0.0, 0.2, 0.0, 0.0, 0.1, 0.0, 0.0)
    assert np.allclose(a.coriolis, 0)
    a = relative_acceleration(
        g, 0.3, 1.0, 0.0, 0.2, 0.0, 0.0, 0.1, 0.5, 0.0
    )  # slide on a rotating link
    assert np.allclose(
        a.coriolis, 2 * np.cross([0, 0, 1.0], 0.5 * relative_position(g, 0.3, 0.2, 0.1).u)
    )


def test_batch_and_moving_base():
    g = RelativeMotionGeometry([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0], [0.5, 0, 0], [0.5, 0.2, 0.1])
    th = np.linspace(0, 1, 5)
    v = relative_velocity(g, th, np.ones(5), th, np.ones(5), th, np.ones(5), p0_dot=[1.0, 0, 0])
    v1 = relative_velocity(g, th[3], 1, th[3], 1, th[3], 1, p0_dot=[1.0, 0, 0])
    assert v.total.shape == (5, 3) and np.allclose(v.total[3], v1.total)
    a = relative_acceleration(g, th, 1, 0, th, 1, 0, th, 1, 0, p0_ddot=[0, 2.0, 0])
    a0 = relative_acceleration(g, th, 1, 0, th, 1, 0, th, 1, 0)
    assert np.allclose(a.total - a0.total, [0, 2.0, 0])


def test_relative_motion_bad_input():
    with pytest.raises(ValueError, match="zero length"):
        RelativeMotionGeometry([0, 0, 0], [0, 0, 0], [1.0, 0, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="unit vector"):
        RelativeMotionGeometry([0, 0, 2.0], [0, 0, 0], [1.0, 0, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="q1"):
        RelativeMotionGeometry([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0], [0, 0, 0], [0, np.nan, 0])
    g = RelativeMotionGeometry([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0], [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="theta"):
        relative_position(g, np.nan, 0, 0)
