"""Human-arm analyses: gravity torque maps and reaching torques for human_arm7 vs Pinocchio."""

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
import pytest  # noqa: E402

from anthroarm.dynamics import human as Hu  # noqa: E402


def test_gravity_map_vs_pinocchio_and_statics():
    robot, dyn = Hu.human_arm(1.62, 58.0, "female")
    res = Hu.gravity_torque_map(grid=9, robot=robot, dyn=dyn, height=1.62, mass=58.0, sex="female")
    assert res["tau"].shape == (9, 9, 7)
    d = robot.model.createData()
    for i in (0, 4, 8):
        for k in (0, 3, 8):
            q = res["q"][i, k]
            assert np.allclose(
                res["tau"][i, k], pin.computeGeneralizedGravity(robot.model, d, q), atol=1e-12
            )
    # arm hanging down (q = 0): no shoulder-flexion torque; arm horizontal forward: maximal
    t_down = dyn.gravity(np.zeros(7))[0]
    q_fwd = np.zeros(7)
    q_fwd[0] = np.pi / 2
    t_fwd = dyn.gravity(q_fwd)[0]
    assert abs(t_down) < 1e-12 and abs(t_fwd) > 5.0  # ≈ m_arm g r_com: several N m
    # statics: |shoulder torque| horizontal = Σ m_i g · horizontal CoM distance (hand included)
    pin.centerOfMass(robot.model, d, q_fwd)
    m_tot = sum(robot.model.inertias[i].mass for i in range(1, robot.model.njoints))
    assert abs(abs(t_fwd) - m_tot * 9.81 * abs(d.com[0][1])) < 1e-10


def test_heavier_person_needs_more_torque():
    q = np.zeros(7)
    q[0] = 1.2
    t1 = Hu.human_arm(1.75, 60.0)[1].gravity(q)[0]
    t2 = Hu.human_arm(1.75, 90.0)[1].gravity(q)[0]
    # segment masses scale linearly with body mass (de Leva); the 20 g joint housings do not
    assert 1.45 < t2 / t1 < 1.5


def test_reaching_parts_sum_and_match_rnea():
    robot, dyn = Hu.human_arm()
    q0 = np.zeros(7)
    q1 = np.array([1.2, -0.3, 0.2, 1.4, 0.5, 0.1, -0.2])
    res = Hu.reaching_torques(q0, q1, duration=0.6, samples=31, robot=robot, dyn=dyn)
    assert np.allclose(res["inertial"] + res["velocity"] + res["gravity"], res["tau"], atol=1e-12)
    d = robot.model.createData()
    for k in (0, 10, 30):
        ref = pin.rnea(robot.model, d, res["q"][k], res["qd"][k], res["qdd"][k])
        assert np.allclose(res["tau"][k], ref, atol=1e-10)
    assert np.allclose(res["q"][-1], q1) and np.allclose(res["qd"][[0, -1]], 0)
    Hu.plot_reaching(res)
    Hu.plot_gravity_map(
        Hu.gravity_torque_map(grid=5, robot=robot, dyn=dyn), joint="shoulder_flexion"
    )
    small, small_dyn = Hu.human_arm(1.55, 50.0, "female")
    # the map reports the body it was computed for, not the keyword defaults
    assert Hu.gravity_torque_map(grid=2, robot=small, dyn=small_dyn)["params"] == dict(
        height=1.55, mass=50.0, sex="female"
    )


def test_bad_input():
    robot, dyn = Hu.human_arm()
    with pytest.raises(ValueError, match="unknown joint"):
        Hu.gravity_torque_map(joints=("knee", "elbow_flexion"), robot=robot, dyn=dyn)
    with pytest.raises(ValueError):
        Hu.reaching_torques(np.zeros(7), [np.nan] * 7, robot=robot, dyn=dyn)
    with pytest.raises(ValueError, match="height"):
        Hu.human_arm(height=5.0)
