"""Compiled closed-form IK of the SRS 7R arm (swivel parameter) and the planar 2R arm read from
the chain's geometry (anthroarm.ik.families): human_arm7, planar2r and random user SRS arms
written here as URDFs (a general shoulder route and the SP2 route).

Oracles: Pinocchio FK of every returned exact branch inside the limits (FK(IK(T)) = T to
1e-9), the joint values the pose was made from (among the branches to 1e-9), and
``swivel_angle`` of the returned solutions (= the swivel asked for)."""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik import families as F
from anthroarm.ik.qp.tasks.swivel import swivel_angle

PI = np.pi


def _wrapdiff(a, b):
    return np.abs(np.angle(np.exp(1j * (a - b))))


def _pin_pose(r, theta):
    q = r.chain.configuration(theta)
    pin.framesForwardKinematics(r.model, r.data, q)
    return r.data.oMf[r.tool_id].homogeneous.copy()


def _poses(r, n, seed):
    rng = np.random.default_rng(seed)
    Q = r.random_q(n, rng)
    T = np.empty((n, 4, 4))
    for i, q in enumerate(Q):
        pin.framesForwardKinematics(r.model, r.data, q)
        T[i] = r.data.oMf[r.tool_id].homogeneous
    return Q, T


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def srs_urdf(tmp_path, name, seed, along=False):
    """A random user SRS arm: three shoulder joints at S, an elbow joint at E, three wrist
    joints at W (random axes, no two consecutive parallel), a tool with a random offset and
    orientation, limits ±π.  ``along``: the third shoulder axis along the upper arm (the SP2
    route)."""
    r = np.random.default_rng(seed)
    S = r.uniform(-0.2, 0.2, 3)
    up = r.uniform(-1, 1, 3)
    up = _unit(up) * r.uniform(0.2, 0.4)
    axes = [_unit(r.normal(size=3)) for _ in range(7)]
    if along:
        axes[2] = _unit(up)
    axes[3] = _unit(np.cross(up, r.normal(size=3)))  # an elbow that bends the arm
    fore = _unit(r.normal(size=3)) * r.uniform(0.2, 0.4)
    offs = [S, np.zeros(3), np.zeros(3), up, fore, np.zeros(3), np.zeros(3)]
    links = "".join(f'<link name="l{i}"/>' for i in range(8)) + '<link name="tool"/>'
    js = []
    for i in range(7):
        xyz = " ".join(f"{float(x)!r}" for x in offs[i])
        ax = " ".join(f"{float(x)!r}" for x in axes[i])
        js.append(
            f'<joint name="j{i + 1}" type="revolute"><origin xyz="{xyz}" rpy="0 0 0"/>'
            f'<parent link="l{i}"/><child link="l{i + 1}"/><axis xyz="{ax}"/>'
            f'<limit lower="{-PI!r}" upper="{PI!r}" effort="10" velocity="1"/></joint>'
        )
    txyz = " ".join(f"{float(x)!r}" for x in r.uniform(-0.1, 0.1, 3))
    trpy = " ".join(f"{float(x)!r}" for x in r.uniform(-1, 1, 3))
    js.append(
        f'<joint name="jt" type="fixed"><origin xyz="{txyz}" rpy="{trpy}"/>'
        '<parent link="l7"/><child link="tool"/></joint>'
    )
    path = tmp_path / f"{name}.urdf"
    path.write_text(
        f'<?xml version="1.0"?><robot name="{name}"><link name="base"/>'
        '<joint name="j0" type="fixed"><parent link="base"/><child link="l0"/></joint>'
        f"{links}{''.join(js)}</robot>"
    )
    return aa.load(str(path))


