"""``spherical``: a spherical wrist (axes 4, 5, 6 meet) and nothing else.  Quartic, 4 × 2
branches: (q1, q2, q3) by SP5 (−p12 + R01ᵀ p16 = R12 (p23 + R23 p34), up to 4 roots), then the
wrist (:func:`~anthroarm.ik.classes.branches.wrist_of`).  IK-Geo ``IK_spherical`` (arXiv
2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel, local2
from ..subproblems.base import TOL_QUARTIC
from ..subproblems.quartic import sp5_one
from ..vec3 import angle_cs, mv, neg, sub
from .base import QUARTIC, GeoClass
from .branches import absent, back3, wrist_of, wrist_reads


@kernel
def solve(h, P, R06, p, B):
    """(q1, q2, q3) SP5, the wrist (spherical wrist only)."""

    p16 = sub(sub(p, mv(R06, P[6])), P[0])
    u0, w0 = wrist_reads(h, R06)
    t = local2(4, 3)
    cnt, _ = sp5_one(neg(P[1]), p16, P[2], P[3], neg(h[0]), h[1], h[2], TOL_QUARTIC, t)
    for j in range(4):
        if j >= cnt:
            absent(B, 2 * j, 2 * j + 2)
            continue
        a1, a2, a3 = angle_cs(t[j, 0]), angle_cs(t[j, 1]), angle_cs(t[j, 2])
        wrist_of(h, back3(h, a1, a2, a3, u0), back3(h, a1, a2, a3, w0), B, 2 * j, a1, a2, a3, True)


CLASS = GeoClass(
    "spherical",
    "4-5-6 spherical",
    lambda r: r.spherical[3],
    QUARTIC,
    meets=((3, 4, 5),),
    labels=(("q1q2q3", 4), ("q5", 2)),
    solve=solve,
)
