"""The pieces of a collision-free fingertip grasp (:func:`anthroarm.hand.solve_grasp` with
``collision_free=True``).

The grasped object is a collision body (:meth:`Sphere.obstacle
<anthroarm.hand.objects.Sphere.obstacle>`, :meth:`Cylinder.obstacle
<anthroarm.hand.objects.Cylinder.obstacle>`) beside the robot's own capsules and boxes
(:func:`anthroarm.collision.model`).  A fingertip is a capsule of radius r around the distal
phalanx's axis, and its frame sits on that axis: a fingertip *touches* the object when the
capsule's surface is within the contact margin δ of the object's, i.e. when the tip frame lies
on the object grown by r + g, with the target gap g = δ/2 (``CollisionGrasp.target``; the
fingertip surface at a gap from the object surface, not the fingertip centre on it).

Every QP step of the collision-free iterations carries the velocity damper of Faverjon &
Tournassoud (1987), :class:`~anthroarm.ik.qp.limits.collision.CollisionLimit`, on every pair
closer than d_i: the fingertip capsules against the object aim at d = 0 (``contact_bodies``,
they must reach it), every other body against the object and every active self pair (finger
against finger, finger against palm, arm against torso) at d = :data:`CLEARANCE`.  The step
acceptance of :func:`~anthroarm.ik.qp.limits.collision_step.step` keeps the true distances
(coal) above min(0, the distance before the step).

Success adds to the grasp's own criteria (:mod:`anthroarm.hand.grasp`), by coal at the answer:
no body deeper than :data:`PENETRATION_TOL` (1e-4 m) into the object or into another body, and
every fingertip capsule within [−1e-4 m, δ] of the object.
"""

from __future__ import annotations

import math

import numpy as np

from .. import collision, ik
from ..errors import GraspError
from ..ik.qp.limits.collision import CollisionLimit
from ..ik.qp.limits.collision_step import step as collision_step
from .fingers import Hand

#: the contact margin δ (m): a fingertip capsule this close to the object touches it
CONTACT_MARGIN = 1e-3
#: the deepest penetration (m) into the object or between two bodies that counts as none
PENETRATION_TOL = 1e-4
#: the trust region (rad or m per iteration) of the collision-free iterations: the damper
#: linearises d, and 0.2 rad steps leaked ~2 mm into the object
COLLISION_MAX_STEP = 0.05
#: the distance (m) the damper keeps between bodies that need not touch
CLEARANCE = 2e-4
#: detection distance d_i (m) and the approach allowed at d_i per iteration, ξ dt (m): a pair
#: closes at most half its gap beyond d_s per iteration
D_DETECT = 0.04
XI_DT = 0.02
#: how far (m) the open hand starts behind the grasp along the palm normal
APPROACH_BACK = 0.04


def open_fingers(robot, hand: Hand, q=None) -> np.ndarray:
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
            flex_positive = (
                not (np.isfinite(j.lower) and np.isfinite(j.upper)) or j.upper >= -j.lower
            )
            q[j.idx_q] = (
                min(max(0.0, j.lower), j.upper)
                if flex_positive
                else max(min(0.0, j.upper), j.lower)
            )
    return q


