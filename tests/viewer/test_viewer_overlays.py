"""The meshcat escape hatch (``Viewer.scene``) and the point-cloud and arrow overlays, read back
from the commands the static page replays.

Oracles: matplotlib's own colour maps for the point colours; geometry (each arrow's tip vertex
is origin + scale · direction, every vertex lies inside the arrow's cylinder of head radius,
every normal is a unit vector) for the arrow mesh.
"""

from __future__ import annotations

import base64
import json
import re

import meshcat.geometry as mg
import numpy as np
import pytest
import umsgpack
from matplotlib import colormaps

import anthroarm as aa
from anthroarm.errors import ParameterError, ViewerError
from anthroarm.viewer import Viewer


@pytest.fixture(scope="module")
def viewer():
    return Viewer(aa.load("planar2r"))


def page_commands(v: Viewer) -> list[dict]:
    m = re.search(r"var cmds = (\[.*?\]);", v.static_html(), re.S)
    assert m, "no replayed commands in the page"
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]


def objects_at(v: Viewer, path: str) -> list[dict]:
    return [c for c in page_commands(v) if c["type"] == "set_object" and c["path"] == path]


def attribute(obj: dict, name: str) -> np.ndarray:
    data = obj["object"]["geometries"][0]["data"]
    a = data["index"] if name == "index" else data["attributes"][name]
    dtype = np.float32 if a["type"] == "Float32Array" else np.uint32
    return np.frombuffer(a["array"].data, dtype).reshape(-1, a["itemSize"])


def test_scene_is_a_meshcat_visualizer_whose_commands_reach_the_page(viewer):
    from meshcat.visualizer import Visualizer

    sc = viewer.scene
    assert isinstance(sc, Visualizer)
    sc["mine/box"].set_object(mg.Box([0.1, 0.2, 0.3]), mg.MeshLambertMaterial(color=0x00FF00))
    sc["mine/box"].set_transform(np.diag([1.0, 1.0, 1.0, 1.0]))
    sc["/Grid"].set_property("visible", True)
    sc.set_cam_pos([1.0, 2.0, 3.0])
    cmds = page_commands(viewer)
    box = [c for c in cmds if c["type"] == "set_object" and c["path"] == "/meshcat/mine/box"]
    assert len(box) == 1 and box[0]["object"]["geometries"][0]["type"] == "BoxGeometry"
    assert box[0]["object"]["materials"][0]["color"] == 0x00FF00
    grid = [
        c["value"]
        for c in cmds
        if c["type"] == "set_property" and c["path"] == "/Grid" and c["property"] == "visible"
    ]
    assert grid == [True]
    cam = [
        c["value"]
        for c in cmds
        if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"
    ]
    assert cam[-1] == [1.0, 3.0, -2.0]  # meshcat's camera frame is y-up: (x, z, -y)
    sc["mine"].delete()
    assert not [c for c in page_commands(viewer) if c["path"].startswith("/meshcat/mine")]
    with pytest.raises(ViewerError, match="screenshot"):
        sc.get_image()
    with pytest.raises(ParameterError):
        sc.set_cam_pos([1.0, float("nan"), 0.0])


def test_points_coloured_by_values_follow_the_colour_map(viewer):
    rng = np.random.default_rng(3)
    P = rng.uniform(-0.5, 0.5, (50, 3))
    w = rng.uniform(2.0, 7.0, 50)
    out = viewer.show_points(P, values=w, colormap="plasma", size=0.01, name="map")
    (obj,) = objects_at(viewer, f"{viewer.root}/overlays/map")
    np.testing.assert_allclose(attribute(obj, "position"), P, atol=1e-6)
    expect = np.asarray(colormaps["plasma"]((w - w.min()) / (w.max() - w.min())))[:, :3]
    np.testing.assert_allclose(attribute(obj, "color"), expect, atol=1e-6)
    assert obj["object"]["materials"][0]["size"] == 0.01
    assert out["vmin"] == w.min() and out["vmax"] == w.max()
    # a fixed range clips: everything at or above vmax gets the map's top colour
    viewer.show_points(P, values=w, colormap="viridis", vmin=0.0, vmax=2.0, name="map")
    (obj,) = objects_at(viewer, f"{viewer.root}/overlays/map")
    np.testing.assert_allclose(
        attribute(obj, "color"), np.tile(colormaps["viridis"](1.0)[:3], (50, 1)), atol=1e-6
    )
    # one colour for all
    viewer.show_points(P[:4], colors=(0.0, 0.5, 1.0), name="map")
    (obj,) = objects_at(viewer, f"{viewer.root}/overlays/map")
    np.testing.assert_allclose(attribute(obj, "color"), np.tile([0.0, 0.5, 1.0], (4, 1)), atol=1e-6)
    viewer.clear("map")
    assert not objects_at(viewer, f"{viewer.root}/overlays/map")


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"points": np.zeros((4, 2))}, "N>=1, 3"),
        ({"points": [[0, 0, np.nan]]}, "NaN"),
        ({"points": "abc"}, "array"),
        ({"points": np.zeros((4, 3)), "values": np.ones(3)}, "one number per point"),
        ({"points": np.zeros((4, 3)), "values": [1, 2, np.inf, 4]}, "finite"),
        ({"points": np.zeros((4, 3)), "values": np.ones(4), "colormap": "nope"}, "colour map"),
        ({"points": np.zeros((4, 3)), "values": np.ones(4), "colors": (1, 0, 0)}, "not both"),
        ({"points": np.zeros((4, 3)), "colors": (2, 0, 0)}, "0..1"),
        ({"points": np.zeros((4, 3)), "colors": np.zeros((3, 3))}, r"\(4, 3\)"),
        ({"points": np.zeros((4, 3)), "size": -1.0}, "positive"),
        (
            {"points": np.zeros((4, 3)), "values": np.arange(4.0), "vmin": 3, "vmax": 1},
            "vmin <= vmax",
        ),
    ],
)
def test_bad_points_raise_parameter_errors(viewer, kwargs, match):
    with pytest.raises(ParameterError, match=match):
        viewer.show_points(**kwargs)


