"""Hostile inputs to the control surface (issue 30): anthroarm.control (DDA, interpolation, servo,
motor, bilateral, gripper, teach/playback) and anthroarm.trajectory.  Every case is a typed error
from anthroarm.errors naming the parameter, or a correct (finite) answer; none may hang, crash
inside numpy/Python, or hand back NaN/inf."""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import time

import numpy as np
import pytest

from anthroarm.control import dda as dda_mod
from anthroarm.control import gripper
from anthroarm.control.bilateral import Bilateral
from anthroarm.control.interpolation import (
    arc_poses,
    circle_through,
    line_points,
    line_poses,
)
from anthroarm.control.motor import DCMotor, rms
from anthroarm.control.servo import PositionServo
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
from anthroarm.errors import (
    AnthroarmError,
    ControlError,
    DegenerateArcError,
    ParameterError,
    PlaybackError,
)


@contextlib.contextmanager
def within(seconds: float):
    """Fail (instead of hanging the suite) when the block takes longer than ``seconds``."""

    def on_alarm(*_):
        raise TimeoutError(f"took longer than {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


SERVO = dict(k_m=0.1, k=0.01, J_m=1e-5, J_L=1e-3, i=100.0, k_a=10.0, k_p=1.0, k_s=0.01)


def _step(x, **kw):
    return Step([float(x), 0.0], 1.0, **kw)


# =============================================================================== control: DDA
@pytest.mark.parametrize(
    "counts",
    [
        [2**63],
        np.array([2**63], dtype=np.uint64),
        np.array([2**64 - 1], dtype=np.uint64),
        np.array([-(2**63)], dtype=np.int64),
        [2**62 + 1, 3],
    ],
    ids=["int 2^63", "uint64 2^63", "uint64 max", "int64 min", "just beyond 2^62"],
)
def test_dda_refuses_counts_beyond_the_range(counts):
    """Counts of 2**63 wrapped to negative counts with status "ok" (and uint64 2**64-1 to -1)."""
    with within(5), pytest.raises(ControlError, match="counts"):
        dda_mod.dda(counts)


@pytest.mark.parametrize("counts", [[1 + 2j], [True, False], ["3"]])
def test_dda_refuses_counts_that_are_not_integers(counts):
    with pytest.raises(ControlError, match="counts"):
        dda_mod.dda(counts)


def test_dda_huge_tick_count_names_the_budget():
    with within(5), pytest.raises(ControlError, match="budget"):
        dda_mod.dda([1, 2], n_ticks=10**12)


@pytest.mark.parametrize(
    "args",
    [
        (["a"], [1.0], 1.0),
        ([0.0, 0.0], [1.0, 1.0], [1.0, 2.0, 3.0]),
        ([0.0, 0.0], [1.0, 1.0], [[1.0, 2.0], [1.0, 2.0]]),
        ([], [], 1.0),
    ],
    ids=["string", "resolution length", "resolution 2-D", "no axes"],
)
def test_pulse_counts_refuses_malformed_input(args):
    with pytest.raises(ControlError):
        dda_mod.pulse_counts(*args)


# ====================================================================== control: interpolation
UNIT_ARC = ([0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0])


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e200, 1e300])
def test_arc_at_extreme_scales_is_the_scaled_unit_arc(scale):
    """Radii of 1e-300 or 1e300 gave radius 0 or inf and a NaN sweep."""
    ref = circle_through(*UNIT_ARC)
    arc = circle_through(*(np.array(p) * scale for p in UNIT_ARC))
    assert math.isfinite(arc.radius) and math.isfinite(arc.sweep)
    assert arc.radius == pytest.approx(scale * ref.radius, rel=1e-12)
    assert arc.sweep == pytest.approx(ref.sweep, rel=1e-12)
    s = np.linspace(0.0, 1.0, 7)
    np.testing.assert_allclose(arc.points(s) / scale, ref.points(s), atol=1e-12)


