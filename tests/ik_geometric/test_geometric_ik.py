"""Closed-form IK of any 6R arm by its geometry (anthroarm.ik.geometric through aa.ik.analytic):
the UR3/5/10 (three parallel + two intersecting), kinova and a PUMA 560 (spherical wrist + two
parallel), the prosthetic arm (spherical shoulder: a reversed spherical_two_intersecting), and
random user arms of each class written here as standard-DH URDFs, including the two classes
solved by a 1-D search (two_parallel, two_intersecting).

Oracles: Pinocchio FK of every returned branch (FK(IK(T)) = T to 1e-9) and the joint values
the pose was made from; PyPI ik-geo (Rust) for the number of exact solutions and their values
on the same poses (skipped when ik_geo is not installed)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import UnsupportedModelError
from anthroarm.ik import classify as C
from anthroarm.ik import fk as FK
from anthroarm.ik import geometric as G
from anthroarm.ik.closed_form import closed_form_info
from anthroarm.models.standard_dh import PUMA560, standard_dh_urdf

PI = np.pi


def dh_urdf(tmp_path, name, alpha, a, d, lim=PI):
    """A 6R arm from standard DH parameters (anthroarm.models.standard_dh), joint limits ±lim."""
    path = tmp_path / f"{name}.urdf"
    path.write_text(standard_dh_urdf(name, alpha, a, d, lim))
    return aa.load(str(path))


def puma560(tmp_path):
    return dh_urdf(tmp_path, "puma560", **PUMA560)


def random_arm(tmp_path, cls, seed):
    """A random user 6R arm whose DH parameters satisfy the class constraints."""
    r = np.random.default_rng(seed)
    L = lambda: r.uniform(0.05, 0.5)  # noqa: E731
    A = lambda: r.choice([-1, 1]) * r.uniform(0.3, 1.3)  # a generic twist
    if cls == C.SPHERICAL_TWO_PARALLEL:  # 2 ∥ 3 (α2 = 0), a4 = a5 = d5 = 0
        alpha, a, d = (
            [A(), 0, A(), A(), A(), A()],
            [L(), L(), L(), 0, 0, L()],
            [L(), L(), L(), L(), 0, L()],
        )
    elif cls == C.SPHERICAL_TWO_INTERSECTING:  # 1 × 2 (a1 = 0), spherical wrist
        alpha, a, d = (
            [A(), A(), A(), A(), A(), A()],
            [0, L(), L(), 0, 0, L()],
            [L(), L(), L(), L(), 0, L()],
        )
    elif cls == C.SPHERICAL:  # a spherical wrist, nothing else (SP5 quartic)
        alpha, a, d = (
            [A(), A(), A(), A(), A(), A()],
            [L(), L(), L(), 0, 0, L()],
            [L(), L(), L(), L(), 0, L()],
        )
    elif cls == C.THREE_PARALLEL:  # 2 ∥ 3 ∥ 4 alone (SP6 quartic)
        alpha, a, d = (
            [A(), 0, 0, A(), A(), A()],
            [L(), L(), L(), L(), L(), L()],
            [L(), L(), L(), L(), L(), L()],
        )
    elif cls == C.TWO_PARALLEL:  # 2 ∥ 3 (α2 = 0) alone: a 1-D search over q1
        alpha, a, d = [A(), 0, A(), A(), A(), A()], [L() for _ in range(6)], [L() for _ in range(6)]
    elif cls == C.TWO_INTERSECTING:  # 5 × 6 (a5 = 0) alone: a 1-D search over q4
        alpha, a, d = [A() for _ in range(6)], [L(), L(), L(), L(), 0, L()], [L() for _ in range(6)]
    else:  # 2 ∥ 3 ∥ 4 (α2 = α3 = 0), 5 × 6 (a5 = 0)
        alpha, a, d = (
            [A(), 0, 0, A(), A(), A()],
            [L(), L(), L(), L(), 0, L()],
            [L(), L(), L(), L(), L(), L()],
        )
    return dh_urdf(tmp_path, f"user_{cls}_{seed}", alpha, a, d)


def _fk(robot, q):
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(robot.tool)].homogeneous.copy()


def _poses(robot, n, seed):
    th = robot.chain.random_q(n, np.random.default_rng(seed))
    return th, np.array([_fk(robot, q) for q in th])


def _angles(robot, Q):
    return robot.chain.angles(Q) if hasattr(robot.chain, "angles") else Q


def _arms(tmp_path):
    return [
        ("ur3", aa.load("ur3")),
        ("ur5", aa.load("ur5")),
        ("ur10", aa.load("ur10")),
        ("kinova", aa.load("kinova")),
        ("puma560", puma560(tmp_path)),
    ] + [
        (f"user_{c}", random_arm(tmp_path, c, s))
        for s in (1, 2)
        for c in G.SOLVED
        if c not in G.SEARCHED
    ]


CLASS = {
    "ur3": C.THREE_PARALLEL_TWO_INTERSECTING,
    "ur5": C.THREE_PARALLEL_TWO_INTERSECTING,
    "ur10": C.THREE_PARALLEL_TWO_INTERSECTING,
    "kinova": C.SPHERICAL_TWO_PARALLEL,
    "puma560": C.SPHERICAL_TWO_PARALLEL,
}


def test_every_branch_fk_verified_and_the_pose_found(tmp_path):
    for label, robot in _arms(tmp_path):
        gp = G.plan_for(robot)
        assert gp is not None, label
        assert gp.cls == CLASS.get(label, label[5:]), label
        assert aa.ik.has_analytic(robot)
        th, T = _poses(robot, 12, 3)
        res = aa.ik.analytic_batch(robot, T)
        assert res.valid.any(1).all(), (label, res.reasons)
        for i in range(len(T)):
            r = res[i]
            assert len(r) <= 8 and np.isfinite(r.solutions).all()
            for q in r.solutions:
                assert np.abs(_fk(robot, q) - T[i]).max() < 1e-9, label
                assert (q >= robot.lower - 1e-12).all() and (q <= robot.upper + 1e-12).all()
            # the posture the pose was made from is among the branches (mod 2π)
            A = _angles(robot, r.solutions)
            d = np.abs(np.angle(np.exp(1j * (A - _angles(robot, th[i][None]))))).max(1)
            assert d.min() < 1e-7, label
        one = aa.ik.analytic(robot, T[0])
        np.testing.assert_allclose(one.solutions, res[0].solutions, atol=1e-12)
        assert one.branches == res[0].branches


def test_reversed_class_prosthetic_arm():
    """The prosthetic arm has a spherical shoulder: spherical_two_intersecting of the reversed
    chain.  (aa.ik.analytic keeps the book's procedure for it; the class solver is checked here.)"""
    robot = aa.load("prosthetic_arm")
    gp = G.plan_for(robot)
    assert gp.cls == C.SPHERICAL_TWO_INTERSECTING and gp.reversed
    th, T = _poses(robot, 15, 4)
    q, valid, exact = G.solve(gp, T)
    assert exact.all()  # generic poses: 8 exact branches
    for i in range(len(T)):
        for k in range(8):
            assert np.abs(_fk(robot, robot.chain.configuration(q[i, k])) - T[i]).max() < 1e-9
        assert np.abs(np.angle(np.exp(1j * (q[i] - th[i])))).max(1).min() < 1e-7
    # the book method (registered) and the class solver find the same solutions inside the limits
    book = aa.ik.analytic_batch(robot, T)
    for i in range(len(T)):
        ours = np.array(
            [x for x in q[i] if ((x >= robot.lower - 1e-9) & (x <= robot.upper + 1e-9)).all()]
        )
        assert len(ours) == len(book[i])


def test_branch_counts_and_values_equal_ik_geo(tmp_path):
    ik_geo = pytest.importorskip("ik_geo")
    arms = _arms(tmp_path) + [
        ("prosthetic_arm", aa.load("prosthetic_arm")),
        ("sixr_arm", aa.load("sixr_arm")),
    ]
    for label, robot in arms:
        gp = G.plan_for(robot)
        geo = getattr(ik_geo.Robot, gp.cls)(gp.H.tolist(), gp.P.tolist())
        _, T = _poses(robot, 15, 6)
        q, valid, exact = G.solve(gp, T)
        counts = []
        for i in range(len(T)):
            R, p = T[i, :3, :3], T[i, :3, 3]
            if gp.reversed:
                R, p = R.T, -R.T @ p
            theirs = np.array(
                [s for s, ls in geo.get_ik((R @ gp.R_tool.T).T.tolist(), p.tolist()) if not ls]
            )
            if gp.reversed:
                theirs = theirs[:, ::-1]
            theirs = theirs[:, gp.order]
            ours = q[i][exact[i]]
            assert len(ours) == len(theirs), label
            counts.append(len(ours))
            dd = np.abs(np.angle(np.exp(1j * (ours[:, None] - theirs[None])))).max(-1)
            # spherical, three_parallel: the quartic's roots; ik-geo's are not polished (FK error up to ~1e-10,
            # ours ~1e-15: test_every_branch_fk_verified), so they agree to ~1e-7 rad
            atol = 1e-6 if gp.cls in (C.SPHERICAL, C.THREE_PARALLEL) else 1e-8
            assert dd.min(1).max() < atol and dd.min(0).max() < atol, label
        if label.startswith("ur") or label in ("kinova", "puma560", "sixr_arm"):
            assert max(counts) == 8


def test_unreachable_pose_says_so():
    robot = aa.load("ur5")
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 0.0]  # 3 m: out of reach
    r = aa.ik.analytic(robot, T)
    assert not r.success and r.solutions.shape == (0, 6) and "outside the workspace" in r.reason
    b = aa.ik.analytic_batch(robot, np.stack([T, robot.fk(robot.neutral())]))
    assert not b.valid[0].any() and b.valid[1].any() and b.reasons[1] is None