def test_arrows_end_where_they_should(viewer):
    O = np.array([[0.0, 0.0, 0.0], [0.1, -0.2, 0.3], [0.5, 0.5, 0.5]])
    D = np.array([[0.0, 0.0, 2.0], [1.0, 1.0, 0.0], [-3.0, 1.0, 2.0]])
    tips = viewer.show_arrows(
        O, D, scale=0.1, radius=0.004, colors=[[1, 0, 0], [0, 1, 0], [0, 0, 1]], name="forces"
    )
    np.testing.assert_allclose(tips, O + 0.1 * D)
    (obj,) = objects_at(viewer, f"{viewer.root}/overlays/forces")
    X, N, C = attribute(obj, "position"), attribute(obj, "normal"), attribute(obj, "color")
    idx = attribute(obj, "index")
    assert idx.max() < len(X) and len(X) == len(N) == len(C)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-5)
    for k, (o, v, c) in enumerate(zip(O, 0.1 * D, np.eye(3))):
        mine = np.all(np.abs(C - c) < 1e-6, axis=1)
        Xk = X[mine].astype(float)
        d = v / np.linalg.norm(v)
        along = (Xk - o) @ d
        across = np.linalg.norm((Xk - o) - np.outer(along, d), axis=1)
        assert (
            along.min() > -1e-6 and abs(along.max() - np.linalg.norm(v)) < 1e-6
        )  # tail at o, tip at o + v
        assert across.max() < 2.2 * 0.004 + 1e-6  # head radius
        assert np.isclose(
            across[along < 0.5 * np.linalg.norm(v)].max(), 0.004, atol=1e-6
        )  # shaft radius
    # a zero vector draws nothing; all-zero draws no object at all
    viewer.show_arrows(O[:1], np.zeros((1, 3)), name="forces")
    assert not objects_at(viewer, f"{viewer.root}/overlays/forces")
    with pytest.raises(ParameterError, match="same shape"):
        viewer.show_arrows(O, D[:2])
    with pytest.raises(ParameterError, match="positive"):
        viewer.show_arrows(O, D, scale=0.0)
    with pytest.raises(ParameterError, match="NaN"):
        viewer.show_arrows(O, D * np.nan)


