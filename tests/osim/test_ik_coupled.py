"""``aa.ik.solve`` and the QP layer on an OpenSim model with nonlinear couplings, in its
independent coordinates: gait2392 (23 coordinates; Pinocchio's 27 joints are φ(q), the knee
translations splines of the knee angle).  Every answer is checked with Pinocchio's own forward
kinematics on the full configuration φ(q) (``robot.coupling.full``, itself checked against
OpenSim in tests/osim/test_against_opensim.py), Jacobians against finite differences of it.
arm26 (no coupling) solves as any robot."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ParameterError, UnsupportedModelError
from anthroarm.ik import qp

FRAME = "calcn_r"


@pytest.fixture(scope="module")
def gait():
    return aa.load(aa.osim.path("gait2392"))


def pose(robot, q, frame=FRAME) -> pin.SE3:
    """Pinocchio's placement of ``frame`` at the full configuration φ(q)."""
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, robot.coupling.full(np.asarray(q, float)))
    return d.oMf[robot.model.getFrameId(frame)]


def errors(M: pin.SE3, T) -> tuple[float, float]:
    T = np.asarray(T)
    return (
        float(np.linalg.norm(M.translation - T[:3, 3])),
        float(np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3]))),
    )


def within(robot, q) -> bool:
    return bool(np.all(q >= robot.lower) and np.all(q <= robot.upper))


def test_solve_twenty_random_reachable_targets(gait):
    assert gait.coupling is not None and gait.nq == 23 and gait.model.nq == 27
    rng = np.random.default_rng(7)
    for _ in range(20):
        T = pose(gait, gait.random_q(rng=rng)).homogeneous
        r = aa.ik.solve(gait, T, frame=FRAME)
        assert r.success and r.status == "success", r.message
        assert r.q.shape == (23,) and within(gait, r.q)
        pe, re = errors(pose(gait, r.q), T)
        assert pe <= 1e-6 and re <= 1e-6
        assert abs(pe - r.pos_err) < 1e-12 and abs(re - r.rot_err) < 1e-12


def test_solve_on_a_model_with_a_coupler():
    """leg6dof9musc: a CoordinateCouplerConstraint makes one coordinate a function of another
    (coupling.dependent_steps); its 6 coordinates all move the toes."""
    leg = aa.load(aa.osim.path("leg6dof9musc"))
    assert leg.coupling.dependent_steps and leg.nq == 6
    rng = np.random.default_rng(2)
    for _ in range(5):
        T = pose(leg, leg.random_q(rng=rng), "toes_r").homogeneous
        r = aa.ik.solve(leg, T, frame="toes_r")
        assert r.success and within(leg, r.q)
        assert max(errors(pose(leg, r.q, "toes_r"), T)) <= 1e-6


def test_q0_rows_need_as_many_targets(gait):
    """As for any robot: an (N, nq) q0 is one seed per target, ValueError with one target."""
    qs = gait.random_q(2, rng=1)
    T = pose(gait, qs[0]).homogeneous
    with pytest.raises(ValueError, match="needs a batch of 2 targets"):
        aa.ik.solve(gait, T, q0=qs, frame=FRAME)


def test_solve_from_threads(gait):
    """One Robot solved for from two threads at once (each thread its own pin.Data)."""
    rng = np.random.default_rng(5)
    Ts = [pose(gait, gait.random_q(rng=rng)).homogeneous for _ in range(8)]
    with ThreadPoolExecutor(2) as ex:
        rs = list(ex.map(lambda T: aa.ik.solve(gait, T, frame=FRAME), Ts))
    for r, T in zip(rs, Ts):
        assert r.success and max(errors(pose(gait, r.q), T)) <= 1e-6


def test_off_path_coordinates_keep_q0_and_batches(gait):
    """Coordinates that do not move the foot keep the caller's values; a batch (position
    targets, warm-started) gives one answer per target in the coordinates."""
    rng = np.random.default_rng(3)
    Q = gait.random_q(4, rng=rng)
    P = np.array([pose(gait, q).translation for q in Q])
    q0 = gait.random_q(rng=rng)
    r = aa.ik.solve(gait, P[0], q0=q0, frame=FRAME)
    assert r.success and r.mode == "position"
    left = [gait.joint_names.index(n) for n in ("hip_flexion_l", "knee_angle_l", "lumbar_bending")]
    np.testing.assert_array_equal(r.q[left], q0[left])
    b = aa.ik.solve(gait, P, frame=FRAME, warm_start=True)
    assert b.q.shape == (4, 23) and b.success.all()
    for q, p in zip(b.q, P):
        assert within(gait, q)
        assert np.linalg.norm(pose(gait, q).translation - p) <= 1e-6


