"""One-shot inverse kinematics: ``aa.ik.solve(robot, T)`` -> :class:`~anthroarm.ik.result.IKResult`.

Method: damped Gauss–Newton (Levenberg–Marquardt) on the pose error with projected (clipped)
steps, and random restarts inside the joint limits under a time budget.  Per iteration:

    e = log₆(T(q)⁻¹ T*)  (body twist, m and rad),   J = ᵇJ(q)  (LOCAL frame Jacobian),
    Δq = Jᵀ (J Jᵀ + λ I)⁻¹ e,   λ = λ₀ + k ‖e‖²   (Chan / Sugihara damping),
    q ← clip(q + Δq, q_min, q_max).

This is the book's feedback-compensation Newton step Δq = J⁻¹ e (Ch. 7 §7-5) made robust: the
damping is the λ → ∞ blend toward the steepest-descent direction Jᵀe of §7-6 (A9) when the
error is large or J is singular, and vanishes near the solution (quadratic convergence).
Joint ranges, the penalty constraints g_i(Q) ≥ 0 of (7-84)–(7-85), are enforced exactly by
the projection.  An attempt stops when the error no longer falls by 10 % in three iterations;
the next seed is then tried.

Seeds, in order: ``q0`` (clipped into the limits; default the comfortable posture of a human
arm or the middle of the joint ranges), the closed-form branches of :func:`anthroarm.ik.analytic`
when the robot has one, then uniform random configurations inside the limits until
``max_time`` or ``max_restarts``.  ``analytic="auto"`` brings the closed-form seeds in only after
:data:`ANALYTIC_AFTER` failed attempts: measured on 300 random poses, a closed-form call costs
0.4 ms (prosthetic_arm, all branches) to 6 ms (human_arm7, 36-angle swivel grid) against a
median 0.1–0.2 ms for the whole Gauss–Newton solve, so seeding with them first made the
median 4–20× slower at the same 100 % success; ``analytic=True`` puts them first anyway.

Targets: a 4×4 rigid pose (``mode="pose"``), a position (3,) (``"position"``: error p* − p in
the world frame, LOCAL_WORLD_ALIGNED linear Jacobian rows) or a rotation (3, 3)
(``"orientation"``: log₃(Rᵀ R*), LOCAL angular rows).  A leading batch axis solves N targets
(:class:`~anthroarm.ik.result.IKBatchResult`).

Redundant arms (human arm): ``posture`` adds a secondary objective in the null space of the
primary task, Δq += N (q_ref − q − Δq), N = I − Jᵀ(JJᵀ + λI)⁻¹J, so the arm settles at the
solution nearest the comfortable reference posture; ``swivel=φ*`` instead places the elbow at
the swivel angle φ* (:mod:`anthroarm.ik.qp.tasks.swivel`).
"""

from __future__ import annotations

import importlib.util
import math
import time
import weakref

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dposv, dpotrs

from ..errors import UnsupportedModelError
from .qp.targets import as_position, as_rotation, as_se3
from .qp.tasks.posture import comfortable_posture
from .qp.tasks.swivel import swivel_frames as _swivel_frames
from .qp.tasks.swivel import swivel_from_points
from .result import IKBatchResult, IKResult

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

#: Gauss–Newton settings (tuned on panda / ur5 / talos_arm / human_arm7 / prosthetic_arm).
LAMBDA0 = 1e-10   # floor of the damping (keeps JJᵀ + λI positive definite at singularities)
K_DAMP = 0.01     # λ grows with the squared error: large errors -> short, gradient-like steps
MAX_ITER = 60     # iterations per attempt (before the stall test ends it earlier)
STALL = 3         # an attempt ends after STALL iterations without a 10 % error decrease
NULL_TOL = 1e-4   # posture / swivel secondary step norm (rad) under which it has settled
NULL_EXTRA = 60   # extra iterations allowed for the secondary objective
NULL_STEP = 1.0   # longest null-space step (rad)
ANALYTIC_AFTER = 8  # analytic="auto": closed-form seeds join after this many failed attempts
LOCKSTEP_MIN = 8      # batches at least this large iterate all targets together (vectorised LM)
LOCKSTEP_ATTEMPTS = 10 # attempts per target in lockstep; the rest go to the one-target solver
HUMAN_GRID = np.linspace(-np.pi, np.pi, 12, endpoint=False)  # swivel grid of those seeds (human_arm7)

