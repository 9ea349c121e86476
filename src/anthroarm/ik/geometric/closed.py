"""The closed IK-Geo classes (:data:`CLOSED`): one compiled kernel per class and pose, built from
the subproblem kernels of :mod:`anthroarm.ik.subproblems` (the decompositions of the table in
:mod:`anthroarm.ik.geometric`), and the spherical wrist they share."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel, local, local2
from .. import classify as C
from ..subproblems.base import TOL, TOL_QUARTIC
from ..subproblems.circle import sp1_cs, sp2_cs, sp3_cs, sp4_cs
from ..subproblems.quartic import sp5_one, sp6_one
from ..vec3 import (
    add,
    angle_cs,
    atan2,
    dot,
    mat,
    mtm,
    mtv,
    mv,
    neg,
    norm,
    perpendicular,
    rot_cs,
    rotate_cs,
    rows6,
    rows7,
    sub,
    vec,
)

# ----------------------------------------------------------------------------- the closed classes
# One compiled kernel per class and pose (:mod:`anthroarm.jit`), built from the subproblem
# kernels of :mod:`.subproblems`; vectors are tuples (:mod:`.vec3`).  Each writes its 8
# branches into the rows of B (8, :data:`BRANCH_ROW`): the six angles (rad), their cosines
# (from column :data:`COS`) and sines (:data:`SIN`), whether the branch exists (:data:`EXISTS`,
# 1.0 / 0.0) and whether every subproblem on it was exact (:data:`EXACT`) — one array, so a
# call passes one reference, not five — in the order of the labels: the first branching
# subproblem outermost, the root index innermost.  A branch under a root that does not exist
# is left NaN / not existing.  An angle travels as its rotation, the pair a = (cos θ, sin θ):
# the subproblems give the rotation they find so (``sp*_cs``, :func:`.subproblems.unit_cs`),
# the rotations that follow and the FK check of :func:`_verified` evaluate no trigonometry,
# and the angles themselves are read at the end, in one vectorised loop (:func:`_angles`).
COS, SIN, EXISTS, EXACT, BRANCH_ROW = 6, 12, 18, 19, 20


@kernel
def _none(B, b0, b1):
    """Branches b0 … b1 − 1 do not exist (their root does not)."""
    for b in range(b0, b1):
        B[b, EXISTS] = 0.0


@kernel
def _put(B, b, a1, a2, a3, a4, a5, a6, v, e):
    """Branch b: its six rotations (pairs (cos θ, sin θ)) and its flags; the angles are read
    from them at the end (:func:`_angles`)."""
    row = (a1, a2, a3, a4, a5, a6)
    for j in range(6):
        B[b, COS + j], B[b, SIN + j] = row[j]
    B[b, EXISTS], B[b, EXACT] = 1.0 if v else 0.0, 1.0 if e else 0.0


@kernel
def _angles(B):
    """The six angles of every branch row of B read from their cosines and sines,
    θ = atan2(sin, cos) ∈ (−π, π] (:func:`.vec3.atan2`): one loop of 48 independent atan2 on
    contiguous scratch, which the compiler vectorises — the subproblems hand on rotations, and
    an angle is only read once its branch is complete."""
    C, S, A = local(48), local(48), local(48)
    for b in range(8):
        for j in range(6):
            C[6 * b + j], S[6 * b + j] = B[b, COS + j], B[b, SIN + j]
    for k in range(48):
        A[k] = atan2(S[k], C[k])
    for b in range(8):
        for j in range(6):
            B[b, j] = A[6 * b + j]


@kernel
def _wrist(h, R03, R06, B, b, a1, a2, a3, ex):
    """Spherical wrist from R36 = R03ᵀ R06 (:func:`_wrist_of`); branches b (first q5 root) and
    b + 1.  a1, a2, a3: the rotations (cos, sin) of q1, q2, q3."""
    u, w = _wrist_reads(h, mtm(R03, R06))
    _wrist_of(h, u, w, B, b, a1, a2, a3, ex)


@kernel
def _wrist_reads(h, R):
    """(R h6, R x), x = :func:`.vec3.perpendicular` of h6: the two columns of a rotation R that
    :func:`_wrist_of` reads of R36 (R = R36, or R06 before it is turned back, :func:`_back3`)."""
    return mv(R, h[5]), mv(R, perpendicular(h[5]))


@kernel
def _back3(h, a1, a2, a3, v):
    """R03ᵀ v = rot(h3, −q3) rot(h2, −q2) rot(h1, −q1) v of the rotations (cos, sin) a1, a2, a3."""
    return rotate_cs(
        h[2], a3[0], -a3[1], rotate_cs(h[1], a2[0], -a2[1], rotate_cs(h[0], a1[0], -a1[1], v))
    )


@kernel
def _wrist_of(h, u, w, B, b, a1, a2, a3, ex):
    """Spherical wrist from u = R36 h6 and w = R36 x (x = :func:`.vec3.perpendicular` of h6; the
    two columns of R36 = R03ᵀ R06 it reads): q5 by SP4 (h4ᵀ R36 h6 = h4ᵀ rot(h5, q5) h6), q4
    and q6 by SP1; branches b (first q5 root) and b + 1.  a1, a2, a3: the rotations (cos, sin)
    of q1, q2, q3."""
    h4, h5, h6 = h[3], h[4], h[5]
    x = perpendicular(h6)
    ca, sa, cb, sb, cnt, ea, eb, _ = sp4_cs(h4, h6, h5, dot(h4, u), TOL)
    for j in range(2):
        if j >= cnt:
            B[b + j, EXISTS] = 0.0
            continue
        c, s = (ca, sa) if j == 0 else (cb, sb)
        # q4 (0 where it is free: h4 ∥ rot(h5, q5) h6, the wrist singularity), then q6 from
        # rot(h6, q6) = rot(h5, −q5) rot(h4, −q4) R36 applied to x ⟂ h6 (never singular)
        c4, s4, e4, _ = sp1_cs(rotate_cs(h5, c, s, h6), u, h4, TOL)
        c6, s6, e6, _ = sp1_cs(x, rotate_cs(h5, c, -s, rotate_cs(h4, c4, -s4, w)), h6, TOL)
        _put(
            B,
            b + j,
            a1,
            a2,
            a3,
            (c4, s4),
            (c, s),
            (c6, s6),
            True,
            ex and (ea if j == 0 else eb) and e4 and e6,
        )


@kernel
def _spherical_two_parallel(h, P, R06, p, B):
    """q1 SP4, q3 SP3, q2 SP1, the wrist (spherical wrist, axes 2 ∥ 3)."""
    wrist = sub(sub(p, mv(R06, P[6])), P[0])  # p_16 (wrist centre − p01)
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(
        h[1], wrist, neg(h[0]), dot(h[1], add(add(P[1], P[2]), P[3])), TOL
    )
    u0, w0 = _wrist_reads(h, R06)
    for i1 in range(2):
        if i1 >= n1:
            _none(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        v = sub(rotate_cs(neg(h[0]), a1[0], a1[1], wrist), P[1])  # R01ᵀ p_16 − p12
        u1, w1 = rotate_cs(h[0], a1[0], -a1[1], u0), rotate_cs(h[0], a1[0], -a1[1], w0)
        c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(neg(P[3]), P[2], h[2], norm(v), TOL)
        for i3 in range(2):
            b = 4 * i1 + 2 * i3
            if i3 >= n3:
                _none(B, b, b + 2)
                continue
            a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
            c2, s2, e2, _ = sp1_cs(add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), v, h[1], TOL)
            ex = (e1a if i1 == 0 else e1b) and (e3a if i3 == 0 else e3b) and e2
            u = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, u1))  # R03ᵀ R06 h6
            w = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, w1))
            _wrist_of(h, u, w, B, b, a1, (c2, s2), a3, ex)


@kernel
def _spherical_two_intersecting(h, P, R06, p, B):
    """q3 SP3, (q1, q2) SP2, the wrist (spherical wrist, axes 1 × 2)."""
    p16 = sub(sub(p, mv(R06, P[6])), P[0])  # from the 1–2 intersection
    u0, w0 = _wrist_reads(h, R06)
    c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(P[3], neg(P[2]), h[2], norm(p16), TOL)
    for i3 in range(2):
        if i3 >= n3:
            _none(B, 4 * i3, 4 * i3 + 4)
            continue
        a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
        c1a, s1a, c2a, s2a, c1b, s1b, c2b, s2b, n12, ea, eb, _ = sp2_cs(
            p16, add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), neg(h[0]), h[1], TOL
        )
        for j in range(2):
            b = 4 * i3 + 2 * j
            if j >= n12:
                _none(B, b, b + 2)
                continue
            a1, a2 = ((c1a, s1a), (c2a, s2a)) if j == 0 else ((c1b, s1b), (c2b, s2b))
            _wrist_of(
                h,
                _back3(h, a1, a2, a3, u0),
                _back3(h, a1, a2, a3, w0),
                B,
                b,
                a1,
                a2,
                a3,
                (e3a if i3 == 0 else e3b) and (ea if j == 0 else eb),
            )


@kernel
def _three_parallel_tail(h, P, R06, p06, a1, a5, ex, B, b):
    """Axes 2 ∥ 3 ∥ 4 with q1 and q5 known (rotations (cos, sin) a1, a5; branches b, b + 1 by
    the SP3 of q3): θ14 = q2 + q3 + q4 and q6 by SP1, q3 by SP3 (the planar elbow), q2 by SP1,
    q4 by difference.  h3, h4 may be −h2: rot(h3, q3) = rot(h2, ±q3)."""
    s3n = 1.0 if dot(h[1], h[2]) >= 0.0 else -1.0
    s4n = 1.0 if dot(h[1], h[3]) >= 0.0 else -1.0
    R01 = rot_cs(h[0], a1[0], a1[1])
    c5, s5 = a5
    # q6 (0 where it is free: h6 ∥ h2, the wrist aligned with the parallel axes), then θ14 from
    # rot(h2, θ14) = R01ᵀ R06 rot(h6, −q6) rot(h5, −q5) applied to x ⟂ h2 (never singular)
    c6, s6, e6, _ = sp1_cs(
        rotate_cs(neg(h[4]), c5, s5, h[1]), mtv(R06, mv(R01, h[1])), neg(h[5]), TOL
    )
    x = perpendicular(h[1])
    c14, s14, e14, _ = sp1_cs(
        x, mtv(R01, mv(R06, rotate_cs(h[5], c6, -s6, rotate_cs(h[4], c5, -s5, x)))), h[1], TOL
    )
    d_in = sub(
        sub(mtv(R01, p06), P[1]),
        rotate_cs(h[1], c14, s14, add(P[4], rotate_cs(h[4], c5, s5, P[5]))),
    )
    ca, sa, cb, sb, n3, ea, eb, _ = sp3_cs(neg(P[3]), P[2], h[1], norm(d_in), TOL)
    for j in range(2):
        if j >= n3:
            B[b + j, EXISTS] = 0.0
            continue
        c3, s3 = (ca, sa) if j == 0 else (cb, sb)
        c2, s2, e2, _ = sp1_cs(add(P[2], rotate_cs(h[1], c3, s3, P[3])), d_in, h[1], TOL)
        # q4 = θ14 − q2 − q3: its rotation is e^{iθ14} e^{−i(q2 + q3)}
        c23, s23 = c2 * c3 - s2 * s3, s2 * c3 + c2 * s3
        c4, s4 = c14 * c23 + s14 * s23, s14 * c23 - c14 * s23
        _put(
            B,
            b + j,
            a1,
            (c2, s2),
            (c3, s3n * s3),
            (c4, s4n * s4),
            a5,
            (c6, s6),
            True,
            ex and e14 and e6 and (ea if j == 0 else eb) and e2,
        )


@kernel
def _three_parallel_two_intersecting(h, P, R06, p, B):
    """2 ∥ 3 ∥ 4 and 5 × 6 (p56 = 0): q1 by SP4 (h2ᵀ R01ᵀ p16 = h2ᵀ (p12 + … + p45)), q5 by SP4
    (h2ᵀ R01ᵀ R06 h6 = h2ᵀ R45 h6), then :func:`_three_parallel_tail`."""
    p06 = sub(sub(p, mv(R06, P[6])), P[0])
    d1 = dot(h[1], add(add(add(P[1], P[2]), P[3]), P[4]))
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(h[1], p06, neg(h[0]), d1, TOL)
    R06h6 = mv(R06, h[5])
    for i1 in range(2):
        if i1 >= n1:
            _none(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        c5a, s5a, c5b, s5b, n5, e5a, e5b, _ = sp4_cs(
            h[1], h[5], h[4], dot(h[1], rotate_cs(neg(h[0]), a1[0], a1[1], R06h6)), TOL
        )
        for i5 in range(2):
            b = 4 * i1 + 2 * i5
            if i5 >= n5:
                _none(B, b, b + 2)
                continue
            _three_parallel_tail(
                h,
                P,
                R06,
                p06,
                a1,
                (c5a, s5a) if i5 == 0 else (c5b, s5b),
                (e1a if i1 == 0 else e1b) and (e5a if i5 == 0 else e5b),
                B,
                b,
            )


@kernel
def _three_parallel(h, P, R06, p, B):
    """2 ∥ 3 ∥ 4 alone: (q1, q5) by SP6 (the two height equations along h2, of the position
    and of h6; a quartic, up to 4), then :func:`_three_parallel_tail`."""
    p06 = sub(sub(p, mv(R06, P[6])), P[0])
    t = local2(4, 2)
    cnt, _ = sp6_one(
        (h[1], h[1], h[1], h[1]),
        (neg(h[0]), h[4], neg(h[0]), h[4]),
        (p06, neg(P[5]), mv(R06, h[5]), neg(h[5])),
        dot(h[1], add(add(add(P[1], P[2]), P[3]), P[4])),
        0.0,
        TOL_QUARTIC,
        t,
    )
    for j in range(4):
        if j >= cnt:
            _none(B, 2 * j, 2 * j + 2)
            continue
        _three_parallel_tail(h, P, R06, p06, angle_cs(t[j, 0]), angle_cs(t[j, 1]), True, B, 2 * j)


@kernel
def _spherical(h, P, R06, p, B):
    """Spherical wrist only: (q1, q2, q3) by SP5 (−p12 + R01ᵀ p16 = R12 (p23 + R23 p34), a
    quartic, up to 4), then the wrist."""
    p16 = sub(sub(p, mv(R06, P[6])), P[0])
    u0, w0 = _wrist_reads(h, R06)
    t = local2(4, 3)
    cnt, _ = sp5_one(neg(P[1]), p16, P[2], P[3], neg(h[0]), h[1], h[2], TOL_QUARTIC, t)
    for j in range(4):
        if j >= cnt:
            _none(B, 2 * j, 2 * j + 2)
            continue
        a1, a2, a3 = angle_cs(t[j, 0]), angle_cs(t[j, 1]), angle_cs(t[j, 2])
        _wrist_of(
            h, _back3(h, a1, a2, a3, u0), _back3(h, a1, a2, a3, w0), B, 2 * j, a1, a2, a3, True
        )


#: the compiled class solvers, by their index in :data:`CLOSED`
CLOSED = (
    C.SPHERICAL_TWO_PARALLEL,
    C.SPHERICAL_TWO_INTERSECTING,
    C.THREE_PARALLEL_TWO_INTERSECTING,
    C.SPHERICAL,
    C.THREE_PARALLEL,
)


@kernel
def _solve_closed(cls, h, P, R06, p, B):
    """The 8 branches of one pose of class ``cls`` (index in :data:`CLOSED`) into B: the
    class solver writes their rotations and flags, :func:`_angles` reads the angles; a branch
    that does not exist is NaN."""
    for b in range(8):
        B[b, EXISTS], B[b, EXACT] = 0.0, 0.0
    if cls == 0:
        _spherical_two_parallel(h, P, R06, p, B)
    elif cls == 1:
        _spherical_two_intersecting(h, P, R06, p, B)
    elif cls == 2:
        _three_parallel_two_intersecting(h, P, R06, p, B)
    elif cls == 3:
        _spherical(h, P, R06, p, B)
    else:
        _three_parallel(h, P, R06, p, B)
    _angles(B)
    for b in range(8):
        if B[b, EXISTS] == 0.0:
            for j in range(6):
                B[b, j] = math.nan
            B[b, EXACT] = 0.0


@kernel
def _closed_loop(cls, H, P, R06, p, Q, V, E):
    h, PP = rows6(H), rows7(P)
    B = np.empty((8, BRANCH_ROW))
    for i in range(len(p)):
        _solve_closed(cls, h, PP, mat(R06[i]), vec(p[i]), B)
        for b in range(8):
            for j in range(6):
                Q[i, b, j] = B[b, j]
            V[i, b], E[i, b] = B[b, EXISTS] != 0.0, B[b, EXACT] != 0.0
