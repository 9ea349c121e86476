"""Single-pose closed-form IK in plain Python floats (the fast path of ``aa.ik.analytic``).

The same formulas, branches and branch order as the vectorised general path in
:mod:`anthroarm.ik.closed_form` (see its docstring for the equations of each arm: 6R arm
Eqs. (7-1)–(7-15) corrected, prosthetic arm (7-17)–(7-31) with the robust elbow, planar 2R,
human_arm7 at one swivel angle), written with the ``math`` module for one pose: no numpy
temporaries, cos/sin of a branch pair obtained by symmetry (θ + π, −θ) instead of new calls.

Each kernel returns the candidates as a tree of nested branches and, for every candidate inside
the joint limits, its FK residual from the generated straight-line FK of ``robot.chain``
(:mod:`anthroarm.ik.fk_codegen`, evaluated once per distinct branch prefix): an independent
forward computation of the returned joint values.  A candidate is kept if its code is OK, it
lies inside the limits after the 2π wrap and ``max |FK(q) − T| ≤ tol`` (3×4 pose entries, m for
the position).  Candidates outside the joint limits are pruned before their FK check; the
kernels report the failure code and the residuals of the candidates inside the limits, from
which the caller words the general path's reasons.  Inputs that are not plainly valid never get
here (the caller hands them to the general path, which raises the error).

Frames/units: ``T`` rows of the tool pose in the base frame (m); joint values in rad.
"""

from __future__ import annotations

import math

from .analytic_plan import TWO_PI, WRAP_TOL

_atan2, _sqrt, _cos, _sin = math.atan2, math.sqrt, math.cos, math.sin
_asin, _acos, _floor = math.asin, math.acos, math.floor
PI = math.pi
HALF_PI = 0.5 * math.pi
OK, OUTSIDE, ELBOW, DEGENERATE, OUT_OF_PLANE = 0, 1, 2, 3, 4


def _wrap(q, lo, hi, lo_f):
    """``q`` shifted by a multiple of 2π into [lo, hi] (clipped within ``WRAP_TOL``), or None."""
    qw = q - _floor((q - lo_f + WRAP_TOL) / TWO_PI) * TWO_PI
    if not (lo - WRAP_TOL <= qw <= hi + WRAP_TOL):
        return None
    return lo if qw < lo else (hi if qw > hi else qw)


class Candidates:
    """Kernel output for one pose: ``sols`` list of (branch index, q list, residual) of the
    candidates that passed (code OK, inside the limits, residual ≤ tol), in branch order;
    ``code`` the failure code if no candidate exists at all (else OK); ``singular`` message."""

    __slots__ = ("sols", "code", "singular", "tried")

    def __init__(self, sols, code=OK, singular=None, tried=()):
        self.sols = sols
        self.code = code
        self.singular = singular
        self.tried = tried  # (branch, residual) of every candidate inside the limits


