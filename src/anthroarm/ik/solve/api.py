"""``aa.ik.solve``: argument checks, the seed order and restarts of one target, and the lockstep
batch.  See :mod:`anthroarm.ik.solve` for the method."""

from __future__ import annotations

import math

import numpy as np

from ... import jit
from ..closed.limits import refine
from ..qp.tasks.swivel import swivel_frames as _swivel_frames
from ..result import IKBatchResult, IKResult
from . import coupled, lm
from .kernel import MAX_ITER, STALL, clock, damped_step, damping
from .nullspace import Swivel, posture
from .nullspace import swivel as swivel_phase
from .seeds import SWIVEL_GRID, SWIVEL_GRID_COARSE, TableSeeds, analytic_seeds
from .targets import ORIENTATION, Target, check_options, check_q0, parse
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


# long: the public docstring (every argument); the body is the dispatch of a coupled model
# and the calls of the steps
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
        seed table and the kernels, made or loaded once per (robot, frame) on the first call,
        and the garbage collector's pauses are not charged to it (:func:`~anthroarm.ik.solve.kernel.clock`).
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
    mode, batch, targets = parse(T, mode)
    check_options(tol_pos, tol_rot, max_time, max_restarts, rng, analytic)
    Q0 = None if q0 is None else sh.theta(check_q0(robot, q0, batch, len(targets)))
    th_ref, sw = _reference(robot, sh, posture, swivel, swivel_frames)
    redundant = sh.dof > (6 if mode == "pose" else 3)  # the objectives need a self-motion
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
    _prepare(pb, mode, tp, tr)
    if not batch:
        return _result(sh, solve_one(pb, Target(mode, targets[0], tp, tr), Q0), Q0)
    return _solve_batch(pb, mode, [Target(mode, t, tp, tr) for t in targets], Q0, warm_start)


def _prepare(pb: Problem, mode: str, tp: float, tr: float) -> None:
    """The one-time work of a (robot, frame, settings), done before any clock starts so that no
    call's ``max_time`` is charged for it: the seed tables (and the aligned table of a pose
    problem), the compiled kernel of the iteration and those of the closed form (compiled, or
    loaded from the disk cache: :func:`_warm_closed_form`); once per workspace and settings
    (``ws.prepared``: a later call of the same settings returns at once)."""
    ws = pb.ws
    key = (mode, pb.analytic is not False, pb.th_ref is not None, pb.swivel is not None)
    if key in ws.prepared:
        return
    ws.table()
    if mode == "pose":
        ws.aligned()
    if not ws.lm.warm:
        lm.warm(ws)
    if pb.analytic is not False and ws.sh.has_closed_form:
        _warm_closed_form(pb, mode, tp, tr)
    ws.prepared.add(key)


def _solve_batch(pb: Problem, mode: str, tgs, Q0, warm_start: bool):
    """The IKBatchResult of the targets ``tgs`` (seeds: the rows of an (N, n) ``Q0``, one
    (n,) ``Q0`` for all, or none): in lockstep (:func:`solve_lockstep`) for
    :data:`LOCKSTEP_MIN` targets and more, unless they are chained (``warm_start``) or the
    closed form answers a pose first; else one after the other, target i seeded with the answer
    of target i − 1 when ``warm_start`` and no ``Q0``."""
    sh = pb.ws.sh
    seeds = [None if Q0 is None else (Q0[i] if Q0.ndim == 2 else Q0) for i in range(len(tgs))]
    if (
        not warm_start
        and len(tgs) >= LOCKSTEP_MIN
        and not (pb.closed_form_first(Q0) and mode == "pose")
    ):
        results = solve_lockstep(pb, tgs, seeds)
    else:
        chain = warm_start and Q0 is None
        results, prev = [], None
        for tg, seed in zip(tgs, seeds):
            r = solve_one(pb, tg, prev if (chain and prev is not None) else seed)
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


