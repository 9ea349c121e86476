"""QP-IK tasks: Jacobians against finite differences, objectives against pink, swivel geometry."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik import qp
from anthroarm.ik.qp.tasks.swivel import swivel_from_points


@pytest.fixture(scope="module")
def panda():
    return aa.load("panda")


@pytest.fixture(scope="module")
def human():
    return aa.load("human_arm7")


def fd_jacobian(robot, task, q, h=1e-6):
    """Central differences of task.compute_error along each tangent direction (pin.integrate)."""
    conf = qp.IKConfiguration(robot, q)
    m = len(task.compute_error(conf))
    J = np.zeros((m, robot.nv))
    for k in range(robot.nv):
        d = np.zeros(robot.nv)
        d[k] = h
        conf.update(pin.integrate(robot.model, q, d))
        ep = task.compute_error(conf)
        conf.update(pin.integrate(robot.model, q, -d))
        em = task.compute_error(conf)
        J[:, k] = (ep - em) / (2 * h)
    return J


def _tasks(robot, rng):
    qa, qb = robot.random_q(2, rng=rng)
    T = robot.fk(qb)
    frames = robot.frame_names
    ft = qp.FrameTask(robot, target=T)
    pt = qp.PositionTask(robot, target=T[:3, 3])
    ot = qp.OrientationTask(robot, target=T[:3, :3])
    root = robot.model.frames[robot.frame_id(frames[len(frames) // 2])].name
    rt = qp.RelativeFrameTask(robot, robot.tool, root)
    conf = qp.IKConfiguration(robot, qb)
    rt.set_target_from_configuration(conf)
    post = qp.PostureTask(robot, cost=0.3, target=qb)
    cp = qp.JointCouplingTask(robot, robot.joint_names[:2], [1.0, -2.0], offset=0.1)
    return qa, [ft, pt, ot, rt, post, cp]


@pytest.mark.parametrize("name", ["panda", "human_arm7", "ur5"])
def test_task_jacobians_match_finite_differences(name):
    robot = aa.load(name)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, tasks = _tasks(robot, rng)
        conf = qp.IKConfiguration(robot, q)
        for t in tasks:
            J = t.compute_jacobian(conf)
            Jfd = fd_jacobian(robot, t, q)
            assert np.abs(J - Jfd).max() < 1e-6, (t, np.abs(J - Jfd).max())


def test_swivel_jacobian_matches_finite_differences(human):
    rng = np.random.default_rng(0)
    task = qp.SwivelTask(human, target=0.3)
    n_checked = 0
    for q in human.random_q(10, rng=rng):
        if abs(np.sin(q[3])) < 0.2:  # near-straight elbow: swivel ill-defined
            continue
        conf = qp.IKConfiguration(human, q)
        J = task.compute_jacobian(conf)
        Jfd = fd_jacobian(human, task, q)
        assert np.abs(J - Jfd).max() < 1e-6
        n_checked += 1
    assert n_checked >= 3


@pytest.mark.parametrize(
    "name, expected",
    [
        ("human_arm7", ("shoulder_flexion", "elbow_flexion", "wrist_deviation")),
        ("human_right_arm", ("right_shoulder_Z", "right_elbow_Z", "right_wrist_Z")),
    ],
)
def test_swivel_frames_from_the_chain_geometry(name, expected):
    """The (shoulder, elbow, wrist) frames are found from the joint origins (Pinocchio's joint
    placements at q = 0: three co-located shoulder joints, then the elbow and wrist groups),
    not from the arm's name: a copy of the model under another name gives the same frames."""
    robot = aa.load(name)
    assert qp.tasks.swivel_frames(robot) == expected
    renamed = aa.load(robot.model.copy(), name="someone_else", tool=robot.tool)
    assert qp.tasks.swivel_frames(renamed) == expected
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, pin.neutral(robot.model))
    origin = {robot.model.names[i]: data.oMi[i].translation for i in range(1, robot.model.njoints)}
    S, E, W = (origin[n] for n in expected)
    assert min(np.linalg.norm(S - E), np.linalg.norm(E - W)) > 0.1


