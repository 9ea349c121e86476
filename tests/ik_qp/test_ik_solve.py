"""One-shot IK aa.ik.solve: success on reachable poses, limits, target kinds, batch, bad input,
unreachable targets, human-arm posture and swivel, property tests."""

import json

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.errors import UnknownFrameError
from anthroarm.ik import IKBatchResult, IKResult, qp
from anthroarm.ik import closed_form as cf
from anthroarm.ik.solve import seeds, targets, workspace

ROBOTS = ["panda", "ur5", "talos_arm", "human_arm7", "prosthetic_arm"]


@pytest.fixture(scope="module")
def robots():
    return {n: aa.load(n) for n in ROBOTS}


def pose_error(robot, q, T, frame=None):
    """Independent check with pin.framesForwardKinematics on a fresh Data."""
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    M = d.oMf[robot.frame_id(frame)]
    return np.linalg.norm(M.translation - T[:3, 3]), np.linalg.norm(
        pin.log3(M.rotation.T @ T[:3, :3])
    )


@pytest.mark.parametrize("name", ROBOTS)
def test_reachable_poses_are_solved_within_limits(robots, name):
    robot = robots[name]
    qs = robot.random_q(40, rng=123)
    for q_goal in qs:
        T = robot.fk(q_goal)
        res = aa.ik.solve(robot, T)
        assert isinstance(res, IKResult)
        assert res.success, res.message
        assert res.status == "success"
        assert robot.within_limits(res.q)  # exact, no tolerance
        pe, re = pose_error(robot, res.q, T)
        assert pe <= 1e-6 and re <= 1e-6
        assert res.pos_err == pytest.approx(pe, abs=1e-12) and res.rot_err == pytest.approx(
            re, abs=1e-12
        )


def test_position_and_orientation_targets(robots):
    robot = robots["panda"]
    for q_goal in robot.random_q(10, rng=5):
        T = robot.fk(q_goal)
        r1 = aa.ik.solve(robot, T[:3, 3])
        assert r1.success and r1.mode == "position" and robot.within_limits(r1.q)
        assert pose_error(robot, r1.q, T)[0] <= 1e-6
        r2 = aa.ik.solve(robot, T[:3, :3])
        assert r2.success and r2.mode == "orientation" and robot.within_limits(r2.q)
        assert pose_error(robot, r2.q, T)[1] <= 1e-6
        r3 = aa.ik.solve(robot, T, mode="position")
        assert r3.success and pose_error(robot, r3.q, T)[0] <= 1e-6


def test_batch_form_and_warm_start(robots):
    robot = robots["ur5"]
    qs = robot.random_q(12, rng=9)
    Ts = robot.fk(qs)
    out = aa.ik.solve(robot, Ts)
    assert isinstance(out, IKBatchResult) and len(out) == 12
    assert out.success.all() and out.q.shape == (12, 6)
    assert robot.within_limits(out.q).all()
    for i, r in enumerate(out):
        assert pose_error(robot, r.q, Ts[i])[0] <= 1e-6
    # a smooth path: warm start from the previous solution keeps consecutive solutions close
    path = robot.fk(qs[0] + np.linspace(0, 0.3, 15)[:, None] * np.ones(6))
    w = aa.ik.solve(robot, path, q0=None, warm_start=True)
    assert w.success.all()
    assert np.abs(np.diff(w.q, axis=0)).max() < 0.2
    pos = aa.ik.solve(robot, Ts[:, :3, 3])
    assert pos.mode == "position" and pos.success.all()
    q0s = aa.ik.solve(robot, Ts, q0=qs)  # per-target seeds at the answer: zero restarts
    assert q0s.success.all() and (q0s.restarts == 0).all()


def test_out_of_reach_target(robots):
    robot = robots["panda"]
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 0.5]
    res = aa.ik.solve(robot, T, max_time=0.02)
    assert not res.success and res.status == "out_of_reach"
    assert "reaches at most" in res.message and "closest pose" in res.message
    assert robot.within_limits(res.q)
    # the closest pose found is stretched toward the target: nearer than the seed
    seed_err = pose_error(robot, qp.comfortable_posture(robot), T)[0]
    assert res.pos_err < seed_err
    assert res.pos_err >= np.linalg.norm(T[:3, 3]) - 1.3  # panda reach is about 1.2 m
    assert json.loads(json.dumps(res.as_dict()))["status"] == "out_of_reach"


