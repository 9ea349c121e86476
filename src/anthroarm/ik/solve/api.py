"""``aa.ik.solve``: argument checks, the seed order and restarts of one target, and the lockstep
batch.  See :mod:`anthroarm.ik.solve` for the method."""

from __future__ import annotations

import math

import numpy as np

from ... import jit
from ..closed.limits import refine
from ..qp.targets import as_rigid
from ..qp.tasks.swivel import swivel_frames as _swivel_frames
from ..result import IKBatchResult, IKResult
from . import coupled, lm
from .kernel import MAX_ITER, STALL, clock, damped_step, damping
from .nullspace import Swivel, posture
from .nullspace import swivel as swivel_phase
from .seeds import SWIVEL_GRID, SWIVEL_GRID_COARSE, TableSeeds, analytic_seeds
from .targets import ORIENTATION, Target, check_options, parse
from .workspace import workspace

ANALYTIC_AFTER = 8  # analytic="auto": closed-form seeds join after this many failed attempts
LOCKSTEP_MIN = 8  # batches at least this large iterate all targets together
WARM_POSES = (
    8  # poses of fixed configurations solved untimed before a first call (_warm_closed_form)
)
LOCKSTEP_ATTEMPTS = 10  # attempts per target in lockstep; the rest go to the one-target solver


class Problem:
    """The settings of one call, shared by its targets: the robot (for the closed form only),
    the calling thread's workspace, the time budget (s of thread CPU time), the restart cap and
    generator, the posture reference θ_ref (None: no posture phase), the swivel objective
    (None: none) and the closed-form policy."""

    __slots__ = (
        "robot",
        "ws",
        "max_time",
        "max_restarts",
        "rng",
        "_gen",
        "th_ref",
        "swivel",
        "analytic",
    )

    def __init__(self, robot, ws, max_time, max_restarts, rng, th_ref, swivel, analytic):
        self.robot, self.ws, self.max_time, self.max_restarts = robot, ws, max_time, max_restarts
        self.rng, self._gen = rng, None
        self.th_ref, self.swivel, self.analytic = th_ref, swivel, analytic

    def random(self):
        """A uniform random θ in the sampling box (the generator made on first use: most
        solves need no restart)."""
        if self._gen is None:
            r = self.rng
            self._gen = (
                r
                if isinstance(r, np.random.Generator)
                else np.random.default_rng(0 if r is None else r)
            )
        sh = self.ws.sh
        return sh.lo_s + (sh.hi_s - sh.lo_s) * self._gen.random(sh.n)

    def closed_form_first(self, seed) -> bool:
        """The closed form answers first (``analytic=True``, or ``"auto"`` where it is cheap:
        :func:`.seeds.closed_form_cheap`).  A redundant arm's swivel grid is cheap compiled,
        not on the reference path (:mod:`anthroarm.jit`: ~18 ms a target for human_arm7,
        against ~1 ms for a 6R class): until the process runs compiled kernels, Gauss–Newton
        goes first there and the closed form joins as seeds after ``ANALYTIC_AFTER`` attempts."""
        sh = self.ws.sh
        return self.analytic is True or (
            self.analytic == "auto"
            and seed is None
            and sh.closed_form_first
            and (not sh.swivel_family or jit.compiled())
        )


def _reference(robot, sh, posture, swivel, swivel_frames):
    """(reference posture θ in the limits or None, :class:`Swivel` or None) of :func:`solve`'s
    ``posture``, ``swivel`` and ``swivel_frames``."""
    if isinstance(posture, str):
        if posture != "auto":
            raise ValueError(f"posture must be 'auto', None or a configuration, got {posture!r}")
        th_ref = sh.posture_auto
    elif posture is None:
        th_ref = None
    else:
        th_ref = np.minimum(
            np.maximum(sh.theta(robot.check_q(posture, name="posture")), sh.lo), sh.hi
        )
    if swivel is None:
        return th_ref, None
    swivel = float(swivel)
    if not math.isfinite(swivel):
        raise ValueError(f"swivel must be finite, got {swivel}")
    return th_ref, Swivel([robot.frame_id(f) for f in _swivel_frames(robot, swivel_frames)], swivel)


