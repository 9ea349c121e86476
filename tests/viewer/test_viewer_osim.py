"""The viewer on an OpenSim model with nonlinear couplings (gait2392: 23 coordinates drive 27
Pinocchio joints, the knees' translations splines of the knee angles): the configuration the
viewer is given is the model's coordinates q; every body it draws sits at Pinocchio's pose at
φ(q), which ``robot.fk`` gives (itself checked against OpenSim in tests/osim).  No browser: the
commands the viewer sends are read back."""

from __future__ import annotations

import json
import os

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.viewer import Viewer, browser


class Recorder:
    """Stands in for the server: records every message the viewer sends."""

    def __init__(self):
        self.messages = []

    def send_many(self, cmds):
        self.messages.append(list(cmds))


@pytest.fixture(scope="module")
def gait():
    return aa.load(aa.osim.path("gait2392"))


def _joint_poses(robot, q):
    """Pose of every Pinocchio joint at coordinates q, from robot.fk of the OpenSim bodies:
    a body frame's pose times its placement's inverse is its joint's pose."""
    out = {}
    for f in robot.model.frames:
        if f.type == pin.FrameType.BODY and f.parentJoint > 0 and f.parentJoint not in out:
            T = robot.fk(q, f.name)
            out[f.parentJoint] = T @ np.linalg.inv(f.placement.homogeneous)
    return out


def _sent(messages):
    return {
        c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T
        for c in messages
        if c["type"] == "set_transform"
    }


def test_display_poses_are_robot_fk(gait):
    assert gait.coupling is not None and gait.nq == 23 and gait.model.nq == 27
    v = Viewer(gait)  # failed before: Pinocchio was given the 23 coordinates
    v.server = rec = Recorder()
    knee = gait.joint_names.index("knee_angle_r")
    checked = 0
    for q in gait.random_q(3, rng=4):
        for bend in (0.0, -2.0):  # knee straight and bent: the spline translation moves the tibia
            q = q.copy()
            q[knee] = bend
            v.display(q)
            sent = _sent(rec.messages[-1])
            want = _joint_poses(gait, q)
            for b in v.bodies:
                if b.joint is not None and b.joint + 1 in want:
                    np.testing.assert_allclose(sent[v._bpath(b)], want[b.joint + 1], atol=1e-12)
                    checked += 1
    assert checked >= 6 * 10


def test_play_keyframes_are_robot_fk(gait):
    v = Viewer(gait)
    Q = np.linspace(gait.default_q(), gait.random_q(rng=5), 4)
    v.play(Q, dt=0.1, trace=False)
    anim = next(
        c for c in (umsgpack.unpackb(c) for c in v.store.commands()) if c["type"] == "set_animation"
    )
    checked = 0
    for track in anim["animations"]:
        body = next(b for b in v.bodies if v._bpath(b) == track["path"])
        if body.joint + 1 not in _joint_poses(gait, Q[0]):
            continue  # a joint with no OpenSim body of its own (pelvis_tx ...)
        checked += 1
        pos = next(t for t in track["clip"]["tracks"] if t["name"] == ".position")["keys"]
        for k in (0, 3):
            want = _joint_poses(gait, Q[k])[body.joint + 1]
            np.testing.assert_allclose(pos[k]["value"], want[:3, 3], atol=1e-12)
    assert checked >= 10


def _page_theta(spec, values):
    """The page's joint values (the ``teach`` script of viewer/_store.py, step by step): each
    slider sets its coordinate, each Pinocchio joint follows by its table or linear relation."""
    theta = np.array(spec["theta"], dtype=float)
    for s in spec["sliders"]:
        theta[s["joint"]] = values[s["name"]] * s["scale"]
    for j, J in enumerate(spec["joints"]):
        if "xs" in J:
            theta[j] = np.interp(theta[J["src"]], J["xs"], J["ys"])
        elif J["src"] >= 0:
            theta[j] = J["mult"] * theta[J["src"]] + J["off"]
    return theta[: len(spec["joints"])]