def test_singular_pose_ur5_home():
    """q = 0 of the UR5 is a wrist singularity (axes 4 and 6 parallel): whatever is returned
    is FK-exact and finite, with no duplicates."""
    robot = aa.load("ur5")
    T = robot.fk(robot.neutral())
    r = aa.ik.analytic(robot, T)
    assert r.success and np.isfinite(r.solutions).all()
    for q in r.solutions:
        assert np.abs(_fk(robot, q) - T).max() < 1e-9
    D = np.abs(r.solutions[:, None] - r.solutions[None]).max(-1) + np.eye(len(r)) * 9
    assert D.min() > 1e-9


def test_bad_rotation_and_options():
    robot = aa.load("ur10")
    T = robot.fk(robot.neutral())
    bad = T.copy()
    bad[:3, :3] *= 1.01
    with pytest.raises(ValueError, match="not a rotation matrix"):
        aa.ik.analytic(robot, bad)
    with pytest.raises(ValueError, match="swivel"):
        aa.ik.analytic(robot, T, swivel=0.3)
    empty = aa.ik.analytic_batch(robot, np.zeros((0, 4, 4)))
    assert len(empty) == 0
    # a batch: the compiled call finds the bad pose; the message names it as the caller indexed it
    Ts = robot.fk(robot.random_q(8, np.random.default_rng(1)))
    for i, fix in (
        (5, lambda M: M[:3, :3].__imul__(1.01)),
        (2, lambda M: M[3].__setitem__(0, 0.1)),
        (7, lambda M: M[:3, :3].__setitem__(slice(None), -M[:3, :3])),
    ):
        bad = Ts.copy()
        fix(bad[i])
        with pytest.raises(ValueError, match=rf"T\[{i}\]"):
            aa.ik.analytic_batch(robot, bad)
    with pytest.raises(ValueError, match="param"):
        aa.ik.analytic_batch(
            aa.load("panda"),
            np.repeat(aa.load("panda").fk(aa.load("panda").neutral())[None], 3, 0),
            param=[[0.1, np.nan]],
        )
    # a held joint that is not an angle (inf, or so large its digits below a turn are lost):
    # a clear error from the single-pose path and the batch (once an endless 2π-shifting loop)
    panda = aa.load("panda")
    Tp = panda.fk(panda.random_q(rng=3))
    for bad in (np.inf, -np.inf, 1e300, -2e12):
        with pytest.raises(ValueError, match="param must be finite angles"):
            aa.ik.analytic(panda, Tp, param=bad)
        with pytest.raises(ValueError, match="param must be finite angles"):
            aa.ik.analytic_batch(panda, Tp[None], param=bad)
    assert all(np.isnan(G.wrap(x)) for x in (np.inf, -np.inf, np.nan, 1e300, -1e12))
    assert G.wrap(1e6) == pytest.approx(np.angle(np.exp(1e6j)), abs=1e-9)


def test_near_intersecting_axes_within_tolerance_are_polished(tmp_path):
    """Wrist axes 1e-7 m from a common point: classified spherical within tol = 1e-6 (the
    classification reports 5e-8 m: the least-squares common point lies midway), so the class
    solution is off by ~1e-7; it is polished onto the pose and then FK-exact."""
    robot = dh_urdf(
        tmp_path,
        "puma_off",
        [PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0],
        [0, 0.4318, 0.0203, 0, 0, 0],
        [0.6718, 0, 0.15005, 0.4318, 1e-7, 0],
    )
    gp = G.plan_for(robot)
    assert (
        gp.cls == C.SPHERICAL_TWO_PARALLEL
        and abs(gp.classification.worst_accepted[0] - 5e-8) < 1e-12
    )
    th, T = _poses(robot, 1, 8)
    q, _, exact = G.solve(gp, T)
    raw = max(np.abs(_fk(robot, x) - T[0]).max() for x in q[0][exact[0]])
    assert 1e-9 < raw < 1e-6  # the class solution alone is not exact
    r = aa.ik.analytic(robot, T[0])
    assert r.success and all(np.abs(_fk(robot, x) - T[0]).max() < 1e-9 for x in r.solutions)


def test_polished_solutions_of_continuous_joints_come_out_polished(tmp_path):
    """The arm above with joints 1, 4 and 6 continuous (nq = 9): the compiled call polishes its
    candidates and writes their configurations, the (cos, sin) pairs of the polished angles —
    Pinocchio's FK of every solution, one pose and a batch, is the pose to 1e-9 (the class
    solution's pairs would be ~1e-7 off)."""
    text = standard_dh_urdf(
        "puma_off_cont",
        [PI / 2, 0, -PI / 2, PI / 2, -PI / 2, 0],
        [0, 0.4318, 0.0203, 0, 0, 0],
        [0.6718, 0, 0.15005, 0.4318, 1e-7, 0],
    )
    for j in ("j1", "j4", "j6"):
        text = text.replace(
            f'<joint name="{j}" type="revolute">', f'<joint name="{j}" type="continuous">'
        )
    path = tmp_path / "puma_off_cont.urdf"
    path.write_text(text)
    robot = aa.load(str(path))
    assert robot.nq == 9 and G.plan_for(robot).cls == C.SPHERICAL_TWO_PARALLEL
    th, T = _poses(robot, 6, 8)
    gp = G.plan_for(robot)
    q, _, exact = G.solve(gp, T[:1])
    assert (
        max(np.abs(_fk(robot, robot.chain.configuration(x)) - T[0]).max() for x in q[0][exact[0]])
        > 1e-9
    )
    ch = robot.chain
    cos_at = [ch.joints[j].idx_q for j in ch.independent if ch.joints[j].kind == "continuous"]
    assert len(cos_at) == 3
    batch = aa.ik.analytic_batch(robot, T)
    for i in range(len(T)):
        one = aa.ik.analytic(robot, T[i])
        assert len(one) > 0 and one.solutions.shape[1] == 9
        for x in list(one.solutions) + list(batch.solutions[i][batch.valid[i]]):
            assert np.abs(_fk(robot, x) - T[i]).max() < 1e-9
            np.testing.assert_allclose(
                np.hypot(x[cos_at], x[[k + 1 for k in cos_at]]), 1.0, atol=1e-15
            )


def test_no_closed_form_geometry():
    robot = aa.load("rrprr5")  # 5 joints, one prismatic
    assert C.classify(robot).name == C.NOT_6R and G.plan_for(robot) is None
    assert not aa.ik.has_analytic(robot)
    with pytest.raises(
        UnsupportedModelError, match="no closed form for this geometry.*not_6r.*aa.ik.solve"
    ):
        aa.ik.analytic(robot, np.eye(4))