def solve(
    robot,
    T,
    q0=None,
    frame=None,
    tol_pos: float = 1e-6,
    tol_rot: float = 1e-6,
    max_time: float = 0.05,
    *,
    mode: str | None = None,
    max_restarts: int | None = None,
    rng=None,
    posture="auto",
    swivel: float | None = None,
    swivel_frames=None,
    analytic="auto",
    warm_start: bool = False,
):
    """Inverse kinematics of ``robot`` for target ``T`` (see :mod:`anthroarm.ik.solve`).

    Parameters
    ----------
    robot : anthroarm.Robot
        Any robot ``aa.load`` takes: revolute, prismatic, continuous and mimic joints, serial
        or a tree (joints off the frame's path keep their ``q0`` values, else their reference
        posture).  Thread-safe: one Robot may be solved for from several threads at once.
    T : 4×4 pose (or ``pin.SE3``), position (3,), rotation (3, 3), or a batch with a leading axis N.
        World frame, metres.  ``ValueError`` for NaN, a wrong shape or a non-rigid transform.
    q0 : (nq,) or (N, nq), optional
        Initial guess (clipped into the limits).  Default: the nearest entry of the seed table
        (for a posture problem, nearest with a penalty on the distance to the posture).
    frame : str, optional
        Frame to place (default the tool); unknown names raise
        :class:`~anthroarm.errors.UnknownFrameError` listing the valid ones.
    tol_pos, tol_rot : float
        Success tolerances, m and rad.
    max_time : float
        Time budget per target, s of CPU time of the calling thread (restarts stop when it is
        spent; a CPU-time budget makes the answer independent of the machine's load).  The
        seed table, built once per (robot, frame) on the first call, is not charged to it.
    mode : None, "pose", "position", "orientation"
        Override the target kind (e.g. ``"position"`` with a 4×4 ``T`` uses its translation).
    max_restarts : int, optional
        Cap on restarts, i.e. seeds after the first (default: limited by ``max_time`` only).
    rng : int or numpy Generator, optional
        Seed of the random restarts (default 0: reproducible results).
    posture : "auto", None or (nq,)
        Reference posture for the null space of redundant arms; ``"auto"`` uses the comfortable
        posture for the human arm (:func:`~anthroarm.ik.qp.tasks.posture.comfortable_posture`)
        and nothing otherwise.
    swivel : float, optional
        Elbow swivel angle (rad) for a human arm (overrides ``posture``); ``swivel_frames``
        = (shoulder, elbow, wrist) frame names for arms outside the catalog.
    analytic : "auto", True or False
        Closed-form seeds (see :mod:`anthroarm.ik.solve`).
    warm_start : bool
        Batch only: seed target i with the solution of target i − 1 (trajectories).

    Returns
    -------
    IKResult, or IKBatchResult for a batch.  Every returned q is within the joint limits; a
    continuous joint's angle is the one the iteration reached from its seed (no added turn).
    An OpenSim model with nonlinear couplings (``robot.coupling``) is solved in its independent
    coordinates (q of length ``robot.nq``, within the coordinate ranges; Jacobian J·dφ/dq):
    :func:`anthroarm.ik.solve.coupled.solve`.
    """
    if getattr(robot, "coupling", None) is not None:
        return coupled.solve(
            robot,
            T,
            q0,
            frame,
            tol_pos,
            tol_rot,
            max_time,
            mode=mode,
            max_restarts=max_restarts,
            rng=rng,
            posture=posture,
            swivel=swivel,
            swivel_frames=swivel_frames,
            analytic=analytic,
            warm_start=warm_start,
        )
    ws = workspace(robot, robot.frame_id(frame))
    sh = ws.sh
    if type(T) is np.ndarray and T.shape == (4, 4) and mode in (None, "pose"):
        mode, batch, targets = "pose", False, [as_rigid(T, "T")]
    else:
        mode, batch, targets = parse(T, mode)
    check_options(tol_pos, tol_rot, max_time, max_restarts, rng, analytic)
    Q0 = None
    if q0 is not None:
        Q0 = robot.check_q(q0, name="q0")
        if Q0.ndim == 2 and (not batch or len(Q0) != len(targets)):
            raise ValueError(f"q0 of shape {Q0.shape} needs a batch of {len(Q0)} targets")
        Q0 = sh.theta(Q0)
    th_ref, sw = _reference(robot, sh, posture, swivel, swivel_frames)
    redundant = sh.dof > (6 if mode == "pose" else 3)
    pb = Problem(
        robot,
        ws,
        float(max_time),
        max_restarts,
        rng,
        th_ref if redundant and sw is None else None,
        sw if redundant else None,
        analytic,
    )
    tp, tr = float(tol_pos), float(tol_rot)
    ws.table()  # the one-time seed tables and compiled kernel: built here, before any clock
    if mode == "pose":  # starts, so the first call is not charged for them
        ws.aligned()
    if not ws.lm.warm:
        lm.warm(ws)
    if analytic is not False and sh.has_closed_form:
        _warm_closed_form(pb, mode, tp, tr)
    if not batch:
        return _result(sh, solve_one(pb, Target(mode, targets[0], tp, tr), Q0), Q0)
    tgs = [Target(mode, t, tp, tr) for t in targets]
    seeds = [None if Q0 is None else (Q0[i] if Q0.ndim == 2 else Q0) for i in range(len(tgs))]
    if (
        not warm_start
        and len(tgs) >= LOCKSTEP_MIN
        and not (pb.closed_form_first(Q0) and mode == "pose")
    ):
        results = solve_lockstep(pb, tgs, seeds)
    else:
        results, prev = [], None
        for tg, seed in zip(tgs, seeds):
            r = solve_one(
                pb, tg, prev if (warm_start and prev is not None and Q0 is None) else seed
            )
            results.append(r)
            prev = r.q
    results = [_result(sh, r, s) for r, s in zip(results, seeds)]
    return IKBatchResult.collect(results, sh.nq, mode)


