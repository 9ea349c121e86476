"""The search classes of the geometric IK, compiled: one Numba kernel call for a batch of poses.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, §IV (the 6-DOF solvers ``IK_2_parallel``,
``IK_2_intersecting``, ``IK_gen_6_dof``); the decompositions were read from the reference
implementation (github.com/rpiRobotics/ik-geo, ``matlab/+IK``); the code is our own, built on
the scalar subproblem kernels of :mod:`anthroarm.ik.subproblems` (``sp1_one``, ``sp5_one``,
``sp6_one``) and the tuple algebra of :mod:`anthroarm.ik.vec3`.

Conventions (IK-Geo): joint i turns about the unit axis ``H[i]`` (base frame, q = 0); ``P[0]``
is the base → joint 1 offset, ``P[i]`` joint i → joint i + 1, ``P[6]`` joint 6 → tool (m);
the pose is ``R06`` (the tool orientation with its value at q = 0 removed) and ``p`` the tool
position (base frame, m); angles in rad.

=====================  ============================================================  =========
class                  search (IK-Geo)                                               branches
=====================  ============================================================  =========
``two_parallel``       ``IK_2_parallel`` (h2 ∥ h3): 1-D over q1; (q4, q6) SP6,        ≤ 16
                       θ23 SP1, error ‖span‖ − ‖p23‖; at a root q2, q5 SP1
``two_intersecting``   ``IK_2_intersecting`` (p56 = 0): 1-D over q4; (q1, q2, q3)     ≤ 16
                       SP5, error h5ᵀ R04ᵀ R06 h6 − h5ᵀ h6; at a root q5, q6 SP1
``gen_six_dof``        ``IK_gen_6_dof``: 2-D over (q1, q2); (q3, q4, q5) SP5, error   ≤ 16
                       ‖R05 h6 − R06 h6‖; local minima polished by Newton; q6 SP1
=====================  ============================================================  =========

The 1-D search (per pose, in the kernel): the searched joint is sampled on :data:`SEARCH_GRID`
+ 1 values over [−π, π]; each root of the inner subproblem is followed to the next sample by
the nearest root there (a match closer than :data:`_MATCH` rad in every unknown); a sign change
of the error along a followed root is a bracket, refined by the Illinois variant of regula
falsi (the root followed by the one nearest its interpolation between the bracket's ends) until
``|e| ≤ SEARCH_TOL / 100`` or 60 steps; a refined root with ``|e| ≤`` :data:`SEARCH_TOL` whose
pose error (FK) is above :data:`_FK_TOL` gets a few Newton steps on the pose (|e| pins the
angle loosely where e is flat); it is ``exact`` where the pose is met to SEARCH_TOL.  A sample
interval where the number of roots changes (a fold: a pair of roots appears or vanishes there,
moving like a square root), a root moves by more than :data:`_FAST` rad, or two roots at an
end are closer than _FAST (a near fold: the error along them turns fast) is sampled again on
33 points crowded quadratically towards both ends, and its brackets come from that finer
sampling.  An interval of a finer look where the number of roots is the same at both ends
but a followed root still moves by more than :data:`_JUMP` (two folds of the inner
subproblem inside it — the root runs back on an arc between them, and a solution on that arc
is seen by no sample — or a root turning fast past a near singularity) is looked at again
the same way, down to :data:`_DEPTH` levels; where the number of roots changes inside a finer
look, a sign change is bracketed only between mutually nearest roots (a root vanishing at the
fold is nearest to another root beyond it, with no root between them).  A pair of roots
inside one sample interval (two IK solutions closer than it — near a singular pose, a few %
of random poses) is no sign change at the samples: at every *dip*
(|e| along a followed root smallest at a sample, of one sign there and at both neighbours, grid
or finer samples) low enough that a zero may hide next to it (|e| ≤ :data:`_DIP` × the steeper
secant slope × the wider gap), |e| is minimised along the root by safeguarded parabolic
interpolation until it changes sign (two brackets, refined as above), the bound proves no zero
can hide, or the bracket is narrower than :data:`_DIP_TOL` (a minimum within :data:`_TOUCH` of
zero — the error touching zero — seeds Newton on the pose).  Next to a fold of the finer
sampling, the roots with ``|e| <`` :data:`_SEED`, and the pair that meets at the fold where
their errors differ in sign, seed Newton steps on the whole arm's pose (a root on the arc
through a fold is a sign change along neither root), kept where they converge to
:data:`SEARCH_TOL`.

The 2-D search: (q1, q2) on a :data:`SEARCH_GRID_2D` ² periodic grid; every (sample, SP5 root)
whose error is below 0.3 and not above the best root of any of its 8 neighbours gives q6 by
SP1 and seeds 20 Newton steps on the pose; the converged ones (pose error ≤ SEARCH_TOL) are
kept.  A branch whose basin the grid misses is not found (no completeness claim).

Each pose gets up to :data:`SEARCH_BRANCHES` slots, filled in the order the branches are
found (the refined brackets along the grid, the dips of the grid, the brackets and dips of
finer samplings, each followed by those of its own finer looks, then the polished fold seeds);
a branch within 1e-8 rad (every joint, mod 2π) of an earlier one is dropped.
"""

from __future__ import annotations

import math

import numpy as np

from ..jit import kernel
from .subproblems import TOL, TOL_QUARTIC, sp1_one, sp5_one, sp6_one
from .vec3 import (
    add,
    cross,
    dot,
    mm,
    mtv,
    mv,
    neg,
    norm,
    rot,
    rotate,
    rows6,
    rows7,
    scale,
    sub,
    transpose,
    vec,
    wrap,
)

