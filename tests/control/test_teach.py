"""Teach / store / playback: playback order of every mode, missing labels, the stored program's
round trip, and the timed path (interpolation reaches every taught point at its time)."""

import numpy as np
import pytest

from anthroarm.control.interpolation import circle_through
from anthroarm.control.teach import (
    Call,
    Jump,
    Program,
    Step,
    play_fixed,
    play_jump,
    play_random_access,
    play_select,
    play_subroutines,
    record,
)
from anthroarm.errors import ControlError, PlaybackError


def pick_and_place():
    return record(
        "pick",
        [[0.0, 0.0], [0.5, 0.2], [0.5, 0.6], [0.0, 0.3]],
        [0.0, 1.0, 0.5, 2.0],
        labels=["home", "above", "grasp", "place"],
    )


def test_fixed_sequence_plays_in_taught_order_every_cycle():
    p = pick_and_place()
    pb = play_fixed(p, cycles=3)
    assert pb.labels == ["home", "above", "grasp", "place"] * 3
    assert [e.cycle for e in pb.executed] == [0] * 4 + [1] * 4 + [2] * 4
    ch = p.channels()
    assert ch["sequence"] == ["home", "above", "grasp", "place"]
    assert np.array_equal(ch["time"], [0.0, 1.0, 0.5, 2.0]) and ch["position"].shape == (4, 2)
    # separated storage round trip: channels -> program -> channels
    back = Program.from_channels("pick", **{k: v for k, v in ch.items()})
    assert back.to_json() == p.to_json()
    with pytest.raises(ControlError, match="lengths"):
        Program.from_channels("x", ["a"], [[0.0], [1.0]], [0.0, 1.0])
    with pytest.raises(PlaybackError, match="fixed sequence"):
        play_fixed(Program("j", (Step([0.0], 0, label="a"), Jump("a", "s"))))


def test_program_jump_skips_when_the_sensor_is_on():
    items = (
        Step([0.0], 0, label="start"),
        Step([1.0], 1, label="a"),
        Jump("place", "full"),
        Step([2.0], 1, label="b"),
        Step([3.0], 1, label="place"),
    )
    p = Program("box", items)
    # the box is full on every second cycle: then b is skipped
    pb = play_jump(p, {"full": [False, True]}, cycles=3)
    assert pb.labels == [
        "start",
        "a",
        "b",
        "place",
        "start",
        "a",
        "place",
        "start",
        "a",
        "b",
        "place",
    ]
    # a sensor as a function of (name, cycle)
    pb2 = play_jump(p, lambda name, cycle: cycle == 0, cycles=2)
    assert pb2.labels == ["start", "a", "place", "start", "a", "b", "place"]
    with pytest.raises(PlaybackError, match="sensor 'full'"):
        play_jump(p, {"other": True})


def test_missing_label_and_duplicate_label_raise():
    with pytest.raises(PlaybackError, match="'nowhere'.*labels: \\['a'\\]"):
        Program("bad", (Step([0.0], 0, label="a"), Jump("nowhere")))
    with pytest.raises(PlaybackError, match="twice"):
        Program("bad", (Step([0.0], 0, label="a"), Step([1.0], 1, label="a")))
    with pytest.raises(ControlError, match="shape"):
        Program("bad", (Step([0.0], 0), Step([1.0, 2.0], 1)))


def test_endless_jump_loop_stops_with_a_status():
    p = Program("loop", (Step([0.0], 0, label="a"), Step([1.0], 1), Jump("a")))
    pb = play_jump(p, {}, max_steps=9)
    assert pb.status == "step limit" and len(pb.executed) == 9


def test_program_select_and_subroutines():
    A = record("A", [[0.0], [1.0]], 1.0, labels=["A0", "A1"])
    B = record("B", [[0.0], [-1.0], [-2.0]], 1.0, labels=["B0", "B1", "B2"])
    # Fig. 9-10: judge size/weight, take program A or B
    pick = lambda s: "B" if s["heavy"] else "A"  # noqa: E731
    assert play_select([A, B], pick, {"heavy": True}).labels == ["B0", "B1", "B2"]
    assert play_select({"A": A, "B": B}, "A").labels == ["A0", "A1"]
    with pytest.raises(PlaybackError, match="programs: \\['A', 'B'\\]"):
        play_select([A, B], "C")
    pb = play_subroutines({"A": A, "B": B}, ["A", "B", "A"])
    assert pb.labels == ["A0", "A1", "B0", "B1", "B2", "A0", "A1"]
    assert pb.mode == "subroutine"
    with pytest.raises(PlaybackError, match="subroutine 'Z'"):
        play_subroutines({"A": A}, ["A", "Z"])
    # a call inside a program, nested
    outer = Program("outer", (Step([5.0], 0, label="o"), Call("A"), Step([6.0], 1, label="o2")))
    pb = play_select({"outer": outer, "A": A}, "outer")
    assert pb.labels == ["o", "A0", "A1", "o2"]


