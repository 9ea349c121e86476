"""The ``anthroarm demo`` scene: the §6-3 human arm reaching for a sequence of targets.

Each target is a hand pose (position and orientation of the hand point H) taken from a
natural posture — reach forward, hand to mouth, reach to the side, overhead, across the body
— so every target is reachable inside the joint ranges of Table 2.2.  The hand is driven to
each target by differential IK: the target moves from the current hand pose to the goal along
a minimum-jerk path (slerp for the orientation), then holds still for a moment.

IK per step (dt = 20 ms): QP differential IK (:mod:`anthroarm.ik.qp`: FrameTask + small
PostureTask, the model's configuration and velocity limits, OSQP by default).

>>> res = reach_demo()                 # DemoResult(Q (N, 7), dt, targets, errors, method)
>>> v = Viewer(res.robot); v.play(res.Q, res.dt); v.export_html("demo.html")

Function-local import (heavy, ~1 s: qpsolvers and OSQP, only paid for by a demo that runs):
``anthroarm.ik.qp`` in :class:`QPStepper`.
"""

from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..ik import qp
from ..loading import load
from .viewer import Viewer

#: Postures (degrees; shoulder x, y, z, elbow x, wrist z, y, x) whose hand poses are the targets.
REACH_POSTURES_DEG = {
    "reach forward": [85, -5, 0, 15, 0, 0, 10],
    "across the body": [70, 0, 45, 60, 20, 0, 0],
    "hand to mouth": [60, 5, 55, 135, 0, -5, 0],
    "reach to the side": [10, -80, 0, 20, -30, 0, 0],
    "overhead": [155, -10, 10, 25, 0, -10, 0],
    "back to rest": [5, -5, 0, 15, 0, 0, 0],
}


@dataclass
class DemoResult:
    robot: object
    Q: np.ndarray  # (N, nq) joint trajectory, rad
    dt: float  # s between rows
    targets: list  # [(name, 4x4 target pose)]
    errors: list = field(
        default_factory=list
    )  # [(name, position error m, rotation error rad)] at each hold end
    method: str = ""  # "qp/<solver>"


@contextlib.contextmanager
def quiet_c_stdout():
    """Silence C-level writes to stdout (some QP solvers print from C)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # Jupyter, captured output: nothing to do
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, fd)
        os.close(saved)


def min_jerk(s: np.ndarray) -> np.ndarray:
    """10 s³ − 15 s⁴ + 6 s⁵: 0 → 1 with zero velocity and acceleration at both ends."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s * s)


def interpolate_pose(T0: np.ndarray, T1: np.ndarray, s: float) -> np.ndarray:
    """Pose between T0 and T1: straight line for the position, slerp (log3/exp3) for the rotation."""
    T = np.eye(4)
    T[:3, 3] = (1 - s) * T0[:3, 3] + s * T1[:3, 3]
    w = pin.log3(T0[:3, :3].T @ T1[:3, :3])
    T[:3, :3] = T0[:3, :3] @ pin.exp3(s * w)
    return T


def pose_error(robot, q, T) -> tuple[float, float]:
    """(position error m, rotation angle error rad) of the tool at ``q`` against ``T``."""
    F = robot.fk(q)
    return float(np.linalg.norm(F[:3, 3] - T[:3, 3])), float(
        np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))
    )


# ----------------------------------------------------------------------------- IK stepper
class QPStepper:
    """One QP differential-IK step with anthroarm.ik.qp (FrameTask + PostureTask, default limits)."""

    def __init__(self, robot, q0, solver="osqp", orientation_cost=0.3):
        self.qp = qp
        self.conf = qp.IKConfiguration(robot, q0)
        self.ee = qp.FrameTask(
            robot, position_cost=1.0, orientation_cost=orientation_cost, lm_damping=1e-3
        )
        self.post = qp.PostureTask(robot, cost=1e-3)
        self.post.set_target(np.clip(robot.neutral(), robot.lower, robot.upper))
        self.solver = solver
        self.method = f"qp/{solver}"

    def __call__(self, q, T, dt):
        self.ee.set_target(T)
        v = self.qp.step(self.conf, None, [self.ee, self.post], dt=dt, solver=self.solver)
        self.conf.integrate_inplace(v, dt)
        return np.array(self.conf.q, dtype=float)


# ----------------------------------------------------------------------------- the demo
def reach_demo(
    robot=None,
    postures_deg=None,
    move_time: float = 1.4,
    hold_time: float = 0.5,
    dt: float = 0.02,
    method: str = "qp",
    solver: str = "osqp",
    progress=None,
) -> DemoResult:
    """Simulate the human arm reaching for each posture's hand pose in turn, by QP
    differential IK (``method`` "qp"; "auto" is the same).

    ``progress``: an optional callable ``progress(done, total)`` called once per target.
    Returns a :class:`DemoResult`; ``errors`` holds the pose error at the end of each hold."""
    robot = robot if robot is not None else load("human_arm7")
    postures = postures_deg if postures_deg is not None else REACH_POSTURES_DEG
    if method not in ("qp", "auto"):
        raise ValueError(
            f"method must be 'qp' (QP differential IK, anthroarm.ik.qp), got {method!r}"
        )
    if not (dt > 0 and move_time > 0 and hold_time >= 0):
        raise ValueError("dt and move_time must be > 0 and hold_time >= 0")
    targets = []
    for name, deg in postures.items():
        qt = np.clip(np.deg2rad(np.asarray(deg, float)), robot.lower, robot.upper)
        targets.append((name, robot.fk(robot.check_q(qt, name))))
    q = robot.neutral()
    step = QPStepper(robot, q, solver=solver)
    Q = [q.copy()]
    errors = []
    n_move = max(1, int(round(move_time / dt)))
    n_hold = int(round(hold_time / dt))
    with quiet_c_stdout():
        for k, (name, Tgoal) in enumerate(targets):
            T0 = robot.fk(q)
            for i in range(1, n_move + n_hold + 1):
                s = float(min_jerk(np.array(i / n_move)))
                q = step(q, interpolate_pose(T0, Tgoal, s), dt)
                Q.append(q.copy())
            errors.append((name, *pose_error(robot, q, Tgoal)))
            if progress is not None:
                progress(k + 1, len(targets))
    return DemoResult(robot, np.asarray(Q), dt, targets, errors, step.method)


def demo_viewer(res: DemoResult, live: bool = False, port=None):
    """A Viewer playing the demo: targets as overlays, the hand's path traced, looping."""
    v = Viewer(res.robot, live=live, port=port)
    for k, (name, T) in enumerate(res.targets):
        v.show_target(T, name=f"target_{k}", size=0.06)
    v.play(res.Q, res.dt, loop=True, trace=True)
    return v
