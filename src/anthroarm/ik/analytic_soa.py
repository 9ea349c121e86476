"""Batched closed-form IK on a structure of arrays (the fast path of ``aa.ik.analytic_batch``).

The same formulas, branches and branch order as the general path in
:mod:`anthroarm.ik.closed_form` (its docstring lists the equations of each arm), laid out like
:mod:`anthroarm.kinematics.batched`: every pose entry is one contiguous length-N vector, and the
branches are leading axes of size 2 (e.g. the 6R arm's θ1 has shape (2, 1, 1, N), (θ2, θ3)
(2, 2, 1, N), θ4–θ6 (2, 2, 2, N)), so all branches of all poses are computed at once and
shared quantities are computed once per distinct branch prefix.  cos/sin of a branch pair come
from symmetry (θ + π, −θ) or from the atan2 arguments rather than new transcendental calls.

Verification: the generated FK of ``robot.chain`` (:mod:`anthroarm.ik.fk_codegen`) evaluated
on the wrapped joint values with the same broadcasting, an independent forward computation of
every candidate; kept if the code is OK, the candidate lies inside the joint limits and
``max |FK(q) − T| ≤ tol`` (3×4 pose entries; the position only for planar2r).

:func:`solve` returns the raw arrays; :func:`anthroarm.ik.closed_form.analytic_batch` wraps
them into an :class:`~anthroarm.ik.closed_form.AnalyticBatchResult`.  Units: m, rad.
"""

from __future__ import annotations

import numpy as np

from .analytic_plan import TWO_PI, WRAP_TOL
from .fk_codegen import cos_sin

PI = np.pi
HALF_PI = 0.5 * np.pi
OK, OUTSIDE, ELBOW, DEGENERATE, OUT_OF_PLANE = 0, 1, 2, 3, 4


def pose_rows(Ts: np.ndarray) -> np.ndarray:
    """(16, N) contiguous rows of the poses (N, 4, 4): row 4 i + j is entry (i, j)."""
    return np.ascontiguousarray(Ts.reshape(Ts.shape[0], 16).T)


def poses_ok(E: np.ndarray, tol_orthonormal: float, position_only: bool) -> bool:
    """The checks of ``closed_form._check_poses`` on pose rows E (16, N): finite, last row
    [0, 0, 0, 1], rotation orthonormal (|RᵀR − I| ≤ tol) with det ≥ 0."""
    if not np.isfinite(E).all():
        return False
    if (np.abs(E[12:15]).max() > 1e-12) or np.abs(E[15] - 1.0).max() > 1e-12:
        return False
    if position_only:
        return True
    c0, c1, c2 = (E[0], E[4], E[8]), (E[1], E[5], E[9]), (E[2], E[6], E[10])

    def dot(a, b):
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    err = np.abs(dot(c0, c0) - 1.0)
    for d in (np.abs(dot(c1, c1) - 1.0), np.abs(dot(c2, c2) - 1.0),
              np.abs(dot(c0, c1)), np.abs(dot(c0, c2)), np.abs(dot(c1, c2))):
        np.maximum(err, d, out=err)
    det = c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1]) \
        + c2[0] * (c0[1] * c1[2] - c0[2] * c1[1])
    return not ((err > tol_orthonormal) | (det < 0)).any()


def _wrap(q, plan, j):
    """(q wrapped by a multiple of 2π into the limits of joint j and clipped, inside mask or True)."""
    if q.size and plan.fast_lo[j] <= q.min() and q.max() <= plan.fast_hi[j]:
        return q, True                      # the common case: no wrap index, no clipping
    lo, hi = plan.lower[j], plan.upper[j]
    qw = q - np.floor((q - plan.lo_f[j] + WRAP_TOL) / TWO_PI) * TWO_PI
    inside = (qw >= lo - WRAP_TOL) & (qw <= hi + WRAP_TOL)
    np.clip(qw, lo, hi, out=qw)
    return qw, inside


def _where(mask, a, b):
    return np.where(mask, a, b) if mask.any() else b


