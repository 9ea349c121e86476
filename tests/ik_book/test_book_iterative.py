"""The book's iterative methods (§7-4 二, §7-5, §7-6) and Table 7.3 (l. 5649-5657).

Expected values: Table 7.3 as printed (iterations the notes §4 E3 prove reproducible), the
exact answer (−π/3, 2π/3), Pinocchio FK/Jacobians, finite differences."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.ik.book_methods import (
    PoseTask,
    PositionTask,
    conjugate_direction,
    feedback_compensation,
    gradual_approach,
    newton,
    penalty_minimize,
    steepest_descent,
)
from anthroarm.ik.book_tables import (
    TABLE_7_3,
    TABLE_7_3_SOLUTION,
    TABLE_7_3_START,
    TABLE_7_3_TARGET,
)


@pytest.fixture(scope="module")
def planar():
    return aa.load("planar2r")


@pytest.fixture
def task(planar):
    return PositionTask(planar, TABLE_7_3_TARGET, rows=(1, 2))  # r = (y, z), Fig. 7-14


def _book(name):
    t1, t2 = TABLE_7_3[name]
    return np.array([t1, t2]).T  # (5, 2)


def test_table73_steepest_descent_iterations_1_2(task):
    res = steepest_descent(task, TABLE_7_3_START, tol=1e-8)
    np.testing.assert_allclose(res.iterates[1:3], _book("steepest_descent")[1:3], atol=2e-3)
    np.testing.assert_allclose(res.q, TABLE_7_3_SOLUTION, atol=1e-6)
    assert abs(res.steps[0] - 1 / (2 * 3.732)) < 1e-3  # ω1 = pᵀp / (2 pᵀJᵀJp) = 0.134 (7-82)


def test_table73_newton_first_iterate_and_convergence(task):
    res = newton(task, TABLE_7_3_START, tol=1e-12)
    assert abs(res.iterates[1, 0] - (-2.000)) < 5e-4
    np.testing.assert_allclose(res.q, TABLE_7_3_SOLUTION, atol=1e-12)
    # quadratic convergence: e_{k+1} ≤ C e_k² near the solution
    e = res.errors
    assert e[-2] < 1e-5 and e[-1] <= 10 * e[-2] ** 2 + 1e-15


def test_table73_printed_newton_theta2_is_not_newton(task):
    """The printed iteration-1 θ2 = 3.752 is not a Newton iterate: J⁻¹δr gives 4.256 (notes §4 E3)."""
    res = newton(task, TABLE_7_3_START)
    assert abs(res.iterates[1, 1] - 4.2556) < 1e-3
    assert abs(res.iterates[1, 1] - _book("feedback_compensation")[1, 1]) > 0.4


def test_table73_conjugate_direction_first_iterate(task):
    res = conjugate_direction(task, TABLE_7_3_START, tol=1e-8, restart=2)
    np.testing.assert_allclose(res.iterates[1], _book("conjugate_direction")[1], atol=2e-3)
    np.testing.assert_allclose(res.q, TABLE_7_3_SOLUTION, atol=1e-6)


@pytest.mark.xfail(
    strict=True,
    reason="book's implementation details unknown (notes §4 E3): Table 7.3 "
    "rows beyond the asserted iterates do not reproduce",
)
@pytest.mark.parametrize(
    "name,fn",
    [
        ("feedback_compensation", newton),
        ("steepest_descent", steepest_descent),
        ("conjugate_direction", conjugate_direction),
    ],
)
def test_table73_remaining_iterates(task, name, fn):
    res = fn(task, TABLE_7_3_START)
    np.testing.assert_allclose(res.iterates[:5], _book(name), atol=5e-3)


@pytest.mark.parametrize("start", [(-0.9, 1.9), (-1.2, 2.3), (-0.8, 1.6)])
def test_table73_near_start_ranking(task, start):
    """The book's conclusion from a near start: speed (1) Newton > (3) CG > (2) SD."""
    it = [f(task, start, tol=1e-6).iterations for f in (newton,)]
    it.append(conjugate_direction(task, start, tol=1e-6, restart=2).iterations)
    it.append(steepest_descent(task, start, tol=1e-6).iterations)
    assert it[0] < it[1] < it[2]


def test_fletcher_reeves_needs_restarts(task):
    assert (
        conjugate_direction(task, TABLE_7_3_START, tol=1e-6, restart=10**9).iterations
        > 5 * conjugate_direction(task, TABLE_7_3_START, tol=1e-6, restart=2).iterations
    )


def test_descent_survives_singular_start(task):
    """Straight arm (θ2 = 0): J is singular, Newton stops, steepest descent still converges."""
    assert newton(task, [0.3, 0.0]).status == "singular"
    res = steepest_descent(task, [0.3, 0.0], tol=1e-8)
    assert res.success


def test_newton_6r_full_pose():
    robot = aa.load("sixr_arm")
    rng = np.random.default_rng(4)
    q = robot.random_q(None, rng, margin=0.1)
    res = newton(PoseTask(robot, robot.fk(q)), q + 0.05 * rng.normal(size=6), tol=1e-12)
    assert res.success and np.abs(robot.fk(res.q) - robot.fk(q)).max() < 1e-11


# ---------------------------------------------------------------------------- tracking (Fig. 7-11)
def _circle(t, c=(1.0, 0.5), rad=0.3, w=1.0):
    y = c[0] + rad * np.cos(w * t), c[1] + rad * np.sin(w * t)
    yd = -rad * w * np.sin(w * t), rad * w * np.cos(w * t)
    ydd = -rad * w * w * np.cos(w * t), -rad * w * w * np.sin(w * t)
    return np.array(y), np.array(yd), np.array(ydd)