def test_arc_far_from_the_origin_keeps_its_radius():
    base = np.array([1e300, 0.0, 0.0])
    arc = circle_through(*(base + 1e295 * np.array(p) for p in UNIT_ARC))
    assert arc.radius == pytest.approx(1e295, rel=1e-9)
    assert math.isfinite(arc.sweep) and 0.0 < arc.sweep < 2 * math.pi


def test_nearly_collinear_arc_is_finite_and_passes_its_points():
    p1, p2, p3 = np.zeros(3), np.array([1.0, 1e-150, 0.0]), np.array([2.0, 0.0, 0.0])
    arc = circle_through(p1, p2, p3, tol=0.0)
    assert math.isfinite(arc.radius) and math.isfinite(arc.sweep)
    pts = arc.points(np.array([0.0, arc.via_angle / arc.sweep, 1.0]))
    np.testing.assert_allclose(pts, [p1, p2, p3], atol=1e-12)
    assert np.all(np.isfinite(arc.points(np.linspace(0, 1, 11))))


def test_arc_whose_radius_overflows_is_degenerate():
    p1, p2, p3 = np.zeros(3), np.array([1e300, 1e290, 0.0]), np.array([2e300, 0.0, 0.0])
    with pytest.raises(DegenerateArcError, match="radius"):
        circle_through(p1, p2, p3, tol=0.0)


@pytest.mark.parametrize("tol", [math.nan, -1.0, math.inf, "x", 1.0])
def test_arc_refuses_a_bad_tolerance(tol):
    with pytest.raises(ControlError, match="tol"):
        circle_through(*UNIT_ARC, tol=tol)


def test_line_between_the_ends_of_the_float_range_is_finite():
    mid = line_points([-1e308, 0.0, 0.0], [1e308, 0.0, 0.0], 0.5)
    np.testing.assert_array_equal(mid, [0.0, 0.0, 0.0])


def test_pose_with_a_bad_last_row_is_refused():
    """A 4x4 pose with last row (5, 5, 5, 5) was silently replaced by (0, 0, 0, 1)."""
    bad = np.eye(4)
    bad[3] = 5.0
    with pytest.raises(ControlError, match="last row"):
        line_poses(bad, np.eye(4), 0.5)


@pytest.mark.parametrize(
    "call",
    [
        lambda: line_points([0, 0, 0], [1, 1, 1], "x"),
        lambda: circle_through([0, 0, 0], "abc", [2, 0, 0]),
        lambda: arc_poses(np.eye(4), "abc", np.eye(4), 0.5),
    ],
    ids=["s string", "point string", "via string"],
)
def test_interpolation_refuses_strings(call):
    with pytest.raises(ControlError):
        call()


# ============================================================================ control: servo
@pytest.mark.parametrize(
    "bad", [{"i": 1e200}, {"i": 1e308}, {"k_m": 1e308}, {"k_a": 1e308}, {"k_s": 1e308}]
)
def test_servo_with_coefficients_beyond_the_float_range_is_refused(bad):
    """(9-5)'s coefficients overflowed: OverflowError from i**2, LinAlgError from poles()."""
    with pytest.raises(ControlError, match="floating-point range"):
        PositionServo(**{**SERVO, **bad})


@pytest.mark.parametrize("omega_n", [1e200, 1e-200])
def test_tuned_servo_at_extreme_frequencies_is_refused(omega_n):
    motor = DCMotor(R=1.0, k_m=0.05, J_m=1e-6, i=50.0)
    with pytest.raises(ControlError):
        PositionServo.tuned(motor, 1e-3, omega_n, 0.7)


def test_servo_step_response_with_a_trillion_samples_names_the_budget():
    with within(5), pytest.raises(ControlError, match="budget"):
        PositionServo(**SERVO).step_response(1.0, n=10**12)