def test_posture_is_followed_in_the_null_space(gait):
    rng = np.random.default_rng(11)
    T = pose(gait, gait.random_q(rng=rng)).homogeneous
    ref = gait.default_q()
    free = aa.ik.solve(gait, T, q0=gait.random_q(rng=rng), frame=FRAME, posture=None)
    held = aa.ik.solve(gait, T, q0=free.q, frame=FRAME, posture=ref)
    assert free.success and held.success and within(gait, held.q)
    assert max(errors(pose(gait, held.q), T)) <= 1e-6
    assert np.linalg.norm(held.q - ref) < np.linalg.norm(free.q - ref)


def test_unreachable_target_and_bad_input(gait):
    T = np.eye(4)
    T[:3, 3] = [50.0, 0.0, 0.0]  # pelvis translations reach 5 m
    r = aa.ik.solve(gait, T, frame=FRAME, max_time=0.01)
    assert not r.success and r.status == "not_converged" and within(gait, r.q)
    assert np.isfinite(r.q).all() and r.pos_err > 40
    with pytest.raises(ParameterError, match="23"):
        aa.ik.solve(gait, T, q0=np.zeros(27), frame=FRAME)
    with pytest.raises(ParameterError, match="swivel"):
        aa.ik.solve(gait, T, frame=FRAME, swivel=0.3)
    with pytest.raises(ValueError, match="max_time"):
        aa.ik.solve(gait, T, frame=FRAME, max_time=float("nan"))
    assert not aa.ik.has_analytic(gait, FRAME)  # no closed form in the coordinates
    with pytest.raises(UnsupportedModelError, match="aa.ik.solve"):
        aa.ik.analytic(gait, pose(gait, gait.default_q()).homogeneous, frame=FRAME)


def test_configuration_is_in_the_coordinates(gait):
    """IKConfiguration: q, limits and Jacobians in the 23 coordinates; the frame Jacobian is the
    derivative of Pinocchio's FK at φ(q) (central differences, LOCAL_WORLD_ALIGNED)."""
    q = gait.random_q(rng=5, margin=0.05)
    conf = qp.IKConfiguration(gait, q)
    assert conf.nq == conf.nv == 23
    np.testing.assert_array_equal(conf.lower, gait.lower)
    fid = gait.frame_id(FRAME)
    J = conf.frame_jacobian(fid, pin.LOCAL_WORLD_ALIGNED)
    assert J.shape == (6, 23)
    M0 = pose(gait, q)
    h = 1e-6
    for k in range(23):
        dq = np.zeros(23)
        dq[k] = h
        Mp, Mm = pose(gait, q + dq), pose(gait, q - dq)
        v = (Mp.translation - Mm.translation) / (2 * h)
        w = pin.log3(Mp.rotation @ Mm.rotation.T) / (2 * h)
        np.testing.assert_allclose(J[:3, k], v, atol=1e-7)
        np.testing.assert_allclose(J[3:, k], w, atol=1e-7)
    np.testing.assert_allclose(conf.frame_placement(fid).homogeneous, M0.homogeneous, atol=1e-15)
    np.testing.assert_array_equal(conf.integrate(np.ones(23), 0.1), q + 0.1)


def test_marker_task_in_the_coordinates(gait):
    """MarkerTask: points on the right calcaneus and the left tibia; their Jacobian (6, 23)
    equals central differences of the points' positions by Pinocchio's FK at φ(q)."""
    chain = gait.chain
    joints = [chain.frame(gait.frame_id(b)).joint for b in (FRAME, "tibia_l")]
    local = np.array([[0.01, 0.02, 0.03], [0.0, -0.1, 0.02]])
    task = qp.MarkerTask(gait, joints, local)
    d = gait.model.createData()

    def points(q):
        pin.forwardKinematics(gait.model, d, gait.coupling.full(q))
        return np.concatenate([d.oMi[j + 1].act(x) for j, x in zip(joints, local)])

    q = gait.random_q(rng=3, margin=0.05)
    conf = qp.IKConfiguration(gait, q)
    J = task.compute_jacobian(conf)
    assert J.shape == (6, 23)
    np.testing.assert_allclose(task.positions(conf).ravel(), points(q), atol=1e-14)
    h = 1e-6
    for k in range(23):
        dq = np.zeros(23)
        dq[k] = h
        np.testing.assert_allclose(J[:, k], (points(q + dq) - points(q - dq)) / (2 * h), atol=1e-8)


