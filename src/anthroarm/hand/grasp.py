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

from .. import ik
from ..errors import CouplingError, GraspError
from ..ik import qp
from ..ik.qp.tasks.contact_normal import ContactNormalTask
from ..ik.qp.tasks.surface_contact import SurfaceContactTask
from .collision_grasp import (
    COLLISION_MAX_STEP,
    CONTACT_MARGIN,
    CollisionGrasp,
)
from .fingers import Hand
from .objects import Cylinder, Sphere

#: success criteria of the issue: every fingertip within 1 mm, its normal within 5°
POSITION_TOL = 1e-3
NORMAL_TOL = math.radians(5.0)
#: iterations without a 1 % improvement of the best error after which an attempt has stalled
STALL_WINDOW = 25
#: collision-free grasps: hand-only solves from random finger joints tried after a grasp whose
#: fingers go through the object (``solve_grasp(collision_free=True)``)
FINGER_TRIES = 8
#: then the damper's iterations from open, backed-off hands (palm turned 0°, ±30°, ...)
APPROACH_TRIES = 3


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
    fingers=None,
) -> np.ndarray:
    """A start for a grasp with given contact ``points``: the arm joints of ``q`` moved so that the
    palm sits where a hand shape fits the contacts, the finger joints shaped for them.

    Block-coordinate rounds from the mid-range hand (every finger joint in the middle of its
    range): fit the palm pose to the contacts (:func:`_fit_palm`), then close the fingers on the
    contacts with the palm held at that pose (at most 30 QP iterations with ``move_arm=False``,
    the problem carried into the current palm frame), and fit again; ``rounds`` fits in all.
    The arm joints then come from :func:`anthroarm.ik.solve` on the palm frame (from ``q``, or
    from a random arm configuration with ``seed_arm``); where the fitted pose is out of reach,
    the nearest configuration it found inside the limits (else ``q``'s arm).  ``fingers``:
    the finger joints (``hand.finger_q_indices``) to start from instead of mid-range."""
    robot = hand.robot
    model = robot.model
    data = model.createData()
    chain = robot.chain
    fq = hand.finger_q_indices
    aq = hand.arm_q_indices
    cur = np.array(q, dtype=float)
    mid = 0.5 * (chain.lower + chain.upper)
    cur[fq] = np.where(np.isfinite(mid[fq]), mid[fq], cur[fq])
    if fingers is not None:  # another hand shape to fit the palm with
        cur[fq] = fingers
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
        The object is a collision body (:mod:`anthroarm.hand.collision_grasp`): the
        fingertips aim at the object grown by their capsule radius and half the contact margin
        (their surfaces at a gap from the object's, not their axes on it).  First the grasp
        without collisions on that surface (the same arguments, ``position_tol`` at most half
        the margin); when coal finds it collision-free it is the answer, otherwise the
        iterations run again with the velocity damper
        :class:`~anthroarm.ik.qp.limits.collision.CollisionLimit` on every step (fingertip
        capsules against the object to d = 0, every other body and every self pair to
        0.2 mm; at most 0.05 rad per iteration), from that answer (the damper pushes apart
        what is in) and then from an approach (the fingers open, the palm 4 cm back).
        Success adds: every fingertip capsule within ``contact_margin`` of the object, no
        body deeper than 1e-4 m into it or into another body (coal).  When no attempt gives
        that the status is ``"no_collision_free_grasp"`` (``info["reason"]`` says why: no
        grasp even without collisions, the object grown by the fingertips wider than the
        span, or every collision-free attempt failed).  ``info`` has ``penetration``,
        ``self_penetration``, ``tip_gaps`` (m, coal) and ``phase`` (``"direct"``,
        ``"repair"`` or ``"approach"``).  Not with ``couplings`` or ``step_fn``.
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
    if collision_free:
        if couplings or step_fn is not None:
            raise GraspError("collision_free=True takes no couplings= and no step_fn=")
        kw = dict(
            q0=q0, max_iterations=max_iterations, max_step=max_step, position_cost=position_cost,
            normal_cost=normal_cost, lm_damping=lm_damping, posture_cost=posture_cost,
            position_tol=position_tol, normal_tol=normal_tol, solver=solver, tasks=tuple(tasks),
            restarts=restarts, seed=seed, move_arm=move_arm,
        )  # fmt: skip
        return _solve_collision_free(robot, obj, contacts, hand, contact_margin, kw, t0)
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
    limits = _limits(robot, hand, conf.q, move_arm, max_step)
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
    check=None,
):
    """QP iterations from ``conf`` until the criteria hold (and ``check(q)``, when given), the
    step vanishes, the error stops improving (by 1 % over 25 iterations: ``"stalled"``) or
    ``max_iterations``."""
    status = "max_iterations"
    it = 0
    info = {}
    history = []
    while True:
        pe, ne, cp, on_side = grasp_errors(hand, conf, obj, points)
        within = conf.within_limits(1e-9)
        if pe.max() <= position_tol and ne.max() <= normal_tol and on_side and within:
            if check is None or check(conf.q):
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