@pytest.mark.parametrize("dt", [1e6, 1e308])
def test_saturating_servo_long_step_is_refused_before_it_runs(dt):
    """RK4 sub-steps of 1/50 of the fastest time constant over dt = 1e6 s: a hang (and an
    OverflowError for 1e308)."""
    servo = PositionServo(**SERVO, V_max=10.0)
    with within(5), pytest.raises(ControlError, match="budget"):
        servo.advance([0.0, 0.0], dt, 1.0)
    with within(5), pytest.raises(ControlError, match="budget"):
        servo.simulate(np.array([0.0, dt]), 1.0)


def test_linear_servo_huge_step_is_not_nan():
    out = PositionServo(**SERVO).advance([0.0, 0.0], 1e308, 1.0)
    np.testing.assert_allclose(out, [1.0, 0.0])  # a stable servo has settled


@pytest.mark.parametrize("method", ["rhs", "voltage"])
def test_servo_ode_refuses_strings(method):
    servo = PositionServo(**SERVO)
    with pytest.raises(ControlError):
        getattr(servo, method)("ab", 0.0, 0.0)


# ============================================================================ control: motor
def test_motor_whose_torque_speed_slope_underflows_is_refused():
    """k_m = 1e-200: k_m²/R underflowed to 0, then ZeroDivisionError in the time constant."""
    with pytest.raises(ControlError, match="k_m"):
        DCMotor(R=1.0, k_m=1e-200, J_m=1.0)


def test_motor_arrays_that_do_not_broadcast_are_named():
    m = DCMotor(R=1.0, k_m=0.05, J_m=1e-6, i=50.0, V_nom=12.0)
    with pytest.raises(ControlError, match="omega"):
        m.motor_torque([1.0, 2.0, 3.0], [1.0, 2.0])


def test_motor_replace_with_an_unknown_parameter_is_typed():
    m = DCMotor(R=1.0, k_m=0.05, J_m=1e-6)
    with pytest.raises(ParameterError, match="foo"):
        m.replace(foo=1.0)


def test_rms_at_the_ends_of_the_float_range_is_exact():
    assert rms([0.0, 1.0], [1e200, 1e200]) == pytest.approx(1e200)
    assert rms([-1e308, 1e308], [1.0, 1.0]) == pytest.approx(1.0)


# ======================================================================== control: bilateral
def test_bilateral_tiny_max_step_names_the_budget():
    t = np.linspace(0.0, 1.0, 11)
    for max_step in (1e-12, 5e-324):
        with within(5), pytest.raises(ControlError, match="budget"):
            Bilateral().simulate("symmetric", t, np.sin(t), max_step=max_step)
    with within(5), pytest.raises(ControlError, match="budget"):
        Bilateral().simulate("symmetric", [0.0, 1e300], [0.0, 1.0])


@pytest.mark.parametrize("path", [lambda tt: "x", lambda tt: tt], ids=["string", "one value"])
def test_bilateral_bad_operator_path_is_named(path):
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ControlError, match="theta_h"):
        Bilateral().simulate("symmetric", t, path)


def test_bilateral_static_feel_beyond_the_float_range_is_refused():
    """k_f = G = 1e308 against 1e308 N m returned inf."""
    with pytest.raises(ControlError, match="floating-point range"):
        Bilateral(k_f=1e308, G=1e308).static_feel("force_feedback", 1e308)


# ========================================================================== control: gripper
def test_gripper_hostile_counts_and_resolutions():
    with within(5), pytest.raises(ControlError, match="max_steps"):
        gripper.tactile_search(lambda q: False, [0.0, 0.0], [1.0, 0.0], 1.0, 10**9)
    with within(5), pytest.raises(ControlError, match="step"):
        gripper.tactile_search(lambda q: False, [0.0, 0.0], [1.0, 0.0], 1e308, 3)
    with within(5), pytest.raises(ControlError, match="resolution"):
        gripper.correct_position(0.01, 0.02, 0.05, 1e-3, 5e-324)
    with within(5), pytest.raises(ControlError, match="resolution"):
        gripper.correct_attitude(0.1, 0.02, 0.05, 1e-3, 5e-324)
    with within(5), pytest.raises(ControlError, match="max_corrections"):
        gripper.correct_position(0.01, 0.02, 0.05, 1e-12, 1e-3, max_corrections=10**10)


