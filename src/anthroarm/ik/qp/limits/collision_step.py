"""One QP differential-IK step with inequality limits (collision avoidance)::

    min_Δq  Σ_tasks ½‖W(J Δq + α e)‖² + ½ λ‖Δq‖²
    s.t.    lo(q, dt) ≤ Δq ≤ hi(q, dt)        (the box limits, combined as in ``qp.step``)
            G Δq ≤ h                           (limits with ``inequalities``: CollisionLimit,
                                                CollisionBarrier)

The objective and the box are built by the same code as :func:`anthroarm.ik.qp.step` (the
tasks' ``_accumulate`` into its workspace, ``combine_into`` for the boxes); the QP is solved by
daqp (box rows as simple bounds, G as general rows) or quadprog.  ``qp.step`` takes boxes only;
this function is the hook an inequality limit needs until ``qp.step`` takes G, h itself.

Status (``full=True``): ``"optimal"``; ``"start_in_collision"`` when a pair started in collision (d < 0;
the rows then ask ḋ > 0: the step pushes the pair apart, as for any pair closer than d_s);
``"blocked"`` when the step, halved six times, still took a pair below min(d_s, its distance
before the step) by the true distances (step acceptance: the rows are linear in q);
``"relaxed"`` when the rows and the box had no common point even with the separation asked
of pairs inside d_s halved three times, and the rows were relaxed to "get no closer"
(h ← max(h, 0), feasible with Δq = 0); ``"infeasible"`` / ``"failed"`` with the
zero velocity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..configuration import IKConfiguration
from ..step import _Workspace, default_limits
from ..tasks.base import Task
from .base import BIG, combine_into

SOLVERS = ("daqp", "quadprog")
#: halvings of a step whose true distances fall below the floor before it is refused
BACKTRACK = 6


@dataclass
class CollisionStepResult:
    """Output of :func:`step` with ``full=True``: velocity ``v`` (nv,), ``status`` (see the
    module docstring), ``rows`` (inequality rows used), ``min_distance`` (m, smallest distance
    an inequality limit saw at the start of the step; inf when none was close)."""

    v: np.ndarray
    status: str
    rows: int
    min_distance: float
    info: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status in ("optimal", "start_in_collision", "relaxed", "blocked")


def _solve_daqp(H, c, lo, hi, G, h):
    import daqp  # optional-import: a base dependency listed in anthroarm.optional

    n, m = len(c), len(h)
    bu = np.concatenate([np.minimum(hi, BIG), h])
    bl = np.concatenate([np.maximum(lo, -BIG), np.full(m, -BIG)])
    sense = np.zeros(n + m, dtype=np.int32)
    x, _, flag, _ = daqp.solve(H, c, np.ascontiguousarray(G, dtype=float), bu, bl, sense)
    if flag > 0:
        return x, "optimal"
    return None, "infeasible" if flag == -1 else "failed"


def _solve_quadprog(H, c, lo, hi, G, h):
    import quadprog  # optional-import

    n = len(c)
    eye = np.eye(n)
    C = np.hstack([-G.T, eye, -eye])
    b = np.concatenate([-h, np.maximum(lo, -BIG), -np.minimum(hi, BIG)])
    try:
        x = quadprog.solve_qp(H, -c, C, b, 0)[0]
    except ValueError as exc:
        return None, "infeasible" if "inconsistent" in str(exc) else "failed"
    return x, "optimal"


def _accept(conf, ineq, v, dt, dmin, status):
    """Step acceptance: the rows linearise d with one witness point per pair, and when the
    closest features switch within a step (a box's corner turning onto a face) the true
    distance can fall below the prediction.  The step is checked with the true distances at
    q + v dt and halved (up to :data:`BACKTRACK` times, then v = 0: ``"blocked"``) until no
    pair ends below min(d_s, its smallest distance before the step)."""
    floor = min(min(getattr(lim, "d_safe", 0.0) for lim in ineq), dmin) - 1e-6
    robot = conf.robot
    for _ in range(BACKTRACK):
        q = pin.integrate(robot.model, conf.q, v * dt)
        d = min(lim.min_distance_at(q) for lim in ineq)
        if d >= floor:
            return v, status
        v = 0.5 * v
    return np.zeros_like(v), "blocked"


def _configuration(robot, q):
    """The :class:`IKConfiguration` a step works on: ``robot`` itself if it is one (moved to
    ``q`` if given), else the one kept on the robot for :func:`step`, moved to ``q``."""
    if isinstance(robot, IKConfiguration):
        if q is not None:
            robot.update(q)
        return robot
    st = robot.__dict__.setdefault("_collision_step", {})
    conf = st.get("conf")
    if conf is None:
        conf = st["conf"] = IKConfiguration(robot, q)
    else:
        conf.update(q)
    return conf


def _inequalities(ineq, conf, dt, nv):
    """The stacked rows G Δq ≤ h of the inequality limits, the smallest distance they saw
    (``dmin``, m; inf for none) and whether the step starts in collision (a distance < 0)."""
    Gs, hs, dmin, start_bad = [], [], math.inf, False
    for lim in ineq:
        G, h = lim.inequalities(conf, dt)
        Gs.append(G)
        hs.append(h)
        last = getattr(lim, "last", None)
        if last is not None and len(last):
            dmin = min(dmin, last.min)
            start_bad = start_bad or last.min < 0.0
    G = np.vstack(Gs) if Gs else np.zeros((0, nv))
    h = np.concatenate(hs) if hs else np.zeros(0)
    return G, h, dmin, start_bad


def _solve_relaxed(solve, H, c, lo, hi, G, h, start_bad):
    """(x, status) of the QP; where it is infeasible, the pairs inside the safety distance are
    asked to separate more slowly (h < 0 scaled by 1/2, 1/4, 1/8), then only not to approach
    (h clipped at 0: ``"relaxed"``); ``"start_in_collision"`` where the step started so."""
    x, status = solve(H, c, lo, hi, G, h)
    scale = 0.5
    while x is None and len(h) and scale > 0.1:
        x, status = solve(H, c, lo, hi, G, np.where(h < 0.0, scale * h, h))
        scale *= 0.5
    if x is None and len(h):
        x, status = solve(H, c, lo, hi, G, np.maximum(h, 0.0))
        if x is not None:
            status = "relaxed"
    elif start_bad and x is not None:
        status = "start_in_collision"
    return x, status


def step(
    robot,
    q,
    tasks,
    dt: float,
    limits="default",
    solver: str = "daqp",
    damping: float = 1e-12,
    full: bool = False,
):
    """Joint velocity v (nv,) of one differential-IK step with box and inequality limits.

    Parameters
    ----------
    robot : Robot or IKConfiguration
        As :func:`anthroarm.ik.qp.step` (a Robot: an IKConfiguration kept on it is updated to q).
    q : array (nq,) or None
    tasks : sequence of :class:`~anthroarm.ik.qp.tasks.Task`
    dt : float
        Step duration, s (> 0).
    limits : ``"default"`` (configuration + velocity limits), or a sequence mixing box limits
        and limits with ``inequalities(conf, dt) -> (G, h)`` (CollisionLimit,
        CollisionBarrier).
    solver : ``"daqp"`` or ``"quadprog"``.
    damping : float
        Tikhonov weight λ on ‖Δq‖².
    full : bool
        Return a :class:`CollisionStepResult` instead of the bare velocity.
    """
    conf = _configuration(robot, q)
    if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive finite number of seconds, got {dt!r}")
    if solver not in SOLVERS:
        raise ValueError(f"solver must be one of {SOLVERS}, got {solver!r}")
    diag = float(damping)
    if not (math.isfinite(diag) and diag >= 0.0):
        raise ValueError(f"damping must be a finite number >= 0, got {damping!r}")
    if isinstance(limits, str):
        if limits != "default":
            raise ValueError(f"limits must be 'default' or a list of limits, got {limits!r}")
        limits = default_limits(conf.robot)
    limits = list(limits or ())
    boxes = [lim for lim in limits if not hasattr(lim, "inequalities")]
    ineq = [lim for lim in limits if hasattr(lim, "inequalities")]
    nv = conf.nv
    ws = conf.__dict__.get("_collision_ws")
    if ws is None:
        ws = conf.__dict__["_collision_ws"] = _Workspace(nv)
    first = True
    for t in tasks:
        acc = getattr(t, "_accumulate", None) or Task._accumulate.__get__(t)
        diag += acc(conf, ws, first)
        first = False
    if first:
        ws.Hc.fill(0.0)
    if diag:
        np.add(ws.Hd, diag, out=ws.Hd)
    combine_into(boxes, conf, dt, ws)
    G, h, dmin, start_bad = _inequalities(ineq, conf, dt, nv)
    lo, hi = ws.lo.copy(), ws.hi.copy()
    if not np.isfinite(ws.Hc.dot(ws.Hc)):
        x, status = None, "failed"
    else:
        solve = _solve_daqp if solver == "daqp" else _solve_quadprog
        x, status = _solve_relaxed(solve, ws.H, ws.c, lo, hi, G, h, start_bad)
    if x is None:
        v = np.zeros(nv)
    else:
        v = np.clip(x, lo, hi) / dt
        if ineq and status != "failed":
            v, status = _accept(conf, ineq, v, dt, dmin, status)
    for lim in boxes:
        lim.after_step(v, dt)
    if full:
        return CollisionStepResult(v, status, len(h), dmin)
    return v


__all__ = ["step", "CollisionStepResult", "SOLVERS"]
