"""The branch rows the closed IK-Geo classes write (:data:`BRANCH_ROW` wide, 8 a pose) and the
kernels they share: the spherical wrist (:func:`wrist`, :func:`wrist_of`) and the tail of the classes with
three parallel axes (:func:`three_parallel_tail`).

One compiled kernel per class and pose (:mod:`anthroarm.jit`), built from the subproblem kernels
of :mod:`anthroarm.ik.subproblems`; vectors are tuples (:mod:`anthroarm.ik.vec3`).  Each writes
its 8 branches into the rows of B (8, :data:`BRANCH_ROW`): the six angles (rad), their cosines
(from column :data:`COS`) and sines (:data:`SIN`), whether the branch exists (:data:`EXISTS`,
1.0 / 0.0) and whether every subproblem on it was exact (:data:`EXACT`) — one array, so a call
passes one reference, not five — in the order of the labels: the first branching subproblem
outermost, the root index innermost.  A branch under a root that does not exist is left NaN /
not existing.  An angle travels as its rotation, the pair a = (cos θ, sin θ): the subproblems
give the rotation they find so (``sp*_cs``, :func:`anthroarm.ik.subproblems.unit_cs`), the
rotations that follow and the FK check evaluate no trigonometry, and the angles themselves are
read at the end, in one vectorised loop (:func:`angles`)."""

from __future__ import annotations

from ...jit import kernel, local
from ..subproblems.base import TOL
from ..subproblems.circle import sp1_cs, sp3_cs, sp4_cs
from ..vec3 import (
    add,
    atan2,
    dot,
    mtm,
    mtv,
    mv,
    neg,
    norm,
    perpendicular,
    rot_cs,
    rotate_cs,
    sub,
)

COS, SIN, EXISTS, EXACT, BRANCH_ROW = 6, 12, 18, 19, 20


@kernel
def absent(B, b0, b1):
    """Branches b0 … b1 − 1 do not exist (their root does not)."""
    for b in range(b0, b1):
        B[b, EXISTS] = 0.0


@kernel
def put(B, b, a1, a2, a3, a4, a5, a6, v, e):
    """Branch b: its six rotations (pairs (cos θ, sin θ)) and its flags; the angles are read
    from them at the end (:func:`angles`)."""
    row = (a1, a2, a3, a4, a5, a6)
    for j in range(6):
        B[b, COS + j], B[b, SIN + j] = row[j]
    B[b, EXISTS], B[b, EXACT] = 1.0 if v else 0.0, 1.0 if e else 0.0


@kernel
def angles(B):
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
def wrist(h, R03, R06, B, b, a1, a2, a3, ex):
    """Spherical wrist from R36 = R03ᵀ R06 (:func:`wrist_of`); branches b (first q5 root) and
    b + 1.  a1, a2, a3: the rotations (cos, sin) of q1, q2, q3."""
    u, w = wrist_reads(h, mtm(R03, R06))
    wrist_of(h, u, w, B, b, a1, a2, a3, ex)


@kernel
def wrist_reads(h, R):
    """(R h6, R x), x = :func:`.vec3.perpendicular` of h6: the two columns of a rotation R that
    :func:`wrist_of` reads of R36 (R = R36, or R06 before it is turned back, :func:`back3`)."""
    return mv(R, h[5]), mv(R, perpendicular(h[5]))


@kernel
def back3(h, a1, a2, a3, v):
    """R03ᵀ v = rot(h3, −q3) rot(h2, −q2) rot(h1, −q1) v of the rotations (cos, sin) a1, a2, a3."""
    return rotate_cs(
        h[2], a3[0], -a3[1], rotate_cs(h[1], a2[0], -a2[1], rotate_cs(h[0], a1[0], -a1[1], v))
    )


@kernel
def wrist_of(h, u, w, B, b, a1, a2, a3, ex):
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
        put(
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
def three_parallel_tail(h, P, R06, p06, a1, a5, ex, B, b):
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
        put(
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
