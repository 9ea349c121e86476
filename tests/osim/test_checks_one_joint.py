"""``anthroarm.kinematics.checks.rows`` on one-joint robots: Pinocchio's
``computeFrameJacobian`` gives a (6,) array when the model has one joint (Tug_of_War's slider,
a one-revolute URDF); the rows used to fail with a broadcast error."""

import numpy as np

import anthroarm as aa
from anthroarm.kinematics import checks

ONE_JOINT = """<robot name="one"><link name="base"/><link name="l1"/>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
 <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
 <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


def test_kinematics_rows_on_tug_of_war():
    robot = aa.load(aa.osim.path("Tug_of_War"))
    assert robot.nq == 1
    rows = checks.rows(robot, 8, np.random.default_rng(0))
    assert any(r.status == "ok" and "jacobian" in r.quantity for r in rows)
    bad = [(r.quantity, r.max_abs_err, r.note) for r in rows if r.status == "FAIL"]
    assert not bad, bad


def test_kinematics_rows_on_a_one_revolute_urdf(tmp_path):
    p = tmp_path / "one.urdf"
    p.write_text(ONE_JOINT)
    robot = aa.load(str(p), tool="l1")
    rows = checks.rows(robot, 8, np.random.default_rng(0))
    bad = [(r.quantity, r.max_abs_err, r.note) for r in rows if r.status == "FAIL"]
    assert not bad, bad
    # the Jacobian row compares against Pinocchio: the slider's column is the z axis (mathematics)
    J = robot.jacobian(np.array([0.3]))
    np.testing.assert_allclose(J.reshape(6, -1)[:, 0], [0, 0, 0, 0, 0, 1], atol=1e-15)
