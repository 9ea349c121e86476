"""hand.solve_grasp on the Allegro hand and on the 27-DOF human upper limb (arm + hand).

Every answer is checked here, independently of the solver: fingertip poses from Pinocchio FK
(a fresh pin.Data), the distance to the object and its outward normal from the geometry of the
sphere/cylinder written out in this file, the limits from robot.lower/upper.  Success = every
fingertip within 1 mm (of the surface, or of its contact point), pad normal within 5° of the
inward normal, inside the limits (the issue's criteria)."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import CouplingError, FingertipError, GraspError
from anthroarm.hand import Cylinder, Hand, Sphere, solve_grasp
from anthroarm.hand.problems import open_hand, reachable_grasps
from anthroarm.ik import qp
from anthroarm.ik.qp.tasks.posture import comfortable_posture

MM, DEG5 = 1e-3, np.radians(5.0)


@pytest.fixture(scope="module")
def allegro():
    return aa.load("allegro_right_hand", tool="link_3.0_tip")


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def _geometry(obj, p):
    """(signed distance, outward normal) at p, from the primitive's definition."""
    if isinstance(obj, Sphere):
        w = p - obj.center
    else:
        u = obj.axis
        w = (p - obj.center) - ((p - obj.center) @ u) * u
    rho = np.linalg.norm(w)
    return rho - obj.radius, w / rho


def _check(robot, hand, obj, q, contacts=None):
    """Assert the issue's criteria at q from Pinocchio FK and the geometry."""
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    assert np.all(q >= robot.lower - 1e-9) and np.all(q <= robot.upper + 1e-9)
    for k, f in enumerate(hand.fingers):
        M = d.oMf[robot.model.getFrameId(f.tip)]
        p = M.translation
        if contacts is None:
            dist, m = _geometry(obj, p)
            assert abs(dist) <= MM, f.tip
        else:
            c = contacts[k]
            assert np.linalg.norm(p - c) <= MM, f.tip
            dist_c, m = _geometry(obj, c)
            assert abs(dist_c) < 1e-12
        pad = M.rotation @ f.pad_axis
        assert np.arccos(np.clip(-pad @ m, -1, 1)) <= DEG5, f.tip


def test_allegro_cylinder_sliding_contacts(allegro):
    hand = Hand(allegro)
    problems = reachable_grasps(allegro, 4, rng=1, hand=hand)
    assert len(problems) == 4
    q0 = open_hand(allegro, hand)
    for pb in problems:
        _check(allegro, hand, pb.obj, pb.witness)  # the witness is one
        res = solve_grasp(allegro, pb.obj, hand=hand, q0=q0)
        assert res.success and res.status == "success", res
        _check(allegro, hand, pb.obj, res.q)
        assert res.position_errors.max() <= MM and res.normal_errors.max() <= DEG5


def test_allegro_sphere_tripod_given_contacts(allegro):
    hand = Hand(allegro, tips=["link_3.0_tip", "link_7.0_tip", "link_15.0_tip"])
    problems = reachable_grasps(allegro, 3, kind="sphere", rng=5, hand=hand, radius=(0.02, 0.05))
    assert len(problems) == 3
    q0 = open_hand(allegro, hand)
    for pb in problems:
        res = solve_grasp(allegro, pb.obj, pb.contacts, hand=hand, q0=q0)
        assert res.success, res
        _check(
            allegro,
            hand,
            pb.obj,
            res.q,
            contacts=np.array([pb.obj.project(c) for c in pb.contacts]),
        )


def test_limb_arm_and_hand_cylinder(limb):
    """Five fingertips on a cylinder that the witness reaches with a random arm pose; the
    solver starts from the comfortable arm posture with the hand open."""
    hand = Hand(limb)
    problems = reachable_grasps(limb, 8, rng=11, hand=hand, per_hand=4)
    assert len(problems) == 8
    q0 = open_hand(limb, hand, comfortable_posture(limb))
    for pb in problems:
        on_surface = np.array([pb.obj.project(c) for c in pb.contacts])  # what solve_grasp aims at
        _check(limb, hand, pb.obj, pb.witness, contacts=on_surface)  # the witness is one
        res = solve_grasp(limb, pb.obj, pb.contacts, hand=hand, q0=q0)
        assert res.success, res
        _check(limb, hand, pb.obj, res.q, contacts=on_surface)
        assert (
            np.abs(res.q[hand.arm_q_indices] - q0[hand.arm_q_indices]).max() > 0.1
        )  # the arm moved


