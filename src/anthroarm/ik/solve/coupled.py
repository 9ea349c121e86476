"""``aa.ik.solve`` on an OpenSim model with nonlinear couplings (``robot.coupling``), in its
independent coordinates.

Such a model (``aa.load("gait2392.osim")``: knee translations that are splines of the knee
angle) moves Pinocchio's joints as φ(q) of its coordinates q (:mod:`anthroarm.osim.coupling`).
The solver iterates on q itself, with the kernel every other robot uses
(:func:`~anthroarm.ik.solve.kernel.attempt`: damped Gauss–Newton, the coordinate ranges held by
its active set) on the target's error at φ(q) and the chain-rule Jacobian::

    e = log₆(T(φ(q))⁻¹ T*),   J = ᵇJ(φ(q)) · G(q),   G = dφ/dq,
    Δq = Jᵀ (J Jᵀ + λ I)⁻¹ e,   q ← clip(q + Δq, q_min, q_max)

(position and rotation targets as in :mod:`anthroarm.ik.solve.targets`).  φ and G come from
:class:`~anthroarm.osim.coupling.FastCoupling` (OpenSim's functions evaluated as OpenSim does),
the kinematics from Pinocchio at φ(q); the projected-Jacobian formulation is that of Jain,
*Robot and Multibody Dynamics* (2011), §8, and of OpenSim's own IK in the coordinates (Delp et
al. 2007, IEEE TBME 54(11)).

Seeds, in order: ``q0`` (clipped into the ranges), the model's default pose
(``robot.default_q()``, where OpenSim's ``assemble`` starts; tag ``"default"``), then uniform
random coordinates inside the ranges (tag ``"restart"``) until ``max_time`` (CPU time of the
calling thread) or ``max_restarts``.  Only the coordinates that move the frame are sampled and
iterated: the others keep ``q0``'s values (else the posture's, else the default pose's).  A
``posture`` (nq,) then lowers ½‖q − q_ref‖² along the self-motion (:func:`posture`: projected
gradient steps, Liégeois 1977, each brought back onto the target by the kernel).  There is no closed form, seed table or swivel
objective for these models; the answer is checked with Pinocchio's FK at φ(q).
"""

from __future__ import annotations

import math
import threading

import numpy as np

from ...errors import ParameterError
from ...osim.coupling import FastCoupling
from ..result import IKBatchResult, IKResult
from .kernel import attempt, clip, clock, damping
from .targets import Target, check_options, check_q0, parse

POSTURE_STEP = 0.25  # longest null-space move of the posture phase (rad or m)
POSTURE_TOL = 1e-4  # the posture phase stops when its move is shorter (rad or m)
POSTURE_ITER = 200  # and after this many moves


class CoupledTarget(Target):
    """A :class:`~anthroarm.ik.solve.targets.Target` whose configuration is the coordinates q:
    its error is the target's at φ(q) and its Jacobian ``J(φ(q)) G(q)`` (``ws.G`` holds the G
    of the last :meth:`residual`)."""

    __slots__ = ()

    def residual(self, ws, q):
        phi, ws.G = ws.coupling.jacobian(q)
        return Target.residual(self, ws, phi)

    def jacobian(self, ws):
        return Target.jacobian(self, ws).dot(ws.G)

    def errors(self, ws, q):
        return Target.errors(self, ws, ws.coupling.jacobian(q)[0])


class Shared:
    """What the kernel and the null-space phase read of a coupled (robot, frame): ``dof`` (the
    coordinates that move the frame), no continuous joints, no θ → q map."""

    __slots__ = ("dof", "continuous", "to_q")

    def __init__(self, dof: int):
        self.dof, self.continuous, self.to_q = dof, None, None


class CoupledWorkspace:
    """A thread's workspace for (robot, frame): the Pinocchio model and its own ``pin.Data``
    (so a Robot may be solved for from several threads at once), the coupling map, the frame
    id, the coordinates that move it (``path``), the coordinate ranges ``lo``/``hi`` and the
    kernel's preallocated linear systems (as :class:`~anthroarm.ik.solve.workspace.Workspace`).
    Nothing in it refers to the Robot."""

    __slots__ = (
        "sh",
        "model",
        "data",
        "fid",
        "n",
        "lo",
        "hi",
        "to_q",
        "lin",
        "coupling",
        "G",
        "path",
    )

    def __init__(self, robot, fid: int, on_path):
        self.path = on_path
        self.model = robot.model
        self.data = robot.model.createData()
        self.fid = fid
        self.coupling = FastCoupling(robot.coupling)
        self.n = robot.nq
        self.lo = np.array(robot.lower, dtype=float)
        self.hi = np.array(robot.upper, dtype=float)
        self.to_q = None  # Target.residual is handed φ(q) itself
        self.sh = Shared(int(on_path.sum()))
        self.G = None
        self.lin = {}
        for m in {3, 6, min(self.n, 6)}:
            A = np.empty((m, m))
            self.lin[m] = (A, A.T, A.reshape(-1)[:: m + 1])


