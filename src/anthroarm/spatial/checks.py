"""Cross-check provider for the book's spatial mathematics (Ch. 5, 002 §4-1).

Rows ``spatial`` (errors are max-abs over random samples): E^{wθ} (5-105) vs ``pin.exp3``;
screw matrix (4-6) vs ``pin.exp6``; dual matrix (5-145) vs ``SE3.actInv`` on a Plücker line;
(5-130) vs the classical acceleration of a revolute–prismatic chain; Euler z–x–z (5-80) and
hand angles (6-47) round trips.  The mechanisms built on them (relative motion, RCCC) are
checked in :mod:`anthroarm.mechanisms.checks`, §6-6 error propagation in
:mod:`anthroarm.kinematics.checks`.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..check_rows import CheckRow
from . import dual as D
from .euler import euler_zxz, euler_zxz_inverse
from .hand_angles import hand_angles, hand_matrix
from .rotation_tensor import rotated_vector_motion, rotation_tensor
from .screw import screw_matrix, screw_twist

LWA = pin.LOCAL_WORLD_ALIGNED


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _spatial_rows(n, rng, CheckRow):
    W = _unit(rng, n)
    th = rng.uniform(-np.pi, np.pi, n)
    e_exp3 = max(np.abs(rotation_tensor(w, t) - pin.exp3(t * w)).max() for w, t in zip(W, th))
    e_exp6 = 0.0
    e_line = 0.0
    e_acc = 0.0
    e_euler = 0.0
    e_hand = 0.0
    for w, t in zip(W, th):
        p, s = rng.normal(size=3), rng.normal()
        tw = screw_twist(t, s, w, p)
        e_exp6 = max(
            e_exp6,
            np.abs(
                screw_matrix(t, s, w, p) - pin.exp6(pin.Motion(tw[:3], tw[3:])).homogeneous
            ).max(),
        )
        M = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        L = D.Line.from_point_direction(rng.normal(size=3), rng.normal(size=3))
        L2 = D.transform_line(D.dual_matrix_from_se3(M.rotation, M.translation), L)
        m = M.actInv(L.as_motion())
        e_line = max(e_line, np.abs(np.r_[L2.moment - m.linear, L2.u - m.angular]).max())
        # (5-130) vs a revolute-prismatic chain
        R, Rd, Rdd = rng.normal(size=(3, 3))
        thd, thdd = rng.normal(size=2)
        mot = rotated_vector_motion(w, t, thd, thdd, R, Rd, Rdd)
        model = pin.Model()
        j = model.addJoint(0, pin.JointModelRevoluteUnaligned(w), pin.SE3.Identity(), "r")
        for name, jm in (
            ("x", pin.JointModelPX()),
            ("y", pin.JointModelPY()),
            ("z", pin.JointModelPZ()),
        ):
            j = model.addJoint(j, jm, pin.SE3.Identity(), name)
        data = model.createData()
        pin.forwardKinematics(model, data, np.r_[t, R], np.r_[thd, Rd], np.r_[thdd, Rdd])
        acc = pin.getClassicalAcceleration(model, data, j, LWA).linear
        e_acc = max(e_acc, np.abs(mot.acceleration - acc).max() / max(1.0, np.abs(acc).max()))
        a = rng.uniform(-np.pi, np.pi, 3)
        a[1] = rng.uniform(0.05, np.pi - 0.05)
        C = euler_zxz(*a)
        ref = (
            pin.exp3(np.array([0, 0, a[0]]))
            @ pin.exp3(np.array([a[1], 0, 0]))
            @ pin.exp3(np.array([0, 0, a[2]]))
        )
        e_euler = max(
            e_euler,
            np.abs(C - ref).max(),
            np.abs(euler_zxz(*euler_zxz_inverse(C).angles) - C).max(),
        )
        b = rng.uniform(-1.5, 1.5)
        H = hand_matrix(a[0], b, a[2])
        e_hand = max(e_hand, np.abs(hand_angles(H).angles - np.array([a[0], b, a[2]])).max())
    return [
        CheckRow("spatial", "E^{wθ} (5-105) vs exp3", float(e_exp3), 1e-12, n),
        CheckRow("spatial", "screw matrix 002 (4-6) vs exp6", float(e_exp6), 1e-12, n),
        CheckRow("spatial", "dual matrix (5-145) on a line vs SE3.actInv", float(e_line), 1e-11, n),
        CheckRow("spatial", "rotated vector acc (5-130) vs classical acc", float(e_acc), 1e-11, n),
        CheckRow(
            "spatial",
            "Euler z-x-z (5-80) vs exp3, inverse",
            float(e_euler),
            1e-10,
            n,
            "pinocchio+round trip",
        ),
        CheckRow(
            "spatial", "hand angles (6-44)/(6-47) round trip", float(e_hand), 1e-10, n, "round trip"
        ),
    ]


def rows(models, samples, rng) -> list:
    """Provider for :mod:`anthroarm.crosscheck` (``samples`` capped at 50 to keep it ~ a second;
    the rows need no model)."""

    return _spatial_rows(max(1, min(int(samples), 50)), rng, CheckRow)