_CHAINS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()

#: The budget ``max_time`` is CPU time of the calling thread: on a busy machine a wall-clock
#: budget turns into failures that depend on the load; with a CPU-time budget (and the fixed
#: restart seed) the same call gives the same answer.  Wall time can exceed it when the process
#: is descheduled.
_clock = time.thread_time


class _Chain:
    """Per (robot, frame) workspace: model, own data, limits, reach bound."""

    def __init__(self, robot, fid: int):
        model = robot.model
        if model.nq != model.nv:
            raise UnsupportedModelError(f"{robot.name}: aa.ik.solve supports 1-DOF joints (revolute, prismatic); "
                                        f"this model has nq={model.nq} != nv={model.nv}")
        self.robot = robot
        self.model = model
        self.data = model.createData()
        self.fid = fid
        self.n = model.nq
        self.lo = np.array(model.lowerPositionLimit, dtype=float)
        self.hi = np.array(model.upperPositionLimit, dtype=float)
        self.lo_s = np.where(np.isfinite(self.lo), self.lo, -np.pi)   # sampling box
        self.hi_s = np.where(np.isfinite(self.hi), self.hi, np.pi)
        # reach bound: |p_frame| <= sum of the joint offsets on the path + tool offset
        # (+ the largest travel of prismatic joints); rotations preserve lengths
        frame = model.frames[fid]
        jid = frame.parentJoint
        reach = float(np.linalg.norm(frame.placement.translation))
        for j in model.supports[jid][1:]:
            reach += float(np.linalg.norm(model.jointPlacements[j].translation))
            jm = model.joints[j]
            if "Prismatic" in jm.shortname() or "Translation" in jm.shortname():
                i = jm.idx_q
                reach += float(max(abs(self.lo_s[i]), abs(self.hi_s[i])))
        self.reach = reach
        self.path = [model.joints[j].idx_q for j in model.supports[jid][1:]]
        self.default_ref = comfortable_posture(robot)

    def clip(self, q):
        return np.minimum(np.maximum(q, self.lo), self.hi)


def _chain(robot, fid: int) -> _Chain:
    d = _CHAINS.get(robot)
    if d is None:
        d = _CHAINS[robot] = {}
    ch = d.get(fid)
    if ch is None:
        ch = d[fid] = _Chain(robot, fid)
    return ch


# ------------------------------------------------------------------------------ residuals
def _res_pose(ch: _Chain, target: pin.SE3):
    model, data, fid = ch.model, ch.data, ch.fid

    def f(q):
        pin.computeJointJacobians(model, data, q)
        M = pin.updateFramePlacement(model, data, fid).actInv(target)
        e = pin.log6(M).vector
        t = M.translation
        w = e[3:]
        return pin.getFrameJacobian(model, data, fid, LOCAL), e, math.sqrt(t @ t), math.sqrt(w @ w)

    return f


def _res_position(ch: _Chain, p: np.ndarray):
    model, data, fid = ch.model, ch.data, ch.fid

    def f(q):
        pin.computeJointJacobians(model, data, q)
        e = p - pin.updateFramePlacement(model, data, fid).translation
        return pin.getFrameJacobian(model, data, fid, LWA)[:3], e, math.sqrt(e @ e), 0.0

    return f


def _res_orientation(ch: _Chain, R: np.ndarray):
    model, data, fid = ch.model, ch.data, ch.fid

    def f(q):
        pin.computeJointJacobians(model, data, q)
        e = pin.log3(pin.updateFramePlacement(model, data, fid).rotation.T @ R)
        return pin.getFrameJacobian(model, data, fid, LOCAL)[3:], e, 0.0, math.sqrt(e @ e)

    return f


