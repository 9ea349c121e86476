"""``three_parallel``: axes 2 ∥ 3 ∥ 4 and nothing else.  Quartic, 4 × 2 branches: (q1, q5) by
SP6 (the two height equations along h2, of the position and of h6; up to 4 roots), then
:func:`~anthroarm.ik.classes.branches.three_parallel_tail`.  IK-Geo ``IK_3_parallel`` (arXiv
2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel, local2
from ..subproblems.base import TOL_QUARTIC
from ..subproblems.quartic import sp6_one
from ..vec3 import add, angle_cs, dot, mv, neg, sub
from .base import QUARTIC, GeoClass
from .branches import absent, three_parallel_tail


@kernel
def solve(h, P, R06, p, B):
    """(q1, q5) SP6, then the three-parallel tail (2 ∥ 3 ∥ 4 alone)."""

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
            absent(B, 2 * j, 2 * j + 2)
            continue
        three_parallel_tail(h, P, R06, p06, angle_cs(t[j, 0]), angle_cs(t[j, 1]), True, B, 2 * j)


CLASS = GeoClass(
    "three_parallel",
    "2 ∥ 3 ∥ 4",
    lambda r: r.three_parallel[1],
    QUARTIC,
    labels=(("q1q5", 4), ("q3", 2)),
    solve=solve,
)
