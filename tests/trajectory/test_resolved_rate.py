"""Resolved-rate straight lines (§7-7): the open loop's first-order drift, the closed loop, the
book's Jacobian against Pinocchio's."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.trajectory import straight_line_move


@pytest.fixture(scope="module")
def move_setup():
    robot = aa.load("sixr_arm")
    q0 = np.radians([10, 30, 20, 15, 40, 10])
    T0 = robot.fk(q0)
    Tg = T0.copy()
    Tg[:3, 3] += [0.08, -0.05, 0.06]
    import pinocchio as pin

    Tg[:3, :3] = T0[:3, :3] @ pin.exp3(np.array([0.1, -0.2, 0.15]))
    return robot, q0, Tg


def test_resolved_rate_open_loop_drift_first_order(move_setup):
    """Open-loop Euler integration of (7-89)/(7-96): the end-pose drift shrinks ~linearly with
    Δt."""
    robot, q0, Tg = move_setup
    d1 = straight_line_move(robot, q0, Tg, 1.0, 0.02)
    d2 = straight_line_move(robot, q0, Tg, 1.0, 0.01)
    assert d1.final_pos_err > 1e-5  # the book's open loop drifts
    assert 1.5 < d1.final_pos_err / d2.final_pos_err < 2.6
    assert d2.line_deviation < d1.line_deviation


def test_resolved_rate_closed_loop(move_setup):
    robot, q0, Tg = move_setup
    open_ = straight_line_move(robot, q0, Tg, 1.0, 0.01)
    closed = straight_line_move(robot, q0, Tg, 1.0, 0.01, closed_loop=True, k=50.0)
    assert closed.final_pos_err < open_.final_pos_err / 10
    assert closed.line_deviation < open_.line_deviation
    assert closed.final_rot_err < 1e-3


def test_resolved_rate_book_jacobian_equals_pinocchio(move_setup):
    robot, q0, Tg = move_setup
    a = straight_line_move(robot, q0, Tg, 0.5, 0.05, jacobian="book")
    b = straight_line_move(robot, q0, Tg, 0.5, 0.05, jacobian="pinocchio")
    np.testing.assert_allclose(a.q, b.q, atol=1e-10)
    with pytest.raises(ValueError):
        straight_line_move(robot, q0, Tg, 0.5, 1.0)
