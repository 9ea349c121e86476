"""Via-point trajectories (§7-4 一): polynomials through via points, boundary conditions and
continuity, bad input, joint trajectories from poses.  Resolved-rate lines:
test_resolved_rate.py."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.trajectory import ViaPointTrajectory, joint_via_trajectory


@settings(max_examples=30, deadline=None)
@given(st.integers(3, 7), st.integers(0, 2**31 - 1))
def test_via_points_boundary_and_continuity(k, seed):
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.3, 2.0, k)) - 0.3
    Q = rng.uniform(-2, 2, (k, 3))
    tr = ViaPointTrajectory(times, Q)
    np.testing.assert_allclose(tr(times), Q, atol=1e-9)  # through every via point
    for end in (times[0], times[-1]):
        np.testing.assert_allclose(tr(end, 1), 0, atol=1e-8)  # zero velocity
        np.testing.assert_allclose(tr(end, 2), 0, atol=1e-7)  # zero acceleration
    h = 1e-7
    for tk in times[1:-1]:  # C²: left and right limits of q, q̇, q̈ agree at the via points
        for d in (0, 1, 2):
            np.testing.assert_allclose(
                tr(tk - h, d), tr(tk + h, d), atol=1e-4 * (1 + np.abs(tr(tk, d)).max())
            )
    # velocity is the derivative of position (finite differences)
    tm = 0.5 * (times[0] + times[1])
    np.testing.assert_allclose(tr(tm, 1), (tr(tm + 1e-6) - tr(tm - 1e-6)) / 2e-6, atol=1e-5)


def test_via_points_bad_input():
    with pytest.raises(ValueError):
        ViaPointTrajectory([0, 0, 1], np.zeros((3, 2)))
    with pytest.raises(ValueError):
        ViaPointTrajectory([0, 1], np.zeros((3, 2)))
    with pytest.raises(ValueError):
        ViaPointTrajectory([0, 1], [[0, np.nan], [1, 1]])
    tr = ViaPointTrajectory([0, 1, 2], [[0, 0], [1, 2], [0, 1]])
    with pytest.raises(ValueError, match="finite"):  # used to return NaN
        tr([0.5, np.nan])
    for d in (-1, 6, 1.5):
        with pytest.raises(ValueError, match="derivative"):
            tr(0.5, d)


def test_joint_via_trajectory_from_poses():
    robot = aa.load("prosthetic_arm")
    Qv = np.radians([[-60, 80, 0, 80, 0, 0], [-50, 85, 5, 70, 10, -10], [-40, 95, 0, 60, 5, 0]])
    poses = robot.fk(Qv)
    tr, Q = joint_via_trajectory(robot, poses, [0.0, 1.0, 2.5])
    np.testing.assert_allclose(robot.fk(tr(np.array([0.0, 1.0, 2.5]))), poses, atol=1e-9)
    T = np.eye(4)
    T[:3, 3] = [3, 0, 0]
    with pytest.raises(ValueError, match="via point 1"):
        joint_via_trajectory(robot, [poses[0], T], [0, 1])
