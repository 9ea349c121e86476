"""The EMG-driven chain (issue 34 item 4): activation dynamics against OpenSim 4.6's
``Thelen2003Muscle`` activation rate and against an independent ODE integrator (scipy's Radau
at rtol 1e-12); the A-shape against its formula's limits; muscle torques of the driven biceps
against OpenSim (``equilibrateMuscles`` → ``getTendonForce`` × ``computeMomentArm``); the torque
an activity needs against Pinocchio (gravity + Jᵀ of the held weight); bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import anthroarm as aa
from anthroarm.errors import EMGError, MuscleError
from anthroarm.muscles import emg as me
from anthroarm.muscles import read_muscles

TA, TD = 0.01, 0.04  # arm26's Thelen2003 activation / deactivation time constants


def _rate(u, e):
    # Thelen (2003) Eq. 7, written out here from the paper
    return (e - u) / (TA * (0.5 + 1.5 * u)) if e > u else (e - u) * (0.5 + 1.5 * u) / TD


def test_activation_rate_is_opensims():
    opensim = pytest.importorskip("opensim")
    opensim.Logger.setLevelString("error")
    model = opensim.Model(str(aa.osim.path("arm26")))
    state = model.initSystem()
    bic = model.getMuscles().get("BIClong")
    th = opensim.Thelen2003Muscle.safeDownCast(bic)
    h = 1e-9
    for u, e in [(0.2, 0.8), (0.7, 0.1), (0.05, 1.0), (0.95, 0.02), (0.4, 0.41)]:
        bic.setActivation(state, u)
        model.realizeVelocity(state)
        controls = model.updControls(state)
        bic.setControls(opensim.Vector(1, e), controls)
        model.setControls(state, controls)
        model.realizeAcceleration(state)
        ours = (me.step(u, e, h, TA, TD) - u) / h
        assert np.isclose(ours, th.getActivationRate(state), rtol=1e-5), (u, e)


def test_exact_steps_equal_an_ode_integrator():
    rng = np.random.default_rng(3)
    fs = 1000.0
    e = np.repeat(rng.uniform(0, 1, 6), 20)  # held excitations, 20 ms each
    u = me.neural_activation(e, fs, tau_act=TA, tau_deact=TD, u0=0.0)
    t = np.arange(e.size) / fs
    ref = [0.0]
    for k in range(1, e.size):  # the same zero-order hold, integrated by Radau
        sol = solve_ivp(
            lambda _t, y, ek=e[k - 1]: [_rate(y[0], ek)],
            (t[k - 1], t[k]),
            [ref[-1]],
            method="Radau",
            rtol=1e-12,
            atol=1e-14,
        )
        ref.append(sol.y[0, -1])
    assert np.abs(u - np.array(ref)).max() < 1e-9
    assert u.min() >= 0 and u.max() <= 1


def test_activation_closed_forms():
    # activation: c ln(w/w0) - 1.5 (w - w0) = -dt/tau_act; deactivation: w/(c+1.5w) decays
    for u0, e, dt in [(0.1, 0.9, 0.004), (0.0, 0.5, 0.02), (0.9, 0.1, 0.01), (1.0, 0.0, 0.05)]:
        u1 = float(me.step(u0, e, dt, TA, TD))
        c, w0, w = 0.5 + 1.5 * e, abs(e - u0), abs(e - u1)
        if e > u0:
            assert np.isclose(c * np.log(w / w0) - 1.5 * (w - w0), -dt / TA, rtol=1e-12)
        else:
            lhs = w / (c + 1.5 * w)
            assert np.isclose(lhs, w0 / (c + 1.5 * w0) * np.exp(-c * dt / TD), rtol=1e-12)


def test_a_shape():
    u = np.linspace(0, 1, 11)
    for A in (-3.0, -1.5, -0.5):
        a = me.activation_shape(u, A)
        assert a[0] == 0 and np.isclose(a[-1], 1.0, rtol=1e-15)
        assert np.all(np.diff(a) > 0) and np.all(a[1:-1] > u[1:-1])  # concave for A < 0
        assert np.isclose(a[5], (np.exp(A / 2) - 1) / (np.exp(A) - 1), rtol=1e-14)
    np.testing.assert_array_equal(me.activation_shape(u, 0.0), u)
    assert np.abs(me.activation_shape(u, -1e-6) - u).max() < 1e-6


def test_excitation_of_a_steady_sine_is_its_mean_rectified_value():
    fs, amp = 2000.0, 1e-3
    t = np.arange(8000) / fs
    x = amp * np.sin(2 * np.pi * 100 * t)
    # MAV of a sine: 2A/pi (the MVC above the low-pass's 4 % start-up overshoot)
    e = me.excitation(x, fs, mvc=2 * amp / np.pi * 1.1)
    assert abs(e[-2000:].mean() - 1 / 1.1) < 5e-3


def test_shipped_recording():
    rec = me.read_recording()
    assert rec.channels == ["BicepsBrachiiR"] and rec.emg.shape == (1, 6534)
    assert abs(rec.fs - 1923.08) < 0.1 and np.abs(rec.emg).max() < 1e-3  # volts
    e = me.excitation(rec.emg, rec.fs)
    assert e.max() == 1.0 and e.min() >= 0.0


def _arm26_cylinders(tmp_path):
    text = re.sub(
        r"(<WrapEllipsoid name=\"\w+\">\s*<!--[^>]*-->\s*<active>)true",
        r"\1false",
        aa.osim.path("arm26").read_text(),
    )
    p = tmp_path / "arm26_cylinders.osim"
    p.write_text(text)
    return p


def test_driven_biceps_torque_against_opensim(tmp_path):
    opensim = pytest.importorskip("opensim")
    opensim.Logger.setLevelString("error")
    p = _arm26_cylinders(tmp_path)
    robot, ms = aa.load(p), read_muscles(p)
    full = me.read_recording()
    # the first 0.16 s (the cylinder wraps are evaluated state by state)
    rec = me.Recording(full.t[:300], full.emg[:, :300], full.channels, full.fs)
    n = rec.t.size
    s = (rec.t - rec.t[0]) / (rec.t[-1] - rec.t[0])
    q = np.column_stack([np.zeros(n), 0.3 + 1.2 * np.sin(np.pi * s) ** 2])
    res = me.drive(robot, ms, rec, q, {"BIClong": 0, "BICshort": 0}, strength=0.5)
    assert np.all(np.isfinite(res.torque))
    model = opensim.Model(str(p))
    state = model.initSystem()
    coords = [model.getCoordinateSet().get(c) for c in robot.joint_names]
    mus = [model.getMuscles().get(i) for i in range(len(ms))]
    for k in np.linspace(0, n - 1, 8).astype(int):
        for c, v in zip(coords, q[k]):
            c.setValue(state, float(v), False)
        for m, a in zip(mus, res.activations[k]):
            m.setActivation(state, float(a))
        model.equilibrateMuscles(state)
        model.realizeDynamics(state)
        tau = [
            0.5 * sum(m.computeMomentArm(state, c) * m.getTendonForce(state) for m in mus)
            for c in coords
        ]
        assert np.allclose(res.torque[k], tau, rtol=1e-6, atol=1e-5), (k, res.torque[k], tau)


def test_needed_torque_of_a_static_hold_is_gravity_and_the_weight():
    robot = aa.load(aa.osim.path("arm26"))
    t = np.linspace(0, 1, 20)
    q = np.tile([0.2, 1.1], (20, 1))
    need = me.needed_torques(robot, t, q, payload=3.0, frame="r_radius_styloid")
    J = robot.jacobian(q[0], "r_radius_styloid")[:3]
    g = robot.model.gravity.linear
    expected = robot.gravity(q[0]) - J.T @ (3.0 * g)
    assert np.abs(need - expected).max() < 1e-9


def test_bad_recordings(tmp_path):
    rec = me.read_recording()
    x = rec.emg.copy()
    x[0, 100] = np.nan
    with pytest.raises(EMGError, match="sample 100"):
        me.check_recording(rec.t, x)
    t = rec.t.copy()
    t[3000:] += 0.2
    with pytest.raises(EMGError, match="gap"):
        me.check_recording(t, rec.emg)
    with pytest.raises(EMGError, match="increase"):
        me.check_recording(rec.t[::-1], rec.emg)
    p = tmp_path / "holey.csv"
    p.write_text(
        "Time,EMG\n" + "".join(f"{k / 1000},{'' if k == 5 else 1e-5}\n" for k in range(20))
    )
    with pytest.raises(EMGError, match="not a number"):
        me.read_recording(p)
    with pytest.raises(EMGError, match="mvc"):
        me.excitation(rec.emg, rec.fs, mvc=1e-9)


@pytest.mark.parametrize("bad", [-0.2, 1.5, np.nan])
def test_activations_outside_the_unit_interval(bad):
    with pytest.raises(MuscleError):
        me.neural_activation(np.array([0.1, bad, 0.3]), 1000.0)
    with pytest.raises(MuscleError):
        me.activation_shape(np.array([bad]))
    robot, ms = aa.load(aa.osim.path("arm26")), read_muscles(aa.osim.path("arm26"))
    rec = me.read_recording()
    with pytest.raises(MuscleError):
        me.drive(robot, ms, rec, np.zeros(2), {"BIClong": 0}, rest=bad, wrap=False)


def test_plot_returns_a_figure():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    robot, ms = aa.load(aa.osim.path("arm26")), read_muscles(aa.osim.path("arm26"))
    rec = me.read_recording()
    res = me.drive(robot, ms, rec, np.array([0.0, 1.0]), {"BIClong": 0}, wrap=False)
    need = me.needed_torques(robot, rec.t, np.tile([0.0, 1.0], (rec.t.size, 1)), payload=1.0)
    fig = me.plot(res, need, "r_elbow_flex")
    assert len(fig.axes) == 2


def test_every_evaluates_a_subset_of_the_same_chain():
    robot, ms = aa.load(aa.osim.path("arm26")), read_muscles(aa.osim.path("arm26"))
    rec = me.read_recording()
    q = np.column_stack([np.zeros(rec.t.size), np.linspace(0.2, 1.6, rec.t.size)])
    full = me.drive(robot, ms, rec, q, {"BIClong": 0, "BICshort": 0}, wrap=False)
    sub = me.drive(robot, ms, rec, q, {"BIClong": 0, "BICshort": 0}, wrap=False, every=10)
    np.testing.assert_array_equal(sub.t, full.t[::10])
    np.testing.assert_allclose(sub.torque, full.torque[::10], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(sub.activation, full.activation[:, ::10])
    with pytest.raises(MuscleError, match="every"):
        me.drive(robot, ms, rec, q, {"BIClong": 0}, wrap=False, every=0)