def _check_srs(r, n=60, seed=0, route=None):
    plan = F.srs_plan(r)
    assert plan is not None, F.srs_reason(r)
    if route is not None:
        assert F.SRS_ROUTES[plan.route] == route
    Q, T = _poses(r, n, seed)
    phi = swivel_angle(r, Q)
    th, cand, exact, inside, res, _ = F.srs_verified(plan, T, phi[:, None])
    assert th.shape == (n, 8, 7) and cand.shape == exact.shape == inside.shape == res.shape == (
        n,
        8,
    )
    # the sampled configuration is among the branches
    theta = r.chain.angles(Q)
    d = np.nanmin(_wrapdiff(th, theta[:, None, :]).max(-1), 1)
    assert d.max() < 1e-9
    # every exact branch inside the limits reaches the pose (Pinocchio) and the residual says so
    ok = exact & inside
    assert ok.any(1).all()
    assert res[ok].max() < 1e-9
    for i, k in zip(*np.nonzero(ok)):
        assert np.abs(_pin_pose(r, th[i, k])[:3] - T[i, :3]).max() < 1e-9
    # and has the swivel angle asked for
    i, k = np.nonzero(ok)
    got = swivel_angle(r, r.chain.configuration(th[i, k]))
    assert _wrapdiff(got, phi[i]).max() < 1e-9
    assert not np.isnan(th[cand]).any() and np.isnan(th[~cand]).all()
    return plan


# ----------------------------------------------------------------------------- SRS 7R
def test_human_arm7_fk_of_ik_and_sampled_branch():
    r = aa.load("human_arm7")
    plan = _check_srs(r, n=200, seed=1, route="sp2")
    assert plan.labels == F.srs_branch_labels("sp2")
    assert plan.labels[0] == "q4=0,q1q2=0,q6=0" and plan.labels[5] == "q4=1,q1q2=0,q6=1"
    assert F.srs_plan(r) is plan  # cached
    r.chain = copy.copy(r.chain)  # a new chain: rebuilt
    again = F.srs_plan(r)
    assert again is not plan and again.chain is r.chain


def test_human_arm7_general_route_same_branches():
    """The general shoulder route (R03 from the two vector pairs, SP4 + SP1) gives the SP2
    route's solutions, branch by branch, on an arm where both apply."""
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    Q, T = _poses(r, 100, 2)
    grid = np.linspace(-PI, PI, 7, endpoint=False)
    sw = np.broadcast_to(grid, (100, 7))
    a = F.srs_verified(plan, T, sw)
    b = F.srs_verified(dataclasses.replace(plan, route=1), T, sw)
    ea, eb = a[2] & a[3], b[2] & b[3]
    assert (ea.sum(1) == eb.sum(1)).all()
    for i in range(100):
        A, B = a[0][i][ea[i]], b[0][i][eb[i]]
        assert all(_wrapdiff(B, x).max(1).min() < 1e-9 for x in A)
    assert b[4][eb].max() < 1e-9