def test_qp_drives_the_foot_within_the_coordinate_ranges(gait):
    """Frame task, configuration and velocity limits: the foot reaches the pose of a random
    in-range configuration; every step stays inside the ranges and under v_max.  A posture
    task alone brings the coordinates to its target (the middle of the ranges by default)."""
    conf = qp.IKConfiguration(gait, gait.default_q())
    T = pose(gait, gait.random_q(rng=21, margin=0.1)).homogeneous
    task = qp.FrameTask(gait, FRAME, 1.0, 1.0, lm_damping=1e-3, target=T)
    vmax = np.full(23, 3.0)
    limits = [qp.ConfigurationLimit(gait), qp.VelocityLimit(gait, v_max=vmax)]
    dt = 0.01
    for _ in range(150):
        v = qp.step(conf, None, [task], dt, limits=limits, solver="daqp")
        assert v.shape == (23,) and np.all(np.abs(v) <= vmax + 1e-9)
        conf.integrate_inplace(v, dt)
        assert conf.within_limits(1e-9), conf.limit_violations(1e-9)
    assert max(errors(pose(gait, conf.q), T)) < 1e-9
    post = qp.PostureTask(gait, cost=1.0)
    mid = 0.5 * (gait.lower + gait.upper)
    np.testing.assert_allclose(post.target, mid)
    for _ in range(100):
        conf.integrate_inplace(qp.step(conf, None, [post], dt, limits=limits), dt)
        assert conf.within_limits(1e-9)
    np.testing.assert_allclose(conf.q, mid, atol=1e-6)


def test_qp_range_binds_the_knee(gait):
    """Only the right knee free (the other coordinates' ranges pinned at the start): a foot
    pose that needs the knee at 0.5 rad, beyond its upper limit 0.1745 rad, stops the knee
    at the limit; the default limits of ``qp.step(robot, q, ...)`` are the coordinates' too."""
    i = gait.joint_names.index("knee_angle_r")
    q0 = gait.default_q()
    qt = q0.copy()
    qt[i] = 0.5
    lo, hi = q0.copy(), q0.copy()
    lo[i], hi[i] = gait.lower[i], gait.upper[i]
    conf = qp.IKConfiguration(gait, q0)
    task = qp.FrameTask(gait, FRAME, 1.0, 0.0, target=pose(gait, qt).homogeneous)
    lim = [qp.ConfigurationLimit(gait, lower=lo, upper=hi)]
    for _ in range(200):
        conf.integrate_inplace(qp.step(conf, None, [task], 0.02, limits=lim), 0.02)
    assert conf.q[i] <= gait.upper[i] + 1e-9 and conf.q[i] > gait.upper[i] - 1e-3
    np.testing.assert_allclose(np.delete(conf.q, i), np.delete(q0, i), atol=1e-9)
    v = qp.step(gait, gait.default_q(), [task], 0.01)
    assert v.shape == (23,) and np.isfinite(v).all()


def test_uncoupled_osim_model_still_solves():
    """arm26 has no coupling: its coordinates are Pinocchio's joints; the answer's pose is
    checked with Pinocchio's own FK."""
    arm = aa.load(aa.osim.path("arm26"))
    assert arm.coupling is None
    q = arm.random_q(rng=1)
    T = arm.fk(q, "r_ulna_radius_hand")
    r = aa.ik.solve(arm, T[:3, 3], frame="r_ulna_radius_hand", rng=0)
    assert r.success and r.q.shape == (2,)
    d = arm.model.createData()
    pin.framesForwardKinematics(arm.model, d, r.q)
    p = d.oMf[arm.model.getFrameId("r_ulna_radius_hand")].translation
    np.testing.assert_allclose(p, T[:3, 3], atol=1e-6)
    conf = qp.IKConfiguration(arm, q)
    assert conf.G is None and conf.nq == 2
