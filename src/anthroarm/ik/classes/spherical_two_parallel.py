"""``spherical_two_parallel``: a spherical wrist (axes 4, 5, 6 meet) and axes 2 ∥ 3 — the
common industrial 6R arm (ur5's cousins with a spherical wrist, the book's 6R arm, the care
robot).  Closed form, 2 × 2 × 2 branches: q1 by SP4, q3 by SP3, q2 by SP1, then the wrist
(q5 by SP4, q4 and q6 by SP1; :func:`~anthroarm.ik.classes.branches.wrist_of`).  IK-Geo
``IK_spherical_2_parallel`` (arXiv 2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL
from ..subproblems.circle import sp1_cs, sp3_cs, sp4_cs
from ..vec3 import add, dot, mv, neg, norm, rotate_cs, sub
from .base import CLOSED_FORM, GeoClass
from .branches import absent, wrist_of, wrist_reads


@kernel
def solve(h, P, R06, p, B):
    """q1 SP4, q3 SP3, q2 SP1, the wrist (spherical wrist, axes 2 ∥ 3)."""

    wrist = sub(sub(p, mv(R06, P[6])), P[0])  # p_16 (wrist centre − p01)
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(
        h[1], wrist, neg(h[0]), dot(h[1], add(add(P[1], P[2]), P[3])), TOL
    )
    u0, w0 = wrist_reads(h, R06)
    for i1 in range(2):
        if i1 >= n1:
            absent(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        v = sub(rotate_cs(neg(h[0]), a1[0], a1[1], wrist), P[1])  # R01ᵀ p_16 − p12
        u1, w1 = rotate_cs(h[0], a1[0], -a1[1], u0), rotate_cs(h[0], a1[0], -a1[1], w0)
        c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(neg(P[3]), P[2], h[2], norm(v), TOL)
        for i3 in range(2):
            b = 4 * i1 + 2 * i3
            if i3 >= n3:
                absent(B, b, b + 2)
                continue
            a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
            c2, s2, e2, _ = sp1_cs(add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), v, h[1], TOL)
            ex = (e1a if i1 == 0 else e1b) and (e3a if i3 == 0 else e3b) and e2
            u = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, u1))  # R03ᵀ R06 h6
            w = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, w1))
            wrist_of(h, u, w, B, b, a1, (c2, s2), a3, ex)


CLASS = GeoClass(
    "spherical_two_parallel",
    "4-5-6 spherical, 2 ∥ 3",
    lambda r: r.spherical[3] and r.parallel[1],
    CLOSED_FORM,
    meets=((3, 4, 5),),
    labels=(("q1", 2), ("q3", 2), ("q5", 2)),
    solve=solve,
)