#: samples of the searched joint over [−π, π] (IK-Geo's reference implementation uses 200)
SEARCH_GRID = 256
#: samples of each searched joint of ``gen_six_dof`` (a grid of its square)
SEARCH_GRID_2D = 64
#: most branches a search class returns per pose (a 6R arm has at most 16 solutions)
SEARCH_BRANCHES = 16
#: |e| at which a refined root counts as exact (the error functions are in m or unitless)
SEARCH_TOL = 1e-12
#: two roots of the inner subproblem at neighbouring samples are the same branch when their
#: angles differ by less than this (rad); a branch that appears or vanishes there is not followed
_MATCH = 0.5
#: a sample interval where a root moves by more than this (rad) is sampled again more finely
_FAST = 0.2
#: a root next to a fold with |e| below this seeds a Newton polish of the whole arm
_SEED = 0.05
#: an interval of a finer look (≤ 1/16 of a sample interval wide) where a followed root moves by
#: more than this (rad) with the number of roots unchanged is looked at again the same way (a
#: rate ≥ 8× that of _FAST over a sample interval: roots the finer samples do not resolve)
_JUMP = 0.1
#: levels of finer looks (interval widths ≤ 1.5e-3, 9e-5, 5e-6 rad at levels 1-3)
_DEPTH = 3
#: points per half of a finer sampling (2 · _SUB + 1 in all) and regula-falsi steps at most
_SUB = 16
_ITERS = 60
#: Newton steps on the pose for a fold seed of a 1-D search and for a 2-D local minimum
_POLISH_1D = 12
_POLISH_2D = 20
#: Newton steps on the pose for a refined root whose error stayed above SEARCH_TOL or whose
#: pose error is above _FK_TOL
_POLISH_ROOT = 3
#: pose error (max entry of |R − R06| and |o − p|, m) above which a refined root is polished
_FK_TOL = 1e-11
#: error below which a local minimum of the 2-D grid seeds Newton
_MIN_2D = 0.3
#: most fold seeds kept per pose (more are ignored; a fold has at most a few roots)
_MAX_SEEDS = 256
#: a dip of the error along a followed root (|e| smallest at a sample, of one sign at it and
#: both neighbours) is searched for a sign change where |e| there is at most this times the
#: steeper secant slope to a neighbour times the wider gap (``_low``; 2: a safety factor over
#: a V, for a slope that steepens towards the dip)
_DIP = 2.0
#: steps of the minimisation of |e| in a dip, and the bracket width (rad) where it stops
_DIP_ITERS = 40
_DIP_TOL = 1e-10
#: a dip whose minimum stays above zero but within this of it (|e|) seeds a Newton polish
_TOUCH = 1e-9

#: the classes solved here, by their index in the compiled kernel
CLASSES = ("two_parallel", "two_intersecting", "gen_six_dof")


# ----------------------------------------------------------------------------- helpers
@kernel
def solve6(A, b):
    """Solve A x = b (6×6, in place: ``b`` becomes x) by Gaussian elimination with partial
    pivoting; returns det A (0 when a pivot vanishes, b then undefined)."""
    det = 1.0
    for c in range(6):
        piv, big = c, abs(A[c, c])
        for r in range(c + 1, 6):
            if abs(A[r, c]) > big:
                piv, big = r, abs(A[r, c])
        if big == 0.0:
            return 0.0
        if piv != c:
            for k in range(6):
                A[c, k], A[piv, k] = A[piv, k], A[c, k]
            b[c], b[piv] = b[piv], b[c]
            det = -det
        d = A[c, c]
        det *= d
        for r in range(c + 1, 6):
            f = A[r, c] / d
            if f != 0.0:
                for k in range(c, 6):
                    A[r, k] -= f * A[c, k]
                b[r] -= f * b[c]
    for c in range(5, -1, -1):
        s = b[c]
        for k in range(c + 1, 6):
            s -= A[c, k] * b[k]
        b[c] = s / A[c, c]
    return det


@kernel
def fk_geo(h, PP, q):
    """FK in IK-Geo's form for joint angles ``q`` (6,) rad: (R06 (row tuples), the tool
    position (m)), both in the base frame; ``h`` the 6 axes, ``PP`` the 7 offsets (tuples)."""
    R = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    o = PP[0]
    for i in range(6):
        R = mm(R, rot(h[i], q[i]))
        o = add(o, mv(R, PP[i + 1]))
    return R, o


@kernel
def polish(h, PP, R06, p, q, iters, J, F):
    """Newton steps on the whole arm's pose equations from ``q`` (6,) rad, in place (the
    spatial Jacobian at the tool point; position error p − o (m), rotation error
    ½ vee(R06 Rᵀ − R R06ᵀ)); a step whose Jacobian has |det| ≤ 1e-12 is not taken.  ``q`` is
    wrapped into (−π, π] at the end; returns whether it converged (max entry of |R − R06| and
    |o − p| ≤ :data:`SEARCH_TOL`).  ``J`` (6, 6), ``F`` (6,) scratch."""
    for _ in range(iters):
        R = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        o = PP[0]
        for i in range(6):
            J[3, i], J[4, i], J[5, i] = mv(R, h[i])  # the joint's axis (base frame)
            J[0, i], J[1, i], J[2, i] = o  # a point of it, crossed below
            R = mm(R, rot(h[i], q[i]))
            o = add(o, mv(R, PP[i + 1]))
        for i in range(6):
            ax = (J[3, i], J[4, i], J[5, i])
            c = cross(ax, sub(o, (J[0, i], J[1, i], J[2, i])))
            J[0, i], J[1, i], J[2, i] = c
        W = mm(R06, transpose(R))
        F[0], F[1], F[2] = sub(p, o)
        F[3] = 0.5 * (W[2][1] - W[1][2])
        F[4] = 0.5 * (W[0][2] - W[2][0])
        F[5] = 0.5 * (W[1][0] - W[0][1])
        if abs(solve6(J, F)) <= 1e-12:
            break  # the same q (and J) at every later step
        for i in range(6):
            q[i] += F[i]
    err = pose_error(h, PP, R06, p, q)
    for i in range(6):
        q[i] = wrap(q[i])
    return err <= SEARCH_TOL


