"""``spherical_two_intersecting``: a spherical wrist (axes 4, 5, 6 meet) and axes 1, 2
intersecting — the wrist's spherical triple seen from the other end is a spherical *shoulder*
(the prosthetic arm, solved on its reversed chain).  Closed form, 2 × 2 × 2 branches: q3 by
SP3, (q1, q2) by SP2, then the wrist (:func:`~anthroarm.ik.classes.branches.wrist_of`).
IK-Geo ``IK_spherical_2_intersecting`` (arXiv 2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL
from ..subproblems.circle import sp2_cs, sp3_cs
from ..vec3 import add, mv, neg, norm, rotate_cs, sub
from .base import CLOSED_FORM, GeoClass
from .branches import absent, back3, wrist_of, wrist_reads


@kernel
def solve(h, P, R06, p, B):
    """q3 SP3, (q1, q2) SP2, the wrist (spherical wrist, axes 1 × 2)."""

    p16 = sub(sub(p, mv(R06, P[6])), P[0])  # from the 1–2 intersection
    u0, w0 = wrist_reads(h, R06)
    c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(P[3], neg(P[2]), h[2], norm(p16), TOL)
    for i3 in range(2):
        if i3 >= n3:
            absent(B, 4 * i3, 4 * i3 + 4)
            continue
        a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
        c1a, s1a, c2a, s2a, c1b, s1b, c2b, s2b, n12, ea, eb, _ = sp2_cs(
            p16, add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), neg(h[0]), h[1], TOL
        )
        for j in range(2):
            b = 4 * i3 + 2 * j
            if j >= n12:
                absent(B, b, b + 2)
                continue
            a1, a2 = ((c1a, s1a), (c2a, s2a)) if j == 0 else ((c1b, s1b), (c2b, s2b))
            wrist_of(
                h,
                back3(h, a1, a2, a3, u0),
                back3(h, a1, a2, a3, w0),
                B,
                b,
                a1,
                a2,
                a3,
                (e3a if i3 == 0 else e3b) and (ea if j == 0 else eb),
            )


CLASS = GeoClass(
    "spherical_two_intersecting",
    "4-5-6 spherical, 1 and 2 intersect",
    lambda r: r.spherical[3] and r.intersecting[0],
    CLOSED_FORM,
    meets=((0, 1), (3, 4, 5)),
    labels=(("q3", 2), ("q1q2", 2), ("q5", 2)),
    solve=solve,
)