# ---------------------------------------------------------------------------- 6R arm (Fig. 6-3)
def sixr(E, plan):
    """Branch axes (shoulder, elbow, wrist); Eqs. (7-1)–(7-15) corrected (ch7 notes §0.4)."""
    prm = plan.params
    s0, h2, s3, P = prm["s0"], prm["h2"], prm["s3"], prm["P"]
    ux, uy, uz, ax, ay, az = E[0], E[4], E[8], E[2], E[6], E[10]
    dx, dy, dz = E[3] - P * ax, E[7] - P * ay, E[11] - P * az - s0     # wrist centre D − B
    rxy = np.sqrt(dx * dx + dy * dy)
    ssing = rxy < 1e-12
    th1a = np.arctan2(dy, dx)                                            # (7-2)
    rs = np.where(ssing, 1.0, rxy)
    c1, s1 = dx / rs, dy / rs
    if ssing.any():
        th1a[ssing], c1[ssing], s1[ssing] = 0.0, 1.0, 0.0
    X = dx * c1 + dy * s1
    k = (X * X + dz * dz - h2 * h2 - s3 * s3) / (2.0 * h2 * s3)          # sin θ3, (7-6)
    code = np.where(np.abs(k) > 1.0 + 1e-12, OUTSIDE, OK)
    np.clip(k, -1.0, 1.0, out=k)
    ask = np.arcsin(k)
    c3a = np.sqrt((1.0 - k) * (1.0 + k))                                 # cos(asin k) ≥ 0, accurate at |k| → 1
    th3 = np.stack([ask, PI - ask])[None]                                # (1, 2, N) elbow up/down
    hk = h2 + s3 * k
    phi = np.stack([np.arctan2(-s3 * c3a, hk), np.arctan2(s3 * c3a, hk)])[None]
    psi = np.stack([np.arctan2(dz, X), np.arctan2(dz, -X)])[:, None]
    th2 = psi - phi                                                      # (7-4), (2, 2, N)
    C1 = np.stack([c1, -c1])[:, None]                                    # θ1 + π: (2, 1, N)
    S1 = np.stack([s1, -s1])[:, None]
    th23 = th2 + th3
    c23, s23 = cos_sin(th23)
    ha = C1 * ax + S1 * ay
    hu = C1 * ux + S1 * uy
    Mm = S1 * ax - C1 * ay                                               # (L, M, N) of (7-8)
    Mx1 = S1 * ux - C1 * uy
    L = c23 * ha + s23 * az
    Nn = s23 * ha - c23 * az                                             # N = −cos θ5 (7-12)
    Mx0 = c23 * hu + s23 * uz
    Mx2 = s23 * hu - c23 * uz
    rho = np.sqrt(L * L + Mm * Mm)
    wsing = rho < 1e-12
    th4a = np.arctan2(Mm, L)
    rr = np.where(wsing, 1.0, rho)
    c4, s4 = L / rr, Mm / rr
    if wsing.any():
        th4a, c4, s4 = np.where(wsing, 0.0, th4a), np.where(wsing, 1.0, c4), np.where(wsing, 0.0, s4)
    th4 = np.stack([th4a, th4a + PI], 2)                                 # (2, 2, 2, N) wrist flip
    C4 = np.stack([c4, -c4], 2)
    S4 = np.stack([s4, -s4], 2)
    L, Nn, Mm, Mx0, Mx1, Mx2 = (x[:, :, None] for x in (L, Nn, Mm, Mx0, Mx1, Mx2))
    a5 = C4 * L + S4 * Mm
    th5 = np.arctan2(a5, -Nn)                                            # (7-12) corrected
    n5 = np.sqrt(a5 * a5 + Nn * Nn)
    c5, s5 = -Nn / n5, a5 / n5
    th6 = np.arctan2(S4 * Mx0 - C4 * Mx1, c5 * (C4 * Mx0 + S4 * Mx1) + s5 * Mx2)   # (7-14)
    th1 = np.stack([th1a, th1a + PI])[:, None, None]                     # (2, 1, 1, N)
    th2 = th2[:, :, None]                                                # (2, 2, 1, N)
    th3 = np.broadcast_to(th3[:, :, None], th2.shape)
    sing = np.full(E.shape[1], None, dtype=object)
    ws = wsing.reshape(4, -1).any(0)
    sing[ws] = "wrist singularity (sin θ5 = 0: only θ4 + θ6 is determined; θ4 = 0 returned)"
    sing[ssing] = "shoulder singularity (wrist centre on the z0 axis: θ1 is free; θ1 = 0 returned)"
    return [th1, th2, th3, th4, th5, th6], code, sing, (2, 2, 2)