def test_general_6r_by_a_2d_search(tmp_path):
    """A general 6R (no parallel or intersecting consecutive axes): the 2-D search over
    (q1, q2) finds the sampled posture on every pose (no completeness claim), each branch
    FK-exact (Pinocchio, 1e-9)."""
    r = np.random.default_rng(0)
    robot = dh_urdf(
        tmp_path, "gen6r", r.uniform(0.3, 1.3, 6), r.uniform(0.05, 0.4, 6), r.uniform(0.05, 0.4, 6)
    )
    gp = G.plan_for(robot)
    assert (
        C.classify(robot).name == C.GEN_SIX_DOF
        and gp.cls == C.GEN_SIX_DOF
        and aa.ik.has_analytic(robot)
    )
    th, T = _poses(robot, 8, 3)
    res = aa.ik.analytic_batch(robot, T)
    assert res.branches[0] == "q1q2root=0" and res.valid.any(1).all(), res.reasons
    for i in range(len(T)):
        sols = res[i].solutions
        assert all(np.abs(_fk(robot, q) - T[i]).max() < 1e-9 for q in sols)
        assert np.abs(np.angle(np.exp(1j * (sols - th[i])))).max(1).min() < 1e-7, i


@pytest.mark.parametrize("name, polish", [("panda", 1e-12), ("xarm7", 1e-12)])
def test_seven_joint_arm_as_a_family_of_its_last_joint(name, polish):
    """panda and xarm7 with the last joint held are 6R arms with a spherical shoulder
    (spherical_two_intersecting of the reversed chain).  xarm7's URDF rounds its angles (axes
    ~4e-6 rad off, shoulder lines 5e-7 m apart): the class solution is polished onto the exact
    pose by Newton steps on the first six joints in the compiled call, the held joint stays
    where it was asked to be."""
    robot = aa.load(name)
    gp = G.plan_for(robot)
    assert gp.cls == C.SPHERICAL_TWO_INTERSECTING and gp.reversed and gp.param_joint == 6
    th, T = _poses(robot, 8, 9)
    res = aa.ik.analytic_batch(robot, T, param=th[:, 6])
    assert res.valid.any(1).all(), res.reasons
    for i in range(len(T)):
        r = res[i]
        for q in r.solutions:
            assert np.abs(_fk(robot, q) - T[i]).max() < 1e-9
            assert abs(np.angle(np.exp(1j * (q[6] - th[i, 6])))) < polish  # the parameter held
        d = np.abs(np.angle(np.exp(1j * (r.solutions - th[i])))).max(1)
        assert d.min() < max(polish, 1e-9)
    grid = aa.ik.analytic(robot, T[0])  # default: a grid of the held joint
    assert len(grid) > 0 and all(np.abs(_fk(robot, q) - T[0]).max() < 1e-9 for q in grid.solutions)
    assert "param#" in grid.branches[0]
    gb = aa.ik.analytic_batch(robot, T[:3])  # the same grid for every pose of a batch
    assert len(gb.branches) == gb.solutions.shape[1] == 8 * 12 and gb.valid.any(1).all()
    assert gb[0].branches == grid.branches
    with pytest.raises(ValueError, match="param: a 1-D array gives one angle per pose"):
        aa.ik.analytic_batch(robot, T[:3], param=[0.1, 0.2])
    with pytest.raises(ValueError, match="param="):
        aa.ik.analytic(aa.load("ur5"), aa.load("ur5").fk(aa.load("ur5").neutral()), param=0.3)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_held_pose_is_the_first_six_joints_pose(name):
    """T · M⁻¹ e^{−ξ7 v} M (:func:`held_poses`, the one source the compiled one-pose call and the
    batch path both run) is the tool pose with the held joint at 0, the other joints where they
    were: Pinocchio's FK of q with q7 = 0 (T = F6 e^{ξ7 v} M), compiled and reference."""
    from anthroarm import jit
    from anthroarm.ik.geometric.verify import held_poses

    robot = aa.load(name)
    gp = G.plan_for(robot)
    assert robot.model.nq == 7 and gp.param_joint == 6  # q's last entry is the held joint
    q, T = _poses(robot, 50, 3)
    k = 6
    q0 = q.copy()
    q0[:, k] = 0.0
    want = np.array([_fk(robot, x) for x in q0])
    args = (T, np.ascontiguousarray(gp.M), gp.param_axis, gp.param_point, q[:, k].copy())
    for f in (held_poses, jit.reference(held_poses)):
        out = np.empty((len(T), 4, 4))
        f(*args, out)
        assert np.abs(out - want).max() < 1e-12
    # the printed-form check: e^{+ξ7 v} in place of e^{−ξ7 v} gives another pose
    out = np.empty((len(T), 4, 4))
    held_poses(T, np.ascontiguousarray(gp.M), gp.param_axis, gp.param_point, -q[:, k], out)
    assert np.abs(out - want).max() > 1e-3


@pytest.mark.parametrize("name", ["ur10", "panda", "prosthetic_arm"])
def test_check_rows_pass(name):
    """The `anthroarm check` rows (FK(IK(T)) = T; branch counts = ik-geo's when installed) on a
    6R arm, a 7-joint arm (its sampled last joint held) and a reversed class."""
    rows = G.check_rows(aa.load(name), 8, np.random.default_rng(0))
    assert len(rows) >= 1 and all(r.ok for r in rows), [
        (r.quantity, r.max_abs_err, r.note) for r in rows
    ]
    assert rows[0].max_abs_err < 1e-9
    assert G.check_rows(aa.load("unimate5"), 8, np.random.default_rng(0)) == []


def _ik_geo_fk(gp, x):
    """FK in IK-Geo's form (R06, p) of the class kinematics of ``gp``."""
    R, p = np.eye(3), gp.P[0].copy()
    for i in range(6):
        R = R @ G.sp.rot(gp.H[i], x[i])
        p = p + R @ gp.P[i + 1]
    return R, p


@pytest.mark.parametrize("cls", [C.TWO_PARALLEL, C.TWO_INTERSECTING])
def test_search_classes_every_branch_fk_verified_and_the_pose_found(tmp_path, cls):
    """Random user arms of the 1-D search classes: every branch aa.ik.analytic_batch returns is
    FK-exact (Pinocchio, 1e-9), the sampled posture is among them (mod 2π), the number of
    solutions is even, the labels name the search root."""
    for seed in (1, 2):
        robot = random_arm(tmp_path, cls, seed)
        gp = G.plan_for(robot)
        assert gp is not None and gp.cls == cls and not gp.reversed
        assert aa.ik.has_analytic(robot) and closed_form_info(robot).family == cls
        th, T = _poses(robot, 20, 3)
        res = aa.ik.analytic_batch(robot, T)
        assert res.solutions.shape[1] == G.SEARCH_BRANCHES == len(res.branches)
        assert res.branches[0] == ("q1root=0" if cls == C.TWO_PARALLEL else "q4root=0")
        assert res.valid.any(1).all(), res.reasons
        for i in range(len(T)):
            r = res[i]
            for q in r.solutions:
                assert np.abs(_fk(robot, q) - T[i]).max() < 1e-9
            d = np.abs(np.angle(np.exp(1j * (r.solutions - th[i])))).max(1)
            assert d.min() < 1e-7, (cls, seed, i)
        one = aa.ik.analytic(robot, T[0])
        np.testing.assert_allclose(one.solutions, res[0].solutions, atol=1e-12)
        # a 6R arm's real solutions come in pairs (complex roots of its degree-16 polynomial in
        # conjugate pairs): an odd count at a generic pose means a missed root (e.g. next to a fold)
        _, _, exact = G.solve(gp, T)
        assert (exact.sum(1) % 2 == 0).all(), exact.sum(1)


def test_search_class_exact_flag_and_unreachable(tmp_path):
    """A refined root is exact (its error below SEARCH_TOL); a pose out of reach has no branch
    and a reason."""
    robot = random_arm(tmp_path, C.TWO_INTERSECTING, 1)
    gp = G.plan_for(robot)
    _, T = _poses(robot, 3, 5)
    q, valid, exact = G.solve(gp, T)
    assert q.shape == (3, G.SEARCH_BRANCHES, 6) and exact.any(1).all() and (exact <= valid).all()
    far = np.eye(4)
    far[:3, 3] = [5.0, 0.0, 0.0]
    r = aa.ik.analytic(robot, far)
    assert not r.success and r.solutions.shape == (0, 6) and "outside the workspace" in r.reason