def _limits(robot, hand, q, move_arm, max_step) -> list:
    """The configuration limit (the arm's joints held at ``q`` unless ``move_arm``: a box of
    zero width) and the trust region ``max_step`` as a velocity limit."""
    lower, upper = None, None
    if not move_arm and hand.arm_joints:
        lower, upper = np.array(robot.chain.lower), np.array(robot.chain.upper)
        for i in hand.arm_joints:
            j = robot.chain.joints[i]
            if not j.is_mimic and j.nq == 1:
                lower[j.idx_q] = upper[j.idx_q] = q[j.idx_q]
    return [
        qp.ConfigurationLimit(robot, lower=lower, upper=upper),
        qp.VelocityLimit(robot, v_max=np.full(robot.nv, float(max_step))),
    ]


def _solve_collision_free(robot, obj, contacts, hand, margin, kw, t0) -> GraspResult:
    """``solve_grasp(..., collision_free=True)``: see its docstring."""
    coll = CollisionGrasp(robot, hand, obj, margin)
    tgt = coll.target
    ptol = min(float(kw["position_tol"]), coll.gap)
    if tgt.size > hand.span:
        n = len(hand.fingers)
        q = robot.check_q(kw["q0"]) if kw["q0"] is not None else robot.neutral()
        info = dict(coll.report(q), phase="none", attempts=0)
        info["reason"] = (
            f"the {obj.kind} grown by the fingertip radius and the gap is "
            f"{1e3 * tgt.size:.1f} mm across, wider than the hand's span {1e3 * hand.span:.1f} mm"
        )
        return GraspResult(
            q, False, "no_collision_free_grasp", 0, time.perf_counter() - t0, hand.tips,
            np.full(n, np.inf), np.full(n, np.pi), np.full((n, 3), np.nan),
            robot.within_limits(q), info,
        )  # fmt: skip
    # 1. the grasp without collisions on the grown surface: often collision-free as it is
    r1 = solve_grasp(robot, tgt, contacts, hand=hand, **dict(kw, position_tol=ptol))
    rep = coll.report(r1.q)
    best = (r1.q, r1.status, r1.position_errors, r1.normal_errors, r1.contacts, r1.within_limits)
    total, phase, attempts = r1.iterations, "direct", r1.info.get("attempts", 1)
    ok = r1.success and rep["collision_free"]
    points = r1.contacts if contacts is not None else None
    fit = points is not None and kw["move_arm"] and bool(hand.arm_v_indices)
    if not ok:
        # 2. other hand shapes (random finger joints; with given contacts the palm fitted
        # anew to each) without the damper: the cheap way around a finger or a palm through
        # the object
        rng = np.random.default_rng(kw["seed"])
        fq = hand.finger_q_indices
        lo, hi = robot.chain.lower[fq], robot.chain.upper[fq]
        lo, hi = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
        tasks = grasp_tasks(
            robot, hand, tgt, points, position_cost=kw["position_cost"],
            normal_cost=kw["normal_cost"], lm_damping=kw["lm_damping"],
        ) + list(kw["tasks"])  # fmt: skip
        limits = _limits(robot, hand, r1.q, kw["move_arm"], kw["max_step"])
        conf = qp.IKConfiguration(robot, r1.q)
        # the fingers that do not grasp open, out of the object's way
        base = coll.open(r1.q)
        base[fq] = r1.q[fq]
        for k in range(FINGER_TRIES):
            start = base.copy()
            start[fq] = lo + (hi - lo) * rng.uniform(0.05, 0.6, len(fq))
            if fit:  # the palm turned about the contacts' line by ±30°, ±60°, ...
                start = _turn_palm(hand, points, start, _angle(k))
            conf.update(start)
            out = _descend(
                conf, hand, tgt, points, tasks, limits, [], kw["solver"],
                kw["max_iterations"], ptol, kw["normal_tol"], None, check=coll.ok,
            )  # fmt: skip
            total += out[2]
            attempts += 1
            if out[1] == "success":
                best, ok, phase = (out[0], out[1], *out[3:7]), True, "fingers"
                rep = coll.report(out[0])
                break
    if not ok:
        # 3. the damper on every step: from that answer (the damper pushes apart what is in),
        # then from approaches (the fingers open, the palm back and turned)
        tasks = grasp_tasks(
            robot, hand, tgt, points, position_cost=kw["position_cost"],
            normal_cost=kw["normal_cost"], lm_damping=kw["lm_damping"],
        ) + list(kw["tasks"])  # fmt: skip
        limits = _limits(
            robot, hand, r1.q, kw["move_arm"], min(float(kw["max_step"]), COLLISION_MAX_STEP)
        )
        conf = qp.IKConfiguration(robot, r1.q)
        for k in range(APPROACH_TRIES + 1):
            phase, start = ("approach", r1.q) if k else ("repair", r1.q)
            if k > 1 and fit:  # the palm turned
                start = _turn_palm(hand, points, r1.q, _angle(k - 2))
            if k:
                start = coll.approach(start, move_arm=kw["move_arm"])
            conf.update(start)
            out = _descend(
                conf, hand, tgt, points, tasks, limits, [], kw["solver"],
                kw["max_iterations"], ptol, kw["normal_tol"], coll.step, check=coll.ok,
            )  # fmt: skip
            total += out[2]
            attempts += 1
            if out[1] == "success":
                best, ok = (out[0], out[1], *out[3:7]), True
                rep = coll.report(out[0])
                break
    q, status, pe, ne, cp, within = best
    info = dict(rep, phase=phase if ok else "none", attempts=attempts)
    if not ok:
        status = "no_collision_free_grasp"
        info["reason"] = (
            "every collision-free attempt failed"
            if r1.success
            else f"no grasp even without collisions ({r1.status})"
        )
        info["grasp_status"] = r1.status
    cp = np.array([obj.project(c) for c in cp])  # the contacts on the object itself
    return GraspResult(
        q, ok, "success" if ok else status, total, time.perf_counter() - t0, hand.tips,
        pe, ne, cp, within, info,
    )  # fmt: skip


def _turn_palm(hand, points, q, angle) -> np.ndarray:
    """``q`` with the arm moved (:func:`anthroarm.ik.solve` on the palm frame) so that the palm
    turns by ``angle`` (rad) about the line through the contact ``points`` (their principal
    direction through their centroid): the freedom a grasp with two contacts leaves."""
    robot = hand.robot
    c = points.mean(axis=0)
    u = np.linalg.svd(points - c)[2][0]
    R = pin.exp3(angle * u)
    M = robot.fk(q, frame=hand.palm)
    T = np.eye(4)
    T[:3, :3] = R @ M[:3, :3]
    T[:3, 3] = c + R @ (M[:3, 3] - c)
    res = ik.solve(robot, T, q0=q, frame=hand.palm, tol_pos=1e-4, tol_rot=1e-3, max_time=0.01)
    out = q.copy()
    if res.q is not None and np.isfinite(res.q).all() and robot.within_limits(res.q):
        out[hand.arm_q_indices] = res.q[hand.arm_q_indices]
    return out


def _angle(k: int) -> float:
    """The k-th palm turn of the collision-free tries: +30°, −30°, +60°, −60°, ... (rad)."""
    return math.radians(30.0 * (k // 2 + 1) * (-1) ** k)
