"""Gripper behaviours: search steps, correction end conditions, grasp steady forces from
statics, slip control against a hand-integrated constant-acceleration motion."""

import math

import numpy as np
import pytest

from anthroarm.control import (
    DCMotor,
    SlipController,
    correct_attitude,
    correct_position,
    grasp,
    simulate_slip,
    tactile_search,
)
from anthroarm.errors import ControlError


def test_tactile_search_stops_on_the_first_step_past_the_edge():
    edge, step = 0.137, 0.01
    r = tactile_search(lambda p: p[0] >= edge, [0.0, 0.2, 0.1], [1.0, 0.0, 0.0], step)
    assert r.found and r.status == "contact"
    assert r.steps == math.ceil(edge / step)  # 14 unit steps
    assert (
        r.position[0] == pytest.approx(r.steps * step)
        and r.position[0] >= edge > r.position[0] - step
    )
    miss = tactile_search(lambda p: False, [0.0, 0.0], [0.0, 2.0], 0.01, max_steps=25)
    assert not miss.found and miss.status == "not found" and miss.steps == 25
    assert miss.position == pytest.approx([0.0, 0.25])
    with pytest.raises(ControlError):
        tactile_search(lambda p: True, [0.0, 0.0], [0.0, 0.0], 0.01)


@pytest.mark.parametrize("offset", [-0.0123, -0.004, 0.0, 0.0071, 0.02])
def test_position_correction_centres_the_object(offset):
    unit, res = 0.001, 0.0015
    r = correct_position(offset, width=0.03, opening=0.08, unit=unit, resolution=res)
    assert r.status == "aligned"
    # both jaws touch on the same increment: ceil((h+d)/res) == ceil((h-d)/res), so |2d| < res
    half = 0.5 * (0.08 - 0.03)
    assert math.ceil((half + r.error) / res - 1e-12) == math.ceil((half - r.error) / res - 1e-12)
    assert abs(r.error) < res / 2 + 1e-15
    # every correction moved one unit towards the centre, never past it by more than a unit
    assert np.allclose(np.abs(np.diff(r.history)), unit)
    assert r.corrections == len(r.history) - 1
    assert r.corrections <= math.ceil(abs(offset) / unit)


def test_attitude_correction_makes_the_pad_parallel():
    unit, res, pad = math.radians(0.5), 0.0005, 0.04
    r = correct_attitude(math.radians(12.0), pad_length=pad, gap=0.01, unit=unit, resolution=res)
    assert r.status == "aligned"
    assert pad * abs(math.tan(r.error)) < res + 1e-15
    assert np.allclose(np.diff(r.history), -unit)  # turned one way only
    assert r.error > 0 or abs(r.error) < unit
    lim = correct_attitude(
        math.radians(12.0), pad_length=pad, gap=0.01, unit=unit, resolution=res, max_corrections=3
    )
    assert lim.status == "limit" and lim.corrections == 3
    with pytest.raises(ControlError):
        correct_attitude(math.radians(80.0), pad_length=pad, gap=0.01, unit=unit, resolution=res)
    with pytest.raises(ControlError, match="fit"):
        correct_position(0.03, width=0.03, opening=0.08, unit=0.001, resolution=0.001)


MOTOR = DCMotor(R=8.0, k_m=0.012, J_m=5e-7, b_m=1e-7, i=50.0, eta=0.7, V_nom=6.0)
LEAD = 0.002


@pytest.mark.parametrize("mode", ["hard", "soft", "zero"])
def test_grasp_modes_reach_their_static_forces(mode):
    r = grasp(MOTOR, mode, gap=0.01, stiffness=2e4, lead=LEAD, duration=4.0, set_force=5.0, n=401)
    assert 1.0 < r.contact_time < 1.1  # 10 mm at 10 mm/s, after the start-up
    assert np.all(r.force[r.t < r.contact_time] == 0.0)
    # statics: hard = the stall force at V_nom through gear and lead; soft = the set force; zero =
    # none
    stall = MOTOR.eta * MOTOR.i * MOTOR.k_m * MOTOR.V_nom / (MOTOR.R * LEAD)
    expected = {"hard": stall, "soft": 5.0, "zero": 0.0}[mode]
    assert r.force[-1] == pytest.approx(expected, rel=2e-3, abs=1e-3)
    assert r.x[-1] == pytest.approx(0.01 + expected / 2e4, abs=2e-6)
    assert np.all(np.abs(r.V) <= MOTOR.V_nom + 1e-12)


