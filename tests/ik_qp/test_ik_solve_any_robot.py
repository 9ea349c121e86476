"""aa.ik.solve on robots it has never seen (example-robot-data arms, continuous and mimic
joints, trees), from several threads at once, and without keeping dropped Robots alive.

Oracles: Pinocchio's FK on a fresh ``pin.Data`` for every answer, the joint limits of the
model, the single-threaded answers (the solver is deterministic), ``weakref`` for the memory."""

import gc
import sys
import threading
import weakref
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.chain import CONTINUOUS

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "foundation"))
from test_chain import USER_URDF  # noqa: E402

UNSEEN = [
    ("panda", {}),
    ("ur5", {}),
    ("ur10", {}),
    ("xarm7", {}),
    ("z1", {}),
    ("so101", {"tool": "gripper_frame_link", "locked": ["gripper"]}),
    ("kinova", {}),
]


def judge(robot, q, T, frame=None):
    """(pos_err m, rot_err rad, inside the limits) by Pinocchio on a fresh Data."""
    m = robot.model
    d = m.createData()
    pin.framesForwardKinematics(m, d, q)
    M = d.oMf[m.getFrameId(frame or robot.tool)]
    inside = bool(np.all((q >= m.lowerPositionLimit) & (q <= m.upperPositionLimit)))
    return (
        np.linalg.norm(M.translation - T[:3, 3]),
        np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3])),
        inside,
    )


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


@pytest.mark.parametrize("name,kw", UNSEEN, ids=[n for n, _ in UNSEEN])
def test_unseen_robots_all_solved_inside_the_limits(name, kw):
    """100 random reachable poses (FK of uniform configurations): 100 % solved to 1e-6 m /
    1e-6 rad, no limit violated, judged by Pinocchio; the batch call gives the same answers'
    quality."""
    robot = aa.load(name, **kw)
    Q = robot.random_q(100, rng=2024)
    Ts = robot.fk(Q)
    for T in Ts:
        r = aa.ik.solve(robot, T)
        pe, re, inside = judge(robot, r.q, T)
        assert r.success and pe <= 1e-6 and re <= 1e-6 and inside, (name, r.message)
    out = aa.ik.solve(robot, Ts[:20])
    assert out.success.all()
    assert all(judge(robot, q, T)[2] for q, T in zip(out.q, Ts[:20]))


def test_kinova_continuous_joints_stay_near_the_seed():
    """kinova (3 continuous joints, nq = 9, nv = 6): from a seed near the goal the answer's
    continuous angles are the goal's up to the seed's side of ±π, i.e. within the small
    perturbation of the seed — no extra turn; the (cos, sin) pairs are unit vectors.  A seed
    whose continuous angles are the goal's + 2π·k is the same q: the answer is the goal."""
    robot = aa.load("kinova")
    ch = robot.chain
    cont = [j.index for j in ch.joints if j.kind == CONTINUOUS]
    rng = np.random.default_rng(5)
    for q_goal in robot.random_q(20, rng=6):
        T = robot.fk(q_goal)
        th = ch.angles(q_goal)[list(ch.independent)]
        th0 = th + rng.normal(0.0, 0.05, th.shape)
        r = aa.ik.solve(robot, T, q0=ch.configuration(np.clip(th0, *ch.sampling_box)))
        assert r.success
        ch.check_unit(r.q)
        d = ch.angles(r.q)[cont] - ch.angles(q_goal)[cont]
        d = (d + np.pi) % (2 * np.pi) - np.pi
        assert np.abs(d).max() < 0.3  # the nearby solution, not another turn or branch
        pe, re, inside = judge(robot, r.q, T)
        assert pe <= 1e-6 and re <= 1e-6 and inside


def test_baxter_tree_off_path_joints_keep_the_seed():
    """baxter, tool on the left gripper: the right arm, head and right gripper do not move the
    tool (zero Jacobian columns) and are returned at the caller's q0 values exactly."""
    robot = aa.load("baxter", tool="left_gripper")
    path_joints = {robot.chain.joints[i].name for i in robot.chain.path()}
    off = [k for k, n in enumerate(robot.chain.q_names) if n not in path_joints]
    assert len(off) >= 8
    q0 = robot.random_q(rng=1)
    for q in robot.random_q(15, rng=2):
        T = robot.fk(q)
        r = aa.ik.solve(robot, T, q0=q0)
        pe, re, inside = judge(robot, r.q, T)
        assert r.success and pe <= 1e-6 and re <= 1e-6 and inside
        np.testing.assert_array_equal(r.q[off], q0[off])


@pytest.mark.parametrize("kw", [{"tool": "l_gripper_r_finger_tip"}], ids=["mimic_finger"])
def test_baxter_tool_through_a_mimic_finger(kw):
    """The tool hangs on a mimic joint (r finger = −1 × l finger): Pinocchio's Jacobian column
    of the source carries it; 30 poses solved inside the limits."""
    robot = aa.load("baxter", **kw)
    for q in robot.random_q(30, rng=3):
        T = robot.fk(q)
        r = aa.ik.solve(robot, T)
        pe, re, inside = judge(robot, r.q, T)
        assert r.success and pe <= 1e-6 and re <= 1e-6 and inside, r.message