def test_swivel_grid_agrees_with_swivel_angle():
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    Q, T = _poses(r, 50, 3)
    grid = np.linspace(-PI, PI, 12, endpoint=False)
    wide = dataclasses.replace(plan, lower_path=np.full(7, -np.inf), upper_path=np.full(7, np.inf))
    th, cand, exact, inside, res, _ = F.srs_verified(wide, T, np.broadcast_to(grid, (50, 12)))
    assert th.shape == (50, 96, 7)
    assert (exact.sum(1) == 96).all()  # reachable poses: every branch of every swivel
    assert res[exact].max() < 1e-9
    i, k = np.nonzero(exact)
    got = swivel_angle(r, r.chain.configuration(th[i, k]))
    assert _wrapdiff(got, grid[k // 8]).max() < 1e-9
    # the elbow the kernel places is the elbow frame of the solution
    S, W, E = F.srs_points(plan, T, np.broadcast_to(grid, (50, 12)))
    names = plan.swivel_frames
    q = r.chain.configuration(th[i, k])
    assert np.abs(r.fk(q, names[1])[:, :3, 3] - E[i, k // 8]).max() < 1e-9
    assert np.abs(r.fk(q, names[2])[:, :3, 3] - W[i]).max() < 1e-9


def test_straight_elbow():
    """q4 = 0 (arm straight): the swivel angle is the elbow axis' (d = n × a_E); the sampled
    configuration is found."""
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    rng = np.random.default_rng(4)
    th0 = r.chain.angles(r.random_q(30, rng))
    th0[:, 3] = 0.0
    Q = r.chain.configuration(th0)
    T = r.fk(Q)
    th, cand, exact, inside, res, _ = F.srs_verified(plan, T, swivel_angle(r, Q))
    d = np.nanmin(_wrapdiff(th, th0[:, None, :]).max(-1), 1)
    assert d.max() < 1e-9
    assert res[exact & inside].max() < 1e-9


def test_solutions_are_the_candidates_inside_that_pass_fk():
    """The kernel's solution flags: a candidate inside the limits whose residual is ≤ tol, at a
    generic pose (no two branches coincide) exactly those — each of them checked against
    Pinocchio's FK of its configuration — and with a tol below every residual, none."""
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    Q, T = _poses(r, 40, 6)
    th, cand, exact, inside, res, ok = F.srs_verified(plan, T, swivel_angle(r, Q), 1e-9)
    np.testing.assert_array_equal(ok, cand & inside & (res <= 1e-9))
    assert ok.any(1).all()
    for i, b in zip(*np.nonzero(ok)):
        q = r.chain.configuration(th[i, b])
        assert np.abs(r.fk(q) - T[i])[:3].max() <= 1e-9
    assert not F.srs_verified(plan, T, swivel_angle(r, Q), 1e-300)[5].any()


def test_unreachable_pose_no_valid_branch():
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    Q, T = _poses(r, 10, 5)
    T[:5, :3, 3] *= 10.0  # far out of reach
    th, cand, exact, inside, res, _ = F.srs_verified(plan, T, np.zeros((10, 3)))
    assert not exact[:5].any()
    assert (res[:5][cand[:5]] > 1e-3).all()  # least-squares candidates only
    assert not np.isnan(th[cand]).any()  # no NaN in a candidate row
    # every candidate that can be returned (inside the limits) or explains a failure (inexact) is
    # FK-checked; an exact one outside the limits is never returned and not checked
    checked = cand & (inside | ~exact)
    assert np.isfinite(res[checked]).all() and np.isinf(res[~checked]).all()
    assert (cand & exact & ~inside).any() and checked[:5][cand[:5]].all()
    assert exact[5:].all()  # reachable: every branch (limits aside)


def test_malformed_pose_raises_with_index():
    r = aa.load("human_arm7")
    plan = F.srs_plan(r)
    _, T = _poses(r, 4, 6)
    T[2, 0, 0] = np.nan
    with pytest.raises(ValueError, match=r"T\[2\]"):
        F.srs_verified(plan, T, 0.0)
    T[2] = np.eye(4)
    T[2, :3, :3] *= 2.0
    with pytest.raises(ValueError, match=r"T\[2\]"):
        F.srs_verified(plan, T, 0.0)
    _, T = _poses(r, 4, 6)
    with pytest.raises(ValueError, match=r"swivel\[1\]"):
        F.srs_verified(plan, T, np.array([0.0, np.nan, 0.0, 0.0]))
    with pytest.raises(ValueError, match="length N = 4"):
        F.srs_verified(plan, T, np.zeros(3))
    # through aa.ik.analytic_batch (its compiled call finds the pose, the message details it),
    # also from a batch large enough to be split across threads
    _, T = _poses(r, 5000, 6)
    T[4321, :3, :3] *= 1.01
    with pytest.raises(ValueError, match=r"T\[4321\]: the rotation part is not a rotation matrix"):
        aa.ik.analytic_batch(r, T, swivel=0.0)
    T[4321] = r.fk(r.neutral())
    sw = np.zeros(5000)
    sw[3000] = np.inf
    with pytest.raises(ValueError, match="swivel"):
        aa.ik.analytic_batch(r, T, swivel=sw)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_user_srs_arm_general_route(tmp_path, seed):
    r = srs_urdf(tmp_path, f"srs{seed}", seed)
    plan = _check_srs(r, n=60, seed=seed, route="general")
    assert plan.labels[0] == "q4=0,q2=0,q6=0"


@pytest.mark.parametrize("seed", [3, 4])
def test_user_srs_arm_sp2_route(tmp_path, seed):
    _check_srs(srs_urdf(tmp_path, f"srsa{seed}", seed, along=True), n=60, seed=seed, route="sp2")


def test_no_srs_plan_for_other_arms():
    assert F.srs_plan(aa.load("planar2r")) is None
    assert "not 7" in F.srs_reason(aa.load("planar2r"))


# ----------------------------------------------------------------------------- planar 2R
def test_planar_both_branches():
    r = aa.load("planar2r")
    plan = F.planar_plan(r)
    assert plan is not None and plan.labels == ("q2=0", "q2=1")
    Q, T = _poses(r, 100, 7)
    P = T[:, :3, 3]
    th, cand, exact, inside, res, _ = F.planar_verified(plan, P)
    assert th.shape == (100, 2, 2)
    assert exact.all() and res.max() < 1e-9
    theta = r.chain.angles(Q)
    assert np.nanmin(_wrapdiff(th, theta[:, None, :]).max(-1), 1).max() < 1e-9
    # the two elbow branches: opposite q2
    assert _wrapdiff(th[:, 0, 1], -th[:, 1, 1]).max() < 1e-9
    for i in range(100):
        for b in range(2):
            assert np.abs(_pin_pose(r, th[i, b])[:3, 3] - P[i]).max() < 1e-9


def test_planar_off_plane_and_out_of_reach():
    r = aa.load("planar2r")
    plan = F.planar_plan(r)
    _, T = _poses(r, 20, 8)
    P = T[:, :3, 3].copy()
    off = P + plan.h1 * 0.05
    th, cand, exact, inside, res, ok = F.planar_verified(plan, off)
    assert (
        not cand.any()
        and not exact.any()
        and np.isnan(th).all()
        and np.isinf(res).all()
        and not ok.any()
    )
    # a batch of off-plane targets: no solution flagged (the flags are written, not left as found)
    big = np.repeat(off, 200, axis=0)
    assert not F.planar_verified(plan, big)[5].any()
    res_b = aa.ik.analytic_batch(
        r,
        np.repeat(T, 200, axis=0)
        + np.pad(plan.h1 * 0.05, (0, 1))[None, :, None] * np.array([0, 0, 0, 1.0])[None, None, :],
    )
    assert not res_b.valid.any() and all("plane of motion" in x for x in res_b.reasons)
    far = P + 5.0 * (P - plan.o1) / np.linalg.norm(P - plan.o1, axis=1)[:, None]  # beyond reach 2
    th, cand, exact, inside, res, _ = F.planar_verified(plan, far)
    assert not exact.any() and not np.isnan(th[cand]).any()
    with pytest.raises(ValueError, match=r"P\[1\]"):
        F.planar_verified(plan, np.array([[0, 1.0, 0], [np.inf, 0, 0]]))
    assert F.planar_plan(aa.load("human_arm7")) is None


@pytest.mark.parametrize("name", ["human_arm7", "planar2r"])
def test_one_pose_path_is_the_batch_answer(name):
    """aa.ik.analytic of one pose (its lean compiled path) gives exactly what analytic_batch
    gives for that pose — solutions, labels, swivel angles — on reachable poses (each solution
    FK-exact by Pinocchio) and the batch's reason where there is none (a pose out of reach)."""
    robot = aa.load(name)
    model, data = robot.model, robot.model.createData()
    Q = robot.random_q(40, np.random.default_rng(8))
    T = robot.fk(Q)
    for k in range(len(Q)):
        kw = {"swivel": float(swivel_angle(robot, Q[k]))} if name == "human_arm7" else {}
        a, b = aa.ik.analytic(robot, T[k], **kw), aa.ik.analytic_batch(robot, T[k][None], **kw)[0]
        assert a.branches == b.branches and len(a) > 0
        np.testing.assert_array_equal(a.solutions, b.solutions)
        if kw:
            np.testing.assert_array_equal(a.swivel, b.swivel)
        for q in a.solutions:
            pin.framesForwardKinematics(model, data, q)
            err = data.oMf[robot.tool_id].translation - T[k][:3, 3]
            assert np.abs(err).max() < 1e-9
    far = T[0].copy()
    far[:3, 3] *= 100.0
    a, b = aa.ik.analytic(robot, far), aa.ik.analytic_batch(robot, far[None])[0]
    assert len(a) == 0 and a.reason == b.reason and a.reason


def test_srs_nearest_is_the_verified_family_in_one_call():
    """``srs_nearest`` (the seeds of ``aa.ik.solve`` on an SRS arm): at every swivel angle of a
    grid, the same solutions as ``srs_verified`` with duplicates dropped, the one nearest the
    reference first, and that one's position / rotation errors equal to Pinocchio's; with
    ``first`` only those of the first angle that has any."""
    from anthroarm.ik import closed_form as cf
    from anthroarm.ik import geometric as G

    r = aa.load("human_arm7")
    plan = cf._solver(r).plan
    grid = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    rng = np.random.default_rng(31)
    for T in _poses(r, 12, 32)[1]:
        T = np.ascontiguousarray(T)
        ref = r.random_q(rng=rng)
        th, cand, exact, inside, res, _ = (a[0] for a in F.srs_verified(plan, T[None], grid[None]))
        ok = G.mark_solutions(th[None], cand[None], inside[None], res[None], 1e-9, 8)[0]
        out = F.srs_nearest(plan, T, ref, grid, False)
        if not ok.any():
            assert out is None
            continue
        S, pe, re = out
        assert sorted(map(tuple, np.round(S, 10))) == sorted(map(tuple, np.round(th[ok], 10)))
        assert np.argmin(((S - ref) ** 2).sum(1)) == 0
        F_ = _pin_pose(r, S[0])
        assert pe == pytest.approx(np.linalg.norm(T[:3, 3] - F_[:3, 3]), abs=1e-14)
        assert re == pytest.approx(np.linalg.norm(pin.log3(F_[:3, :3].T @ T[:3, :3])), abs=1e-12)
        k0 = int(np.flatnonzero(ok)[0]) // 8  # the first angle with a solution
        first = F.srs_nearest(plan, T, ref, grid, True)[0]
        assert sorted(map(tuple, np.round(first, 10))) == sorted(
            map(tuple, np.round(th[ok][np.flatnonzero(ok) // 8 == k0], 10))
        )


def test_solve_answers_an_srs_arm_from_the_compiled_call():
    """``aa.ik.solve`` without a posture objective answers the human arm (and the 27-joint limb,
    a tree) with the closed form's solution from one compiled call, its errors Pinocchio's."""
    for name in ("human_arm7", "human_upper_limb"):
        r = aa.load(name)
        for q in r.random_q(6, rng=33):
            T = r.fk(q)
            res = aa.ik.solve(r, T, posture=None)
            assert (
                res.success
                and res.seed == "analytic"
                and res.iterations == 0
                and r.within_limits(res.q)
            ), name
            data = r.model.createData()
            pin.framesForwardKinematics(r.model, data, res.q)
            M = data.oMf[r.tool_id]
            assert res.pos_err == pytest.approx(np.linalg.norm(T[:3, 3] - M.translation), abs=1e-14)
            assert res.rot_err == pytest.approx(
                np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3])), abs=1e-12
            )


def test_planar_position_and_pose_give_the_batch_answer():
    """A planar 2R arm's one-pose paths — a position (3,) and a 4×4 pose (position only) —
    give exactly analytic_batch's row (solutions, labels, residuals) on reachable targets, on
    targets off the plane of motion (beyond and within tol), out of reach, and on a joint
    limit (q2 = ±π: the arm folded back); each solution's position checked by Pinocchio."""
    robot = aa.load("planar2r")
    plan = F.planar_plan(robot)
    model, data = robot.model, robot.model.createData()
    Q = robot.random_q(30, np.random.default_rng(12))
    Q[0] = [0.3, np.pi] if robot.upper[1] >= np.pi else Q[0]
    T = robot.fk(Q)
    P = [t[:3, 3].copy() for t in T]
    P += [P[1] + plan.h1 * 1e-3, P[2] + plan.h1 * 1e-10, P[3] * 100.0]
    for i, p in enumerate(P):
        pose = np.eye(4)
        pose[:3, 3] = p
        b = aa.ik.analytic_batch(robot, p[None])[0]
        assert (len(b) > 0) == (i < 30 or i == 31), (
            i
        )  # reachable: sampled, or off the plane by 1e-10
        for target in (p, pose):
            a = aa.ik.analytic(robot, target)
            assert a.branches == b.branches and a.reason == b.reason
            np.testing.assert_array_equal(a.solutions, b.solutions)
            np.testing.assert_array_equal(a.residuals, b.residuals)
            for q in a.solutions:
                pin.framesForwardKinematics(model, data, q)
                assert np.abs(data.oMf[robot.tool_id].translation - p).max() < 1e-9