def test_slip_controller_hostile_numbers():
    with pytest.raises(ControlError, match="grip_max"):
        gripper.SlipController(0.0, 0.05, grip_max=-math.inf)
    with pytest.raises(ControlError, match="grip_max"):
        gripper.SlipController(0.0, 0.05, grip_max=10**400)
    with pytest.raises(ControlError, match="pulses"):
        gripper.SlipController(0.1, 1.0).update(10**400)
    with pytest.raises(ControlError, match="n_jaws"):
        gripper.simulate_slip(1.0, 0.5, gripper.SlipController(0.0, 0.05), 1e-3, n_jaws=10**400)


def test_grasp_with_a_lead_whose_square_underflows_is_refused():
    motor = DCMotor(R=2.0, k_m=0.02, J_m=1e-6, i=100.0, V_nom=24.0)
    with pytest.raises(ControlError, match="lead"):
        gripper.grasp(motor, "hard", gap=0.005, stiffness=1e4, lead=1e-300, duration=0.2, n=11)


# ======================================================================= control: trajectory
def test_via_point_trajectory_refuses_strings_with_a_typed_error():
    from anthroarm.trajectory import ViaPointTrajectory

    with pytest.raises(AnthroarmError):
        ViaPointTrajectory("abc", [[0.0], [1.0]])
    traj = ViaPointTrajectory([0.0, 1.0], [[0.0], [1.0]])
    with pytest.raises(AnthroarmError):
        traj("x")


def test_straight_line_move_with_a_trillion_steps_names_the_budget():
    import anthroarm as aa
    from anthroarm.trajectory import straight_line_move

    robot = aa.load("prosthetic_arm")
    q = np.full(robot.model.nq, 0.3)
    with within(10), pytest.raises(ControlError, match="budget"):
        straight_line_move(robot, q, robot.fk(q), 2.0, 1e-12)
    with pytest.raises(ControlError, match="dt"):
        straight_line_move(robot, q, robot.fk(q), 2.0, "x")


# ============================================================================ teach: calls
def test_mutually_recursive_subroutines_are_refused_with_the_cycle_named():
    a = Program("a", (_step(0), Call("b")))
    b = Program("b", (_step(1), Call("a")))
    with within(5), pytest.raises(PlaybackError, match="a -> b -> a"):
        play_subroutines({"a": a, "b": b}, ["a"])
    with within(5), pytest.raises(PlaybackError, match="a -> b -> a"):
        play_select({"a": a, "b": b}, "a")


def test_self_calling_subroutine_without_steps_is_refused():
    e = Program("e", (Call("e"),))
    with within(5), pytest.raises(PlaybackError, match="e -> e"):
        play_subroutines({"e": e}, ["e"])


def test_exponential_call_tree_without_steps_stops():
    """Forty subroutines, each calling the next twice and none with a step: 2**40 calls, no
    step ever counted against max_steps (a hang)."""
    lib = {f"s{k}": Program(f"s{k}", (Call(f"s{k + 1}"), Call(f"s{k + 1}"))) for k in range(40)}
    lib["s40"] = Program("s40", ())
    with within(10):
        out = play_subroutines(lib, ["s0"])
    assert out.status == "step limit"


def test_call_depth_beyond_the_bound_is_refused():
    lib = {f"s{k}": Program(f"s{k}", (Call(f"s{k + 1}"),)) for k in range(300)}
    lib["s300"] = Program("s300", (_step(0),))
    with within(5), pytest.raises(PlaybackError, match="deeper"):
        play_subroutines(lib, ["s0"])


def test_jump_sensor_with_no_values_is_named():
    prog = Program("p", (_step(0, label="top"), Jump("top", "s")))
    with pytest.raises(PlaybackError, match="'s'"):
        play_jump(prog, {"s": []})