def test_batch_voxel_maps_as_point_clouds_with_legends():
    """reachability_map / comfort_map of anthroarm.batch: one point per reached voxel at its
    centre (recomputed here from the result's arrays), coloured through the colour map, with
    the legend in the page."""
    from anthroarm.batch import jobs

    robot = aa.load("human_arm7")
    v = Viewer(robot)
    res = jobs.reachability_map(robot, n=3000, voxel=0.08, seed=0, progress=False)
    out = v.show_map(res)
    counts = res["counts"]
    i, j, k = np.nonzero(counts)
    centres = np.stack([res.coords["x"][i], res.coords["y"][j], res.coords["z"][k]], 1)
    assert counts.sum() == 3000 and len(out["points"]) == len(centres)
    np.testing.assert_allclose(np.sort(out["points"], axis=0), np.sort(centres, axis=0))
    (obj,) = objects_at(v, f"{v.root}/overlays/reachability_map")
    material = obj["object"]["materials"][0]
    # half the 8 cm voxel, see-through and not hiding what lies behind: the robot shows inside
    assert material["size"] == pytest.approx(0.04)
    assert material["transparent"] is True and 0 < material["opacity"] < 1
    assert material["depthWrite"] is False
    c = counts[i, j, k].astype(float)
    order = np.lexsort(centres.T)
    got = attribute(obj, "color")[np.lexsort(out["points"].T)]
    np.testing.assert_allclose(
        got, colormaps["viridis"]((c[order] - c.min()) / (c.max() - c.min()))[:, :3], atol=1e-6
    )
    legends = [
        x["spec"]
        for x in page_commands(v)
        if x["type"] == "anthroarm_ui" and x["spec"]["kind"] == "legend"
    ]
    assert any(
        sp["title"].startswith("reachability_map: counts") and sp["ticks"][-1] == f"{c.max():.3g}"
        for sp in legends
    )
    comfort = jobs.comfort_map(robot, n=3000, voxel=0.08, seed=0, progress=False)
    out = v.show_map(comfort)
    assert (
        len(out["points"])
        == np.isfinite(comfort["discomfort"]).sum()
        == (comfort["counts"] > 0).sum()
    )
    with pytest.raises(ParameterError, match="voxel map"):
        v.show_map(comfort, "nope")
    with pytest.raises(ParameterError, match="batch result"):
        v.show_map({"counts": 1})


def test_legends_for_manipulability_and_limits_are_in_the_page_and_go_away():
    v = Viewer(aa.load("planar2r"))
    res = v.show_workspace(200)
    specs = lambda: {x["path"]: x["spec"] for x in page_commands(v) if x["type"] == "anthroarm_ui"}
    man = specs()[f"{v.root}/overlays/workspace/legend"]
    assert man["title"].startswith("manipulability (m²")
    assert man["ticks"] == [
        "0",
        f"{res['manipulability'].max() / 2:.3g}",
        f"{res['manipulability'].max():.3g}",
    ]
    assert man["stops"][0] == pytest.approx(list(colormaps["viridis"](0.0)[:3]), abs=1e-4)
    v.show_limits()
    lim = specs()[f"{v.root}/ui/limits"]
    assert lim["stops"][0] == pytest.approx(list(aa.viewer.limit_color(0.0))) and lim["stops"][
        -1
    ] == pytest.approx(list(aa.viewer.viewer.LIMIT_RGB))
    v.show_limits(False)
    v.clear("workspace")
    assert set(specs()) == {f"{v.root}/ui/scale"}  # only the scale-bar note is left
    v.set_scale_bar(False)
    assert not specs()


def test_grid_axes_and_scale_bar_are_drawn_to_scale_and_switch_off():
    v = Viewer(aa.load("human_arm7"))
    sp = v.spacing
    assert sp in {m * 10.0**k for m in (1, 2, 5) for k in range(-3, 2)}
    (grid,) = objects_at(v, f"{v.root}/grid")
    assert grid["object"]["object"]["type"] == "LineSegments"
    X = attribute(grid, "position").astype(float)
    # lines on the floor, every one on a multiple of the spacing (so through the base origin)
    assert np.ptp(X[:, 2]) < 1e-6 and X[0, 2] < 0
    along_y = X[0::2][np.isclose(X[0::2, 0], X[1::2, 0])]
    np.testing.assert_allclose(along_y[:, 0] / sp, np.round(along_y[:, 0] / sp), atol=1e-4)
    # the scale bar is one grid square long: its five pieces add up to the spacing
    bar = [
        c
        for c in page_commands(v)
        if c["type"] == "set_object" and c["path"].startswith(f"{v.root}/scale/")
    ]
    assert len(bar) == 5
    assert sum(c["object"]["geometries"][0]["height"] for c in bar) == pytest.approx(sp)
    notes = [
        c["spec"]["text"]
        for c in page_commands(v)
        if c["type"] == "anthroarm_ui" and c["spec"]["kind"] == "note"
    ]
    assert notes == [f"scale bar and grid squares: {aa.viewer.viewer.format_length(sp)}"]
    axes = [
        c
        for c in page_commands(v)
        if c["type"] == "set_object" and c["path"].startswith(f"{v.root}/axes/")
    ]
    assert len(axes) == 3

    def visible(path):
        vals = [
            c["value"]
            for c in page_commands(v)
            if c["type"] == "set_property" and c["path"] == path and c["property"] == "visible"
        ]
        return vals[-1]

    assert visible(f"{v.root}/grid") and visible(f"{v.root}/axes") and visible(f"{v.root}/scale")
    v.set_grid(False)
    v.set_axes(False)
    v.set_scale_bar(False)
    assert not (
        visible(f"{v.root}/grid") or visible(f"{v.root}/axes") or visible(f"{v.root}/scale")
    )
    v2 = Viewer(aa.load("planar2r"), grid=False, axes=False, scale_bar=False)
    cmds = page_commands(v2)
    assert [
        c["value"] for c in cmds if c["type"] == "set_property" and c["path"] == f"{v2.root}/grid"
    ] == [False]


