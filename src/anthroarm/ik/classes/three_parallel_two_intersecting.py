"""``three_parallel_two_intersecting``: axes 2 ∥ 3 ∥ 4 and 5, 6 intersecting (p56 = 0) — the
ur5 family.  Closed form, 2 × 2 × 2 branches: q1 by SP4 (h2ᵀ R01ᵀ p16 = h2ᵀ (p12 + … + p45)),
q5 by SP4 (h2ᵀ R01ᵀ R06 h6 = h2ᵀ R45 h6), then
:func:`~anthroarm.ik.classes.branches.three_parallel_tail` (q2 + q3 + q4 and q6 by SP1, q3 by
SP3, q2 by SP1, q4 by difference).  IK-Geo ``IK_3_parallel_2_intersecting`` (arXiv
2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL
from ..subproblems.circle import sp4_cs
from ..vec3 import add, dot, mv, neg, rotate_cs, sub
from .base import CLOSED_FORM, GeoClass
from .branches import absent, three_parallel_tail


@kernel
def solve(h, P, R06, p, B):
    """q1 SP4, q5 SP4, then the three-parallel tail (2 ∥ 3 ∥ 4, 5 × 6)."""

    p06 = sub(sub(p, mv(R06, P[6])), P[0])
    d1 = dot(h[1], add(add(add(P[1], P[2]), P[3]), P[4]))
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(h[1], p06, neg(h[0]), d1, TOL)
    R06h6 = mv(R06, h[5])
    for i1 in range(2):
        if i1 >= n1:
            absent(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        c5a, s5a, c5b, s5b, n5, e5a, e5b, _ = sp4_cs(
            h[1], h[5], h[4], dot(h[1], rotate_cs(neg(h[0]), a1[0], a1[1], R06h6)), TOL
        )
        for i5 in range(2):
            b = 4 * i1 + 2 * i5
            if i5 >= n5:
                absent(B, b, b + 2)
                continue
            three_parallel_tail(
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


CLASS = GeoClass(
    "three_parallel_two_intersecting",
    "2 ∥ 3 ∥ 4, 5 and 6 intersect",
    lambda r: r.three_parallel[1] and r.intersecting[4],
    CLOSED_FORM,
    meets=((4, 5),),
    labels=(("q1", 2), ("q5", 2), ("q3", 2)),
    solve=solve,
)