def test_not_converged_target_within_reach(robots):
    """Within the reach bound but not attainable inside the joint limits: the pose of a
    configuration with the shoulder rotated outside its range [−π, 0] (prosthetic arm; checked
    unattainable with a 0.3 s budget, 6000 restarts, during development).  Status
    not_converged, the closest pose found, within the limits, and the reason in the message."""
    robot = robots["prosthetic_arm"]
    q = 0.5 * (robot.lower + robot.upper)
    q[0] = 1.2
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    T = d.oMf[robot.tool_id].homogeneous.copy()
    res = aa.ik.solve(robot, T, max_time=0.01)
    assert not res.success and res.status == "not_converged"
    assert "joint-limited workspace" in res.message and "closest pose found" in res.message
    assert robot.within_limits(res.q)
    pe, re = pose_error(robot, res.q, T)
    assert res.pos_err == pytest.approx(pe, abs=1e-12) and res.rot_err == pytest.approx(
        re, abs=1e-12
    )
    assert pe > 1e-3
    # closest: better than the seed
    assert pe + re < sum(pose_error(robot, qp.comfortable_posture(robot), T))


def test_bad_input(robots):
    robot = robots["panda"]
    T = robot.fk(robot.neutral())
    bad = T.copy()
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match="finite"):
        aa.ik.solve(robot, bad)
    sk = T.copy()
    sk[:3, :3] *= 1.1
    with pytest.raises(ValueError, match="not a rotation"):
        aa.ik.solve(robot, sk)
    br = T.copy()
    br[3] = [0, 0, 1, 1]
    with pytest.raises(ValueError, match="not rigid"):
        aa.ik.solve(robot, br)
    with pytest.raises(ValueError, match="shape"):
        aa.ik.solve(robot, np.eye(5))
    with pytest.raises(UnknownFrameError, match="valid frames: .*panda_hand"):
        aa.ik.solve(robot, T, frame="hand_of_god")
    with pytest.raises(ValueError, match="panda_joint3"):
        aa.ik.solve(robot, T, q0=[0, 0, np.nan, -1, 0, 1, 0])
    with pytest.raises(ValueError, match="tol_pos"):
        aa.ik.solve(robot, T, tol_pos=-1)
    with pytest.raises(ValueError, match="max_time"):
        aa.ik.solve(robot, T, max_time=0)
    with pytest.raises(ValueError, match="mode"):
        aa.ik.solve(robot, T, mode="both")
    with pytest.raises(ValueError, match="is a position"):
        aa.ik.solve(robot, np.zeros(3), mode="orientation")


def test_q0_rows_need_as_many_targets(robots):
    """An (N, nq) q0 is one seed per target (the docstring): with one target, or a batch of
    another length, ValueError (the one check of both solvers, targets.check_q0)."""
    robot = robots["ur5"]
    qs = robot.random_q(3, rng=2)
    Ts = robot.fk(qs)
    with pytest.raises(ValueError, match="needs a batch of 3 targets"):
        aa.ik.solve(robot, Ts[0], q0=qs)
    with pytest.raises(ValueError, match="needs a batch of 3 targets"):
        aa.ik.solve(robot, Ts[:2], q0=qs)
    assert aa.ik.solve(robot, Ts, q0=qs).success.all()


def test_one_pose_fast_path_reads_as_the_general_parse():
    """targets.parse: a 4×4 float64 array (the fast path) gives the target that the same pose as
    nested lists gives (the general path), and a (1, 4, 4) array is a batch of that one pose."""
    R = pin.utils.rotate("z", 0.3) @ pin.utils.rotate("x", -1.1)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, [0.1, -0.2, 0.3]
    fast = targets.parse(T, None)
    assert fast[:2] == ("pose", False)
    for H in (targets.parse(T.tolist(), None)[2][0], targets.parse(T, "pose")[2][0]):
        assert np.array_equal(fast[2][0], H)
    mode, batch, (H,) = targets.parse(T[None], None)
    assert (mode, batch) == ("pose", True) and np.array_equal(H, T)
    assert targets.parse(T, "position")[2][0].tolist() == [0.1, -0.2, 0.3]


