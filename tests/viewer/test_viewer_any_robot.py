"""The viewer on robots a user brings (issue 11): example-robot-data arms by name, baxter's
left arm and the allegro hand (tool=), continuous joints (kinova), mimic joints (baxter's
fingers, a user URDF), and robots given as a ``pin.Model`` with or without a visual model.

Oracles: Pinocchio's ``oMi`` / ``oMf`` of the joint or link each body is named after, looked up
by name in ``robot.model`` with a fresh ``pin.Data`` (not through ``robot.chain``);
``pin.updateGeometryPlacements`` (``oMg``) for the pieces of a visual model; yourdfpy (an
independent URDF parser) for the link bodies of URDF robots; the URDF's own numbers for a
mimic joint.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.errors import ViewerError
from anthroarm.viewer import Viewer
from anthroarm.viewer.meshes import PackedMesh, mesh_placement


def _user_urdf() -> str:
    """The user URDF of the chain tests (continuous joints and a mimic finger), one copy."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "_chain_tests", Path(__file__).parents[1] / "foundation" / "test_chain.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.USER_URDF


ROBOTS = {
    "panda": {},
    "ur5": {},
    "ur10": {},
    "xarm7": {},
    "z1": {},
    "so101": {"tool": "gripper_frame_link"},
    "kinova": {},
    "baxter": {"tool": "left_gripper"},
    "allegro_right_hand": {"tool": "link_3.0_tip"},
}


class Recorder:
    """Stands in for the server: records every message the viewer sends."""

    def __init__(self):
        self.messages = []

    def send_many(self, cmds):
        self.messages.append(list(cmds))


