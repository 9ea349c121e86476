"""Tips are read from the joint tree: a serial chain has one tip, a tree one per leaf joint.

Oracles: Pinocchio (frame placements of ``buildSampleModelManipulator`` on random q), the tool
every catalog and example-robot-data robot loaded with before tips were read from the joint
tree (literals below: documented behaviour, recorded by running the code before the change)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import AmbiguousToolError

#: the tool of every catalog name (``aa.models.names()``), loaded without tool=
CATALOG_TOOLS = {
    "articulated_robot": "tool",
    "care_robot": "grip",
    "cartesian_robot": "tool",
    "cylindrical_robot": "tool",
    "human_arm7": "hand_point",
    "human_right_arm": "right_hand",
    "human_upper_limb": "hand_point",
    "panda": "panda_hand",
    "planar2r": "tip",
    "prosthetic_arm": "palm",
    "prosthetic_hand": "index_tip",
    "rrprr5": "gripper",
    "sixr_arm": "hand",
    "spherical_robot": "tool",
    "talos_arm": "gripper_left_base_link",
    "unimate5": "hand",
    "ur5": "tool0",
}

#: example-robot-data robots by name: (tool=, the tool they load with)
ERD_TOOLS = {
    "ur5": (None, "tool0"),
    "ur10": (None, "tool0"),
    "panda": (None, "panda_hand"),
    "kinova": (None, "j2s6s200_end_effector"),
    "xarm7": (None, "link_eef"),
    "talos_arm": (None, "gripper_left_base_link"),
    "z1": (None, "gripperMover"),
    "so100": (None, "jaw"),
    "double_pendulum": (None, "link2"),
    "baxter": ("left_gripper", "left_gripper"),
    "allegro_right_hand": ("link_3.0_tip", "link_3.0_tip"),
}


def test_catalog_covers_every_name():
    assert sorted(CATALOG_TOOLS) == sorted(aa.models.names())


@pytest.mark.parametrize("name", sorted(CATALOG_TOOLS))
def test_catalog_tool_unchanged(name):
    r = aa.load(name)
    assert r.tool == CATALOG_TOOLS[name]


@pytest.mark.parametrize("name", sorted(ERD_TOOLS))
def test_example_robot_data_tool_unchanged(name):
    tool, expected = ERD_TOOLS[name]
    r = aa.load(name, tool=tool)
    assert r.tool == expected


def test_trees_still_list_their_tips():
    with pytest.raises(AmbiguousToolError) as e:
        aa.load("allegro_right_hand")
    for tip in ("link_3.0_tip", "link_7.0_tip", "link_11.0_tip", "link_15.0_tip"):
        assert tip in str(e.value)
    # a link fixed to a moving body with nothing below it is a tip, on a leaf joint or not
    with pytest.raises(AmbiguousToolError) as e:
        aa.load("so101")
    assert "gripper_frame_link" in str(e.value) and "moving_jaw_so101_v1_link" in str(e.value)


def test_sample_manipulator_is_serial_and_matches_pinocchio():
    model = pin.buildSampleModelManipulator()
    r = aa.load(model)
    assert r.tips == ("effector_body",) and r.tool == "effector_body"
    rng = np.random.default_rng(29)
    Q = r.random_q(40, rng=rng)
    T = r.fk(Q)
    data = model.createData()
    for q, Ti in zip(Q, T):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(Ti, data.oMf[r.tool_id].homogeneous, atol=1e-12)
        np.testing.assert_allclose(r.fk(q), Ti, atol=1e-12)


def _link(model, parent, name, placement, axis=pin.JointModelRY):
    jid = model.addJoint(parent, axis(), placement, name)
    model.appendBodyToJoint(jid, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    model.addJointFrame(jid)
    model.addBodyFrame(name + "_body", jid, pin.SE3.Identity(), -1)
    return jid


def _up(z):
    return pin.SE3(np.eye(3), np.array([0.0, 0.0, z]))


def test_tree_built_in_code_lists_its_tips():
    m = pin.Model()
    j1 = _link(m, 0, "trunk", _up(0.1), pin.JointModelRZ)
    a = _link(m, j1, "left", _up(0.3))
    _link(m, a, "left_end", _up(0.2))
    _link(m, j1, "right", _up(0.3))
    with pytest.raises(AmbiguousToolError) as e:
        aa.load(m)
    msg = str(e.value)
    assert "2 tips" in msg and "left_end_body" in msg and "right_body" in msg
    assert "trunk_body" not in msg and "left_body," not in msg
    r = aa.load(m, tool="right_body")
    assert r.tips == ("left_end_body", "right_body")


def test_serial_chain_rule_for_several_frames_on_the_last_joint():
    """The tip is the last body or operational frame on the last joint (a name saying tool,
    tcp, end effector, eef or hand first); with none, the last frame on it that is not its
    joint frame, else its joint frame."""
    m = pin.Model()
    j = 0
    for k in range(3):
        j = _link(m, j, f"j{k}", _up(0.2))
    m.addFrame(pin.Frame("marker", j, 0, _up(0.05), pin.FrameType.OP_FRAME))
    assert aa.load(m).tool == "marker"  # added after j2_body
    m.addFrame(pin.Frame("tcp", j, 0, _up(0.1), pin.FrameType.OP_FRAME))
    m.addFrame(pin.Frame("probe", j, 0, _up(0.1), pin.FrameType.OP_FRAME))
    assert aa.load(m).tool == "tcp"  # a tool name wins over the order
    bare = pin.Model()
    j = 0
    for k in range(3):
        j = bare.addJoint(j, pin.JointModelRX(), _up(0.2), f"j{k}")
        bare.addJointFrame(j)
    assert aa.load(bare).tips == ("j2",)  # only joint frames: the last joint's
    bare.addFrame(pin.Frame("imu", j, 0, _up(0.1), pin.FrameType.SENSOR))
    assert aa.load(bare).tips == ("imu",)