def _warm_closed_form(pb: Problem, mode: str, tp: float, tr: float) -> None:
    """Compile the closed form's kernels that these settings use (or load them from the disk
    cache), once per (robot, frame, settings) and before any clock starts: one untimed solve of
    the pose of the reference posture, closed form first, with no budget.  ``max_time`` is the
    caller's budget for solving, never for compilation or cache loading: without this, the first
    call of a process with an empty cache spent its 50 ms compiling and failed (issue 28)."""
    sh = pb.ws.sh
    key = (mode, pb.th_ref is not None, pb.swivel is not None)
    if key in sh.warm:
        return
    # the reference posture's pose, poses of a few fixed configurations (the closed form's
    # paths differ with the pose: solved at the first swivel angle or not, polished, rescued)
    # and a pose out of reach
    rng = np.random.default_rng(0)
    thetas = [sh.ref] + [
        sh.lo_s + (sh.hi_s - sh.lo_s) * rng.random(sh.n) for _ in range(WARM_POSES)
    ]
    poses = [pb.ws.fk(th).homogeneous for th in thetas]
    far = poses[0].copy()
    far[:3, 3] *= 4.0 * sh.reach / max(float(np.linalg.norm(far[:3, 3])), 1e-3)
    warm = Problem(pb.robot, pb.ws, 60.0, 0, 0, pb.th_ref, pb.swivel, True)
    for H in poses + [far]:
        _, _, (tgt,) = parse(H, mode)
        solve_one(warm, Target(mode, tgt, tp, tr), None)
    # the polish of a closed-form candidate at a singular pose (bounded least squares): its
    # first use imports scipy.optimize (~1 s), which a first target needing it paid in its budget
    robot = pb.robot
    if robot.nq == robot.nv:  # the polish is for arms without continuous joints
        q = sh.q(sh.ref)
        refine(robot, q, robot.fk(q), robot.lower, robot.upper, False)
    sh.warm.add(key)


def _result(sh, r, seed):
    """The IKResult in Pinocchio's q (its ``q`` holds θ until here); joints off the frame's path
    take the caller's seed values (they do not move the frame)."""
    th = r.q
    if seed is not None and not sh.all_on_path:
        th = np.where(sh.on_path, th, seed)
    r.q = th if sh.to_q is None else sh.to_q(th)  # θ is a fresh array of this call
    return r


