"""From a compiled solver's branches to a result: the configurations, the polish of near-exact
candidates, the FK check, the rescue of poses whose candidates lie on a limit, and why a pose has
no solution (:func:`finish`, :func:`reason`), shared by every kind of closed form
(:mod:`.kinds`).

A candidate is a solution when it is inside the limits and max |FK(q) − T| ≤ ``tol`` over the
3×4 pose entries (m / unitless; the position alone where ``position_only``); one inside the
limits with a residual ≤ :data:`POLISH_MAX` is first polished (:func:`.limits.refine`); a pose
without a solution whose exact candidates lie just outside the limits is rescued along its
self-motions (:func:`.limits.rescue`) where its kind allows (``kinds.ClosedFormKind.rescues``).
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from .. import geometric as _geo
from .limits import refine, rescue
from .results import AnalyticBatchResult

#: FK residual (m / unitless) up to which a candidate is polished (an arm of its class only
#: within the classification tolerance; a singular pose)
POLISH_MAX = _geo.POLISH_MAX


def fk_residual(robot, Qw, Ts, position_only):
    """max |FK(q) − T| (3×4 entries, or position) of candidates Qw (N, B, nq) against Ts (N, 4, 4),
    +inf for a non-finite candidate.  Few candidates: Pinocchio's FK (one C++ call each, the
    calling thread's ``robot.data``); many: the batched chain FK (``robot.chain.serial``)."""
    N, B = Qw.shape[:2]
    finite = np.isfinite(Qw).all(-1)
    if N * B > 64:
        Tf = robot.chain.serial(robot.tool).fk(
            np.where(finite[..., None], Qw, 0.0).reshape(N * B, -1)
        )
        Tf = Tf.reshape(N, B, 4, 4)
        d = np.abs(Tf[..., :3, 3] - Ts[:, None, :3, 3]).max(-1)
        if not position_only:
            d = np.maximum(d, np.abs(Tf[..., :3, :3] - Ts[:, None, :3, :3]).max(axis=(-1, -2)))
        return np.where(finite, d, np.inf)
    model, data, fid = robot.model, robot.data, robot.tool_id
    res = np.empty((N, B))
    for i in range(N):
        Ti = Ts[i]
        for b in range(B):
            if not finite[i, b]:
                res[i, b] = np.inf
                continue
            pin.framesForwardKinematics(model, data, Qw[i, b])
            M = data.oMf[fid]
            e = np.abs(M.translation - Ti[:3, 3]).max()
            if not position_only:
                e = max(e, np.abs(M.rotation - Ti[:3, :3]).max())
            res[i, b] = e
    return res


def grid_labels(labels, S, what):
    return list(labels) if S == 1 else [f"{b},{what}#{k}" for k in range(S) for b in labels]


def empty(robot, labels, swivel=False):
    B = len(labels)
    return AnalyticBatchResult(
        np.zeros((0, B, robot.nq)),
        np.zeros((0, B), bool),
        labels,
        [],
        swivel=np.zeros((0, B)) if swivel else None,
        residuals=np.zeros((0, B)),
        model=robot.name,
    )


