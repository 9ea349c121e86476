"""The 1-D search along the grid: sampling the inner subproblem, following its roots from sample
to sample, and refining each sign change of the error by regula falsi (Illinois)."""

from __future__ import annotations

import math

from ...jit import kernel
from ..classes import search_assemble as _assemble
from ..classes import search_inner as _inner
from ..vec3 import wrap
from .constants import _FAST, _FK_TOL, _ITERS, _MATCH, _POLISH_ROOT, SEARCH_TOL
from .polish import _push, fk_error, polish


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
    cls, h, PP, R06, p, p16, X, RS, ES, CS, g, S1, DM, th, e, t2, out, q, q2, pol, Q, V, E, n
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
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, pol))
    return n


@kernel
def _root_branch(cls, h, PP, R06, p, p16, out, q, q2, pol):
    """The branch at a refined root ``out`` (x, inner root, |e|) into ``q`` (6,); returns
    whether it is exact.  A root whose error stayed above :data:`SEARCH_TOL` (regula falsi
    stalls where two roots share a sample interval), or whose pose error is above
    :data:`_FK_TOL` (|e| ≤ SEARCH_TOL pins the angle only to SEARCH_TOL / |e′|, loose where e
    is flat: at a pair of roots close together), while every subproblem on it was exact gets
    :data:`_POLISH_ROOT` Newton steps on the whole pose (scratch ``q2``), kept where they
    converge (quadratic convergence from a root already good to ~1e-7)."""
    ex = _assemble(cls, h, PP, R06, p16, wrap(out[0]), out[1], out[2], out[3], q)
    if ex and (out[4] > SEARCH_TOL or fk_error(pol, R06, p, q) > _FK_TOL):
        for j in range(6):
            q2[j] = q[j]
        ex = polish(pol, R06, p, q2, _POLISH_ROOT)
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
