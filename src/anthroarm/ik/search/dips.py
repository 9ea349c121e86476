"""The dips of the error along a followed root (a pair of roots inside one sample interval, seen by
no sample): minimised by safeguarded parabolic interpolation until the error changes sign."""

from __future__ import annotations

import math

from ...jit import kernel
from ..classes import search_assemble as _assemble
from ..vec3 import wrap
from .brackets import _follow, _nearest, _refine, _root_branch
from .constants import _DIP, _DIP_ITERS, _DIP_TOL, _MATCH, _POLISH_1D, _TOUCH
from .polish import _push, polish


@kernel
def _low(xa, xb, xc, fa, fb, fc):
    """Whether a zero may hide in the dip fa ≥ fb ≤ fc > 0 at xa < xb < xc: fb is at most
    :data:`_DIP` times the steeper of its two secant slopes times the wider of its two gaps (a
    function that falls no faster than that slope reaches zero within the wider gap; a
    parabola through a pair of roots in one gap, or a V through them, always passes; a smooth
    dip that stays away from zero, |e| large against its variation over a gap, does not)."""
    s = max((fa - fb) / (xb - xa), (fc - fb) / (xc - xb))
    return fb <= _DIP * s * max(xb - xa, xc - xb)


# long: a compiled kernel whose 26 arguments take a line each; the minimisation is one loop
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
    pol,
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
                return _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, pol))
            if _refine(cls, h, PP, R06, p16, xa, xu, ea, eu, ra, ru, th, e, t2, out):
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, pol))
            if _refine(cls, h, PP, R06, p16, xu, xc, eu, ec, ru, rc, th, e, t2, out):
                n = _push(Q, V, E, n, q, _root_branch(cls, h, PP, R06, p, p16, out, q, q2, pol))
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
        if polish(pol, R06, p, q, _POLISH_1D):
            n = _push(Q, V, E, n, q, True)
    return n


# long: a compiled kernel whose 32 arguments take a line each; the body is one loop
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
    pol,
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
            pol,
            Q,
            V,
            E,
            n,
        )
    return n