def test_seed_outside_limits_returns_within_limits(robots):
    robot = robots["panda"]
    T = robot.fk(robot.random_q(rng=3))
    q0 = robot.upper + 1.0
    res = aa.ik.solve(robot, T, q0=q0)
    assert res.success and robot.within_limits(res.q)


def test_other_frame(robots):
    robot = robots["panda"]
    q = robot.random_q(rng=8)
    T = robot.fk(q, "panda_link5")
    res = aa.ik.solve(robot, T, frame="panda_link5")
    assert res.success and pose_error(robot, res.q, T, "panda_link5")[0] <= 1e-6


def test_human_arm_posture_is_comfortable(robots):
    """With the posture objective the human arm lands closer to the comfortable posture than
    without it, on the same targets (the null-space pull keeps the hand pose exact)."""
    robot = robots["human_arm7"]
    ref = qp.comfortable_posture(robot)
    d_with, d_without = [], []
    for q_goal in robot.random_q(15, rng=21):
        T = robot.fk(q_goal)
        a = aa.ik.solve(robot, T)  # posture="auto" for human_arm7
        b = aa.ik.solve(robot, T, posture=None)
        assert a.success and b.success
        assert pose_error(robot, a.q, T)[0] <= 1e-6 and robot.within_limits(a.q)
        d_with.append(np.linalg.norm(a.q - ref))
        d_without.append(np.linalg.norm(b.q - ref))
    assert np.mean(d_with) < np.mean(d_without)
    assert np.sum(np.array(d_with) <= np.array(d_without) + 1e-9) >= 12


def test_human_arm_swivel(robots):
    robot = robots["human_arm7"]
    hits = 0
    for q_goal in robot.random_q(10, rng=2):
        if abs(np.sin(q_goal[3])) < 0.3:
            continue
        T = robot.fk(q_goal)
        phi_goal = qp.swivel_angle(robot, q_goal)  # a swivel angle known to be attainable
        res = aa.ik.solve(robot, T, swivel=phi_goal, q0=qp.comfortable_posture(robot))
        assert res.success and robot.within_limits(res.q)
        d = qp.swivel_angle(robot, res.q) - phi_goal
        if abs(np.arctan2(np.sin(d), np.cos(d))) < 1e-4:
            hits += 1
    assert hits >= 4


def test_analytic_seed_when_available(robots):
    robot = robots["prosthetic_arm"]
    assert cf.has_analytic(robot)
    T = robot.fk(robot.random_q(rng=4))
    res = aa.ik.solve(robot, T, analytic=True)
    assert res.success and res.seed == "analytic" and res.restarts == 0


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    name=st.sampled_from(ROBOTS),
    kind=st.sampled_from(["reach", "random"]),
)
def test_property_never_violates_limits(robots, seed, name, kind):
    """Random targets (reachable, or arbitrary poses that may be unreachable) and random seeds:
    every answer is within the limits, errors are reported honestly, no undocumented exception."""
    robot = robots[name]
    rng = np.random.default_rng(seed)
    if kind == "reach":
        T = robot.fk(robot.random_q(rng=rng))
    else:
        T = np.eye(4)
        T[:3, :3] = pin.exp3(rng.normal(size=3))
        T[:3, 3] = rng.uniform(-1.5, 1.5, 3)
    q0 = rng.uniform(robot.lower - 0.5, robot.upper + 0.5) if rng.random() < 0.5 else None
    res = aa.ik.solve(robot, T, q0=q0, max_time=0.01, rng=int(seed))
    assert robot.within_limits(res.q)
    pe, re = pose_error(robot, res.q, T)
    assert res.pos_err == pytest.approx(pe, abs=1e-9) and res.rot_err == pytest.approx(re, abs=1e-9)
    assert res.success == (pe <= 1e-6 and re <= 1e-6)
    assert res.status in ("success", "out_of_reach", "not_converged")


