"""Rotation tensor E^{wθ} (5-88)–(5-130) and DCM kinematics (5-85)–(5-87′)."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rate, rotation, unit3, vec3
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.spatial import rotation_tensor as T
from anthroarm.spatial.rotations import rot_y, rot_z, skew, unit_axis

H = settings(max_examples=40, deadline=None)


def printed_5_104(w, th):
    """(5-104) as printed (line 3168): a33 = cos θ + ν²(1 − cos²θ)."""
    l, m, n = w
    c, s = np.cos(th), np.sin(th)
    v = 1 - c
    return np.array(
        [
            [c + l * l * v, l * m * v - n * s, n * l * v + m * s],
            [l * m * v + n * s, c + m * m * v, m * n * v - l * s],
            [n * l * v - m * s, m * n * v + l * s, c + n * n * (1 - c**2)],
        ]
    )


@H
@given(unit3, angle)
def test_rotation_tensor_is_exp3_and_5_104(w, th):
    E = T.rotation_tensor(w, th)
    assert np.allclose(E, pin.exp3(th * w), atol=1e-14)
    P = printed_5_104(w, th)
    assert np.allclose(P[:2], E[:2]) and np.allclose(P[2, :2], E[2, :2])
    if abs(w[2]) > 0.3 and abs(np.sin(th)) > 0.3:
        assert not np.isclose(P[2, 2], E[2, 2])  # the printed (3,3) element is wrong


@H
@given(unit3, angle, vec3)
def test_rotate_5_88_inverse_transpose_det(w, th, R):
    Rp = T.rotate(w, th, R)
    assert np.allclose(T.rotate(w, -th, Rp), R, atol=1e-12)  # E^{w(-θ)}(R') = R
    E = T.rotation_tensor(w, th)
    assert np.isclose(np.linalg.det(E), 1.0)  # (5-113)
    assert np.allclose(np.linalg.inv(E), E.T) and np.allclose(
        E.T, T.rotation_tensor(w, -th)
    )  # (5-114)-(5-116)
    for J in (T.J1(w), T.J2(w), T.J3(w)):
        assert np.linalg.svd(J, compute_uv=False).min() < 1e-12  # (5-117): |J| = 0


@H
@given(unit3)
def test_J_product_table_5_118(w):
    P = T.component_products(w)
    J1, J2, J3 = T.J1(w), T.J2(w), T.J3(w)
    Z = np.zeros((3, 3))
    expected = {
        "J1J1": J1,
        "J1J2": Z,
        "J1J3": Z,
        "J2J1": Z,
        "J2J2": J2,
        "J2J3": J3,
        "J3J1": Z,
        "J3J2": J3,
        "J3J3": -J2,
    }
    for k, v in expected.items():
        assert np.allclose(P[k], v, atol=1e-14), k
    assert np.allclose(J3, pin.skew(w))


@H
@given(st.floats(0, np.pi), angle, angle)
def test_axis_from_angles_5_101_and_conjugation_5_103(alpha, beta, th):
    w = T.axis_from_angles(alpha, beta)
    Ek = lambda a: rot_z(a)  # E^{kθ}
    Ej = lambda a: rot_y(a)
    assert np.allclose(w, Ek(beta) @ Ej(alpha) @ [0, 0, 1])  # (5-100)
    E = Ek(beta) @ Ej(alpha) @ Ek(th) @ Ej(-alpha) @ Ek(-beta)  # (5-102)/(5-103) with β outside
    assert np.allclose(E, T.rotation_tensor(w, th), atol=1e-14)
    printed = Ek(th) @ Ej(alpha) @ Ek(th) @ Ej(-alpha) @ Ek(-th)  # the OCR's outer θ
    if abs(np.sin(alpha)) > 0.2 and abs(np.sin(th - beta)) > 0.2 and abs(np.sin(th)) > 0.2:
        assert not np.allclose(printed, E, atol=1e-6)


@H
@given(angle, angle, vec3)
def test_noncommutativity_5_109_5_110(a, b, R):
    x, y, z = R
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    R1 = rot_z(b) @ rot_y(a) @ R
    R2 = rot_y(a) @ rot_z(b) @ R
    assert np.allclose(
        R1, [(x * ca + z * sa) * cb - y * sb, (x * ca + z * sa) * sb + y * cb, -x * sa + z * ca]
    )
    assert np.allclose(
        R2, [(x * cb - y * sb) * ca + z * sa, x * sb + y * cb, -(x * cb - y * sb) * sa + z * ca]
    )


@H
@given(unit3, angle, vec3, vec3)
def test_dot_and_cross_invariance_5_119_5_120(w, th, A, B):
    EA, EB = T.rotate(w, th, A), T.rotate(w, th, B)
    assert np.isclose(EA @ EB, A @ B)
    assert np.allclose(np.cross(EA, EB), T.rotate(w, th, np.cross(A, B)), atol=1e-12)


# ----------------------------------------------------------------------------- derivatives
@H
@given(unit3, vec3, angle, rate, rate)
def test_tensor_rates_5_122_5_129_with_moving_axis_vs_fd(w0, dv, th0, thd, thdd):
    wd0 = np.cross(w0, dv)  # initial axis rate ⟂ w

    def w_of(t):  # a unit axis path
        v = w0 + t * wd0 + 0.5 * t * t * dv
        return v / np.linalg.norm(v)

    def th_of(t):
        return th0 + thd * t + 0.5 * thdd * t * t

    h = 1e-4
    E = lambda t: T.rotation_tensor(w_of(t), th_of(t))
    w1 = (w_of(h) - w_of(-h)) / (2 * h)
    w2 = (w_of(h) - 2 * w_of(0) + w_of(-h)) / h**2
    Ed = (E(h) - E(-h)) / (2 * h)
    Edd = (E(h) - 2 * E(0) + E(-h)) / h**2
    assert np.allclose(T.rotation_tensor_rate(w_of(0), th0, thd, w1), Ed, atol=1e-6)
    assert np.allclose(T.rotation_tensor_acc(w_of(0), th0, thd, thdd, w1, w2), Edd, atol=1e-4)
    # fixed axis: (5-125) Ė = θ̇ J3 E and (5-129) Ë = θ̈ J3 E − θ̇² J2 E
    E0 = T.rotation_tensor(w0, th0)
    assert np.allclose(T.rotation_tensor_rate(w0, th0, thd), thd * T.J3(w0) @ E0, atol=1e-12)
    assert np.allclose(
        T.rotation_tensor_acc(w0, th0, thd, thdd),
        thdd * T.J3(w0) @ E0 - thd**2 * T.J2(w0) @ E0,
        atol=1e-12,
    )


def _rp_chain(w):
    """Revolute about w at the origin, then prismatic x, y, z (R in the rotating frame)."""
    model = pin.Model()
    I = pin.Inertia.FromSphere(1.0, 0.1)
    j = model.addJoint(0, pin.JointModelRevoluteUnaligned(w), pin.SE3.Identity(), "rot")
    model.appendBodyToJoint(j, I, pin.SE3.Identity())
    for n, jm in (
        ("px", pin.JointModelPX()),
        ("py", pin.JointModelPY()),
        ("pz", pin.JointModelPZ()),
    ):
        j = model.addJoint(j, jm, pin.SE3.Identity(), n)
        model.appendBodyToJoint(j, I, pin.SE3.Identity())
    fid = model.addFrame(pin.Frame("tip", j, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return model, fid


@H
@given(unit3, angle, rate, rate, vec3, vec3, vec3)
def test_rotated_vector_5_126_5_130_vs_pinocchio(w, th, thd, thdd, R, Rd, Rdd):
    m = T.rotated_vector_motion(w, th, thd, thdd, R, Rd, Rdd)
    model, fid = _rp_chain(w)
    data = model.createData()
    pin.forwardKinematics(model, data, np.r_[th, R], np.r_[thd, Rd], np.r_[thdd, Rdd])
    pin.updateFramePlacements(model, data)
    LWA = pin.LOCAL_WORLD_ALIGNED
    assert np.allclose(m.position, data.oMf[fid].translation, atol=1e-12)
    assert np.allclose(m.velocity, pin.getFrameVelocity(model, data, fid, LWA).linear, atol=1e-12)
    assert np.allclose(
        m.acceleration, pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear, atol=1e-11
    )
    # the four named terms of (5-130)
    E = T.rotation_tensor(w, th)
    assert np.allclose(m.tangential, E @ (thdd * np.cross(w, R)))
    assert np.allclose(
        m.centripetal, E @ (thd**2 * np.cross(w, np.cross(w, R)))
    )  # −θ̇² J2 R = θ̇² w×(w×R)
    assert np.allclose(m.coriolis, 2 * thd * E @ np.cross(w, Rd))
    assert np.allclose(m.relative, E @ Rdd)
    assert np.allclose(m.velocity, m.rotation_velocity + m.stretch_velocity)


def test_rotated_vector_motion_batch():
    w = unit_axis([1.0, 2.0, -1.0])
    th = np.linspace(0, 1, 4)
    R = np.tile([0.3, -0.2, 0.5], (4, 1))
    m = T.rotated_vector_motion(w, th, 0.5 * np.ones(4), np.zeros(4), R, R, R)
    m1 = T.rotated_vector_motion(w, th[2], 0.5, 0.0, R[2], R[2], R[2])
    assert m.acceleration.shape == (4, 3)
    assert np.allclose(m.acceleration[2], m1.acceleration)


# ----------------------------------------------------------------------------- DCM kinematics
@H
@given(rotation(), vec3, vec3)
def test_dcm_kinematics_5_85_to_5_87_vs_pinocchio(C, wb, wbd):
    """A spherical-joint body: pin's LOCAL angular velocity / acceleration are the body ω, ω̇."""
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "ball")
    model.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.1), pin.SE3.Identity())
    data = model.createData()
    q = pin.Quaternion(C).coeffs()
    pin.forwardKinematics(model, data, q, wb, wbd)
    w_space = pin.getVelocity(model, data, j, pin.WORLD).angular
    assert np.allclose(T.body_to_space_rate(C, skew(wb)), skew(w_space), atol=1e-12)  # (5-86)
    Cd_body = T.dcm_rate(C, wb, "body")
    assert np.allclose(Cd_body, T.dcm_rate(C, w_space, "space"), atol=1e-12)  # (5-85) = (5-85')
    assert np.allclose(T.angular_velocity(C, Cd_body, "body"), wb, atol=1e-12)
    assert np.allclose(T.angular_velocity(C, Cd_body, "space"), w_space, atol=1e-12)
    # (5-87) vs finite differences of C(t) = C exp(t wb + t²/2 wbd)
    h = 1e-4
    Ct = lambda t: C @ pin.exp3(t * wb + 0.5 * t * t * wbd)
    Cdd = (Ct(h) - 2 * Ct(0) + Ct(-h)) / h**2
    assert np.allclose(T.dcm_acc(C, wb, wbd, "body"), Cdd, atol=1e-5)
    wsd = C @ wbd  # space angular acceleration (ω̇_s = C ω̇_b since ω_s × ω_s = 0)
    assert np.allclose(T.dcm_acc(C, w_space, wsd, "space"), Cdd, atol=1e-5)
    assert np.allclose(pin.getAcceleration(model, data, j, pin.LOCAL).angular, wbd)


def test_rotation_tensor_bad_input():
    with pytest.raises(ValueError, match="zero length"):
        T.rotation_tensor([0, 0, 0], 1.0)
    with pytest.raises(ValueError, match="unit vector"):
        T.J1([1.0, 1.0, 0])
    with pytest.raises(ValueError, match="frame"):
        T.dcm_rate(np.eye(3), [0, 0, 1], "moving")
    with pytest.raises(ValueError, match="not orthogonal"):
        T.dcm_acc(np.ones((3, 3)), [0, 0, 1], [0, 0, 0])
    with pytest.raises(ValueError, match="theta_dot must be finite"):
        T.rotation_tensor_rate([0, 0, 1.0], 0.1, np.nan)
    with pytest.raises(ValueError, match="theta_ddot must be finite"):
        T.rotation_tensor_acc([0, 0, 1.0], 0.1, 1.0, np.inf)
    with pytest.raises(ValueError, match="C_dot"):
        T.angular_velocity(np.eye(3), np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match="W_body"):
        T.body_to_space_rate(np.eye(3), np.full((3, 3), np.nan))