# ---------------------------------------------------------------------------- 6R arm (Fig. 6-3)
def sixr(T, plan, tol, position_only=False):
    """Eqs. (7-1)–(7-15) corrected (ch7 notes §0.4); branches (shoulder, elbow, wrist) as
    ``closed_form.SIXR_BRANCHES``."""
    (ux, _, ax, px), (uy, _, ay, py), (uz, _, az, pz) = T[0], T[1], T[2]
    prm = plan.params
    s0, h2, s3, P = prm["s0"], prm["h2"], prm["s3"], prm["P"]
    dx, dy, dz = px - P * ax, py - P * ay, pz - P * az - s0      # wrist centre D relative to B
    rxy = _sqrt(dx * dx + dy * dy)
    shoulder_sing = rxy < 1e-12
    if shoulder_sing:
        th1a, c1, s1 = 0.0, 1.0, 0.0
    else:
        th1a = _atan2(dy, dx)                                      # (7-2)
        c1, s1 = _cos(th1a), _sin(th1a)
    X = dx * c1 + dy * s1                                         # B of (7-3); −X for θ1 + π
    k = (X * X + dz * dz - h2 * h2 - s3 * s3) / (2.0 * h2 * s3)   # sin θ3, (7-6)
    if abs(k) > 1.0 + 1e-12:
        return Candidates([], OUTSIDE)
    k = 1.0 if k > 1.0 else (-1.0 if k < -1.0 else k)
    ask = _asin(k)
    c3a = _cos(ask)
    lo, hi, lf, fl, fh = plan.lower, plan.upper, plan.lo_f, plan.fast_lo, plan.fast_hi
    st0, st1, st2 = (plan.fk_pos if position_only else plan.fk).scalar
    Tt = (T[0][0], T[0][1], T[0][2], T[0][3], T[1][0], T[1][1], T[1][2], T[1][3],
          T[2][0], T[2][1], T[2][2], T[2][3])
    # elbow: θ3 ∈ {asin k, π − asin k}; the second atan2 of (7-4) per elbow branch
    th3s = (ask, PI - ask)
    phis = (_atan2(-s3 * c3a, h2 + s3 * k), _atan2(s3 * c3a, h2 + s3 * k))
    sols = []
    tried = []
    wrist_sing = False
    for sh in (0, 1):
        if sh == 0:
            th1, C1, S1, Xs = th1a, c1, s1, X
        else:
            th1, C1, S1, Xs = th1a + PI, -c1, -s1, -X
        q1 = (th1 if fl[0] <= th1 <= fh[0] else _wrap(th1, lo[0], hi[0], lf[0]))
        psi = _atan2(dz, Xs)
        ha = C1 * ax + S1 * ay                                    # x1-free parts of C30·a, C30·u
        hu = C1 * ux + S1 * uy
        Mm = S1 * ax - C1 * ay
        Mx1 = S1 * ux - C1 * uy
        fk0 = st0(q1) if q1 is not None else None
        for el in (0, 1):
            th3 = th3s[el]
            th2 = psi - phis[el]                                   # (7-4)
            th23 = th2 + th3
            c23, s23 = _cos(th23), _sin(th23)
            # third and first columns of M = C30 · R (hand): (L, M, N) and (Mx0, Mx1, Mx2)
            L = c23 * ha + s23 * az
            N = s23 * ha - c23 * az
            Mx0 = c23 * hu + s23 * uz
            Mx2 = s23 * hu - c23 * uz
            rho = _sqrt(L * L + Mm * Mm)
            if rho < 1e-12:
                wrist_sing = True
                th4a, c4, s4 = 0.0, 1.0, 0.0
            else:
                th4a = _atan2(Mm, L)                               # (7-8)
                c4, s4 = L / rho, Mm / rho                         # cos, sin of θ4
            if fk0 is None:
                continue
            q2 = (th2 if fl[1] <= th2 <= fh[1] else _wrap(th2, lo[1], hi[1], lf[1]))
            q3 = (th3 if fl[2] <= th3 <= fh[2] else _wrap(th3, lo[2], hi[2], lf[2]))
            if q2 is None or q3 is None:
                continue
            fk1 = st1(fk0, q2, q3)
            base = sh * 4 + el * 2
            # θ5 from N = −cos θ5 (7-12 corrected), θ6 from (7-14); the wrist flip θ4 + π negates
            # c4, s4 and hence exactly the atan2 arguments: θ5 → −θ5, (y6, x6) → (−y6, −x6)
            a5 = c4 * L + s4 * Mm
            th5 = _atan2(a5, -N)
            n5 = _sqrt(a5 * a5 + N * N)
            c5, s5 = -N / n5, a5 / n5
            y6 = s4 * Mx0 - c4 * Mx1
            x6 = c4 * c5 * Mx0 + s4 * c5 * Mx1 + s5 * Mx2
            for wr in (0, 1):
                if wr == 0:
                    th4, th5w, th6 = th4a, th5, _atan2(y6, x6)
                else:
                    th4, th5w, th6 = th4a + PI, -th5, _atan2(-y6, -x6)
                q4 = (th4 if fl[3] <= th4 <= fh[3] else _wrap(th4, lo[3], hi[3], lf[3]))
                q5 = (th5w if fl[4] <= th5w <= fh[4] else _wrap(th5w, lo[4], hi[4], lf[4]))
                q6 = (th6 if fl[5] <= th6 <= fh[5] else _wrap(th6, lo[5], hi[5], lf[5]))
                if q4 is None or q5 is None or q6 is None:
                    continue
                res = st2(fk1, q4, q5, q6, Tt)
                tried.append((base + wr, res))
                if res <= tol:
                    sols.append((base + wr, [q1, q2, q3, q4, q5, q6], res))
    sing = None
    if shoulder_sing:
        sing = "shoulder singularity (wrist centre on the z0 axis: θ1 is free; θ1 = 0 returned)"
    elif wrist_sing:
        sing = "wrist singularity (sin θ5 = 0: only θ4 + θ6 is determined; θ4 = 0 returned)"
    return Candidates(sols, OK, sing, tried)