class SeedOrder:
    """The seeds of :func:`solve_one` in turn, :meth:`next` giving (θ, tag): the closed-form
    solutions ``ana`` (tag ``"analytic"``; set at the start when the closed form goes first, or
    later by :func:`solve_one`), ``q0`` clipped into the limits, the seed-table entries nearest
    first (``"table"``; the table made when first needed), then uniform random θ
    (``"restart"``)."""

    __slots__ = ("pb", "tg", "ana", "i", "seed", "table")

    def __init__(self, pb: Problem, tg: Target, seed, ana):
        self.pb, self.tg, self.seed, self.ana, self.i, self.table = pb, tg, seed, ana, 0, None

    def next(self):
        ana = self.ana
        if ana is not None and self.i < len(ana):
            self.i += 1
            return ana[self.i - 1].copy(), "analytic"
        pb = self.pb
        if self.seed is not None:
            sh = pb.ws.sh
            th, self.seed = np.minimum(np.maximum(self.seed, sh.lo), sh.hi), None
            return th, "q0"
        if self.table is None:
            self.table = TableSeeds(pb.ws, self.tg, pb.th_ref)
        th = self.table.next()
        return (pb.random(), "restart") if th is None else (th, "table")


def solve_one(pb: Problem, tg: Target, seed):
    """One target: the seeds in order — closed form (``analytic=True``, or "auto" where it is
    cheap and no q0 is given), q0, the seed table nearest first, uniform random
    (:class:`SeedOrder`) — each refined by :func:`~anthroarm.ik.solve.lm.attempt` until one
    converges, the budget is spent or ``max_restarts`` is reached; then the posture or swivel
    phase (:func:`_converged`).  A closed-form seed of a posture problem goes straight to the
    posture phase, which verifies it.  Returns an IKResult whose ``q`` is θ (:func:`_result`
    maps it)."""
    ws = pb.ws
    t0 = clock()
    deadline = t0 + pb.max_time
    th_ref, sw = pb.th_ref, pb.swivel
    out_of_reach = _out_of_reach(ws.sh, tg)
    ana, note = None, ""
    if not out_of_reach and pb.closed_form_first(seed):
        ana, note, done = _closed_form_seeds(pb, tg, seed)
        if done is not None:
            return done
    order = SeedOrder(pb, tg, seed, ana)
    total_it = restarts = attempts = 0
    best_q, best_E = None, math.inf
    while True:
        th, tag = order.next()
        if attempts:
            restarts += 1
        if tag == "analytic" and th_ref is not None and sw is None:
            ths, pe2, re2, it = posture(ws, tg, th, th_ref, deadline + 0.5 * pb.max_time)
            total_it += it
            attempts += 1
            if ths is not None:
                msg = "converged from an analytic seed"
                pe, re = math.sqrt(pe2), math.sqrt(re2)
                return IKResult(ths, True, "success", pe, re, total_it, restarts, msg, tg.mode, tag)
        ths, ok, it, pe2, re2, bq, bE = lm.attempt(ws, tg, th, deadline)
        total_it += it
        attempts += 1
        if bE < best_E:
            best_q, best_E = bq, bE
        if ok:
            return _converged(pb, tg, ths, pe2, re2, tag, total_it, restarts, deadline)
        if out_of_reach and attempts >= 3:
            break
        if (
            pb.analytic == "auto"
            and order.ana is None
            and not out_of_reach
            and attempts >= ANALYTIC_AFTER
        ):
            order.ana, note, _ = analytic_seeds(
                pb.robot, ws, tg, best_q, sw.target if sw else None, SWIVEL_GRID
            )
        if clock() > deadline or (pb.max_restarts is not None and restarts >= pb.max_restarts):
            break
    th = best_q if best_q is not None else th
    return _unsolved(pb, tg, th, tag, out_of_reach, note, total_it, restarts, t0)