def test_nice_lengths_and_framing_distance():
    from anthroarm.viewer.viewer import framing_distance, nice_length

    assert [nice_length(x) for x in (0.013, 0.02, 0.049, 0.7, 3.0)] == pytest.approx(
        [0.01, 0.02, 0.02, 0.5, 2.0]
    )
    # a unit cube seen along x: its near face (depth 0.5) must fit fill · tan(37.5°) (vertical and 4:3)
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    D = framing_distance(corners, np.array([1.0, 0.0, 0.0]), fill=0.8)
    assert D == pytest.approx(0.5 + 0.5 / (0.8 * np.tan(np.radians(37.5))))


def test_hands_are_drawn_from_their_own_visual_geometry():
    """allegro (URDF meshes) and human_upper_limb (designed phalanx and palm shapes): every
    finger link carries its URDF visuals; no generated 'palm' paddle; the person's torso stays."""
    from anthroarm.viewer.visuals import robot_bodies

    for name, tool in (("allegro_right_hand", "link_3.0_tip"), ("human_upper_limb", None)):
        robot = aa.load(name, tool=tool) if tool else aa.load(name)
        bodies = robot_bodies(robot)
        groups = {p.group for b in bodies for p in b.pieces}
        assert "palm" not in groups and "mesh" in groups, (name, groups)
        with_visuals = {b.name for b in bodies if any(p.group == "mesh" for p in b.pieces)}
        from lxml import etree

        root = etree.fromstring(robot.info.text.encode())
        urdf_links = {l.get("name") for l in root.findall("link") if l.find("visual") is not None}
        assert with_visuals == urdf_links, (name, urdf_links ^ with_visuals)
        assert len(with_visuals) >= 16
    assert bodies[0].name == "torso"
    assert {p.group for p in robot_bodies(robot, "generated")[-1].pieces} >= {
        "links"
    }  # the skeleton is still there on request
    assert any(p.group == "palm" for b in robot_bodies(robot, "generated") for p in b.pieces)


def test_joint_values_colour_each_link_by_its_joint_with_a_legend():
    """Gravity torques of the §6-3 arm (Pinocchio's computeGeneralizedGravity) colour the
    links: the body moved by joint j gets plasma(|τ_j| scaled to the range); show_limits and
    this colouring replace each other; None restores the colours."""
    import pinocchio as pin

    robot = aa.load("human_arm7")
    v = Viewer(robot)
    q = np.deg2rad([30, -20, 10, 60, 0, 0, 0])
    v.display(q)
    tau = pin.computeGeneralizedGravity(robot.model, robot.model.createData(), q)

    class Rec:
        def __init__(self):
            self.messages = []

        def send_many(self, cmds):
            self.messages.append(list(cmds))

    v.server = rec = Rec()
    out = v.show_joint_values(tau, "gravity torque |τ| (N·m)")
    colors = {c["path"]: c["color"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    a = np.abs(tau)
    expect = colormaps["plasma"]((a - a.min()) / (a.max() - a.min()))[:, :3]
    coloured = [
        b for b in v.bodies if b.joint is not None and any(p.group == "links" for p in b.pieces)
    ]
    assert len(coloured) >= 3 and len(colors) == len(
        coloured
    )  # joints at one point share the next link
    for b in coloured:
        np.testing.assert_allclose(
            colors[f"{v.root}/bodies/{b.name}/links"], expect[b.joint], atol=2e-3
        )
    np.testing.assert_allclose(out["values"], a)
    legend = [c["spec"] for c in rec.messages[-1] if c["type"] == "anthroarm_ui"]
    assert (
        legend[0]["title"] == "gravity torque |τ| (N·m)"
        and legend[0]["ticks"][-1] == f"{a.max():.3g}"
    )
    n = len(rec.messages)
    v.show_limits()  # replaces the torque colours and legend
    assert any(
        c["type"] == "delete" and c["path"].endswith("/ui/joint_values")
        for m in rec.messages[n:]
        for c in m
    )
    v.show_limits(False)
    restored = [c for c in rec.messages[-1] if c["type"] == "set_object"]
    assert restored and not [c for c in rec.messages[-1] if c["type"] == "anthroarm_color"]
    with pytest.raises(ParameterError, match="one number per joint"):
        v.show_joint_values(np.ones(3))
