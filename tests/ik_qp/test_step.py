"""QP-IK step: agreement with pink and between backends, limits, robustness cases, book Newton
step."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import SolverNotAvailableError
from anthroarm.ik import qp

BACKENDS = ["osqp", "daqp", "quadprog", "proxqp"]


@pytest.fixture(scope="module")
def panda():
    return aa.load("panda")


@pytest.mark.parametrize("solver", BACKENDS)
def test_step_matches_pink(panda, solver):
    """Same tasks, same default limits (configuration gain 0.5 + velocity): same velocity."""
    import pink  # noqa: F401  (in the test extra: a missing pink must fail, not skip)
    from pink.tasks import FrameTask as PFT
    from pink.tasks import PostureTask as PPT

    rng = np.random.default_rng(11)
    q = panda.random_q(rng=rng, margin=0.05)
    conf = qp.IKConfiguration(panda, q)
    ee = qp.FrameTask(panda, lm_damping=1e-3)
    post = qp.PostureTask(panda, cost=1e-3, target=q)
    pee = PFT(panda.tool, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
    ppost = PPT(cost=1e-3)
    ppost.set_target(q)
    T0 = panda.fk(q)
    for k in range(25):
        T = T0.copy()
        T[:3, 3] += 0.08 * np.array([np.cos(0.3 * k) - 1, np.sin(0.3 * k), 0.02 * k])
        ee.set_target(T)
        pee.set_target(pin.SE3(T))
        v = qp.step(conf, None, [ee, post], 0.01, solver=solver)
        pc = pink.Configuration(panda.model, panda.model.createData(), conf.q)
        vp = pink.solve_ik(pc, [pee, ppost], 0.01, solver="quadprog")  # dense reference
        # the QP variable is Δq = v·dt: it must match the dense solution to 1e-9
        assert np.abs(v - vp).max() * 0.01 < 1e-9, (k, np.abs(v - vp).max())
        conf.integrate_inplace(v, 0.01)


def test_backends_agree_with_quadprog_on_random_qps():
    rng = np.random.default_rng(0)
    n = 7
    for n_eq in (0, 2):
        bs = {s: qp.make_backend(s, n, n_eq) for s in BACKENDS}
        for _ in range(150):
            J = rng.normal(size=(6, n))
            H = J.T @ J + 1e-3 * np.eye(n)
            c = rng.normal(size=n)
            lo, hi = -rng.random(n) * 0.5 - 0.05, rng.random(n) * 0.5 + 0.05
            A = rng.normal(size=(n_eq, n)) if n_eq else None
            b = (
                A @ (0.02 * rng.uniform(-1, 1, n)) if n_eq else None
            )  # feasible: a point inside the box
            xs = {s: be.solve(H, c, lo, hi, A, b) for s, be in bs.items()}
            ref = xs["quadprog"][0]
            for s, (x, status) in xs.items():
                assert status == "optimal", (s, status)
                assert np.abs(x - ref).max() < 1e-8, (s, np.abs(x - ref).max())
                assert np.all(x >= lo) and np.all(x <= hi)  # box respected exactly
                if n_eq:
                    assert np.abs(A @ x - b).max() < 1e-8


def test_osqp_workspace_is_built_once(panda, monkeypatch):
    """After the first step, no scipy.sparse matrix is built (peers.md §4.2: ~1 ms per step)."""
    import scipy.sparse as sp

    conf = qp.IKConfiguration(panda, panda.random_q(rng=1, margin=0.1))
    ee = qp.FrameTask(panda, target=panda.fk(panda.random_q(rng=2)), lm_damping=1e-3)
    qp.step(conf, None, [ee], 0.01, solver="osqp")
    backend = conf._qp_state["backends"][("osqp", 7, 0)]

    def boom(*a, **k):
        raise AssertionError("scipy.sparse matrix built during a step")

    monkeypatch.setattr(sp, "csc_matrix", boom)
    monkeypatch.setattr(sp, "csc_array", boom)
    for _ in range(20):
        v = qp.step(conf, None, [ee], 0.01, solver="osqp")
        conf.integrate_inplace(v, 0.01)
    assert conf._qp_state["backends"][("osqp", 7, 0)] is backend


@pytest.mark.parametrize("solver", BACKENDS)
def test_limits_never_violated_while_tracking(panda, solver):
    """A target that pulls joint 4 (upper limit −0.07 rad) past its limit: q stays inside,
    exactly."""
    q = panda.neutral()
    q[3] = -0.5
    conf = qp.IKConfiguration(panda, q)
    T = panda.fk(q)
    q_bad = q.copy()
    q_bad[3] = 0.6  # outside the limit: the pose is reachable only by violating it
    T = panda.fk(np.clip(q_bad, -10, 10)) if False else _fk_unclipped(panda, q_bad)
    ee = qp.FrameTask(panda, target=T, lm_damping=1e-3)
    for _ in range(150):
        out = qp.step(conf, None, [ee], 0.02, solver=solver, full=True)
        assert out.ok
        assert np.all(out.v * 0.02 >= out.lo - 1e-15) and np.all(out.v * 0.02 <= out.hi + 1e-15)
        conf.integrate_inplace(out.v, 0.02)
        assert panda.within_limits(conf.q), conf.limit_violations()
        assert np.all(np.abs(out.v) <= panda.velocity_limit * (1 + 1e-12))
    assert conf.q[3] > -0.0698 - 0.01  # it pressed against the limit


def _fk_unclipped(robot, q):
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    return d.oMf[robot.tool_id].homogeneous.copy()


def test_start_outside_limits_is_pulled_back(panda):
    """pink#206: pink's QP is infeasible (or raises) when q starts outside its limits.  Here the
    joint moves back toward its range at the full velocity limit, then stays inside."""
    q = panda.neutral()
    q[3] = 0.4  # upper limit is −0.0698 rad
    conf = qp.IKConfiguration(panda, q)
    ee = qp.FrameTask(panda, target=_fk_unclipped(panda, q), lm_damping=1e-3)
    dt = 0.01
    vmax = panda.velocity_limit[3]
    out = qp.step(conf, None, [ee], dt, full=True)
    assert out.status == "optimal"
    assert out.v[3] == pytest.approx(-vmax)  # full speed back toward the range
    inside_at = None
    for k in range(200):
        out = qp.step(conf, None, [ee], dt, full=True)
        assert out.ok
        conf.integrate_inplace(out.v, dt)
        if panda.within_limits(conf.q) and inside_at is None:
            inside_at = k
        if inside_at is not None:
            assert panda.within_limits(conf.q)
    assert inside_at is not None and inside_at < 40


def test_singular_target_steps_bounded_and_converge():
    """pink#59: near a singularity undamped Gauss–Newton jumps; with LM damping the steps stay
    bounded and the task still converges (planar 2R, target at the edge of the workspace)."""
    robot = aa.load("planar2r")
    target = np.array([0.0, 1.99999, 0.0])
    conf = qp.IKConfiguration(robot, np.array([0.4, 0.05]))
    task = qp.PositionTask(robot, cost=[0.0, 1.0, 1.0], lm_damping=1.0, target=target)
    steps = []
    for _ in range(400):
        v = qp.step(conf, None, [task], 1.0, limits=None, solver="daqp")
        steps.append(np.linalg.norm(v))
        conf.integrate_inplace(v, 1.0)
    err = np.linalg.norm(task.compute_error(conf))
    assert err < 1e-6
    assert max(steps) < 1.0
    # undamped from the same start: the first step is huge (ill-conditioned J)
    conf2 = qp.IKConfiguration(robot, np.array([0.4, 0.05]))
    t2 = qp.PositionTask(robot, cost=[0.0, 1.0, 1.0], lm_damping=0.0, target=target)
    v0 = qp.step(conf2, None, [t2], 1.0, limits=None, damping=0.0, solver="quadprog")
    assert np.linalg.norm(v0) > 5 * max(steps)


def test_unreachable_target_converges_to_closest_point():
    robot = aa.load("planar2r")
    conf = qp.IKConfiguration(robot, np.array([0.3, 0.4]))
    task = qp.PositionTask(robot, cost=[0.0, 1.0, 1.0], lm_damping=1.0, target=[0.0, 3.0, 0.0])
    for _ in range(300):
        v = qp.step(conf, None, [task], 1.0, limits=None, solver="osqp")
        assert np.linalg.norm(v) < 2.0
        conf.integrate_inplace(v, 1.0)
    assert np.linalg.norm(task.compute_error(conf)) == pytest.approx(
        1.0, abs=1e-4
    )  # reach 2 m, target 3 m


@pytest.mark.parametrize("solver", BACKENDS)
def test_infeasible_constraint_gives_status_and_zero_step(panda, solver):
    conf = qp.IKConfiguration(panda, panda.neutral())
    hard = qp.JointCouplingTask(
        panda, ["panda_joint1"], [1.0], offset=2.5
    )  # q1 = 2.5 now: too fast
    out = qp.step(
        conf, None, [qp.PostureTask(panda)], 0.01, solver=solver, constraints=[hard], full=True
    )
    assert out.status == "infeasible"
    assert np.all(out.v == 0.0)
    # a feasible equality holds exactly
    hard2 = qp.JointCouplingTask(
        panda, ["panda_joint1", "panda_joint3"], [1.0, -1.0], offset=conf.q[0] - conf.q[2]
    )
    out = qp.step(
        conf,
        None,
        [qp.FrameTask(panda, target=panda.fk(panda.random_q(rng=3)))],
        0.01,
        solver=solver,
        constraints=[hard2],
        full=True,
    )
    assert out.ok and abs(out.v[0] - out.v[2]) < 1e-8


def test_acceleration_limit(panda):
    conf = qp.IKConfiguration(panda, panda.neutral())
    acc = qp.AccelerationLimit(panda, a_max=2.0)
    lims = [qp.ConfigurationLimit(panda), qp.VelocityLimit(panda), acc]
    ee = qp.FrameTask(panda, target=panda.fk(panda.random_q(rng=4, margin=0.2)), lm_damping=1e-3)
    dt, v_prev = 0.01, np.zeros(7)
    for _ in range(100):
        v = qp.step(conf, None, [ee], dt, limits=lims)
        assert np.all(np.abs(v - v_prev) <= 2.0 * dt + 1e-12)
        v_prev = v
        conf.integrate_inplace(v, dt)


def test_book_newton_step_planar2r():
    """Ch. 7 Table 7.3 row (1) (feedback compensation, static target = Newton): one FrameTask-like
    position task with α = 1, no damping, no limits, dt = 1 gives Δq = J⁻¹δr.  From (0, π/6) to
    y* = 1, z* = 0: iterate 1 = (−2.000, 4.256) (notes E3; the book prints θ1 = −2.000), then
    quadratic convergence to (−π/3, 2π/3)."""
    robot = aa.load("planar2r")
    conf = qp.IKConfiguration(robot, np.array([0.0, np.pi / 6]))
    task = qp.PositionTask(robot, cost=[0.0, 1.0, 1.0], target=[0.0, 1.0, 0.0])
    its = []
    for _ in range(6):
        v = qp.step(conf, None, [task], 1.0, limits=None, damping=0.0, solver="quadprog")
        conf.integrate_inplace(v, 1.0)
        its.append(conf.q.copy())
    assert its[0][0] == pytest.approx(-2.000, abs=5e-4)  # book's printed θ1
    assert its[0][1] == pytest.approx(4.2556, abs=5e-4)  # Newton (notes E3)
    assert np.allclose(its[1], [-0.6724, 1.8415], atol=5e-4)
    assert np.allclose(its[-1], [-np.pi / 3, 2 * np.pi / 3], atol=1e-10)


def test_book_table_7_3_printed_theta2_is_not_the_newton_step():
    """The printed iterate-1 θ2 = 3.752 (Table 7.3 row (1), l.5649–5657) is not what the Newton
    step of the feedback-compensation method gives (4.256): documented, not reproduced."""
    robot = aa.load("planar2r")
    conf = qp.IKConfiguration(robot, np.array([0.0, np.pi / 6]))
    task = qp.PositionTask(robot, cost=[0.0, 1.0, 1.0], target=[0.0, 1.0, 0.0])
    v = qp.step(conf, None, [task], 1.0, limits=None, damping=0.0, solver="quadprog")
    printed_theta2 = 3.752
    assert abs(conf.integrate(v, 1.0)[1] - printed_theta2) > 0.5


def test_bad_input(panda):
    conf = qp.IKConfiguration(panda)
    with pytest.raises(SolverNotAvailableError, match="installed solvers: .*osqp"):
        qp.step(conf, None, [qp.PostureTask(panda)], 0.01, solver="no_such_solver")
    for dt in (0.0, -1.0, np.nan, "x"):
        with pytest.raises(ValueError, match="dt"):
            qp.step(conf, None, [qp.PostureTask(panda)], dt)
    with pytest.raises(ValueError, match="limits"):
        qp.step(conf, None, [qp.PostureTask(panda)], 0.01, limits="all")
    # the Robot form works and caches a configuration
    v = qp.step(panda, panda.neutral(), [qp.PostureTask(panda)], 0.01)
    assert v.shape == (7,) and np.all(np.isfinite(v))
    assert "osqp" in qp.available_solvers()


FINGER_URDF = """<?xml version="1.0"?>
<robot name="finger">
  <link name="base"/>
  <link name="l1"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="2"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.05 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="2"/></joint>
  <joint name="tipj" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.04 0 0"/>
    </joint>
