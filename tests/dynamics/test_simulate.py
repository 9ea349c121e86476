"""Forward simulation: energy balance T + V + D − W, RK4 vs solve_ivp, Lagrange vs pin.aba."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.dynamics import simulate as S


def test_conservative_energy_rk4_and_solve_ivp():
    robot = aa.load("planar2r")
    r4 = S.simulate(robot, [0.3, -0.2], [0.0, 0.5], t_end=2.0, dt=1e-3)
    assert r4.status == "ok" and r4.energy_drift < 1e-8
    assert r4.dissipated[-1] == 0 and np.ptp(r4.T) > 1.0  # it really swings
    ivp = S.simulate(
        robot, [0.3, -0.2], [0.0, 0.5], t_end=2.0, dt=1e-2, method="DOP853", rtol=1e-11, atol=1e-11
    )
    assert ivp.energy_drift < 1e-7
    assert np.max(np.abs(ivp.q[-1] - r4.q[-1])) < 1e-6


def test_damped_balance_and_decay():
    robot = aa.load("prosthetic_arm")
    q0 = robot.neutral() + 0.3
    r = S.simulate(robot, q0, np.zeros(6), t_end=1.0, dt=1e-3, damping=0.05)
    assert r.energy_drift < 1e-8
    assert r.dissipated[-1] > 0 and np.all(np.diff(r.dissipated) >= 0)


def test_driven_balance_counts_work():
    robot = aa.load("planar2r")
    tau = lambda t, q, qd: np.array([np.sin(3 * t), 0.5])  # noqa: E731
    r = S.simulate(robot, [0.0, 0.0], [0.0, 0.0], t_end=1.0, dt=1e-3, tau=tau, damping=[0.1, 0.2])
    assert abs(r.work[-1]) > 1e-3 and r.energy_drift < 1e-8


@pytest.mark.parametrize("name", ["panda", "human_arm7"])
def test_lagrange_vs_pin_aba_integration(name):
    robot = aa.load(name)
    rng = np.random.default_rng(0)
    q0 = robot.random_q(rng=rng)
    cmp = S.compare_with_pinocchio(
        robot, q0, rng.standard_normal(robot.nv) * 0.5, t_end=0.2, dt=2e-3, damping=0.1
    )
    assert cmp["max_dq"] < 1e-10 and cmp["max_dqd"] < 1e-9


def test_bad_input():
    robot = aa.load("planar2r")
    with pytest.raises(ValueError, match="NaN"):
        S.simulate(robot, [np.nan, 0], [0, 0], 0.1)
    with pytest.raises(ValueError, match="damping"):
        S.simulate(robot, [0, 0], [0, 0], 0.1, damping=-1)
    with pytest.raises(ValueError, match="shape"):
        S.simulate(robot, [0, 0, 0], [0, 0], 0.1)
    for method in ("rk4", "RK45"):
        r = S.simulate(
            robot, [0, 0], [0, 0], 0.05, tau=lambda t, q, qd: np.array([np.nan, 0.0]), method=method
        )
        assert r.status.startswith("diverged") and np.all(np.isfinite(r.q))


def test_continuous_joints_simulate_like_pinocchio(tmp_path, monkeypatch):
    """kinova (3 continuous joints, nq = 9, nv = 6): q0 and the trajectory in the robot's layout,
    (cos, sin) pairs stay unit, and the generated code follows pin.aba with the same RK4."""
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path))
    robot = aa.load("kinova")
    rng = np.random.default_rng(7)
    q0, v0 = robot.random_q(rng=rng), rng.standard_normal(robot.nv)
    out = S.compare_with_pinocchio(robot, q0, v0, t_end=0.05, dt=1e-3, damping=0.1)
    a = out["lagrange"]
    assert a.q.shape == (51, robot.nq) and a.qd.shape == (51, robot.nv)
    robot.chain.check_unit(a.q)
    np.testing.assert_allclose(a.q[0], q0, atol=1e-15)
    assert out["max_dq"] < 1e-10 and out["max_dqd"] < 1e-9
    assert a.energy_drift < 1e-6