def test_teach_sliders_are_the_coordinates(gait):
    """One slider per coordinate (23, named after them, their ranges), none for the knees'
    spline translations; the page's joints at any slider values are φ(q) (Pinocchio's FK of
    them = robot.fk's body poses, to the 1e-6 m of the sampled spline tables)."""
    v = Viewer(gait)
    spec = v._teach_spec()
    c = gait.coupling
    assert [s["name"] for s in spec["sliders"]] == list(gait.joint_names)
    assert "knee_r_translation1" not in {s["name"] for s in spec["sliders"]}
    for s, lo, hi in zip(spec["sliders"], gait.lower, gait.upper):
        assert lo - 1e-9 <= s["min"] * s["scale"] <= s["max"] * s["scale"] <= hi + 1e-9
        assert s["unit"] == ("mm" if s["name"] in ("pelvis_tx", "pelvis_ty", "pelvis_tz") else "°")
    tables = [J for J in spec["joints"] if "xs" in J]
    assert len(tables) == 4  # the two knees' two spline translations
    rng = np.random.default_rng(6)
    data = gait.model.createData()
    for _ in range(5):
        values = {s["name"]: rng.uniform(s["min"], s["max"]) for s in spec["sliders"]}
        q = np.array([values[s["name"]] * s["scale"] for s in spec["sliders"]])
        theta = _page_theta(spec, values)
        assert len(theta) == c.nq_full
        pin.forwardKinematics(gait.model, data, theta)
        for jid, T in _joint_poses(gait, q).items():
            np.testing.assert_allclose(data.oMi[jid].homogeneous, T, atol=1e-6)


@pytest.mark.browser
@pytest.mark.skipif(
    browser.find_chromium() is None and not os.environ.get("CI"), reason="chromium is not installed"
)
def test_teach_page_moves_the_knee_as_robot_fk(gait, tmp_path):
    """In headless Chromium: the exported page's knee slider set to -90° (its input event, as a
    drag fires it) puts every body where robot.fk puts it at the sliders' coordinates."""
    v = Viewer(gait)
    v.teach()
    html = v.export_html(tmp_path / "teach.html")
    with browser.live_tab("about:blank", size=(900, 640)) as tab, browser.DevTools(tab) as page:
        page.call("Page.navigate", url=html.resolve().as_uri())
        page.wait_for(
            "window.anthroarm_ready === true && "
            "document.querySelectorAll('#anthroarm-teach input').length > 0"
        )
        page.evaluate(
            "(function () { var e = document.querySelector("
            "'#anthroarm-teach input[data-joint=\"knee_angle_r\"]');"
            " e.value = -90; e.dispatchEvent(new Event('input')); })()"
        )
        values = dict(
            page.evaluate(
                "Array.from(document.querySelectorAll('#anthroarm-teach input[type=range]'))"
                ".map(function (e) { return [e.dataset.joint, parseFloat(e.value)]; })"
            )
        )
        paths = [p for p, jid, _ in v._moving() if jid is not None]
        js = (
            "(function (paths) { var out = {}; paths.forEach(function (p) {"
            " var parts = p.split('/').filter(function (x) { return x.length > 0; });"
            " out[p] = Array.from(viewer.scene_tree.find(parts).object.matrix.elements); });"
            f" return out; }})({json.dumps(paths)})"
        )
        got = {p: np.asarray(m).reshape(4, 4).T for p, m in page.evaluate(js).items()}
    assert values["knee_angle_r"] == -90
    spec = v._teach_spec()
    q = np.array([values[s["name"]] * s["scale"] for s in spec["sliders"]])
    want = _joint_poses(gait, q)
    checked = 0
    for path, jid, _ in v._moving():
        if jid in want:
            np.testing.assert_allclose(got[path], want[jid], atol=1e-6, err_msg=path)
            checked += 1
    assert checked >= 10