</robot>
"""


def test_coupled_finger_joints_hold_as_constraints(tmp_path):
    """A two-joint finger whose joints move together (q2 = 0.5 q1 + 0.1, URDF <mimic> semantics):
    the coupling, passed as a hard constraint, holds exactly while the tip follows a target.
    (The file has no <mimic> tag, so the coupling is declared here.)"""
    path = tmp_path / "finger.urdf"
    path.write_text(FINGER_URDF)
    robot = aa.load(str(path), tool="tip")
    assert robot.joint_names == ["j1", "j2"]
    tasks = [qp.JointCouplingTask.mimic(robot, "j2", "j1", multiplier=0.5, offset=0.1)]
    q = np.array([0.2, 0.5 * 0.2 + 0.1])
    conf = qp.IKConfiguration(robot, q)
    target = np.array([0.06, 0.05, 0.0])
    pos = qp.PositionTask(robot, cost=[1.0, 1.0, 0.0], target=target)
    for _ in range(200):
        out = qp.step(conf, None, [pos], 0.05, constraints=tasks, full=True)
        assert out.ok
        conf.integrate_inplace(out.v, 0.05)
        assert abs(conf.q[1] - (0.5 * conf.q[0] + 0.1)) < 1e-9
    # the reachable point closest to the target on the coupled (1-DOF) curve
    assert np.linalg.norm(pos.compute_error(conf)[:2]) < 0.02