@kernel
def pose_error(h, PP, R06, p, q):
    """The pose error of joint angles ``q`` (6,) rad: the max entry of |R − R06| and |o − p|
    (m) at their FK."""
    R, o = fk_geo(h, PP, q)
    err = 0.0
    for i in range(3):
        err = max(err, abs(o[i] - p[i]))
        for j in range(3):
            err = max(err, abs(R[i][j] - R06[i][j]))
    return err


@kernel
def _push(Q, V, E, n, q, ex):
    """Append branch ``q`` (6,) to the slots Q (16, 6), V, E holding ``n`` branches, unless
    it is within 1e-8 rad of one of them (every joint, mod 2π) or the slots are full; returns
    the new count."""
    if n >= SEARCH_BRANCHES:
        return n
    for a in range(n):
        d = 0.0
        for j in range(6):
            d = max(d, abs(wrap(q[j] - Q[a, j])))
        if d < 1e-8:
            return n
    for j in range(6):
        Q[n, j] = wrap(q[j])
    V[n], E[n] = True, ex
    return n + 1


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


# ----------------------------------------------------------------------------- 1-D search
@kernel
def _sample(cls, h, PP, R06, p16, X, RS, ES, CS, t2):
    """The inner subproblem at every angle of ``X``: roots RS (L, 4, 3), errors ES (L, 4),
    counts CS (L,)."""
    for i in range(len(X)):
        CS[i] = _inner(cls, h, PP, R06, p16, X[i], RS[i], ES[i], t2)


@kernel
def _nearest(RS, CS, i, r):
    """The root at sample ``i`` of RS (L, 4, 3) nearest to ``r`` (3-tuple; max over the unknowns
    of the wrapped difference): (its index, the distance; inf where there is none)."""
    best, k = math.inf, 0
    for t in range(CS[i]):
        d = max(
            abs(wrap(RS[i, t, 0] - r[0])),
            max(abs(wrap(RS[i, t, 1] - r[1])), abs(wrap(RS[i, t, 2] - r[2]))),
        )
        if d < best:
            best, k = d, t
    return k, best


@kernel
def _interval(RS, CS, g, S1, DM):
    """Follow each root at sample g to sample g + 1 (the nearest root there, max over the
    unknowns of the wrapped difference): S1 (4,) its index, DM (4,) the distance (inf: no
    root there).  Returns whether the interval needs a finer look (the number of roots changes
    or a root moves by more than _FAST, or finds no partner)."""
    fine = CS[g] != CS[g + 1]
    for s in range(CS[g]):
        k, best = _nearest(RS, CS, g + 1, (RS[g, s, 0], RS[g, s, 1], RS[g, s, 2]))
        S1[s], DM[s] = k, best
        if best > _FAST:
            fine = True
    # two roots closer than _FAST at an end: a near fold (a pair of roots passing close, the
    # error along them turning fast)
    for i in range(g, g + 2):
        for s in range(CS[i]):
            for t in range(s + 1, CS[i]):
                d = 0.0
                for c in range(3):
                    d = max(d, abs(wrap(RS[i, s, c] - RS[i, t, c])))
                if d < _FAST:
                    fine = True
    return fine


@kernel
def _interpolated_root(cls, h, PP, R06, p16, x, xl, xr, rl, rr, th, e, t2):
    """The inner roots at ``x`` (into ``th``, errors ``e``) and the one nearest to the linear
    interpolation at x of the roots ``rl`` at ``xl`` and ``rr`` at ``xr`` (max over the unknowns
    of the wrapped difference): (its index, the distance — inf without a root —, the
    interpolation)."""
    cnt = _inner(cls, h, PP, R06, p16, x, th, e, t2)
    t = (x - xl) / (xr - xl if xr != xl else 1.0)
    t = min(max(t, 0.0), 1.0)
    ref = (
        rl[0] + t * wrap(rr[0] - rl[0]),
        rl[1] + t * wrap(rr[1] - rl[1]),
        rl[2] + t * wrap(rr[2] - rl[2]),
    )
    best, k = math.inf, 0
    for r in range(cnt):
        d = max(
            abs(wrap(th[r, 0] - ref[0])),
            max(abs(wrap(th[r, 1] - ref[1])), abs(wrap(th[r, 2] - ref[2]))),
        )
        if d < best:
            best, k = d, r
    return k, best, ref


@kernel
def _refine(cls, h, PP, R06, p16, xl, xr, el, er, rl, rr, th, e, t2, out):
    """Illinois regula falsi on the bracket [xl, xr] (errors el, er of opposite signs, inner
    roots rl, rr (3-tuples) at the ends), the root followed by the one nearest its
    interpolation between the ends.  Writes (x, root (3), |e|) into ``out`` (5,); returns
    False where the followed root was lost."""
    for _ in range(_ITERS):
        den = er - el
        w = er / den if den != 0.0 else 0.5
        xm = xr - w * (xr - xl)
        k, best, _ = _interpolated_root(cls, h, PP, R06, p16, xm, xl, xr, rl, rr, th, e, t2)
        lost = not (best < math.inf)
        em = math.nan if lost else e[k]
        rm = (th[k, 0], th[k, 1], th[k, 2])
        if (em < 0.0) != (er < 0.0):
            xl, el, rl = xr, er, rr
        else:
            el = 0.5 * el
        xr, er, rr = xm, em, rm
        if lost or abs(em) <= 0.01 * SEARCH_TOL or abs(xr - xl) <= 1e-15:
            break
    if not math.isfinite(er):
        return False
    if abs(el) < abs(er):
        out[0], out[1], out[2], out[3], out[4] = xl, rl[0], rl[1], rl[2], abs(el)
    else:
        out[0], out[1], out[2], out[3], out[4] = xr, rr[0], rr[1], rr[2], abs(er)
    return True


