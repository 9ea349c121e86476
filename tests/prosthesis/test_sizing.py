"""Actuator sizing against the motor equations written out here (Eq. (9-1) through a gearbox):

motor torque   τ_em = J_m i α + τ / (η i)   (motoring, τ ω ≥ 0),   η τ / i   (back-driven)
voltage        V = R τ_em / k_m + k_m i ω  ≤ V_nom                 (torque–speed line)
thermal        RMS(τ_em) ≤ τ_cont;  gearbox: max|τ| ≤ τ_max, RMS(τ) ≤ τ_cont,g;  speed i|ω| ≤ limit
"""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.dynamics.hand_model import minimum_jerk
from anthroarm.dynamics.loads import HeldObject
from anthroarm.errors import ActivityError
from anthroarm.prosthesis import catalogue as C
from anthroarm.prosthesis import envelope as E
from anthroarm.prosthesis import sizing as S


def _act(name, t, tau, qd=None, qdd=None):
    n = len(t)
    tau = np.asarray(tau, float).reshape(n, -1)
    z = np.zeros_like(tau)
    qd = z if qd is None else np.asarray(qd, float).reshape(n, -1)
    qdd = z if qdd is None else np.asarray(qdd, float).reshape(n, -1)
    return E.ActivityTorques(name, np.asarray(t, float), z, qd, qdd, tau, tau, tau * qd, ["j"])


def _catalogue(tmp_path, motors, gears):
    m = tmp_path / "m.csv"
    g = tmp_path / "g.csv"
    m.write_text(",".join(C.MOTOR_COLUMNS) + "\n" + "\n".join(motors) + "\n")
    g.write_text(",".join(C.GEARBOX_COLUMNS) + "\n" + "\n".join(gears) + "\n")
    return C.load(m, g)


def oracle(motor, gear, demands, scale):
    """Utilisations from the equations in the module docstring (SI)."""
    i, eta = gear.ratio, gear.efficiency
    u = dict(voltage=0.0, thermal=0.0, gear_peak=0.0, gear_rms=0.0, speed=0.0)
    for t, tau, w, a in demands:
        tau, w, a = scale * tau, scale * w, scale * a
        gear_t = np.where(tau * w >= 0, tau / (eta * i), eta * tau / i)
        tem = motor.J_m * i * a + gear_t
        V = motor.R * tem / motor.k_m + motor.k_m * i * w
        T = t[-1] - t[0]
        u["voltage"] = max(u["voltage"], np.max(np.abs(V)) / motor.V_nom)
        u["thermal"] = max(u["thermal"], np.sqrt(np.trapezoid(tem**2, t) / T) / motor.tau_cont)
        u["gear_peak"] = max(u["gear_peak"], np.max(np.abs(tau)) / gear.tau_max)
        u["gear_rms"] = max(u["gear_rms"], np.sqrt(np.trapezoid(tau**2, t) / T) / gear.tau_cont)
        u["speed"] = max(
            u["speed"], np.max(np.abs(w)) * i / min(motor.max_speed, gear.max_input_speed)
        )
    return u


def test_static_hold_picks_the_lightest_motor_within_its_thermal_limit(tmp_path):
    # hold 2 N m for 10 s; gear 20:1, eta 0.8 -> motor torque 2 * 1.2 / 16 = 0.15 N m with a 20 % margin
    cat = _catalogue(
        tmp_path,
        [
            "light,X,20,24,1.0,20,10,140,10000,100",  # tau_cont 0.14 N m < 0.15: thermal fails
            "medium,X,20,24,1.0,20,10,160,10000,150",  # 0.16 N m: fits
            "heavy,X,20,24,1.0,20,10,500,10000,400",
        ],
        ["G20,X,20,2,20,0.8,5,8,8000,50"],
    )
    t = np.linspace(0, 10, 11)
    env = E.envelope([_act("hold", t, np.full(11, 2.0))])
    res = S.size(env, cat, margin=0.2)
    js = res.joints[0]
    assert js.status == "ok" and js.choice.motor.name == "medium"
    assert res.drive_mass == pytest.approx(0.150 + 0.050)
    assert js.choice.utilisation["thermal"] == pytest.approx(0.15 / 0.16, rel=1e-12)
    # voltage: R tau_em / k_m = 1.0 * 0.15 / 0.02 = 7.5 V of 24 V
    assert js.choice.utilisation["voltage"] == pytest.approx(7.5 / 24, rel=1e-12)
    light = next(c for c in cat.combinations() if c[0].name == "light")
    assert (
        max(
            S._utilisation(
                *light, [(t, np.full(11, 2.0), np.zeros(11), np.zeros(11))], 1.2
            ).values()
        )
        > 1.0
    )


def test_no_pair_fits_gives_the_reason(tmp_path):
    cat = _catalogue(
        tmp_path, ["m,X,20,24,1.0,20,10,160,10000,150"], ["G,X,20,2,20,0.8,1,1.5,8000,50"]
    )
    t = np.linspace(0, 1, 11)
    tau = np.zeros(11)
    tau[5] = 2.0  # a short peak: RMS 0.6 N m
    env = E.envelope([_act("lift", t, tau)])
    res = S.size(env, cat, margin=0.0)
    js = res.joints[0]
    assert js.status == "none" and js.choice is None and res.unfit == ["j"]
    assert js.closest.limiting == "gear_peak"  # 2 N m > 1.5 N m intermittent
    assert "gearbox's intermittent output torque" in js.reason and "1.33x" in js.reason
    assert res.drive_mass == 0.0


