"""``two_parallel``: axes 2 ∥ 3.  A 1-D search over q1 (:mod:`anthroarm.ik.search`): at each
q1, (q4, q6) by SP6 (the heights along h2 of the position and of h5) and θ23 = q2 + q3 by SP1,
the error ‖span‖ − ‖p23‖ (the elbow must reach the span vector); at a root q2 and q5 by SP1;
≤ 16 branches.  IK-Geo ``IK_2_parallel`` (arXiv 2211.05737, Table I)."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL, TOL_QUARTIC
from ..subproblems.circle import sp1_one
from ..subproblems.quartic import sp6_one
from ..vec3 import add, dot, mm, mtv, mv, neg, norm, rot, sub, wrap
from .base import SEARCH_1D, GeoClass


@kernel
def _parts(h, PP, R06, p16, q1, t6, t4):
    """At (q1, q6, q4): θ23 = q2 + q3 by SP1 (of h5), its exactness, the span vector v (the
    elbow must reach it: ‖v‖ = ‖p23‖), R16 = R01ᵀ R06, R34, R56."""
    h2, h4, h5 = h[1], h[3], h[4]
    Rt1 = rot(h[0], -q1)
    R16 = mm(Rt1, R06)
    R34, R56 = rot(h4, t4), rot(h[5], t6)
    t23, e23, _ = sp1_one(mv(R34, h5), mv(R16, mtv(R56, h5)), h2, TOL)
    R13 = rot(h2, t23)
    v = sub(
        sub(sub(sub(mv(Rt1, p16), PP[1]), mv(R13, PP[3])), mv(R13, mv(R34, PP[4]))),
        mv(R16, mtv(R56, PP[5])),
    )
    return t23, e23, v, R16, R34, R56


@kernel
def inner(h, PP, R06, p16, x, th, e, t2):
    """The inner subproblem at q1 = ``x``: the heights along h2 of the position and of h5 (SP6
    in q6, q4); writes its roots (q6, q4, 0) into ``th`` (4, 3), their errors ‖v‖ − ‖p23‖ into
    ``e`` (4,); returns their number."""
    h2 = h[1]
    Rt1 = rot(h[0], -x)
    R16 = mm(Rt1, R06)
    h1 = mtv(R16, h2)  # R06ᵀ R01 h2
    d1 = dot(h2, mv(Rt1, p16)) - dot(h2, add(add(PP[1], PP[2]), PP[3]))
    cnt, _ = sp6_one(
        (h1, h2, h1, h2),
        (neg(h[5]), h[3], neg(h[5]), h[3]),
        (PP[5], PP[4], h[4], neg(h[4])),
        d1,
        0.0,
        TOL_QUARTIC,
        t2,
    )
    d23 = norm(PP[2])
    for r in range(cnt):
        _, _, v, _, _, _ = _parts(h, PP, R06, p16, x, t2[r, 0], t2[r, 1])
        th[r, 0], th[r, 1], th[r, 2] = t2[r, 0], t2[r, 1], 0.0
        e[r] = norm(v) - d23
    return cnt


@kernel
def assemble(h, PP, R06, p16, x, r0, r1, r2, q):
    """The branch at q1 = ``x`` and inner root (q6, q4) = (r0, r1) into ``q`` (6,): q2 and q5
    by SP1; returns whether every subproblem on it was exact."""
    t6, t4 = r0, r1
    t23, e23, v, R16, R34, R56 = _parts(h, PP, R06, p16, x, t6, t4)
    h2 = h[1]
    q2, e2, _ = sp1_one(PP[2], v, h2, TOL)
    q5, e5, _ = sp1_one(mtv(R34, h2), mv(R56, mtv(R16, h2)), neg(h[4]), TOL)
    s3 = 1.0 if dot(h[1], h[2]) >= 0.0 else -1.0
    q[0], q[1], q[2], q[3], q[4], q[5] = x, q2, s3 * wrap(t23 - q2), t4, q5, t6
    return e23 and e2 and e5


CLASS = GeoClass(
    "two_parallel",
    "2 ∥ 3",
    lambda r: r.parallel[1],
    SEARCH_1D,
    searched="q1",
    inner=inner,
    assemble=assemble,
)
