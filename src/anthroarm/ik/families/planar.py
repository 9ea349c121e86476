"""The planar 2R arm, position only: q2 by SP3, q1 by SP1, compiled; the batch driver
:func:`planar_verified`."""

from __future__ import annotations

import math

import numpy as np

from ...jit import borrow, kernel, local, local2, local_flags, part, part2
from ..fk import WIDTH, chain_pose
from ..geometric.fk import POLISH_MAX
from ..geometric.limits import into_limits
from ..geometric.verify import _mark_solutions, _pose_status
from ..subproblems.base import TOL
from ..subproblems.circle import sp1_one, sp3_one
from ..vec3 import dot, norm, rotate, sub, vec, wrap
from .plans import PlanarPlan


# ----------------------------------------------------------------------------- planar 2R
@kernel
def _fk_position_residual(A, q, p):
    """max |F(q) p_tool − p| over the 3 position entries: the tool point of the chain's FK
    (:func:`anthroarm.ik.fk.chain_pose` of ``PlanarPlan.fk_frames``, base frame, m)."""
    _, x = chain_pose(A, q)
    return max(abs(x[0] - p[0]), max(abs(x[1] - p[1]), abs(x[2] - p[2])))


@kernel(inline=True)
def _planar_unpack(cf):
    """The constants of ``PlanarPlan.packed``: (h1, h2, o1, o2, p_tool (3-tuples), the FK
    check's frames (3, 16), lo, hi (2,)) — views of ``cf``, compiled into each caller."""
    return (
        vec(cf[0:3]),
        vec(cf[3:6]),
        vec(cf[6:9]),
        vec(cf[9:12]),
        vec(cf[12:15]),
        part2(cf, 15, 3, WIDTH),
        part(cf, 15 + 3 * WIDTH, 2),
        part(cf, 17 + 3 * WIDTH, 2),
    )


@kernel(inline=True)
def _planar_pose(plan, p, tol, Q, V, E, IN, RES, OK, q):
    """Both branches of one target ``p`` (3-tuple, finite): Q (2, 2) path order, V, E, IN, RES
    (position), OK (the solutions, :func:`.geometric._mark_solutions`); ``plan``:
    :func:`_planar_unpack`; ``q`` (2,) scratch."""
    h1, h2, o1, o2, pt, A, lo, hi = plan
    p1, p2 = sub(pt, o2), sub(o1, o2)
    for b in range(2):
        Q[b, 0], Q[b, 1] = math.nan, math.nan
        V[b], E[b], IN[b], RES[b] = False, False, False, math.inf
    if abs(dot(h1, sub(p, pt))) <= tol:  # else off the plane of motion: no candidate
        po = sub(p, o1)
        ta, tb, cnt, ea, eb, _ = sp3_one(p1, p2, h2, norm(po), TOL)
        for b in range(cnt):
            q2 = ta if b == 0 else tb
            q1, e1, _ = sp1_one(sub(rotate(h2, q2, p1), p2), po, h1, TOL)
            q[0], q[1] = wrap(q1), wrap(q2)
            inside = into_limits(q, 2, lo, hi)
            Q[b, 0], Q[b, 1] = q[0], q[1]
            V[b], E[b], IN[b] = True, (ea if b == 0 else eb) and e1, inside
            RES[b] = _fk_position_residual(A, q, p)
    _mark_solutions(Q, V, IN, RES, tol, 2, OK)


@kernel
def _planar_verified(cf, P, tol, Q, V, E, IN, RES, OK):
    """Both branches of targets P (N, 3) (:func:`_planar_pose` of each): Q (N, 2, 2) path
    order, V, E, IN, RES, OK (N, 2); returns the index of the first non-finite target (−1 if
    none).  ``cf``: ``PlanarPlan.packed``."""
    plan = _planar_unpack(cf)
    q = local(2)
    for i in range(len(P)):
        for j in range(3):
            if not math.isfinite(P[i, j]):
                return i
        _planar_pose(
            plan, (P[i, 0], P[i, 1], P[i, 2]), tol, Q[i], V[i], E[i], IN[i], RES[i], OK[i], q
        )
    return -1


@kernel
def planar_pose_solutions(cf, ci, T, angle, tol, tol_orthonormal, out):
    """One pose T (4, 4) of a planar 2R arm, position only (its rotation is not compared; every
    entry finite and its last row [0, 0, 0, 1], :func:`.geometric._pose_status`): the solutions
    into the rows of ``out`` (2, 4) — θ in independent-joint order (``ci``: ``order``), the FK
    residual, the branch — and the bit mask of their branches returned (≤ 0: none, a malformed
    pose or a candidate to polish — the general path answers).  ``angle`` and
    ``tol_orthonormal`` are not read (the signature of :func:`.geometric.pose_solutions`).
    ``cf``, ``ci``: ``PlanarPlan.packed``, passed on borrowed (``anthroarm.jit.borrow``)."""
    cf, ci, T, out = borrow(cf), borrow(ci), borrow(T), borrow(out)
    if 0 < _pose_status(T, math.inf) < 3:  # not finite, or not its last row (the rotation: unread)
        return -1
    Q, RES, q = local2(2, 2), local(2), local(2)
    V, E, IN, OK = local_flags(2), local_flags(2), local_flags(2), local_flags(2)
    _planar_pose(_planar_unpack(cf), (T[0, 3], T[1, 3], T[2, 3]), tol, Q, V, E, IN, RES, OK, q)
    K, mask = 0, 0
    for b in range(2):
        if V[b] and E[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
            return -2
        if OK[b]:
            out[K, 0], out[K, 1] = Q[b, ci[0]], Q[b, ci[1]]
            out[K, 2], out[K, 3] = RES[b], b
            K += 1
            mask |= 1 << b
    return mask


def planar_verified(plan: PlanarPlan, P, tol: float = 1e-9):
    """Both elbow branches of the planar 2R arm of ``plan`` for tool positions ``P`` (N, 3)
    (base frame, m), position only, in one compiled call.  Returns θ (N, 2, 2) in
    ``robot.chain.independent`` order (rad, wrapped into the limits), candidate (N, 2), exact
    (N, 2), inside (N, 2), FK residual (N, 2) (max |error| of the 3 position entries; inf
    without a candidate), solution (N, 2) (residual ≤ ``tol``, inside, not a duplicate of
    the other branch).  A target farther than ``tol`` (m) from the plane of motion has no
    candidate.  Raises ``ValueError`` naming the first non-finite target."""
    P = np.ascontiguousarray(P, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3:
        raise ValueError(f"P must have shape (N, 3), got {P.shape}")
    N = len(P)
    Q, V, E = np.empty((N, 2, 2)), np.empty((N, 2), bool), np.empty((N, 2), bool)
    IN, RES, OK = np.empty((N, 2), bool), np.empty((N, 2)), np.empty((N, 2), bool)
    bad = _planar_verified(plan.packed[0], P, float(tol), Q, V, E, IN, RES, OK)
    if bad >= 0:
        raise ValueError(f"P[{bad}] is not a finite position")
    return (Q if plan.in_order else Q[..., plan.order]), V, E, IN, RES, OK
