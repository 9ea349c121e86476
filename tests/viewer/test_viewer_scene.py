"""The viewer's scene without a server: what is sent, where it is drawn, static HTML.

Oracles: yourdfpy's own forward kinematics (an independent URDF parser) for every link
transform sent to the browser; the planar 2R closed form |l1 l2 sin θ2| and det(J Jᵀ) from
Pinocchio's Jacobian for the manipulability colours; arithmetic for limit proximity.
"""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.errors import MeshNotFoundError, ViewerError
from anthroarm.viewer import Viewer, limit_color, limit_proximity, manipulability
from anthroarm.viewer._store import SceneStore
from anthroarm.viewer.viewer import LIMIT_RGB

BOOK = ["human_arm7", "prosthetic_arm", "sixr_arm", "unimate5", "rrprr5", "planar2r"]


@pytest.fixture(scope="module")
def human():
    return aa.load("human_arm7")


def html_commands(html: str) -> list[dict]:
    """Decode the commands a static page replays."""
    m = re.search(r"var cmds = (\[.*?\]);", html, re.S)
    assert m, "no replayed commands in the page"
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]


class Recorder:
    """Stands in for the server: records every message the viewer sends."""

    def __init__(self):
        self.messages = []

    def send_many(self, cmds):
        self.messages.append(list(cmds))


def test_display_sends_every_moving_body_in_one_message(human):
    v = Viewer(human)
    v.server = rec = Recorder()
    q = human.random_q(rng=1)
    v.display(q)
    assert len(rec.messages) == 1
    paths = {c["path"] for c in rec.messages[0] if c["type"] == "set_transform"}
    moving = {v._bpath(b) for b in v.bodies if b.joint is not None or b.frame is not None}
    assert paths == moving and len(moving) == human.nq


@pytest.mark.parametrize("name", ["human_arm7", "prosthetic_arm", "unimate5"])
def test_book_body_transforms_match_yourdfpy(name):
    """The pose sent for the body of joint j is the pose of joint j's child link, as computed by
    yourdfpy from the same URDF text (independent of Pinocchio)."""
    robot = aa.load(name)
    v = Viewer(robot)
    v.server = rec = Recorder()
    u = robot.urdf
    for q in robot.random_q(5, rng=2):
        v.display(q)
        sent = {
            c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T
            for c in rec.messages[-1]
            if c["type"] == "set_transform"
        }
        u.update_cfg(robot.yourdfpy_cfg(q))
        for b in v.bodies:
            if b.joint is None:
                continue
            child = u.joint_map[robot.chain.joints[b.joint].name].child
            np.testing.assert_allclose(sent[v._bpath(b)], u.get_transform(child), atol=1e-12)


def test_urdf_mesh_bodies_match_yourdfpy():
    robot = aa.load("panda")
    v = Viewer(robot)
    v.server = rec = Recorder()
    u = robot.urdf
    q = robot.random_q(rng=3)
    v.display(q)
    sent = {
        c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T
        for c in rec.messages[-1]
        if c["type"] == "set_transform"
    }
    u.update_cfg(robot.yourdfpy_cfg(q))
    checked = 0
    for b in v.bodies:
        if b.frame is None or b.name not in u.link_map:
            continue
        np.testing.assert_allclose(sent[v._bpath(b)], u.get_transform(b.name), atol=1e-12)
        checked += 1
    assert checked >= 8  # panda_link0..7 and the hand carry meshes


def test_panda_meshes_are_the_package_files():
    robot = aa.load("panda")
    v = Viewer(robot, mesh_triangles=None)  # the files as they are
    objs = [umsgpack.unpackb(c) for c in v.store.commands()]
    meshes = [
        o
        for o in objs
        if o["type"] == "set_object"
        and o["object"]["geometries"]
        and o["object"]["geometries"][0].get("type") == "_meshfile"
    ]
    assert len(meshes) >= 8
    first = robot.info.meshes[next(iter(robot.info.meshes))]
    assert first.is_file()


