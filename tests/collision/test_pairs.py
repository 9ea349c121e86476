"""Pair filtering (MoveIt's approach), SRDF disable lists and edits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm.collision.pairs import sample_distances


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def test_filter_reasons_hold_on_samples(limb):
    cm = C.model(limb)
    reasons = set(cm.disabled.values())
    assert {"adjacent", "never"} <= reasons
    # adjacent and touching at their shared joint: upper arm / forearm meet at the elbow
    assert (
        cm.disabled[cm.key(cm.names.index("upper_arm_0"), cm.names.index("forearm_0"))]
        == "adjacent"
    )
    # neighbours that do not touch stay checked: the upper arm against the torso
    active = {frozenset(p) for p in cm.pair_names()}
    assert frozenset(("upper_arm_0", "torso")) in active
    # finger against finger is checked (index / middle proximal phalanges)
    assert frozenset(("index_proximal_0", "middle_proximal_0")) in active
    # "never" pairs stay apart on fresh samples (other seed than the filter's), by coal
    never = [
        (cm.names.index(a), cm.names.index(b))
        for (a, b), why in cm.disabled.items()
        if why == "never"
    ]
    D = sample_distances(limb, C.build(limb), never, limb.random_q(200, rng=123))
    assert D.min() > 0.0
    # the GeometryModel carries exactly the active pairs (what pink reads)
    assert len(cm.geometry.collisionPairs) == len(cm.pairs)


def test_edit_pairs(limb):
    cm = C.build(limb, samples=50)
    n = len(cm.pairs)
    cm.disable("upper_arm", "torso")
    assert len(cm.pairs) == n - 1 and cm.disabled[cm.key(0, cm.names.index("torso"))] == "user"
    cm.enable("upper_arm", "torso")
    assert len(cm.pairs) == n
    with pytest.raises(aa.errors.CollisionError, match="no collision body or link 'nose'"):
        cm.disable("nose", "torso")


def test_srdf_disable_list():
    robot = aa.load("panda")
    srdf = Path(robot.info.path).parents[1] / "srdf" / "panda.srdf"
    listed = C.read_srdf(srdf)
    assert ("panda_hand", "panda_link3", "Never") in listed
    cm = C.build(robot, srdf=srdf, samples=0)
    assert (
        cm.disabled[cm.key(cm.names.index("panda_hand_0"), cm.names.index("panda_link3_0"))]
        == "srdf"
    )
    with pytest.raises(aa.errors.CollisionError, match="not valid XML"):
        C.read_srdf("<robot><disable_collisions")


def test_capsules_follow_the_chain(limb):
    """A capsule's axis runs from its joint to the next joint (Pinocchio FK as the oracle)."""
    cm = C.model(limb)
    q = limb.random_q(rng=0)
    data = limb.model.createData()
    pin.forwardKinematics(limb.model, data, q)
    g = cm.geometry.geometryObjects[cm.names.index("forearm_0")]
    M = data.oMi[g.parentJoint] * g.placement
    h = g.geometry.halfLength
    ends = {tuple(np.round(M.act(np.array([0, 0, s * h])), 9)) for s in (-1, 1)}
    elbow = data.oMi[limb.model.getJointId("elbow_flexion")].translation
    wrist = data.oMi[limb.model.getJointId("wrist_deviation")].translation
    assert ends == {tuple(np.round(elbow, 9)), tuple(np.round(wrist, 9))}
