"""One compiled call from a pose to its verified branches: the pose check, the class solver, the
2π shift into the limits, the FK check and polish, the removal of duplicates and the chain's
configuration of each solution — for a batch (:func:`_verified`) and for one pose
(:func:`_verified_one`, :func:`pose_solutions`)."""

from __future__ import annotations

import math

import numpy as np

from ...chain_kernels import put_joint
from ...jit import borrow, kernel, local, local2, local_flags, view2
from ..vec3 import (
    add,
    angle_cs,
    cross,
    dot,
    mat,
    mm,
    mtm,
    mtv,
    mv,
    neg,
    rot_cs,
    rows6,
    rows7,
    sub,
    transpose,
    vec,
    wrap,
)
from .closed import BRANCH_ROW, COS, EXACT, EXISTS, SIN, _solve_closed
from .fk import POLISH_MAX, _fk_residuals, _polish_chain, _target_errors
from .limits import into_limit_rows
from .plan import _unpack


@kernel
def _pose_status(T, tol_orthonormal):
    """0: a valid pose; 1: not finite; 2: last row not [0, 0, 0, 1]; 3: not a rotation."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return 1
    if (
        abs(T[3, 0]) > 1e-12
        or abs(T[3, 1]) > 1e-12
        or abs(T[3, 2]) > 1e-12
        or abs(T[3, 3] - 1.0) > 1e-12
    ):
        return 2
    R = mat(T)
    RtR = mtm(R, R)
    for i in range(3):
        for j in range(3):
            if abs(RtR[i][j] - (1.0 if i == j else 0.0)) > tol_orthonormal:
                return 3
    if dot(transpose(R)[0], cross(transpose(R)[1], transpose(R)[2])) < 0.0:
        return 3
    return 0


@kernel
def _verified(cf, ci, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF):
    """Every branch of poses T (N, 4, 4) (:func:`_verify_pose` of each, ``param`` (N,) the held
    7th joint): writes Q (N, 8, n), V, E, IN, RES, OK (N, 8) and, unless its last axis is
    empty, CONF (N, 8, nq).  Returns the index of the first malformed pose (−1 if none).
    ``cf``, ``ci``: :attr:`GeoPlan.packed`.  Compiled without reference counts
    (:func:`anthroarm.jit.kernel`): its scratch is local (n ≤ 7 joints)."""
    plan = _pose_plan(cf, ci)
    n = plan[2]
    B6 = local2(8, BRANCH_ROW)
    q = local(7)
    QC, QS = view2(local(56), 8, n), view2(local(56), 8, n)
    S = view2(local(96), n + 1, 12)
    J, W, F = local2(6, 7), local2(7, 6), local(6)
    CHK = local_flags(8)
    for i in range(len(T)):
        if not _verify_pose(
            plan,
            T[i],
            param[i],
            tol,
            tol_orthonormal,
            Q[i],
            V[i],
            E[i],
            IN[i],
            RES[i],
            OK[i],
            CONF[i],
            (B6, q, QC, QS, S, J, W, F, CHK),
        ):
            return i
    return -1


@kernel(inline=True)
def _pose_plan(cf, ci):
    """The constants :func:`_verify_pose` takes, from :attr:`GeoPlan.packed` (:func:`_unpack`,
    its vectors and matrices as tuples, :mod:`.vec3`; the tool pose at q = 0 as (MR, Mp)):
    (class index, reversed, n, h, P, R_tool, MR, Mp, the held joint's axis and point, A, lo,
    hi, order, index).  Compiled into each caller."""
    cls, rev, n, H, P, R_tool, p_axis, p_point, M, A, lo, hi, order, index = _unpack(cf, ci)
    return (
        cls,
        rev,
        n,
        rows6(H),
        rows7(P),
        mat(R_tool),
        mat(M[:3, :3]),
        vec(M[:3, 3]),
        p_axis,
        p_point,
        A,
        lo,
        hi,
        order,
        index,
    )


@kernel(inline=True)
def held_pose(R, p, MR, Mp, axis, point, c, s):
    """The pose (R, p) of the first six joints' tool for the tool pose T = (R, p) of a 7-joint
    arm whose last joint (twist ξ7: unit ``axis`` through ``point``, base frame at q = 0) is
    held at v (``c``, ``s`` = cos v, sin v), with M = (MR, Mp) the tool pose at q = 0: from
    T = F6(q1…q6) e^{ξ7 v} M, the first six joints reach T · M⁻¹ e^{−ξ7 v} M (the 6R arm with
    tool M).  e^{−ξ7 v} = (Rv, point − Rv·point) with Rv = rot(axis, −v), so
    M⁻¹ e^{−ξ7 v} M = (MRᵀ Rv MR, MRᵀ (Rv Mp + point − Rv point − Mp)).  Tuples
    (:mod:`anthroarm.ik.vec3`); the one source of this transform (:func:`held_poses` for a
    batch)."""
    Rv = rot_cs(axis, c, -s)
    X = mtm(MR, mm(Rv, MR))
    x = mtv(MR, sub(add(mv(Rv, Mp), sub(point, mv(Rv, point))), Mp))
    return mm(R, X), add(mv(R, x), p)


@kernel
def held_poses(T, M, axis, point, v, out):
    """:func:`held_pose` of each tool pose T (N, 4, 4) with its held last joint at v (N,) rad,
    into ``out`` (N, 4, 4); M (4, 4) the tool pose at q = 0, ``axis``, ``point`` (3,)."""
    MR, Mp, a, pt = mat(M), (M[0, 3], M[1, 3], M[2, 3]), vec(axis), vec(point)
    for i in range(T.shape[0]):
        cs = angle_cs(v[i])
        Ti = T[i]
        R, p = held_pose(mat(Ti), (Ti[0, 3], Ti[1, 3], Ti[2, 3]), MR, Mp, a, pt, cs[0], cs[1])
        for r in range(3):
            for k in range(3):
                out[i, r, k] = R[r][k]
            out[i, r, 3] = p[r]
            out[i, 3, r] = 0.0
        out[i, 3, 3] = 1.0


@kernel(inline=True)
def _verify_pose(plan, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF, scratch):
    """Every branch of one pose T (4, 4) in path order, wrapped into the limits and FK-checked:
    writes Q (8, n) rad, V (candidate exists), E (exact), IN (inside the limits), RES (FK
    residual; inf where there is no candidate, and for an exact candidate outside the limits,
    which is never returned and so not checked), OK (a solution: candidate, inside, residual
    ≤ tol, and not within 1e-9 rad of an earlier solution of its pose); a candidate inside the
    limits with tol < residual ≤ :data:`POLISH_MAX` is polished (:func:`_polish_chain`) and
    kept polished where that brings it within tol.  ``CONF`` (8, nq), unless its last axis is
    empty: the chain's configuration q of each solution (:func:`_configurations`).  ``param``
    the held 7th joint (rad).  Returns False for a malformed pose (:func:`_pose_status`).
    ``plan``: :func:`_pose_plan`; ``scratch``: B6 (8, :data:`BRANCH_ROW`), q (7,), QC, QS
    (8, n), S (n + 1, 12), J (6, 7), W (7, 6), F (6,), CHK (8,).  Compiled into each caller
    (:func:`_verified`, :func:`_verified_one`)."""
    cls, rev, n, h, PP, Rt, MR, Mp, p_axis, p_point, A, lo, hi, order, index = plan
    B6, q, QC, QS, S, J, W, F, CHK = scratch
    if _pose_status(T, tol_orthonormal) != 0:
        return False
    R, p = mat(T), (T[0, 3], T[1, 3], T[2, 3])
    t7, a7 = 0.0, (1.0, 0.0)
    if n == 7:
        t7 = wrap(param)
        a7 = angle_cs(t7)
        R, p = held_pose(R, p, MR, Mp, p_axis, p_point, a7[0], a7[1])
    if rev:
        p = neg(mtv(R, p))
        R = transpose(R)
    _solve_closed(cls, h, PP, mm(R, transpose(Rt)), p, B6)
    for b in range(8):
        V[b], E[b] = B6[b, EXISTS] != 0.0, B6[b, EXACT] != 0.0
        for j in range(n):
            jj = 5 - j if rev else j  # a reversed chain's joints come last first
            x = (B6[b, jj], B6[b, COS + jj], B6[b, SIN + jj]) if j < 6 else (t7, a7[0], a7[1])
            Q[b, j], QC[b, j], QS[b, j] = x
    into_limit_rows(Q, QC, QS, V, E, n, lo, hi, IN, CHK)
    _fk_residuals(A, Q, QC, QS, CHK, n, T, RES, S)
    for b in range(8):
        if V[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
            for j in range(n):
                q[j] = Q[b, j]
            r = _polish_chain(A, q, n, T, lo, hi, tol, J, W, F)
            if r <= tol:
                for j in range(n):
                    Q[b, j], QC[b, j], QS[b, j] = q[j], math.cos(q[j]), math.sin(q[j])
                RES[b] = r
    _mark_solutions(Q, V, IN, RES, tol, 8, OK)
    if CONF.shape[1] > 0:
        _configurations(order, index, n, Q, QC, QS, OK, CONF)
    return True


@kernel
def _configurations(order, index, n, Q, QC, QS, OK, CONF):
    """The chain's configuration q (:func:`anthroarm.chain_kernels.put_joint`) of each solution
    b (``OK[b]``) of θ Q (8, n) (path order) with its cosines QC and sines QS into CONF (8, nq)
    (NaN rows elsewhere); ``order``, ``index``: :func:`_unpack`'s."""
    for b in range(8):
        if not OK[b]:
            for j in range(CONF.shape[1]):
                CONF[b, j] = math.nan
            continue
        for k in range(n):
            j = order[k]
            put_joint(CONF[b], index[k, 0], index[k, 1] != 0, Q[b, j], QC[b, j], QS[b, j])