def test_packed_panda_meshes_approximate_the_files_and_fit_a_jupyter_cell():
    """Default mesh budget: each mesh file becomes a PackedMesh of at most MESH_TRIANGLES
    triangles whose vertices lie within one clustering cell of the file's own vertices (trimesh
    reads the file: the oracle), with the same bounding box to 2 % of its size; the Jupyter
    cell of the whole arm embeds at most 2 MB (15 MB with the raw files)."""
    import io

    import trimesh
    from scipy.spatial import cKDTree

    from anthroarm.viewer.visuals import MESH_TRIANGLES, PackedMesh

    robot = aa.load("panda")
    v = Viewer(robot)
    packed = {}
    for b in v.bodies:
        for piece in b.pieces:
            if isinstance(piece.geometry, PackedMesh):
                packed[id(piece.geometry)] = piece.geometry
    assert len(packed) >= 8
    files = {p for p in robot.info.meshes.values() if "/visual/" in str(p)}
    by_count = {}
    for f in files:
        m = trimesh.load(io.BytesIO(f.read_bytes()), file_type=f.suffix[1:], force="mesh")
        by_count[f] = m
    for g in packed.values():
        assert len(g.faces) <= MESH_TRIANGLES and g.faces.max() < len(g.grid)
        W = g.vertices
        # the file this mesh came from: the one whose bounding box matches
        best = min(
            by_count.values(), key=lambda m: np.abs(m.bounds - np.array([W.min(0), W.max(0)])).max()
        )
        side = float(np.ptp(best.vertices, axis=0).max())
        np.testing.assert_allclose([W.min(0), W.max(0)], best.bounds, atol=0.02 * side)
        cell = side / 8  # coarsest grid the budget could need for these meshes is far finer
        d, _ = cKDTree(best.vertices).query(W)
        assert d.max() < cell, (d.max(), side)
        assert np.median(d) < 0.01 * side
    assert len(v._repr_html_().encode()) <= 2 * 2**20
    assert (
        len(Viewer(robot, mesh_triangles=None)._repr_html_().encode()) > 10 * 2**20
    )  # what it was


@pytest.mark.parametrize("name", BOOK)
def test_generated_capsules_connect_the_joints(name):
    """Every child joint origin (and the tool) is the end of a capsule of its parent body."""
    robot = aa.load(name)
    v = Viewer(robot)
    model = robot.model
    for b in v.bodies:
        if b.joint is None:
            continue
        ends = []
        for p in b.pieces:
            if p.group == "links" and type(p.geometry).__name__ == "Sphere":
                ends.append(p.offset[:3, 3])
        jid = model.getJointId(b.name)  # Pinocchio's own tables, not robot.chain
        targets = [
            model.jointPlacements[c].translation
            for c in range(1, model.njoints)
            if model.parents[c] == jid
        ]
        tool = model.frames[robot.tool_id]
        if tool.parentJoint == jid:
            targets.append(tool.placement.translation)
        for t in targets:
            if np.linalg.norm(t) < 1e-9:
                continue
            assert min(np.linalg.norm(e - t) for e in ends) < 1e-12, (name, b.name, t)


def test_kinds_of_generated_visuals(human):
    v = Viewer(human)
    groups = {p.group for b in v.bodies for p in b.pieces}
    assert {"links", "joint", "axis", "palm", "torso"} <= groups
    # one joint-centre sphere and one axis cylinder per joint
    for b in v.bodies:
        if b.joint is not None:
            assert sum(p.group == "joint" for p in b.pieces) == 1
            axes = [p for p in b.pieces if p.group == "axis"]
            assert len(axes) == 1
            # the cylinder (meshcat: along y) is turned onto the joint axis
            ax = axes[0].offset[:3, 1]
            S = np.zeros(3)
            S[
                ["JointModelRX", "JointModelRY", "JointModelRZ"].index(
                    human.model.joints[human.model.getJointId(b.name)].shortname()
                )
            ] = 1
            assert abs(abs(ax @ S) - 1) < 1e-12


def test_missing_mesh_names_the_file(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text("""<?xml version="1.0"?>
<robot name="meshy">
  <link name="base"><visual><geometry><mesh filename="meshes/base.stl"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="l1"><visual><geometry><mesh filename="meshes/missing_forearm.stl"/></geometry></visual></link>
</robot>""")
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "base.stl").write_bytes(b"solid x\nendsolid x\n")
    robot = aa.load(str(urdf), check_meshes=False)
    with pytest.raises(MeshNotFoundError, match=r"missing_forearm\.stl") as exc:
        Viewer(robot)
    assert "l1" in str(exc.value) and str(tmp_path) in str(exc.value)