# ---------------------------------------------------------------------------- prosthetic arm (Fig. 7-2)
def prosthetic(E, plan):
    """Branch axes (elbow root, shoulder, flexion); Eqs. (7-17)–(7-31), robust elbow."""
    prm = plan.params
    L1, L2, L3 = prm["L1"], prm["L2"], prm["L3"]
    l1_, l2_, l3_ = E[0], E[4], E[8]
    m1, m2, m3 = E[1], E[5], E[9]
    Wx, Wy, Wz = E[3] - L3 * E[2], E[7] - L3 * E[6], E[11] - L3 * E[10]   # step 1
    # sums in the order of the general path's einsum ((x0 + x2) + x1): the elbow below is
    # ill-conditioned near the straight arm, and equal rounding keeps both paths together
    W2 = (Wx * Wx + Wz * Wz) + Wy * Wy
    c4 = (W2 - L1 * L1 - L2 * L2) / (2.0 * L1 * L2)                      # (7-24)
    code = np.where(np.abs(c4) > 1.0 + 1e-12, OUTSIDE, OK)
    th4p = np.arccos(np.clip(c4, -1.0, 1.0))
    h = 0.5 * (L1 * L1 + W2 - L2 * L2)
    g = (Wx * m1 + Wz * m3) + Wy * m2
    dX, dY, dZ = Wy * m3 - Wz * m2, Wz * m1 - Wx * m3, Wx * m2 - Wy * m1
    dd = (dX * dX + dZ * dZ) + dY * dY
    degen = dd < 1e-14 * np.maximum(W2, 1e-30)
    code[(code == OK) & degen] = DEGENERATE
    dd_s = np.where(degen, 1.0, dd)
    alpha = (h - g * g) / dd_s
    beta = (W2 * g - g * h) / dd_s
    E0x, E0y, E0z = alpha * Wx + beta * m1, alpha * Wy + beta * m2, alpha * Wz + beta * m3
    disc = (L1 * L1 - ((E0x * E0x + E0z * E0z) + E0y * E0y)) / dd_s        # t² of (7-22)
    code[(code == OK) & (disc < -1e-12)] = ELBOW
    t = np.sqrt(np.maximum(disc, 0.0))
    tt = np.stack([t, -t])                                               # elbow roots (2, N)
    Ex, Ey, Ez = E0x + tt * dX, E0y + tt * dY, E0z + tt * dZ
    zx, zy = Ex / L1, Ey / L1
    th2a = np.arccos(np.clip(-Ez / L1, -1.0, 1.0))                        # (7-19)
    shs = np.sqrt(zx * zx + zy * zy) < 1e-12
    th1a = np.arctan2(zy, zx)                                            # (7-18) with atan2
    if shs.any():
        th1a = np.where(shs, -HALF_PI, th1a)
    c1a, s1a = cos_sin(th1a)
    c2a, s2a = cos_sin(th2a)
    th1 = np.stack([th1a, th1a + PI], 1)[:, :, None]                     # (2, 2, 1, N)
    th2 = np.stack([th2a, -th2a], 1)[:, :, None]
    c1 = np.stack([c1a, -c1a], 1)
    s1 = np.stack([s1a, -s1a], 1)
    c2 = np.stack([c2a, c2a], 1)
    s2 = np.stack([s2a, -s2a], 1)
    # R2 = Rz(θ1) Rx90 Rz(θ2) Rx90 and v = R2ᵀ (W − E)/L2 = (s4 s3, −s4 c3, c4)   (7-26)
    ux, uy, uz = ((Wx - Ex) / L2)[:, None], ((Wy - Ey) / L2)[:, None], ((Wz - Ez) / L2)[:, None]
    a00, a01, a02 = c1 * c2, s1, c1 * s2
    a10, a11, a12 = s1 * c2, -c1, s1 * s2
    a20, a22 = s2, -c2
    v0 = a00 * ux + a10 * uy + a20 * uz                                  # (2, 2, N)
    v1 = a01 * ux + a11 * uy
    sg = np.array([1.0, -1.0])[:, None]                                  # sign of sin θ4 per flexion
    C4, s4p = cos_sin(th4p)
    els = np.abs(s4p) < 1e-12
    v0e, v1e = v0[:, :, None], v1[:, :, None]
    th3 = np.arctan2(sg * v0e, -sg * v1e)                                # (2, 2, 2, N)
    if els.any():
        th3 = np.where(els, 0.0, th3)
    # (θ4p = 0, where sin(−θ4p) = −0.0 counts as ≥ 0, lies inside the elbow singularity: θ3 = 0)
    s3, c3 = cos_sin(th3)                                                # cos/sin(θ3 + 90°) = (−sin θ3, cos θ3)
    c3 = -c3
    S4 = s4p * sg                                                        # (2, N)
    a00, a01, a02, a10, a11, a12, a20, a22 = (x[:, :, None] for x in (a00, a01, a02, a10, a11, a12, a20, a22))
    b00 = a00 * c3 + a01 * s3
    b02 = a00 * s3 - a01 * c3
    b10 = a10 * c3 + a11 * s3
    b12 = a10 * s3 - a11 * c3
    b20 = a20 * c3
    b22 = a20 * s3
    r00 = b00 * C4 + a02 * S4
    r10 = b10 * C4 + a12 * S4
    r20 = b20 * C4 + a22 * S4
    r02 = a02 * C4 - b00 * S4
    r12 = a12 * C4 - b10 * S4
    r22 = a22 * C4 - b20 * S4
    # M = R4ᵀ R (hand) = Rz5 Rx90 Rz6 Rx-90 (7-28); R4 column 1 = −(b02, b12, b22)
    M01 = r00 * m1 + r10 * m2 + r20 * m3
    M11 = -(b02 * m1 + b12 * m2 + b22 * m3)
    th5 = np.arctan2(-M01, M11)
    n5 = np.sqrt(M01 * M01 + M11 * M11)
    n5 = np.where(n5 == 0.0, 1.0, n5)
    c5, s5 = M11 / n5, -M01 / n5
    zero5 = (M01 == 0.0) & (M11 == 0.0)
    if zero5.any():                                                      # atan2(0, 0) = 0
        c5, s5 = np.where(zero5, 1.0, c5), np.where(zero5, 0.0, s5)
    M00 = r00 * l1_ + r10 * l2_ + r20 * l3_
    M10 = -(b02 * l1_ + b12 * l2_ + b22 * l3_)
    M20 = r02 * l1_ + r12 * l2_ + r22 * l3_
    th6 = np.arctan2(M20, c5 * M00 + s5 * M10)                           # (7-30)/(7-31)
    th4 = np.broadcast_to(np.stack([th4p, -th4p]), th3.shape)
    sing = np.full(E.shape[1], None, dtype=object)
    sing[els] = "elbow singularity (straight arm, sin θ4 = 0: θ3 + θ5 only determined; θ3 = 0 returned)"
    sing[shs.any(0)] = "shoulder singularity (elbow on the vertical axis: θ1 is free; θ1 = -90° returned)"
    return [th1, th2, th3, th4, th5, th6], code, sing, (2, 2, 2)