def test_human_posture_optimum_matches_closed_form_family(robots):
    """Oracle: the closed form parameterises every solution of a human_arm7 pose by the swivel
    angle; the posture objective must land on the member nearest the comfortable posture
    (up to the 0.5° grid of the scan)."""
    robot = robots["human_arm7"]
    assert cf.has_analytic(robot)
    ref = qp.comfortable_posture(robot)
    rng = np.random.default_rng(0)
    goals = np.clip(ref + rng.uniform(-0.6, 0.6, (6, 7)), robot.lower, robot.upper)
    grid = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    for g in goals:
        T = robot.fk(g)
        res = aa.ik.solve(robot, T)
        S = cf.analytic(robot, T, swivel=grid).solutions
        d_min = np.min(np.linalg.norm(S - ref, axis=1))
        d = np.linalg.norm(res.q - ref)
        assert res.success
        assert d <= d_min + 1e-6  # never worse than the best closed-form member found
        assert d >= d_min - 5e-3  # and within the grid resolution of it


# ------------------------------------------------------------------ seeds and fast paths of aa.ik.solve
def _target(robot, T):
    return targets.Target("pose", pin.SE3(T), 1e-6, 1e-6)


def _ws(robot):
    return workspace.workspace(robot, robot.tool_id)


def test_seed_table_distance_is_the_pose_distance(robots):
    """The table lookup x·G equals ‖p − p*‖² + w²‖R − R*‖²_F up to a constant (oracle: the
    distance computed directly from Pinocchio FK of the table's configurations)."""
    robot = robots["talos_arm"]
    ws = _ws(robot)
    Q = ws.table()[0][:200]
    H = robot.fk(Q)
    T = robot.fk(robot.random_q(rng=11))
    w2 = (seeds.SEED_ROT_WEIGHT * robot.chain.reach()) ** 2
    direct = ((H[:, :3, 3] - T[:3, 3]) ** 2).sum(1) + w2 * ((H[:, :3, :3] - T[:3, :3]) ** 2).sum(
        (1, 2)
    )
    sc = T.ravel().dot(ws.table()[1])[:200]
    np.testing.assert_allclose(sc - sc[0], direct - direct[0], atol=1e-9)


def test_aligned_seed_table_turns_first_and_last_joint_exactly(robots):
    """panda and ur5 (first and last joints spanning at least a half turn): a target made from a table entry
    with its first and last joints turned is matched by that entry, and the seed turned onto it
    is the target's configuration itself (oracle: FK of the configuration the target came from).
    talos_arm (wrist range 1.4 rad) has no aligned table."""
    for name in ("panda", "ur5"):
        robot = robots[name]
        ws = _ws(robot)
        al = ws.aligned()
        assert al is not None
        Q = ws.table()[0]
        for k, (d1, dn) in zip((5, 300, 1500), ((0.4, -0.7), (-1.1, 0.2), (0.05, 1.3))):
            q = Q[k].copy()
            q[al.iq1] += d1
            q[al.iqn] += dn
            if not robot.within_limits(q):
                continue
            T = robot.fk(q)
            table = seeds.TableSeeds(ws, _target(robot, T), None)
            q_seed = table.next()
            assert table.k0 == k
            np.testing.assert_allclose(q_seed, q, atol=1e-12)
            assert np.abs(robot.fk(q_seed) - T).max() < 1e-12
    assert _ws(robots["talos_arm"]).aligned() is None


def test_seed_tags_and_restart_cap(robots):
    """Seeds are tagged; max_restarts=0 tries exactly one seed, and the answer is still the
    closest pose found inside the limits (the closed-form seeds switched off: the table and
    restart seeds)."""
    robot = robots["panda"]
    tags = set()
    restarted = 0
    for q in robot.random_q(40, rng=31):
        r = aa.ik.solve(robot, robot.fk(q), analytic=False)
        assert r.success
        tags.add(r.seed)
        if r.restarts == 0:
            assert r.seed == "table"
        if r.seed == "restart":  # uniform random seeds come after the table's
            assert r.restarts >= seeds.TABLE_SEEDS
        restarted += r.restarts > 0
    assert tags <= {"table", "restart"} and "table" in tags and restarted > 0
    T = np.eye(4)
    T[:3, 3] = [2.0, 0.0, 0.3]  # out of reach
    r = aa.ik.solve(robot, T, max_restarts=0)
    assert not r.success and r.restarts == 0 and robot.within_limits(r.q)