@pytest.mark.parametrize("cls", [C.TWO_PARALLEL, C.TWO_INTERSECTING])
def test_search_classes_against_ik_geo(tmp_path, cls):
    """IK-Geo (PyPI ik-geo 1.x) exposes both classes, but its 1-D search (200 samples, a
    secant refinement stopped at |Δe| < 1e-5) returns 1-3 roots per pose whose FK error is
    above 1e-5 and flags none exact, so its branch counts are no oracle here: every solution
    of ik-geo that is FK-exact to 1e-5 must be among ours (to 1e-4 rad), and we find at least
    as many."""
    ik_geo = pytest.importorskip("ik_geo")
    for seed in (1, 2):
        robot = random_arm(tmp_path, cls, seed)
        gp = G.plan_for(robot)
        geo = getattr(ik_geo.Robot, cls)(gp.H.tolist(), gp.P.tolist())
        _, T = _poses(robot, 20, 3)
        q, valid, exact = G.solve(gp, T)
        R06, p06 = G.class_pose(gp, T)
        for i in range(len(T)):
            ours = q[i][exact[i]]
            good = []
            for s, _ in geo.get_ik(R06[i].T.tolist(), p06[i].tolist()):
                R, p = _ik_geo_fk(gp, np.array(s))
                if max(np.abs(R - R06[i]).max(), np.abs(p - p06[i]).max()) < 1e-5:
                    good.append(np.array(s))
            assert len(ours) >= len(good)
            for g in good:
                assert np.abs(np.angle(np.exp(1j * (ours - g)))).max(1).min() < 1e-4, (cls, seed, i)


def test_standard_dh_urdf_is_the_dh_product_and_rejects_bad_rows(tmp_path):
    """The written PUMA 560 is Π Rz(θi) Tz(di) Tx(ai) Rx(αi) (computed here from the DH table)
    by Pinocchio's FK; bad rows are ParameterErrors."""
    from anthroarm.errors import ParameterError

    robot = puma560(tmp_path)

    def dh(q):
        T = np.eye(4)
        for th, al, a, d in zip(q, PUMA560["alpha"], PUMA560["a"], PUMA560["d"]):
            ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
            T = T @ np.array(
                [
                    [ct, -st * ca, st * sa, a * ct],
                    [st, ct * ca, -ct * sa, a * st],
                    [0, sa, ca, d],
                    [0, 0, 0, 1],
                ]
            )
        return T

    for q in robot.random_q(20, np.random.default_rng(5)):
        np.testing.assert_allclose(_fk(robot, q), dh(q), atol=1e-12)
    with pytest.raises(ParameterError):
        standard_dh_urdf("x", [0] * 5, [0] * 6, [0] * 6)
    with pytest.raises(ParameterError):
        standard_dh_urdf("x", [0] * 6, [np.nan] * 6, [0] * 6)
    with pytest.raises(ParameterError):
        standard_dh_urdf("x", [0] * 6, [0] * 6, [0] * 6, limit=-1)
    with pytest.raises(ParameterError):
        standard_dh_urdf('x"/><evil', [0] * 6, [0] * 6, [0] * 6)


def test_singular_poses_say_so_and_stay_exact(tmp_path):
    """Poses made at singular configurations — a PUMA / 6R wrist with q5 = 0 (axes 4 and 6 one
    line), a UR with q5 = 0 (axes 2, 3, 4, 6 parallel) and a stretched UR elbow (q3 = 0) — give
    FK-exact solutions (Pinocchio), no NaN, the sampled one among them where the solutions only
    coincide (the elbow; at a wrist family one member is returned), and `singular` says so;
    the Jacobian volume it uses is checked against numpy's SVD of Pinocchio's Jacobian (zero
    smallest singular value exactly when the volume vanishes).  A generic pose is not singular."""
    cases = [
        (puma560(tmp_path), [0.2, 0.3, 0.4, 0.5, 0.0, 0.6], False),
        (aa.load("sixr_arm"), [0.3, 0.5, 0.0, 0.2, 0.0, 0.4], False),
        (aa.load("ur5"), [0.3, -1.0, 1.0, -0.5, 0.0, 0.2], False),
        (aa.load("ur5"), [0.3, -1.0, 0.0, -0.5, 0.7, 0.2], True),
    ]
    for robot, q, among in cases:
        q = np.array(q)
        T = _fk(robot, q)
        assert np.linalg.svd(robot.jacobian(q), compute_uv=False)[-1] < 1e-12
        for r in (aa.ik.analytic(robot, T), aa.ik.analytic_batch(robot, T[None])[0]):
            assert len(r) and np.isfinite(r.solutions).all() and r.reason is None
            assert all(np.abs(_fk(robot, s) - T).max() < 1e-9 for s in r.solutions)
            assert not among or np.abs(np.angle(np.exp(1j * (r.solutions - q)))).max(1).min() < 1e-6
            assert r.singular and "singular configuration" in r.singular, robot.name
        assert aa.ik.analytic_batch(robot, T[None]).singular[0] == r.singular
    robot = aa.load("ur5")
    q = np.array([0.3, -1.0, 1.0, -0.5, 0.7, 0.2])
    assert np.linalg.svd(robot.jacobian(q), compute_uv=False)[-1] > 1e-2
    r = aa.ik.analytic(robot, _fk(robot, q))
    assert len(r) == 8 and r.singular is None and r.as_dict()["singular"] is None
    vol = G.jacobian_volumes(G.plan_for(robot), r.solutions[None], np.ones((1, len(r)), bool))[0]
    for v, s in zip(vol, r.solutions):
        J = robot.jacobian(s)
        assert np.isclose(v, abs(np.linalg.det(J)) / np.prod(np.linalg.norm(J, axis=0)), rtol=1e-9)


def test_into_limits_takes_the_turn_nearest_zero():
    """Of the angles q + 2πk inside the limits, the one nearest 0 (a ±2π UR joint answers 0.4,
    not 0.4 − 2π); within 1e-9 outside a limit: onto it; no turn inside: not inside (oracle: the
    candidates q + 2πk listed by hand)."""
    two_pi = 2 * np.pi
    lo = np.array([-two_pi, 0.0, -np.pi, -3 * np.pi, -np.inf, -1.0])
    hi = np.array([two_pi, two_pi, 0.0, 3 * np.pi, np.inf, 1.0])
    Q = np.array(
        [[0.4, -0.5, 0.2, 7.0, 4.0, 1.0 + 1e-10], [3.5, 0.3, -0.5 + two_pi, -7.0, -4.0, 2.0]]
    )
    Qw, inside = G.wrap_into_limits(Q, lo, hi)
    np.testing.assert_allclose(
        Qw[0], [0.4, two_pi - 0.5, 0.2, 7.0 - two_pi, 4.0 - two_pi, 1.0], atol=1e-12
    )
    assert not inside[0]  # 0.2 has no turn in [−π, 0]
    np.testing.assert_allclose(
        Qw[1, :5], [3.5 - two_pi, 0.3, -0.5, -7.0 + two_pi, -4.0 + two_pi], atol=1e-12
    )
    assert not inside[1]  # 2.0 has no turn in [−1, 1]
    assert G.wrap_into_limits(Q[:, :5], lo[:5], hi[:5])[1][1]
    ur5 = aa.load("ur5")
    q = np.array([0.4, -1.1, 1.3, -0.6, 0.9, 0.2])
    r = aa.ik.analytic(ur5, _fk(ur5, q))
    assert (
        np.abs(r.solutions - q).max(1).min() < 1e-9
    )  # the sampled angles themselves, no turn added


def test_into_limit_keeps_the_rotation_of_a_turn_and_recomputes_it_on_a_limit():
    """An angle carried with its (cos, sin): moved by whole turns it keeps them (the same
    rotation, no trigonometry); put onto a limit it gets cos and sin of the angle returned
    (oracle: math.cos / math.sin of the returned angle)."""
    x = -0.5
    c, s = math.cos(x), math.sin(x)
    q, qc, qs, ok = G.into_limit_cs(x, c, s, 0.0, 2 * np.pi, True)
    assert ok and q == pytest.approx(2 * np.pi - 0.5, abs=1e-15)
    assert (qc, qs) == (c, s)  # the turn: the same numbers
    assert abs(qc - math.cos(q)) < 1e-15 and abs(qs - math.sin(q)) < 1e-15
    x = 1.0 + 5e-10  # onto the limit 1.0
    q, qc, qs, ok = G.into_limit_cs(x, math.cos(x), math.sin(x), -1.0, 1.0, True)
    assert ok and q == 1.0 and (qc, qs) == (math.cos(1.0), math.sin(1.0))
    x = 1.0 + 5e-10 + 2 * np.pi  # a turn, then onto the limit 1.0
    q, qc, qs, ok = G.into_limit_cs(x, math.cos(x), math.sin(x), -1.0, 1.0, True)
    assert ok and q == 1.0 and (qc, qs) == (math.cos(1.0), math.sin(1.0))