@kernel
def _brackets(
    cls, h, PP, R06, p, p16, X, RS, ES, CS, g, S1, DM, th, e, t2, out, q, q2, J, F, Q, V, E, n
):
    """The brackets of sample interval ``g`` of X, RS, ES, CS (roots followed by
    :func:`_interval`: S1, DM): every followed root (closer than :data:`_MATCH`) whose error
    changes sign is refined (:func:`_refine`) and its branch pushed.  Where the number of roots
    changes (a fold, inside a finer look), only a pair of mutually nearest roots: a root of the
    pair that vanishes at the fold is nearest to another root beyond it (no root to refine
    between them: the refinement would end at the fold, inexact).  Returns the branch count."""
    for s in range(CS[g]):
        s1 = S1[s]
        if DM[s] < _MATCH and (ES[g, s] < 0.0) != (ES[g + 1, s1] < 0.0):
            r1 = (RS[g + 1, s1, 0], RS[g + 1, s1, 1], RS[g + 1, s1, 2])
            if CS[g] != CS[g + 1] and _nearest(RS, CS, g, r1)[0] != s:
                continue
            if _refine(
                cls,
                h,
                PP,
                R06,
                p16,
                X[g],
                X[g + 1],
                ES[g, s],
                ES[g + 1, s1],
                (RS[g, s, 0], RS[g, s, 1], RS[g, s, 2]),
                r1,
                th,
                e,
                t2,
                out,
            ):
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, J, F))
    return n


@kernel
def _root_branch(cls, h, PP, R06, p, p16, out, q, q2, J, F):
    """The branch at a refined root ``out`` (x, inner root, |e|) into ``q`` (6,); returns
    whether it is exact.  A root whose error stayed above :data:`SEARCH_TOL` (regula falsi
    stalls where two roots share a sample interval), or whose pose error is above
    :data:`_FK_TOL` (|e| ≤ SEARCH_TOL pins the angle only to SEARCH_TOL / |e′|, loose where e
    is flat: at a pair of roots close together), while every subproblem on it was exact gets
    :data:`_POLISH_ROOT` Newton steps on the whole pose (scratch ``q2``), kept where they
    converge (quadratic convergence from a root already good to ~1e-7)."""
    ex = _assemble(cls, h, PP, R06, p16, wrap(out[0]), out[1], out[2], out[3], q)
    if ex and (out[4] > SEARCH_TOL or pose_error(h, PP, R06, p, q) > _FK_TOL):
        for j in range(6):
            q2[j] = q[j]
        ex = polish(h, PP, R06, p, q2, _POLISH_ROOT, J, F)
        if ex:
            for j in range(6):
                q[j] = q2[j]
    return ex


@kernel
def _follow(cls, h, PP, R06, p16, x, xl, xr, rl, rr, th, e, t2):
    """The inner root at ``x`` (between ``xl`` and ``xr``, whose followed roots are ``rl``,
    ``rr``) nearest to the linear interpolation of rl, rr: (its error (NaN: no root), the
    root)."""
    k, best, ref = _interpolated_root(cls, h, PP, R06, p16, x, xl, xr, rl, rr, th, e, t2)
    if not best < _MATCH:
        return math.nan, ref
    return e[k], (th[k, 0], th[k, 1], th[k, 2])


@kernel
def _low(xa, xb, xc, fa, fb, fc):
    """Whether a zero may hide in the dip fa ≥ fb ≤ fc > 0 at xa < xb < xc: fb is at most
    :data:`_DIP` times the steeper of its two secant slopes times the wider of its two gaps (a
    function that falls no faster than that slope reaches zero within the wider gap; a
    parabola through a pair of roots in one gap, or a V through them, always passes; a smooth
    dip that stays away from zero, |e| large against its variation over a gap, does not)."""
    s = max((fa - fb) / (xb - xa), (fc - fb) / (xc - xb))
    return fb <= _DIP * s * max(xb - xa, xc - xb)