def test_random_access_history_is_not_quadratic():
    with within(8):
        out = play_random_access({"a": _step(0)}, "a", lambda a, h: "a", max_steps=200_000)
    assert out.status == "step limit" and len(out.executed) == 200_000


# ============================================================================ teach: files
def test_from_json_refuses_deep_nesting():
    deep = '{"name": "x", "items": ' + "[" * 100_000 + "]" * 100_000 + "}"
    with pytest.raises(ControlError, match="nest"):
        Program.from_json(deep)


def test_from_json_refuses_an_integer_with_too_many_digits():
    text = json.dumps({"name": "x", "items": []})[:-1] + ', "n": ' + "9" * 5000 + "}"
    with pytest.raises(ControlError):
        Program.from_json(text)


@pytest.mark.parametrize(
    "item",
    [{"kind": "jump", "label": 5}, {"kind": "call", "name": [1]}, {"kind": "step"}, 5],
)
def test_from_json_refuses_items_of_the_wrong_type(item):
    with pytest.raises(ControlError):
        Program.from_json(json.dumps({"name": "x", "items": [item]}))


def test_load_refuses_what_is_not_a_small_regular_program_file(tmp_path):
    with pytest.raises(ControlError, match="folder"):
        Program.load(tmp_path)
    with pytest.raises(ControlError, match="not found"):
        Program.load(tmp_path / "missing.json")
    binary = tmp_path / "bin.json"
    binary.write_bytes(b"\x80\x81\xff")
    with pytest.raises(ControlError, match="(?i)utf-8"):
        Program.load(binary)
    huge = tmp_path / "huge.json"
    with open(huge, "wb") as f:
        f.truncate(2**40)  # sparse: 1 TiB that must be refused before it is read
    with within(5), pytest.raises(ControlError, match="bytes"):
        Program.load(huge)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with within(5), pytest.raises(ControlError, match="regular file"):
        Program.load(fifo)


def test_save_load_round_trip_still_works(tmp_path):
    p = Program("p", (_step(0, label="a"), Jump("a", "s"), _step(1), Call("q")))
    p.save(tmp_path / "p.json")
    assert Program.load(tmp_path / "p.json").to_json() == p.to_json()


# ========================================================================= teach: programs
@pytest.mark.parametrize(
    "call",
    [
        lambda: Program("x", 5),
        lambda: Program(5, ()),
        lambda: Jump(5),
        lambda: Call(None),
        lambda: record("x", [[0.0], [1.0]], "a"),
        lambda: record("x", [[0.0], [1.0]], [1.0, 2.0, 3.0]),
        lambda: Program.from_channels("x", 5, [[1.0]], [1.0]),
        lambda: play_subroutines({"a": 5}, ["a"]),
        lambda: play_select({"a": Program("a", ())}, lambda s: ["a"]),
    ],
    ids=[
        "items int",
        "name int",
        "jump label int",
        "call name None",
        "times string",
        "times length",
        "sequence int",
        "library value",
        "selector unhashable",
    ],
)
def test_teach_refuses_malformed_programs(call):
    with pytest.raises(ControlError):
        call()


@pytest.mark.parametrize("dt", [1e-12, 5e-324])
def test_trajectory_with_a_tiny_time_step_names_the_budget(dt):
    """dt = 1e-12 over 2 s asked numpy for 14.6 TiB (MemoryError); 5e-324 an OverflowError."""
    pb = play_fixed(record("x", [[0.0], [1.0]], 2.0))
    t0 = time.perf_counter()
    with pytest.raises(ControlError, match="budget") as err:
        pb.trajectory(dt)
    assert time.perf_counter() - t0 < 1.0
    assert "dt" in str(err.value)


def test_trajectory_between_huge_joint_values_is_finite():
    pb = play_fixed(record("x", [[0.0], [1e308], [-1e308]], 1.0))
    t, p = pb.trajectory(0.5)
    assert np.all(np.isfinite(p))
    np.testing.assert_allclose(p[:, 0], [0.0, 5e307, 1e308, 0.0, -1e308])