def test_results_pickle_with_their_singular_text(tmp_path):
    """A single and a batch result cross a process boundary (pickle) with `singular` evaluated:
    the singular PUMA pose keeps its text, a generic pose its None."""
    import pickle

    robot = puma560(tmp_path)
    T = np.stack(
        [
            _fk(robot, np.array(q))
            for q in ([0.2, 0.3, 0.4, 0.5, 0.0, 0.6], [0.2, 0.3, 0.4, 0.5, 0.7, 0.6])
        ]
    )
    one = pickle.loads(pickle.dumps(aa.ik.analytic(robot, T[0])))
    assert one.singular and "singular configuration" in one.singular
    batch = pickle.loads(pickle.dumps(aa.ik.analytic_batch(robot, T)))
    assert batch.singular[0] == one.singular and batch.singular[1] is None
    assert batch[0].singular == one.singular and batch[1].singular is None
    np.testing.assert_array_equal(batch[0].solutions, aa.ik.analytic_batch(robot, T)[0].solutions)


def test_local_frames_fk_is_pinocchios():
    """The FK of the compiled check (the chain as :func:`anthroarm.ik.fk.local_frames`, the
    product A_0 Rz(q1) A_1 ⋯ Rz(qn) A_n) is Pinocchio's tool pose, on 6- and 7-joint arms
    (panda's held 7th joint, human_arm7's SRS plan, kinova's continuous joints); where q is the
    joint angles, the Jacobian of the polish is Pinocchio's world-aligned frame Jacobian of the
    joints on the path."""
    from anthroarm.ik import families as fam

    rng = np.random.default_rng(11)
    for name in ("ur5", "kinova", "panda", "prosthetic_arm", "human_arm7"):
        robot = aa.load(name)
        plan = fam.srs_plan(robot) if name == "human_arm7" else G.plan_for(robot)
        A = plan.fk_frames if name == "human_arm7" else G._unpack(*plan.packed)[9]
        n = len(plan.fk_axes)
        for q in robot.random_q(10, rng=rng):
            th = np.empty(n)
            th[plan.order] = robot.angles(q)  # path order
            R, t = FK.chain_pose(A, th)
            F = _fk(robot, q)
            np.testing.assert_allclose(np.array(R), F[:3, :3], atol=1e-12, err_msg=name)
            np.testing.assert_allclose(np.array(t), F[:3, 3], atol=1e-12, err_msg=name)
            if robot.nq == n and name != "human_arm7":
                J = np.empty((6, n))
                FK.chain_fk_jacobian(A, th, J, np.empty((n, 6)), n)
                Jp = pin.computeFrameJacobian(
                    robot.model, robot.data, q, robot.tool_id, pin.LOCAL_WORLD_ALIGNED
                )
                np.testing.assert_allclose(
                    J, Jp[:, np.argsort(plan.order)], atol=1e-12, err_msg=name
                )


def test_target_errors_are_pinocchios():
    """The position and rotation errors the one-pose kernel reports with its nearest solution
    (what ``aa.ik.solve`` returns for a closed-form answer) are Pinocchio's ‖p* − p‖ and
    ‖log₃(Rᵀ R*)‖ of the same configuration, for targets off by up to a few cm and rotations
    up to and near π (where a cos-only formula loses its digits)."""
    robot = aa.load("ur5")
    plan = G.plan_for(robot)
    cf, ci = plan.packed
    n, A = ci[2], G._unpack(cf, ci)[9]
    rng = np.random.default_rng(7)
    for k, q in enumerate(robot.random_q(40, rng=rng)):
        F = pin.SE3(_fk(robot, q))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = [1e-7, 0.3, 2.0, np.pi - 1e-9, np.pi][k % 5]
        T = (F * pin.SE3(pin.exp3(angle * axis), rng.normal(scale=0.02, size=3))).homogeneous
        assert plan.order_is_path and robot.nq == n  # ur5: q is θ in path order
        pe, re = G._target_errors(A, q, np.ascontiguousarray(T))
        assert pe == pytest.approx(np.linalg.norm(T[:3, 3] - F.translation), abs=1e-13)
        assert re == pytest.approx(
            np.linalg.norm(pin.log3(F.rotation.T @ T[:3, :3])), abs=1e-9 if angle > 3 else 1e-13
        )


def test_continuous_joints_come_out_as_the_chains_configuration():
    """kinova (3 continuous joints, nq = 9): the configurations the compiled call writes (one
    pose and a batch) are Chain.configuration of their own angles (unit (cos, sin) pairs, to
    1e-15), and Pinocchio's FK of each is the pose."""
    robot = aa.load("kinova")
    ch = robot.chain
    T = np.array([_fk(robot, q) for q in robot.random_q(20, rng=5)])
    batch = aa.ik.analytic_batch(robot, T)
    for i in range(len(T)):
        one = aa.ik.analytic(robot, T[i])
        assert one.solutions.shape == (len(one), robot.nq) and len(one) > 0
        np.testing.assert_array_equal(one.solutions, batch.solutions[i][batch.valid[i]])
        th = ch.angles(one.solutions)[:, list(ch.independent)]
        np.testing.assert_allclose(one.solutions, ch.configuration(th), rtol=0, atol=1e-15)
        for q in one.solutions:
            assert np.abs(_fk(robot, q) - T[i])[:3].max() <= 1e-9
    assert np.isnan(batch.solutions[~batch.valid]).all()


def test_solve_answers_a_closed_class_from_the_compiled_call():
    """On a closed 6R class without a posture objective ``aa.ik.solve`` returns the closed form's
    solution nearest the comfortable posture with no Gauss–Newton iteration; its reported errors
    are Pinocchio's (recomputed here), and it is inside the limits."""
    for name in ("ur5", "prosthetic_arm", "kinova"):
        robot = aa.load(name)
        for q in robot.random_q(10, rng=3):
            T = _fk(robot, q)
            r = aa.ik.solve(robot, T)
            assert (
                r.success
                and r.seed == "analytic"
                and r.iterations == 0
                and robot.within_limits(r.q)
            ), name
            F = pin.SE3(_fk(robot, r.q))
            assert r.pos_err == pytest.approx(np.linalg.norm(T[:3, 3] - F.translation), abs=1e-14)
            assert r.rot_err == pytest.approx(
                np.linalg.norm(pin.log3(F.rotation.T @ T[:3, :3])), abs=1e-12
            )


@pytest.fixture(scope="module")
def panda_with_fingers(tmp_path_factory):
    """The panda URDF with its fingers (a tree: the hand's two prismatic joints, the second a
    mimic of the first, are off the path to panda_hand) and the catalog panda (fingers locked)."""
    arm = aa.load("panda")
    f = tmp_path_factory.mktemp("tree") / "panda_fingers.urdf"
    f.write_text(arm.info.text)
    return aa.load(str(f), tool=arm.tool), arm


def test_tree_is_solved_by_its_arm(panda_with_fingers):
    """A tree whose path to the tool is an arm with a closed form (here the panda's 7 joints,
    the fingers off the path) gets that arm's closed form: the same branches as the arm alone,
    every solution a configuration of the whole robot checked here by Pinocchio's FK, the joints
    off the path at the comfortable posture (the middle of the finger's range) or at q_rest."""
    robot, arm = panda_with_fingers
    assert robot.nq == 8 and closed_form_info(robot).family == closed_form_info(arm).family
    assert aa.ik.closed_form.held_joint(robot) == 6
    finger = robot.model.getJointId("panda_finger_joint1")
    iq = robot.model.joints[finger].idx_q
    mid = 0.5 * (robot.model.lowerPositionLimit[iq] + robot.model.upperPositionLimit[iq])
    for q in robot.random_q(8, rng=11):
        T = _fk(robot, q)
        res = aa.ik.analytic(robot, T, param=q[6])
        ref = aa.ik.analytic(arm, T, param=q[6])
        assert res.branches == ref.branches and len(res) >= 1
        assert np.array_equal(res.solutions[:, :7], ref.solutions)
        assert np.allclose(res.solutions[:, iq], mid)
        for x in res.solutions:
            assert np.abs(_fk(robot, x)[:3] - T[:3]).max() < 1e-9 and robot.within_limits(x)
        rest = q.copy()
        rest[iq] = 0.031
        assert np.allclose(
            aa.ik.analytic(robot, T, param=q[6], q_rest=rest).solutions[:, iq], 0.031
        )
    Ts = np.array([_fk(robot, q) for q in robot.random_q(6, rng=12)])
    b = aa.ik.analytic_batch(robot, Ts, param=0.3)
    assert b.solutions.shape == (6, b.valid.shape[1], 8)
    assert np.isnan(b.solutions[~b.valid]).all() and np.isfinite(b.solutions[b.valid]).all()
    with pytest.raises(ValueError, match="q_rest"):
        aa.ik.analytic(robot, Ts[0], param=0.3, q_rest=np.zeros(7))
    far = robot.neutral()
    far[iq] = 5.0  # the finger's range is [0, 0.04] m
    with pytest.raises(ValueError, match="panda_finger_joint1 outside the joint limits"):
        aa.ik.analytic(robot, Ts[0], param=0.3, q_rest=far)