@kernel
def _dip(
    cls,
    h,
    PP,
    R06,
    p,
    p16,
    xa,
    xb,
    xc,
    ea,
    eb,
    ec,
    ra,
    rb,
    rc,
    th,
    e,
    t2,
    out,
    q,
    q2,
    J,
    F,
    Q,
    V,
    E,
    n,
):
    """A dip of the error along a followed root: |e| at ``xb`` below its value at ``xa`` < xb
    and ``xc`` > xb, all three of one sign (``ea``, ``eb``, ``ec``; followed inner roots ``ra``,
    ``rb``, ``rc``).  |e| is minimised over [xa, xc] along the root by successive parabolic
    interpolation (a golden-section step where the vertex falls outside the bracket or next
    to xb, and every 4th step); at the first point where e changes sign, the two brackets it
    makes with xa and xc are refined (``_refine``) and their branches pushed — the pair of
    roots inside one sample interval that no sample sees.  It stops without a root where
    ``_low`` no longer holds for the shrunk bracket or it is narrower than :data:`_DIP_TOL`;
    a minimum then within :data:`_TOUCH` of zero (the error touching zero) seeds a Newton
    polish of the whole arm.  Returns the new branch count."""
    sg = 1.0 if eb > 0.0 else -1.0
    fa, fb, fc = sg * ea, sg * eb, sg * ec
    gold = 0.381966011250105
    for it in range(_DIP_ITERS):
        if xc - xa <= _DIP_TOL or not _low(xa, xb, xc, fa, fb, fc):
            break  # no zero can hide in [xa, xc] any more
        # the vertex of the parabola through (a, fa), (b, fb), (c, fc)
        u1, u2 = (xb - xa) * (fb - fc), (xb - xc) * (fb - fa)
        den = 2.0 * (u1 - u2)
        ok = den != 0.0
        if ok:
            xu = xb - ((xb - xa) * u1 - (xb - xc) * u2) / den
            m = 0.05 * min(xb - xa, xc - xb)
            ok = xa + m < xu < xc - m and abs(xu - xb) > 0.25 * _DIP_TOL and it % 4 != 3
        if not ok:  # golden section of the larger side
            xu = xb + gold * (xc - xb) if xc - xb > xb - xa else xb - gold * (xb - xa)
        if xu < xb:
            eu, ru = _follow(cls, h, PP, R06, p16, xu, xa, xb, ra, rb, th, e, t2)
        else:
            eu, ru = _follow(cls, h, PP, R06, p16, xu, xb, xc, rb, rc, th, e, t2)
        if not math.isfinite(eu):
            return n  # the root is lost (a fold): not a dip
        fu = sg * eu
        if fu <= 0.0:
            # a sign change: a root on either side of xu (one where fu is exactly 0)
            if fu == 0.0:
                out[0], out[1], out[2], out[3], out[4] = xu, ru[0], ru[1], ru[2], 0.0
                return _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, J, F))
            if _refine(cls, h, PP, R06, p16, xa, xu, ea, eu, ra, ru, th, e, t2, out):
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, J, F))
            if _refine(cls, h, PP, R06, p16, xu, xc, eu, ec, ru, rc, th, e, t2, out):
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, J, F))
            return n
        if fu < fb:
            if xu < xb:
                xc, fc, ec, rc = xb, fb, eb, rb
            else:
                xa, fa, ea, ra = xb, fb, eb, rb
            xb, fb, eb, rb = xu, fu, eu, ru
        elif xu < xb:
            xa, fa, ea, ra = xu, fu, eu, ru
        else:
            xc, fc, ec, rc = xu, fu, eu, ru
    if fb <= _TOUCH:
        _assemble(cls, h, PP, R06, p16, wrap(xb), rb[0], rb[1], rb[2], q)
        if polish(h, PP, R06, p, q, _POLISH_1D, J, F):
            n = _push(Q, V, E, n, q, True)
    return n


