"""hand.Hand: fingers, arm joints, palm, pad normals and span read from the tree.

Oracles: Pinocchio's frame Jacobians (a joint belongs to a finger iff its column moves that
fingertip and no other), the tip velocity of the distal joint (the pad normal is its direction),
Pinocchio FK distances between fingertips (bounded by the span)."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import CouplingError, FingertipError
from anthroarm.hand import Hand


@pytest.fixture(scope="module")
def allegro():
    return aa.load("allegro_right_hand", tool="link_3.0_tip")


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


@pytest.fixture(scope="module")
def linkage():
    """The book's linkage hand as a plain URDF: passive joints are mimic joints, bars are leaves."""
    return aa.load("prosthetic_hand")


def _moving_columns(robot, q, frame_id):
    d = robot.model.createData()
    J = pin.computeFrameJacobian(robot.model, d, q, frame_id, pin.LOCAL_WORLD_ALIGNED)
    return set(np.flatnonzero(np.abs(J).max(axis=0) > 1e-12).tolist())


@pytest.mark.parametrize("name", ["allegro", "limb", "linkage"])
def test_fingers_are_the_joints_that_move_one_tip_only(name, request):
    robot = request.getfixturevalue(name)
    hand = Hand(robot)
    q = robot.random_q(rng=5, margin=0.05)
    cols = {f.tip: _moving_columns(robot, q, f.tip_id) for f in hand.fingers}
    for f in hand.fingers:
        others = set().union(*(c for t, c in cols.items() if t != f.tip))
        assert set(f.v_indices) == cols[f.tip] - others
        assert set(hand.arm_v_indices) == cols[f.tip] & others
    if name == "allegro":
        assert len(hand.fingers) == 4 and hand.arm_joints == () and hand.palm == "palm_link"
    elif name == "linkage":  # one driver per digit; of each digit's leaves (bars too) the fingertip
        assert sorted(hand.tips) == [
            "index_tip",
            "little_tip",
            "middle_tip",
            "ring_tip",
            "thumb_tip",
        ]
        assert all(len(f.v_indices) == 1 for f in hand.fingers) and hand.arm_joints == ()
    else:  # hand_point is a tip of the tree but no joint of its own moves it: not a finger
        assert sorted(hand.tips) == [
            "index_tip",
            "little_tip",
            "middle_tip",
            "ring_tip",
            "thumb_tip",
        ]
        assert len(hand.arm_joints) == 7 and hand.palm == "palm"
        assert all(len(f.joints) == 4 for f in hand.fingers)


@pytest.mark.parametrize("name", ["allegro", "limb"])
def test_pad_normal_is_the_direction_of_distal_flexion(name, request):
    robot = request.getfixturevalue(name)
    hand = Hand(robot)
    rng = np.random.default_rng(2)
    for q in robot.random_q(3, rng=rng, margin=0.05):
        d = robot.model.createData()
        for f in hand.fingers:
            J = pin.computeFrameJacobian(robot.model, d, q, f.tip_id, pin.LOCAL_WORLD_ALIGNED)
            distal = robot.chain.joints[f.joints[-1]]
            v = J[:3, distal.idx_v]  # tip velocity of the distal joint
            pin.framesForwardKinematics(robot.model, d, q)
            n_world = d.oMf[f.tip_id].rotation @ f.pad_axis
            # flexion = the side of the larger range (the convention), here positive
            assert distal.upper >= -distal.lower
            assert n_world @ v / np.linalg.norm(v) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name", ["allegro", "limb", "linkage"])
def test_span_bounds_fingertip_distances(name, request):
    robot = request.getfixturevalue(name)
    hand = Hand(robot)
    d = robot.model.createData()
    worst = 0.0
    for q in robot.random_q(200, rng=7):
        pin.framesForwardKinematics(robot.model, d, q)
        P = np.array([d.oMf[f.tip_id].translation for f in hand.fingers])
        worst = max(worst, float(np.max(np.linalg.norm(P[:, None] - P[None], axis=-1))))
    assert worst <= hand.span
    assert hand.span < 3 * worst  # a bound, not a vacuous one


def test_not_a_fingertip(allegro, limb):
    with pytest.raises(FingertipError, match="fingertips"):
        Hand(allegro, tips=["link_3.0_tip", "palm_link"])
    with pytest.raises(FingertipError, match="no joint of its own"):
        Hand(limb, tips=["index_tip", "hand_point"])
    with pytest.raises(FingertipError):
        Hand(limb, tips=["index_tip", "index_tip"])
    with pytest.raises(FingertipError):
        Hand(limb, tips=["index_tip"])
    with pytest.raises(FingertipError, match="pad_axes"):
        Hand(limb, pad_axes={"palm": [0, 1, 0]})


def test_coupled_joints_inconsistent_values():
    robot = aa.load("human_upper_limb", dip_coupling="2/3")
    hand = Hand(robot)
    q = hand.configuration({"index_pip": 0.9, "index_dip": 0.6})  # 0.6 = 2/3 · 0.9: consistent
    theta = robot.chain.angles(q)
    names = [j.name for j in robot.chain.joints]
    assert theta[names.index("index_dip")] == pytest.approx(0.6, abs=1e-12)
    with pytest.raises(CouplingError, match="index_pip"):
        hand.configuration({"index_pip": 0.9, "index_dip": 0.2})
