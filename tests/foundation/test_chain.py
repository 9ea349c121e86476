"""robot.chain and aa.load on robots a user brings: example-robot-data by name, continuous and
mimic joints, trees with several tips, pin.Model / RobotWrapper sources, keywords.

Oracles: Pinocchio (FK, Jacobians, pin.neutral, joint types), the URDF text (mimic
multipliers), mathematics (rigidity of rotations, unit (cos, sin) pairs)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.chain import CONTINUOUS, PRISMATIC, REVOLUTE
from anthroarm.errors import (
    AmbiguousToolError,
    UnknownFrameError,
    UnknownModelError,
    UnsupportedModelError,
)

USER_URDF = """<?xml version="1.0"?>
<robot name="user_arm">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1.0"/><origin xyz="0 0 0.1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="0.8"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.002" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l3"><inertial><mass value="0.5"/><origin xyz="0.05 0 0"/>
    <inertia ixx="0.001" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger_a"><inertial><mass value="0.05"/><origin xyz="0 0 0.02"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger_b"><inertial><mass value="0.05"/><origin xyz="0 0 0.02"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="spin" type="continuous"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.2" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <joint name="wrist" type="continuous"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.25 0 0"/><axis xyz="0.6 0 0.8"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l3"/><child link="tool"/>
    <origin xyz="0.1 0 0"/></joint>
  <joint name="grip" type="revolute"><parent link="l3"/><child link="finger_a"/>
    <origin xyz="0.1 0.02 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.8" effort="1"
      velocity="1"/></joint>
  <joint name="grip_mimic" type="revolute"><parent link="l3"/><child link="finger_b"/>
    <origin xyz="0.1 -0.02 0"/><axis xyz="1 0 0"/><limit lower="-0.8" upper="0"
      effort="1" velocity="1"/>
    <mimic joint="grip" multiplier="-1.0" offset="0.1"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


@pytest.mark.parametrize("name", ["ur10", "xarm7", "kinova", "z1", "double_pendulum_continuous"])
def test_example_robot_data_by_name(name):
    r = aa.load(name)
    assert r.chain.tool in r.tips and len(r.tips) == 1
    full = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path(name)))
    assert r.nq == full.nq and r.nv == full.nv