@kernel
def _dips(
    cls,
    h,
    PP,
    R06,
    p,
    p16,
    RS0,
    ES0,
    CS0,
    i0,
    x0,
    RS1,
    ES1,
    CS1,
    i1,
    x1,
    RS2,
    ES2,
    CS2,
    i2,
    x2,
    th,
    e,
    t2,
    out,
    q,
    q2,
    J,
    F,
    Q,
    V,
    E,
    n,
):
    """Every dip of the error at sample ``i1`` of RS1, ES1, CS1 (angle ``x1``) between its
    neighbours, sample ``i0`` of RS0, … (angle ``x0`` < x1) and sample ``i2`` of RS2, … (angle
    ``x2`` > x1): a root there followed to both (nearest, closer than :data:`_MATCH`) whose |e|
    is the smallest of the three, all of one sign, and low enough that a zero may hide next to
    it (:func:`_low`) — searched by ``_dip``.  Returns the new branch count."""
    for t in range(CS1[i1]):
        eb = ES1[i1, t]
        rb = (RS1[i1, t, 0], RS1[i1, t, 1], RS1[i1, t, 2])
        k0, d0 = _nearest(RS0, CS0, i0, rb)
        k2, d2 = _nearest(RS2, CS2, i2, rb)
        if not (d0 < _MATCH and d2 < _MATCH) or eb == 0.0:
            continue
        ea, ec = ES0[i0, k0], ES2[i2, k2]
        sg = 1.0 if eb > 0.0 else -1.0
        fa, fb, fc = sg * ea, sg * eb, sg * ec
        if not (fa > 0.0 and fc > 0.0 and fb <= fa and fb <= fc) or not _low(
            x0, x1, x2, fa, fb, fc
        ):
            continue
        n = _dip(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            x0,
            x1,
            x2,
            ea,
            eb,
            ec,
            (RS0[i0, k0, 0], RS0[i0, k0, 1], RS0[i0, k0, 2]),
            rb,
            (RS2[i2, k2, 0], RS2[i2, k2, 1], RS2[i2, k2, 2]),
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
    return n


@kernel
def _copy_sample(RS, ES, CS, i, RD, ED, CD, j):
    """Copy sample ``i`` of RS, ES, CS into slot ``j`` of RD, ED, CD."""
    CD[j] = CS[i]
    for r in range(4):
        ED[j, r] = ES[i, r]
        for c in range(3):
            RD[j, r, c] = RS[i, r, c]


@kernel
def _look(
    cls,
    h,
    PP,
    R06,
    p,
    p16,
    xa,
    xb,
    u,
    deeper,
    X2,
    RS2,
    ES2,
    CS2,
    FL,
    NR,
    NE,
    NC,
    NX,
    S1,
    DM,
    FM,
    SX,
    SR,
    ns,
    th,
    e,
    t2,
    out,
    q,
    q2,
    J,
    F,
    Q,
    V,
    E,
    n,
):
    """A finer look at the interval [xa, xb]: its samples X2 = xa + (xb − xa) ``u`` (roots RS2,
    errors ES2, counts CS2), the brackets and dips of them, the dips at both ends (with the
    samples next to the interval: slot 0 (left, angle NX[0]) and 1 (right, NX[1]) of NR, NE,
    NC) and the fold seeds (appended to SX, SR, ``ns`` of them).  Where ``deeper``, an interval
    of it where the number of roots is unchanged but a followed root moves by more than
    :data:`_JUMP` (the finer samples still do not resolve the roots there: two folds of the inner
    subproblem inside it, the root running back and forth, or a root turning fast past a near
    singularity) is flagged in FL for a finer look again, and its brackets and the dips at its
    ends are left to that.  Returns (the new branch count, the new seed count)."""
    L2 = len(u)
    for i in range(L2):
        X2[i] = xa + (xb - xa) * u[i]
    X2[L2 - 1] = xb
    _sample(cls, h, PP, R06, p16, X2, RS2, ES2, CS2, t2)
    for g2 in range(L2 - 1):
        _interval(RS2, CS2, g2, S1, DM)
        fast = False
        if deeper and CS2[g2] == CS2[g2 + 1]:
            for s in range(CS2[g2]):
                fast = fast or DM[s] > _JUMP
        FL[g2] = fast
        if not fast:
            n = _brackets(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                X2,
                RS2,
                ES2,
                CS2,
                g2,
                S1,
                DM,
                th,
                e,
                t2,
                out,
                q,
                q2,
                J,
                F,
                Q,
                V,
                E,
                n,
            )
        if g2 > 0 and not FL[g2 - 1] and not fast:
            n = _dips(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                RS2,
                ES2,
                CS2,
                g2 - 1,
                X2[g2 - 1],
                RS2,
                ES2,
                CS2,
                g2,
                X2[g2],
                RS2,
                ES2,
                CS2,
                g2 + 1,
                X2[g2 + 1],
                th,
                e,
                t2,
                out,
                q,
                q2,
                J,
                F,
                Q,
                V,
                E,
                n,
            )
        if CS2[g2] != CS2[g2 + 1]:
            # fold seeds: on the side with more roots, those with a small error, and all those
            # nearest to no root of the other side (the pair that meets at the fold) where
            # their errors differ in sign (a root on the arc through the fold)
            side = g2 if CS2[g2] > CS2[g2 + 1] else g2 + 1
            other = g2 + 1 if side == g2 else g2
            for j in range(4):
                FM[j] = True
            for t in range(CS2[other]):
                k, _ = _nearest(
                    RS2, CS2, side, (RS2[other, t, 0], RS2[other, t, 1], RS2[other, t, 2])
                )
                FM[k] = False
            pos = neg_ = False
            for j in range(CS2[side]):
                if FM[j]:
                    pos = pos or ES2[side, j] > 0.0
                    neg_ = neg_ or ES2[side, j] < 0.0
            for j in range(CS2[side]):
                if (abs(ES2[side, j]) < _SEED or (FM[j] and pos and neg_)) and ns < _MAX_SEEDS:
                    SX[ns] = X2[side]
                    SR[ns, 0], SR[ns, 1], SR[ns, 2] = (
                        RS2[side, j, 0],
                        RS2[side, j, 1],
                        RS2[side, j, 2],
                    )
                    ns += 1
    # the ends of the finer look, between its next samples and the samples beyond it
    if not FL[0]:
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            NR,
            NE,
            NC,
            0,
            NX[0],
            RS2,
            ES2,
            CS2,
            0,
            X2[0],
            RS2,
            ES2,
            CS2,
            1,
            X2[1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
    if not FL[L2 - 2]:
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            RS2,
            ES2,
            CS2,
            L2 - 2,
            X2[L2 - 2],
            RS2,
            ES2,
            CS2,
            L2 - 1,
            X2[L2 - 1],
            NR,
            NE,
            NC,
            1,
            NX[1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
    return n, ns


@kernel
def _search_1d_pose(cls, h, PP, R06, p, Q, V, E, grid):
    """Every branch of one pose of a 1-D search class into Q (16, 6), V, E; returns their
    number."""
    p16 = sub(sub(p, mv(R06, PP[6])), PP[0])
    L = grid + 1
    step = 2.0 * math.pi / grid
    X = np.empty(L)
    for i in range(L):
        X[i] = i * step - math.pi
    X[L - 1] = math.pi
    RS, ES, CS = np.zeros((L, 4, 3)), np.full((L, 4), math.nan), np.zeros(L, dtype=np.int64)
    t2, th, e = np.empty((4, 2)), np.empty((4, 3)), np.empty(4)
    S1, DM = np.zeros(4, dtype=np.int64), np.zeros(4)
    out, q, q2 = np.empty(5), np.empty(6), np.empty(6)
    J, F = np.empty((6, 6)), np.empty(6)
    _sample(cls, h, PP, R06, p16, X, RS, ES, CS, t2)
    fine = np.zeros(grid, dtype=np.bool_)
    n = 0
    for g in range(grid):
        fine[g] = _interval(RS, CS, g, S1, DM)
        if fine[g]:
            continue  # its brackets come from the finer look
        n = _brackets(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            X,
            RS,
            ES,
            CS,
            g,
            S1,
            DM,
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
    # dips at the samples between two plain intervals (sample 0 ≡ L − 1: its left neighbour is L − 2)
    for g in range(grid):
        gl = g - 1 if g > 0 else grid - 1
        if fine[gl] or fine[g]:
            continue
        il, xl = (g - 1, X[g - 1]) if g > 0 else (L - 2, X[L - 2] - 2.0 * math.pi)
        n = _dips(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            RS,
            ES,
            CS,
            il,
            xl,
            RS,
            ES,
            CS,
            g,
            X[g],
            RS,
            ES,
            CS,
            g + 1,
            X[g + 1],
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
    # the finer looks: 2 _SUB + 1 points crowded quadratically towards both ends, at up to
    # _DEPTH levels (level d + 1 looks again at the flagged intervals of level d, depth first)
    L2 = 2 * _SUB + 1
    u = np.empty(L2)
    for i in range(_SUB + 1):
        u[i] = (i / _SUB) ** 2 / 2.0
    for i in range(_SUB):
        u[_SUB + 1 + i] = 1.0 - u[_SUB - 1 - i]
    XL = np.empty((_DEPTH, L2))
    RSL, ESL = np.zeros((_DEPTH, L2, 4, 3)), np.full((_DEPTH, L2, 4), math.nan)
    CSL, FL = np.zeros((_DEPTH, L2), dtype=np.int64), np.zeros((_DEPTH, L2 - 1), dtype=np.bool_)
    # the samples next to each level's interval (0: left, 1: right), copied from its parent
    NR, NE = np.zeros((_DEPTH, 2, 4, 3)), np.full((_DEPTH, 2, 4), math.nan)
    NC, NX = np.zeros((_DEPTH, 2), dtype=np.int64), np.empty((_DEPTH, 2))
    pos = np.zeros(_DEPTH, dtype=np.int64)
    SX, SR, FM = np.empty(_MAX_SEEDS), np.empty((_MAX_SEEDS, 3)), np.empty(4, dtype=np.bool_)
    ns = 0
    for g in range(grid):
        if not fine[g]:
            continue
        il, xl = (g - 1, X[g - 1]) if g > 0 else (L - 2, X[L - 2] - 2.0 * math.pi)
        ir, xr = (g + 2, X[g + 2]) if g + 2 < L else (1, X[1] + 2.0 * math.pi)
        _copy_sample(RS, ES, CS, il, NR[0], NE[0], NC[0], 0)
        _copy_sample(RS, ES, CS, ir, NR[0], NE[0], NC[0], 1)
        NX[0, 0], NX[0, 1] = xl, xr
        n, ns = _look(
            cls,
            h,
            PP,
            R06,
            p,
            p16,
            X[g],
            X[g + 1],
            u,
            _DEPTH > 1,
            XL[0],
            RSL[0],
            ESL[0],
            CSL[0],
            FL[0],
            NR[0],
            NE[0],
            NC[0],
            NX[0],
            S1,
            DM,
            FM,
            SX,
            SR,
            ns,
            th,
            e,
            t2,
            out,
            q,
            q2,
            J,
            F,
            Q,
            V,
            E,
            n,
        )
        d = 0
        pos[0] = 0
        while d >= 0:
            k = pos[d]
            while k < L2 - 1 and not FL[d, k]:
                k += 1
            if k >= L2 - 1:
                d -= 1  # every flagged interval of level d done
                continue
            pos[d] = k + 1
            if k > 0:
                _copy_sample(RSL[d], ESL[d], CSL[d], k - 1, NR[d + 1], NE[d + 1], NC[d + 1], 0)
                NX[d + 1, 0] = XL[d, k - 1]
            else:
                _copy_sample(NR[d], NE[d], NC[d], 0, NR[d + 1], NE[d + 1], NC[d + 1], 0)
                NX[d + 1, 0] = NX[d, 0]
            if k + 2 < L2:
                _copy_sample(RSL[d], ESL[d], CSL[d], k + 2, NR[d + 1], NE[d + 1], NC[d + 1], 1)
                NX[d + 1, 1] = XL[d, k + 2]
            else:
                _copy_sample(NR[d], NE[d], NC[d], 1, NR[d + 1], NE[d + 1], NC[d + 1], 1)
                NX[d + 1, 1] = NX[d, 1]
            d += 1
            n, ns = _look(
                cls,
                h,
                PP,
                R06,
                p,
                p16,
                XL[d - 1, k],
                XL[d - 1, k + 1],
                u,
                d + 1 < _DEPTH,
                XL[d],
                RSL[d],
                ESL[d],
                CSL[d],
                FL[d],
                NR[d],
                NE[d],
                NC[d],
                NX[d],
                S1,
                DM,
                FM,
                SX,
                SR,
                ns,
                th,
                e,
                t2,
                out,
                q,
                q2,
                J,
                F,
                Q,
                V,
                E,
                n,
            )
            pos[d] = 0
    for k in range(ns):
        _assemble(cls, h, PP, R06, p16, SX[k], SR[k, 0], SR[k, 1], SR[k, 2], q)
        if polish(h, PP, R06, p, q, _POLISH_1D, J, F):
            n = _push(Q, V, E, n, q, True)
    return n


# ----------------------------------------------------------------------------- 2-D search
@kernel
def _r05(h, q1, q2, t):
    return mm(
        mm(mm(mm(rot(h[0], q1), rot(h[1], q2)), rot(h[2], t[0])), rot(h[3], t[1])), rot(h[4], t[2])
    )


@kernel
def _gen_six_dof_pose(h, PP, R06, p, Q, V, E, grid):
    """Every branch found for one pose of ``gen_six_dof`` into Q (16, 6), V, E; returns their
    number."""
    p16 = sub(sub(p, mv(R06, PP[6])), PP[0])
    h6 = h[5]
    R06h6 = mv(R06, h6)
    # a unit vector ⟂ h6 (h6 × the axis of its smallest component)
    a0, a1, a2 = abs(h6[0]), abs(h6[1]), abs(h6[2])
    ax = (
        (1.0, 0.0, 0.0)
        if a0 <= a1 and a0 <= a2
        else ((0.0, 1.0, 0.0) if a1 <= a2 else (0.0, 0.0, 1.0))
    )
    u = cross(h6, ax)
    u = scale(u, 1.0 / norm(u))
    G2 = grid * grid
    step = 2.0 * math.pi / grid
    xs = np.empty(grid)
    for i in range(grid):
        xs[i] = i * step - math.pi
    GQ, GE, GM = np.zeros((G2, 4, 3)), np.full((G2, 4), math.inf), np.full(G2, math.inf)
    t = np.empty((4, 3))
    for i in range(grid):
        for j in range(grid):
            k = i * grid + j
            q1, q2 = xs[i], xs[j]
            p63 = sub(rotate(neg(h[1]), q2, sub(rotate(neg(h[0]), q1, p16), PP[1])), PP[2])
            cnt, _ = sp5_one(neg(PP[3]), p63, PP[4], PP[5], neg(h[2]), h[3], h[4], TOL_QUARTIC, t)
            for r in range(cnt):
                GQ[k, r, 0], GQ[k, r, 1], GQ[k, r, 2] = t[r, 0], t[r, 1], t[r, 2]
                R05 = _r05(h, q1, q2, (t[r, 0], t[r, 1], t[r, 2]))
                GE[k, r] = norm(sub(mv(R05, h6), R06h6))
                GM[k] = min(GM[k], GE[k, r])
    q = np.empty(6)
    J, F = np.empty((6, 6)), np.empty(6)
    n = 0
    for i in range(grid):
        for j in range(grid):
            k = i * grid + j
            nb = math.inf
            for a in range(-1, 2):
                for b in range(-1, 2):
                    if a != 0 or b != 0:
                        nb = min(nb, GM[((i + a) % grid) * grid + (j + b) % grid])
            for r in range(4):
                if GE[k, r] <= nb and GE[k, r] < _MIN_2D:
                    tr = (GQ[k, r, 0], GQ[k, r, 1], GQ[k, r, 2])
                    R05 = _r05(h, xs[i], xs[j], tr)
                    q6, _, _ = sp1_one(u, mtv(R05, mv(R06, u)), h6, TOL)
                    q[0], q[1], q[2], q[3], q[4], q[5] = xs[i], xs[j], tr[0], tr[1], tr[2], q6
                    if polish(h, PP, R06, p, q, _POLISH_2D, J, F):
                        n = _push(Q, V, E, n, q, True)
    return n


# ----------------------------------------------------------------------------- driver
@kernel
def _search_loop(cls, H, P, R06, p, Q, V, E, grid):
    h, PP = rows6(H), rows7(P)
    for i in range(len(p)):
        Q[i, :, :] = math.nan
        V[i, :] = False
        E[i, :] = False
        R, pp = (vec(R06[i, 0]), vec(R06[i, 1]), vec(R06[i, 2])), vec(p[i])
        if cls == 2:
            _gen_six_dof_pose(h, PP, R, pp, Q[i], V[i], E[i], grid)
        else:
            _search_1d_pose(cls, h, PP, R, pp, Q[i], V[i], E[i], grid)


def solve_search(cls: str, H, P, R06, p, grid: int | None = None):
    """Every branch of the search class ``cls`` (``"two_parallel"``, ``"two_intersecting"``
    or ``"gen_six_dof"``; IK-Geo ``IK_2_parallel``, ``IK_2_intersecting``, ``IK_gen_6_dof``,
    arXiv 2211.05737 §IV) for N poses, in one compiled call.

    ``H`` (6, 3) unit joint axes and ``P`` (7, 3) offsets (m) in IK-Geo's form (base frame,
    q = 0), ``R06`` (N, 3, 3) = R · R_tool(0)ᵀ, ``p`` (N, 3) the tool positions (base frame, m).
    Returns q (N, 16, 6) rad in (−π, π] (NaN where a slot holds no branch), valid (N, 16),
    exact (N, 16) (False: a refined root whose error stayed above :data:`SEARCH_TOL`, or a
    subproblem with only a least-squares answer).  ``grid``: samples of the searched joint
    (default :data:`SEARCH_GRID`; :data:`SEARCH_GRID_2D` per joint for ``gen_six_dof``).
    ``anthroarm.ik.geometric.solve_class`` calls this for these classes (module docstring)."""
    if cls not in CLASSES:
        raise ValueError(f"cls must be one of {CLASSES}, got {cls!r}")
    c = CLASSES.index(cls)
    H = np.ascontiguousarray(H, dtype=float).reshape(6, 3)
    P = np.ascontiguousarray(P, dtype=float).reshape(7, 3)
    R06 = np.ascontiguousarray(R06, dtype=float).reshape(-1, 3, 3)
    p = np.ascontiguousarray(p, dtype=float).reshape(-1, 3)
    if len(R06) != len(p):
        raise ValueError(f"R06 has {len(R06)} poses, p {len(p)}")
    if grid is None:
        grid = SEARCH_GRID_2D if c == 2 else SEARCH_GRID
    n = len(p)
    q = np.empty((n, SEARCH_BRANCHES, 6))
    valid = np.empty((n, SEARCH_BRANCHES), bool)
    exact = np.empty((n, SEARCH_BRANCHES), bool)
    _search_loop(c, H, P, R06, p, q, valid, exact, int(grid))
    return q, valid, exact & valid


__all__ = [
    "CLASSES",
    "SEARCH_BRANCHES",
    "SEARCH_GRID",
    "SEARCH_GRID_2D",
    "SEARCH_TOL",
    "fk_geo",
    "polish",
    "pose_error",
    "solve6",
    "solve_search",
]