# ---------------------------------------------------------------------------- prosthetic arm (Fig. 7-2)
def prosthetic(T, plan, tol, position_only=False):
    """Eqs. (7-17)–(7-31) with the robust elbow; branches (elbow root, shoulder, flexion) as
    ``closed_form.PROSTHETIC_BRANCHES``."""
    (l1_, m1, n1, x), (l2_, m2, n2, y), (l3_, m3, n3, z) = T[0], T[1], T[2]
    prm = plan.params
    L1, L2, L3 = prm["L1"], prm["L2"], prm["L3"]
    Wx, Wy, Wz = x - L3 * n1, y - L3 * n2, z - L3 * n3            # step 1: wrist W = C − L3 n
    # sums in the order of the general path's einsum ((x0 + x2) + x1): the elbow below is
    # ill-conditioned near the straight arm, and equal rounding keeps both paths together
    W2 = (Wx * Wx + Wz * Wz) + Wy * Wy
    c4 = (W2 - L1 * L1 - L2 * L2) / (2.0 * L1 * L2)               # (7-24)
    if abs(c4) > 1.0 + 1e-12:
        return Candidates([], OUTSIDE)
    th4p = _acos(1.0 if c4 > 1.0 else (-1.0 if c4 < -1.0 else c4))
    # elbow E: |E| = L1, E·W = h, E·m = g (the two planes of (7-17)); line E0 + t d
    h = 0.5 * (L1 * L1 + W2 - L2 * L2)
    g = (Wx * m1 + Wz * m3) + Wy * m2
    dX, dY, dZ = Wy * m3 - Wz * m2, Wz * m1 - Wx * m3, Wx * m2 - Wy * m1
    dd = (dX * dX + dZ * dZ) + dY * dY
    if dd < 1e-14 * max(W2, 1e-30):
        return Candidates([], DEGENERATE)
    alpha = (h - g * g) / dd
    beta = (W2 * g - g * h) / dd
    E0x, E0y, E0z = alpha * Wx + beta * m1, alpha * Wy + beta * m2, alpha * Wz + beta * m3
    disc = (L1 * L1 - ((E0x * E0x + E0z * E0z) + E0y * E0y)) / dd   # t² of (7-22)
    if disc < -1e-12:
        return Candidates([], ELBOW)
    t = _sqrt(disc) if disc > 0.0 else 0.0
    lo, hi, lf, fl, fh = plan.lower, plan.upper, plan.lo_f, plan.fast_lo, plan.fast_hi
    st0, st1 = (plan.fk_pos if position_only else plan.fk).scalar
    Tt = (l1_, m1, n1, x, l2_, m2, n2, y, l3_, m3, n3, z)
    el_sing = abs(_sin(th4p)) < 1e-12
    s4p = _sin(th4p)
    c4p = _cos(th4p)
    sh_any = False
    sols = []
    tried = []
    # the flexion branches: θ4 = ±θ4p
    flex = ((th4p, c4p, s4p), (-th4p, c4p, -s4p))
    q4s = ((th4p if fl[3] <= th4p <= fh[3] else _wrap(th4p, lo[3], hi[3], lf[3])),
           (-th4p if fl[3] <= -th4p <= fh[3] else _wrap(-th4p, lo[3], hi[3], lf[3])))
    for root in (0, 1):
        tr = t if root == 0 else -t
        Ex, Ey, Ez = E0x + tr * dX, E0y + tr * dY, E0z + tr * dZ
        zx, zy, zz = Ex / L1, Ey / L1, Ez / L1
        mz = -zz
        mz = 1.0 if mz > 1.0 else (-1.0 if mz < -1.0 else mz)
        th2a = _acos(mz)                                           # (7-19)
        rz = _sqrt(zx * zx + zy * zy)
        if rz < 1e-12:
            sh_any = True
            th1a, c1a, s1a = -HALF_PI, 0.0, -1.0
        else:
            th1a = _atan2(zy, zx)                                  # (7-18) with atan2
            c1a, s1a = zx / rz, zy / rz
        c2a, s2a = mz, _sqrt((1.0 - mz) * (1.0 + mz))              # cos, sin of acos(mz)
        ux, uy, uz = (Wx - Ex) / L2, (Wy - Ey) / L2, (Wz - Ez) / L2
        for sh in (0, 1):
            if sh == 0:
                th1, th2, c1, s1, c2, s2 = th1a, th2a, c1a, s1a, c2a, s2a
            else:
                th1, th2, c1, s1, c2, s2 = th1a + PI, -th2a, -c1a, -s1a, c2a, -s2a
            q1 = (th1 if fl[0] <= th1 <= fh[0] else _wrap(th1, lo[0], hi[0], lf[0]))
            q2 = (th2 if fl[1] <= th2 <= fh[1] else _wrap(th2, lo[1], hi[1], lf[1]))
            if q1 is None or q2 is None:                           # prune: outside the limits
                continue
            # R2 = Rz(θ1) Rx90 Rz(θ2) Rx90 = [[c1c2, s1, c1s2], [s1c2, −c1, s1s2], [s2, 0, −c2]]
            a00, a01, a02 = c1 * c2, s1, c1 * s2
            a10, a11, a12 = s1 * c2, -c1, s1 * s2
            a20, a22 = s2, -c2
            # v = R2ᵀ (W − E)/L2 = (s4 s3, −s4 c3, c4)   (7-26)
            v0 = a00 * ux + a10 * uy + a20 * uz
            v1 = a01 * ux + a11 * uy
            fk0 = st0(q1, q2)
            base = root * 4 + sh * 2
            for fx in (0, 1):
                q4 = q4s[fx]
                if q4 is None:
                    continue
                th4, C4, S4 = flex[fx]
                if el_sing:
                    th3, c3, s3 = 0.0, 0.0, 1.0
                else:
                    sg = 1.0 if S4 >= 0 else -1.0
                    y3, x3 = sg * v0, -sg * v1
                    th3 = _atan2(y3, x3)
                    r3 = _sqrt(x3 * x3 + y3 * y3)
                    # hidden +90° of A23: c3 = cos(θ3 + 90°) = −sin θ3, s3 = sin(θ3 + 90°) = cos θ3
                    c3, s3 = (-y3 / r3, x3 / r3) if r3 > 0.0 else (0.0, 1.0)
                q3 = (th3 if fl[2] <= th3 <= fh[2] else _wrap(th3, lo[2], hi[2], lf[2]))
                if q3 is None:
                    continue
                # R3 = R2 R23, R23 = [[c3,0,s3],[s3,0,-c3],[0,1,0]]
                b00 = a00 * c3 + a01 * s3
                b02 = a00 * s3 - a01 * c3
                b10 = a10 * c3 + a11 * s3
                b12 = a10 * s3 - a11 * c3
                b20 = a20 * c3
                b22 = a20 * s3
                # R4 = R3 R34, R34 = [[c4,0,-s4],[s4,0,c4],[0,-1,0]]: columns
                # (b·0 c4 + a·2 s4, −b·2, a·2 c4 − b·0 s4)
                r00 = b00 * C4 + a02 * S4
                r10 = b10 * C4 + a12 * S4
                r20 = b20 * C4 + a22 * S4
                r02 = a02 * C4 - b00 * S4
                r12 = a12 * C4 - b10 * S4
                r22 = a22 * C4 - b20 * S4
                # M = R4ᵀ R (hand) = Rz5 Rx90 Rz6 Rx-90  (7-28); needed: M00, M10, M20, M01, M11
                M01 = r00 * m1 + r10 * m2 + r20 * m3
                M11 = -(b02 * m1 + b12 * m2 + b22 * m3)
                th5 = _atan2(-M01, M11)                            # y column (−s5, c5, 0)
                q5 = (th5 if fl[4] <= th5 <= fh[4] else _wrap(th5, lo[4], hi[4], lf[4]))
                if q5 is None:
                    continue
                n5 = _sqrt(M01 * M01 + M11 * M11)
                c5, s5 = (M11 / n5, -M01 / n5) if n5 > 0.0 else (1.0, 0.0)
                M00 = r00 * l1_ + r10 * l2_ + r20 * l3_
                M10 = -(b02 * l1_ + b12 * l2_ + b22 * l3_)
                M20 = r02 * l1_ + r12 * l2_ + r22 * l3_
                th6 = _atan2(M20, c5 * M00 + s5 * M10)             # (7-30)/(7-31)
                q6 = (th6 if fl[5] <= th6 <= fh[5] else _wrap(th6, lo[5], hi[5], lf[5]))
                if q6 is None:
                    continue
                res = st1(fk0, q3, q4, q5, q6, Tt)
                tried.append((base + fx, res))
                if res <= tol:
                    sols.append((base + fx, [q1, q2, q3, q4, q5, q6], res))
    sing = None
    if sh_any:
        sing = "shoulder singularity (elbow on the vertical axis: θ1 is free; θ1 = -90° returned)"
    elif el_sing:
        sing = "elbow singularity (straight arm, sin θ4 = 0: θ3 + θ5 only determined; θ3 = 0 returned)"
    return Candidates(sols, OK, sing, tried)


