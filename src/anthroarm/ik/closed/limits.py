"""Solutions on the joint limits: the rescue of a pose whose closed-form candidates lie on or just
beyond a limit (:func:`rescue`), and the polish of a near-solution inside the limits
(:func:`refine`).

At a singular configuration (a straight elbow, the shoulder or the wrist with two axes on one
line) the closed form returns one representative q of a one-parameter family of solutions
q_i += t, q_j −= s·t (s = ±1 where J[:, i] = s·J[:, j]); where that representative is outside
the limits, :func:`slide_into_limits` moves it along the family (the smallest |t|, with 2π
shifts).  :func:`refine` minimises ‖FK(q) − T‖ over the 3×4 entries (or the position) by bounded
least squares and finishes with Gauss–Newton steps δq = −J⁺e on an active set
(:func:`newton_on_limits`).  FK and Jacobians: Pinocchio, the calling thread's ``robot.data``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

TWO_PI = 2.0 * np.pi


#: how far (rad) a closed-form candidate may lie outside a joint limit and still be kept, clipped
#: onto the limit and polished (see :func:`rescue`).  The closed forms lose precision at
#: double roots and singular configurations — an arccos near ±1, a square root of a discriminant
#: near 0 — where a joint is determined by the pose only to ≈ √ε ≈ 1.5e-8 rad; a configuration with
#: a joint exactly on its limit then yields a candidate up to a few 1e-8 rad beyond it.  1e-6 rad
#: covers that with margin; every kept candidate still passes the FK check (``tol``).
LIMIT_SLACK = 1e-6


def rescue(robot, Q, which, T, tol, position_only):
    """Solutions of one pose (4×4) whose closed-form candidates ``Q[which]`` lie on or just
    beyond a limit.  Each is moved along its exact self-motions (:func:`slide_into_limits`: a
    straight elbow, the shoulder or the wrist at a singularity, where the closed form returns
    one representative of a one-parameter family) and, if it is then within
    :data:`LIMIT_SLACK` of the limits, clipped onto them and polished (the candidates at such
    poses carry ≈ √ε errors).  Kept if it passes the FK check ``tol``.  Returns
    ``[(branch, q, residual)]``."""
    lo, hi = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
    rows = slice(0, 3) if position_only else slice(None)
    out = []
    for b in np.flatnonzero(which):
        J = np.asarray(robot.jacobian(Q[b]))
        revolute = np.abs(J[3:]).max(0) > 0.0  # a prismatic joint turns nothing
        q = slide_into_limits(turns_into_limits(Q[b], revolute, lo, hi), J[rows], lo, hi)
        if q is None:
            continue
        q, res = refine(robot, np.clip(q, lo, hi), T, lo, hi, position_only, polish=False)
        if res > 1e-6:  # not a near-solution: skip the polish
            continue
        q, res = refine(robot, q, T, lo, hi, position_only)
        if res <= tol and all(np.abs(q - k[1]).max() >= 1e-9 for k in out):
            out.append((int(b), q, res))
    return out


def turns_into_limits(q, revolute, lo, hi):
    """``q`` with each revolute joint turned by the multiple of 2π that brings it nearest its
    limits (a copy).  A joint on a limit comes out of the closed form as often at the limit
    ± 2π, which the exact wrap of the compiled call puts an ulp outside (−π/2 as 3π/2 − 2π)."""
    q = np.array(q, dtype=float)
    x = q[:, None] + _TURNS  # (n, 5): each joint turned by -2..2 turns
    out = np.maximum(lo[:, None] - x, x - hi[:, None])
    best = x[np.arange(q.size), out.argmin(1)]  # the least outside (or most inside) of each
    return np.where(revolute & (out[:, 2] > 0.0), best, q)  # only joints outside move


_TURNS = TWO_PI * np.arange(-2.0, 3.0)


def slide_into_limits(q, J, lo, hi):
    """Move ``q`` along its exact self-motions into the limits, or return None.

    Two revolute joints i, j whose axes are the same line at ``q`` (columns J[:, i] = s·J[:, j]
    of the tool Jacobian, s = ±1: the shoulder at θ2 = 0/π, a straight elbow, a wrist at
    sin θ5 = 0) leave the tool pose unchanged under q_i += t, q_j −= s·t for every t (the links
    between them turn about the common axis, which that turn maps onto itself).  The smallest |t|
    (with 2π shifts of either joint) that brings both inside their limits is chosen."""
    q = q.copy()
    nq = q.size
    scale = max(float(np.abs(J).max()), 1e-300)

    def outside(v):
        return float(np.maximum(lo - v, v - hi).clip(0.0).max())

    for _ in range(2):  # at most two families (shoulder and elbow) at once
        if outside(q) <= LIMIT_SLACK:
            return q
        moved = False
        for i in range(nq):
            for j in range(i + 1, nq):
                bad_ij = max(lo[i] - q[i], q[i] - hi[i], lo[j] - q[j], q[j] - hi[j]) > LIMIT_SLACK
                if not bad_ij:
                    continue
                for s in (1.0, -1.0):
                    if np.abs(J[:, i] - s * J[:, j]).max() > 1e-6 * scale:
                        continue
                    best = None
                    for ki in (-1, 0, 1):
                        for kj in (-1, 0, 1):
                            a, b = lo[i] + TWO_PI * ki - q[i], hi[i] + TWO_PI * ki - q[i]
                            c, d = q[j] - hi[j] - TWO_PI * kj, q[j] - lo[j] - TWO_PI * kj
                            if s < 0:
                                c, d = -d, -c
                            a, b = max(a, c), min(b, d)
                            if a <= b:
                                t = min(max(0.0, a), b)
                                if best is None or abs(t) < abs(best[0]):
                                    best = (t, ki, kj)
                    if best is not None:
                        t, ki, kj = best
                        q[i] += t - TWO_PI * ki
                        q[j] -= s * t + TWO_PI * kj
                        moved = True
                        break
        if not moved:
            break
    return q if outside(q) <= LIMIT_SLACK else None


def refine(robot, q, T, lo, hi, position_only, polish=True):
    """(q, max |FK(q) − T| over the 3×4 entries or the position) after polishing ``q`` inside
    the limits by bounded least squares on the FK error (scipy's trust-region reflective
    method, which copes with the rank-deficient Jacobian at the singular poses where the closed
    forms lose precision).  FK: Pinocchio, ``robot.data`` of the calling thread."""
    model, data, fid = robot.model, robot.data, robot.tool_id
    Rt, pt = T[:3, :3], T[:3, 3]

    def err(x):
        pin.framesForwardKinematics(model, data, x)
        M = data.oMf[fid]
        e = M.translation - pt
        return e if position_only else np.concatenate([e, (M.rotation - Rt).ravel()])

    if polish and bool((hi > lo).all()):
        # scipy.optimize is imported here, not at the top: ~1 s of import time that only a pose
        # with a candidate to polish pays (most calls never do)
        from scipy.optimize import least_squares

        sol = least_squares(
            err, q, bounds=(lo, hi), method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=60
        )
        if np.isfinite(sol.x).all():
            q = np.clip(sol.x, lo, hi)
        # the reflective method creeps towards a solution that lies on a bound (each step halves
        # the distance) and its finite-difference Jacobian stops it near 1e-9: finish with
        # Newton steps on Pinocchio's Jacobian, joints that would cross a limit held on it
        qn = newton_on_limits(model, data, fid, q, T, lo, hi, position_only)
        if float(np.abs(err(qn)).max()) < float(np.abs(err(q)).max()):
            q = qn
    return q, float(np.abs(err(q)).max())


def newton_on_limits(model, data, fid, q, T, lo, hi, position_only, iters: int = 40):
    """Gauss–Newton steps δq = −J⁺ e on the pose error e = (p − p*, log₃(R R*ᵀ)) (world frame;
    J: Pinocchio's frame Jacobian, LOCAL_WORLD_ALIGNED, rows of the position only where
    ``position_only``), with an active set: a joint whose step would leave [lo, hi] is put on
    that limit and held there for the following steps.  Quadratic convergence where the
    solution lies on a limit, which the bounded least squares above only approaches; linear (the
    error halves a step) at a singular configuration on a limit, hence up to ``iters`` steps."""
    x = np.clip(np.array(q, dtype=float), lo, hi)
    if model.nq != model.nv:  # continuous joints: q holds (cos, sin), steps are in v
        return x
    free = np.ones(x.size, dtype=bool)
    rows = slice(0, 3) if position_only else slice(0, 6)
    Rt, pt = T[:3, :3], T[:3, 3]
    for _ in range(iters):
        J = pin.computeFrameJacobian(model, data, x, fid, pin.LOCAL_WORLD_ALIGNED)[rows]
        M = pin.updateFramePlacement(model, data, fid)  # after the Jacobian computed the joints
        e = np.concatenate([M.translation - pt, pin.log3(M.rotation @ Rt.T)])[rows]
        if float(np.abs(e).max()) < 1e-15 or not free.any():
            break
        while True:
            dq = np.zeros(x.size)
            dq[free] = -np.linalg.lstsq(J[:, free], e, rcond=1e-10)[0]
            xn = x + dq
            out = free & ((xn < lo) | (xn > hi))
            if not out.any():
                break
            x[out] = np.clip(xn[out], lo[out], hi[out])  # onto the limit it would cross
            free &= ~out
            if not free.any():
                break
        if not np.isfinite(xn).all():
            break
        x = np.clip(xn, lo, hi)
    return x