@pytest.mark.parametrize("tool", ["tool", "finger_b"])
def test_user_urdf_with_continuous_and_mimic_joints(user_urdf, tool):
    """The user URDF (continuous spin and wrist, a mimic finger): position and pose targets
    from its own configurations are solved inside the limits (tool on the mimic finger too)."""
    robot = aa.load(user_urdf, tool=tool)
    for q in robot.random_q(30, rng=4):
        T = robot.fk(q)
        r = aa.ik.solve(robot, T)
        pe, re, inside = judge(robot, r.q, T, tool)
        assert r.success and pe <= 1e-6 and re <= 1e-6 and inside, r.message
        rp = aa.ik.solve(robot, T[:3, 3])
        assert rp.success and judge(robot, rp.q, T, tool)[0] <= 1e-6


def test_four_threads_share_one_robot():
    """4 threads call ik.solve (each its own targets), fk and jacobian on one Robot at once: every
    answer equals the single-threaded one and passes Pinocchio's check."""
    robot = aa.load("panda")
    targets = [robot.fk(robot.random_q(40, rng=100 + t)) for t in range(4)]
    Qf = robot.random_q(40, rng=9)
    ref_ik = [[aa.ik.solve(robot, T).q for T in Ts] for Ts in targets]
    ref_fk = [robot.fk(q) for q in Qf]
    ref_J = [robot.jacobian(q) for q in Qf]
    errors = []
    barrier = threading.Barrier(4)

    def work(t):
        try:
            barrier.wait()
            for k, T in enumerate(targets[t]):
                r = aa.ik.solve(robot, T)
                pe, re, inside = judge(robot, r.q, T)
                if not (r.success and pe <= 1e-6 and re <= 1e-6 and inside):
                    errors.append(("ik check", t, k))
                if not np.array_equal(r.q, ref_ik[t][k]):
                    errors.append(("ik differs", t, k))
                j = (k + 10 * t) % len(Qf)
                if not np.array_equal(robot.fk(Qf[j]), ref_fk[j]) or not np.array_equal(
                    robot.jacobian(Qf[j]), ref_J[j]
                ):
                    errors.append(("fk/jacobian", t, k))
        except Exception as exc:  # noqa: BLE001 - reported by the assertion below
            errors.append(("raised", t, repr(exc)))

    threads = [threading.Thread(target=work, args=(t,)) for t in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors, errors[:5]


def test_dropped_robots_are_freed():
    """Robots dropped after ik.solve (single, batch and from another thread) are collected:
    the solver's per-robot cache holds them weakly and nothing in it refers to them."""
    refs = []
    for k in range(5):
        robot = aa.load("ur5")
        T = robot.fk(robot.random_q(rng=k))
        assert aa.ik.solve(robot, T).success
        assert aa.ik.solve(robot, np.stack([T] * 8)).success.all()
        th = threading.Thread(target=aa.ik.solve, args=(robot, T))
        th.start()
        th.join()
        refs.append(weakref.ref(robot))
        del robot
    gc.collect()
    assert all(r() is None for r in refs)


def test_theta_to_q_equals_the_chain(user_urdf):
    """The solver's θ → q map (plain floats) equals Chain.configuration, the one source of the
    (cos θ, sin θ) layout, on kinova and the user URDF; Chain.angles inverts it."""
    from anthroarm.ik.solve.workspace import workspace

    for robot in (aa.load("kinova"), aa.load(user_urdf, tool="tool")):
        ch = robot.chain
        sh = workspace(robot, robot.tool_id).sh
        Th = np.random.default_rng(8).uniform(-7.0, 7.0, (50, len(ch.independent)))
        for th in Th:
            np.testing.assert_allclose(sh.to_q(th), ch.configuration(th), rtol=0, atol=2e-16)
            back = sh.theta(sh.to_q(th))
            np.testing.assert_allclose(np.cos(back - th), 1.0, atol=1e-12)  # same angle up to turns


def test_first_call_is_not_charged_for_the_seed_table():
    """The seed table (~2000 FK evaluations, ~15 ms) is built before the budget's clock starts:
    a first call with a 1 ms budget still solves a reachable target (~0.1 ms of work)."""
    robot = aa.load("ur10")
    T = robot.fk(robot.random_q(rng=7))
    res = aa.ik.solve(robot, T, max_time=1e-3)
    assert res.success, res.message
    np.testing.assert_allclose(robot.fk(res.q), T, atol=1e-6)


@pytest.mark.parametrize("rng", ["abc", -1, 2.5, True, [1, 2]])
def test_bad_rng_is_refused_before_solving(rng):
    """A restart generator that cannot be built is a TypeError at the call, not later (or
    never, when the first seed converges)."""
    robot = aa.load("ur5")
    with pytest.raises(TypeError, match="rng"):
        aa.ik.solve(robot, robot.fk(robot.neutral()), rng=rng)