def _converged(pb: Problem, tg: Target, ths, pe2, re2, tag, total_it, restarts, deadline):
    """The IKResult once Gauss–Newton met the tolerances at θ from seed ``tag``: for a swivel
    objective the swivel phase (:func:`~anthroarm.ik.solve.nullspace.swivel`, then
    :func:`_settle_swivel`), for a posture the posture phase
    (:func:`~anthroarm.ik.solve.nullspace.posture`, whose answer replaces θ only if one of its
    iterates meets the tolerances); each phase may run half a budget past ``deadline``."""
    ws, sw, th_ref = pb.ws, pb.swivel, pb.th_ref
    pe, re = math.sqrt(pe2), math.sqrt(re2)
    msg = f"converged from {_article(tag)} {tag} seed"
    late = deadline + 0.5 * pb.max_time
    if sw is not None:
        ths, it2 = swivel_phase(ws, tg, ths, sw, late)
        total_it += it2
        pe, re = tg.errors(ws, ths)
        ths, pe, re, tag2, msg = _settle_swivel(pb, tg, ths, pe, re, msg)
        tag = tag2 or tag
    elif th_ref is not None:
        ths2, pe2, re2, it2 = posture(ws, tg, ths, th_ref, late)
        total_it += it2
        if ths2 is not None:
            ths, pe, re = ths2, math.sqrt(pe2), math.sqrt(re2)
    return IKResult(ths, True, "success", pe, re, total_it, restarts, msg, tg.mode, tag)