def _start(planar):
    from anthroarm.ik.closed_form import analytic

    r0, rd0, _ = _circle(0.0)
    q0 = analytic(planar, np.array([0.0, *r0])).solutions[0]
    task = PositionTask(planar, r0, rows=(1, 2))
    qd0 = np.linalg.solve(task.jacobian(q0), rd0)
    return task, q0, qd0


def test_jacobian_dot_matches_finite_differences(planar):
    task, q0, qd0 = _start(planar)
    h = 1e-6
    fd = (task.jacobian(q0 + h * qd0) - task.jacobian(q0 - h * qd0)) / (2 * h)
    np.testing.assert_allclose(task.jacobian_dot(q0, qd0), fd, atol=1e-8)


def test_feedback_compensation_tracks_within_eps(planar):
    task, q0, qd0 = _start(planar)
    res = feedback_compensation(task, _circle, q0, qd0, dt=0.02, num=300, eps=1e-9)
    assert res.success and res.err.max() <= 1e-9
    # open loop (no compensation): the drift grows
    drift = feedback_compensation(task, _circle, q0, qd0, dt=0.02, num=300, max_corrections=0)
    assert drift.err[-1] > 1e-4 and drift.err[-1] > 10 * drift.err[10]


def test_feedback_compensation_book_K_zero_predicts_worse(planar):
    """With the book's K ≡ 0 the predictor (7-52) is wrong at first order in Δt²: larger
    prediction errors and more corrections than with the true K = J̇."""
    task, q0, qd0 = _start(planar)
    exact = feedback_compensation(task, _circle, q0, qd0, dt=0.02, num=100, eps=1e-9)
    book = feedback_compensation(task, _circle, q0, qd0, dt=0.02, num=100, eps=1e-9, K="book_zero")
    assert book.err_predicted[1:].mean() > 3 * exact.err_predicted[1:].mean()
    assert book.corrections.sum() >= exact.corrections.sum()


# ---------------------------------------------------------------------------- penalty (7-84)-(7-86)
def test_penalty_redundant_arm_constraint():
    """human_arm7 (N = 7 > 6), one constraint g(q) = q_shoulder_rotation − 0.5 ≥ 0 violated at the
    start: the redundancy (swivel) lets FR reach the exact pose with the constraint satisfied
    (the analytic swivel family shows q3 ∈ [−37°, 84°] for this pose)."""
    robot = aa.load("human_arm7")
    q_goal = np.radians([30, -20, 10, 50, 0, 0, 0])
    task = PoseTask(robot, robot.fk(q_goal))
    g = [(lambda q: q[2] - 0.5, lambda q: np.eye(7)[2])]
    res = penalty_minimize(task, q_goal, g, mu=1e4, method="fr", max_iter=3000)
    assert res.success
    assert res.q[2] >= 0.5 - 1e-4
    assert np.abs(robot.fk(res.q) - robot.fk(q_goal)).max() < 1e-9


def test_penalty_violation_shrinks_with_mu():
    """An infeasible constraint (the elbow angle is fixed by the pose): the exterior penalty gives
    a violation that shrinks like 1/μ (7-85)."""
    robot = aa.load("human_arm7")
    q_goal = np.radians([30, -20, 10, 50, 0, 0, 0])
    task = PoseTask(robot, robot.fk(q_goal))
    g = [(lambda q: q[3] - 1.2, lambda q: np.eye(7)[3])]
    viol = []
    for mu in (1.0, 1e2, 1e4):
        res = penalty_minimize(task, q_goal, g, mu=mu, method="fr", max_iter=400)
        viol.append(max(0.0, 1.2 - res.q[3]))
    assert viol[0] > 30 * viol[1] > 900 * viol[2] and viol[2] < 1e-5
    cons = aa.ik.book_methods.joint_limit_constraints(robot)
    assert len(cons) == 14 and all(c(robot.neutral()) >= 0 for c, _ in cons)


def test_penalty_bad_args(planar):
    task = PositionTask(planar, [1.0, 0.0], rows=(1, 2))
    with pytest.raises(ValueError):
        penalty_minimize(task, [0, 0.5], [], method="bfgs")
    with pytest.raises(ValueError):
        newton(task, [np.nan, 0])
    with pytest.raises(ValueError, match="t_end"):  # t_end = inf used to raise OverflowError
        gradual_approach(task, [0, 0.5], t_end=np.inf)
    with pytest.raises(ValueError, match="dt"):
        feedback_compensation(task, _circle, [0, 0.5], [0, 0], dt=np.inf, num=3)


# ---------------------------------------------------------------------------- gradual approach
@pytest.mark.parametrize(
    "mu", [lambda t: 1 / (1 + t), lambda t: 1 / (1 + t * t), lambda t: 1 / (1 + t**3)]
)
def test_gradual_approach_straight_line(mu):
    """(7-38)/(7-49): error ≈ c μ(t); the path is straight (Fig. 7-9)."""
    robot = aa.load("prosthetic_arm")
    q0 = np.radians([-60, 80, 0, 80, 0, 0])
    x0 = robot.fk(q0)[:3, 3]
    target = x0 + np.array([0.05, -0.04, 0.03])
    task = PositionTask(robot, target)
    res = gradual_approach(task, q0, mu=mu, t_end=20.0, dt=0.02)
    c = target - x0
    np.testing.assert_allclose(res.err, np.outer([mu(t) for t in res.t], c), atol=2e-4)
    u = c / np.linalg.norm(c)
    off = (res.x - x0) - np.outer((res.x - x0) @ u, u)
    assert np.abs(off).max() < 2e-4  # straight to 0.2 mm over a 7 cm move
    assert np.linalg.norm(res.err[-1]) <= mu(20.0) * np.linalg.norm(c) + 2e-4
