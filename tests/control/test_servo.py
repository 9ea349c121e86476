"""The analog position servo (9-1)–(9-8) against its own equations composed independently,
closed-form second-order step responses, scipy.signal, and the final-value theorem."""

import math

import numpy as np
import pytest
import scipy.signal

from anthroarm.control import DCMotor, PositionServo
from anthroarm.errors import ControlError

# book symbols, SI: k_m N m/V, k N m s/rad, J kg m^2, k_a V/V, k_p V/rad, k_s V s/rad
SERVO = PositionServo(k_m=0.013, k=4e-4, J_m=2e-6, J_L=0.02, i=20.0, k_a=20.0, k_p=2.0, k_s=0.004)


def composed_acceleration(s: PositionServo, theta, omega, theta_i, M_L, printed_tacho=False):
    """θ̈ from (9-1)–(9-4) written out separately: unknowns θ̈ and the gear force P r,
    J_m i θ̈ + P r = M_m (9-2), J_L θ̈ − η i P r = −M_L (9-3)."""
    w_m = s.i * omega
    V = s.k_a * s.k_p * (theta_i - theta) - s.k_a * s.k_s * w_m  # (9-4), corrected
    M_m = s.k_m * V - s.k * w_m  # (9-1)
    A = np.array([[s.J_m * s.i, 1.0], [s.J_L, -s.eta * s.i]])
    acc, _Pr = np.linalg.solve(A, [M_m, -M_L])
    return acc


def test_9_5_coefficients_from_the_composed_equations():
    rng = np.random.default_rng(1)
    for s in (SERVO, SERVO.__class__(**{**SERVO.__dict__, "eta": 0.7})):
        for _ in range(5):
            th, om, thi, ml = rng.normal(size=4)
            acc = composed_acceleration(s, th, om, thi, ml)
            assert s.rhs(np.array([th, om]), thi, ml)[1] == pytest.approx(acc, rel=1e-12, abs=1e-12)
            # and (9-5): J0 acc + Kv om + Ks th = Ks thi - M_L
            assert s.J0 * acc + s.Kv * om + s.Ks * th == pytest.approx(
                s.Ks * thi - ml, rel=1e-10, abs=1e-12
            )


def test_printed_Kv_of_9_5_fails():
    """Printed K_v = i²(k_s + k_m k_a k_r) (k_r read as the only tacho constant k_s); the damping of
    the composed (9-1)–(9-4) is i²(k + k_m k_a k_s)."""
    s = SERVO
    acc = composed_acceleration(s, 0.0, 1.0, 0.0, 0.0)  # at θ = θ_i, θ̇ = 1: J0 θ̈ = −K_v
    Kv_true = -s.J0 * acc
    printed = s.i**2 * (s.k_s + s.k_m * s.k_a * s.k_s)
    assert Kv_true == pytest.approx(s.Kv, rel=1e-12)
    assert abs(printed - Kv_true) > 0.1 * Kv_true


def closed_form_step(t, wn, z):
    """Unit step of wn² / (s² + 2 z wn s + wn²)."""
    if z < 1:
        wd = wn * math.sqrt(1 - z * z)
        return 1 - np.exp(-z * wn * t) * (
            np.cos(wd * t) + z / math.sqrt(1 - z * z) * np.sin(wd * t)
        )
    r1, r2 = -wn * (z - math.sqrt(z * z - 1)), -wn * (z + math.sqrt(z * z - 1))
    return 1 + (r2 * np.exp(r1 * t) - r1 * np.exp(r2 * t)) / (r1 - r2)


@pytest.mark.parametrize("k_s", [0.0005, 0.004, 0.02])
def test_step_response_equals_the_second_order_closed_form(k_s):
    s = SERVO.__class__(**{**SERVO.__dict__, "k_s": k_s})
    wn = math.sqrt(s.Ks / s.J0)
    z = s.Kv / (2 * math.sqrt(s.Ks * s.J0))
    assert s.natural_frequency == pytest.approx(wn) and s.damping_ratio == pytest.approx(z)
    r = s.step_response(12.0 / np.min(np.abs(s.poles().real)), theta_step=0.3, n=801)
    assert np.allclose(r.theta, 0.3 * closed_form_step(r.t, wn, z), atol=1e-12)
    # e = k_p (θ_i − θ): starts at k_p θ_step and dies out (Fig. 9-16 (a))
    assert r.e[0] == pytest.approx(s.k_p * 0.3)
    assert abs(r.e[-1]) < 1e-3 * s.k_p * 0.3


def test_transfer_functions_against_scipy_and_poles():
    s = SERVO
    tfs = s.transfer_functions()
    t = np.linspace(0, 1.0, 501)
    r = s.simulate(t, 0.0, 0.7)  # load step only (Fig. 9-16 (b))
    _, y = scipy.signal.step(tfs["e/M_L"], T=t)
    assert np.allclose(r.e, 0.7 * y, atol=1e-9 * s.k_p)
    _, y = scipy.signal.step(tfs["theta/M_L"], T=t)
    assert np.allclose(r.theta, 0.7 * y, atol=1e-9)
    # e/θ_i + θ/θ_i * k_p = k_p (identity of (9-7))
    num = np.polyadd(tfs["e/theta_i"].num, s.k_p * np.asarray(tfs["theta/theta_i"].num))
    assert np.allclose(num, s.k_p * np.asarray(tfs["e/theta_i"].den))
    p = s.poles()
    assert np.allclose(np.polyval([s.J0, s.Kv, s.Ks], p), 0.0, atol=1e-6 * s.Ks)