def test_tree_solve_answers_from_the_arm(panda_with_fingers):
    """``aa.ik.solve`` on the tree seeds from its arm's closed form; the answer's errors are
    Pinocchio's and the finger stays at its reference (or the caller's q0)."""
    robot, _ = panda_with_fingers
    for q in robot.random_q(5, rng=13):
        T = _fk(robot, q)
        r = aa.ik.solve(robot, T)
        assert r.success and r.seed == "analytic" and robot.within_limits(r.q)
        F = pin.SE3(_fk(robot, r.q))
        assert r.pos_err == pytest.approx(np.linalg.norm(T[:3, 3] - F.translation), abs=1e-14)


def test_tree_keeps_a_mimic_joint_following_its_arm(tmp_path):
    """A joint off the path that mimics one on it (a finger coupled to the elbow) stays in the
    arm, following its source: the tree still has its arm's closed form, and every solution is
    a consistent configuration (the mimic where its source puts it) that Pinocchio's FK checks."""
    ur5 = aa.load("ur5")
    text = ur5.info.text
    link = '<link name="coupled_finger"/>'
    joint = (
        '<joint name="coupled" type="revolute"><parent link="forearm_link"/><child link="coupled_finger"/>'
        '<origin xyz="0 0.1 0" rpy="0 0 0"/><axis xyz="0 0 1"/>'
        '<limit effort="1" lower="-6.3" upper="6.3" velocity="1"/>'
        '<mimic joint="elbow_joint" multiplier="0.5" offset="0.1"/></joint>'
    )
    f = tmp_path / "ur5_coupled.urdf"
    f.write_text(text.replace("</robot>", link + joint + "</robot>"))
    robot = aa.load(str(f), tool=ur5.tool, check_meshes=False)
    assert aa.ik.has_analytic(robot)
    for q in robot.random_q(5, rng=21):
        T = _fk(robot, q)
        res = aa.ik.analytic(robot, T)
        assert len(res) >= 1
        for x in res.solutions:
            assert np.abs(_fk(robot, x)[:3] - T[:3]).max() < 1e-9
            th = robot.chain.angles(x)[list(robot.chain.independent)]
            assert np.allclose(robot.chain.configuration(th), x)


def test_first_solve_is_not_charged_for_loading_the_kernel():
    """The compiled attempt kernel is loaded (from the disk cache, or built) before the clock
    of ``max_time`` starts: the first solve of a fresh process, from a q0 16 iterations away,
    has its whole 2 ms of CPU (loading the kernel alone takes 2–5 ms)."""
    import subprocess
    import sys

    code = (
        "import numpy as np, anthroarm as aa\n"
        "robot = aa.load('panda')\n"
        "T = robot.fk(robot.random_q(rng=4))\n"
        "r = aa.ik.solve(robot, T, q0=robot.random_q(rng=9), analytic=False, max_time=0.002)\n"
        "print(r.success, r.status)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[0] == "True", out.stdout


def test_tree_without_a_closed_form_says_how_to_get_one():
    """A humanoid's arm with the torso on the path (9 joints) has no closed form; the message
    says to lock joints on the path; with the torso locked the 7-joint arm has one."""
    talos = aa.load("talos", tool="gripper_left_base_link")
    assert not aa.ik.has_analytic(talos)
    with pytest.raises(UnsupportedModelError, match="lock joints on the path"):
        aa.ik.analytic(talos, talos.fk(talos.neutral()))
    locked = aa.load(
        "talos", tool="gripper_left_base_link", locked=["torso_1_joint", "torso_2_joint"]
    )
    assert aa.ik.has_analytic(locked) and closed_form_info(locked).param
    q = locked.random_q(rng=14)
    res = aa.ik.analytic(
        locked,
        _fk(locked, q),
        param=float(q[locked.chain.joints[locked.chain.path(locked.tool_id)[-1]].idx_q]),
    )
    assert len(res) >= 1
    for x in res.solutions:
        assert np.abs(_fk(locked, x)[:3] - _fk(locked, q)[:3]).max() < 1e-9


@pytest.mark.parametrize(
    "name, tip, family",
    [("talos", "left_sole_link", C.SPHERICAL_TWO_PARALLEL), ("solo8", "HR_FOOT", "planar_2r")],
)
def test_legs_of_a_humanoid_and_a_quadruped_in_closed_form(name, tip, family):
    """Trees from example-robot-data: the humanoid's 6R leg (32 joints in all) and the
    quadruped's 2R leg (position only) are solved by the closed form of the joints on the path
    to the foot; every solution, a configuration of the whole robot, is checked by Pinocchio's
    FK, the other joints where q_rest puts them."""
    robot = aa.load(name, tool=tip)
    info = closed_form_info(robot)
    assert info is not None and info.family == family
    on = [robot.chain.joints[j].idx_q for j in robot.chain.path(robot.tool)]
    for q in robot.random_q(6, rng=41):
        T = _fk(robot, q)
        res = aa.ik.analytic(robot, T, q_rest=q)
        assert len(res) >= 1
        for x in res.solutions:
            F = _fk(robot, x)
            err = (
                np.abs(F[:3, 3] - T[:3, 3]).max()
                if info.position_only
                else np.abs(F[:3] - T[:3]).max()
            )
            assert err < 1e-9 and robot.within_limits(x)
            assert np.array_equal(np.delete(x, on), np.delete(q, on))


def test_any_tip_of_a_tree_by_frame():
    """``frame=`` solves another tip of a tree than its tool — the other foot of a humanoid —
    with that tip's closed form; ``aa.ik.solve(frame=...)`` seeds from it; a tip without one says
    why; an unknown frame is a typed error."""
    from anthroarm.errors import UnknownFrameError
    from anthroarm.ik.closed_form import require_form

    talos = aa.load("talos", tool="left_sole_link")
    assert closed_form_info(talos, "right_sole_link").family == C.SPHERICAL_TWO_PARALLEL
    fid = talos.model.getFrameId("right_sole_link")
    data = talos.model.createData()
    for q in talos.random_q(5, rng=51):
        pin.framesForwardKinematics(talos.model, data, q)
        T = data.oMf[fid].homogeneous.copy()
        res = aa.ik.analytic(talos, T, frame="right_sole_link", q_rest=q)
        assert len(res) >= 1
        for x in res.solutions:
            pin.framesForwardKinematics(talos.model, data, x)
            assert np.abs(
                data.oMf[fid].homogeneous[:3] - T[:3]
            ).max() < 1e-9 and talos.within_limits(x)
        batch = aa.ik.analytic_batch(talos, T[None], frame=fid)
        assert batch.valid.sum() == len(aa.ik.analytic(talos, T, frame=fid))
        r = aa.ik.solve(talos, T, frame="right_sole_link")
        assert r.success and r.seed == "analytic" and talos.within_limits(r.q)
    assert not aa.ik.has_analytic(talos, "gripper_left_base_link")
    with pytest.raises(UnsupportedModelError, match="lock joints on the path"):
        require_form(talos, "gripper_left_base_link")
    with pytest.raises(UnknownFrameError):
        aa.ik.analytic(talos, np.eye(4), frame="no_such_frame")
    with pytest.raises(UnsupportedModelError, match="no joint moves the frame 'base_link'"):
        require_form(talos, "base_link")


def test_frame_keeps_the_comfortable_posture_and_refuses_a_shared_name():
    """``frame=`` solves with the robot's own spec (its comfortable posture for the joints off
    the frame's path, as ``aa.load(..., tool=frame)`` would); a frame whose name an earlier frame
    also has cannot be the closed form's tool (it would be the other one): a typed error, and
    ``aa.ik.solve`` for it stays numerical with errors that are the frame's own."""
    from anthroarm.ik.qp.tasks.posture import comfortable_posture

    arm = aa.load("human_arm7")
    frame = "wrist_deviation"
    assert aa.ik.has_analytic(arm, frame)
    on = [arm.chain.joints[j].idx_q for j in arm.chain.path(frame)]
    q = arm.random_q(rng=61)
    res = aa.ik.analytic(arm, arm.fk(q, frame), frame=frame)
    assert len(res) >= 1
    assert np.array_equal(
        np.delete(res.solutions, on, axis=1)[0], np.delete(comfortable_posture(arm), on)
    )
    m = arm.model.copy()
    hand = m.frames[m.getFrameId("hand")]
    dup = m.addFrame(
        pin.Frame(
            "hand",
            hand.parentJoint,
            m.getFrameId("hand"),
            hand.placement * pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1])),
            pin.FrameType.OP_FRAME,
        )
    )
    robot = aa.Robot(m, name="dup", tool=arm.tool)
    assert robot.chain.frame(dup).index == dup != robot.chain.frame("hand").index
    T = robot.fk(robot.random_q(rng=62), dup)
    assert not aa.ik.has_analytic(robot, dup)
    with pytest.raises(UnsupportedModelError, match="shares its name 'hand'"):
        aa.ik.analytic(robot, T, frame=dup)
    r = aa.ik.solve(robot, T, frame=dup, posture=None)
    assert r.success and r.seed != "analytic"
    assert r.pos_err == pytest.approx(
        np.linalg.norm(robot.fk(r.q, dup)[:3, 3] - T[:3, 3]), abs=1e-12
    )