@pytest.fixture(scope="module")
def user_robot(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(_user_urdf())
    return aa.load(str(p), tool="tool")


def sent_transforms(v: Viewer, q) -> dict:
    v.server = rec = Recorder()
    v.display(q)
    v.server = None
    assert len(rec.messages) == 1
    return {
        c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T
        for c in rec.messages[0]
        if c["type"] == "set_transform"
    }


def pinocchio_pose(robot, data, body) -> np.ndarray:
    """oMi of the joint / oMf of the link the body is named after, found by name."""
    model = robot.model
    if body.joint is not None:
        return data.oMi[model.getJointId(body.name)].homogeneous
    return data.oMf[model.getFrameId(body.name, pin.FrameType.BODY)].homogeneous


def check_against_pinocchio(robot, v: Viewer, q) -> int:
    sent = sent_transforms(v, q)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    moving = [b for b in v.bodies if b.joint is not None or b.frame is not None]
    assert set(sent) == {v._bpath(b) for b in moving}
    for b in moving:
        np.testing.assert_allclose(
            sent[v._bpath(b)], pinocchio_pose(robot, data, b), atol=1e-12, err_msg=b.name
        )
    return len(moving)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_example_robot_data_scene_matches_pinocchio_and_yourdfpy(name):
    robot = aa.load(name, **ROBOTS[name])
    v = Viewer(robot)
    meshes = [p for b in v.bodies for p in b.pieces if p.group == "mesh"]
    assert meshes, "a URDF with meshes keeps its meshes"
    u = robot.urdf
    for q in robot.random_q(3, rng=11):
        assert check_against_pinocchio(robot, v, q) >= 4
        sent = sent_transforms(v, q)
        u.update_cfg(robot.yourdfpy_cfg(q))
        for b in v.bodies:
            if b.frame is not None and b.name in u.link_map:
                np.testing.assert_allclose(
                    sent[v._bpath(b)], u.get_transform(b.name), atol=1e-12, err_msg=b.name
                )


def test_kinova_continuous_joints_display_and_limit_colours():
    robot = aa.load("kinova")
    cont = [j for j in robot.chain.joints if j.kind == "continuous"]
    assert len(cont) == 3 and robot.nq == 9
    v = Viewer(robot)
    q = robot.random_q(rng=4)
    # a configuration given by its (cos, sin) pairs is drawn; a whole turn draws the same arm
    sent = sent_transforms(v, q)
    theta = robot.chain.angles(q)
    theta[[j.index for j in cont]] += 2 * np.pi
    q_turned = robot.chain.configuration(theta[list(robot.chain.independent)])
    again = sent_transforms(v, q_turned)
    for path, T in sent.items():
        np.testing.assert_allclose(again[path], T, atol=1e-12)
    with pytest.raises(ValueError, match=cont[0].name):
        bad = q.copy()
        bad[cont[0].idx_q] *= 2
        v.display(bad)
    # limits: the bounded joints at their upper limit, every continuous joint at an angle
    # where (cos, sin) = (-1, 0) (a q entry at Pinocchio's bound): only bounded links turn red
    v.show_limits()
    th = np.array([j.upper if j.kind != "continuous" else np.pi for j in robot.chain.joints])
    qlim = robot.chain.configuration(th[list(robot.chain.independent)])
    v.server = rec = Recorder()
    v.display(qlim)
    red = {c["path"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    by_kind = {}
    for b in v.bodies:
        if b.frame is not None:
            j = robot.chain.frames[b.frame].joint
            if j >= 0:
                by_kind.setdefault(robot.chain.joints[j].kind, set()).add(f"{v._bpath(b)}/mesh")
    assert by_kind["revolute"] <= red
    assert not (by_kind["continuous"] & red)


def test_user_urdf_continuous_and_mimic(user_robot):
    robot = user_robot
    assert robot.chain.kind_counts() == {"revolute": 2, "prismatic": 0, "continuous": 2, "mimic": 1}
    v = Viewer(robot)
    assert {p.group for b in v.bodies for p in b.pieces} >= {
        "links",
        "joint",
        "axis",
        "palm",
    }  # the skeleton
    for q in robot.random_q(4, rng=5):
        check_against_pinocchio(robot, v, q)
    # the mimic finger follows its source: θ_mimic = -θ_grip + 0.1 about x, from the URDF numbers
    grip = robot.chain.joint("grip")
    body_b = next(b for b in v.bodies if b.name == "grip_mimic")
    body_l3 = next(b for b in v.bodies if b.name == "wrist")
    q = robot.random_q(rng=6)
    for g in (0.0, 0.35, 0.8):
        q[grip.idx_q] = g
        sent = sent_transforms(v, q)
        rel = np.linalg.inv(sent[v._bpath(body_l3)]) @ sent[v._bpath(body_b)]
        np.testing.assert_allclose(rel[:3, 3], [0.1, -0.02, 0.0], atol=1e-12)
        np.testing.assert_allclose(rel[:3, :3], pin.utils.rotate("x", -g + 0.1), atol=1e-12)
    # show_limits colours the bounded joints only; the mimic joint with its mapped range
    q[grip.idx_q] = 0.5 * (grip.lower + grip.upper)
    v.display(q)
    v.show_limits()
    v.server = rec = Recorder()
    q[grip.idx_q] = grip.upper
    v.display(q)
    red = {c["path"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    assert f"{v._bpath(body_b)}/joint" in red and f"{v.root}/bodies/grip/joint" in red
    assert not any("/spin/" in p or "/wrist/" in p for p in red)


def test_pin_model_without_visuals_draws_the_skeleton():
    model = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path("kinova")))
    robot = aa.load(model, name="kinova_model")
    assert robot.info is None and robot.visual_model is None
    v = Viewer(robot)
    assert all(b.frame is None for b in v.bodies)
    assert sum(b.joint is not None for b in v.bodies) == len(robot.chain.joints)
    for q in robot.random_q(3, rng=7):
        check_against_pinocchio(robot, v, q)
    with pytest.raises(ViewerError, match="no URDF"):
        Viewer(robot, style="urdf")


def piece_poses_match_omg(robot, v: Viewer, q):
    """Each visual piece's world pose (body pose × offset, mesh scale removed) is Pinocchio's oMg."""
    gm = robot.visual_model
    gd = pin.GeometryData(gm)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    pin.updateGeometryPlacements(robot.model, data, gm, gd)
    sent = sent_transforms(v, q)
    poses = []
    for b in v.bodies:
        M = sent[v._bpath(b)] if b.joint is not None else np.eye(4)
        poses += [M @ p.offset @ np.linalg.inv(mesh_placement(p.geometry)) for p in b.pieces]
    assert len(poses) == len(gm.geometryObjects)
    for k, go in enumerate(gm.geometryObjects):
        scale = np.diag([*go.meshScale, 1.0])
        np.testing.assert_allclose(
            poses[k] @ np.linalg.inv(scale), gd.oMg[k].homogeneous, atol=1e-12, err_msg=go.name
        )


def test_pin_model_with_visual_model_draws_its_meshes():
    path = aa.models.erd_urdf_path("ur5")
    model = pin.buildModelFromUrdf(str(path))
    visual = pin.buildGeomFromUrdf(
        model, str(path), pin.GeometryType.VISUAL, package_dirs=[str(path.parents[4])]
    )
    robot = aa.load(model, visual_model=visual, name="ur5_model")
    v = Viewer(robot, mesh_triangles=None)  # the mesh files as they are
    assert sum(len(b.pieces) for b in v.bodies) == len(visual.geometryObjects)
    objs = [umsgpack.unpackb(c) for c in v.store.commands()]
    files = [
        o
        for o in objs
        if o["type"] == "set_object"
        and o["object"]["geometries"]
        and o["object"]["geometries"][0].get("type") == "_meshfile"
    ]
    assert len(files) == len(visual.geometryObjects)
    for q in robot.random_q(2, rng=8):
        check_against_pinocchio(robot, v, q)
        piece_poses_match_omg(robot, v, q)
    packed = Viewer(robot)  # default: compact meshes, placed by their own grid-to-metres placement
    assert all(isinstance(p.geometry, PackedMesh) for b in packed.bodies for p in b.pieces)
    piece_poses_match_omg(robot, packed, robot.random_q(rng=9))


def test_pin_model_with_primitive_visuals():
    import coal

    model = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path("ur5")))
    gm = pin.GeometryModel()
    rng = np.random.default_rng(9)
    shapes = [
        coal.Box(0.1, 0.2, 0.3),
        coal.Sphere(0.05),
        coal.Cylinder(0.04, 0.3),
        coal.Capsule(0.03, 0.2),
        coal.Ellipsoid(0.1, 0.05, 0.02),
        coal.Cone(0.05, 0.1),
    ]
    for k, g in enumerate(shapes):
        jid = 1 + k % (model.njoints - 1)
        go = pin.GeometryObject(
            f"shape{k}",
            jid,
            model.frames[model.getFrameId(model.names[jid])].parentFrame,
            pin.SE3.Random(),
            g,
        )
        go.meshColor = np.array([0.2, 0.4, 0.6, 1.0])
        gm.addGeometryObject(go)
    robot = aa.load(model, visual_model=gm)
    v = Viewer(robot)
    kinds = [type(p.geometry).__name__ for b in v.bodies for p in b.pieces]
    # one body per joint in joint order; a capsule is a cylinder and two end spheres
    assert kinds == [
        "Box",
        "Sphere",
        "Cylinder",
        "Cylinder",
        "Sphere",
        "Sphere",
        "Ellipsoid",
        "Cylinder",
    ]
    q = robot.random_q(rng=rng)
    sent = sent_transforms(v, q)
    gd = pin.GeometryData(gm)
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, gm, gd)
    y_to_z = np.array(
        [[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1.0]]
    )  # meshcat y → coal z
    for b in v.bodies:
        M = sent[v._bpath(b)]
        gos = [
            k
            for k, go in enumerate(gm.geometryObjects)
            if go.parentJoint == model.getJointId(b.name)
        ]
        pieces = iter(b.pieces)
        for k in gos:
            g = shapes[k]
            p = next(pieces)
            W = M @ p.offset
            name = type(g).__name__
            if name == "Capsule":  # cylinder + two end spheres along the capsule's z
                np.testing.assert_allclose(W[:3, 1], gd.oMg[k].rotation[:, 2], atol=1e-12)
                np.testing.assert_allclose(W[:3, 3], gd.oMg[k].translation, atol=1e-12)
                assert p.geometry.height == pytest.approx(
                    0.2
                ) and p.geometry.radiusTop == pytest.approx(0.03)
                for s in (-1, 1):
                    e = M @ next(pieces).offset
                    np.testing.assert_allclose(
                        e[:3, 3], gd.oMg[k].act(np.array([0, 0, s * 0.1])), atol=1e-12
                    )
                continue
            if name in ("Cylinder", "Cone"):
                W = W @ y_to_z.T
                assert p.geometry.height == pytest.approx(2 * g.halfLength)
            np.testing.assert_allclose(W, gd.oMg[k].homogeneous, atol=1e-12, err_msg=name)
        assert next(pieces, None) is None


def test_viewer_does_not_keep_a_robot_alive():
    import gc
    import weakref

    robot = aa.load("kinova")
    v = Viewer(robot)
    v.display(robot.random_q(rng=0))
    ref = weakref.ref(robot)
    del v, robot
    gc.collect()
    assert ref() is None


def test_joint_triads_follow_every_joint(user_robot):
    robot = user_robot
    v = Viewer(robot)
    v.show_frames("joints")
    q = robot.random_q(rng=10)
    sent = sent_transforms(v, q)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    triads = {p: T for p, T in sent.items() if "/overlays/frames/" in p}
    assert len(triads) == robot.model.njoints - 1
    for j in range(1, robot.model.njoints):
        np.testing.assert_allclose(
            triads[f"{v.root}/overlays/frames/{robot.model.names[j]}"],
            data.oMi[j].homogeneous,
            atol=1e-12,
        )


def test_demo_has_no_ik_fallback():
    from anthroarm.viewer.demo import reach_demo

    with pytest.raises(ValueError, match="qp"):
        reach_demo(method="dls")
