"""Newton steps on the whole arm's pose in IK-Geo's form (its FK, pose error and a 6×6 solve),
and the slots of the branches a search finds."""

from __future__ import annotations

from ...jit import kernel
from ..vec3 import add, cross, mm, mv, rot, sub, transpose, wrap
from .constants import SEARCH_BRANCHES, SEARCH_TOL


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
