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
    grid = [c["value"] for c in cmds if c["type"] == "set_property" and c["path"] == "/Grid" and c["property"] == "visible"]
    assert grid == [True]
    cam = [c["value"] for c in cmds if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"]
    assert cam[-1] == [1.0, 3.0, -2.0]      # meshcat's camera frame is y-up: (x, z, -y)
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
    np.testing.assert_allclose(attribute(obj, "color"), np.tile(colormaps["viridis"](1.0)[:3], (50, 1)), atol=1e-6)
    # one colour for all
    viewer.show_points(P[:4], colors=(0.0, 0.5, 1.0), name="map")
    (obj,) = objects_at(viewer, f"{viewer.root}/overlays/map")
    np.testing.assert_allclose(attribute(obj, "color"), np.tile([0.0, 0.5, 1.0], (4, 1)), atol=1e-6)
    viewer.clear("map")
    assert not objects_at(viewer, f"{viewer.root}/overlays/map")


@pytest.mark.parametrize("kwargs, match", [
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
    ({"points": np.zeros((4, 3)), "values": np.arange(4.0), "vmin": 3, "vmax": 1}, "vmin <= vmax"),
])
def test_bad_points_raise_parameter_errors(viewer, kwargs, match):
    with pytest.raises(ParameterError, match=match):
        viewer.show_points(**kwargs)


def test_arrows_end_where_they_should(viewer):
    O = np.array([[0.0, 0.0, 0.0], [0.1, -0.2, 0.3], [0.5, 0.5, 0.5]])
    D = np.array([[0.0, 0.0, 2.0], [1.0, 1.0, 0.0], [-3.0, 1.0, 2.0]])
    tips = viewer.show_arrows(O, D, scale=0.1, radius=0.004, colors=[[1, 0, 0], [0, 1, 0], [0, 0, 1]], name="forces")
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
        assert along.min() > -1e-6 and abs(along.max() - np.linalg.norm(v)) < 1e-6   # tail at o, tip at o + v
        assert across.max() < 2.2 * 0.004 + 1e-6                                       # head radius
        assert np.isclose(across[along < 0.5 * np.linalg.norm(v)].max(), 0.004, atol=1e-6)  # shaft radius
    # a zero vector draws nothing; all-zero draws no object at all
    viewer.show_arrows(O[:1], np.zeros((1, 3)), name="forces")
    assert not objects_at(viewer, f"{viewer.root}/overlays/forces")
    with pytest.raises(ParameterError, match="same shape"):
        viewer.show_arrows(O, D[:2])
    with pytest.raises(ParameterError, match="positive"):
        viewer.show_arrows(O, D, scale=0.0)
    with pytest.raises(ParameterError, match="NaN"):
        viewer.show_arrows(O, D * np.nan)
