"""``two_intersecting``: axes 5 and 6 intersect.  A 1-D search over q4
(:mod:`anthroarm.ik.search`): at each q4, (q1, q2, q3) by SP5 (the 5-6 intersection placed),
the error h5ᵀ R04ᵀ R06 h6 − h5ᵀ h6; at a root q5 and q6 by SP1; ≤ 16 branches.  IK-Geo
``IK_2_intersecting`` (arXiv 2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL, TOL_QUARTIC
from ..subproblems.circle import sp1_one
from ..subproblems.quartic import sp5_one
from ..vec3 import add, dot, mm, mtv, mv, neg, rot, rotate
from .base import SEARCH_1D, GeoClass


@kernel
def inner(h, PP, R06, p16, x, th, e, t2):
    """The inner subproblem at q4 = ``x``: the 5-6 intersection placed by SP5 in (q1, q2, q3);
    writes its roots into ``th`` (4, 3), their errors h5ᵀ R04ᵀ R06 h6 − h5ᵀ h6 into ``e``
    (4,); returns their number."""
    p35 = add(PP[3], rotate(h[3], x, PP[4]))
    cnt, _ = sp5_one(neg(PP[1]), p16, PP[2], p35, neg(h[0]), h[1], h[2], TOL_QUARTIC, th)
    R06h6 = mv(R06, h[5])
    R4 = rot(h[3], x)
    for r in range(cnt):
        R04 = mm(mm(mm(rot(h[0], th[r, 0]), rot(h[1], th[r, 1])), rot(h[2], th[r, 2])), R4)
        e[r] = dot(h[4], mtv(R04, R06h6)) - dot(h[4], h[5])
    return cnt


@kernel
def assemble(h, PP, R06, p16, x, r0, r1, r2, q):
    """The branch at q4 = ``x`` and inner root (q1, q2, q3) = (r0, r1, r2) into ``q`` (6,): q5
    and q6 by SP1; returns whether every subproblem on it was exact."""
    R04 = mm(mm(mm(rot(h[0], r0), rot(h[1], r1)), rot(h[2], r2)), rot(h[3], x))
    q5, e5, _ = sp1_one(h[5], mtv(R04, mv(R06, h[5])), h[4], TOL)
    q6, e6, _ = sp1_one(h[4], mtv(R06, mv(R04, h[4])), neg(h[5]), TOL)
    q[0], q[1], q[2], q[3], q[4], q[5] = r0, r1, r2, x, q5, q6
    return e5 and e6


CLASS = GeoClass(
    "two_intersecting",
    "5 and 6 intersect",
    lambda r: r.intersecting[4],
    SEARCH_1D,
    meets=((4, 5),),
    searched="q4",
    inner=inner,
    assemble=assemble,
)