@kernel
def _mark_solutions(Q, V, IN, RES, tol, group, OK):
    """The solutions among the branches of one pose (Q (B, n), flags (B,)): a candidate inside
    the limits with FK residual ≤ ``tol``, not within 1e-9 rad of an earlier solution of its
    group (``group`` consecutive branches: one swivel angle or held-joint value) — coincident
    branches at singular poses.  Writes OK (B,)."""
    for b in range(len(V)):
        ok = V[b] and IN[b] and RES[b] <= tol
        a = b - b % group
        while ok and a < b:
            if OK[a]:
                ok = False  # a duplicate of a unless some joint differs
                for j in range(Q.shape[1]):
                    d = abs(
                        Q[b, j] - Q[a, j]
                    )  # differs by 1e-9 rad, and (below a turn: no wrap) as a rotation
                    if d >= 1e-9 and (d <= 2.0 * math.pi - 1e-9 or abs(wrap(d)) >= 1e-9):
                        ok = True
                        break
            a += 1
        OK[b] = ok


@kernel
def _mark_loop(Q, V, IN, RES, tol, group, OK):
    for i in range(len(V)):
        _mark_solutions(Q[i], V[i], IN[i], RES[i], tol, group, OK[i])


@kernel
def blank_unsolved(Q, RES, valid):
    """NaN in place in the rows of Q (N, B, n) and entries of RES (N, B) where not ``valid``
    (N, B): the batch result's "no solution on this branch" (a boolean-mask assignment costs
    several times this loop)."""
    for i in range(Q.shape[0]):
        for b in range(Q.shape[1]):
            if not valid[i, b]:
                RES[i, b] = math.nan
                for j in range(Q.shape[2]):
                    Q[i, b, j] = math.nan