def solve_one(pb: Problem, tg: Target, seed):
    """One target: the seeds in order — closed form (``analytic=True``, or "auto" where it is
    cheap and no q0 is given), q0, the seed table nearest first, uniform random — each
    refined by :func:`~anthroarm.ik.solve.lm.attempt` until one converges, the budget is
    spent or ``max_restarts`` is reached; then the posture or swivel phase.  Returns an
    IKResult whose ``q`` is θ (:func:`_result` maps it)."""
    ws = pb.ws
    sh = ws.sh
    t0 = clock()
    max_time = pb.max_time
    deadline = t0 + max_time
    th_ref, sw = pb.th_ref, pb.swivel
    out_of_reach = _out_of_reach(sh, tg)
    ana, ana_i, note = None, 0, ""
    if not out_of_reach and pb.closed_form_first(seed):
        ana, note, done = _closed_form_seeds(pb, tg, seed)
        if done is not None:
            return done
    table = None  # seed-table entries, nearest first (made when needed)
    total_it = restarts = attempts = 0
    best_q, best_E = None, math.inf
    while True:
        if ana is not None and ana_i < len(ana):
            th, tag = ana[ana_i].copy(), "analytic"
            ana_i += 1
        elif seed is not None:
            th, tag = np.minimum(np.maximum(seed, sh.lo), sh.hi), "q0"
            seed = None
        else:
            if table is None:
                table = TableSeeds(ws, tg, th_ref)
            th, tag = table.next(), "table"
            if th is None:
                th, tag = pb.random(), "restart"
        if attempts:
            restarts += 1
        if tag == "analytic" and th_ref is not None and sw is None:
            # a closed-form solution: straight to the posture phase, which verifies it
            ths, pe2, re2, it = posture(ws, tg, th, th_ref, deadline + 0.5 * max_time)
            total_it += it
            attempts += 1
            if ths is not None:
                return IKResult(
                    ths,
                    True,
                    "success",
                    math.sqrt(pe2),
                    math.sqrt(re2),
                    total_it,
                    restarts,
                    "converged from an analytic seed",
                    tg.mode,
                    tag,
                )
        ths, ok, it, pe2, re2, bq, bE = lm.attempt(ws, tg, th, deadline)
        total_it += it
        attempts += 1
        if bE < best_E:
            best_q, best_E = bq, bE
        if ok:
            pe, re = math.sqrt(pe2), math.sqrt(re2)
            msg = f"converged from {_article(tag)} {tag} seed"
            if sw is not None:
                ths, it2 = swivel_phase(ws, tg, ths, sw, deadline + 0.5 * max_time)
                total_it += it2
                pe, re = tg.errors(ws, ths)
                ths, pe, re, tag2, msg = _settle_swivel(pb, tg, ths, pe, re, msg)
                tag = tag2 or tag
            elif th_ref is not None:
                ths2, pe2, re2, it2 = posture(ws, tg, ths, th_ref, deadline + 0.5 * max_time)
                total_it += it2
                if ths2 is not None:
                    ths, pe, re = ths2, math.sqrt(pe2), math.sqrt(re2)
            return IKResult(ths, True, "success", pe, re, total_it, restarts, msg, tg.mode, tag)
        if out_of_reach and attempts >= 3:
            break
        if (
            pb.analytic == "auto"
            and ana is None
            and not out_of_reach
            and attempts >= ANALYTIC_AFTER
        ):
            ana, note, _ = analytic_seeds(
                pb.robot, ws, tg, best_q, sw.target if sw else None, SWIVEL_GRID
            )
        if clock() > deadline or (pb.max_restarts is not None and restarts >= pb.max_restarts):
            break
    th = best_q if best_q is not None else th
    why = out_of_reach or (
        f"no configuration within the joint limits reached tol_pos={tg.tol_p:g} m / "
        f"tol_rot={tg.tol_r:g} rad after {total_it} iterations, {restarts} restarts, "
        f"{(clock() - t0) * 1e3:.1f} ms CPU (max_time {max_time * 1e3:g} ms); the target is "
        "probably outside the joint-limited workspace"
    )
    pe, re = tg.errors(ws, th)
    msg = f"{why}; closest pose found: pos_err {pe:.3g} m, rot_err {re:.3g} rad" + (
        f"; {note}" if note else ""
    )
    status = "out_of_reach" if out_of_reach else "not_converged"
    return IKResult(th, False, status, pe, re, total_it, restarts, msg, tg.mode, tag)