def test_random_access_follows_the_addresses_chosen():
    pts = {f"P{k}": Step([float(k)], 1.0, label=f"P{k}") for k in range(5)}
    order = ["P0", "P3", "P1", "P4"]
    nxt = lambda a, hist: order[len(hist)] if len(hist) < len(order) else None  # noqa: E731
    pb = play_random_access(pts, "P0", nxt)
    assert pb.labels == order and pb.status == "done"
    with pytest.raises(PlaybackError, match="address 'P9'"):
        play_random_access(pts, "P0", lambda a, h: "P9")
    pb = play_random_access(pts, "P0", lambda a, h: "P1", max_steps=5)
    assert pb.status == "step limit"


def test_store_round_trip(tmp_path):
    T = np.eye(4)
    T[:3, 3] = [0.1, 0.0, 0.3]
    items = (
        Step(np.eye(4), 0.0, label="a", grip=3.0, motion="line"),
        Step(T, 1.0, motion="line", dwell=0.5),
        Jump("a", "again"),
        Call("sub"),
    )
    p = Program("stored", items)
    path = tmp_path / "prog.json"
    p.save(path)
    q = Program.load(path)
    assert q.to_json() == p.to_json()
    assert q.labels == {"a": 0} and isinstance(q.items[3], Call)
    assert np.array_equal(q.items[1].position, T) and q.items[0].grip == 3.0
    with pytest.raises(ControlError):
        Program.from_json('{"name": "x", "items": [{"kind": "teleport"}]}')
    with pytest.raises(ControlError):
        Program.from_json("not json")


def test_trajectory_hits_taught_points_at_their_times_line_and_arc():
    p1, p2, p3 = np.array([0.4, 0.0, 0.2]), np.array([0.0, 0.4, 0.2]), np.array([-0.4, 0.0, 0.2])
    via = np.array([0.4 * np.cos(2.4), 0.4 * np.sin(2.4), 0.2])
    prog = Program(
        "cart",
        (
            Step(p1, 0.0),
            Step(p2, 2.0, motion="line", dwell=0.5),
            Step(p3, 1.0, motion="arc", via=via),
        ),
    )
    pb = play_fixed(prog)
    assert pb.duration == pytest.approx(3.5)
    t, P = pb.trajectory(0.01)
    assert t[-1] == pytest.approx(3.5)
    for tk, pk in ((0.0, p1), (2.0, p2), (2.5, p2), (3.5, p3)):
        k = int(np.argmin(np.abs(t - tk)))
        assert abs(t[k] - tk) < 1e-9 and np.allclose(P[k], pk, atol=1e-12)
    line = (t > 0) & (t < 2.0)
    assert np.allclose(
        P[line], p1 + (t[line] / 2.0)[:, None] * (p2 - p1)
    )  # straight, constant speed
    arc = t > 2.5
    c = circle_through(p2, via, p3)
    assert np.allclose(np.linalg.norm(P[arc] - c.center, axis=1), c.radius)
    assert np.allclose(c.center, [0, 0, 0.2], atol=1e-12)
    # poses: the same path with the hand turning, every sample a rotation
    T1, T2 = np.eye(4), np.eye(4)
    T1[:3, 3], T2[:3, 3] = p1, p2
    T2[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    t2, P2 = play_fixed(
        Program("poses", (Step(T1, 0.0, motion="line"), Step(T2, 1.0, motion="line")))
    ).trajectory(0.1)
    assert np.allclose(P2[-1], T2) and np.allclose(
        P2[:, :3, :3] @ np.swapaxes(P2[:, :3, :3], 1, 2), np.eye(3)
    )


def test_bad_steps():
    with pytest.raises(ControlError, match="via"):
        Step([0, 0, 0], 1.0, motion="arc")
    with pytest.raises(ControlError, match="Cartesian"):
        Step([0, 0], 1.0, motion="line")
    with pytest.raises(ControlError, match="entry by entry"):
        Step(np.eye(4), 1.0)
    with pytest.raises(ControlError):
        Step([0.0], -1.0)
    with pytest.raises(ControlError):
        Step([np.nan], 1.0)
    with pytest.raises(ControlError, match="cycles"):
        play_fixed(pick_and_place(), cycles=0)


def test_joint_path_on_the_care_robot_reaches_every_sample():
    """Teach three poses by FK of known joints, play straight lines between them on the arm:
    every sample's IK meets the pose (robot.fk, Pinocchio) and the joints move continuously."""
    import anthroarm as aa

    robot = aa.load("care_robot")
    qs = np.array(
        [
            [0.2, 0.6, -0.9, 0.1, 0.5, 0.0],
            [0.5, 0.5, -0.7, 0.2, 0.4, 0.2],
            [0.4, 0.8, -1.1, 0.0, 0.6, 0.1],
        ]
    )
    prog = record("arm", [robot.fk(q) for q in qs], [0.0, 0.4, 0.4], motion="line")
    t, q, ok = play_fixed(prog).joint_path(robot, 0.05, q0=qs[0])
    assert ok.all() and len(t) == len(q)
    _, P = play_fixed(prog).trajectory(0.05)
    for k in range(len(t)):
        F = robot.fk(q[k])
        assert np.allclose(F[:3, 3], P[k][:3, 3], atol=1e-5) and np.allclose(
            F[:3, :3], P[k][:3, :3], atol=1e-5
        )
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.2
    with pytest.raises(ControlError, match="4x4 poses"):
        play_fixed(pick_and_place()).joint_path(robot, 0.1)
