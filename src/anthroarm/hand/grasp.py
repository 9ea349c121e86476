"""Fingertip grasps of a sphere or a cylinder: contact placement and the hand-and-arm solve.

:func:`solve_grasp` finds a configuration of the whole robot (arm joints and finger joints,
whatever ``robot.chain`` has) that puts every fingertip on the object with its pad against the
surface, by iterating QP differential-IK steps (:func:`anthroarm.ik.qp.step`) from a start
configuration to convergence.  Two ways to say where the fingertips go:

* ``contacts=None`` (sliding contacts): each fingertip may touch the object anywhere.  One
  :class:`~anthroarm.ik.qp.tasks.surface_contact.SurfaceContactTask` per fingertip (distance to
  the surface and pad normal against the outward normal at the fingertip).  Success: every
  fingertip within ``position_tol`` (1 mm) of the surface, its pad normal within ``normal_tol``
  (5°) of −m, on the side of a bounded cylinder, inside the joint limits.
* ``contacts`` = one point per fingertip (m, world; projected onto the surface; e.g. from
  :meth:`Sphere.point <anthroarm.hand.objects.Sphere.point>` /
  :meth:`Cylinder.point <anthroarm.hand.objects.Cylinder.point>`): a
  :class:`~anthroarm.ik.qp.tasks.position.PositionTask` to the point and a
  :class:`~anthroarm.ik.qp.tasks.contact_normal.ContactNormalTask` along −m there.  Success:
  every fingertip within 1 mm of its point, pad normal within 5° of −m, inside the limits.

The pad normal of each fingertip is :mod:`anthroarm.hand.fingers`' convention (the direction the
distal joint's flexion moves the tip).  Each iteration is one QP step with dt = 1 (Δq = v):
tasks with Levenberg–Marquardt damping, the configuration limit (gain 0.5) and a trust region
``|Δq| ≤ max_step`` (rad or m per iteration, as a velocity limit), the ``couplings``
(:class:`~anthroarm.ik.qp.tasks.coupling.JointCouplingTask`, e.g. a linkage written as a linear
relation) as hard equality constraints; mimic joints are moved by Pinocchio with their source.
A warm start is ``q0`` (the previous grasp's answer).

Statuses of :class:`GraspResult`: ``"success"``; ``"max_iterations"``; ``"stalled"`` (the step
became smaller than 1e-9 before the criteria held: a local minimum, an unreachable object or a
limit in the way); ``"qp_infeasible"`` / ``"qp_failed"`` (the couplings cannot hold inside the
limits, or the solver failed).  Bad input raises: :class:`~anthroarm.errors.GraspError` (an
object larger than the hand's span, a wrong number of contacts),
:class:`~anthroarm.errors.FingertipError` (a contact on a frame that is not a fingertip) and
:class:`~anthroarm.errors.CouplingError` (a start configuration that breaks a coupling).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from .. import collision, ik
from ..errors import CouplingError, GraspError
from ..ik import qp
from ..ik.qp.limits.collision import CollisionLimit
from ..ik.qp.limits.collision_step import step as collision_step
from ..ik.qp.tasks.contact_normal import ContactNormalTask
from ..ik.qp.tasks.surface_contact import SurfaceContactTask
from .fingers import Hand
from .objects import Cylinder, Sphere

#: success criteria of the issue: every fingertip within 1 mm, its normal within 5°
POSITION_TOL = 1e-3
NORMAL_TOL = math.radians(5.0)
#: a collision-free grasp: the fingertip capsules touch the object within this gap (m) and no
#: body goes deeper into it, or into another body of the hand, than PENETRATION_TOL
CONTACT_MARGIN = 1e-3
PENETRATION_TOL = 1e-4
#: the trust region (rad or m per iteration) of a collision-free grasp
COLLISION_MAX_STEP = 0.05
#: iterations without a 1 % improvement of the best error after which an attempt has stalled
STALL_WINDOW = 25


@dataclass
class GraspResult:
    """Outcome of :func:`solve_grasp`.

    Attributes
    ----------
    q : (nq,) array
        Last configuration (Pinocchio layout).
    success : bool
        Every criterion holds (see :func:`solve_grasp`).
    status : str
        ``"success"``, ``"max_iterations"``, ``"stalled"``, ``"qp_infeasible"`` or ``"qp_failed"``.
    iterations : int
        QP steps taken.
    time : float
        Wall time of the solve, s.
    tips : tuple of str
        Fingertip frames, in the order of the arrays below.
    position_errors : (n,) array
        Distance of each fingertip from its contact point (given contacts) or from the
        surface (sliding contacts), m.
    normal_errors : (n,) array
        Angle between each pad normal and −m (the inward surface normal), rad.
    contacts : (n, 3) array
        The contact points: the given points projected onto the surface, or the surface points
        nearest to the fingertips at ``q``, m, world frame.
    within_limits : bool
    """

    q: np.ndarray
    success: bool
    status: str
    iterations: int
    time: float
    tips: tuple
    position_errors: np.ndarray
    normal_errors: np.ndarray
    contacts: np.ndarray
    within_limits: bool
    info: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        return (
            f"GraspResult(status={self.status!r}, iterations={self.iterations}, "
            f"max position error={1e3 * float(np.max(self.position_errors)):.3g} mm, "
            f"max normal error={math.degrees(float(np.max(self.normal_errors))):.3g} deg)"
        )


def _as_object(obj):
    if not isinstance(obj, (Sphere, Cylinder)):
        raise GraspError(
            f"the grasped object is a hand.Sphere or hand.Cylinder, got {type(obj).__name__}"
        )
    return obj


def grasp_errors(hand: Hand, conf, obj, points=None):
    """(position errors (n,) m, normal errors (n,) rad, contact points (n, 3), on_side) of the
    fingertips at ``conf`` (an :class:`~anthroarm.ik.qp.IKConfiguration` whose kinematics are
    current) against ``obj``: against the given ``points`` (n, 3), or the surface."""
    n = len(hand.fingers)
    pe = np.empty(n)
    ne = np.empty(n)
    cp = np.empty((n, 3))
    on_side = True
    for k, f in enumerate(hand.fingers):
        M = conf.frame_placement(f.tip_id)
        p = M.translation
        if points is None:
            pe[k] = abs(obj.distance(p))
            c = obj.project(p)
            if isinstance(obj, Cylinder):
                on_side = on_side and obj.on_side(c)
        else:
            c = points[k]
            pe[k] = float(np.linalg.norm(p - c))
        cp[k] = c
        pad = M.rotation @ f.pad_axis
        ne[k] = math.acos(max(-1.0, min(1.0, -float(pad @ obj.normal(c)))))
    return pe, ne, cp, on_side


def grasp_tasks(
    robot,
    hand: Hand,
    obj,
    points=None,
    *,
    position_cost: float = 1.0,
    normal_cost: float = 0.1,
    lm_damping: float = 1e-3,
) -> list:
    """The QP tasks of a grasp (see the module docstring): per fingertip a surface-contact task
    (``points=None``) or a position task to its point plus a contact-normal task along −m."""
    tasks = []
    for k, f in enumerate(hand.fingers):
        if points is None:
            tasks.append(
                SurfaceContactTask(
                    robot,
                    f.tip_id,
                    obj,
                    axis=f.pad_axis,
                    distance_cost=position_cost,
                    normal_cost=normal_cost,
                    lm_damping=lm_damping,
                )
            )
        else:
            tasks.append(
                qp.PositionTask(
                    robot, f.tip_id, cost=position_cost, lm_damping=lm_damping, target=points[k]
                )
            )
            tasks.append(
                ContactNormalTask(
                    robot,
                    f.tip_id,
                    axis=f.pad_axis,
                    cost=normal_cost,
                    lm_damping=lm_damping,
                    target=-obj.normal(points[k]),
                )
            )
    return tasks


def check_span(hand: Hand, obj) -> None:
    """:class:`~anthroarm.errors.GraspError` when the object's size exceeds the hand's span."""
    if obj.size > hand.span:
        raise GraspError(
            f"{hand.robot.name}: the {obj.kind} is {1e3 * obj.size:.1f} mm across, larger than the "
            f"hand's span {1e3 * hand.span:.1f} mm (the largest possible distance between two "
            f"fingertips {hand.tips}): no fingertip grasp exists"
        )


def _kabsch(P, Q, w):
    """Rotation R and translation t minimising Σ w_k ‖R P_k + t − Q_k‖² (Kabsch 1976)."""
    w = w / w.sum()
    cp, cq = w @ P, w @ Q
    H = (P - cp).T @ ((Q - cq) * w[:, None])
    U, _, Vt = np.linalg.svd(H)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, cq - R @ cp


def _fit_palm(hand: Hand, data, points, obj) -> np.ndarray:
    """World palm pose (4×4) that best carries the fingertips of the configuration in ``data``
    (palm frame) onto ``points``: Kabsch (1976) on the fingertips and on points 5 cm along
    their pad normals against 5 cm along −m."""
    Mp = data.oMf[hand.palm_id]
    P, Q = [], []
    for f, c in zip(hand.fingers, points):
        M = Mp.actInv(data.oMf[f.tip_id])
        P += [M.translation, M.translation + 0.05 * (M.rotation @ f.pad_axis)]
        Q += [c, c - 0.05 * obj.normal(c)]
    R, t = _kabsch(np.array(P), np.array(Q), np.ones(len(P)))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def palm_approach(
    hand: Hand,
    points,
    obj,
    q,
    rng=None,
    seed_arm: bool = False,
    rounds: int = 3,
    solver: str = "daqp",
    step_fn=None,
) -> np.ndarray:
    """A start for a grasp with given contact ``points``: the arm joints of ``q`` moved so that the
    palm sits where a hand shape fits the contacts, the finger joints shaped for them.

    Block-coordinate rounds from the mid-range hand (every finger joint in the middle of its
    range): fit the palm pose to the contacts (:func:`_fit_palm`), then close the fingers on the
    contacts with the palm held at that pose (at most 30 QP iterations with ``move_arm=False``,
    the problem carried into the current palm frame), and fit again; ``rounds`` fits in all.
    The arm joints then come from :func:`anthroarm.ik.solve` on the palm frame (from ``q``, or
    from a random arm configuration with ``seed_arm``); where the fitted pose is out of reach,
    the nearest configuration it found inside the limits (else ``q``'s arm)."""
    robot = hand.robot
    model = robot.model
    data = model.createData()
    chain = robot.chain
    fq = hand.finger_q_indices
    aq = hand.arm_q_indices
    cur = np.array(q, dtype=float)
    mid = 0.5 * (chain.lower + chain.upper)
    cur[fq] = np.where(np.isfinite(mid[fq]), mid[fq], cur[fq])
    for k in range(max(1, int(rounds))):
        pin.framesForwardKinematics(model, data, cur)
        T = _fit_palm(hand, data, points, obj)
        if k == rounds - 1:
            break
        X = data.oMf[hand.palm_id].homogeneous @ np.linalg.inv(T)  # world → current palm placement
        pts = points @ X[:3, :3].T + X[:3, 3]
        res = solve_grasp(
            robot,
            obj.transformed(X),
            pts,
            hand=hand,
            q0=cur,
            move_arm=False,
            restarts=0,
            max_iterations=30,
            solver=solver,
            step_fn=step_fn,
        )
        cur[fq] = res.q[fq]
    q_start = cur
    if seed_arm:
        q_start = cur.copy()
        q_start[aq] = robot.random_q(rng=rng)[aq]
    res = ik.solve(robot, T, q0=q_start, frame=hand.palm, tol_pos=1e-4, tol_rot=1e-3, max_time=0.01)
    if res.q is not None and np.isfinite(res.q).all() and robot.within_limits(res.q):
        cur[aq] = res.q[aq]  # the palm pose, or the nearest the arm reaches: a start
    else:
        cur[aq] = np.asarray(q, dtype=float)[aq]
    return cur


def solve_grasp(
    robot,
    obj,
    contacts=None,
    *,
    hand: Hand | None = None,
    tips=None,
    q0=None,
    couplings=(),
    max_iterations: int = 300,
    max_step: float = 0.2,
    position_cost: float = 1.0,
    normal_cost: float = 0.1,
    lm_damping: float = 1e-3,
    posture_cost: float = 0.0,
    position_tol: float = POSITION_TOL,
    normal_tol: float = NORMAL_TOL,
    solver: str = "daqp",
    tasks=(),
    restarts: int = 25,
    seed=0,
    move_arm: bool = True,
    step_fn=None,
    collision_free: bool = False,
    contact_margin: float = CONTACT_MARGIN,
) -> GraspResult:
    """Grasp ``obj`` (a :class:`~anthroarm.hand.objects.Sphere` or
    :class:`~anthroarm.hand.objects.Cylinder`, world frame) with the fingertips of ``robot``.

    Parameters
    ----------
    robot : anthroarm.Robot
        A hand, or an arm with a hand (every joint moves).
    obj : Sphere or Cylinder
    contacts : (n, 3) array, optional
        One contact point per fingertip (m, world; projected onto the surface), in the order
        of ``hand.tips``; ``None`` for sliding contacts (module docstring).
    hand : Hand, optional
        Fingers and palm (default ``Hand(robot, tips)``).
    tips : sequence of str, optional
        Fingertip frames when ``hand`` is not given (default: every tip of the tree); a frame
        that is not a fingertip raises :class:`~anthroarm.errors.FingertipError`.
    q0 : (nq,) array, optional
        Start (warm start); default the robot's neutral configuration clipped into its limits.
    couplings : sequence of JointCouplingTask
        Linear joint relations held exactly; ``q0`` must satisfy them (to 1e-6) or
        :class:`~anthroarm.errors.CouplingError` is raised.
    max_iterations : int
        QP steps at most.
    max_step : float
        Trust region: the largest change of one joint per iteration (rad or m).
    position_cost, normal_cost, lm_damping
        Task weights ([cost]/m, [cost] per unit of the normal residual) and LM damping.
    posture_cost : float
        Weight of a posture task toward ``q0`` (0: none).
    position_tol, normal_tol : float
        Success criteria, m and rad (default 1 mm, 5°).
    solver : str
        QP backend (:func:`anthroarm.ik.qp.available_solvers`).
    tasks : sequence of Task
        Extra tasks (e.g. a palm orientation), added to the grasp's.
    restarts : int
        Further attempts after one that fails (not after a QP failure): the arm joints where the
        best attempt left them, the finger joints uniform in their ranges (``seed``), and with
        given contacts on an arm every other attempt a finer :func:`palm_approach` (6 rounds;
        from the third attempt on from a random arm configuration: a new arm branch).  The best attempt is returned; ``iterations`` and
        ``time`` count all of them.
    seed : int or numpy Generator
        Random source of the restarts (deterministic by default).
    move_arm : bool
        False holds the arm's joints (those all fingertips share, ``Hand.arm_joints``) at
        their values in ``q0``: a grasp with the palm where it is.
    step_fn : callable, optional
        Replaces :func:`anthroarm.ik.qp.step` in the iterations: ``step_fn(conf, tasks, limits,
        couplings, solver)`` returns an object with ``v`` (nv,), ``ok`` and ``status``, ``info``
        (benchmarks/bench_hand.py runs the same loop on pink's ``solve_ik`` this way).
    collision_free : bool
        The object is a collision body (:mod:`anthroarm.collision`): every step carries the
        velocity damper :class:`~anthroarm.ik.qp.limits.collision.CollisionLimit` against the
        object (d_s = 0) and between the robot's own bodies (fingers, palm, arm, torso), and
        the fingertips aim at the object grown by their capsules' radius, so that the pads
        touch it instead of their axes.  Success adds: every fingertip capsule within
        ``contact_margin`` of the object, no body deeper than 1e-4 m into it or into another
        body; otherwise the status is ``"no_collision_free_grasp"``.  The trust region is at
        most 0.05 rad per iteration (the damper is linear in q).  Not with ``couplings`` or
        ``step_fn``.
    contact_margin : float
        Largest gap (m) between a fingertip capsule and the object that counts as touching.

    Returns
    -------
    GraspResult
    """
    t0 = time.perf_counter()
    obj = _as_object(obj)
    hand = Hand(robot, tips=tips) if hand is None else hand
    if hand.robot is not robot:
        raise GraspError("hand= was built for another Robot")
    check_span(hand, obj)
    coll = None
    if collision_free:
        if couplings or step_fn is not None:
            raise GraspError("collision_free=True takes no couplings= and no step_fn=")
        coll = _CollisionGrasp(robot, hand, obj, contact_margin)
        obj, step_fn = coll.target, coll.step
        # smaller iterations: the damper linearises d, and 0.2 rad steps leak ~2 mm
        max_step = min(float(max_step), COLLISION_MAX_STEP)
    n = len(hand.fingers)
    points = None
    if contacts is not None:
        pts = np.asarray(contacts, dtype=float)
        if pts.shape != (n, 3) or not np.isfinite(pts).all():
            raise GraspError(
                f"contacts must be a finite ({n}, 3) array, one point (m) per fingertip "
                f"{hand.tips}, got shape {np.shape(contacts)}"
            )
        points = np.array([obj.project(p) for p in pts])
    for nm, val in (("max_iterations", max_iterations), ("restarts", restarts)):
        if isinstance(val, bool) or not (isinstance(val, (int, np.integer)) and val >= 0):
            raise ValueError(f"{nm} must be a whole number >= 0, got {val!r}")
    for nm, val in (
        ("max_step", max_step),
        ("position_tol", position_tol),
        ("normal_tol", normal_tol),
    ):
        if not (math.isfinite(val) and val > 0):
            raise ValueError(f"{nm} must be finite and > 0, got {val!r}")
    if q0 is None:
        q0 = robot.neutral()
        chain = robot.chain
        q0 = np.where(np.isfinite(chain.lower), np.maximum(q0, chain.lower), q0)
        q0 = np.where(np.isfinite(chain.upper), np.minimum(q0, chain.upper), q0)
    conf = qp.IKConfiguration(robot, q0)
    couplings = list(couplings)
    for c in couplings:
        e = c.compute_error(conf)
        if not np.all(np.abs(e) <= 1e-6):
            raise CouplingError(
                f"{robot.name}: the start configuration breaks the coupling {c!r} "
                f"(residual {float(np.max(np.abs(e))):.3g}); give a q0 that satisfies it"
            )
    all_tasks = grasp_tasks(
        robot,
        hand,
        obj,
        points,
        position_cost=position_cost,
        normal_cost=normal_cost,
        lm_damping=lm_damping,
    ) + list(tasks)
    if posture_cost:
        all_tasks.append(qp.PostureTask(robot, cost=posture_cost, target=conf.q))
    lower, upper = None, None
    if not move_arm and hand.arm_joints:  # the arm's joints held at q0: a box of zero width
        lower, upper = np.array(robot.chain.lower), np.array(robot.chain.upper)
        for i in hand.arm_joints:
            j = robot.chain.joints[i]
            if not j.is_mimic and j.nq == 1:
                lower[j.idx_q] = upper[j.idx_q] = conf.q[j.idx_q]
    limits = [
        qp.ConfigurationLimit(robot, lower=lower, upper=upper),
        qp.VelocityLimit(robot, v_max=np.full(robot.nv, float(max_step))),
    ]
    rng = np.random.default_rng(seed)
    fq = hand.finger_q_indices
    best = None
    total = 0
    approach = points is not None and move_arm and bool(hand.arm_v_indices)
    for attempt in range(int(restarts) + 1):
        if attempt:
            start = best[0].copy()  # arm where the best attempt left it, fingers anew
            if (
                approach and attempt % 2 == 1
            ):  # or, every other time, a finer approach (a new arm branch
                start = palm_approach(
                    hand,
                    points,
                    obj,
                    start,
                    rng=rng,
                    seed_arm=attempt > 1,
                    solver=solver,
                    rounds=6,
                    step_fn=step_fn,
                )  # after the first restart)
            else:
                start[fq] = robot.random_q(rng=rng)[fq]
            conf.update(start)
            if posture_cost:
                all_tasks[-1].set_target(conf.q)
        elif approach:
            conf.update(
                palm_approach(hand, points, obj, conf.q, rng=rng, solver=solver, step_fn=step_fn)
            )
        out = _descend(
            conf,
            hand,
            obj,
            points,
            all_tasks,
            limits,
            couplings,
            solver,
            max_iterations,
            position_tol,
            normal_tol,
            step_fn,
        )
        total += out[2]
        score = max(out[3].max() / position_tol, out[4].max() / normal_tol)
        if best is None or out[1] == "success" or score < best[-1]:
            best = (*out, score)
        if out[1] == "success" or out[1].startswith("qp_"):
            break
    q, status, _, pe, ne, cp, within, info, _ = best
    if coll is not None:
        info = dict(info, **coll.report(q))
        if status == "success" and not info["collision_free"]:
            status = "no_collision_free_grasp"
    return GraspResult(
        q,
        status == "success",
        status,
        total,
        time.perf_counter() - t0,
        hand.tips,
        pe,
        ne,
        cp,
        within,
        dict(info, attempts=attempt + 1),
    )


class _CollisionGrasp:
    """The pieces of a collision-free grasp: the object as an obstacle, the fingertip capsule
    radii, the object grown by them (what the fingertips aim at), the step with the damper."""

    def __init__(self, robot, hand, obj, margin):
        m = float(margin)
        if not (math.isfinite(m) and m > 0):
            raise GraspError(f"contact_margin must be finite and > 0 (m), got {margin!r}")
        self.robot, self.hand, self.margin = robot, hand, m
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
        self.radius = max(radii)
        self.target = obj.inflated(self.radius)
        # d_i = 10 cm, beyond what one iteration moves a body (max_step 0.2 rad × ~0.5 m);
        # ξ dt = d_i / 2: a pair closes at most half its gap per iteration
        self.limit = CollisionLimit(robot, self.env, d_safe=0.0, d_detect=0.1, xi=0.05)

    def step(self, conf, tasks, limits, couplings, solver):
        return collision_step(
            conf, None, tasks, 1.0, limits=[*limits, self.limit], damping=1e-9, full=True
        )

    def report(self, q) -> dict:
        """Penetration into the object, self-collision depth and fingertip gaps at ``q``."""
        d = collision.distances(self.robot, q, self.env)
        obj = np.array([b < 0 for b in d.body_b], dtype=bool)
        pen = float(max(0.0, -d.distance[obj].min())) if obj.any() else 0.0
        self_pen = float(max(0.0, -d.distance[~obj].min())) if (~obj).any() else 0.0
        gaps = [
            float(d.distance[obj & (d.body_a == b)].min())
            if (obj & (d.body_a == b)).any()
            else np.inf
            for b in self.tip_bodies
        ]
        touching = all(-PENETRATION_TOL <= g <= self.margin for g in gaps)
        return {
            "penetration": pen,
            "self_penetration": self_pen,
            "tip_gaps": gaps,
            "collision_free": bool(
                pen <= PENETRATION_TOL and self_pen <= PENETRATION_TOL and touching
            ),
        }


def _descend(
    conf,
    hand,
    obj,
    points,
    tasks,
    limits,
    couplings,
    solver,
    max_iterations,
    position_tol,
    normal_tol,
    step_fn=None,
):
    """QP iterations from ``conf`` until the criteria hold, the step vanishes, the error stops
    improving (by 1 % over 25 iterations: ``"stalled"``) or ``max_iterations``."""
    status = "max_iterations"
    it = 0
    info = {}
    history = []
    while True:
        pe, ne, cp, on_side = grasp_errors(hand, conf, obj, points)
        within = conf.within_limits(1e-9)
        if pe.max() <= position_tol and ne.max() <= normal_tol and on_side and within:
            status = "success"
            break
        score = max(pe.max() / position_tol, ne.max() / normal_tol)
        history.append(score)
        if len(history) > STALL_WINDOW and score > 0.99 * min(history[:-STALL_WINDOW]):
            status = "stalled"
            break
        if it >= max_iterations:
            break
        if step_fn is None:
            res = qp.step(
                conf,
                None,
                tasks,
                1.0,
                limits=limits,
                solver=solver,
                damping=1e-9,
                constraints=couplings,
                full=True,
            )
        else:
            res = step_fn(conf, tasks, limits, couplings, solver)
        if not res.ok:
            status = f"qp_{res.status}"
            info = res.info
            break
        v = res.v
        it += 1
        if not float(v @ v) > 1e-18:
            status = "stalled"
            break
        conf.integrate_inplace(v, 1.0)
    return conf.q.copy(), status, it, pe, ne, cp, bool(within), info
