"""The viewer on an OpenSim model with nonlinear couplings (gait2392: 23 coordinates drive 27
Pinocchio joints, the knees' translations splines of the knee angles): the configuration the
viewer is given is the model's coordinates q; every body it draws sits at Pinocchio's pose at
φ(q), which ``robot.fk`` gives (itself checked against OpenSim in tests/osim).  No browser: the
commands the viewer sends are read back."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import anthroarm as aa
from anthroarm.viewer import Viewer


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
