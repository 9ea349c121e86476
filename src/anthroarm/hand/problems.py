"""Reachable random grasps, with a witness configuration, for tests and benchmarks.

:func:`reachable_grasps` draws grasp problems that are solvable by construction:

1. an object (cylinder or sphere) of random radius is placed in the **palm frame** in front of
   the palm (on the side the pads face, from :mod:`anthroarm.hand.fingers`), and the fingers
   alone (arm held, :func:`~anthroarm.hand.grasp.solve_grasp` with ``move_arm=False``, sliding
   contacts) are closed on it from the open hand; draws where that fails are discarded;
2. the arm is drawn uniformly inside its limits (``margin`` rad); the witness is that arm
   configuration with the finger configuration of step 1, and the object is carried with the
   palm (its pose relative to the palm is what step 1 solved);
3. the contact points are the fingertips of the witness (Pinocchio FK).

So the witness ``q`` puts every fingertip on its contact point with its pad normal against the
surface (to the criteria of step 1) inside the limits: each problem is reachable.  A solver is
then asked to find *a* configuration from a start that knows nothing of the witness (the
comfortable posture, the open hand).  On a hand without arm joints step 2 is skipped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .fingers import Hand
from .grasp import solve_grasp
from .objects import Cylinder, Sphere


@dataclass
class GraspProblem:
    """One reachable grasp: ``obj`` (world frame), ``contacts`` (n, 3) m, the ``witness``
    configuration (nq,) and ``T_palm_obj``: the object's frame (centre, axis as z) in the palm
    frame."""

    obj: object
    contacts: np.ndarray
    witness: np.ndarray
    T_palm_obj: np.ndarray


def _frame(z) -> np.ndarray:
    z = z / np.linalg.norm(z)
    e = np.eye(3)[int(np.argmin(np.abs(z)))]
    x = e - (e @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def palm_axes(hand: Hand, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(palmar normal, finger direction, across) in the palm frame's axes at ``q``: the mean
    pad normal of the fingers, the mean direction from the palm to the fingertips made normal
    to it, and their cross product (unit vectors; derived from the chain, no names)."""
    model = hand.robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    Mp = data.oMf[hand.palm_id]
    normals = [Mp.rotation.T @ (data.oMf[f.tip_id].rotation @ f.pad_axis) for f in hand.fingers]
    tips = [Mp.actInv(data.oMf[f.tip_id]).translation for f in hand.fingers]
    n = np.mean(normals, axis=0)
    n /= np.linalg.norm(n)
    d = np.mean(tips, axis=0)
    d -= (d @ n) * n
    d /= np.linalg.norm(d)
    return n, d, np.cross(n, d)


def open_hand(robot, hand: Hand, q=None) -> np.ndarray:
    """``q`` (default: neutral clipped into the limits) with every finger joint at the end of its
    range opposite to flexion (the pad side), clipped: the open hand."""
    chain = robot.chain
    q = robot.neutral() if q is None else np.array(q, dtype=float)
    lo, hi = chain.lower, chain.upper
    q = np.where(np.isfinite(lo), np.maximum(q, lo), q)
    q = np.where(np.isfinite(hi), np.minimum(q, hi), q)
    for f in hand.fingers:
        for i in f.joints:
            j = chain.joints[i]
            if j.is_mimic or j.nq != 1:
                continue
            flex_positive = not (np.isfinite(j.lower) and np.isfinite(j.upper)) or j.upper >= -j.lower
            q[j.idx_q] = min(max(0.0, j.lower), j.upper) if flex_positive else max(min(0.0, j.upper), j.lower)
    return q


def reachable_grasps(robot, n: int, kind: str = "cylinder", rng=None, hand: Hand | None = None,
                     radius=(0.015, 0.04), arm_margin: float = 0.2, max_draws: int | None = None,
                     solver: str = "daqp") -> list[GraspProblem]:
    """``n`` reachable grasp problems (see the module docstring).

    Parameters
    ----------
    robot : anthroarm.Robot
    n : int
    kind : ``"cylinder"`` or ``"sphere"``
    rng : seed or numpy Generator
    hand : Hand, optional
    radius : (float, float)
        Range of the object radius, m.
    arm_margin : float
        Arm joints are drawn this far inside their limits (rad or m).
    max_draws : int, optional
        Give up after this many objects (default 20 n); fewer problems are returned then.
    solver : str
        QP backend of step 1.
    """
    if kind not in ("cylinder", "sphere"):
        raise ValueError(f"kind must be 'cylinder' or 'sphere', got {kind!r}")
    rng = np.random.default_rng(rng)
    hand = Hand(robot) if hand is None else hand
    model = robot.model
    data = model.createData()
    q_open = open_hand(robot, hand)
    pin.framesForwardKinematics(model, data, q_open)
    Mp0 = pin.SE3(data.oMf[hand.palm_id])
    nrm, fdir, across = palm_axes(hand, q_open)
    tips0 = np.array([Mp0.actInv(data.oMf[f.tip_id]).translation for f in hand.fingers])
    depth = float(np.mean(tips0 @ fdir))          # how far the fingers reach along the hand
    arm_q = []
    for i in hand.arm_joints:
        j = robot.chain.joints[i]
        if not j.is_mimic:
            arm_q.extend(range(j.idx_q, j.idx_q + j.nq))
    lo_box, hi_box = robot.chain.sampling_box
    margin = min(float(arm_margin), 0.45 * float(np.min(hi_box - lo_box))) if len(lo_box) else 0.0
    out = []
    draws = 0
    max_draws = 20 * n if max_draws is None else max_draws
    while len(out) < n and draws < max_draws:
        draws += 1
        r = float(rng.uniform(*radius))
        c = (nrm * (r + rng.uniform(0.005, 0.025)) + fdir * depth * rng.uniform(0.1, 0.4)
             + across * rng.uniform(-0.01, 0.01))
        axis = across + 0.3 * rng.uniform(-1, 1, 3)
        R = _frame(axis)
        T_palm_obj = np.eye(4)
        T_palm_obj[:3, :3] = R
        T_palm_obj[:3, 3] = c
        Tw = Mp0.homogeneous @ T_palm_obj
        obj = Cylinder(Tw[:3, 3], Tw[:3, 2], r) if kind == "cylinder" else Sphere(Tw[:3, 3], r)
        res = solve_grasp(robot, obj, hand=hand, q0=q_open, move_arm=False, solver=solver, restarts=0,
                          max_iterations=100,
                          position_tol=2e-4, normal_tol=np.radians(1.0))
        if not res.success:
            continue
        q = res.q.copy()
        if arm_q:
            q[arm_q] = robot.random_q(rng=rng, margin=margin)[arm_q]
        pin.framesForwardKinematics(model, data, q)
        Tw = data.oMf[hand.palm_id].homogeneous @ T_palm_obj
        obj = Cylinder(Tw[:3, 3], Tw[:3, 2], r) if kind == "cylinder" else Sphere(Tw[:3, 3], r)
        contacts = np.array([data.oMf[f.tip_id].translation for f in hand.fingers])
        out.append(GraspProblem(obj, contacts, q, T_palm_obj))
    return out