def _out_of_reach(sh, tg) -> str:
    """Why ``tg`` is out of reach ("" if it may be reachable): a sufficient test, the target
    farther from the base than the summed link offsets."""
    if tg.kind == ORIENTATION:
        return ""
    dist = math.sqrt(tg.ps.dot(tg.ps))
    if dist <= sh.reach + tg.tol_p:
        return ""
    return (
        f"target is {dist:.4g} m from the base origin but the chain reaches at most "
        f"{sh.reach:.4g} m (sum of its link offsets)"
    )


def _closed_form_seeds(pb, tg, seed):
    """(closed-form seeds, a note, the answer or None) for :func:`solve_one` when the closed
    form goes first: the answer when any solution will do (no posture, no swivel) and the
    nearest one meets the tolerances, checked by the FK of its compiled call."""
    ws, sh, th_ref, sw = pb.ws, pb.ws.sh, pb.th_ref, pb.swivel
    ref = th_ref if th_ref is not None else (sh.ref if seed is None else seed)
    # without a posture objective any member of a swivel family will do: a coarse grid first
    grid = SWIVEL_GRID if th_ref is not None else SWIVEL_GRID_COARSE
    anyone = th_ref is None and sw is None
    target = sw.target if sw else None
    ana, note, err = analytic_seeds(pb.robot, ws, tg, ref, target, grid, anyone)
    if not len(ana) and grid is SWIVEL_GRID_COARSE and sh.swivel_family:
        ana, note, err = analytic_seeds(pb.robot, ws, tg, ref, target, SWIVEL_GRID, anyone)
    if err is not None and anyone and tg.ok(err[0] * err[0], err[1] * err[1]):
        msg = "converged from an analytic seed"
        done = IKResult(ana[0], True, "success", err[0], err[1], 0, 0, msg, tg.mode, "analytic")
        return ana, note, done
    return ana, note, None


def _settle_swivel(pb, tg, ths, pe, re, msg):
    """After the swivel phase: if the swivel target is still off, try the closed form at that
    angle (another branch of the self-motion may hold it); report what remains.
    Returns (θ, pos_err, rot_err, seed tag or "", message)."""
    ws, sw = pb.ws, pb.swivel
    off = sw.offset(ws, ths)
    if off <= 1e-6:
        return ths, pe, re, "", msg
    tried = ""
    if pb.analytic is not False:
        ref = ws.sh.ref if pb.th_ref is None else pb.th_ref
        S, _, _ = analytic_seeds(pb.robot, ws, tg, ref, sw.target)
        if ws.sh.has_closed_form:
            tried = " and the closed form has no solution at that angle inside the limits"
        for cand in S:
            pe_c, re_c = tg.errors(ws, cand)
            if tg.ok(pe_c * pe_c, re_c * re_c):
                return (
                    cand,
                    pe_c,
                    re_c,
                    "analytic",
                    "converged from an analytic seed at the requested swivel angle",
                )
    msg += (
        f"; swivel angle off by {off:.3g} rad: not reachable along this solution's self-motion within the "
        f"joint limits{tried} (the hand pose is exact)"
    )
    return ths, pe, re, "", msg


