"""Joint angles shifted by whole turns into the joint limits (one angle, a branch row, a batch):
the 2π freedom of a revolute joint, resolved as :func:`anthroarm.ik.closed_form.analytic`
returns its solutions."""

from __future__ import annotations

import math

import numpy as np

from ...jit import kernel
from ..vec3 import wrap


# ----------------------------------------------------------------------------- one call: pose → verified branches
@kernel
def into_limit(x, lo, hi):
    """The angle x (rad) shifted by a multiple of 2π into [lo, hi] (a continuous joint, ±inf:
    into (−π, π]): of the values x + 2πk inside the limits, the one nearest 0 (a UR joint of
    ±2π keeps 0.4, not 0.4 − 2π); a value within 1e-9 rad outside a limit is put onto it.
    Returns (the angle, whether it is inside); an angle that is not keeps the smallest shifted
    value ≥ the lower limit (the caller may move it along a self-motion,
    :func:`anthroarm.ik.closed_form.analytic`)."""
    lo_j, hi_j = lo - 1e-9, hi + 1e-9
    w = wrap(x)
    best = w if lo_j <= w <= hi_j else math.nan
    k = 1
    while best != best and (w + 2.0 * math.pi * k <= hi_j or w - 2.0 * math.pi * k >= lo_j):
        up, down = w + 2.0 * math.pi * k, w - 2.0 * math.pi * k
        if lo_j <= up <= hi_j:
            best = up
        if lo_j <= down <= hi_j and not (abs(best) <= abs(down)):
            best = down
        k += 1
    if best == best:
        return min(max(best, lo), hi), True
    lo_f = lo if math.isfinite(lo) else -math.pi
    return x - 2.0 * math.pi * math.floor((x - lo_f + 1e-9) / (2.0 * math.pi)), False


@kernel
def into_limit_cs(x, c, s, lo, hi, exists):
    """:func:`into_limit` of an angle x carried with its cosine and sine (c, s): (the angle, its
    cosine, its sine, whether it is inside) — (c, s) kept where the angle returned is x moved
    by whole turns (the same rotation), cos and sin of the angle returned where it was put
    onto a limit (it is then the limit) and the branch ``exists``."""
    if -math.pi < x <= math.pi and lo <= x <= hi:  # the usual case: already the angle returned
        return x, c, s, True
    q, ok = into_limit(x, lo, hi)
    if exists and q != x and (q == lo or q == hi):
        c, s = math.cos(q), math.sin(q)
    return q, c, s, ok


@kernel
def into_limit_rows(Q, QC, QS, V, E, n, lo, hi, IN, CHK):
    """:func:`into_limit_cs` of the candidate branches of one pose in place: rows Q (B, n) (rad)
    with their cosines QC and sines QS, flags V (a candidate) and E (exact); writes IN (every
    joint inside) and CHK (its FK residual is wanted: a candidate inside the limits, or a
    least-squares one, :func:`_fk_residuals`)."""
    for b in range(len(V)):
        inside = True
        for j in range(n):
            Q[b, j], QC[b, j], QS[b, j], ok = into_limit_cs(
                Q[b, j], QC[b, j], QS[b, j], lo[j], hi[j], V[b]
            )
            inside = inside and ok
        IN[b] = inside
        CHK[b] = V[b] and (inside or not E[b])


@kernel
def into_limits(q, n, lo, hi):
    """:func:`into_limit` of the angles q[:n] (rad) in place, limits lo, hi (n,); returns
    whether every joint is inside."""
    inside = True
    for j in range(n):
        q[j], ok = into_limit(q[j], lo[j], hi[j])
        inside = inside and ok
    return inside


@kernel
def _into_limits_rows(Q, lo, hi, inside):
    for i in range(Q.shape[0]):
        inside[i] = into_limits(Q[i], Q.shape[1], lo, hi)


def wrap_into_limits(Q, lo, hi):
    """:func:`into_limits` of every row of Q (..., n) rad (a copy; NaN rows stay NaN): (Q
    shifted, inside (...,))."""
    Q = np.array(Q, dtype=float)
    shape = Q.shape
    Q2 = np.ascontiguousarray(Q.reshape(-1, shape[-1]))
    inside = np.empty(len(Q2), dtype=bool)
    _into_limits_rows(
        Q2, np.ascontiguousarray(lo, dtype=float), np.ascontiguousarray(hi, dtype=float), inside
    )
    return Q2.reshape(shape), inside.reshape(shape[:-1])
