"""Reachable random grasps, with a witness configuration, for tests and benchmarks.

:func:`reachable_grasps` draws grasp problems that are solvable by construction:

1. an object (cylinder or sphere) of random radius r is placed in the **palm frame** in front of
   the palm (:func:`palm_axes`: r + 5..25 mm along the mean pad normal of the open hand,
   10..40 % of the fingers' length along them, ±1 cm across; a cylinder's axis across the
   palm, tilted at random), and the fingers
   alone (arm held, :func:`~anthroarm.hand.grasp.solve_grasp` with ``move_arm=False``, sliding
   contacts, to 0.2 mm and 1°) are closed on it from the open hand; draws where that fails are
   discarded;
2. the arm is drawn uniformly inside its limits (``arm_margin`` rad), ``per_hand`` times per
   hand grasp of step 1 (each a different problem: the arm is what a solver must find); the witness
   is that arm configuration with the finger configuration of step 1, and the object is carried with
   the palm (its pose relative to the palm is what step 1 solved);
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

from .collision_grasp import CollisionGrasp, open_fingers
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
    range opposite to flexion (the pad side), clipped: the open hand
    (:func:`anthroarm.hand.collision_grasp.open_fingers`)."""
    return open_fingers(robot, hand, q)


def _fit_object(hand, model, data, q, Mp0, r, kind, across, weights=None):
    """(T_palm_obj, object in the world) of radius ``r`` fitted to the pads at ``q``: the centres
    p_i + r n_i (fingertip p_i, pad normal n_i, palm frame), their mean as the centre and, for a
    cylinder, their principal direction as the axis (a sphere's frame takes ``across`` as z); the
    fingertips weighted by ``weights`` (default equal)."""
    pin.framesForwardKinematics(model, data, q)
    Mp = data.oMf[hand.palm_id]
    centres = np.array([Mp.actInv(data.oMf[f.tip_id]).act(r * f.pad_axis) for f in hand.fingers])
    w = np.ones(len(centres)) if weights is None else np.asarray(weights, dtype=float)
    w = w / w.sum()
    c = w @ centres
    if kind != "cylinder":
        axis = across
    elif len(centres) >= 3:
        axis = np.linalg.svd((centres - c) * np.sqrt(w)[:, None])[2][0]
    else:  # a pinch: the axis normal to the line of the two pads, nearest the palm normal
        e = centres[-1] - centres[0]
        e = e / max(float(np.linalg.norm(e)), 1e-12)
        nrm = palm_axes(hand, q)[0]
        axis = nrm - (nrm @ e) * e
    T_palm_obj = np.eye(4)
    T_palm_obj[:3, :3] = _frame(axis)
    T_palm_obj[:3, 3] = c
    Tw = Mp0.homogeneous @ T_palm_obj
    obj = Cylinder(Tw[:3, 3], Tw[:3, 2], r) if kind == "cylinder" else Sphere(Tw[:3, 3], r)
    return T_palm_obj, obj


def _open_start(robot, hand, kind, rng):
    """What both problem generators start from: (the rng, the Hand, Pinocchio's model and a
    data, the open hand's configuration, the palm's pose there); ``kind`` checked."""
    if kind not in ("cylinder", "sphere"):
        raise ValueError(f"kind must be 'cylinder' or 'sphere', got {kind!r}")
    hand = Hand(robot) if hand is None else hand
    model = robot.model
    data = model.createData()
    q_open = open_hand(robot, hand)
    pin.framesForwardKinematics(model, data, q_open)
    return np.random.default_rng(rng), hand, model, data, q_open, pin.SE3(data.oMf[hand.palm_id])


