"""arm26's muscles in the viewer (``viewer.muscles.show_muscles``), read back from a real meshcat
server on 127.0.0.1 (the scene a newly opened tab receives): one tube mesh per muscle under the
overlay, 8 vertices round each path point of ``muscles.path_points`` (itself checked against
OpenSim in tests/muscles/test_path_points_vs_opensim.py), every ring centred on its point
(geometry: the mean of a ring's vertices is the point), colours the linear blend of the relaxed
and active colours by activation, the previous drawing deleted on each call, bad activations a
:class:`~anthroarm.errors.MuscleError`.
"""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest
import umsgpack

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import MuscleError
from anthroarm.viewer import Viewer
from anthroarm.viewer.muscles import ACTIVE_RGB, DRAW_TOLERANCE, RELAXED_RGB, show_muscles


@pytest.fixture(scope="module")
def live():
    robot = aa.load(aa.osim.path("arm26"))
    with Viewer(robot, live=True) as v:
        yield robot, v


def server_commands(v: Viewer) -> list[dict]:
    """The commands the server replays to a new tab (its page), unpacked."""
    m = re.search(r"var cmds = (\[.*?\]);", v.server.static_html(), re.S)
    assert m, "no replayed commands in the server's page"
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]


def attribute(obj: dict, name: str) -> np.ndarray:
    a = obj["object"]["geometries"][0]["data"]["attributes"][name]
    return np.frombuffer(a["array"].data, np.float32).reshape(-1, a["itemSize"])


def meshes(v: Viewer, root: str) -> dict:
    return {
        c["path"][len(root) + 1 :]: c
        for c in server_commands(v)
        if c["type"] == "set_object" and c["path"].startswith(root + "/")
    }


def test_every_muscle_is_drawn_through_its_path_points(live):
    robot, v = live
    q = robot.random_q(rng=4)
    a = [0.0, 0.25, 0.5, 0.75, 1.0, 0.1]
    drawn = show_muscles(v, q, activations=a)
    ms = muscles.muscle_set(robot)
    paths = muscles.path_points(robot, ms, q, tolerance=DRAW_TOLERANCE)
    assert drawn == {n: len(p.points) for n, p in paths.items()}
    root = f"{v.root}/overlays/muscles"
    got = meshes(v, root)
    assert sorted(got) == sorted(ms.names)
    for k, (nm, p) in enumerate(paths.items()):
        X = attribute(got[nm], "position")
        assert len(X) == 8 * len(p.points), nm
        centres = X.reshape(len(p.points), 8, 3).mean(axis=1)
        np.testing.assert_allclose(centres, p.points, atol=1e-6)  # float32 vertices
        rgb = attribute(got[nm], "color")
        want = (1 - a[k]) * np.array(RELAXED_RGB) + a[k] * np.array(ACTIVE_RGB)
        np.testing.assert_allclose(rgb, np.tile(want, (len(rgb), 1)), atol=1e-6)
    # a wrapped muscle carries its arc: more points than its active path points
    assert drawn["BRA"] > 2 or not paths["BRA"].surface.any()


def test_each_call_replaces_the_drawing(live):
    robot, v = live
    show_muscles(v, robot.default_q())
    drawn = show_muscles(v, robot.default_q(), muscles=["BIClong", "BRA"])
    assert sorted(drawn) == ["BIClong", "BRA"]
    root = f"{v.root}/overlays/muscles"
    assert sorted(meshes(v, root)) == ["BIClong", "BRA"]
    v.clear("muscles")
    assert meshes(v, root) == {}


@pytest.mark.parametrize(
    "bad",
    [[0.5] * 5, [0.5] * 5 + [1.2], [0.5] * 5 + [-0.1], [0.5] * 5 + [float("nan")], ["x"] * 6],
)
def test_bad_activations_are_a_muscle_error(live, bad):
    robot, v = live
    with pytest.raises(MuscleError):
        show_muscles(v, robot.default_q(), activations=bad)


def test_activations_by_name(live):
    robot, v = live
    names = muscles.muscle_set(robot).names
    show_muscles(v, None, activations={n: 1.0 for n in names})
    with pytest.raises(MuscleError, match="no value"):
        show_muscles(v, None, activations={"BRA": 1.0})
