"""The inner subproblems of the 1-D search classes at a searched angle (``two_parallel``: SP6 in
(q6, q4); ``two_intersecting``: SP5 in (q1, q2, q3)), their error, and the branch at a root."""

from __future__ import annotations

from ...jit import kernel
from ..subproblems.base import TOL, TOL_QUARTIC
from ..subproblems.circle import sp1_one
from ..subproblems.quartic import sp5_one, sp6_one
from ..vec3 import add, dot, mm, mtv, mv, neg, norm, rot, rotate, sub, wrap


# ----------------------------------------------------------------------------- 1-D inner subproblems
@kernel
def _tp_parts(h, PP, R06, p16, q1, t6, t4):
    """two_parallel at (q1, q6, q4): θ23 = q2 + q3 by SP1 (of h5), its exactness, the span
    vector v (the elbow must reach it: ‖v‖ = ‖p23‖), R16 = R01ᵀ R06, R34, R56."""
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
def _inner(cls, h, PP, R06, p16, x, th, e, t2):
    """The inner subproblem of a 1-D search class at the searched angle ``x``: writes its
    roots into ``th`` (4, 3) (two_parallel: (q6, q4, 0); two_intersecting: (q1, q2, q3)),
    their errors into ``e`` (4,); returns their number (valid rows first)."""
    if cls == 0:
        # two_parallel: the heights along h2 of the position and of h5 (SP6 in q6, q4)
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
            _, _, v, _, _, _ = _tp_parts(h, PP, R06, p16, x, t2[r, 0], t2[r, 1])
            th[r, 0], th[r, 1], th[r, 2] = t2[r, 0], t2[r, 1], 0.0
            e[r] = norm(v) - d23
        return cnt
    # two_intersecting: the 5-6 intersection placed by SP5 in (q1, q2, q3)
    p35 = add(PP[3], rotate(h[3], x, PP[4]))
    cnt, _ = sp5_one(neg(PP[1]), p16, PP[2], p35, neg(h[0]), h[1], h[2], TOL_QUARTIC, th)
    R06h6 = mv(R06, h[5])
    R4 = rot(h[3], x)
    for r in range(cnt):
        R04 = mm(mm(mm(rot(h[0], th[r, 0]), rot(h[1], th[r, 1])), rot(h[2], th[r, 2])), R4)
        e[r] = dot(h[4], mtv(R04, R06h6)) - dot(h[4], h[5])
    return cnt


@kernel
def _assemble(cls, h, PP, R06, p16, x, r0, r1, r2, q):
    """The branch at a root (searched angle ``x``, inner root (r0, r1, r2)) into ``q`` (6,);
    returns whether every subproblem on it was exact."""
    if cls == 0:
        t6, t4 = r0, r1
        t23, e23, v, R16, R34, R56 = _tp_parts(h, PP, R06, p16, x, t6, t4)
        h2 = h[1]
        q2, e2, _ = sp1_one(PP[2], v, h2, TOL)
        q5, e5, _ = sp1_one(mtv(R34, h2), mv(R56, mtv(R16, h2)), neg(h[4]), TOL)
        s3 = 1.0 if dot(h[1], h[2]) >= 0.0 else -1.0
        q[0], q[1], q[2], q[3], q[4], q[5] = x, q2, s3 * wrap(t23 - q2), t4, q5, t6
        return e23 and e2 and e5
    R04 = mm(mm(mm(rot(h[0], r0), rot(h[1], r1)), rot(h[2], r2)), rot(h[3], x))
    q5, e5, _ = sp1_one(h[5], mtv(R04, mv(R06, h[5])), h[4], TOL)
    q6, e6, _ = sp1_one(h[4], mtv(R06, mv(R04, h[4])), neg(h[5]), TOL)
    q[0], q[1], q[2], q[3], q[4], q[5] = r0, r1, r2, x, q5, q6
    return e5 and e6