def test_grasp_bad_inputs():
    with pytest.raises(ControlError, match="mode"):
        grasp(MOTOR, "firm", gap=0.01, stiffness=2e4, lead=LEAD, duration=1.0)
    with pytest.raises(ControlError, match="V_nom"):
        grasp(MOTOR.replace(V_nom=None), "hard", gap=0.01, stiffness=2e4, lead=LEAD, duration=1.0)
    with pytest.raises(ControlError, match="approach_speed"):
        grasp(MOTOR, "hard", gap=0.01, stiffness=2e4, lead=LEAD, duration=1.0, approach_speed=1.0)


def test_slip_controller_steps_and_holds():
    c = SlipController(grip=2.0, step=0.5, grip_max=4.0)
    assert c.update(0) == 2.0
    assert c.update(3) == 3.5
    assert c.update(5) == 4.0  # capped
    with pytest.raises(ControlError):
        c.update(-1)


def test_slip_one_pulse_then_hold_matches_constant_acceleration_kinematics():
    m, mu, g, u = 0.2, 0.5, 9.81, 1e-3
    F0 = 0.9 * m * g / (2 * mu)  # 10 % short of holding
    step = 0.5 * m * g / (2 * mu)  # one step is plenty
    r = simulate_slip(m, mu, SlipController(F0, step), u, g=g)
    a0 = g - 2 * mu * F0 / m
    a1 = g - 2 * mu * (F0 + step) / m  # < 0: decelerates
    t1 = math.sqrt(2 * u / a0)
    v1 = a0 * t1
    assert r.status == "held" and r.pulses == 1
    assert r.pulse_times[0] == pytest.approx(t1, rel=1e-12)
    assert r.slip == pytest.approx(u + v1 * v1 / (-2 * a1), rel=1e-12)
    assert r.stop_time == pytest.approx(t1 + v1 / -a1, rel=1e-12)
    assert r.grip == pytest.approx(F0 + step)


def test_slip_small_steps_grip_equals_start_plus_steps_and_holds_the_weight():
    m, mu, u = 0.3, 0.4, 5e-4
    F0, step = 1.0, 0.05
    r = simulate_slip(m, mu, SlipController(F0, step), u)
    assert r.status == "held"
    assert r.grip == pytest.approx(F0 + step * r.pulses)
    assert 2 * mu * r.grip >= m * 9.81  # it holds
    assert r.pulses * u <= r.slip < (r.pulses + 1) * u
    assert np.all(np.diff(r.pulse_times) > 0)
    # enough grip from the start: no slip at all
    held = simulate_slip(m, mu, SlipController(m * 9.81 / (2 * mu), step), u)
    assert held.pulses == 0 and held.slip == 0.0
    # a hand too weak to hold: dropped
    weak = simulate_slip(m, mu, SlipController(F0, step, grip_max=2.0), u, max_slip=0.02)
    assert weak.status == "dropped" and weak.grip == 2.0


def test_counts_are_checked():
    with pytest.raises(ControlError, match="max_steps"):
        tactile_search(lambda p: True, [0.0], [1.0], 0.1, max_steps=-1)
    with pytest.raises(ControlError, match="max_corrections"):
        correct_position(0.0, 0.03, 0.08, 0.001, 0.001, max_corrections=1.5)
    with pytest.raises(ControlError, match="n_jaws"):
        simulate_slip(0.1, 0.5, SlipController(1.0, 0.1), 1e-3, n_jaws=0)
    with pytest.raises(ControlError, match="pulses"):
        SlipController(1.0, 0.1).update(True)