def solve_lockstep(pb: Problem, tgs, seeds):
    """Batch form: every target iterates the kernel's damped step together
    (:func:`~anthroarm.ik.solve.kernel.damped_step` with a leading batch axis: the linear
    algebra vectorised); Pinocchio's FK and Jacobians are one call per target.  Converged
    targets leave the batch; a target whose attempt stalls restarts from its next seed (the
    seed table's next nearest entry, then a random θ), up to :data:`LOCKSTEP_ATTEMPTS`
    attempts, after which it is handed to :func:`solve_one` (all its seeds, restarts and the
    time budget); so are converged targets of a posture or swivel problem (their null-space
    phase).  Same answers' quality, less time per target."""
    ws = pb.ws
    sh = ws.sh
    N, n, m = len(tgs), sh.n, tgs[0].m
    tables = [None] * N
    Th = np.empty((N, n))
    for k in range(N):
        if seeds[k] is None:
            tables[k] = TableSeeds(ws, tgs[k], pb.th_ref)
            Th[k] = tables[k].next()
        else:
            Th[k] = seeds[k]
    Th = np.minimum(np.maximum(Th, sh.lo), sh.hi)
    J = np.empty((N, m, n))
    E = np.empty((N, m))
    EE = np.empty(N)
    OK = np.zeros(N, dtype=bool)
    PE2 = np.zeros(N)
    RE2 = np.zeros(N)
    its = np.zeros(N, dtype=int)
    att_it = np.zeros(N, dtype=int)
    attempts = np.ones(N, dtype=int)
    best = np.full(N, np.inf)
    stall = np.zeros(N, dtype=int)
    converged = np.zeros(N, dtype=bool)
    max_attempts = (
        LOCKSTEP_ATTEMPTS
        if pb.max_restarts is None
        else min(LOCKSTEP_ATTEMPTS, int(pb.max_restarts) + 1)
    )
    active = np.arange(N)
    while active.size:
        for k in active:  # Pinocchio: one call per target
            tg = tgs[k]
            E[k], EE[k], PE2[k], RE2[k] = tg.residual(ws, Th[k])
            OK[k] = tg.ok(PE2[k], RE2[k])
            if not OK[k]:
                J[k] = tg.jacobian(ws)
        its[active] += 1
        att_it[active] += 1
        ok = OK[active]
        converged[active[ok]] = True
        active = active[~ok]
        if not active.size:
            break
        Ee = EE[active]
        improved = Ee < 0.9 * best[active]
        best[active] = np.where(improved, Ee, best[active])
        stall[active] = np.where(improved, 0, stall[active] + 1)
        ended = (stall[active] >= STALL) | (att_it[active] >= MAX_ITER)
        stepping = active
        if ended.any():
            ek = active[ended]
            retry = ek[attempts[ek] < max_attempts]
            for k in retry:  # next seed: the next table entry, then random
                if tables[k] is None:
                    tables[k] = TableSeeds(ws, tgs[k], pb.th_ref)
                th = tables[k].next()
                Th[k] = pb.random() if th is None else th
            attempts[retry] += 1
            att_it[retry] = 0
            stall[retry] = 0
            best[retry] = np.inf
            stepping = active[~ended]  # retried targets are evaluated first, next round
            active = np.concatenate([stepping, retry])
        if stepping.size:
            Tn = damped_step(ws, Th[stepping], J[stepping], E[stepping], damping(EE[stepping]))
            if Tn is None:  # a singular system: hand those targets over
                active = np.setdiff1d(active, stepping)
                continue
            Th[stepping] = Tn
    results = []
    for k in range(N):
        restarts = int(attempts[k] - 1)
        tg = tgs[k]
        if converged[k] and pb.th_ref is None and pb.swivel is None:
            tag = ("q0" if seeds[k] is not None else "table") if restarts == 0 else "restart"
            results.append(
                IKResult(
                    Th[k].copy(),
                    True,
                    "success",
                    math.sqrt(PE2[k]),
                    math.sqrt(RE2[k]),
                    int(its[k]),
                    restarts,
                    f"converged from {_article(tag)} {tag} seed (batch)",
                    tg.mode,
                    tag,
                )
            )
            continue
        # a redundant arm's null-space phase, or stalled LOCKSTEP_ATTEMPTS times: the one-target solver
        r = solve_one(pb, tg, Th[k] if converged[k] else seeds[k])
        r.iterations += int(its[k])
        if converged[k]:
            r.restarts += restarts
        results.append(r)
    return results


def _article(word: str) -> str:
    """'an' before a seed tag that starts with a vowel ('analytic'), else 'a' ('table', 'q0')."""
    return "an" if word[:1] in "aeiou" else "a"