def test_closed_form_first_where_cheap(robots):
    """Every arm with a closed form that costs about as much as a few Gauss–Newton iterations
    (a closed 6R class, an SRS arm's swivel grid, a 7-joint arm's held-joint grid: one compiled
    call) takes its first seed from it, verified by one FK (of the compiled closed-form call on a
    closed 6R class without a posture objective, else one Gauss–Newton evaluation); the arms
    without a closed form never do."""
    for name in ("prosthetic_arm", "ur5", "talos_arm", "panda", "human_arm7"):
        robot = robots[name]
        assert _ws(robot).sh.closed_form_first, name
        for q in robot.random_q(5, rng=41):
            T = robot.fk(q)
            r = aa.ik.solve(robot, T)
            assert r.success and r.seed == "analytic" and r.restarts == 0, name
            assert pose_error(robot, r.q, T)[0] <= 1e-6
    robot = robots["prosthetic_arm"]
    out = aa.ik.solve(robot, robot.fk(robot.random_q(12, rng=42)))  # batch: the same path
    assert out.success.all()
    r = aa.ik.solve(robot, robot.fk(robot.random_q(rng=43)), analytic=False)
    assert r.success and r.seed != "analytic"
    for name in ("rrprr5", "unimate5"):
        arm = aa.load(name)
        assert not cf.has_analytic(arm) and not _ws(arm).sh.closed_form_first


def test_human_posture_optimum_on_uniform_targets(robots, monkeypatch):
    """Targets from configurations uniform inside the limits (far from the comfortable
    posture): with the closed-form seeds (forced on, so that the test does not depend on a C
    compiler) the posture phase lands on the member of the closed-form family nearest the
    comfortable posture in at least 19 of 20 cases (oracle: 0.5° swivel scan of the closed
    form; the phase moves along one branch, and a joint limit can cut it).  The solver before
    the secant posture phase missed it in ~25 % of such targets."""
    robot = robots["human_arm7"]
    assert cf.has_analytic(robot)
    monkeypatch.setattr(_ws(robot).sh, "closed_form_first", True)
    ref = qp.comfortable_posture(robot)
    grid = np.linspace(-np.pi, np.pi, 720, endpoint=False)
    worse = at_limit = 0
    for g in robot.random_q(20, rng=1):
        T = robot.fk(g)
        res = aa.ik.solve(robot, T)
        assert res.success and robot.within_limits(res.q)
        assert pose_error(robot, res.q, T)[0] <= 1e-6
        S = cf.analytic(robot, T, swivel=grid).solutions
        d_min = np.min(np.linalg.norm(S - ref, axis=1))
        worse += np.linalg.norm(res.q - ref) > d_min + 1e-6
        at_limit += bool(((res.q == robot.lower) | (res.q == robot.upper)).any())
    assert worse <= 1
    assert (
        at_limit >= 2
    )  # the optimum on a joint limit (frozen joint, shortened null step) is exercised


def test_rigid_fast_path_and_near_rigid_targets(robots):
    """Exact poses, a rotation 1e-9 off orthonormal (re-orthonormalised), other dtypes and a
    pin.SE3 are solved; a non-rigid bottom row raises."""
    robot = robots["ur5"]
    T = robot.fk(robot.random_q(rng=61))
    near = T.copy()
    near[:3, :3] *= 1.0 + 1e-9
    r = aa.ik.solve(robot, near)
    assert r.success and pose_error(robot, r.q, T)[0] <= 1e-6
    assert aa.ik.solve(robot, pin.SE3(T)).success
    r = aa.ik.solve(robot, T.astype(np.float32), tol_pos=1e-5, tol_rot=1e-5)
    assert r.success and pose_error(robot, r.q, T)[0] <= 1e-5
    bad = T.copy()
    bad[3, 0] = 1e-3
    with pytest.raises(ValueError, match="not rigid"):
        aa.ik.solve(robot, bad)