def reachable_grasps(
    robot,
    n: int,
    kind: str = "cylinder",
    rng=None,
    hand: Hand | None = None,
    radius=(0.015, 0.04),
    arm_margin: float = 0.2,
    max_draws: int | None = None,
    solver: str = "daqp",
    per_hand: int = 1,
    rounds: int = 6,
) -> list[GraspProblem]:
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
    per_hand : int
        Arm configurations drawn per hand grasp of step 1 (a hand without arm joints: 1).
    rounds : int
        Fit-and-close rounds of step 1 per draw.
    """
    rng, hand, model, data, q_open, Mp0 = _open_start(robot, hand, kind, rng)
    nrm, fdir, across = palm_axes(hand, q_open)
    fq = hand.finger_q_indices
    lo_f, hi_f = robot.chain.lower[fq], robot.chain.upper[fq]
    lo_f = np.where(np.isfinite(lo_f), lo_f, -np.pi)
    hi_f = np.where(np.isfinite(hi_f), hi_f, np.pi)
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
        # a random half-closed hand; the object fitted to where its pads point, then the fingers
        # closed on it and the object fitted again (alternation: the pair becomes consistent)
        q_h = q_open.copy()
        q_h[fq] = lo_f + (hi_f - lo_f) * rng.uniform(0.2, 0.8, len(fq))
        res = None
        w = None
        for _ in range(rounds):
            T_palm_obj, obj = _fit_object(hand, model, data, q_h, Mp0, r, kind, across, w)
            if obj.size > hand.span:
                break
            res = solve_grasp(
                robot,
                obj,
                hand=hand,
                q0=q_h,
                move_arm=False,
                solver=solver,
                restarts=0,
                max_iterations=40,
                position_tol=2e-4,
                normal_tol=np.radians(1.0),
            )
            if res.success:
                break
            q_h = res.q
            # the fingers that did not reach pull the next fit toward them
            w = 1.0 + res.position_errors / 1e-3 + res.normal_errors / np.radians(5.0)
        if res is None or not res.success:
            continue
        for _ in range(int(per_hand) if arm_q else 1):
            if len(out) >= n:
                break
            q = res.q.copy()
            if arm_q:
                q[arm_q] = robot.random_q(rng=rng, margin=margin)[arm_q]
            pin.framesForwardKinematics(model, data, q)
            Tw = data.oMf[hand.palm_id].homogeneous @ T_palm_obj
            obj = Cylinder(Tw[:3, 3], Tw[:3, 2], r) if kind == "cylinder" else Sphere(Tw[:3, 3], r)
            contacts = np.array([data.oMf[f.tip_id].translation for f in hand.fingers])
            out.append(GraspProblem(obj, contacts, q, T_palm_obj))
    return out


def _object(kind, T, r, length):
    """The object of radius ``r`` whose frame (centre, axis as z) is ``T`` (4×4, world)."""
    if kind == "cylinder":
        return Cylinder(T[:3, 3], T[:3, 2], r, length=length)
    return Sphere(T[:3, 3], r)


def collision_free_grasps(
    robot,
    n: int,
    kind: str = "cylinder",
    rng=None,
    hand: Hand | None = None,
    radius=(0.015, 0.035),
    arm_margin: float = 0.2,
    per_hand: int = 1,
    max_draws: int | None = None,
    arm_tries: int = 20,
    rounds: int = 6,
    solver: str = "daqp",
) -> list[GraspProblem]:
    """``n`` reachable grasp problems whose witness is a collision-free grasp.

    As :func:`reachable_grasps`, with the object fitted so that the fingertip *capsules* touch
    it: step 1 fits an object of radius r + ρ + g (ρ the largest fingertip capsule radius,
    g half the contact margin, :class:`~anthroarm.hand.collision_grasp.CollisionGrasp`) to
    the pads of a random hand (finger joints 10..60 % of their ranges) and closes the fingers
    on it; the object is then the one of radius r with the same centre and axis (a cylinder
    2 cm longer than the fingertips' spread along it).  A draw is kept when coal finds every
    fingertip capsule within the contact margin of the object and no body in it or in another
    body; each arm draw of step 2 is checked the same way (the arm against the torso and the
    object), up to ``arm_tries`` draws.  The contacts are the object's surface points under
    the fingertips of the witness.  On the human limb's hand this keeps most pinches (thumb
    and index) and few grasps with more fingers (their proximal phalanges cross the object).
    """
    rng, hand, model, data, q_open, Mp0 = _open_start(robot, hand, kind, rng)
    across = palm_axes(hand, q_open)[2]
    fq = hand.finger_q_indices
    lo_f, hi_f = robot.chain.lower[fq], robot.chain.upper[fq]
    lo_f = np.where(np.isfinite(lo_f), lo_f, -np.pi)
    hi_f = np.where(np.isfinite(hi_f), hi_f, np.pi)
    aq = hand.arm_q_indices
    lo_box, hi_box = robot.chain.sampling_box
    margin = min(float(arm_margin), 0.45 * float(np.min(hi_box - lo_box))) if len(lo_box) else 0.0
    grow = None
    out = []
    draws = 0
    max_draws = 20 * n if max_draws is None else max_draws
    while len(out) < n and draws < max_draws:
        draws += 1
        r = float(rng.uniform(*radius))
        q_h = q_open.copy()
        q_h[fq] = lo_f + (hi_f - lo_f) * rng.uniform(0.1, 0.6, len(fq))
        res, w = None, None
        for _ in range(rounds):
            if grow is None:
                cg = CollisionGrasp(robot, hand, Sphere(Mp0.translation, r))
                grow = float(cg.radii.max()) + cg.gap
            T_palm_obj, obj = _fit_object(hand, model, data, q_h, Mp0, r + grow, kind, across, w)
            if obj.size > hand.span:
                break
            res = solve_grasp(
                robot, obj, hand=hand, q0=q_h, move_arm=False, solver=solver, restarts=0,
                max_iterations=40, position_tol=2e-4, normal_tol=np.radians(1.0),
            )  # fmt: skip
            if res.success:
                break
            q_h = res.q
            w = 1.0 + res.position_errors / 1e-3 + res.normal_errors / np.radians(5.0)
        if res is None or not res.success:
            continue
        L = None
        if kind == "cylinder":
            pin.framesForwardKinematics(model, data, res.q)
            h = [obj.height(data.oMf[f.tip_id].translation) for f in hand.fingers]
            L = 2.0 * float(np.max(np.abs(h))) + 0.02
        if not CollisionGrasp(robot, hand, _object(kind, Mp0.homogeneous @ T_palm_obj, r, L)).ok(
            res.q
        ):
            continue
        for _ in range(int(per_hand) if len(aq) else 1):
            if len(out) >= n:
                break
            for _ in range(int(arm_tries) if len(aq) else 1):
                q = res.q.copy()
                if len(aq):
                    q[aq] = robot.random_q(rng=rng, margin=margin)[aq]
                pin.framesForwardKinematics(model, data, q)
                o = _object(kind, data.oMf[hand.palm_id].homogeneous @ T_palm_obj, r, L)
                if CollisionGrasp(robot, hand, o).ok(q):
                    contacts = np.array(
                        [o.project(data.oMf[f.tip_id].translation) for f in hand.fingers]
                    )
                    out.append(GraspProblem(o, contacts, q, T_palm_obj))
                    break
    return out