# ------------------------------------------------------------------------------ secondary objectives
class _Posture:
    """Null-space pull toward q_ref (returns the projected step)."""

    def __init__(self, q_ref, gain=1.0):
        self.q_ref = q_ref
        self.gain = gain

    def __call__(self, q, dq1, J, cfac):
        z = self.gain * (self.q_ref - q - dq1)
        return z - J.T @ dpotrs(cfac, J @ z)[0]


class _Swivel:
    """Null-space step that moves the elbow swivel angle to ``target`` (rad)."""

    def __init__(self, ch: _Chain, frames, target: float):
        self.ch = ch
        self.ids = [ch.robot.frame_id(f) for f in frames]
        self.target = target
        self.err = np.inf

    def __call__(self, q, dq1, J, cfac):
        model, data = self.ch.model, self.ch.data
        pts = [pin.updateFramePlacement(model, data, i).translation for i in self.ids]
        try:
            phi, grads = swivel_from_points(*pts)
        except ValueError:  # straight arm: the swivel angle is undefined here
            self.err = np.inf
            return np.zeros_like(q)
        j = np.zeros(len(q))
        for g, i in zip(grads, self.ids):
            j += g @ pin.getFrameJacobian(model, data, i, LWA)[:3]
        d = self.target - phi
        d = math.atan2(math.sin(d), math.cos(d))
        self.err = abs(d)
        nj = j - J.T @ dpotrs(cfac, J @ j)[0]          # N jᵀ
        den = float(j @ nj) + 1e-9
        return nj * ((d - float(j @ dq1)) / den)


def _settle_swivel(robot, ch, mode, target, resid, sw, q_ref, qs, pe, re, tol_p, tol_r, analytic, msg):
    """After the null-space refinement: if the swivel target is still off, try the closed form
    at that angle (another branch of the self-motion may hold it); report what remains.
    Returns (q, pos_err, rot_err, seed tag or "", message)."""
    off = _swivel_offset(ch, sw, qs)
    if off <= 1e-6:
        return qs, pe, re, "", msg
    tried = ""
    if analytic is not False:
        ref = ch.default_ref if q_ref is None else q_ref
        S, _ = _analytic_seeds(robot, ch, mode, target, ref, sw.target)
        cf = _analytic_module()
        if cf is not None and ch.fid == robot.tool_id and cf.has_analytic(robot):
            tried = " and the closed form has no solution at that angle inside the limits"
        for cand in S:
            _, _, pe2, re2 = resid(cand)
            if pe2 <= tol_p and re2 <= tol_r:
                return cand, pe2, re2, "analytic", "converged from an analytic seed at the requested swivel angle"
    msg += (f"; swivel angle off by {off:.3g} rad: not reachable along this solution's self-motion within the "
            f"joint limits{tried} (the hand pose is exact)")
    return qs, pe, re, "", msg


def _swivel_offset(ch, sw: _Swivel, q) -> float:
    """|wrapped swivel(q) − target| (rad); inf where the swivel is undefined (straight arm)."""
    pin.framesForwardKinematics(ch.model, ch.data, q)
    pts = [ch.data.oMf[i].translation for i in sw.ids]
    try:
        phi = swivel_from_points(*pts)[0]
    except ValueError:
        return float("inf")
    d = sw.target - phi
    return abs(math.atan2(math.sin(d), math.cos(d)))


# ------------------------------------------------------------------------------ one attempt
def _attempt(ch, resid, q, tol_p, tol_r, deadline):
    """Damped Gauss–Newton from ``q``.  Returns (q, converged, iterations, best) with best =
    (q, pos_err, rot_err) of the closest iterate."""
    best_E = np.inf
    best = (q, np.inf, np.inf)
    stall = 0
    it = 0
    while it < MAX_ITER:
        J, e, pe, re = resid(q)
        it += 1
        if pe <= tol_p and re <= tol_r:
            return q, True, it, (q, pe, re)
        if pe + re < best[1] + best[2]:
            best = (q, pe, re)
        E = float(e @ e)
        if E < 0.9 * best_E:
            best_E = E
            stall = 0
        else:
            stall += 1
            if stall >= STALL:
                break
        if not it & 3 and _clock() > deadline:  # every 4th iteration: the clock costs ~0.4 µs
            break
        A = J @ J.T
        A.flat[:: A.shape[0] + 1] += LAMBDA0 + K_DAMP * E
        x, info = dposv(A, e)[1:]
        if info != 0:  # not positive definite (NaN/inf): give up this attempt
            break
        q = np.minimum(np.maximum(q + J.T @ x, ch.lo), ch.hi)
    return q, False, it, best


