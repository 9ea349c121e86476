"""Every scene is framed (issue 31 item 4): the subject — a robot, a voxel map around an arm, an
animation, the hand of a limb, a grasp — fills most of the view and nothing of it is cut off.

Method, independent of the viewer's own framing code: read the camera the page is given (the
position set on ``/Cameras/default/rotated/<object>`` in meshcat's y-up frame, and the scene
root's translation, from the packed commands of the exported page), project the subject's
points with meshcat's camera (75° vertical field of view, looking at the origin, z up, a 4:3
canvas; the browser test tests/viewer/test_viewer_browser.py checks this model against real
pixels) and measure the projected box on the canvas.  The subject's points: the corners of the
boxes of the drawn primitives at their Pinocchio poses, the map's voxel centres, the tool
positions of every pose of the animation.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.batch.result import BatchResult
from anthroarm.viewer import Viewer

FOV = 75.0
ASPECT = 4 / 3


def sent(v: Viewer) -> list[dict]:
    return [umsgpack.unpackb(c) for c in v.store.commands()]


def camera(v: Viewer) -> tuple[np.ndarray, np.ndarray]:
    """(camera position in meshcat's world, z up; the root's translation) as the page has them."""
    cmds = sent(v)
    x, y_up, z_up = [
        c["value"]
        for c in cmds
        if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"
    ][-1]
    root = [c for c in cmds if c["type"] == "set_transform" and c["path"] == v.root][-1]
    M = np.asarray(root["matrix"], float).reshape(4, 4).T  # column-major
    return np.array([x, -z_up, y_up]), M[:3, 3]


def project(points, C, aspect=ASPECT) -> np.ndarray:
    """Canvas coordinates in [0, 1] (x right, y down) of world points; camera at C looking at
    the origin with z up.  Also asserts every point is in front of the camera."""
    f = -C / np.linalg.norm(C)
    r = np.cross(f, [0, 0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    V = np.asarray(points, float) - C
    depth = V @ f
    assert depth.min() > 0, "part of the subject is behind the camera"
    t = math.tan(math.radians(FOV / 2))
    px = (V @ r / (depth * t * aspect) + 1) / 2
    py = (1 - V @ u / (depth * t)) / 2
    return np.stack([px, py], 1)


def box_points(g) -> np.ndarray:
    """Corners of a meshcat primitive's local box (cylinders along y)."""
    kind = type(g).__name__
    if kind == "Sphere":
        e = np.full(3, g.radius)
    elif kind == "Ellipsoid":
        e = np.asarray(g.radii, float)
    elif kind == "Cylinder":
        rr = max(g.radiusTop, g.radiusBottom)
        e = np.array([rr, g.height / 2, rr])
    elif kind == "Box":
        e = np.asarray(g.lengths, float) / 2
    else:  # a packed mesh: its vertex grid
        lo, hi = g.grid.min(0).astype(float), g.grid.max(0).astype(float)
        return np.array(
            [
                [(lo, hi)[a][0], (lo, hi)[b][1], (lo, hi)[c][2]]
                for a in (0, 1)
                for b in (0, 1)
                for c in (0, 1)
            ]
        )
    return np.array([e * [a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)])


def robot_points(v: Viewer, q, joints=None) -> np.ndarray:
    """Base-frame corners of every drawn piece at q (only bodies moved by ``joints``)."""
    robot = v.robot
    pin.framesForwardKinematics(robot.model, robot.data, q)
    pts = []
    for b in v.bodies:
        j = (
            b.joint
            if b.joint is not None
            else (robot.chain.frames[b.frame].joint if b.frame is not None else None)
        )
        if joints is not None and j not in joints:
            continue
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
            pts.extend(box_points(p.geometry) @ A[:3, :3].T + A[:3, 3])
    return np.asarray(pts)


def on_canvas(v: Viewer, points, aspect=ASPECT) -> tuple[float, float, np.ndarray]:
    """(width fraction, height fraction, box x0 y0 x1 y1) of the projected base-frame points."""
    C, shift = camera(v)
    px = project(np.asarray(points) + shift, C, aspect)
    lo, hi = px.min(0), px.max(0)
    return float(hi[0] - lo[0]), float(hi[1] - lo[1]), np.r_[lo, hi]


