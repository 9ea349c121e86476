"""Activity demands and their envelope: torques equal to pin.rnea with fext, RMS and derivatives
by mathematics, unusable activities as statuses; the book's weight rules with its printed numbers."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.dynamics.loads import HeldObject
from anthroarm.errors import ActivityError, ParameterError
from anthroarm.prosthesis import envelope as E
from anthroarm.prosthesis import weight_rules as W


@pytest.fixture(scope="module")
def robot():
    return aa.load("human_arm7", height=1.75, mass=70.0, sex="male")


def _poly_traj(robot, n=81, T=1.5):
    """q(t) = q0 + c1 t + c2 t² + c3 t³ (exact derivatives known)."""
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, T, n)
    q0 = 0.5 * (robot.lower + robot.upper)
    c = rng.uniform(-0.08, 0.08, (3, robot.nq))
    q = q0 + np.outer(t, c[0]) + np.outer(t**2, c[1]) + np.outer(t**3, c[2])
    qd = c[0] + np.outer(2 * t, c[1]) + np.outer(3 * t**2, c[2])
    qdd = 2 * c[1] + np.outer(6 * t, c[2])
    return t, q, qd, qdd


def test_activity_torques_equal_rnea_with_fext(robot):
    t, q, qd, qdd = _poly_traj(robot)
    cup = HeldObject(0.5)  # point mass at the hand point
    act = E.activity_torques(robot, "poly", t, q, loads=cup)  # derivatives from the spline
    np.testing.assert_allclose(act.qd, qd, atol=1e-9)
    np.testing.assert_allclose(act.qdd, qdd, atol=1e-7)
    model, data = robot.model, robot.model.createData()
    fr = model.frames[robot.tool_id]
    for k in range(0, len(t), 10):
        # the weight of a resting point mass plus its inertia force, as fext on the hand's joint
        pin.forwardKinematics(model, data, q[k], qd[k], qdd[k])
        pin.updateFramePlacements(model, data)
        a = pin.getFrameClassicalAcceleration(
            model, data, robot.tool_id, pin.LOCAL_WORLD_ALIGNED
        ).linear
        f_world = 0.5 * (model.gravity.linear - a)  # force of the mass on the hand, world axes
        R = data.oMf[robot.tool_id].rotation
        fext = [pin.Force.Zero() for _ in range(model.njoints)]
        fext[fr.parentJoint] = fr.placement.act(pin.Force(R.T @ f_world, np.zeros(3)))
        ref = pin.rnea(model, data, q[k], qd[k], qdd[k], fext)
        np.testing.assert_allclose(act.tau[k], ref, atol=1e-6)  # spline derivatives ~1e-7
        np.testing.assert_allclose(act.power[k], act.tau[k] * act.qd[k])
    assert act.status == "ok"


def test_envelope_peaks_and_rms_by_mathematics(robot):
    """τ = A sin(2π t / T) over one period has RMS A/√2; peaks are maxima of the samples."""
    n, T = 2001, 2.0
    t = np.linspace(0, T, n)
    A = np.linspace(1.0, 7.0, robot.nv)
    tau = np.sin(2 * np.pi * t / T)[:, None] * A
    qd = np.cos(2 * np.pi * t / T)[:, None] * np.ones(robot.nv)
    a1 = E.ActivityTorques(
        "sine", t, np.zeros((n, robot.nq)), qd, qd, tau, tau, tau * qd, robot.joint_names
    )
    a2 = E.ActivityTorques(
        "half",
        t,
        np.zeros((n, robot.nq)),
        0.5 * qd,
        qd,
        0.5 * tau,
        tau,
        0.25 * tau * qd,
        robot.joint_names,
    )
    env = E.envelope([a1, a2])
    np.testing.assert_allclose(env.rms_torque, A / np.sqrt(2), rtol=1e-6)
    np.testing.assert_allclose(env.peak_torque, A, rtol=1e-6)
    np.testing.assert_allclose(env.peak_speed, 1.0)
    np.testing.assert_allclose(env.peak_power, A / 2, rtol=1e-6)  # max |sin cos| = 1/2
    assert [r["joint"] for r in env.rows()] == robot.joint_names


def test_outside_limits_is_a_status_and_left_out(robot):
    t, q, qd, qdd = _poly_traj(robot)
    bad = q.copy()
    j = robot.joint_names.index("elbow_flexion")
    bad[40, j] = robot.upper[j] + 0.3
    a_bad = E.activity_torques(robot, "over", t, bad, qd, qdd)
    assert (
        a_bad.status == "outside_limits"
        and "elbow_flexion" in a_bad.reason
        and "t = 0.750 s" in a_bad.reason
    )
    a_ok = E.activity_torques(robot, "ok", t, q, qd, qdd)
    env = E.envelope([a_bad, a_ok])
    assert [a.name for a in env.activities] == ["ok"] and [a.name for a in env.skipped] == ["over"]
    with pytest.raises(ActivityError, match="no usable activity"):
        E.envelope([a_bad])


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda t, q: (t[::-1], q), "increasing"),
        (lambda t, q: (t[:-1], q), "one time per sample"),
        (lambda t, q: (t[:3], q[:3]), "at least 4"),
        (lambda t, q: (t, np.where(np.arange(len(q))[:, None] == 3, np.nan, q)), "is nan"),
    ],
)
def test_bad_activities(robot, change, words):
    t, q, _, _ = _poly_traj(robot)
    t2, q2 = change(t, q)
    with pytest.raises(ActivityError, match=words):
        E.activity_torques(robot, "bad", t2, q2)


def test_weight_rules_with_the_book_numbers():
    rows = {r.source: r for r in W.check(1.2, 70.0, 7)}
    # drive 1.2 kg at 60 % -> 2.0 kg, at 50 % -> 2.4 kg (L274)
    assert (rows["L274"].value, rows["L274"].limit) == (pytest.approx(2.0), pytest.approx(2.4))
    assert rows["L7445"].limit == 2.0 and rows["L7445"].ok  # 2.0 kg <= 2 kg
    assert rows["L7298"].limit == pytest.approx(0.063 * 70.0)  # 4.41 kg: the book's "4-5 kg"
    assert rows["L7441"].ok and rows["L7441"].limit == 7
    heavy = {r.source: r for r in W.check(1.5, 70.0, 6, unsized_joints=1)}
    assert (
        heavy["L7445"].ok is False
        and heavy["L7441"].ok is False
        and "lower bound" in heavy["L7445"].note
    )
    assert "L7298" not in {r.source for r in W.check(1.0, None, 7)}
    for bad in [(-1.0, 70.0), (np.nan, 70.0), (1.0, 0.0), ("1 kg", 70.0), (1.0, np.inf)]:
        with pytest.raises(ParameterError, match="drive_mass >= 0 kg and body_mass > 0 kg"):
            W.check(*bad, 7)


def test_payload_per_sample_equals_rnea_with_the_object_on_the_hand(robot):
    """An object picked up half-way: samples without it equal pin.rnea of the arm, samples with it
    pin.rnea of the arm whose hand body carries the cylinder's inertia."""
    t, q, qd, qdd = _poly_traj(robot, n=41)
    mass = np.where(t > 0.7, 0.8, 0.0)
    act = E.activity_torques(robot, "pick", t, q, qd, qdd, payload=mass)
    obj = E.held_object(0.8)
    heavy = robot.model.copy()
    fr = heavy.frames[robot.tool_id]
    heavy.inertias[fr.parentJoint] = heavy.inertias[fr.parentJoint] + fr.placement.act(
        pin.Inertia(0.8, obj.com, obj.inertia)
    )
    d0, d1 = robot.model.createData(), heavy.createData()
    for k in range(len(t)):
        ref = (
            pin.rnea(heavy, d1, q[k], qd[k], qdd[k])
            if mass[k] > 0
            else pin.rnea(robot.model, d0, q[k], qd[k], qdd[k])
        )
        np.testing.assert_allclose(act.tau[k], ref, atol=1e-9)
    assert act.payload == 0.8 and act.mass_in_hand.shape == (41,)
    with pytest.raises(ActivityError, match="payload"):
        E.activity_torques(robot, "pick", t, q, qd, qdd, payload=np.ones(5))
    with pytest.raises(ActivityError, match="payload"):
        E.activity_torques(robot, "pick", t, q, qd, qdd, payload=-1.0)