def test_steady_error_is_the_load_torque_over_i_km_ka():
    """(9-8) by simulation (final-value theorem), whatever the set-point; printed 1/(i k_m k_s)
    fails."""
    s = SERVO
    M_L = 0.9
    t = np.linspace(0, 30.0 / np.min(np.abs(s.poles().real)), 3001)
    r = s.simulate(t, 0.4, M_L)
    e_end = r.e[-1]
    assert e_end == pytest.approx(M_L / (s.i * s.k_m * s.k_a), rel=1e-9)
    assert s.steady_error(M_L) == pytest.approx(e_end, rel=1e-9)
    printed = M_L / (s.i * s.k_m * s.k_s)
    assert abs(printed - e_end) > 10 * abs(e_end)
    # the servo error as a force sensor
    assert s.estimate_load_torque(e_end) == pytest.approx(M_L, rel=1e-9)
    # proportional to the load (vectorised)
    assert np.allclose(s.estimate_load_torque(s.steady_error([-1.0, 0.0, 2.5])), [-1.0, 0.0, 2.5])


def test_from_motor_and_tuned():
    m = DCMotor(R=2.0, k_m=0.03, J_m=1.5e-6, b_m=1e-6, i=20.0, eta=0.85, V_nom=24.0)
    s = PositionServo.from_motor(m, J_L=0.01, k_a=10.0, k_p=1.0, k_s=0.002)
    assert s.k_m == pytest.approx(m.stall_torque_coefficient) and s.k == pytest.approx(
        m.torque_speed_slope
    )
    # the servo's static load line at V: the stall torque of the motor at the joint
    acc = composed_acceleration(s, 0.0, 0.0, 1.0 / (s.k_a * s.k_p), 0.0)  # V = 1 V, at rest
    assert s.J0 * acc == pytest.approx(float(m.stall_torque(1.0)), rel=1e-12)
    tuned = PositionServo.tuned(m, J_L=0.01, omega_n=30.0, zeta=0.9)
    assert tuned.natural_frequency == pytest.approx(30.0, rel=1e-12)
    assert tuned.damping_ratio == pytest.approx(0.9, rel=1e-12)
    with pytest.raises(ControlError, match="damping"):
        PositionServo.tuned(m, J_L=0.0, omega_n=500.0, zeta=0.01)


def test_saturated_amplifier_slews_at_the_no_load_speed():
    m = DCMotor(R=2.0, k_m=0.03, J_m=1.5e-6, i=20.0, V_nom=12.0)
    lin = PositionServo.tuned(m, J_L=0.005, omega_n=40.0, zeta=0.8, k_p=1.0)
    big = PositionServo(**{**lin.__dict__, "V_max": 1e9})
    t = np.linspace(0, 0.2, 201)
    assert np.allclose(lin.simulate(t, 0.1).theta, big.simulate(t, 0.1).theta, atol=1e-9)
    sat = PositionServo(**{**lin.__dict__, "V_max": 12.0})
    r = sat.simulate(np.linspace(0, 1.0, 1001), 100.0)  # a far set-point: V stays clipped
    assert r.saturated[10:].all()
    assert r.omega[-1] == pytest.approx(float(m.no_load_speed(12.0)), rel=1e-6)


def test_advance_equals_simulate():
    t = np.linspace(0, 0.3, 31)
    r = SERVO.simulate(t, 0.2, 0.1)
    x = np.zeros(2)
    for k in range(30):
        x = SERVO.advance(x, 0.01, 0.2, 0.1)
    assert np.allclose(x, [r.theta[-1], r.omega[-1]], atol=1e-12)


@pytest.mark.parametrize(
    "kw",
    [
        dict(k_m=0.0),
        dict(k_a=np.nan),
        dict(J_m=0.0, J_L=0.0),
        dict(eta=2.0),
        dict(V_max=-1.0),
        dict(k=-1.0),
    ],
)
def test_bad_parameters(kw):
    with pytest.raises(ControlError):
        PositionServo(**{**SERVO.__dict__, **kw})


def test_bad_simulation_inputs():
    with pytest.raises(ControlError):
        SERVO.simulate([0.0, 0.0, 1.0])
    with pytest.raises(ControlError):
        SERVO.simulate([0.0, 1.0, 2.0], theta_i=[0.0, 1.0])
    with pytest.raises(ControlError):
        SERVO.simulate([0.0, 1.0], theta_i=np.inf)
    with pytest.raises(ControlError):
        SERVO.advance([0.0, 0.0], 0.0, 1.0)


def test_book_units():
    """kgf·cm = 9.80665 N × 0.01 m; kgf·cm·s² = 9.80665 N × 0.01 m × s² = 0.0980665 kg·m²."""
    b = PositionServo.from_book_units(
        k_m=0.5, k=0.01, J_m=2e-5, J_L=0.1, i=50.0, k_a=10.0, k_p=1.0, k_s=0.01
    )
    assert b.k_m == pytest.approx(0.5 * 9.80665 * 0.01) and b.J_L == pytest.approx(
        0.1 * 9.80665 * 0.01
    )
    # the dynamics do not depend on the unit system: ω_n and ζ are those of the same servo in kgf·cm
    wn = math.sqrt(50.0 * 0.5 * 10.0 * 1.0 / (50.0**2 * 2e-5 + 0.1))
    assert b.natural_frequency == pytest.approx(wn, rel=1e-12)
    # the steady error (volts) under a load of 1 kgf·cm is the same number in either system
    assert float(b.steady_error(9.80665e-2)) == pytest.approx(1.0 / (50.0 * 0.5 * 10.0), rel=1e-12)


def test_overflowing_inputs_raise():
    with pytest.raises(ControlError):
        SERVO.simulate([0.0, 1.0, 2.0], theta_i=1e307)
    with pytest.raises(ControlError, match="floating-point"):
        SERVO.estimate_load_torque(1e308)