def test_swivel_frames_without_a_human_layout():
    """An offset elbow (panda) has no default: ValueError asking for frames=; explicit frames
    are accepted and checked."""
    panda = aa.load("panda")
    with pytest.raises(ValueError, match="frames="):
        qp.SwivelTask(panda)
    task = qp.SwivelTask(panda, frames=("panda_link1", "panda_link4", "panda_link7"))
    assert task.frame_ids == tuple(
        panda.frame_id(f) for f in ("panda_link1", "panda_link4", "panda_link7")
    )


def test_swivel_angle_geometry():
    """Rotating the elbow about the shoulder-wrist axis by a known angle changes φ by that angle
    (Rodrigues rotation as the oracle); φ = 0 when the elbow is straight below the axis."""
    S = np.array([0.1, -0.2, 0.3])
    W = S + np.array([0.2, 0.4, -0.3])
    u = (W - S) / np.linalg.norm(W - S)
    down = np.array([0.0, 0.0, -1.0])
    perp = down - (down @ u) * u
    perp /= np.linalg.norm(perp)
    E0 = S + 0.5 * (W - S) + 0.12 * perp  # elbow as low as possible: φ = 0
    assert abs(swivel_from_points(S, E0, W)[0]) < 1e-12
    for ang in np.linspace(-3.0, 3.0, 13):
        R = pin.exp3(u * ang)
        E = S + R @ (E0 - S)
        assert abs(swivel_from_points(S, E, W)[0] - ang) < 1e-12
    # gradients vs finite differences of the point function
    rng = np.random.default_rng(1)
    for _ in range(5):
        P = rng.normal(size=(3, 3))
        phi, grads = swivel_from_points(*P)
        for k in range(3):
            for a in range(3):
                d = np.zeros((3, 3))
                d[k, a] = 1e-6
                fd = (swivel_from_points(*(P + d))[0] - swivel_from_points(*(P - d))[0]) / 2e-6
                assert abs(fd - grads[k][a]) < 1e-6
    with pytest.raises(ValueError, match="straight arm"):
        swivel_from_points(S, S + 0.5 * (W - S), W)


def test_swivel_angle_batch_and_straight_elbow(human):
    """The batched call equals the one-configuration call, which equals swivel_from_points of
    Pinocchio's frame positions; a straight elbow (undefined by the points) gets the elbow-axis
    convention of the closed form: analytic(FK(q), swivel=φ(q)) contains q (round trip)."""
    Q = human.random_q(20, rng=5)
    phis = qp.swivel_angle(human, Q)
    frames = qp.tasks.swivel_frames(human)
    for q, phi in zip(Q, phis):
        P = [human.fk(q, f)[:3, 3] for f in frames]
        assert abs(np.angle(np.exp(1j * (phi - swivel_from_points(*P)[0])))) < 1e-12
        assert qp.swivel_angle(human, q) == pytest.approx(phi, abs=1e-12)
    q = human.random_q(rng=3)
    q[human.joint_names.index("elbow_flexion")] = 0.0  # straight elbow
    with pytest.raises(ValueError, match="straight arm"):
        swivel_from_points(*[human.fk(q, f)[:3, 3] for f in frames])
    phi = qp.swivel_angle(human, q)
    sols = aa.ik.analytic(human, human.fk(q), swivel=phi).solutions
    assert np.min(np.abs(np.angle(np.exp(1j * (sols - q)))).max(axis=1)) < 1e-9