def _unsolved(pb: Problem, tg: Target, th, tag, out_of_reach, note, total_it, restarts, t0):
    """The IKResult of a target no seed solved: status ``"out_of_reach"`` (``out_of_reach`` says
    why) or ``"not_converged"``, θ the closest configuration found and its errors."""
    max_time = pb.max_time
    why = out_of_reach or (
        f"no configuration within the joint limits reached tol_pos={tg.tol_p:g} m / "
        f"tol_rot={tg.tol_r:g} rad after {total_it} iterations, {restarts} restarts, "
        f"{(clock() - t0) * 1e3:.1f} ms CPU (max_time {max_time * 1e3:g} ms); the target is "
        "probably outside the joint-limited workspace"
    )
    pe, re = tg.errors(pb.ws, th)
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
    phase).  Same answers' quality, less time per target.  The rounds are those of
    :class:`Lockstep`: evaluate, end or restart attempts, step."""
    st = Lockstep(pb, tgs, seeds)
    active = np.arange(len(tgs))
    while active.size:
        active = st.evaluate(active)
        if not active.size:
            break
        stepping, active = st.restart(active)
        if stepping.size:
            active = st.step(stepping, active)
    return st.results()


class Lockstep:
    """The state of :func:`solve_lockstep`, one row per target: θ ``Th``, the last residual
    (``E`` = e, ``EE`` = ‖e‖², ``PE2``/``RE2`` the squared errors, ``OK``) and Jacobian ``J``,
    the iterations in all (``its``) and in this attempt (``att_it``), the attempts made, the
    best ‖e‖² of this attempt and the iterations since it last fell by 10 % (``stall``), the
    converged flags and the seed tables (made when needed)."""

    __slots__ = (
        "pb",
        "tgs",
        "seeds",
        "tables",
        "Th",
        "J",
        "E",
        "EE",
        "OK",
        "PE2",
        "RE2",
        "its",
        "att_it",
        "attempts",
        "best",
        "stall",
        "converged",
        "max_attempts",
    )

    def __init__(self, pb: Problem, tgs, seeds):
        """The first seeds: ``seeds[k]`` where given, else the nearest seed-table entry; all
        clipped into the limits."""
        ws = pb.ws
        sh = ws.sh
        N, n, m = len(tgs), sh.n, tgs[0].m
        self.pb, self.tgs, self.seeds = pb, tgs, seeds
        self.tables = tables = [None] * N
        Th = np.empty((N, n))
        for k in range(N):
            if seeds[k] is None:
                tables[k] = TableSeeds(ws, tgs[k], pb.th_ref)
                Th[k] = tables[k].next()
            else:
                Th[k] = seeds[k]
        self.Th = np.minimum(np.maximum(Th, sh.lo), sh.hi)
        self.J = np.empty((N, m, n))
        self.E = np.empty((N, m))
        self.EE = np.empty(N)
        self.OK = np.zeros(N, dtype=bool)
        self.PE2 = np.zeros(N)
        self.RE2 = np.zeros(N)
        self.its = np.zeros(N, dtype=int)
        self.att_it = np.zeros(N, dtype=int)
        self.attempts = np.ones(N, dtype=int)
        self.best = np.full(N, np.inf)
        self.stall = np.zeros(N, dtype=int)
        self.converged = np.zeros(N, dtype=bool)
        cap = pb.max_restarts
        self.max_attempts = (
            LOCKSTEP_ATTEMPTS if cap is None else min(LOCKSTEP_ATTEMPTS, int(cap) + 1)
        )

    def evaluate(self, active):
        """The residual of the ``active`` targets at their θ and, where not converged, their
        Jacobian (Pinocchio: one call per target); returns the targets still to iterate (the
        converged ones marked and dropped)."""
        ws, tgs, Th = self.pb.ws, self.tgs, self.Th
        E, EE, PE2, RE2, OK, J = self.E, self.EE, self.PE2, self.RE2, self.OK, self.J
        for k in active:
            tg = tgs[k]
            E[k], EE[k], PE2[k], RE2[k] = tg.residual(ws, Th[k])
            OK[k] = tg.ok(PE2[k], RE2[k])
            if not OK[k]:
                J[k] = tg.jacobian(ws)
        self.its[active] += 1
        self.att_it[active] += 1
        ok = OK[active]
        self.converged[active[ok]] = True
        return active[~ok]

    def restart(self, active):
        """(the targets that step this round, the targets still active).  An attempt ends after
        :data:`STALL` iterations without ‖e‖² falling below 0.9 × its best, or after
        :data:`MAX_ITER`; its target restarts from its next seed (the next table entry, then a
        random θ; evaluated first, next round) while it has attempts left, else leaves the
        batch."""
        pb, EE, best, stall, attempts = self.pb, self.EE, self.best, self.stall, self.attempts
        Ee = EE[active]
        improved = Ee < 0.9 * best[active]
        best[active] = np.where(improved, Ee, best[active])
        stall[active] = np.where(improved, 0, stall[active] + 1)
        ended = (stall[active] >= STALL) | (self.att_it[active] >= MAX_ITER)
        if not ended.any():
            return active, active
        ek = active[ended]
        retry = ek[attempts[ek] < self.max_attempts]
        tables, Th = self.tables, self.Th
        for k in retry:
            if tables[k] is None:
                tables[k] = TableSeeds(pb.ws, self.tgs[k], pb.th_ref)
            th = tables[k].next()
            Th[k] = pb.random() if th is None else th
        attempts[retry] += 1
        self.att_it[retry] = 0
        stall[retry] = 0
        best[retry] = np.inf
        stepping = active[~ended]
        return stepping, np.concatenate([stepping, retry])

    def step(self, stepping, active):
        """θ ← θ + Δθ of the ``stepping`` targets (:func:`~anthroarm.ik.solve.kernel.damped_step`,
        all at once); returns the active targets, without the stepping ones if their system is
        singular (they are handed to :func:`solve_one`)."""
        EE = self.EE[stepping]
        Tn = damped_step(
            self.pb.ws, self.Th[stepping], self.J[stepping], self.E[stepping], damping(EE)
        )
        if Tn is None:
            return np.setdiff1d(active, stepping)
        self.Th[stepping] = Tn
        return active

    def results(self):
        """The IKResults (θ in ``q``): a converged target's own unless a posture or swivel
        objective is set; :func:`solve_one`'s for the others (from the converged θ: the
        null-space phase; from the caller's seed: a target that stalled in every attempt),
        the lockstep iterations (and restarts, if converged) added."""
        pb, tgs, seeds, Th = self.pb, self.tgs, self.seeds, self.Th
        plain = pb.th_ref is None and pb.swivel is None
        results = []
        for k in range(len(tgs)):
            restarts = int(self.attempts[k] - 1)
            tg, converged = tgs[k], self.converged[k]
            if converged and plain:
                tag = ("q0" if seeds[k] is not None else "table") if restarts == 0 else "restart"
                msg = f"converged from {_article(tag)} {tag} seed (batch)"
                pe, re, it = math.sqrt(self.PE2[k]), math.sqrt(self.RE2[k]), int(self.its[k])
                results.append(
                    IKResult(Th[k].copy(), True, "success", pe, re, it, restarts, msg, tg.mode, tag)
                )
                continue
            r = solve_one(pb, tg, Th[k] if converged else seeds[k])
            r.iterations += int(self.its[k])
            if converged:
                r.restarts += restarts
            results.append(r)
        return results


def _article(word: str) -> str:
    """'an' before a seed tag that starts with a vowel ('analytic'), else 'a' ('table', 'q0')."""
    return "an" if word[:1] in "aeiou" else "a"
