"""The ADL library: every keyframe reached (hand by Pinocchio FK), smooth minimum-jerk joint
trajectories (derivatives against finite differences, Flash & Hogan's peak-velocity ratio 15/8),
limits, comfortable posture, unreachable targets as statuses, the book's Table 9.2 rows."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ActivityError
from anthroarm.ik.qp import comfortable_posture
from anthroarm.motion import activities as A
from anthroarm.motion.timing import keyframe_trajectory, minimum_jerk

PEOPLE = [dict(height=1.75, mass=75.0, sex="male"), dict(height=1.55, mass=50.0, sex="female")]


def _hand(robot, q):
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.model.getFrameId(robot.tool)].translation.copy()


@pytest.mark.parametrize("person", PEOPLE, ids=["m175", "f155"])
def test_every_activity_reaches_its_keyframes_smoothly(person):
    robot = aa.load("human_arm7", **person)
    for name in A.names():
        tr = A.activity_trajectory(robot, name)
        assert tr.reachable, (name, tr.keyframe_status, tr.keyframe_error)
        for kf, qk, tk in zip(tr.activity.keyframes, tr.keyframe_q, tr.keyframe_times):
            assert np.linalg.norm(_hand(robot, qk) - np.asarray(kf.position)) < 1e-3, (
                name,
                kf.name,
            )
            i = int(round(tk * 100))
            np.testing.assert_allclose(tr.q[i], qk, atol=1e-12)
            assert np.abs(tr.qd[i]).max() < 1e-12  # at rest at a keyframe
        assert np.all(tr.q >= robot.lower - 1e-9) and np.all(tr.q <= robot.upper + 1e-9)
        assert np.isfinite(tr.q).all() and np.isfinite(tr.qdd).all()
        dt = tr.t[1] - tr.t[0]
        np.testing.assert_allclose(
            np.gradient(tr.q, dt, axis=0)[1:-1],
            tr.qd[1:-1],
            atol=5e-3 * max(1, np.abs(tr.qd).max()),
        )
        # the jerk jumps where a segment starts or ends: central differences are first-order there
        ends = np.concatenate(
            [tr.keyframe_times, tr.keyframe_times + [kf.hold for kf in tr.activity.keyframes]]
        )
        smooth = np.all(np.abs(tr.t[:, None] - ends[None]) > 1.5 * dt, axis=1)
        smooth[[0, -1]] = False
        np.testing.assert_allclose(
            np.gradient(tr.qd, dt, axis=0)[smooth],
            tr.qdd[smooth],
            atol=2e-2 * max(1, np.abs(tr.qdd).max()),
        )
        np.testing.assert_allclose(tr.hand[5], _hand(robot, tr.q[5]), atol=1e-12)


def test_minimum_jerk_profile():
    """Flash & Hogan (1985): x = x0 + d(10τ³ − 15τ⁴ + 6τ⁵): peak speed 15/8 of the mean at
    τ = 1/2, acceleration zero there, ±10/√3 d/T² at τ = 1/2 ∓ √3/6."""
    T, d = 1.3, 0.7
    t = np.linspace(0, T, 100001)
    x, v, a = minimum_jerk(0.0, d, T, t)
    assert abs(v.max() - 15 / 8 * d / T) < 1e-9 and abs(t[np.argmax(v)] - T / 2) < 1e-4
    assert abs(a.max() - 10 / np.sqrt(3) * d / T**2) < 1e-6
    assert abs(t[np.argmax(a)] - T * (0.5 - np.sqrt(3) / 6)) < 1e-4
    assert x[0] == 0 and abs(x[-1] - d) < 1e-15 and v[0] == 0 and a[0] == 0 and abs(a[-1]) < 1e-12
    jerk = np.gradient(a, t)
    # the jerk of the quintic is 60 d/T³ (1 − 6τ + 6τ²): 60 d/T³ at the ends
    assert (
        abs(jerk[1000] - 60 * d / T**3 * (1 - 6 * t[1000] / T + 6 * (t[1000] / T) ** 2))
        < 1e-3 * 60 * d / T**3
    )
    t2, q2, qd2, qdd2, arr = keyframe_trajectory(
        np.array([[0.0], [1.0], [0.5]]), [0, 1.0, 2.0], [0.5, 0.0, 0.0], rate=50
    )
    np.testing.assert_allclose(arr, [0.0, 1.5, 3.5])
    assert (
        q2.shape == (176, 1)
        and q2[25, 0] == 0.0
        and abs(q2[75, 0] - 1.0) < 1e-15
        and abs(q2[-1, 0] - 0.5) < 1e-15
    )


def test_keyframes_take_the_comfortable_posture():
    """Among the postures that put the hand on the target, the library's is at least as close to
    the comfortable posture as any found from random seeds without the posture objective."""
    robot = aa.load("human_arm7")
    qc = comfortable_posture(robot)
    act = A.activity("reach_shelf", robot)
    tr = A.activity_trajectory(robot, act)
    p = np.asarray(act.keyframes[1].position)
    ours = np.linalg.norm(tr.keyframe_q[1] - qc)
    others = []
    for s in range(12):
        r = aa.ik.solve(robot, p, q0=robot.random_q(rng=s), mode="position", posture=None)
        if r.success:
            others.append(np.linalg.norm(r.q - qc))
    assert len(others) >= 6 and ours <= min(others) + 1e-6


def test_unreachable_keyframe_is_a_status_and_strict_raises():
    robot = aa.load("human_arm7")
    tr = A.activity_trajectory(robot, "reach_shelf", shelf_height=2.6, reach_fraction=0.95)
    assert tr.keyframe_status == ("ok", "unreachable", "ok")
    assert tr.keyframe_error[1] > 0.05 and np.isfinite(tr.q).all()
    assert np.all(tr.q >= robot.lower - 1e-9) and np.all(tr.q <= robot.upper + 1e-9)
    with pytest.raises(ActivityError) as ei:
        A.activity_trajectory(robot, "reach_shelf", shelf_height=2.6, strict=True)
    assert ei.value.keyframe == "shelf" and ei.value.distance > 0.05


def test_parameters_and_payload():
    robot = aa.load("human_arm7")
    tr = A.activity_trajectory(robot, "lift_to_table", object_mass=1.0)
    grasp, table = tr.keyframe_times[1], tr.keyframe_times[2]
    inside = (tr.t >= grasp) & (tr.t < table)
    assert np.all(tr.payload[inside] == 1.0) and np.all(tr.payload[~inside] == 0.0)
    slow = A.activity_trajectory(robot, "hand_to_mouth", move=2.0)
    fast = A.activity_trajectory(robot, "hand_to_mouth", move=1.0)
    assert slow.duration > fast.duration
    # same path, twice the time: half the peak speed (minimum-jerk scaling)
    assert abs(np.abs(slow.qd).max() * 2 - np.abs(fast.qd).max()) < 1e-2 * np.abs(fast.qd).max()
    with pytest.raises(ActivityError, match="unknown activity"):
        A.activity("juggling", robot)
    with pytest.raises(ActivityError, match="unknown"):
        A.activity("pour", robot, jug_colour=3)
    with pytest.raises(ActivityError, match=">= 0"):
        A.activity("pour", robot, object_mass=-1.0)
    with pytest.raises(ActivityError, match="finite"):
        A.activity("pour", robot, move=float("nan"))
    with pytest.raises(ActivityError, match="height"):
        A.activity("pour", aa.load("prosthetic_arm"))
    # bad keyframes and rates are refused before any IK is solved
    for act, needle in (
        (A.Activity("none", "none", []), "no keyframes"),
        (A.Activity("text", "text", [A.Keyframe("k", "abc")]), "3 finite numbers"),
        (A.Activity("inf", "inf", [A.Keyframe("k", (0.0, 0.0, np.inf))]), "3 finite numbers"),
        (
            A.Activity(
                "slow",
                "slow",
                [A.Keyframe("a", (0.0, 0.3, 0.0)), A.Keyframe("b", (0.0, 0.3, 0.1), move=1e300)],
            ),
            "samples",
        ),
    ):
        with pytest.raises(ActivityError, match=needle):
            A.activity_trajectory(robot, act)
    with pytest.raises(ActivityError, match="rate"):
        A.activity_trajectory(robot, "pour", rate=0.0)


def test_table_9_2_rows_are_covered():
    """The six activity rows of the book's Table 9.2 (ch9 notes §2.3) each have an activity."""
    rows = {"穿脱衣服", "洗脸", "饮食", "一般动作", "桌面动作", "卫生动作"}
    covered = {book.split()[0] for (_t, _b, _s, book) in A.ACTIVITIES.values() if book}
    assert covered == rows
