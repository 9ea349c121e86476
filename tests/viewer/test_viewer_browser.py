"""Real browser: headless Chromium (software WebGL) loads the exported HTML file and the live
server page, and the arm must be DRAWN where the camera model says it is.

Method: screenshot the scene, and the same scene with the robot's bodies deleted (baseline);
pixels that differ are the robot.  The expected region is the bounding box of every body
piece projected through meshcat's camera (75° vertical field of view, looking at the origin
from the position the viewer set), padded by the link thickness.  We require robot pixels
inside that box and (almost) none outside it.
"""

from __future__ import annotations

import math
import os

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.viewer import Viewer, browser
from anthroarm.viewer.visuals import PackedMesh

pytestmark = pytest.mark.browser

W, H = 640, 480

if browser.find_chromium() is None:  # pragma: no cover - CI installs chromium (.ci/run)
    if os.environ.get("CI"):
        # in CI the browser test is required: .ci/run installs Debian's chromium
        raise RuntimeError(
            "chromium is not installed but CI requires the real-browser test (.ci/run installs it)"
        )
    pytest.skip(
        "chromium is not installed (Debian: apt-get install chromium)", allow_module_level=True
    )


def camera_position(v: Viewer) -> np.ndarray:
    import umsgpack

    cam = [umsgpack.unpackb(c) for c in v.store.commands()]
    pos = [
        c["value"]
        for c in cam
        if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"
    ]
    x, y_up, z_up = pos[-1]
    return np.array([x, -z_up, y_up])  # meshcat's y-up camera frame -> world