def mark_solutions(Q, V, IN, RES, tol: float, group: int) -> np.ndarray:
    """The solutions (N, B) among candidate branches Q (N, B, n) rad with flags V (candidate),
    IN (inside the limits) and FK residuals RES (N, B): residual ≤ ``tol``, duplicates within
    1e-9 rad inside each ``group`` of consecutive branches dropped (compiled)."""
    OK = np.empty(V.shape, bool)
    _mark_loop(
        np.ascontiguousarray(Q, dtype=float),
        np.ascontiguousarray(V),
        np.ascontiguousarray(IN),
        np.ascontiguousarray(RES, dtype=float),
        float(tol),
        int(group),
        OK,
    )
    return OK


@kernel
def nearest_first(out, K, n, ref, width):
    """Swap the row of ``out[:K]`` whose first ``n`` entries (θ, rad) are nearest ``ref`` (n,)
    (Euclidean) into row 0, columns ``:width`` (the one-pose kernels' solutions first)."""
    best, kb = math.inf, 0
    for k in range(K):
        d = 0.0
        for j in range(n):
            d += (out[k, j] - ref[j]) ** 2
        if d < best:
            best, kb = d, k
    for j in range(width):
        out[0, j], out[kb, j] = out[kb, j], out[0, j]


@kernel
def _verified_one(cf, ci, T, param, tol, tol_orthonormal, ref, out):
    """One pose: the solutions (in the order of the branches) into the rows of ``out`` (8, w + 4):
    θ in independent-joint order (w = n joints) or the chain's configuration q (w = nq ≠ n: a
    continuous joint as (cos, sin), :func:`_configurations`), then the FK residual, the branch
    index; with a reference ``ref`` (n,) (θ, rad; an empty array: none; θ output only) the
    solution nearest it (Euclidean in θ) is swapped into the first row, and that row's last two
    columns hold its position and rotation errors (:func:`_target_errors`, m and rad).  Returns
    the set of branches that are solutions as a bit mask (bit b: branch b; their number K is
    its count of ones, > 0); −1: a malformed pose; −2: no solution, or a candidate to polish
    (the caller's general path answers: reasons, polishing).  One :func:`_verify_pose`, its
    scratch local."""
    plan = _pose_plan(cf, ci)
    n, w, A, order = plan[2], out.shape[1] - 4, plan[10], plan[13]
    Q, RES = view2(local(56), 8, n), local(8)
    V, E, IN, OK = local_flags(8), local_flags(8), local_flags(8), local_flags(8)
    CONF = view2(local(112), 8, w if w != n else 0)
    QC, QS = view2(local(56), 8, n), view2(local(56), 8, n)
    scratch = (
        local2(8, BRANCH_ROW),
        local(7),
        QC,
        QS,
        view2(local(96), n + 1, 12),
        local2(6, 7),
        local2(7, 6),
        local(6),
        local_flags(8),
    )
    if not _verify_pose(plan, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF, scratch):
        return -1
    K, mask = 0, 0
    for b in range(8):
        if V[b] and E[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
            return -2
        if OK[b]:
            if w != n:
                for k in range(w):
                    out[K, k] = CONF[b, k]
            else:
                for k in range(n):
                    out[K, k] = Q[b, order[k]]
            out[K, w], out[K, w + 1] = RES[b], b
            K += 1
            mask |= 1 << b
    if K == 0:
        return -2
    if len(ref) == n and w == n:
        nearest_first(out, K, n, ref, n + 2)
        out[0, n + 2], out[0, n + 3] = _target_errors(A, Q[int(out[0, n + 1])], T)
    return mask


@kernel
def pose_solutions(cf, ci, T, param, tol, tol_orthonormal, out):
    """:func:`_verified_one` of one pose without a reference: the solutions into the rows of
    ``out`` (8, w + 4), the bit mask of their branches returned (≤ 0: the general path
    answers).  What :func:`anthroarm.ik.closed_form.analytic` calls for one pose of a closed
    class (:func:`anthroarm.jit.entry_point`).  Its arrays are passed on borrowed
    (``anthroarm.jit.borrow``: no reference counts taken and given back below it)."""
    cf, ci, T, out = borrow(cf), borrow(ci), borrow(T), borrow(out)
    return _verified_one(cf, ci, T, param, tol, tol_orthonormal, local(1)[:0], out)


NO_REF = np.zeros(0)  # "no reference" of the one-pose kernels (an empty array)


class BadPoseError(ValueError):
    """A pose of a batch is not a rigid transform (not finite, last row, rotation part);
    ``index`` is the first such pose."""

    def __init__(self, index: int, message: str):
        super().__init__(message)
        self.index = index