# ---------------------------------------------------------------------------- planar 2R (Fig. 7-14)
def planar(T, plan, tol, position_only=False):
    """Two elbow branches ±θ2 (position only: the mechanism has 2 DOF)."""
    x, y, z = T[0][3], T[1][3], T[2][3]
    l1, l2 = plan.params["l1"], plan.params["l2"]
    if abs(x) > 1e-9 * max(l1 + l2, 1.0):
        return Candidates([], OUT_OF_PLANE)
    c2 = (y * y + z * z - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if abs(c2) > 1.0 + 1e-12:
        return Candidates([], OUTSIDE)
    t2 = _acos(1.0 if c2 > 1.0 else (-1.0 if c2 < -1.0 else c2))
    base = _atan2(z, y)
    s2, c2c = _sin(t2), _cos(t2)
    lo, hi, lf, fl, fh = plan.lower, plan.upper, plan.lo_f, plan.fast_lo, plan.fast_hi
    (st0,) = (plan.fk_pos if position_only else plan.fk).scalar
    Tt = (T[0][0], T[0][1], T[0][2], x, T[1][0], T[1][1], T[1][2], y, T[2][0], T[2][1], T[2][2], z)
    sols = []
    tried = []
    for b, (th2, sn) in enumerate(((t2, s2), (-t2, -s2))):
        th1 = base - _atan2(l2 * sn, l1 + l2 * c2c)
        q1 = (th1 if fl[0] <= th1 <= fh[0] else _wrap(th1, lo[0], hi[0], lf[0]))
        q2 = (th2 if fl[1] <= th2 <= fh[1] else _wrap(th2, lo[1], hi[1], lf[1]))
        if q1 is None or q2 is None:
            continue
        res = st0(q1, q2, Tt)
        tried.append((b, res))
        if res <= tol:
            sols.append((b, [q1, q2], res))
    return Candidates(sols, OK, None, tried)


# ---------------------------------------------------------------------------- human arm 7 (§6-3)
def human(T, plan, tol, swivel, position_only=False):
    """human_arm7 at one swivel angle φ (rad): branches (elbow, shoulder, wrist) as
    ``closed_form.HUMAN_BRANCHES``; shoulder R = Rx(q1) Ry(q2) Rz(q3), wrist Rz(q5) Ry(q6) Rx(q7)."""
    (r00, r01, r02, hx), (r10, r11, r12, hy), (r20, r21, r22, hz) = T[0], T[1], T[2]
    prm = plan.params
    l1, l2, l3 = prm["l1"], prm["l2"], prm["l3"]
    Wx, Wy, Wz = hx + l3 * r02, hy + l3 * r12, hz + l3 * r22       # wrist: H = W + R (0, 0, −l3)
    Wn = _sqrt(Wx * Wx + Wy * Wy + Wz * Wz)
    c4 = (Wn * Wn - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if abs(c4) > 1.0 + 1e-12 or Wn < 1e-12:
        return Candidates([], OUTSIDE)
    q4p = _acos(1.0 if c4 > 1.0 else (-1.0 if c4 < -1.0 else c4))
    nx, ny, nz = Wx / Wn, Wy / Wn, Wz / Wn
    # swivel basis: u = −z projected ⊥ n (fallback −y), v = n × u
    ux, uy, uz = nz * nx, nz * ny, -1.0 + nz * nz
    nu = _sqrt(ux * ux + uy * uy + uz * uz)
    if nu < 1e-9:
        ux, uy, uz = ny * nx, -1.0 + ny * ny, ny * nz
        nu = _sqrt(ux * ux + uy * uy + uz * uz)
    ux, uy, uz = ux / nu, uy / nu, uz / nu
    vx, vy, vz = ny * uz - nz * uy, nz * ux - nx * uz, nx * uy - ny * ux
    cc = (l1 * l1 - l2 * l2 + Wn * Wn) / (2.0 * Wn)
    cs, ss = _cos(swivel), _sin(swivel)
    dx, dy, dz = cs * ux + ss * vx, cs * uy + ss * vy, cs * uz + ss * vz
    r2 = l1 * l1 - cc * cc
    r = _sqrt(r2) if r2 > 0.0 else 0.0
    Ex, Ey, Ez = cc * nx + r * dx, cc * ny + r * dy, cc * nz + r * dz   # elbow
    e0x, e0y, e0z = dy * nz - dz * ny, dz * nx - dx * nz, dx * ny - dy * nx   # d × n
    zx, zy, zz = -Ex / l1, -Ey / l1, -Ez / l1
    lo, hi, lf, fl, fh = plan.lower, plan.upper, plan.lo_f, plan.fast_lo, plan.fast_hi
    st0, st1 = (plan.fk_pos if position_only else plan.fk).scalar
    Tt = (r00, r01, r02, hx, r10, r11, r12, hy, r20, r21, r22, hz)
    c4p, s4p = _cos(q4p), _sin(q4p)
    sols = []
    tried = []
    for el in (0, 1):
        if el == 0:
            q4, C4, S4, xx, xy, xz = q4p, c4p, s4p, e0x, e0y, e0z
        else:
            q4, C4, S4, xx, xy, xz = -q4p, c4p, -s4p, -e0x, -e0y, -e0z
        q4w = (q4 if fl[3] <= q4 <= fh[3] else _wrap(q4, lo[3], hi[3], lf[3]))
        if q4w is None:                                           # prune: outside the limits
            continue
        yx, yy, yz = zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx   # ey = ez × ex
        # Rsh columns (ex, ey, ez): R00 = xx, R01 = yx, R02 = zx, R10 = xy, R11 = yy, R12 = zy, R22 = zz
        h = _sqrt(xx * xx + yx * yx)
        # wrist: X = (Rsh Rx(q4))ᵀ R; RW columns: ex, c4 ey + s4 ez, −s4 ey + c4 ez
        wy_x, wy_y, wy_z = C4 * yx + S4 * zx, C4 * yy + S4 * zy, C4 * yz + S4 * zz
        wz_x, wz_y, wz_z = -S4 * yx + C4 * zx, -S4 * yy + C4 * zy, -S4 * yz + C4 * zz
        X00 = xx * r00 + xy * r10 + xz * r20
        X10 = wy_x * r00 + wy_y * r10 + wy_z * r20
        X20 = wz_x * r00 + wz_y * r10 + wz_z * r20
        X21 = wz_x * r01 + wz_y * r11 + wz_z * r21
        X22 = wz_x * r02 + wz_y * r12 + wz_z * r22
        h6 = _sqrt(X21 * X21 + X22 * X22)
        wrists = []
        for wb in (1.0, -1.0):
            wrists.append((_atan2(wb * X10, wb * X00), _atan2(-X20, wb * h6), _atan2(wb * X21, wb * X22)))
        for sh, sb in ((0, 1.0), (1, -1.0)):
            cq2 = sb * h
            q2 = _atan2(zx, cq2)
            if abs(cq2) < 1e-12:                                  # gimbal lock: q1 = 0
                q1, q3 = 0.0, _atan2(xy, yy)
            else:
                q1, q3 = _atan2(-sb * zy, sb * zz), _atan2(-sb * yx, sb * xx)
            w1 = (q1 if fl[0] <= q1 <= fh[0] else _wrap(q1, lo[0], hi[0], lf[0]))
            w2 = (q2 if fl[1] <= q2 <= fh[1] else _wrap(q2, lo[1], hi[1], lf[1]))
            w3 = (q3 if fl[2] <= q3 <= fh[2] else _wrap(q3, lo[2], hi[2], lf[2]))
            if w1 is None or w2 is None or w3 is None:
                continue
            fk0 = st0(w1, w2, w3, q4w)
            base = el * 4 + sh * 2
            for wr in (0, 1):
                q5, q6, q7 = wrists[wr]
                w5 = (q5 if fl[4] <= q5 <= fh[4] else _wrap(q5, lo[4], hi[4], lf[4]))
                w6 = (q6 if fl[5] <= q6 <= fh[5] else _wrap(q6, lo[5], hi[5], lf[5]))
                w7 = (q7 if fl[6] <= q7 <= fh[6] else _wrap(q7, lo[6], hi[6], lf[6]))
                if w5 is None or w6 is None or w7 is None:
                    continue
                res = st1(fk0, w5, w6, w7, Tt)
                tried.append((base + wr, res))
                if res <= tol:
                    sols.append((base + wr, [w1, w2, w3, q4w, w5, w6, w7], res))
    sing = "straight elbow: the swivel angle then turns the elbow axis about the arm" if abs(s4p) < 1e-12 else None
    return Candidates(sols, OK, sing, tried)
