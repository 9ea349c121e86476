"""Master–slave servos of Fig. 9-17: equilibria against statics solved here, free-motion feel
against the quasi-static inertia/friction torque, and an identity between two types."""

import numpy as np
import pytest

from anthroarm.control import Bilateral, Wall
from anthroarm.errors import ControlError

T = np.linspace(0.0, 6.0, 1201)


def ramp(tt):
    """The operator pushes from 0 to 0.5 rad in 1 s and holds."""
    return np.minimum(tt, 1.0) * 0.5, np.where(tt < 1.0, 0.5, 0.0)


def statics(b: Bilateral, kind, theta_h, wall: Wall, load=0.0):
    """Rest of the equations of motion: unknowns θ1, θ2, τ_h (linear while in contact)."""
    # rows: hand τ_h = K_h(θh − θ1); slave K(θ1 − θ2) = load + K_e(θ2 − θw); master τ_h + τ_1 = 0
    A = np.zeros((3, 3))
    rhs = np.zeros(3)
    A[0] = [b.K_h, 0.0, 1.0]
    rhs[0] = b.K_h * theta_h
    A[1] = [b.K, -b.K - wall.K, 0.0]
    rhs[1] = load - wall.K * wall.theta
    tau_e = (
        np.array([0.0, wall.K, 0.0]),
        load - wall.K * wall.theta,
    )  # τ_e = K_e θ2 + (load − K_e θw)
    if kind == "symmetric":  # τ_1 = −K_m(θ1 − θ2)
        A[2] = [-b.K_master, b.K_master, 1.0]
    elif kind == "force_reflecting":  # τ_1 = −k_f K(θ1 − θ2)
        A[2] = [-b.k_f * b.K, b.k_f * b.K, 1.0]
    else:  # τ_1 = G(τ_h − k_f τ_e)
        A[2] = [0.0, -b.G * b.k_f * tau_e[0][1], 1.0 + b.G]
        rhs[2] = b.G * b.k_f * tau_e[1]
    th1, th2, tau_h = np.linalg.solve(A, rhs)
    return th1, th2, tau_h


@pytest.mark.parametrize("kind", ["symmetric", "force_reflecting", "force_feedback"])
def test_operator_feels_the_static_contact_torque(kind):
    b = Bilateral(K_master=25.0, k_f=0.4, G=15.0)
    wall = Wall(0.2, 50.0, 0.5)
    r = b.simulate(kind, T, ramp, wall=wall)
    th1, th2, tau_h = statics(b, kind, 0.5, wall)
    assert r.theta_m[-1] == pytest.approx(th1, abs=1e-7)
    assert r.theta_s[-1] == pytest.approx(th2, abs=1e-7)
    assert r.felt[-1] == pytest.approx(tau_h, abs=1e-6)
    assert r.felt[-1] == pytest.approx(float(b.static_feel(kind, r.tau_env[-1])), abs=1e-6)
    # the reaction is proportional to the load: a constant load adds (ratio) x load
    r2 = b.simulate(kind, T, ramp, wall=wall, load=1.5)
    assert r2.felt[-1] == pytest.approx(statics(b, kind, 0.5, wall, load=1.5)[2], abs=1e-6)


def test_symmetric_with_equal_gains_is_force_reflecting_with_unit_scale():
    b = Bilateral(k_f=1.0)
    a = b.simulate("symmetric", T, ramp, wall=Wall(0.2, 50.0))
    c = b.simulate("force_reflecting", T, ramp, wall=Wall(0.2, 50.0))
    assert np.allclose(a.felt, c.felt, atol=1e-6)


def test_free_motion_feel_inertia_and_friction():
    """Slow sinusoid, no contact: force-reflecting feels (J1 + k_f J2) θ̈ + (B1 + k_f B2) θ̇,
    force-feedback only (J1 θ̈ + B1 θ̇)/(1 + G) (the book: no inertial reaction unloaded)."""
    b = Bilateral(k_f=0.5, G=20.0)
    A, w = 0.3, 2.0

    def path(tt):
        return A * np.sin(w * tt), A * w * np.cos(w * tt)

    om, al = A * w * np.cos(w * T), -A * w * w * np.sin(w * T)
    late = T > 2.0
    fr = b.simulate("force_reflecting", T, path)
    pred = (b.J1 + b.k_f * b.J2) * al + (b.B1 + b.k_f * b.B2) * om
    assert np.max(np.abs(fr.felt[late] - pred[late])) < 0.03 * np.max(np.abs(pred))
    ff = b.simulate("force_feedback", T, path)
    pred_ff = (b.J1 * al + b.B1 * om) / (1 + b.G)
    assert np.max(np.abs(ff.felt[late] - pred_ff[late])) < 0.03 * np.max(np.abs(pred_ff))
    assert np.sqrt(np.mean(ff.felt[late] ** 2)) < 0.05 * np.sqrt(np.mean(fr.felt[late] ** 2))
    # the slave follows the master in every type
    for r in (fr, ff):
        assert np.max(np.abs(r.theta_s[late] - r.theta_m[late])) < 0.05 * A


def test_sampled_operator_path_and_bad_inputs():
    b = Bilateral()
    th = np.minimum(T, 1.0) * 0.5
    r = b.simulate("symmetric", T, th, wall=Wall(0.2, 50.0))
    assert r.felt[-1] == pytest.approx(statics(b, "symmetric", 0.5, Wall(0.2, 50.0))[2], abs=1e-5)
    with pytest.raises(ControlError, match="kind"):
        b.simulate("magic", T, th)
    with pytest.raises(ControlError):
        Bilateral(J1=0.0)
    with pytest.raises(ControlError):
        Wall(0.0, -1.0)
    with pytest.raises(ControlError):
        b.simulate("symmetric", T, th[:-1])


def test_exact_steps_agree_with_an_implicit_integrator():
    """Free motion (linear): the first-order-hold steps against scipy's Radau on the same ODE,
    written here from the module's equations."""
    from scipy.integrate import solve_ivp

    b = Bilateral(k_f=0.5, G=20.0)
    A, w = 0.3, 2.0
    t = np.linspace(0.0, 1.0, 201)

    def path(tt):
        return A * np.sin(w * tt), A * w * np.cos(w * tt)

    for kind in ("symmetric", "force_reflecting", "force_feedback"):

        def f(tt, x):
            th, wh = path(tt)
            tau_h = b.K_h * (th - x[0]) + b.B_h * (wh - x[1])
            e, de = x[0] - x[2], x[1] - x[3]
            tau_2 = b.K * e + b.D * de
            tau_1 = {
                "symmetric": -b.K_master * e - b.D_master * de,
                "force_reflecting": -b.k_f * tau_2,
                "force_feedback": b.G * tau_h,
            }[kind]
            return [x[1], (tau_h + tau_1 - b.B1 * x[1]) / b.J1, x[3], (tau_2 - b.B2 * x[3]) / b.J2]

        sol = solve_ivp(f, (0, 1.0), [0, 0, 0, 0], t_eval=t, method="Radau", rtol=1e-9, atol=1e-12)
        r = b.simulate(kind, t, path)
        assert np.allclose(r.theta_m, sol.y[0], atol=1e-6) and np.allclose(
            r.theta_s, sol.y[2], atol=1e-6
        )
