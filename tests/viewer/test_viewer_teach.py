"""``Viewer.teach``: joint sliders on the page that move the robot, in a real browser.

A headless Chromium (one for the module) loads the page; the DevTools protocol sends real mouse
events (press, move, release) on a slider, as a person's drag, and reads back the slider values
and the transforms meshcat holds for every body.  Oracle: Pinocchio's forward kinematics at the
configuration the sliders show — the page computes its own FK from ``robot.chain`` and must
agree to 1e-9 m for every link, the mimic joint included.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.viewer import Viewer, browser


def user_urdf() -> str:
    """The user URDF of the chain tests (two continuous joints and a mimic finger)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "_chain_tests", Path(__file__).parents[1] / "foundation" / "test_chain.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.USER_URDF


@pytest.fixture(scope="module")
def user_robot(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(user_urdf())
    return aa.load(str(p), tool="tool")


def teach_spec(v: Viewer) -> dict:
    cmds = [umsgpack.unpackb(c) for c in v.store.commands()]
    (spec,) = [
        c["spec"] for c in cmds if c["type"] == "anthroarm_ui" and c["spec"]["kind"] == "teach"
    ]
    return spec


def test_one_slider_per_independent_joint_in_degrees_within_limits(user_robot):
    human = aa.load("human_arm7")
    v = Viewer(human).teach()
    spec = teach_spec(v)
    chain = human.chain
    assert [s["name"] for s in spec["sliders"]] == [j.name for j in chain.joints]
    for s, j in zip(spec["sliders"], chain.joints):
        # the limits in degrees, inside them on the slider's 0.1° grid
        assert s["unit"] == "°" and -1e-6 <= s["min"] - math.degrees(j.lower) < 0.1 + 1e-9
        assert -1e-6 <= math.degrees(j.upper) - s["max"] < 0.1 + 1e-9
    # continuous joints: ±180°; the mimic joint: no slider of its own, it follows its source
    v = Viewer(user_robot).teach()
    spec = teach_spec(v)
    names = {s["name"]: s for s in spec["sliders"]}
    assert set(names) == {"spin", "shoulder", "wrist", "grip"}
    assert (names["spin"]["min"], names["spin"]["max"]) == (-180.0, 180.0)
    mimic = user_robot.chain.joint("grip_mimic")
    js = spec["joints"][mimic.index]
    assert (js["src"], js["mult"], js["off"]) == (user_robot.chain.joint("grip").index, -1.0, 0.1)
    v.teach(False)
    assert not [
        c
        for c in v.store.commands()
        if umsgpack.unpackb(c)["type"] == "anthroarm_ui"
        and umsgpack.unpackb(c)["spec"]["kind"] == "teach"
    ]


# ---------------------------------------------------------------------------- real browser


@pytest.fixture(scope="module")
def page():
    with browser.live_tab("about:blank", size=(900, 640)) as tab, browser.DevTools(tab) as p:
        yield p


def load(page, url: str) -> None:
    page.call("Page.navigate", url=url)
    page.wait_for(
        "window.anthroarm_ready === true && document.querySelectorAll('#anthroarm-teach input').length > 0"
    )


def slider_values(page) -> dict:
    return dict(
        page.evaluate(
            "Array.from(document.querySelectorAll('#anthroarm-teach input[type=range]'))"
            ".map(function (e) { return [e.dataset.joint, parseFloat(e.value)]; })"
        )
    )


def scene_matrices(page, paths) -> dict:
    import json

    js = (
        "(function (paths) { var out = {}; paths.forEach(function (p) {"
        " var parts = p.split('/').filter(function (x) { return x.length > 0; });"
        " out[p] = Array.from(viewer.scene_tree.find(parts).object.matrix.elements); }); return out; })"
        f"({json.dumps(list(paths))})"
    )
    return {
        p: np.asarray(m).reshape(4, 4).T for p, m in page.evaluate(js).items()
    }  # three.js: column-major


def drag_slider(page, joint: str, to_fraction: float) -> None:
    r = page.evaluate(
        f"(function () {{ var e = document.querySelector('#anthroarm-teach input[data-joint=\"{joint}\"]');"
        " var b = e.getBoundingClientRect(); return [b.left, b.top, b.width, b.height,"
        " parseFloat(e.value), parseFloat(e.min), parseFloat(e.max)]; })()"
    )
    left, top, width, height, value, lo, hi = r
    thumb = (
        8.0  # Chromium's range thumb is 16 px wide: its centre travels from 8 px to width - 8 px
    )
    x0 = left + thumb + (value - lo) / (hi - lo) * (width - 2 * thumb)
    x1 = left + thumb + to_fraction * (width - 2 * thumb)
    page.drag((x0, top + height / 2), (x1, top + height / 2))


def expected_poses(v: Viewer, values: dict) -> dict:
    """Pinocchio's pose of every moving body at the configuration the sliders show."""
    robot = v.robot
    chain = robot.chain
    theta = []
    for j in (chain.joints[i] for i in chain.independent):
        s = values[j.name]
        theta.append(s * 1e-3 if j.kind == "prismatic" else math.radians(s))
    q = chain.configuration(np.array(theta))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return {
        path: (data.oMi[jid] if jid is not None else data.oMf[fid]).homogeneous
        for path, jid, fid in v._moving()
    }


@pytest.mark.browser
@pytest.mark.skipif(
    browser.find_chromium() is None and not os.environ.get("CI"), reason="chromium is not installed"
)
def test_dragging_a_slider_moves_the_live_robot_as_pinocchio_says(page):
    with Viewer("human_arm7", live=True) as v:
        v.teach()
        load(page, v.url)
        elbow = [p for p, j, _ in v._moving() if p.endswith("/elbow_flexion")][0]
        before = scene_matrices(page, [elbow])[elbow]
        values0 = slider_values(page)
        drag_slider(page, "elbow_flexion", 0.8)
        values = slider_values(page)
        assert (
            values["elbow_flexion"] > values0["elbow_flexion"] + 60
        )  # the drag moved the slider ...
        assert {k: x for k, x in values.items() if k != "elbow_flexion"} == {
            k: x for k, x in values0.items() if k != "elbow_flexion"
        }  # ... and only that one
        drag_slider(page, "shoulder_flexion", 0.7)
        values = slider_values(page)
        got = scene_matrices(page, [p for p, _, _ in v._moving()])
        want = expected_poses(v, values)
        assert set(got) == set(want)
        for path in want:
            np.testing.assert_allclose(got[path], want[path], atol=1e-9, err_msg=path)
        # the tool readout under the sliders: Pinocchio's tool pose (mm, rpy in degrees)
        text = page.evaluate(
            "document.querySelector('#anthroarm-teach .anthroarm-tool').textContent"
        )
        robot = v.robot
        theta = [math.radians(values[robot.chain.joints[i].name]) for i in robot.chain.independent]
        T = robot.fk(robot.chain.configuration(np.array(theta)))
        nums = [
            float(x)
            for x in text.replace("°", " ").replace("mm,", " ").split()
            if x.lstrip("-").replace(".", "").isdigit()
        ]
        np.testing.assert_allclose(nums[:3], 1000 * T[:3, 3], atol=0.051)
        np.testing.assert_allclose(
            nums[3:6], np.degrees(pin.rpy.matrixToRpy(T[:3, :3])), atol=0.051
        )
        # the scene really changed: the forearm's body turned by the dragged elbow angle
        R = before[:3, :3].T @ got[elbow][:3, :3]
        angle = math.degrees(math.acos(np.clip((np.trace(R) - 1) / 2, -1, 1)))
        assert angle > 30, angle


@pytest.mark.browser
@pytest.mark.skipif(
    browser.find_chromium() is None and not os.environ.get("CI"), reason="chromium is not installed"
)
def test_mimic_joint_follows_in_an_exported_page(page, user_robot, tmp_path):
    v = Viewer(user_robot)
    v.show_limits()
    v.teach()
    html = v.export_html(tmp_path / "teach.html")
    load(page, html.resolve().as_uri())
    drag_slider(page, "grip", 0.9)
    drag_slider(page, "spin", 0.2)  # a continuous joint: ±180° slider
    values = slider_values(page)
    assert values["grip"] > 0 and values["spin"] < -90
    got = scene_matrices(page, [p for p, _, _ in v._moving()])
    want = expected_poses(v, values)
    for path in want:
        np.testing.assert_allclose(got[path], want[path], atol=1e-9, err_msg=path)
    # joint-limit colours follow the sliders: the page's colours are the ones Python's
    # show_limits computes for the same configuration (limit_proximity, limit_color)
    drag_slider(page, "shoulder", 0.995)
    values = slider_values(page)
    chain = user_robot.chain
    q = chain.configuration(
        np.array([math.radians(values[chain.joints[i].name]) for i in chain.independent])
    )

    class Rec:
        def __init__(self):
            self.messages = []

        def send_many(self, cmds):
            self.messages.append(list(cmds))

    v._colors = {}
    v.server = rec = Rec()
    v.display(q)
    v.server = None
    colours = {c["path"]: c["color"] for c in rec.messages[-1] if c["type"] == "anthroarm_color"}
    import json

    shown = page.evaluate(
        "(function (paths) { var out = {}; paths.forEach(function (p) { var c = null;"
        " viewer.scene_tree.find(p.split('/').filter(function (x) { return x; })).object.traverse("
        "function (o) { if (c === null && o.material && o.material.color) { c = o.material.color.toArray(); } });"
        f" out[p] = c; }}); return out; }})({json.dumps(list(colours))})"
    )
    assert len(colours) >= 3
    red = [pth for pth, c in colours.items() if c[0] > 0.8 and c[2] < 0.3]
    assert red, colours  # the shoulder at 99.5 % of its range: something is red
    for pth, c in colours.items():
        np.testing.assert_allclose(shown[pth], c, atol=2e-3, err_msg=pth)
    # the mimic finger (grip_mimic = -grip + 0.1) really turned against the other
    a = [p for p in want if p.endswith("/grip")][0]
    b = [p for p in want if p.endswith("/grip_mimic")][0]
    rel = np.linalg.inv(got[a]) @ got[b]
    assert not np.allclose(rel[:3, :3], np.eye(3), atol=1e-3)


def test_cli_teach_writes_a_page_with_sliders_at_the_given_pose(tmp_path, capsys):
    from anthroarm.cli import main

    out = tmp_path / "teach.html"
    deg = [40.0, -20.0, 10.0, 70.0, 0.0, 0.0, 10.0]
    assert main(["teach", "human_arm7", "--q", *map(str, deg), "--deg", "--html", str(out)]) == 0
    import base64
    import json
    import re

    m = re.search(r"var cmds = (\[.*?\]);", out.read_text(encoding="utf-8"), re.S)
    cmds = [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]
    (spec,) = [
        c["spec"] for c in cmds if c["type"] == "anthroarm_ui" and c["spec"]["kind"] == "teach"
    ]
    assert [s["value"] for s in spec["sliders"]] == pytest.approx(deg)
    assert main(["teach", "human_arm7", "--q", "1", "2", "--html", str(tmp_path / "bad.html")]) == 2
    assert "needs 7 values" in capsys.readouterr().err
    assert not (tmp_path / "bad.html").exists()