def assert_framed(v, points, least=0.6, aspect=ASPECT):
    w, h, box = on_canvas(v, points, aspect)
    assert box.min() >= 0.0 and box.max() <= 1.0, f"cut off: {box}"
    assert max(w, h) >= least, f"the subject fills {w:.2f} of the width, {h:.2f} of the height"
    return w, h


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


def test_a_robot_fills_the_view_from_every_named_side(arm):
    v = Viewer(arm)
    pts = robot_points(v, v.q)
    assert_framed(v, pts)
    for view in ("front", "side", "top", "back", "iso"):
        v.set_camera(view)
        assert_framed(v, pts)
    C, _ = camera(v)
    v.set_camera("front")
    C, _ = camera(v)
    assert C[0] > 0 and abs(C[1]) < 1e-9  # front: from +x
    with pytest.raises(aa.errors.ParameterError, match="front"):
        v.set_camera("frnt")


def test_a_voxel_map_is_seen_from_outside_with_the_arm_in_it(arm):
    """docs/batch.md's v.show_map(res): the camera was inside the cloud before."""
    rng = np.random.default_rng(0)
    P = arm.fk(arm.random_q(4000, rng=rng))[:, :3, 3]
    voxel = 0.05
    lo = np.floor(P.min(0) / voxel) * voxel
    idx = np.floor((P - lo) / voxel).astype(int)
    shape = tuple(idx.max(0) + 1)
    counts = np.zeros(shape, np.int64)
    np.add.at(counts, tuple(idx.T), 1)
    coords = {a: lo[k] + voxel * (np.arange(shape[k]) + 0.5) for k, a in enumerate("xyz")}
    res = BatchResult(
        job="reachability_map",
        variables={"counts": (("x", "y", "z"), counts)},
        coords=coords,
        attrs={"voxel": voxel},
    )
    v = Viewer(arm, q=np.deg2rad([40, -20, 10, 70, 0, 0, 10]))
    out = v.show_map(res)
    cloud = out["points"]
    C, shift = camera(v)
    base_cam = C - shift  # the camera in the base frame
    assert np.any(base_cam < cloud.min(0) - voxel) or np.any(base_cam > cloud.max(0) + voxel)
    assert_framed(v, cloud, least=0.75)
    assert_framed(v, robot_points(v, v.q), least=0.2)  # the arm inside, in view


def test_an_animation_stays_in_view(arm):
    """anthroarm demo swung the arm out of the frame: every pose of a play() is in view."""
    a = np.deg2rad([5, -5, 0, 15, 0, 0, 0])
    b = np.deg2rad([155, -10, 10, 25, 0, -10, 0])
    c = np.deg2rad([10, -80, 0, 20, -30, 0, 0])
    s = np.linspace(0, 1, 40)[:, None]
    Q = np.vstack([(1 - s) * a + s * b, (1 - s) * b + s * c])
    v = Viewer(arm)
    v.play(Q, 0.05)
    pts = np.vstack([robot_points(v, q) for q in Q[::4]])
    assert_framed(v, pts)


def test_the_hand_of_the_limb_is_readable_at_first_sight():
    """view human_upper_limb drew the hand at 60 x 120 px of 1400 x 1000 (6 % x 12 %)."""
    limb = aa.load("human_upper_limb")
    v = Viewer(limb)
    wrist = limb.chain.joint("wrist_flexion").index
    hand = {wrist} | {j.index for j in limb.chain.joints if j.index > wrist}
    w, h = assert_framed(v, robot_points(v, v.q, hand))
    v.set_camera(fit="pose")  # the whole limb on request
    assert_framed(v, robot_points(v, v.q))
    # the teach panel leaves a narrower pane: the hand is framed for it
    v = Viewer(limb).teach()
    from anthroarm.viewer.framing import TEACH_ASPECT

    assert_framed(v, robot_points(v, v.q, hand), aspect=TEACH_ASPECT)


def test_a_hand_on_its_own_is_framed_whole():
    hand = aa.load("prosthetic_hand")
    v = Viewer(hand)
    assert_framed(v, robot_points(v, v.q))


def test_a_camera_at_a_given_distance_stays_there(arm):
    v = Viewer(arm)
    v.set_camera("side", distance=3.0)
    v.show_points(np.array([[5.0, 0, 0], [-5.0, 0, 0]]))
    C, _ = camera(v)
    assert np.linalg.norm(C) == pytest.approx(3.0)