def _frames(robot) -> dict:
    return {}


def workspace(robot, fid: int) -> CoupledWorkspace:
    """The calling thread's :class:`CoupledWorkspace` for (robot, frame id ``fid``), made once
    and kept on the robot (``robot.derived``: dropped with it)."""
    frames = robot.derived("ik.solve.coupled", _frames)  # frame id -> threading.local
    local = frames.get(fid)
    if local is None:
        local = frames.setdefault(fid, threading.local())
    ws = getattr(local, "ws", None)
    if ws is None:
        ws = local.ws = CoupledWorkspace(robot, fid, on_path(robot, fid))
    return ws


def on_path(robot, fid: int) -> np.ndarray:
    """(nq,) bool: the coordinates that move frame ``fid`` — those a Pinocchio joint on the
    frame's path is a function of, through the couplers (``coupling.dependent_steps``)."""
    c = robot.coupling
    chain = robot.chain
    path_q = {chain.joints[i].idx_q for i in chain.path(fid)}
    used = {s.source for s in c.joint_steps if s.target in path_q}
    for s in reversed(c.dependent_steps):  # a coupler's source moves what its target moves
        if s.target in used:
            used.add(s.source)
    return np.array([int(k) in used for k in c.independent], dtype=bool)


def solve(
    robot,
    T,
    q0=None,
    frame=None,
    tol_pos: float = 1e-6,
    tol_rot: float = 1e-6,
    max_time: float = 0.05,
    *,
    mode=None,
    max_restarts=None,
    rng=None,
    posture="auto",
    swivel=None,
    swivel_frames=None,
    analytic="auto",
    warm_start: bool = False,
):
    """:func:`anthroarm.ik.solve` for a robot with ``robot.coupling`` (see the module
    docstring); same arguments, results and statuses, q in the coordinates
    (``robot.joint_names``).  ``posture="auto"`` is none here (no comfortable posture is known
    for these models); ``swivel`` raises :class:`~anthroarm.errors.ParameterError`."""
    fid = robot.frame_id(frame)
    mode, batch, targets = parse(T, mode)
    check_options(tol_pos, tol_rot, max_time, max_restarts, rng, analytic)
    if swivel is not None or swivel_frames is not None:
        raise ParameterError(
            f"{robot.name}: swivel= places a human arm's elbow; this OpenSim model's coordinates "
            "(robot.coupling) have no swivel objective: give a posture (nq,) instead"
        )
    Q0 = check_q0(robot, q0, batch, len(targets))
    ref = _posture_ref(robot, posture)
    ws = workspace(robot, fid)
    lo, hi = ws.lo, ws.hi
    if ref is not None:
        ref = clip(ref, lo, hi)
    default = clip(robot.default_q(), lo, hi)
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
    redundant = int(ws.path.sum()) > (6 if mode == "pose" else 3)
    note = " (no closed form for a model with coupled coordinates)" if analytic is True else ""
    tp, tr = float(tol_pos), float(tol_rot)
    results, prev = [], None
    for i, tgt in enumerate(targets):
        seed = None if Q0 is None else (Q0[i] if Q0.ndim == 2 else Q0)
        if warm_start and batch and seed is None and prev is not None:
            seed = prev
        tg = CoupledTarget(mode, tgt, tp, tr)
        r = _solve_seeded(ws, tg, seed, ref, redundant, default, gen, max_time, max_restarts)
        r.message += note
        results.append(r)
        prev = r.q
    if not batch:
        return results[0]
    return IKBatchResult.collect(results, robot.nq, mode)


def _posture_ref(robot, posture):
    """The reference coordinates of ``posture`` ((nq,), not yet clipped), None for ``"auto"``
    or None (no comfortable posture is known for these models); ValueError otherwise."""
    if isinstance(posture, str):
        if posture != "auto":
            raise ValueError(f"posture must be 'auto', None or a configuration, got {posture!r}")
        return None
    if posture is None:
        return None
    ref = robot.check_q(posture, name="posture")
    if ref.ndim != 1:
        raise ValueError(f"posture must have shape ({robot.nq},), got {ref.shape}")
    return ref


def _solve_seeded(ws, tg, seed, ref, redundant, default, gen, max_time, max_restarts):
    """:func:`solve_one` for one target with the caller's ``seed`` (or None), the posture
    ``ref`` (clipped, or None) and the default pose ``default`` (clipped).  On the frame's
    coordinates the first seed is ``seed`` (else the default pose) and, for a ``redundant``
    frame (more coordinates than the task's dimension), the posture phase pulls them toward
    ``ref``; the other coordinates keep ``seed``'s values, else ``ref``'s, else the default
    pose's, and are not moved."""
    path, lo, hi = ws.path, ws.lo, ws.hi
    base = clip(seed, lo, hi) if seed is not None else (ref if ref is not None else default)
    th_ref = np.where(path, ref, base) if ref is not None and redundant else None
    r = solve_one(
        ws,
        tg,
        seed is not None,
        np.where(path, base, default) if seed is None else base,
        np.where(path, default, base),
        path,
        gen,
        float(max_time),
        max_restarts,
        th_ref,
    )
    r.q = np.where(path, r.q, base)  # coordinates off the frame's path: not moved
    return r