def project(points: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Pixel coordinates of world points for a camera at C looking at the origin, z up."""
    f = -C / np.linalg.norm(C)
    r = np.cross(f, [0, 0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    V = points - C
    xc, yc, zc = V @ r, V @ u, V @ f
    t = math.tan(math.radians(75 / 2))
    px = (xc / (zc * t * W / H) + 1) / 2 * W
    py = (1 - yc / (zc * t)) / 2 * H
    return np.stack([px, py], 1)


def half_extent_corners(g) -> list[np.ndarray]:
    """Corners of the local bounding box of a meshcat primitive (cylinders are along y)."""
    kind = type(g).__name__
    if kind == "Sphere":
        e = np.full(3, g.radius)
    elif kind == "Ellipsoid":
        e = np.asarray(g.radii, float)
    elif kind == "Cylinder":
        e = np.array(
            [max(g.radiusTop, g.radiusBottom), g.height / 2, max(g.radiusTop, g.radiusBottom)]
        )
    elif kind == "Box":
        e = np.asarray(g.lengths, float) / 2
    elif isinstance(g, PackedMesh):  # a packed mesh: its grid's bounds (the offset places the grid)
        lo, hi = g.grid.min(0).astype(float), g.grid.max(0).astype(float)
        return [
            np.array([(lo, hi)[sx][0], (lo, hi)[sy][1], (lo, hi)[sz][2]])
            for sx in (0, 1)
            for sy in (0, 1)
            for sz in (0, 1)
        ]
    elif isinstance(g, mg.MeshGeometry):  # a mesh file: its own bounds
        import io

        import trimesh

        data = g.contents if isinstance(g.contents, bytes) else g.contents.encode()
        lo, hi = trimesh.load(io.BytesIO(data), file_type=g.mesh_format, force="mesh").bounds
        return [
            np.array([(lo, hi)[sx][0], (lo, hi)[sy][1], (lo, hi)[sz][2]])
            for sx in (0, 1)
            for sy in (0, 1)
            for sz in (0, 1)
        ]
    else:
        raise AssertionError(f"unexpected geometry {kind}")
    return [e * np.array([sx, sy, sz]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def expected_box(v: Viewer, q) -> tuple[int, int, int, int]:
    """Pixel box (x0, y0, x1, y1) around every body piece of the robot at q."""
    robot = v.robot
    pin.framesForwardKinematics(robot.model, robot.data, q)
    pts = []
    for b in v.bodies:
        M = (
            np.eye(4)
            if b.joint is None and b.frame is None
            else (
                robot.data.oMi[b.joint + 1].homogeneous
                if b.joint is not None
                else robot.data.oMf[b.frame].homogeneous
            )
        )
        for p in b.pieces:
            A = M @ p.offset
            pts.extend(A[:3, :3] @ c + A[:3, 3] for c in half_extent_corners(p.geometry))
    world = np.asarray(pts) - v.center
    px = project(world, camera_position(v))
    pad = 6  # anti-aliasing and the (un-modelled) perspective bulge of round shapes
    x0, y0 = px.min(0) - pad
    x1, y1 = px.max(0) + pad
    return int(max(0, x0)), int(max(0, y0)), int(min(W, x1)), int(min(H, y1))


def robot_pixels(png, base_png, box):
    m = browser.changed_mask(png, base_png)
    m[:40, W - 260 :] = False  # meshcat's "Open Controls" bar
    x0, y0, x1, y1 = box
    inside = int(m[y0:y1, x0:x1].sum())
    return inside, int(m.sum()) - inside


def baseline(v: Viewer, tmp_path, name="base"):
    """The same page without the robot's bodies."""
    v._send([{"type": "delete", "path": f"{v.root}/bodies"}])
    html = tmp_path / f"{name}.html"
    v.export_html(html)
    return browser.screenshot(html, tmp_path / f"{name}.png", size=(W, H), budget_ms=2000)


@pytest.fixture(scope="module")
def human():
    return aa.load("human_arm7")


@pytest.fixture(scope="module")
def base_png(human, tmp_path_factory):
    """The page without the robot (camera, floor and background depend on the model only)."""
    return baseline(Viewer(human), tmp_path_factory.mktemp("base"))


def test_static_html_draws_the_arm(human, base_png, tmp_path):
    q = np.deg2rad([60, -30, 10, 80, 0, 0, 10])
    v = Viewer(human)  # the camera frames the first pose: the same as the baseline's
    v.display(q)
    html = v.export_html(tmp_path / "arm.html")
    shot = browser.screenshot(html, tmp_path / "arm.png", size=(W, H), budget_ms=2000)
    box = expected_box(v, q)
    inside, outside = robot_pixels(shot, base_png, box)
    area = (box[2] - box[0]) * (box[3] - box[1])
    assert inside > 0.10 * area, (inside, area, box)
    assert outside < 0.02 * inside, (outside, inside)


def test_live_server_page_draws_and_follows_the_arm(human, base_png, tmp_path):
    q1 = np.deg2rad([20, -10, 0, 30, 0, 0, 0])
    q2 = np.deg2rad([150, -20, 30, 40, 0, 0, 0])
    with Viewer(human, live=True) as v:
        v.display(q1)
        s1 = browser.screenshot(v.url, tmp_path / "live1.png", size=(W, H), budget_ms=2000)
        box1 = expected_box(v, q1)
        inside, outside = robot_pixels(s1, base_png, box1)
        assert inside > 0.10 * (box1[2] - box1[0]) * (box1[3] - box1[1])
        assert outside < 0.02 * inside
        v.display(q2)  # a new tab must see the new pose
        s2 = browser.screenshot(v.url, tmp_path / "live2.png", size=(W, H), budget_ms=2000)
        box2 = expected_box(v, q2)
        inside2, outside2 = robot_pixels(s2, base_png, box2)
        assert inside2 > 0.10 * (box2[2] - box2[0]) * (box2[3] - box2[1])
        assert outside2 < 0.02 * inside2
        assert browser.changed_mask(s1, s2).mean() > 0.005  # the arm moved
        # negative control: the served page without the robot equals the static baseline
        v._send([{"type": "delete", "path": f"{v.root}/bodies"}])
        s0 = browser.screenshot(v.url, tmp_path / "live0.png", size=(W, H), budget_ms=2000)
        assert sum(robot_pixels(s0, base_png, box1)) < 50


def test_kinova_html_draws_the_arm_and_turns_its_continuous_joints(tmp_path):
    """kinova (three continuous joints, nq = 9, its URDF's meshes): the exported page draws
    the arm inside the projected bounds of its meshes, and turning the continuous base joint
    by 90° (a new (cos, sin) pair) moves it there."""
    robot = aa.load("kinova")
    chain = robot.chain
    theta = np.array([0.0, 2.4, 1.2, 0.5, 1.0, 0.3])  # base, shoulder, elbow, wrists (rad)
    base = [j for j in chain.joints if j.kind == "continuous"][0]
    pics = []
    v = Viewer(robot)
    for k, turn in enumerate((0.0, np.pi / 2)):
        th = theta.copy()
        th[base.index] += turn
        q = chain.configuration(th[list(chain.independent)])
        v.display(q)
        v.set_camera()  # framed on this pose, as a new Viewer(robot, q=q) is
        html = v.export_html(tmp_path / f"kinova{k}.html")
        shot = browser.screenshot(html, tmp_path / f"kinova{k}.png", size=(W, H), budget_ms=2000)
        base_png = baseline(Viewer(robot, q=q), tmp_path, f"kinova_base{k}")
        box = expected_box(v, q)
        inside, outside = robot_pixels(shot, base_png, box)
        area = (box[2] - box[0]) * (box[3] - box[1])
        assert inside > 0.10 * area, (k, inside, area, box)
        assert outside < 0.02 * inside, (k, outside, inside)
        pics.append(shot)
    assert browser.changed_mask(pics[0], pics[1]).mean() > 0.005  # the arm turned


def test_demo_html_shows_the_arm_moving(tmp_path):
    from anthroarm.viewer.demo import demo_viewer, reach_demo

    res = reach_demo(move_time=0.6, hold_time=0.2)
    v = demo_viewer(res)
    html = v.export_html(tmp_path / "demo.html")
    a = browser.screenshot(html, tmp_path / "t0.png", size=(W, H), budget_ms=300)
    b = browser.screenshot(html, tmp_path / "t1.png", size=(W, H), budget_ms=1500)
    # only the arm moves (targets and the traced path are fixed): the pictures differ
    assert browser.changed_mask(a, b).mean() > 0.005


def test_first_display_frames_the_robot(human, base_png, tmp_path):
    """The default camera: the robot as first displayed fills most of the frame's height and
    is not cut off (meshcat's default view had it fill about a third)."""
    v = Viewer(human)
    html = v.export_html(tmp_path / "framed.html")
    shot = browser.screenshot(html, tmp_path / "framed.png", size=(W, H), budget_ms=2000)
    m = browser.changed_mask(shot, base_png)
    m[:40, W - 260 :] = False
    ys, xs = np.nonzero(m)
    height = (ys.max() - ys.min()) / H
    assert height > 0.6, height
    assert ys.min() > 2 and ys.max() < H - 3 and xs.min() > 2 and xs.max() < W - 3
