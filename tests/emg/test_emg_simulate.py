"""Closed loop: EMG -> codes -> servos (Eqs. (9-1)-(9-8)) -> the elbow and wrist of the
catalog's prosthetic arm (Pinocchio's aba) and the built-in one-DOF hand.

Oracles: Pinocchio's gravity torque with the servo's steady error, Eq. (9-8)
(K_s (theta_i - theta) = M_L at rest); the stalled servo's torque (9-1)/(9-3) against the
object's contact spring; the book's code/vibrator mapping for what moves when."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.emg import EMGProcessor, synthesize
from anthroarm.emg.simulate import HandModel, simulate_powered_hand
from anthroarm.errors import EMGError, ParameterError, UnknownFrameError
from anthroarm.viewer.pages import motion_viewer

FS = 2000.0
JOINTS = {"elbow": "elbow_flexion", "wrist": "forearm_rotation", "fingers": None}


@pytest.fixture(scope="module")
def arm():
    return aa.load("prosthetic_arm")


@pytest.fixture(scope="module")
def run(arm):
    # flex the elbow 0.2-0.9 s; co-contract at 1.3 s (-> wrist); extensor 1.8-2.2 s (supinate);
    # co-contract at 2.6 s (-> fingers); flexor 3.1-4.0 s (close on the object)
    bursts = [
        [(0.2, 0.7, 1), (1.3, 0.25, 1), (2.6, 0.25, 1), (3.1, 0.9, 1)],
        [(1.31, 0.25, 1), (1.8, 0.4, 1), (2.61, 0.25, 1)],
    ]
    rec = synthesize(4.6, FS, bursts, pp=100e-6, rng=11)
    return simulate_powered_hand(arm, rec.emg, FS, JOINTS)


def _window(res, a, b):
    return (res.t >= a) & (res.t <= b)


def test_codes_select_the_joints_the_book_says(run):
    assert run.status == "ok"
    assert run.modes == ("elbow", "wrist", "fingers")
    np.testing.assert_array_equal(run.trace.mode[_window(run, 0.0, 1.25)], 0)
    np.testing.assert_array_equal(run.trace.mode[_window(run, 1.6, 2.55)], 1)
    np.testing.assert_array_equal(run.trace.mode[_window(run, 2.9, 4.6)], 2)
    e, w, f = run.angle.T
    e0 = e[0]
    assert e[_window(run, 1.2, 1.25)].mean() > e0 + 0.5  # flexor 10 flexed the elbow
    assert np.ptp(w[_window(run, 0.0, 1.25)]) < 0.01  # the wrist held while the elbow moved
    assert w[_window(run, 2.4, 2.5)].mean() < w[0] - 0.4  # extensor 01 supinated the wrist
    assert np.ptp(e[_window(run, 2.0, 4.6)]) < 1e-3  # the elbow held after the switch
    assert np.ptp(e[run.t < 0.2]) < 1e-6  # at rest at q0 before any command
    assert np.all(f[run.t < 3.1] == 0.0)  # the hand stays open until its turn
    # the right vibrator announced the wrist, none the fingers, the middle one the grasp
    right = run.vibrators[:, 1]
    assert right[_window(run, 1.45, 1.6)].all() and not right[run.t > 2.6].any()
    assert not run.vibrators[:, 0].any()


def test_elbow_steady_error_equals_the_gravity_load_eq_9_8(run, arm):
    """At rest, K_s (theta_i - theta) = M_L: the gravity torque Pinocchio computes there."""
    k = np.flatnonzero(_window(run, 2.0, 2.5))[-1]
    srv = run.servos["elbow"]
    q = run.q[k]
    g = pin.computeGeneralizedGravity(arm.model, arm.data, q)[
        arm.chain.joint("elbow_flexion").idx_v
    ]
    err = run.setpoint[k, 0] - run.angle[k, 0]
    assert srv.Ks * err == pytest.approx(g, rel=2e-3)
    assert srv.estimate_load_torque(srv.k_p * err) == pytest.approx(g, rel=2e-3)


def test_hand_grasps_the_object_and_the_middle_vibrator_says_so(run):
    h = run.hand
    f = run.angle[:, 2]
    srv = run.servos["fingers"]
    hold = _window(run, 4.25, 4.6)
    assert run.grasped[hold].all() and run.vibrators[hold, 2].all()
    assert not run.grasped[run.t < 3.1].any()
    # stalled on the object: the saturated servo's torque eta i k_m V_max balances the contact spring
    stall = srv.eta * srv.i * srv.k_m * srv.V_max
    assert f[hold].mean() == pytest.approx(h.object_angle + stall / h.contact_stiffness, rel=1e-3)
    assert np.all(run.setpoint[:, 2] - f <= h.max_lead + 1e-9)  # anti-windup


def test_no_emg_keeps_the_arm_at_rest(arm):
    res = simulate_powered_hand(arm, np.zeros((2, int(1.0 * FS))), FS, JOINTS)
    assert np.all(res.trace.command == 0)
    np.testing.assert_allclose(res.q, np.repeat(res.q[:1], len(res.q), axis=0), atol=1e-6)
    g = pin.computeGeneralizedGravity(arm.model, arm.data, res.q[-1])[
        arm.chain.joint("elbow_flexion").idx_v
    ]
    assert res.servos["elbow"].Ks * (res.setpoint[-1, 0] - res.angle[-1, 0]) == pytest.approx(
        g, rel=2e-3
    )


def test_plot_and_viewer(run):
    fig = run.plot()
    assert len(fig.axes) == 5
    html = motion_viewer(run.robot, run.q, run.trace.frame_s, every=10).static_html()
    assert "set_animation" in html or "animation" in html


def test_bad_input(arm):
    x = np.zeros((2, 400))
    with pytest.raises(UnknownFrameError):
        simulate_powered_hand(arm, x, FS, {"elbow": "no_such_joint"})
    with pytest.raises(ParameterError):
        simulate_powered_hand(arm, x, FS, {})
    with pytest.raises(ParameterError):
        simulate_powered_hand(arm, x, FS, {"a": None, "b": None})
    with pytest.raises(ParameterError):
        simulate_powered_hand(arm, x, FS, JOINTS, speeds={"elbow": -1.0})
    x[0, 5] = np.nan
    with pytest.raises(EMGError, match="NaN"):
        simulate_powered_hand(arm, x, FS, JOINTS)
    with pytest.raises(EMGError):
        simulate_powered_hand(arm, np.zeros((3, 400)), FS, JOINTS)
    with pytest.raises(EMGError):
        simulate_powered_hand(arm, np.zeros((2, 400)), FS, JOINTS, processor=EMGProcessor(1000.0))
    with pytest.raises(EMGError, match="two control frames"):
        simulate_powered_hand(arm, np.zeros((2, 5)), FS, JOINTS)
    assert HandModel().contact_torque(0.5, 0.0) == 0.0


@pytest.mark.parametrize(
    "kw",
    [
        dict(J_L=0.0),
        dict(upper=-1.0),
        dict(object_angle=2.0),
        dict(contact_stiffness=-1.0),
        dict(max_lead=float("nan")),
        dict(J_L="heavy"),
    ],
)
def test_bad_hand_models(kw):
    with pytest.raises(ParameterError):
        HandModel(**kw)


def test_a_hand_model_of_the_catalog_moves_its_fingers_together():
    """human_upper_limb: the elbow (gear raised for its heavier forearm) and twelve finger joints
    driven by the fingers mode; every other joint stays where q0 put it."""
    r = aa.load("human_upper_limb", tool="index_tip")
    fingers = [
        f"{f}_{j}"
        for f in ("index", "middle", "ring", "little")
        for j in ("mcp_flexion", "pip", "dip")
    ]
    q0 = np.zeros(r.nq)
    for jt in r.chain.joints:
        q0[jt.idx_q] = np.clip(0.0, jt.lower, jt.upper)
    q0[r.chain.joint("elbow_flexion").idx_q] = 1.2
    bursts = [
        [(0.2, 0.25, 1), (0.9, 0.25, 1), (1.4, 0.25, 1), (1.9, 0.5, 1)],
        [(0.91, 0.25, 1), (1.41, 0.25, 1)],
    ]
    rec = synthesize(2.6, FS, bursts, pp=100e-6, rng=3)
    res = simulate_powered_hand(
        r,
        rec.emg,
        FS,
        {"elbow": "elbow_flexion", "wrist": "forearm_pronation", "fingers": fingers},
        q0=q0,
    )
    assert res.status == "ok" and res.hand is None
    assert sorted(res.joint_servos) == sorted(["elbow_flexion", "forearm_pronation", *fingers])
    e = res.angle[:, 0]
    assert e[-1] > 1.2 + 0.15  # flexed against its gravity load
    k = int(np.searchsorted(res.t, 1.85))  # at rest, before the fingers move
    g = pin.computeGeneralizedGravity(r.model, r.data, res.q[k])[
        r.chain.joint("elbow_flexion").idx_v
    ]
    assert res.servos["elbow"].Ks * (res.setpoint[k, 0] - e[k]) == pytest.approx(
        g, rel=2e-3
    )  # Eq. (9-8)
    fq = np.array([res.q[:, r.chain.joint(n).idx_q] for n in fingers])
    assert np.all(fq[:, res.t < 1.9] < 1e-3) and np.all(
        fq[:, -1] > 0.5
    )  # closed together, after their turn
    assert np.ptp(fq[:, -1]) < 0.05
    driven = {"elbow_flexion", "forearm_pronation", *fingers}
    still = [r.chain.joint(j.name).idx_q for j in r.chain.joints if j.name not in driven]
    np.testing.assert_array_equal(res.q[:, still], np.repeat(q0[None, still], len(res.q), axis=0))
    with pytest.raises(ParameterError, match="two modes"):
        simulate_powered_hand(
            r, rec.emg, FS, {"elbow": "elbow_flexion", "fingers": ["elbow_flexion"]}, q0=q0
        )
    with pytest.raises(ParameterError):
        simulate_powered_hand(r, rec.emg, FS, {"elbow": "elbow_flexion", "fingers": []}, q0=q0)