def _special_q(robot, n, seed):
    """Configurations with joints at 0, ±π/2, ±π, just inside ±π, on a limit or 1e-11 inside it
    (singular wrists, stretched elbows, angles at the wrap) — where a branch's angle may be
    shifted by 2π or put onto a limit after the class solver found it."""
    rng = np.random.default_rng(seed)
    Q = robot.random_q(n, rng=rng)
    lo, hi = robot.lower, robot.upper
    for q in Q:
        for j in range(robot.nq):
            if rng.random() < 0.4:
                q[j] = rng.choice(
                    [
                        0.0,
                        PI / 2,
                        -PI / 2,
                        PI,
                        -PI,
                        PI - 1e-12,
                        lo[j],
                        hi[j],
                        lo[j] + 1e-11,
                        hi[j] - 1e-11,
                    ]
                )
        np.clip(q, lo, hi, out=q)
    return Q


def test_reported_residuals_are_pinocchios_of_the_returned_angles(tmp_path):
    """Every ``residuals`` entry is Pinocchio's max |FK(q) − T| over the 3×4 pose of the very
    ``q`` returned (to 1e-12), and ≤ tol — on random and special configurations (joints on a
    limit of ±π, wrists aligned), at the default tol and at 1e-11.  The FK check had reported
    the residual of a polished candidate before its joint was put onto a limit (a PUMA 560 with
    q1 = −π at q5 = 0: reported 2.6e-16, true 5.5e-10, returned at tol = 1e-11)."""
    puma = puma560(tmp_path)
    arms = [
        puma,
        aa.load("ur5"),
        aa.load("sixr_arm"),
        aa.load("prosthetic_arm"),
        aa.load("talos_arm"),
    ]
    T0 = _fk(puma, np.array([-PI, 1.970655768409248, 2.511687152757056, 0.0, 0.0, PI - 1e-12]))
    checked = 0
    for robot in arms:
        Ts = [
            _fk(robot, q) for q in np.vstack([robot.random_q(20, rng=2), _special_q(robot, 40, 3)])
        ]
        if robot is puma:
            Ts.append(T0)
        for tol in (1e-9, 1e-11):
            for T in Ts:
                r = aa.ik.analytic(robot, T, tol=tol)
                for q, res in zip(r.solutions, r.residuals):
                    e = np.abs(_fk(robot, q)[:3] - T[:3]).max()
                    assert abs(e - res) <= 1e-12 and e <= tol, (robot.name, tol, res, e)
                    checked += 1
    assert checked > 2000


def test_carried_cos_sin_are_those_of_the_returned_angle(tmp_path):
    """The class solvers carry each angle as (θ, cos θ, sin θ), the rotation the subproblem
    found: cos and sin must be those of the θ they return (the FK check rotates by them), on
    every closed class — reversed chains, axes 3 and 4 antiparallel to 2 (the sign flips of the
    three-parallel tail), singular poses where a subproblem returns (0, 1, 0)."""
    arms = [
        puma560(tmp_path),
        aa.load("ur5"),
        aa.load("prosthetic_arm"),
        aa.load("talos_arm"),
        aa.load("kinova"),
        random_arm(tmp_path, C.SPHERICAL, 4),
        random_arm(tmp_path, C.THREE_PARALLEL, 5),
        dh_urdf(
            tmp_path,
            "ur5_antiparallel",
            [PI / 2, 0, PI, PI / 2, -PI / 2, 0],
            [0, -0.425, 0.392, 0, 0, 0],
            [0.089, 0, 0, 0.109, 0.095, 0.082],
        ),
    ]
    rows = 0
    for robot in arms:
        plan = G.plan_for(robot)
        cls, rev, n, H, P = G._unpack(*plan.packed)[:5]
        Q = np.vstack([robot.random_q(30, rng=6), _special_q(robot, 30, 7)])
        T = np.array([_fk(robot, q) for q in Q])
        R06, p06 = G.class_pose(plan, T, None if plan.param_joint is None else 0.0)
        B = np.empty((8, G.BRANCH_ROW))
        for i in range(len(T)):
            G._solve_closed(
                cls, G.rows6(H), G.rows7(P), G.mat(np.ascontiguousarray(R06[i])), G.vec(p06[i]), B
            )
            ex = B[:, G.EXISTS] != 0
            th = B[ex, :6]
            np.testing.assert_allclose(
                B[ex, G.COS : G.COS + 6], np.cos(th), atol=1e-14, err_msg=robot.name
            )
            np.testing.assert_allclose(
                B[ex, G.SIN : G.SIN + 6], np.sin(th), atol=1e-14, err_msg=robot.name
            )
            rows += int(ex.sum())
    assert rows > 2000


def test_srs_single_pose_is_the_batch_row():
    """The SRS arm's one-pose path (one compiled call) gives exactly the batch path's row:
    solutions, labels, swivel angles, residuals and reasons — at one angle and on the default
    grid, with and without a solution."""
    from anthroarm.ik.qp.tasks.swivel import swivel_angle

    robot = aa.load("human_arm7")
    Q = robot.random_q(40, rng=8)
    for q in Q:
        T = _fk(robot, q)
        a0 = swivel_angle(robot, q)
        for sw in (a0, float(a0), 2.5):  # a numpy scalar (general path), floats (one call)
            a, b = (
                aa.ik.analytic(robot, T, swivel=sw),
                aa.ik.analytic_batch(robot, T[None], swivel=sw)[0],
            )
            assert a.branches == b.branches and a.reason == b.reason
            for x, y in (
                (a.solutions, b.solutions),
                (a.swivel, b.swivel),
                (a.residuals, b.residuals),
            ):
                np.testing.assert_array_equal(x, y)
    for q in Q[:5]:
        T = _fk(robot, q)
        a, b = aa.ik.analytic(robot, T), aa.ik.analytic_batch(robot, T[None], _single_grid=True)[0]
        assert a.branches == b.branches and len(a) > 0
        np.testing.assert_array_equal(a.solutions, b.solutions)
        np.testing.assert_array_equal(a.swivel, b.swivel)