def test_hard_coupling_holds(allegro):
    """joint_2.0 = joint_3.0 (a linkage written as a linear relation) as a hard constraint: the
    answer keeps it exactly; a start that breaks it is a CouplingError."""
    hand = Hand(allegro)
    pb = reachable_grasps(allegro, 1, rng=2, hand=hand)[0]
    c = qp.JointCouplingTask.mimic(allegro, "joint_3.0", "joint_2.0")
    q0 = open_hand(allegro, hand)
    q0[3] = q0[2]
    res = solve_grasp(allegro, pb.obj, hand=hand, q0=q0, couplings=[c])
    assert res.status in ("success", "stalled", "max_iterations")
    assert abs(res.q[3] - res.q[2]) < 1e-8
    assert np.isfinite(res.q).all()
    bad = q0.copy()
    bad[3] = bad[2] + 0.3
    with pytest.raises(CouplingError, match="coupling"):
        solve_grasp(allegro, pb.obj, hand=hand, q0=bad, couplings=[c])


def test_bad_grasps(allegro, limb):
    hand = Hand(allegro)
    with pytest.raises(GraspError, match="span"):
        solve_grasp(allegro, Sphere([0.1, 0.0, 0.05], 0.5 * hand.span + 0.01), hand=hand)
    with pytest.raises(GraspError, match="one point"):
        solve_grasp(allegro, Cylinder([0.1, 0, 0], [0, 1, 0], 0.03), np.zeros((3, 3)), hand=hand)
    with pytest.raises(GraspError):
        solve_grasp(allegro, "a cup")
    with pytest.raises(FingertipError, match="not a fingertip"):
        solve_grasp(allegro, Sphere([0.1, 0.0, 0.05], 0.03), tips=["link_3.0_tip", "link_2.0"])
    with pytest.raises(FingertipError):
        solve_grasp(limb, Sphere([0.1, 0.0, 0.05], 0.03), tips=["index_tip", "palm"])
    with pytest.raises(ValueError):
        solve_grasp(allegro, Sphere([0.1, 0.0, 0.05], 0.03), max_step=np.nan)
    # out of reach: a status, finite numbers, no exception
    res = solve_grasp(
        allegro, Sphere([2.0, 0.0, 0.0], 0.03), hand=hand, restarts=1, max_iterations=60
    )
    assert not res.success and res.status in ("stalled", "max_iterations")
    assert np.isfinite(res.q).all() and np.isfinite(res.position_errors).all() and res.within_limits
    assert res.position_errors.min() > 1.0  # metres away, as the geometry says


def test_grasp_overlays(allegro):
    """The drawn cylinder's axis (meshcat's y) is the object's axis, the frame is a rotation;
    show_grasp puts the object, points and arrows into the viewer's scene."""
    from anthroarm.hand.overlays import object_transform, show_grasp

    cyl = Cylinder([0.1, 0.02, 0.0], [0.3, -1.0, 0.2], 0.03)
    T = object_transform(cyl)
    np.testing.assert_allclose(T[:3, 1], cyl.axis, atol=1e-15)
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-15)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)
    np.testing.assert_allclose(T[:3, 3], cyl.center)
    v = aa.viewer.Viewer(allegro)
    contacts = np.array([cyl.point(a, 0.01) for a in (0.0, 1.0, 2.0, 3.0)])
    show_grasp(v, cyl, contacts, name="cup")
    import base64
    import json
    import re

    import umsgpack

    m = re.search(r"var cmds = (\[.*?\]);", v.static_html(), re.S)  # the page's replayed commands
    cmds = [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]
    paths = {c["path"]: c for c in cmds if c["type"] in ("set_object", "set_transform")}
    obj = f"{v.root}/overlays/cup_object"
    assert paths[obj]["type"] in ("set_object", "set_transform")
    assert any(p.startswith(f"{v.root}/overlays/cup_points") for p in paths)
    assert any(p.startswith(f"{v.root}/overlays/cup_normals") for p in paths)
    geo = [c for c in cmds if c["type"] == "set_object" and c["path"] == obj][0]["object"][
        "geometries"
    ][0]
    assert geo["type"] == "CylinderGeometry" and geo["radiusTop"] == pytest.approx(0.03)
    with pytest.raises(TypeError):
        show_grasp(v, "a cup", contacts)
