"""DC motor + gearbox (anthroarm.control.motor) against the circuit equations and mathematics."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from anthroarm.control import DCMotor, rms
from anthroarm.errors import ControlError

# a coreless 24 V motor like the care robot's (maxon-like numbers), 100:1 gearbox
MOTOR = DCMotor(
    R=2.3,
    k_m=0.0302,
    J_m=1.35e-6,
    L=0.24e-3,
    b_m=2e-6,
    i=100.0,
    eta=0.8,
    V_nom=24.0,
    tau_cont=0.0289,
    name="test motor",
)


def steady_state(m: DCMotor, V: float, tau_load_m: float) -> tuple[float, float]:
    """Motor speed and current at rest of d/dt: V = R I + k ω, k I = b ω + τ (linear solve)."""
    A = np.array([[m.R, m.k_m], [m.k_m, -m.b_m]])
    I, w = np.linalg.solve(A, [V, tau_load_m])
    return w, I


def test_torque_speed_line_matches_circuit_equations():
    V = 18.0
    for tau_m in (0.0, 0.01, 0.05, 0.1):
        w, I = steady_state(MOTOR, V, tau_m)
        assert MOTOR.motor_torque(V, w) == pytest.approx(tau_m, abs=1e-12)
        # the joint sees eta * i times the shaft torque at speed w / i
        assert MOTOR.joint_torque(w / MOTOR.i, V) == pytest.approx(
            MOTOR.eta * MOTOR.i * tau_m, abs=1e-10
        )
        assert MOTOR.speed_at_torque(MOTOR.eta * MOTOR.i * tau_m, V) == pytest.approx(
            w / MOTOR.i, rel=1e-12
        )
        assert MOTOR.voltage(MOTOR.eta * MOTOR.i * tau_m, w / MOTOR.i) == pytest.approx(
            V, rel=1e-12
        )


def test_stall_torque_and_no_load_speed_are_the_ends_of_the_line():
    w0, _ = steady_state(MOTOR, 24.0, 0.0)
    I_stall = np.linalg.solve(np.array([[MOTOR.R, MOTOR.k_m], [0.0, 1.0]]), [24.0, 0.0])[0]  # w = 0
    assert MOTOR.no_load_speed() == pytest.approx(w0 / MOTOR.i, rel=1e-12)
    assert MOTOR.stall_torque() == pytest.approx(
        MOTOR.eta * MOTOR.i * MOTOR.k_m * I_stall, rel=1e-12
    )
    assert MOTOR.joint_torque(MOTOR.no_load_speed()) == pytest.approx(0.0, abs=1e-12)
    assert MOTOR.joint_torque(0.0) == pytest.approx(MOTOR.stall_torque(), rel=1e-12)
    # straight line in between (vectorised)
    w = np.linspace(0.0, float(MOTOR.no_load_speed()), 7)
    assert np.allclose(
        MOTOR.joint_torque(w), MOTOR.stall_torque() * (1 - w / MOTOR.no_load_speed()), rtol=1e-12
    )


def test_book_symbols_of_9_1():
    assert MOTOR.stall_torque_coefficient == pytest.approx(MOTOR.k_m / MOTOR.R)
    assert MOTOR.torque_speed_slope == pytest.approx(MOTOR.k_m**2 / MOTOR.R + MOTOR.b_m)
    assert MOTOR.reflected_inertia == pytest.approx(1e4 * 1.35e-6)


def test_dynamic_motor_settles_on_the_steady_line():
    """Integrate L dI/dt = V - R I - k w, J dw/dt = k I - b w - tau and compare the end state."""
    m, V, tau = MOTOR, 12.0, 0.02

    def f(t, x):
        I, w = x
        return [(V - m.R * I - m.k_m * w) / m.L, (m.k_m * I - m.b_m * w - tau) / m.J_m]

    sol = solve_ivp(f, (0, 0.5), [0.0, 0.0], method="LSODA", rtol=1e-10, atol=1e-12)
    w_end = sol.y[1, -1]
    assert m.speed_at_torque(m.eta * m.i * tau, V) * m.i == pytest.approx(w_end, rel=1e-6)
    assert m.electrical_time_constant == pytest.approx(0.24e-3 / 2.3)
    # the unloaded speed rises with the mechanical time constant (L neglected): 1 - e^-1 at tau_m
    m0 = m.replace(L=0.0)
    tm = m0.mechanical_time_constant
    w_inf = m0.no_load_speed(V) * m0.i
    sol = solve_ivp(
        lambda t, w: [(m0.k_m * (V - m0.k_m * w[0]) / m0.R - m0.b_m * w[0]) / m0.J_m],
        (0, tm),
        [0.0],
        rtol=1e-11,
        atol=1e-12,
    )
    assert sol.y[0, -1] == pytest.approx(w_inf * (1 - np.exp(-1.0)), rel=1e-7)


def test_gear_efficiency_follows_the_power_flow():
    tau, w = 2.0, 1.5  # joint torque, speed (N m, rad/s)
    # shaft torque after the rotor's viscous friction (b_m i w) is what enters the gears
    tm = MOTOR.required_motor_torque(tau, w) - MOTOR.b_m * MOTOR.i * w
    # motoring: motor shaft power = joint power / eta
    assert tm * MOTOR.i * w == pytest.approx(tau * w / MOTOR.eta, rel=1e-12)
    # back-driven: the motor absorbs eta times the joint power
    tb = MOTOR.required_motor_torque(tau, -w) - MOTOR.b_m * MOTOR.i * (-w)
    assert tb * MOTOR.i * (-w) == pytest.approx(MOTOR.eta * tau * (-w), rel=1e-12)
    # acceleration of the rotor through the gear
    a = 3.0
    assert MOTOR.required_motor_torque(0.0, 0.0, a) * MOTOR.i == pytest.approx(
        MOTOR.reflected_inertia * a
    )


def test_rms_of_a_sine_and_the_thermal_limit():
    t = np.linspace(0.0, 2.0, 20001)  # two full periods
    assert rms(t, 3.0 * np.sin(2 * np.pi * t)) == pytest.approx(3.0 / np.sqrt(2), rel=1e-7)
    # constant holding torque at zero speed: RMS motor torque = tau / (eta i)
    limit = MOTOR.continuous_torque
    ok = MOTOR.thermal_check(t, 0.99 * limit)
    bad = MOTOR.thermal_check(t, 1.01 * limit)
    assert ok.ok and not bad.ok
    assert ok.rms_torque == pytest.approx(0.99 * MOTOR.tau_cont, rel=1e-12)
    assert bad.ratio == pytest.approx(1.01, rel=1e-12)
    # a sine of amplitude sqrt(2) * limit is exactly at the limit
    cyc = MOTOR.thermal_check(t, np.sqrt(2) * limit * np.sin(2 * np.pi * t))
    assert cyc.ratio == pytest.approx(1.0, rel=1e-6)
    assert cyc.peak_torque == pytest.approx(np.sqrt(2) * MOTOR.tau_cont, rel=1e-6)


def test_within_torque_speed():
    w = 0.5 * float(MOTOR.no_load_speed())
    t_max = float(MOTOR.joint_torque(w))
    assert MOTOR.within_torque_speed(0.99 * t_max, w)
    assert not MOTOR.within_torque_speed(1.01 * t_max, w)


@pytest.mark.parametrize(
    "bad",
    [
        dict(R=0.0),
        dict(k_m=-1.0),
        dict(eta=1.2),
        dict(eta=0.0),
        dict(i=np.nan),
        dict(J_m=-1e-6),
        dict(L=np.inf),
        dict(tau_cont=0.0),
    ],
)
def test_bad_parameters_raise_control_error(bad):
    with pytest.raises(ControlError):
        MOTOR.replace(**bad)


def test_missing_ratings_raise():
    m = MOTOR.replace(V_nom=None, tau_cont=None)
    with pytest.raises(ControlError, match="V_nom"):
        m.stall_torque()
    with pytest.raises(ControlError, match="tau_cont"):
        m.thermal_check([0, 1], 1.0)
    with pytest.raises(ControlError):
        rms([0.0, 0.0], [1.0, 1.0])


def test_results_beyond_the_float_range_raise():
    with pytest.raises(ControlError, match="floating-point"):
        MOTOR.replace(R=1e-3).motor_torque(1e308, 0.0)  # k_m/R = 30 N m/V: 3e309 N m
    with pytest.raises(ControlError):
        MOTOR.joint_torque(1e307, 1e308)
    with pytest.raises(ControlError, match="floating-point"):
        MOTOR.copper_loss(1e300)  # R I^2 with I ~ 4e299 A