class CollisionGrasp:
    """The object as an obstacle, the fingertip capsules, the target surface (the object grown
    by the fingertip radius and the target gap), the damper and the coal report.

    Parameters
    ----------
    robot : anthroarm.Robot
    hand : Hand
    obj : Sphere or Cylinder
    margin : float
        The contact margin δ (m, > 0).
    """

    def __init__(self, robot, hand: Hand, obj, margin: float = CONTACT_MARGIN):
        m = float(margin)
        if not (math.isfinite(m) and m > 0):
            raise GraspError(f"contact_margin must be finite and > 0 (m), got {margin!r}")
        self.robot, self.hand, self.obj, self.margin = robot, hand, obj, m
        # every finger of the tree, those that do not grasp too (opened out of the way)
        self.all_fingers = Hand(robot) if len(hand.fingers) < len(robot.chain.tips) else hand
        cm = collision.model(robot)
        self.env = collision.environment([obj.obstacle()])
        self.tip_bodies, radii = [], []
        for f in hand.fingers:
            j = robot.model.frames[f.tip_id].parentJoint
            idx = [i for i in range(cm.n) if cm.joint[i] == j and cm.is_capsule[i]]
            if not idx:
                raise GraspError(
                    f"{robot.name}: fingertip {f.tip!r} has no capsule in its collision model"
                )
            self.tip_bodies.append(idx[0])
            radii.append(float(cm.cap_radius[idx[0]]))
        self.radii = np.array(radii)
        #: the target gap g = δ/2 between a fingertip capsule and the object
        self.gap = 0.5 * m
        # one target surface for every fingertip: the largest radius (tips of smaller radius
        # aim at a gap larger by the difference; the report says whether it stays within δ)
        self.target = obj.inflated(float(self.radii.max()) + self.gap)
        self.limit = CollisionLimit(
            robot,
            self.env,
            d_safe=0.0,
            d_detect=D_DETECT,
            xi=XI_DT,
            margin=CLEARANCE,
            contact_bodies=self.tip_bodies,
        )

    def step(self, conf, tasks, limits, couplings, solver):
        """One QP step with the damper (the ``step_fn`` of the grasp iterations)."""
        return collision_step(
            conf,
            None,
            tasks,
            1.0,
            limits=[*limits, self.limit],
            solver=solver if solver in ("daqp", "quadprog") else "daqp",
            damping=1e-9,
            full=True,
        )

    def report(self, q) -> dict:
        """Penetration into the object, self-collision depth and fingertip gaps at ``q``
        (coal, every checked pair), and whether they make a collision-free grasp."""
        d = collision.distances(self.robot, q, self.env)
        obj = d.body_b < 0
        pen = float(max(0.0, -d.distance[obj].min())) if obj.any() else 0.0
        self_pen = float(max(0.0, -d.distance[~obj].min())) if (~obj).any() else 0.0
        gaps = []
        for b in self.tip_bodies:
            sel = obj & (d.body_a == b)
            gaps.append(float(d.distance[sel].min()) if sel.any() else math.inf)
        touching = all(-PENETRATION_TOL <= g <= self.margin for g in gaps)
        return {
            "penetration": pen,
            "self_penetration": self_pen,
            "tip_gaps": gaps,
            "collision_free": bool(
                pen <= PENETRATION_TOL and self_pen <= PENETRATION_TOL and touching
            ),
        }

    def ok(self, q) -> bool:
        """The coal criteria of a collision-free grasp hold at ``q``."""
        return self.report(q)["collision_free"]

    def open(self, q) -> np.ndarray:
        """``q`` with every finger of the hand open (:func:`open_fingers`), those that do not
        grasp too."""
        return open_fingers(self.robot, self.all_fingers, q)

    def approach(self, q, back: float = APPROACH_BACK, move_arm: bool = True) -> np.ndarray:
        """A start for the collision-free iterations: the fingers of ``q`` opened and the palm
        moved ``back`` (m) away from the object along the line from the object to the palm
        (the arm by :func:`anthroarm.ik.solve` on the palm frame; ``q``'s arm where that
        fails), then moved farther while it is still in collision, up to 3 × ``back``.
        ``move_arm=False``: the fingers opened only."""
        robot, hand = self.robot, self.hand
        start = self.open(q)
        if not move_arm or not len(hand.arm_q_indices):
            return start
        M = robot.fk(q, frame=hand.palm)
        p = M[:3, 3]
        away = p - self.obj.project(p)
        nrm = float(np.linalg.norm(away))
        away = away / nrm if nrm > 1e-9 else -M[:3, 1]
        best = start
        for k in (1.0, 2.0, 3.0):
            T = M.copy()
            T[:3, 3] = p + k * back * away
            res = ik.solve(
                robot, T, q0=start, frame=hand.palm, tol_pos=1e-4, tol_rot=1e-3, max_time=0.01
            )
            if res.q is None or not np.isfinite(res.q).all() or not robot.within_limits(res.q):
                continue
            cand = start.copy()
            aq = hand.arm_q_indices
            cand[aq] = res.q[aq]
            best = cand
            if collision.min_distance(robot, cand, self.env) > CLEARANCE:
                break
        return best


__all__ = [
    "CollisionGrasp",
    "open_fingers",
    "CONTACT_MARGIN",
    "PENETRATION_TOL",
    "COLLISION_MAX_STEP",
    "CLEARANCE",
    "APPROACH_BACK",
]