def finish(
    robot,
    s,
    Ts,
    th,
    cand,
    exact,
    inside,
    res,
    valid,
    labels,
    tol,
    position_only,
    swivel=None,
    conf=None,
    singular=None,
):
    """From the compiled solver's branches to the result: configurations (``conf``, where the
    compiled call made them), polish of near-exact candidates, duplicates, the rescue of poses
    whose candidates lie on a limit (where ``s.kind.rescues``), reasons.  ``singular``: None
    (never singular), or ``f(TH, valid, rows)`` giving the :attr:`AnalyticIKResult.singular`
    texts of the poses ``rows`` from the joint angles ``TH`` (N, B, n) and ``valid`` (N, B),
    called on first use."""
    N, B = cand.shape
    ch = robot.chain
    Q = (
        th if s.plain else conf if conf is not None else ch.configuration(th)
    )  # NaN below where no solution
    res = np.array(res, dtype=float)
    # near-exact candidates inside the limits: the exact ones always; a subproblem's
    # least-squares root (flagged inexact) only on a pose with no exact candidate within tol —
    # at a singular pose it is within √ε of a solution, which the polish finds, but on a pose
    # with solutions it is a near miss (a straight elbow's root ~1e-5 from a pose reached
    # elsewhere: 11 of 10 000 random ur5 poses, 25 ms each, never a new solution)
    near = cand & inside & (res > tol) & (res <= POLISH_MAX)
    near &= exact | ~(cand & inside & (res <= tol)).any(1, keepdims=True)
    polished = bool(near.any()) and s.plain
    if polished:
        Q = np.array(Q)
        for i, b in zip(*np.nonzero(near)):
            Q[i, b], res[i, b] = refine(
                robot, Q[i, b], Ts[i], robot.lower, robot.upper, position_only
            )
    if valid is None or polished:
        valid = _geo.mark_solutions(Q if polished else th, cand, inside, res, tol, s.form.branches)
    else:
        valid = np.array(valid)
    none = ~valid.any(1)  # poses without a solution
    if s.kind.rescues and s.plain and none.any():
        Q = _rescue_poses(robot, Q, none, cand, exact, inside, res, valid, Ts, tol, position_only)
    reasons = [None] * N
    for i in np.flatnonzero(~valid.any(1)) if none.any() else ():
        reasons[i] = reason(
            robot, s, Ts[i], cand[i], exact[i], inside[i], res[i], tol, position_only
        )
    # polished: a plain arm, Q = θ
    singular_of = (
        None if singular is None else functools.partial(singular, Q if polished else th, valid)
    )

    # Q and res are this call's own arrays (the compiled call's, or copies): NaN in place where
    # no solution (a new 8·n·N array would cost more than the rest of this function)
    _geo.blank_unsolved(Q, res, valid)
    return AnalyticBatchResult(
        solutions=Q,
        valid=valid,
        branches=labels,
        reasons=reasons,
        swivel=None if swivel is None else np.where(valid, swivel, np.nan),
        residuals=res,
        _singular_of=singular_of,
        model=robot.name,
    )


def _rescue_poses(robot, Q, none, cand, exact, inside, res, valid, Ts, tol, position_only):
    """:func:`.limits.rescue` of the poses without a solution (``none`` (N,)) that have exact or
    near-exact candidates outside the limits: ``Q`` (a copy where any is rescued) with their
    solutions, ``valid``, ``res`` and ``inside`` marked in place."""
    todo = np.flatnonzero(none & (cand & (exact | (res <= POLISH_MAX)) & ~inside).any(1))
    if todo.size:
        Q = np.array(Q)
        for i in todo:
            for b, q, r in rescue(
                robot,
                Q[i],
                cand[i] & (exact[i] | (res[i] <= POLISH_MAX)) & ~inside[i],
                Ts[i],
                tol,
                position_only,
            ):
                Q[i, b], valid[i, b], res[i, b], inside[i, b] = q, True, r, True
    return Q


#: an FK residual (m / unitless) up to which a pose without a solution is reported as a near miss
#: (rounding of the pose, not the workspace) by :func:`reason`
NEAR_MISS = 1e-6


def reason(robot, s, T, cand, exact, inside, res, tol, position_only) -> str:
    """Why pose ``T`` has no solution, from its branches' flags."""
    fam = s.form.family
    outside = s.kind.outside(s.plan, T, tol)
    if outside is not None:
        return outside
    if not (cand & exact).any():
        best = float(np.min(res)) if np.isfinite(res).any() else float("inf")
        if best <= NEAR_MISS:
            return (
                f"not reached to tol = {tol:g}: the best candidate leaves an FK residual of {best:.3g} "
                "(the pose is not a rigid transform to that precision — a single-precision pose, a rotation "
                "orthonormal only to ~1e-8 — or lies that close to the workspace boundary); pass a larger tol "
                "to accept it"
            )
        return (
            f"outside the workspace: no branch of the {fam} closed form reaches this pose (its "
            f"subproblems have least-squares answers only; best FK residual {best:.3g})"
        )
    if not (cand & exact & inside).any():
        ch = (
            robot.chain
        )  # limits of the joints solved for (θ, not q: a continuous joint is cos, sin in q)
        joints = [ch.joints[j] for j in ch.independent]
        return (
            f"all {int((cand & exact).sum())} closed-form solutions violate the joint limits ("
            + ", ".join(
                f"{j.name} continuous"
                if j.kind == "continuous"
                else f"{j.name} [{j.lower:.4g}, {j.upper:.4g}]"
                for j in joints
            )
            + ")"
        )
    worst = float(np.min(np.where(cand & exact & inside, res, np.inf)))
    text = (
        f"no candidate passed the FK check (best residual {worst:.3g} > tol {tol:g}); the pose is at a "
        "singularity or not reachable with this orientation"
    )
    text += s.kind.tolerance_note(s.plan)
    return text
