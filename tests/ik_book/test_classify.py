"""Kinematic classification (anthroarm.ik.classify) from robot.chain at q = 0.

Oracles: the arms' published geometry (spherical wrists, the UR's three parallel axes), a
PUMA-like 6R URDF built here, and Pinocchio's joint placements at q = 0 for the axes/points."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ParameterError
from anthroarm.ik import classify as C

PUMA = """<?xml version="1.0"?>
<robot name="puma_like">
  <link name="base"/>
  {links}
  {joints}
</robot>"""


def puma_urdf(tmp_path, shoulder_offset=0.15, wrist_offset=0.0):
    # PUMA 560-like: 1 ⟂ 2 intersecting (with a shoulder offset along axis 2), 2 ∥ 3,
    # 4-5-6 a spherical wrist (wrist_offset ≠ 0 breaks it)
    j = [
        ("j1", "base", "l1", (0, 0, 0.67), (0, 0, 1)),
        ("j2", "l1", "l2", (0, 0, 0), (0, 1, 0)),
        ("j3", "l2", "l3", (0.432, shoulder_offset, 0), (0, 1, 0)),
        ("j4", "l3", "l4", (0.02, 0, -0.43), (0, 0, 1)),
        ("j5", "l4", "l5", (0, wrist_offset, 0), (0, 1, 0)),
        ("j6", "l5", "l6", (0, 0, 0), (0, 0, 1)),
        ("jt", "l6", "tool", (0, 0, -0.056), None),
    ]
    links = "\n  ".join(f'<link name="{n}"/>' for n in ("l1", "l2", "l3", "l4", "l5", "l6", "tool"))
    joints = []
    for name, parent, child, xyz, axis in j:
        kind = "fixed" if axis is None else "revolute"
        body = (
            f'<origin xyz="{xyz[0]} {xyz[1]} {xyz[2]}" rpy="0 0 0"/>'
            f'<parent link="{parent}"/><child link="{child}"/>'
        )
        if axis is not None:
            body += (
                f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>'
                '<limit lower="-3" upper="3" effort="10" velocity="1"/>'
            )
        joints.append(f'<joint name="{name}" type="{kind}">{body}</joint>')
    path = tmp_path / "puma_like.urdf"
    path.write_text(PUMA.format(links=links, joints="\n  ".join(joints)))
    return aa.load(str(path))


@pytest.mark.parametrize(
    "name, cls, rev",
    [
        ("sixr_arm", C.SPHERICAL_TWO_PARALLEL, False),
        ("kinova", C.SPHERICAL_TWO_PARALLEL, False),  # continuous joints count as revolute
        ("ur3", C.THREE_PARALLEL_TWO_INTERSECTING, False),
        ("ur5", C.THREE_PARALLEL_TWO_INTERSECTING, False),
        ("ur10", C.THREE_PARALLEL_TWO_INTERSECTING, False),
        ("prosthetic_arm", C.SPHERICAL_TWO_INTERSECTING, True),  # spherical shoulder
    ],
)
def test_catalog_classes(name, cls, rev):
    c = C.classify(aa.load(name))
    assert (c.name, c.reversed) == (cls, rev)
    assert c.has_closed_form and c.reason is None
    assert c.worst_accepted[0] < 1e-9 and c.worst_accepted[1] < 1e-9
    assert c.nearest_rejected[0] > 1e-3  # no near call on these arms


def test_relations_of_ur5_and_sixr():
    ur = C.classify(aa.load("ur5"))
    assert (
        ur.parallel == ((1, 2), (2, 3)) and ur.three_parallel == (1,) and (4, 5) in ur.intersecting
    )
    assert ur.spherical == ()
    six = C.classify(aa.load("sixr_arm"))
    assert six.spherical == (3,) and six.parallel == ((1, 2),)


def test_not_6r():
    c = C.classify(aa.load("panda"))
    assert c.name == C.NOT_6R and "7 joints" in c.reason and not c.has_closed_form
    assert c.kinematics.n == 7


def test_axes_and_points_match_pinocchio():
    robot = aa.load("ur10")
    kin = C.kinematics(robot)
    model = robot.model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    for i, j in enumerate(kin.joints):
        M = data.oMi[j + 1]
        assert np.allclose(kin.points[i], M.translation, atol=1e-12)
        ax = robot.chain.joints[j].axis
        assert np.allclose(kin.H[i], M.rotation @ ax, atol=1e-12)
    pin.updateFramePlacements(model, data)
    tool = data.oMf[model.getFrameId(robot.tool)]
    assert np.allclose(kin.p_tool, tool.translation) and np.allclose(kin.R_tool, tool.rotation)
    assert np.allclose(kin.P.sum(0), tool.translation)


def test_user_puma(tmp_path):
    c = C.classify(puma_urdf(tmp_path))
    assert c.name == C.SPHERICAL_TWO_PARALLEL and not c.reversed
    names = [n for n, r in c.compatible if not r]
    assert C.SPHERICAL_TWO_INTERSECTING in names  # the shoulder offset is along axis 2
    assert c.intersecting[0] == (0, 1) and (1, 2) in c.parallel and c.spherical == (3,)


def test_user_puma_broken_wrist_and_tolerance(tmp_path):
    robot = puma_urdf(tmp_path, wrist_offset=1e-4)  # axes 4 and 6 0.1 mm apart
    c = C.classify(robot)
    assert c.spherical == () and c.name == C.TWO_PARALLEL
    # the near miss is reported: the three lines are 0.05 mm from one common point
    assert abs(c.nearest_rejected[0] - 5e-5) < 1e-9
    loose = C.classify(robot, tol=1e-3)  # within a looser tolerance: spherical
    assert loose.name == C.SPHERICAL_TWO_PARALLEL and loose.tol == 1e-3
    assert abs(loose.worst_accepted[0] - 5e-5) < 1e-9


@pytest.mark.parametrize("kw", [{"tol": 0}, {"tol": -1}, {"angle_tol": float("nan")}, {"tol": "a"}])
def test_bad_tolerance(kw):
    with pytest.raises(ParameterError):
        C.classify(aa.load("sixr_arm"), **kw)
