"""Synthetic trials for the motion tests: markers by Pinocchio FK of a known motion.

The marker positions are computed here from Pinocchio frame placements (``oMf[body].act(p)``),
independently of anthroarm.motion's own marker kinematics."""

import numpy as np
import pinocchio as pin

from anthroarm.ik.qp import comfortable_posture


def pin_marker_positions(robot, marker_set, Q):
    """(N, M, 3) world marker positions by Pinocchio frame placements (m)."""
    Q = np.atleast_2d(Q)
    model, data = robot.model, model_data(robot)
    fids = [model.getFrameId(m.body) for m in marker_set]
    out = np.empty((len(Q), len(marker_set), 3))
    for n, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        for k, (m, f) in enumerate(zip(marker_set, fids)):
            out[n, k] = data.oMf[f].act(np.asarray(m.position, float))
    return out


def model_data(robot):
    return robot.model.createData()


def known_motion(robot, n=200, rate=100.0, amplitude=0.3, seed=0):
    """A smooth motion around the comfortable posture inside the limits: each joint a sine of
    its own frequency and phase, amplitude a fraction of its half range."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    qc = comfortable_posture(robot)
    half = 0.5 * (robot.upper - robot.lower)
    f = rng.uniform(0.3, 1.0, robot.nq)
    ph = rng.uniform(0, 2 * np.pi, robot.nq)
    Q = qc + amplitude * half * np.sin(2 * np.pi * f * t[:, None] + ph)
    return t, np.clip(Q, robot.lower + 1e-3, robot.upper - 1e-3)