def test_speed_and_backdriving(tmp_path):
    """A joint lowered at constant speed against gravity (τ > 0, ω < 0): back-driven, the motor
    needs η τ / i; the voltage is R η τ/(i k_m) − k_m i |ω|."""
    cat = _catalogue(
        tmp_path,
        ["m,X,20,24,1.0,20,10,500,10000,150"],
        ["G,X,20,2,20,0.8,5,8,8000,50", "G2,X,20,3,100,0.7,5,8,8000,60"],
    )
    t = np.linspace(0, 1, 21)
    a = _act("lower", t, np.full(21, 1.0), qd=np.full(21, -3.0))
    env = E.envelope([a])
    assert S.size(env, cat, 0.1).joints[0].status == "ok"
    demands = [(a.t, a.tau[:, 0], a.qd[:, 0], a.qdd[:, 0])]
    for m, g in cat.combinations():
        u = S._utilisation(m, g, demands, 1.1)
        ref = oracle(m, g, demands, 1.1)
        for k in S.CHECKS:
            assert u[k] == pytest.approx(ref[k], rel=1e-12, abs=1e-15), (g.name, k)
    # the 100:1 gear turns the motor at 330 rad/s = 3151 rpm (< 8000): fine; its speed check is 3.3*100/(8000 rpm)
    g2 = next(g for g in cat.gearboxes if g.name == "G2")
    assert S._utilisation(cat.motors[0], g2, demands, 1.1)["speed"] == pytest.approx(
        3.3 * 100 / (8000 * np.pi / 30)
    )


@pytest.fixture(scope="module")
def person_envelope():
    robot = aa.load("human_arm7", height=1.75, mass=70.0, sex="male")
    q0 = robot.neutral()
    acts = []
    for k, (dq, T) in enumerate(
        [((1.3, 0, 0, 1.2, 0, 0, 0), 1.2), ((0.6, -0.8, 0.4, 1.8, 0.8, 0, -0.5), 1.0)]
    ):
        t = np.linspace(0, T, 101)
        q, qd, qdd = minimum_jerk(q0, q0 + np.array(dq), T, t)
        acts.append(E.activity_torques(robot, f"a{k}", t, q, qd, qdd, HeldObject(0.5)))
    return robot, E.envelope(acts)


def test_person_sizing_is_feasible_and_lightest_by_the_motor_equations(person_envelope):
    robot, env = person_envelope
    cat = C.load()
    res = S.size(env, cat, margin=0.2)
    assert [js.joint for js in res.joints] == robot.joint_names
    for j, js in enumerate(res.joints):
        demands = [(a.t, a.tau[:, j], a.qd[:, j], a.qdd[:, j]) for a in env.activities]
        feasible = []
        for m, g in cat.combinations():
            u = oracle(m, g, demands, 1.2)
            if max(u.values()) <= 1.0:
                feasible.append((m.mass + g.mass, m.name, g.name))
        if js.status == "ok":
            assert feasible, js.joint
            assert js.choice.mass == pytest.approx(min(feasible)[0], abs=1e-12)
            ref = oracle(js.choice.motor, js.choice.gearbox, demands, 1.2)
            for k in S.CHECKS:
                assert js.choice.utilisation[k] == pytest.approx(ref[k], rel=1e-9, abs=1e-15)
        else:
            assert not feasible
    assert res.drive_mass == pytest.approx(sum(js.choice.mass for js in res.joints if js.choice))


def test_bad_margin(person_envelope):
    with pytest.raises(ActivityError, match="margin"):
        S.size(person_envelope[1], C.load(), margin=-0.1)
    with pytest.raises(ActivityError, match="margin"):
        S.size(person_envelope[1], C.load(), margin=float("nan"))


def test_a_pair_whose_equations_overflow_does_not_cover_the_joint(tmp_path):
    """A gearbox with absurd (but positive, finite, in-bound) ratio and efficiency: η i underflows
    to 0, so τ/(η i) is inf where τ ≠ 0 and NaN where τ = 0.  The pair must not cover the joint
    (inf, never NaN, which max() would skip, nor a ControlError from deep inside the motor model)."""
    cat = _catalogue(
        tmp_path, ["m,X,20,24,1.0,20,10,160,10000,150"], ["G,X,20,2,1e-300,1e-300,5,8,8000,50"]
    )
    t = np.linspace(0, 1, 11)
    tau = np.where(t > 0.5, 2.0, 0.0)
    env = E.envelope([_act("x", t, tau)])
    demands = [(a.t, a.tau[:, 0], a.qd[:, 0], a.qdd[:, 0]) for a in env.activities]
    u = S._utilisation(cat.motors[0], cat.gearboxes[0], demands, 1.0)
    assert (
        u["thermal"] == np.inf and u["voltage"] == np.inf and not np.isnan(list(u.values())).any()
    )
    js = S.size(env, cat, 0.0).joints[0]
    assert js.status == "none" and "infx" in js.reason