def _refine(ch, resid, q, tol_p, tol_r, secondary, deadline):
    """Second phase for redundant arms: from a solution ``q``, move in the null space of the
    primary task toward the secondary objective (posture or swivel), Gauss–Newton corrected
    (the pose error may grow in between and is driven back).  Returns the last iterate that
    meets the tolerances (the phase-1 solution if none does), and the iterations used."""
    good = q
    it = 0
    while it < NULL_EXTRA and _clock() <= deadline:
        J, e, pe, re = resid(q)
        it += 1
        if pe <= tol_p and re <= tol_r:
            good = q
        A = J @ J.T
        A.flat[:: A.shape[0] + 1] += LAMBDA0 + K_DAMP * float(e @ e)
        cfac, x, info = dposv(A, e)
        if info != 0:
            break
        dq = J.T @ x
        dq2 = secondary(q, dq, J, cfac)
        n2 = math.sqrt(dq2 @ dq2)
        if pe <= tol_p and re <= tol_r and n2 < NULL_TOL:
            break
        if n2 > NULL_STEP:  # long null-space moves leave the linearisation: shorten them
            dq2 *= NULL_STEP / n2
        q = np.minimum(np.maximum(q + dq + dq2, ch.lo), ch.hi)
    else:
        J, e, pe, re = resid(q)
        if pe <= tol_p and re <= tol_r:
            good = q
    return good, it


# ------------------------------------------------------------------------------ targets
def _parse(robot, T, mode):
    """-> (mode, batch: bool, list of targets)."""
    if mode not in (None, "pose", "position", "orientation"):
        raise ValueError(f"mode must be None, 'pose', 'position' or 'orientation', got {mode!r}")
    if isinstance(T, pin.SE3):
        T = T.homogeneous
    arr = np.asarray(T, dtype=float)
    sh = arr.shape
    if sh == (4, 4) or (arr.ndim == 3 and sh[1:] == (4, 4)):
        m = mode or "pose"
        batch = arr.ndim == 3
        items = arr if batch else [arr]
        out = []
        for i, a in enumerate(items):
            name = f"T[{i}]" if batch else "T"
            M = as_se3(a, name)
            out.append(M if m == "pose" else (M.translation.copy() if m == "position" else M.rotation.copy()))
        return m, batch, out
    if mode == "position" and arr.ndim == 2 and sh[1] == 3:
        return "position", True, [as_position(a, f"T[{i}]") for i, a in enumerate(arr)]
    if sh == (3,):
        if mode not in (None, "position"):
            raise ValueError(f"a (3,) target is a position; mode={mode!r} needs a 4x4 pose")
        return "position", False, [as_position(arr, "T")]
    if sh == (3, 3) or (arr.ndim == 3 and sh[1:] == (3, 3)):
        if mode not in (None, "orientation"):
            raise ValueError(f"a 3x3 target is a rotation; mode={mode!r} needs a 4x4 pose")
        batch = arr.ndim == 3
        items = arr if batch else [arr]
        return "orientation", batch, [as_rotation(a, f"T[{i}]" if batch else "T") for i, a in enumerate(items)]
    if arr.ndim == 2 and sh[1] == 3 and mode is None:
        return "position", True, [as_position(a, f"T[{i}]") for i, a in enumerate(arr)]
    raise ValueError(f"target T must be a 4x4 pose, a position (3,), a rotation (3, 3), or a batch of them "
                     f"with a leading axis; got shape {sh}")