# ---------------------------------------------------------------------------- planar 2R (Fig. 7-14)
def planar(E, plan):
    l1, l2 = plan.params["l1"], plan.params["l2"]
    x, y, z = E[3], E[7], E[11]
    c2 = (y * y + z * z - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    code = np.where(np.abs(c2) > 1.0 + 1e-12, OUTSIDE, OK)
    code[np.abs(x) > 1e-9 * max(l1 + l2, 1.0)] = OUT_OF_PLANE
    t2 = np.arccos(np.clip(c2, -1.0, 1.0))
    c2c, s2 = cos_sin(t2)
    base = np.arctan2(z, y)
    th2 = np.stack([t2, -t2])
    th1 = np.stack([base - np.arctan2(l2 * s2, l1 + l2 * c2c), base - np.arctan2(-l2 * s2, l1 + l2 * c2c)])
    return [th1, th2], code, np.full(E.shape[1], None, dtype=object), (2,)


# ---------------------------------------------------------------------------- human arm 7 (§6-3)
def human(E, plan, swivel):
    """Branch axes (swivel S, elbow, shoulder, wrist); ``swivel`` (N, S) rad."""
    prm = plan.params
    l1, l2, l3 = prm["l1"], prm["l2"], prm["l3"]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = E[0], E[1], E[2], E[4], E[5], E[6], E[8], E[9], E[10]
    Wx, Wy, Wz = E[3] + l3 * r02, E[7] + l3 * r12, E[11] + l3 * r22     # wrist: H = W + R (0, 0, −l3)
    Wn = np.sqrt(Wx * Wx + Wy * Wy + Wz * Wz)
    c4 = (Wn * Wn - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    code = np.where((np.abs(c4) > 1.0 + 1e-12) | (Wn < 1e-12), OUTSIDE, OK)
    q4p = np.arccos(np.clip(c4, -1.0, 1.0))
    Wd = np.where(Wn > 1e-12, Wn, 1.0)
    nx, ny, nz = Wx / Wd, Wy / Wd, Wz / Wd
    ux, uy, uz = nz * nx, nz * ny, nz * nz - 1.0                          # −z projected ⊥ n
    nu = np.sqrt(ux * ux + uy * uy + uz * uz)
    vert = nu < 1e-9
    if vert.any():                                                       # fallback −y
        ux, uy, uz = np.where(vert, ny * nx, ux), np.where(vert, ny * ny - 1.0, uy), np.where(vert, ny * nz, uz)
        nu = np.sqrt(ux * ux + uy * uy + uz * uz)
    ux, uy, uz = ux / nu, uy / nu, uz / nu
    vx, vy, vz = ny * uz - nz * uy, nz * ux - nx * uz, nx * uy - ny * ux
    cc = np.where(Wn > 1e-12, (l1 * l1 - l2 * l2 + Wn * Wn) / (2.0 * Wd), 0.0)
    r = np.sqrt(np.maximum(l1 * l1 - cc * cc, 0.0))
    sw = np.ascontiguousarray(swivel.T)                                  # (S, N)
    cs, ss = cos_sin(sw)
    dx, dy, dz = cs * ux + ss * vx, cs * uy + ss * vy, cs * uz + ss * vz
    Ex, Ey, Ez = cc * nx + r * dx, cc * ny + r * dy, cc * nz + r * dz
    e0x, e0y, e0z = dy * nz - dz * ny, dz * nx - dx * nz, dx * ny - dy * nx   # d × n   (S, N)
    zx, zy, zz = -Ex / l1, -Ey / l1, -Ez / l1
    sg = np.array([1.0, -1.0])[:, None]                                   # elbow axis (2, 1)
    zx, zy, zz = zx[:, None], zy[:, None], zz[:, None]                   # (S, 1, N)
    xx, xy, xz = sg * e0x[:, None], sg * e0y[:, None], sg * e0z[:, None]   # (S, 2, N)
    yx, yy, yz = zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx
    # shoulder XYZ Euler, two branches (cos q2 > 0 / < 0): axis 2 of (S, 2, 2, N)
    sb = np.array([1.0, -1.0])[:, None]
    h = np.sqrt(xx * xx + yx * yx)[:, :, None]                           # (S, 2, 1, N)
    cq2 = sb * h                                                          # (S, 2, 2, N)
    zxe, zye, zze = zx[:, :, None], zy[:, :, None], zz[:, :, None]
    q2 = np.arctan2(np.broadcast_to(zxe, cq2.shape), cq2)
    q1 = np.arctan2(-sb * zye, sb * zze)
    q3 = np.arctan2(-sb * yx[:, :, None], sb * xx[:, :, None])
    gl = np.abs(cq2) < 1e-12
    if gl.any():                                                         # gimbal lock: q1 = 0
        q1 = np.where(gl, 0.0, q1)
        q3 = np.where(gl, np.arctan2(xy, yy)[:, :, None], q3)
    # wrist: X = (Rsh Rx(q4))ᵀ R = Rz(q5) Ry(q6) Rx(q7), per elbow (S, 2, N)
    C4, s4p = cos_sin(q4p)
    S4 = sg * s4p                                                        # (2, N)
    wyx, wyy, wyz = C4 * yx + S4 * zx, C4 * yy + S4 * zy, C4 * yz + S4 * zz
    wzx, wzy, wzz = C4 * zx - S4 * yx, C4 * zy - S4 * yy, C4 * zz - S4 * yz
    X00 = xx * r00 + xy * r10 + xz * r20
    X10 = wyx * r00 + wyy * r10 + wyz * r20
    X20 = wzx * r00 + wzy * r10 + wzz * r20
    X21 = wzx * r01 + wzy * r11 + wzz * r21
    X22 = wzx * r02 + wzy * r12 + wzz * r22
    h6 = np.sqrt(X21 * X21 + X22 * X22)
    wb = sb                                                              # wrist branch (2, 1)
    X00, X10, X20, X21, X22, h6 = (x[:, :, None, None] for x in (X00, X10, X20, X21, X22, h6))
    q5 = np.arctan2(wb * X10, wb * X00)                                  # (S, 2, 1, 2, N)
    q6 = np.arctan2(np.broadcast_to(-X20, q5.shape), wb * h6)
    q7 = np.arctan2(wb * X21, wb * X22)
    S = sw.shape[0]
    q1, q2, q3 = (x[:, :, :, None] for x in (q1, q2, q3))               # (S, 2, 2, 1, N)
    q4 = np.stack([q4p, -q4p])[None, :, None, None]                      # (1, 2, 1, 1, N)
    sing = np.full(E.shape[1], None, dtype=object)
    sing[np.abs(s4p) < 1e-12] = "straight elbow: the swivel angle then turns the elbow axis about the arm"
    return [q1, q2, q3, q4, q5, q6, q7], code, sing, (S, 2, 2, 2)


#: poses per chunk: the temporaries of one chunk (8 branches × 2048 × 8 B = 128 kB each) stay in
#: the CPU caches; whole 10 000-pose arrays do not, and the FK check runs about 2× slower
CHUNK = 2048


def solve(plan, E, tol, position_only, swivel=None):
    """Candidates, verification and validity of N poses (rows E (16, N)), in chunks of
    :data:`CHUNK` poses.

    Returns ``(Q, valid, code, inside, res, sing, bshape)``: Q (N, B, nq) wrapped joint values,
    valid (N, B), code (N, B), inside (N, B), res (N, B) FK residuals, sing (N,) messages,
    bshape the branch axes (B = their product, in the order of the branch labels)."""
    N = E.shape[1]
    out = None
    for a in range(0, N, CHUNK):
        b = min(N, a + CHUNK)
        part = _solve_chunk(plan, E[:, a:b] if (a, b) != (0, N) else E, tol, position_only,
                            None if swivel is None else swivel[a:b])
        if (a, b) == (0, N):
            return part
        if out is None:
            out = [np.empty((N,) + x.shape[1:], x.dtype) for x in part[:6]]
        for o, x in zip(out, part[:6]):
            o[a:b] = x
    return (*out, part[6])


#: the kernel of each closed-form family (models.closed_forms names the arms of each)
KERNELS = {"spherical_wrist_6r": sixr, "prosthetic_6r": prosthetic, "planar_2r": planar}


def _solve_chunk(plan, E, tol, position_only, swivel):
    if plan.form.swivel:
        qs, code, sing, bshape = human(E, plan, swivel)
    else:
        qs, code, sing, bshape = KERNELS[plan.family](E, plan)
    N = E.shape[1]
    full = bshape + (N,)
    wrapped, inside = [], None
    for j, q in enumerate(qs):
        qw, ins = _wrap(q, plan, j)
        wrapped.append(qw)
        if ins is not True:
            inside = ins if inside is None else inside & ins
    fk = plan.fk_pos if position_only else plan.fk
    bounds = [0, *fk.splits, plan.nq]
    Trows = tuple(E[4 * i + j] for i in range(3) for j in range(4))
    st = None
    last = fk.n_stages - 1
    for k, f in enumerate(fk.numpy):
        args = wrapped[bounds[k]:bounds[k + 1]]
        if k > 0:
            args = [st, *args]
        if k == last:
            args = [*args, Trows]
        st = f(*args)
    res = np.broadcast_to(st, full)
    valid = res <= tol                                                   # NaN compares False
    valid &= (code == OK)
    if inside is not None:
        valid &= inside
    B = int(np.prod(bshape))
    Q = np.empty((N, B, len(qs)))                                        # (nq, B, N) -> (N, B, nq)
    for j, qw in enumerate(wrapped):
        Q[:, :, j] = np.broadcast_to(qw, full).reshape(B, N).T
    valid = valid.reshape(B, N).T
    res = res.reshape(B, N).T
    ins = np.ones((N, B), bool) if inside is None else np.broadcast_to(inside, full).reshape(B, N).T
    code = np.broadcast_to(code, full).reshape(B, N).T
    return Q, valid, code, ins, res, sing, bshape