def test_batch_singular_is_that_of_the_solutions_found():
    """``singular`` of a batch result describes the solutions the call found: the arrays it
    reads later (``solutions``, ``valid``) are read-only, so a caller cannot change them under
    it (they had been writable, and shared); the per-pose results are writable copies."""
    robot = aa.load("ur5")
    T = _fk(robot, np.array([0.3, -1.2, 1.4, -0.5, 1.1, 0.2]))[None]
    B = aa.ik.analytic_batch(robot, T)
    for name in ("solutions", "valid", "residuals"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(B, name)[0, 0] = 0.0
    assert B[0].singular is None
    one = B[0]
    one.solutions[0, 4] = 0.0  # a copy: the batch is unchanged
    assert B.solutions[0, 0, 4] != 0.0 and B[0].singular is None
    tree = aa.load("human_upper_limb")  # a tree's result, mapped onto the robot
    Bt = aa.ik.analytic_batch(tree, _fk(tree, tree.random_q(rng=3))[None])
    with pytest.raises(ValueError, match="read-only"):
        Bt.solutions[0, 0] = 0.0


def test_limits_reason_names_the_limits_of_the_joints_solved_for():
    """kinova (continuous joints: q holds cos/sin pairs, nq = 9 ≠ 6): a pose whose every solution
    violates the limits is reported with the six joints' own limits (oracle: the URDF's, read
    here from the chain), the continuous ones as such — not with the bounds of q's cos/sin
    entries."""
    robot = aa.load("kinova")
    ch = robot.chain
    rng = np.random.default_rng(0)
    texts = []
    for _ in range(20):
        th = rng.uniform(-np.pi, np.pi, 6)
        th[1] = 0.3  # joint 2 below its lower limit 0.82
        r = aa.ik.analytic(robot, robot.fk(ch.configuration(th)))
        if len(r) == 0:
            texts.append(r.reason)
    assert texts
    for text in texts:
        assert "violate the joint limits" in text
        for j in ch.independent:
            joint = ch.joints[j]
            want = (
                "continuous"
                if joint.kind == "continuous"
                else f"[{joint.lower:.4g}, {joint.upper:.4g}]"
            )
            assert f"{joint.name} {want}" in text
        assert "[-1, 1]" not in text


def test_a_single_precision_pose_is_a_near_miss_not_outside_the_workspace():
    """A reachable pose rounded to float32 is no rigid transform to 1e-9 (its rotation is
    orthonormal to ~1e-8): no solution at the default tol, and the reason says it was missed by
    ~1e-8 and how to accept it — not "outside the workspace"; with tol = 1e-6 every branch comes
    back, each within 1e-6 of the rounded pose by Pinocchio's FK (ur5, sixr_arm, human_arm7)."""
    from anthroarm.ik import swivel_angle

    for name in ("ur5", "sixr_arm", "human_arm7"):
        robot = aa.load(name)
        q = robot.random_q(rng=2)
        kw = {"swivel": float(swivel_angle(robot, q[None])[0])} if name == "human_arm7" else {}
        T32 = _fk(robot, q).astype(np.float32)
        r = aa.ik.analytic(robot, T32, **kw)
        assert len(r) == 0 and r.reason.startswith("not reached to tol = 1e-09"), (name, r.reason)
        assert "outside the workspace" not in r.reason and "larger tol" in r.reason
        r = aa.ik.analytic(robot, T32, tol=1e-6, **kw)
        assert len(r) > 0, (name, r.reason)
        for x in r.solutions:
            assert np.abs(_fk(robot, x) - T32).max() <= 1e-6
    far = _fk(aa.load("ur5"), aa.load("ur5").random_q(rng=2))
    far[:3, 3] *= 3.0
    assert aa.ik.analytic(aa.load("ur5"), far).reason.startswith("outside the workspace")


def test_a_reachable_pose_at_a_tangent_root_is_solved():
    """A pose reached by a configuration inside the limits has a solution, also where a
    subproblem's two roots meet (panda's shoulder at q2 = 0, joints on their limits): its only
    in-limit candidates are least-squares roots off by ~1e-8, which the compiled Newton polish
    takes to the pose (FK-verified); they had been dropped with 'all 6 closed-form solutions
    violate the joint limits'."""
    robot = aa.load("panda")
    lo, hi = robot.lower, robot.upper
    Q = [
        np.array(
            [
                -2.8973,
                1e-13,
                2.89729999999,
                -1.7704468480934643,
                2.8973,
                2.127241565806812,
                2.897299999,
            ]
        )
    ]
    rng = np.random.default_rng(12)
    for q in robot.random_q(60, rng=rng):
        q[1] = rng.choice([0.0, 1e-13, -1e-13])  # the shoulder singularity
        for j in (0, 2, 4, 6):
            if rng.random() < 0.5:
                q[j] = rng.choice([lo[j], hi[j]])
        Q.append(q)
    for q in Q:
        T = _fk(robot, q)
        r = aa.ik.analytic(robot, T, param=float(q[6]))
        assert len(r) > 0, (q.tolist(), r.reason)
        for s in r.solutions:
            assert np.abs(_fk(robot, s)[:3] - T[:3]).max() <= 1e-9 and robot.within_limits(s)


@pytest.mark.parametrize("layout", ["fortran", "misaligned", "read_only", "list", "strided_view"])
def test_every_array_layout_of_one_pose_gets_the_same_solutions(layout):
    """One pose reaches the compiled call unchecked by Numba's dispatcher (jit.entry_point) only
    as a C-order, aligned float64 4×4 array; any other layout of the same pose (Fortran order,
    an unaligned buffer, a strided view, a list, a read-only array) is copied or answered by the
    general path — with the same solutions, each verified here by Pinocchio FK."""
    robot = aa.load("ur5")
    q = robot.random_q(1, rng=11)[0]
    T = _fk(robot, q)
    ref = aa.ik.analytic(robot, T)
    assert len(ref) >= 1
    if layout == "fortran":
        X = np.asfortranarray(T)
    elif layout == "misaligned":
        X = np.ndarray((4, 4), dtype=np.float64, buffer=bytearray(16 * 8 + 1), offset=1)
        X[...] = T
        assert not X.flags.aligned
    elif layout == "read_only":
        X = T.copy()
        X.flags.writeable = False
    elif layout == "list":
        X = T.tolist()
    else:
        big = np.zeros((4, 8))
        big[:, ::2] = T
        X = big[:, ::2]
    got = aa.ik.analytic(robot, X)
    assert got.branches == ref.branches and np.array_equal(got.solutions, ref.solutions)
    assert np.array_equal(got.residuals, ref.residuals)
    for s in got.solutions:
        assert np.abs(_fk(robot, s) - T)[:3].max() <= 1e-9


def test_entry_point_is_the_kernel_for_those_types():
    """jit.entry_point gives the compiled body the dispatcher itself would call for those
    argument types: the same outputs as the dispatcher on a pose of ur5 (the branch mask, and in
    each solution row θ, the FK residual and the branch; the rest of ``out`` left untouched) —
    for the kernel aa.ik.analytic calls (geometric.pose_solutions), and its result is
    analytic's."""
    from anthroarm import jit

    robot = aa.load("ur5")
    T = np.ascontiguousarray(_fk(robot, robot.random_q(1, rng=5)[0]))
    cf, ci = G.plan_for(robot).packed
    a, b = np.full((8, 10), np.nan), np.full((8, 10), np.nan)
    call = jit.entry_point(G.pose_solutions, cf, ci, T, 0.0, 1e-9, 1e-6, a)
    m1 = call(cf, ci, T, 0.0, 1e-9, 1e-6, a)
    m2 = G.pose_solutions(cf, ci, T, 0.0, 1e-9, 1e-6, b)
    assert m1 == m2 > 0
    res = aa.ik.analytic(robot, T)
    assert np.array_equal(res.solutions, a[: len(res), :6]) and np.array_equal(
        res.residuals, a[: len(res), 6]
    )
    K = bin(m1).count("1")
    assert np.array_equal(a, b, equal_nan=True) and not np.isnan(a[:K, :8]).any()


def test_singular_text_of_a_tree_is_that_of_its_arms_solutions():
    """A tree's one-pose result holds the robot's configurations, but its ``singular`` is that
    of the arm's solutions — as the batch path and the leg alone say.  talos's right leg with
    the knee straight (singular: normalised |det J| of the leg ≈ 0, Pinocchio-free check: the
    leg solved alone) and bent (not singular), the left leg folded off the path; the fast
    path's maker once read the robot's q as the leg's θ and called the straight knee regular."""
    robot = aa.load("talos", tool="right_sole_link")
    arm = aa.ik.closed_form._solver(robot).arm.robot
    on = [robot.chain.joints[j].idx_q for j in robot.chain.path(robot.tool)]
    for knee, singular in ((1e-7, True), (0.8, False)):
        q = robot.neutral().copy()
        q[on[3]] = knee
        q[:6] = [0, 0, -0.4, 1.0, -0.5, 0]
        T = _fk(robot, q)
        one = aa.ik.analytic(robot, T, q_rest=q)
        row = aa.ik.analytic_batch(robot, T[None], q_rest=q)[0]
        alone = aa.ik.analytic(arm, T)
        assert len(one) >= 1
        assert (
            (one.singular is not None)
            == (row.singular is not None)
            == (alone.singular is not None)
            == singular
        )