def _analytic_module():
    if importlib.util.find_spec("anthroarm.ik.closed_form") is None:
        return None
    from . import closed_form

    return closed_form if hasattr(closed_form, "analytic") and hasattr(closed_form, "has_analytic") else None


def _analytic_seeds(robot, ch, mode, target, ref, swivel, grid=None):
    """Closed-form solutions (K, nq) sorted by distance to ``ref``, or an empty array."""
    if mode != "pose" or ch.fid != robot.tool_id:
        return np.zeros((0, ch.n)), ""
    cf = _analytic_module()
    if cf is None or not cf.has_analytic(robot):
        return np.zeros((0, ch.n)), ""
    try:
        kw = {}
        if robot.name == "human_arm7":
            if swivel is not None:
                kw["swivel"] = swivel
            elif grid is not None:
                kw["swivel"] = grid
        S = np.asarray(cf.analytic(robot, target.homogeneous, **kw).solutions, dtype=float).reshape(-1, ch.n)
    except Exception as exc:  # a seed source only: never let it break the solve
        return np.zeros((0, ch.n)), f"analytic seed failed: {exc}"
    if len(S):
        S = S[np.argsort(np.abs(S - ref).sum(axis=1))]
    return S, ""


# ------------------------------------------------------------------------------ public API
def solve(robot, T, q0=None, frame=None, tol_pos: float = 1e-6, tol_rot: float = 1e-6, max_time: float = 0.05,
          *, mode: str | None = None, max_restarts: int | None = None, rng=None, posture="auto",
          swivel: float | None = None, swivel_frames=None, analytic="auto", warm_start: bool = False):
    """Inverse kinematics of ``robot`` for target ``T`` (see the module docstring).

    Parameters
    ----------
    robot : anthroarm.Robot
    T : 4×4 pose (or ``pin.SE3``), position (3,), rotation (3, 3), or a batch with a leading axis N.
        World frame, metres.  ``ValueError`` for NaN, a wrong shape or a non-rigid transform.
    q0 : (nq,) or (N, nq), optional
        Initial guess (clipped into the limits).  Default: :func:`comfortable_posture`
        (human arm) or the middle of the joint ranges.
    frame : str, optional
        Frame to place (default the tool); unknown names raise
        :class:`~anthroarm.errors.UnknownFrameError` listing the valid ones.
    tol_pos, tol_rot : float
        Success tolerances, m and rad.
    max_time : float
        Time budget per target, s of CPU time of the calling thread (restarts stop when it is
        spent); see :data:`_clock`.
    mode : None, "pose", "position", "orientation"
        Override the target kind (e.g. ``"position"`` with a 4×4 ``T`` uses its translation).
    max_restarts : int, optional
        Cap on random restarts (default: limited by ``max_time`` only).
    rng : int or numpy Generator, optional
        Seed of the restarts (default 0: reproducible results).
    posture : "auto", None or (nq,)
        Reference posture for the null space of redundant arms; ``"auto"`` uses the comfortable
        posture for the human arm (``human_arm7``) and nothing otherwise.
    swivel : float, optional
        Elbow swivel angle (rad) for a human arm (overrides ``posture``); ``swivel_frames``
        = (shoulder, elbow, wrist) frame names for arms outside the catalog.
    analytic : "auto", True or False
        Closed-form seeds (see the module docstring).
    warm_start : bool
        Batch only: seed target i with the solution of target i − 1 (trajectories).

    Returns
    -------
    IKResult, or IKBatchResult for a batch.  Every returned q is within the joint limits.
    """
    fid = robot.frame_id(frame)
    ch = _chain(robot, fid)
    mode, batch, targets = _parse(robot, T, mode)
    for name, v in (("tol_pos", tol_pos), ("tol_rot", tol_rot), ("max_time", max_time)):
        if not (isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a positive finite number, got {v!r}")
    if max_restarts is not None and (int(max_restarts) != max_restarts or max_restarts < 0):
        raise ValueError(f"max_restarts must be a non-negative integer, got {max_restarts!r}")
    if analytic not in ("auto", True, False):
        raise ValueError(f"analytic must be 'auto', True or False, got {analytic!r}")
    # seeds
    default_ref = ch.default_ref
    if q0 is None:
        Q0 = None
    else:
        Q0 = robot.check_q(q0, name="q0")
        if Q0.ndim == 2 and (not batch or len(Q0) != len(targets)):
            raise ValueError(f"q0 of shape {Q0.shape} needs a batch of {len(Q0)} targets")
    # secondary objective (redundant arms)
    if isinstance(posture, str):
        if posture != "auto":
            raise ValueError(f"posture must be 'auto', None or a configuration, got {posture!r}")
        q_ref = default_ref if robot.name in ("human_arm7",) else None
    elif posture is None:
        q_ref = None
    else:
        q_ref = ch.clip(robot.check_q(posture, name="posture"))
    sw_frames = None
    if swivel is not None:
        swivel = float(swivel)
        if not math.isfinite(swivel):
            raise ValueError(f"swivel must be finite, got {swivel}")
        sw_frames = _swivel_frames(robot, swivel_frames)
    dim = {"pose": 6, "position": 3, "orientation": 3}[mode]
    redundant = ch.n > dim
    # the restart generator is created on first use (most solves need no restart)
    gen = [rng] if isinstance(rng, np.random.Generator) else [None, 0 if rng is None else rng]

    q_ref_sec = q_ref if redundant and swivel is None else None
    sw_sec = (sw_frames, swivel) if (redundant and swivel is not None) else None
    seeds = []
    for i in range(len(targets)):
        if Q0 is None:
            seeds.append(q_ref if q_ref is not None else default_ref)
        else:
            seeds.append(Q0[i] if Q0.ndim == 2 else Q0)
    if batch and not warm_start and len(targets) >= LOCKSTEP_MIN and analytic is not True:
        results = _solve_lockstep(robot, ch, mode, targets, np.array(seeds, dtype=float), tol_pos, tol_rot,
                                  max_time, max_restarts, gen, q_ref_sec, sw_sec, analytic)
    else:
        results = []
        prev = None
        for i, tgt in enumerate(targets):
            seed = prev if (warm_start and prev is not None and Q0 is None) else seeds[i]
            res = _solve_one(robot, ch, mode, tgt, seed, tol_pos, tol_rot, max_time, max_restarts, gen,
                             q_ref_sec, sw_sec, analytic)
            results.append(res)
            prev = res.q
    if not batch:
        return results[0]
    return IKBatchResult(
        q=np.array([r.q for r in results]).reshape(len(results), ch.n),
        success=np.array([r.success for r in results], dtype=bool),
        status=[r.status for r in results],
        pos_err=np.array([r.pos_err for r in results]), rot_err=np.array([r.rot_err for r in results]),
        iterations=np.array([r.iterations for r in results], dtype=int),
        restarts=np.array([r.restarts for r in results], dtype=int),
        messages=[r.message for r in results], mode=mode)


def _solve_lockstep(robot, ch, mode, targets, seeds, tol_p, tol_r, max_time, max_restarts, gen, q_ref, sw,
                    analytic):
    """Batch form: every target iterates the same damped Gauss–Newton step together, the linear
    algebra vectorised over the batch (``np.linalg.solve`` on (N, m, m)); Pinocchio's FK and
    Jacobians are still one call per target.  Converged targets leave the batch; a target whose
    attempt stalls restarts from a random configuration, up to :data:`LOCKSTEP_ATTEMPTS`
    attempts, after which it is handed to the one-target solver (all its seeds, restarts and
    the time budget).  Same answers' quality, ~3× less time per target."""
    model, data, fid = ch.model, ch.data, ch.fid
    N, n = len(targets), ch.n
    m = 6 if mode == "pose" else 3
    Q = ch.clip(seeds.copy())
    J = np.empty((N, m, n))
    E = np.empty((N, m))
    PE = np.zeros(N)
    RE = np.zeros(N)
    its = np.zeros(N, dtype=int)
    att_it = np.zeros(N, dtype=int)
    attempts = np.ones(N, dtype=int)
    best = np.full(N, np.inf)
    stall = np.zeros(N, dtype=int)
    converged = np.zeros(N, dtype=bool)
    max_attempts = LOCKSTEP_ATTEMPTS if max_restarts is None else min(LOCKSTEP_ATTEMPTS, int(max_restarts) + 1)
    active = np.arange(N)
    eye = np.eye(m)
    while active.size:
        for k in active:                      # Pinocchio: one call per target
            q = Q[k]
            pin.computeJointJacobians(model, data, q)
            M = pin.updateFramePlacement(model, data, fid)
            if mode == "pose":
                Mt = M.actInv(targets[k])
                E[k] = pin.log6(Mt).vector
                t = Mt.translation
                PE[k] = math.sqrt(t @ t)
                J[k] = pin.getFrameJacobian(model, data, fid, LOCAL)
            elif mode == "position":
                E[k] = targets[k] - M.translation
                J[k] = pin.getFrameJacobian(model, data, fid, LWA)[:3]
            else:
                E[k] = pin.log3(M.rotation.T @ targets[k])
                J[k] = pin.getFrameJacobian(model, data, fid, LOCAL)[3:]
        Ea = E[active]
        if mode == "pose":
            RE[active] = np.sqrt((Ea[:, 3:] ** 2).sum(1))
        elif mode == "position":
            PE[active] = np.sqrt((Ea ** 2).sum(1))
        else:
            RE[active] = np.sqrt((Ea ** 2).sum(1))
        its[active] += 1
        att_it[active] += 1
        ok = (PE[active] <= tol_p) & (RE[active] <= tol_r)
        converged[active[ok]] = True
        active = active[~ok]
        if not active.size:
            break
        Ee = (E[active] ** 2).sum(1)
        improved = Ee < 0.9 * best[active]
        best[active] = np.where(improved, Ee, best[active])
        stall[active] = np.where(improved, 0, stall[active] + 1)
        ended = (stall[active] >= STALL) | (att_it[active] >= MAX_ITER)
        if ended.any():
            ek = active[ended]
            retry = ek[attempts[ek] < max_attempts]
            if retry.size:
                if gen[0] is None:
                    gen[0] = np.random.default_rng(gen[1])
                Q[retry] = ch.lo_s + (ch.hi_s - ch.lo_s) * gen[0].random((retry.size, n))
                attempts[retry] += 1
                att_it[retry] = 0
                stall[retry] = 0
                best[retry] = np.inf
            stepping = active[~ended]          # retried targets are evaluated first, next round
            active = np.concatenate([stepping, retry])
        else:
            stepping = active
        if stepping.size:                     # vectorised damped Gauss–Newton step
            Js = J[stepping]
            A = Js @ Js.transpose(0, 2, 1)
            A += (LAMBDA0 + K_DAMP * (E[stepping] ** 2).sum(1))[:, None, None] * eye
            try:
                x = np.linalg.solve(A, E[stepping][..., None])
            except np.linalg.LinAlgError:    # a singular system: hand those targets over
                active = np.setdiff1d(active, stepping)
                continue
            Q[stepping] = np.minimum(np.maximum(Q[stepping] + (Js.transpose(0, 2, 1) @ x)[..., 0], ch.lo), ch.hi)
    results = []
    for k in range(N):
        restarts = int(attempts[k] - 1)
        if converged[k] and q_ref is None and sw is None:
            tag = "q0" if restarts == 0 else "restart"
            results.append(IKResult(Q[k].copy(), True, "success", float(PE[k]), float(RE[k]), int(its[k]), restarts,
                                    f"converged from a {tag} seed (batch)", mode, tag))
        elif converged[k]:                    # redundant arm: null-space settling, one target at a time
            r = _solve_one(robot, ch, mode, targets[k], Q[k], tol_p, tol_r, max_time, max_restarts, gen, q_ref, sw,
                           analytic)
            r.iterations += int(its[k])
            r.restarts += restarts
            results.append(r)
        else:                                 # stalled LOCKSTEP_ATTEMPTS times: the full one-target solver
            r = _solve_one(robot, ch, mode, targets[k], seeds[k], tol_p, tol_r, max_time, max_restarts, gen, q_ref,
                           sw, analytic)
            r.iterations += int(its[k])
            results.append(r)
    return results


def _solve_one(robot, ch, mode, target, seed, tol_p, tol_r, max_time, max_restarts, gen, q_ref, sw, analytic):
    t0 = _clock()
    deadline = t0 + max_time
    resid = {"pose": _res_pose, "position": _res_position, "orientation": _res_orientation}[mode](ch, target)
    if sw is not None:
        secondary = _Swivel(ch, sw[0], sw[1])
    elif q_ref is not None:
        secondary = _Posture(q_ref)
    else:
        secondary = None
    # reachability (a sufficient test for "unreachable": farther than the summed link offsets)
    out_of_reach = ""
    if mode in ("pose", "position"):
        p = target.translation if mode == "pose" else target
        dist = float(np.linalg.norm(p))
        if dist > ch.reach + tol_p:
            out_of_reach = (f"target is {dist:.4g} m from the base origin but the chain reaches at most "
                            f"{ch.reach:.4g} m (sum of its link offsets)")
    q = ch.clip(np.asarray(seed, dtype=float))
    total_it = 0
    best = (q, np.inf, np.inf)
    note = ""
    seeds_tag = "q0"
    restarts = 0
    ana = None
    ana_i = 0
    if analytic is True and not out_of_reach:
        ana, note = _analytic_seeds(robot, ch, mode, target, q, sw[1] if sw else None)
    attempt = 0
    while True:
        if ana is not None and ana_i < len(ana):
            q, seeds_tag = ana[ana_i].copy(), "analytic"
            ana_i += 1
        elif attempt > 0:
            if gen[0] is None:
                gen[0] = np.random.default_rng(gen[1])
            g = gen[0]
            q = ch.lo_s + (ch.hi_s - ch.lo_s) * g.random(ch.n)
            seeds_tag = "restart"
            restarts += 1
        qs, ok, it, b = _attempt(ch, resid, q, tol_p, tol_r, deadline)
        total_it += it
        pe, re = b[1], b[2]
        if ok and secondary is not None:
            qs, it2 = _refine(ch, resid, qs, tol_p, tol_r, secondary, deadline + 0.5 * max_time)
            total_it += it2
            _, _, pe, re = resid(qs)
        attempt += 1
        if b[1] + b[2] < best[1] + best[2]:
            best = b
        if ok:
            msg = f"converged from a {seeds_tag} seed"
            if isinstance(secondary, _Swivel):
                qs, pe, re, tag, msg = _settle_swivel(robot, ch, mode, target, resid, secondary, q_ref, qs, pe, re,
                                                      tol_p, tol_r, analytic, msg)
                seeds_tag = tag or seeds_tag
            return IKResult(qs, True, "success", pe, re, total_it, restarts, msg, mode, seeds_tag)
        if out_of_reach and attempt >= 3:
            break
        if analytic == "auto" and ana is None and not out_of_reach and attempt >= ANALYTIC_AFTER:
            ana, note = _analytic_seeds(robot, ch, mode, target, best[0], sw[1] if sw else None, HUMAN_GRID)
        if _clock() > deadline:
            break
        if max_restarts is not None and restarts >= max_restarts and (ana is None or ana_i >= len(ana)):
            break
    q = best[0]
    _, _, pe, re = resid(q)
    el = (_clock() - t0) * 1e3
    if out_of_reach:
        status, why = "out_of_reach", out_of_reach
    else:
        status = "not_converged"
        why = (f"no configuration within the joint limits reached tol_pos={tol_p:g} m / tol_rot={tol_r:g} rad "
               f"after {total_it} iterations, {restarts} restarts, {el:.1f} ms CPU (max_time {max_time * 1e3:g} ms); "
               f"the target is probably outside the joint-limited workspace")
    msg = f"{why}; closest pose found: pos_err {pe:.3g} m, rot_err {re:.3g} rad" + (f"; {note}" if note else "")
    return IKResult(q, False, status, pe, re, total_it, restarts, msg, mode, seeds_tag)