def solve_one(ws, tg, given, first, default, path, gen, max_time, max_restarts, th_ref):
    """One target: ``first`` (q0, tag ``"q0"``, when ``given``), then ``default`` (the model's
    default pose on the frame's coordinates), then random restarts on the frame's coordinates,
    each refined by :func:`~anthroarm.ik.solve.kernel.attempt`; then the posture phase when
    ``th_ref`` is set.  Returns an :class:`~anthroarm.ik.result.IKResult` in the coordinates."""
    t0 = clock()
    deadline = t0 + max_time
    lo, hi = ws.lo, ws.hi
    seeds = [(first, "q0")] if given else []
    seeds.append((default if given else first, "default"))
    total = attempts = 0
    best_q, best_E = first, math.inf
    tag = seeds[0][1]
    while True:
        if attempts < len(seeds):
            q, tag = seeds[attempts]
            q = clip(q, lo, hi)
        else:
            q = np.where(path, lo + (hi - lo) * gen.random(ws.n), seeds[0][0])
            tag = "restart"
        qs, ok, it, pe2, re2, bq, bE = attempt(ws, tg, q, deadline)
        total += it
        attempts += 1
        if bE < best_E:
            best_q, best_E = bq, bE
        if ok:
            pe, re = math.sqrt(pe2), math.sqrt(re2)
            if th_ref is not None:
                qs, pe2, re2, it2 = posture(ws, tg, qs, pe2, re2, th_ref, deadline + 0.5 * max_time)
                total += it2
                pe, re = math.sqrt(pe2), math.sqrt(re2)
            return IKResult(
                qs,
                True,
                "success",
                pe,
                re,
                total,
                attempts - 1,
                f"converged from the {tag} seed in the coordinates (J G, G = dφ/dq)",
                tg.mode,
                tag,
            )
        if clock() > deadline or (max_restarts is not None and attempts - 1 >= max_restarts):
            break
    pe, re = tg.errors(ws, best_q)
    msg = (
        f"no configuration within the coordinate ranges reached tol_pos={tg.tol_p:g} m / "
        f"tol_rot={tg.tol_r:g} rad after {total} iterations, {attempts - 1} restarts, "
        f"{(clock() - t0) * 1e3:.1f} ms CPU (max_time {max_time * 1e3:g} ms); the target is "
        f"probably outside the range-limited workspace; closest pose found: pos_err {pe:.3g} m, "
        f"rot_err {re:.3g} rad"
    )
    return IKResult(best_q, False, "not_converged", pe, re, total, attempts - 1, msg, tg.mode, tag)


def posture(ws, tg, q, pe2, re2, ref, deadline):
    """From a solution q (squared errors ``pe2``, ``re2``), lower ½‖q − q_ref‖² along the
    self-motion: the projected gradient p = N (q_ref − q), N = I − Jᵀ(JJᵀ + λI)⁻¹J (Liégeois
    1977; the book's redundancy resolution, Ch. 7 §7-6 (7-84)–(7-86)), a move of at most
    :data:`POSTURE_STEP` along it, clipped into the ranges, then the kernel's Gauss–Newton back
    onto the target.  A move is kept when the target is met again and q came nearer q_ref; its
    length doubles then (up to the full projected step) and halves otherwise.  Stops below
    :data:`POSTURE_TOL`, after :data:`POSTURE_ITER` moves or at the deadline.  Several
    dimensions of self-motion (a leg with the pelvis free: 6 and more) need these re-converged
    moves where the secant step of :func:`~anthroarm.ik.solve.nullspace.posture` is for one.

    Returns (q, pos_err², rot_err², iterations), q always a solution."""
    lo, hi = ws.lo, ws.hi
    d = np.linalg.norm(q - ref)
    alpha = 1.0
    total = 0
    for _ in range(POSTURE_ITER):
        e, E, _, _ = tg.residual(ws, q)
        J = tg.jacobian(ws)
        z = ref - q
        A = J.dot(J.T)
        A.flat[:: len(A) + 1] += damping(E)
        p = z - J.T.dot(np.linalg.solve(A, J.dot(z)))
        n = float(np.linalg.norm(p))
        length = alpha * min(n, POSTURE_STEP)
        if length < POSTURE_TOL or clock() > deadline:
            break
        qn, ok, it, pn2, rn2, _, _ = attempt(ws, tg, clip(q + p * (length / n), lo, hi), deadline)
        total += it
        dn = np.linalg.norm(qn - ref) if ok else math.inf
        if dn < d:
            q, d, pe2, re2 = qn, dn, pn2, rn2
            alpha = min(1.0, 2.0 * alpha)
        else:
            alpha *= 0.5
    return q, pe2, re2, total