def test_kinova_continuous_joints_and_random_q_rigid():
    r = aa.load("kinova")
    kinds = [j.kind for j in r.chain.joints]
    short = [r.model.joints[j.index + 1].shortname() for j in r.chain.joints]
    assert kinds.count(CONTINUOUS) == sum("RUB" in s for s in short) == 3
    Q = r.random_q(500, rng=3)
    for j in r.chain.joints:
        if j.kind == CONTINUOUS:
            np.testing.assert_allclose(np.hypot(Q[:, j.idx_q], Q[:, j.idx_q + 1]), 1.0, atol=1e-15)
    T = r.fk(Q)
    R = T[:, :3, :3]
    np.testing.assert_allclose(
        np.einsum("nij,nkj->nik", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    # the angles are uniform on the circle: every quadrant is visited
    th = r.chain.angles(Q)[:, [j.index for j in r.chain.joints if j.kind == CONTINUOUS]]
    assert np.all(
        [np.histogram(th[:, k], bins=4, range=(-np.pi, np.pi))[0].min() > 60 for k in range(3)]
    )


def test_non_unit_cos_sin_pair_names_the_joint():
    r = aa.load("kinova")
    q = r.neutral()
    j = next(j for j in r.chain.joints if j.kind == CONTINUOUS)
    q[j.idx_q], q[j.idx_q + 1] = 2.0, 0.0
    with pytest.raises(ValueError, match=j.name):
        r.fk(q)
    Q = r.random_q(3, rng=0)
    Q[2, j.idx_q] *= 1.5
    with pytest.raises(ValueError, match=rf"{j.name}.*row 2"):
        r.fk(Q)


@pytest.mark.parametrize(
    "name,kw",
    [
        ("kinova", {}),
        ("panda", {}),
        ("ur10", {}),
        ("human_arm7", {}),
        ("prosthetic_arm", {}),
        ("baxter", {"tool": "l_gripper_r_finger_tip"}),  # through a mimic finger
        ("allegro_right_hand", {"tool": "link_3.0_tip"}),
        ("double_pendulum_continuous", {}),
    ],
)
def test_batched_fk_and_jacobian_equal_pinocchio(name, kw):
    r = aa.load(name, **kw)
    Q = r.random_q(64, rng=11)
    T, J = r.fk(Q), r.jacobian(Q)
    assert T.shape == (64, 4, 4) and J.shape == (64, 6, r.nv)
    m, d = r.model, r.model.createData()
    for q, Ti, Ji in zip(Q, T, J):
        pin.framesForwardKinematics(m, d, q)
        np.testing.assert_allclose(Ti, d.oMf[r.tool_id].homogeneous, atol=1e-12)
        np.testing.assert_allclose(
            Ji, pin.computeFrameJacobian(m, d, q, r.tool_id, pin.LOCAL_WORLD_ALIGNED), atol=1e-12
        )


def test_user_urdf_with_continuous_and_mimic(user_urdf):
    with pytest.raises(AmbiguousToolError) as e:
        aa.load(user_urdf)
    assert "tool" in str(e.value) and "finger_a" in str(e.value)
    r = aa.load(user_urdf, tool="tool")
    c = r.chain
    assert [j.kind for j in c.joints] == [CONTINUOUS, REVOLUTE, CONTINUOUS, REVOLUTE, REVOLUTE]
    mim = c.joint("grip_mimic")
    assert mim.is_mimic and c.joints[mim.mimic.source].name == "grip"
    assert (mim.mimic.multiplier, mim.mimic.offset) == (-1.0, 0.1)  # the URDF's tag
    np.testing.assert_allclose(c.joint("wrist").axis, [0.6, 0, 0.8])
    assert (r.nq, r.nv) == (6, 4)
    th = c.angles(r.random_q(10, rng=1))
    np.testing.assert_allclose(th[:, mim.index], -th[:, c.joint("grip").index] + 0.1)
    # FK of the mimic finger equals Pinocchio's
    Q = r.random_q(20, rng=2)
    np.testing.assert_allclose(
        r.fk(Q, "finger_b"), np.stack([r.fk(q, "finger_b") for q in Q]), atol=1e-12
    )
    np.testing.assert_allclose(
        r.jacobian(Q, "finger_b"), np.stack([r.jacobian(q, "finger_b") for q in Q]), atol=1e-12
    )


def test_configuration_inverts_angles(user_urdf):
    r = aa.load(user_urdf, tool="tool")
    q = r.random_q(rng=5)
    th = r.chain.angles(q)[list(r.chain.independent)]
    np.testing.assert_allclose(r.chain.configuration(th), q, atol=1e-15)


def _configuration_by_joint(chain, theta):
    """q from θ the long way, joint by joint (a continuous joint's q is (cos θ, sin θ))."""
    theta = np.asarray(theta, dtype=float)
    q = np.empty(theta.shape[:-1] + (chain.nq,))
    for k, i in enumerate(chain.independent):
        j = chain.joints[i]
        if j.kind == CONTINUOUS:
            q[..., j.idx_q], q[..., j.idx_q + 1] = np.cos(theta[..., k]), np.sin(theta[..., k])
        else:
            q[..., j.idx_q] = theta[..., k]
    return q


@pytest.mark.parametrize("source", ["kinova", "ur5", "prosthetic_hand", "user"])
def test_configuration_any_shape_is_joint_by_joint(source, user_urdf):
    """``configuration`` (a compiled kernel) equals the joint-by-joint reference on every batch
    shape — one θ, (N, n), (N, B, n), N = 0, a batch large enough to be split across threads —
    with continuous, mimic and prismatic joints, and keeps NaN rows NaN; a chain without
    independent joints gives empty configurations; a wrong last dimension or a scalar is a
    ValueError naming the joints."""
    r = aa.load(user_urdf, tool="tool") if source == "user" else aa.load(source)
    c, n = r.chain, len(r.chain.independent)
    rng = np.random.default_rng(9)
    for shape in [(n,), (7, n), (3, 5, n), (0, n), (0, 4, n), (9000, n)]:
        th = rng.uniform(-4, 4, shape)
        if th.size:
            th.reshape(-1, n)[0] = np.nan
        q = c.configuration(th)
        assert q.shape == shape[:-1] + (c.nq,)
        np.testing.assert_array_equal(q, _configuration_by_joint(c, th))
    for bad in (np.zeros(n + 1), np.float64(0.3)):
        with pytest.raises(ValueError, match="theta must have"):
            c.configuration(bad)
    none = aa.load("ur5", active=[])
    assert none.chain.configuration(np.zeros(0)).shape == (0,) and none.random_q(3).shape == (3, 0)


def test_tree_needs_a_tool_and_lists_tips():
    with pytest.raises(AmbiguousToolError) as e:
        aa.load("baxter")
    for tip in ("l_gripper_l_finger_tip", "r_gripper_r_finger_tip"):
        assert tip in str(e.value)
    r = aa.load("baxter", tool="left_gripper")
    assert r.tool == "left_gripper" and "l_gripper_l_finger_tip" in r.tips
    with pytest.raises(AmbiguousToolError, match="link_15.0_tip"):
        aa.load("allegro_right_hand")


def test_wrong_names_list_the_valid_ones():
    with pytest.raises(UnknownFrameError, match="tip frames: .*tool0"):
        aa.load("ur10", tool="nope")
    with pytest.raises(UnknownFrameError, match="shoulder_pan_joint"):
        aa.load("ur10", active=["shoulder_pan_joint", "elbow"])
    with pytest.raises(UnknownFrameError, match="shoulder_pan_joint"):
        aa.load("ur10", locked=["nope"])
    with pytest.raises(UnknownModelError, match="xarm7"):
        aa.load("xarm8")


def test_unknown_keyword_is_a_type_error(user_urdf):
    with pytest.raises(TypeError, match="foo"):
        aa.load(user_urdf, tool="tool", foo=1)
    with pytest.raises(TypeError, match="foo"):
        aa.load("ur10", foo=1)
    with pytest.raises(TypeError, match="foo"):
        aa.load("human_arm7", foo=1)
    with pytest.raises(TypeError):
        aa.load(3.5)


def test_locked_and_active(user_urdf):
    r = aa.load("ur10", locked={"wrist_3_joint": 0.4})
    assert r.nq == 5 and r.locked == {"wrist_3_joint": 0.4}
    full = aa.load("ur10")
    q5 = r.random_q(rng=0)
    q6 = np.r_[q5, 0.4]
    np.testing.assert_allclose(r.fk(q5), full.fk(q6), atol=1e-14)
    a = aa.load("ur10", active=["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"])
    assert a.nq == 3 and set(a.locked) == {"wrist_1_joint", "wrist_2_joint", "wrist_3_joint"}
    # a continuous joint locked at an angle; the mimic pair locked together
    u = aa.load(user_urdf, tool="tool", locked={"wrist": 0.7, "grip": 0.3, "grip_mimic": None})
    assert u.nq == 3 and u.locked["grip_mimic"] == pytest.approx(-0.3 + 0.1)
    with pytest.raises(UnsupportedModelError, match="grip_mimic"):
        aa.load(user_urdf, tool="tool", locked=["grip"])


def _ff_ball_model(frames: bool):
    m = pin.Model()
    j1 = m.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base_ff")
    m.appendBodyToJoint(j1, pin.Inertia.Random(), pin.SE3.Identity())
    b = m.addBodyFrame("body1", j1, pin.SE3.Identity(), m.addJointFrame(j1, 0)) if frames else 0
    j2 = m.addJoint(
        j1, pin.JointModelSpherical(), pin.SE3(pin.utils.rotate("x", 0.3), np.ones(3)), "ball"
    )
    m.appendBodyToJoint(j2, pin.Inertia.Random(), pin.SE3.Identity())
    if frames:
        m.addBodyFrame("body2", j2, pin.SE3.Identity(), m.addJointFrame(j2, b))
    return m


def test_model_without_frames_cannot_be_reduced_but_does_not_crash():
    """pin.buildReducedModel segfaults on a model whose joints have no frames."""
    with pytest.raises(UnsupportedModelError, match="joint frame"):
        aa.load(_ff_ball_model(frames=False), locked=["base_ff", "ball"])


def test_free_flyer_and_spherical_are_refused_with_advice():
    m = _ff_ball_model(frames=True)
    with pytest.raises(UnsupportedModelError, match="base_ff.*locked="):
        aa.load(m)
    with pytest.raises(UnsupportedModelError, match="ball.*active="):
        aa.load(m, locked=["base_ff"])
    r = aa.load(m, locked=["base_ff", "ball"], tool="body2")
    assert r.nq == 0 and r.fk(np.zeros(0)).shape == (4, 4)


def test_pin_model_and_robot_wrapper_sources():
    path = str(aa.models.erd_urdf_path("ur10"))
    model = pin.buildModelFromUrdf(path)
    r = aa.load(model, tool="tool0", name="my_ur10")
    assert r.name == "my_ur10" and r.info is None and r.nq == 6
    q = r.random_q(rng=1)
    np.testing.assert_allclose(r.fk(q), aa.load("ur10").fk(q), atol=1e-14)
    erd_share = aa.urdf_io.default_package_dirs()["example-robot-data"].parent  # .../share
    w = pin.RobotWrapper.BuildFromURDF(path, [str(erd_share)])
    rw = aa.load(w)
    assert rw.visual_model is not None and rw.tool == "tool0"
    with pytest.raises(TypeError, match="package_dirs"):
        aa.load(model, package_dirs=["/tmp"])


def test_models_lists_example_robot_data():
    names = aa.models.erd_names()
    for n in ("ur10", "xarm7", "kinova", "z1", "so101", "baxter", "allegro_right_hand"):
        assert n in names
    assert aa.models.erd_urdf_path("xarm7").is_file()


def test_joint_kinds_from_pinocchio_types():
    """PX/PY/PZ and RX/RY/RZ (axis-aligned) and unaligned joints all read right."""
    r = aa.load("baxter", tool="left_gripper")
    for j in r.chain.joints:
        short = r.model.joints[j.index + 1].shortname()
        if short.startswith("JointModelP"):
            assert j.kind == PRISMATIC and j.axis[ord(short[-1]) - ord("X")] == 1.0
        if short in ("JointModelRX", "JointModelRY", "JointModelRZ"):
            assert j.kind == REVOLUTE and j.axis[ord(short[-1]) - ord("X")] == 1.0


def test_default_pinocchio_limits_mean_unbounded():
    """A pin.Model built in code keeps ±DBL_MAX limits: sampling must not overflow."""
    m = pin.Model()
    j = m.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "hinge")
    f = m.addJointFrame(j, 0)
    m.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.1), pin.SE3.Identity())
    m.addBodyFrame("tip", j, pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.5])), f)
    assert m.upperPositionLimit[0] > 1e300
    r = aa.load(m)
    assert r.chain.joint("hinge").upper == np.inf and r.tool == "tip"
    Q = r.random_q(1000, rng=0)
    assert np.all(np.isfinite(Q)) and np.all(np.abs(Q) <= np.pi)
    np.testing.assert_allclose(
        r.fk(Q)[:, 2, 3], 0.5 * np.cos(Q[:, 0]), atol=1e-15
    )  # Ry(θ) e_z · 0.5


def test_batched_positions_equal_pinocchio():
    r = aa.load("kinova")
    Q = r.random_q(50, rng=4)
    d = r.model.createData()
    P = r.chain.serial().positions(Q)
    for q, p in zip(Q, P):
        pin.framesForwardKinematics(r.model, d, q)
        np.testing.assert_allclose(p, d.oMf[r.tool_id].translation, atol=1e-12)
    assert r.chain.serial().positions(Q[0]).shape == (3,)
    assert aa.batch.reachability_map is not None  # aa.batch is a lazy attribute