def test_limit_proximity_arithmetic():
    lo, hi = np.array([-1.0, 0.0, -np.inf]), np.array([1.0, 2.0, np.inf])
    np.testing.assert_allclose(limit_proximity([0.0, 1.0, 5.0], lo, hi), [0, 0, 0])
    np.testing.assert_allclose(limit_proximity([1.0, 0.0, 0.0], lo, hi), [1, 1, 0])
    np.testing.assert_allclose(limit_proximity([0.5, 1.5, 0.0], lo, hi), [0.5, 0.5, 0])
    np.testing.assert_allclose(
        limit_proximity([3.0, -1.0, 0.0], lo, hi), [1, 1, 0]
    )  # beyond: clipped
    assert limit_color(0.5) == pytest.approx(limit_color(0.0))
    assert limit_color(1.0) == pytest.approx(LIMIT_RGB)


def test_limit_colours_sent_only_for_changes(human):
    v = Viewer(human)
    v.show_limits()
    v.server = rec = Recorder()
    q = 0.5 * (human.lower + human.upper)
    q[3] = human.upper[3]  # elbow at its limit
    v.display(q)
    colors = {c["path"]: c["color"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    red = {p for p, c in colors.items() if c == pytest.approx(LIMIT_RGB, abs=1e-3)}
    # the elbow's own centre, and the forearm (drawn from the coincident forearm-rotation joint)
    assert red == {
        f"{v.root}/bodies/elbow_flexion/joint",
        f"{v.root}/bodies/forearm_pronation/links",
    }
    v.display(q)  # same pose: no colour traffic
    assert not [c for c in rec.messages[-1] if c["type"] == "anthroarm_color"]
    q[3] = 0.5 * (human.lower[3] + human.upper[3])
    v.display(q)  # back to mid-range: the two recoloured parts get their own colours back
    back = {c["path"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    assert back == red
    v.display(q)  # same pose: no colour traffic
    assert not [c for c in rec.messages[-1] if c["type"] == "anthroarm_color"]


def test_manipulability_against_closed_form_and_pinocchio():
    planar = aa.load("planar2r")
    Q = planar.random_q(50, rng=4)
    np.testing.assert_allclose(manipulability(planar, Q), np.abs(np.sin(Q[:, 1])), atol=1e-12)
    robot = aa.load("sixr_arm")
    Q = robot.random_q(20, rng=5)
    ref = []
    for q in Q:
        J = pin.computeFrameJacobian(
            robot.model, robot.data, q, robot.tool_id, pin.LOCAL_WORLD_ALIGNED
        )[:3]
        ref.append(np.sqrt(np.linalg.det(J @ J.T)))
    np.testing.assert_allclose(manipulability(robot, Q), ref, rtol=1e-9, atol=1e-14)


def test_workspace_cloud_points_are_tool_positions(human):
    v = Viewer(human)
    out = v.show_workspace(200, rng=7)
    Q = human.random_q(200, rng=7)
    np.testing.assert_allclose(out["points"], human.fk(Q)[:, :3, 3], atol=1e-12)
    assert out["manipulability"].shape == (200,) and (out["manipulability"] >= 0).all()
    cmds = [umsgpack.unpackb(c) for c in v.store.commands()]
    cloud = [
        c for c in cmds if c["type"] == "set_object" and c["path"].endswith("/overlays/workspace")
    ]
    assert len(cloud) == 1 and cloud[0]["object"]["object"]["type"] == "Points"


def test_animation_keyframes_follow_the_trajectory(human):
    v = Viewer(human)
    Q = np.linspace(human.neutral(), human.random_q(rng=8), 12)
    v.play(Q, dt=0.05)
    html = v.static_html()
    anims = [c for c in html_commands(html) if c["type"] == "set_animation"]
    assert len(anims) == 1
    anim = anims[0]
    assert anim["options"]["repetitions"] == float("inf")
    u = human.urdf
    for track in anim["animations"]:
        body = next(b for b in v.bodies if v._bpath(b) == track["path"])
        clip = track["clip"]
        assert clip["fps"] == pytest.approx(20.0)
        pos = next(t for t in clip["tracks"] if t["name"] == ".position")["keys"]
        rot = next(t for t in clip["tracks"] if t["name"] == ".quaternion")["keys"]
        assert [k["time"] for k in pos] == list(range(12))
        for k in (0, 5, 11):
            u.update_cfg(human.yourdfpy_cfg(Q[k]))
            T = u.get_transform(u.joint_map[body.name].child)
            np.testing.assert_allclose(pos[k]["value"], T[:3, 3], atol=1e-12)
            x, y, z, w = rot[k]["value"]
            R = pin.Quaternion(w, x, y, z).toRotationMatrix()
            np.testing.assert_allclose(R, T[:3, :3], atol=1e-12)


def test_static_html_is_self_contained(human):
    v = Viewer(human)
    v.show_target(human.fk(human.random_q(rng=9)))
    html = v.static_html()
    assert "MeshCat" in html and len(html) > 500_000  # meshcat's JavaScript is inlined
    assert not re.search(r"<script[^>]+src=", html)
    assert not re.search(r"(src|href)=[\"']https?://", html)
    kinds = {c["type"] for c in html_commands(html)}
    assert {"set_object", "set_transform", "set_property"} <= kinds


def test_export_html_needs_an_existing_folder(human, tmp_path):
    v = Viewer(human)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        v.export_html(tmp_path / "nope" / "x.html")
    p = v.export_html(tmp_path / "x.html")
    assert p.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")


def test_scene_store_keeps_latest_state_only():
    st = SceneStore()
    for i in range(100):
        st.apply({"type": "set_transform", "path": "/a/b", "matrix": [float(i)] * 16})
    st.apply({"type": "set_object", "path": "/a/b", "object": {}})
    cmds = [umsgpack.unpackb(c) for c in st.commands()]
    assert [c["type"] for c in cmds] == ["set_object", "set_transform"]
    assert cmds[1]["matrix"][0] == 99.0
    st.apply({"type": "delete", "path": "/a"})
    assert st.commands() == []
    st.apply(
        {
            "type": "anthroarm_batch",
            "path": "",
            "commands": [
                {"type": "set_property", "path": "/x", "property": "visible", "value": False}
            ],
        }
    )
    assert umsgpack.unpackb(st.commands()[0])["property"] == "visible"


def test_bad_inputs_raise_value_errors(human):
    v = Viewer(human)
    with pytest.raises(ValueError, match="shape"):
        v.display(np.zeros(3))
    with pytest.raises(ValueError):
        v.display(np.full(7, np.nan))
    with pytest.raises(ValueError, match="trajectory"):
        v.play(np.zeros(7))
    with pytest.raises(ValueError, match="dt"):
        v.play(np.zeros((3, 7)), dt=0.0)
    with pytest.raises(ValueError, match="4x4"):
        v.show_target(np.eye(3))
    with pytest.raises(ValueError):
        v.show_trace(np.zeros((1, 3)))
    with pytest.raises(ValueError, match="style"):
        Viewer(human, style="pretty")
    with pytest.raises(ViewerError, match="visual_model"):
        Viewer(human, style="visual_model")


def test_jupyter_cell_is_a_static_iframe_when_not_live(human):
    v = Viewer(human)
    h = v._repr_html_()
    assert h.count("<iframe") == 1 and "srcdoc=" in h and "&lt;!DOCTYPE html&gt;" in h
    assert v.jupyter_cell(300).data == v._iframe(300)


def test_display_after_play_stops_the_animation(human):
    v = Viewer(human)
    v.play(np.linspace(human.neutral(), human.random_q(rng=12), 5))
    assert any(c["type"] == "set_animation" for c in html_commands(v.static_html()))
    v.server = rec = Recorder()
    v.display(human.neutral())
    assert (
        rec.messages[-1][0]["type"] == "set_animation" and rec.messages[-1][0]["animations"] == []
    )
    assert not any(c["type"] == "set_animation" for c in html_commands(v.static_html()))
    v.display(human.neutral())  # no animation left: nothing to stop
    assert all(c["type"] != "set_animation" for c in rec.messages[-1])