def test_frame_and_posture_objectives_match_pink(panda):
    import pink  # noqa: F401  (in the test extra: a missing pink must fail, not skip)
    from pink.tasks import FrameTask as PFT
    from pink.tasks import PostureTask as PPT

    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qt = panda.random_q(2, rng=rng)
        T = panda.fk(qt)
        conf = qp.IKConfiguration(panda, q)
        pc = pink.Configuration(panda.model, panda.model.createData(), q)
        ours = qp.FrameTask(
            panda,
            position_cost=[1.0, 0.5, 2.0],
            orientation_cost=0.3,
            lm_damping=1e-2,
            gain=0.7,
            target=T,
        )
        theirs = PFT(
            panda.tool,
            position_cost=[1.0, 0.5, 2.0],
            orientation_cost=0.3,
            lm_damping=1e-2,
            gain=0.7,
        )
        theirs.set_target(pin.SE3(T))
        for a, b in [(ours.compute_qp_objective(conf), theirs.compute_qp_objective(pc))]:
            assert np.abs(a[0] - b[0]).max() < 1e-12 and np.abs(a[1] - b[1]).max() < 1e-12
        pp = PPT(cost=1e-2)
        pp.set_target(qt)
        a, b = (
            qp.PostureTask(panda, cost=1e-2, target=qt).compute_qp_objective(conf),
            pp.compute_qp_objective(pc),
        )
        assert np.abs(a[0] - b[0]).max() < 1e-15 and np.abs(a[1] - b[1]).max() < 1e-15


def test_comfortable_posture(human, panda):
    q = qp.comfortable_posture(human)
    assert human.within_limits(q)
    assert q[human.joint_names.index("elbow_flexion")] == pytest.approx(np.deg2rad(80))
    # hand in front of the body and below the shoulder, elbow bent: a relaxed posture
    p = human.fk(q)[:3, 3]
    assert p[1] > 0.1 and p[2] < -0.1
    mid = qp.comfortable_posture(panda)
    assert np.allclose(mid, 0.5 * (panda.lower + panda.upper))
    # the posture comes from the model (spec.comfort), not from the robot's name
    assert qp.tasks.has_comfortable_posture(human) and not qp.tasks.has_comfortable_posture(panda)
    renamed = aa.load(aa.models.urdf_path("human_arm7"))  # same joints, no spec
    assert not qp.tasks.has_comfortable_posture(renamed)
    np.testing.assert_allclose(
        qp.comfortable_posture(renamed), 0.5 * (renamed.lower + renamed.upper)
    )


def test_mimic_coupling_task(panda):
    c = qp.JointCouplingTask.mimic(
        panda, "panda_joint2", "panda_joint1", multiplier=2.0, offset=0.1
    )
    q = panda.neutral()
    q[0], q[1] = 0.3, 0.7
    conf = qp.IKConfiguration(panda, q)
    assert c.compute_error(conf)[0] == pytest.approx(0.7 - 2.0 * 0.3 - 0.1)
    with pytest.raises(ValueError, match="unknown joint"):
        qp.JointCouplingTask(panda, ["nope"], [1.0])


def test_task_bad_input(panda):
    with pytest.raises(ValueError, match="gain"):
        qp.FrameTask(panda, gain=2.0)
    with pytest.raises(ValueError, match="cost"):
        qp.PostureTask(panda, cost=np.nan)
    for bad in (np.nan, np.inf, -1e-3):  # a NaN damping used to be accepted and poisoned H
        with pytest.raises(ValueError, match="lm_damping"):
            qp.FrameTask(panda, lm_damping=bad)
    with pytest.raises(ValueError, match="gain"):
        qp.PositionTask(panda, gain=np.nan)
    t = qp.FrameTask(panda)
    with pytest.raises(ValueError, match="no target"):
        t.compute_error(qp.IKConfiguration(panda))
    T = np.eye(4)
    T[0, 0] = 2.0
    with pytest.raises(ValueError, match="not a rotation"):
        t.set_target(T)
    T = np.eye(4)
    T[1, 3] = np.nan
    with pytest.raises(ValueError, match="finite"):
        t.set_target(T)
    with pytest.raises(aa.errors.UnknownFrameError, match="valid frames"):
        qp.FrameTask(panda, frame="no_such_frame")
    with pytest.raises(ValueError, match="shape"):
        qp.IKConfiguration(panda, np.zeros(3))
    with pytest.raises(ValueError, match="panda_joint2"):
        qp.IKConfiguration(panda, [0, np.nan, 0, -1, 0, 1, 0])
