"""Muscle paths over a ``WrapEllipsoid``: OpenSim 4's algorithm, with the exact derivative.

``ellipsoid`` reproduces ``WrapEllipsoid::wrapLine`` (opensim-core,
``OpenSim/Simulation/Wrap/WrapEllipsoid.cpp``, read to understand and rewritten here), the
method of Garner & Pandy, *The Obstacle-Set Method for Representing Muscle Paths in
Musculoskeletal Models*, Comput Methods Biomech Biomed Engin 3 (2000) 1-30, as SIMM implements
it (Delp & Loan 1995, *A graphics-based software system to develop and analyze models of
musculoskeletal structures*, Comput Biol Med 25(1) 21-34):

1. coordinates scaled by 3 / (a + b + c); either end point inside the ellipsoid: no wrap
   (``INSIDE``); the straight segment must cross the ellipsoid, else no wrap;
2. the wrapping plane: through both end points and a surface point c₁ found by "Frans'
   technique" (the closest surface point to where the segment crosses the coordinate plane
   most normal to it), by the "fan" (the mean direction from 298 points of the chord to their
   closest surface points), or by a blend of the two (``hybrid``: |cos| of the segment with its
   most parallel axis between 0.7073 and 0.9), or the chord's midpoint (``midpoint``); closest
   surface points by the Graphics Gems IV point-to-ellipsoid iteration (Hart, *Distance to an
   ellipsoid*, Graphics Gems IV, 1994, 113-119); a one-sided ``quadrant`` mirrors c₁ onto the
   allowed side;
3. the tangent points r₁, r₂: on the ellipsoid, in the plane, with the line from the end point
   tangent (the end point on the tangent plane at rᵢ);
4. the surface path: the plane's section of the ellipsoid between r₁ and r₂, a polyline of
   ⌊|r₁ − r₂| / 1 mm⌋ chords (at most 499) whose vertices are rays from the point where the
   plane meets the coordinate axis most normal to it, at equal angles; far side when a
   one-sided wrap would otherwise leave the end points the wrong way.

Differences from OpenSim, on purpose: OpenSim stops its Levenberg-Marquardt search for the
tangent points when the squared residual falls below 1e-8 (scaled units) and its
point-to-ellipsoid Newton iteration at |f| < 1e-9; here the same searches are followed by
Newton steps to machine precision, so that the result is a differentiable function of the end
points.  The tangent points move by a few micrometres; the length, stationary in the tangent
points, by far less (measured in tests/muscles: ~1e-9 m on arm26).

Derivative.  The surface path of an ellipsoid is not a shortest path, so its tangent points
may not be held fixed (the envelope theorem of :mod:`anthroarm.muscles.wrap` does not apply).  The length and
the tangent points are differentiated with respect to the two end points by the complex step
(Squire & Trapp, *Using complex variables to estimate derivatives of real functions*, SIAM
Rev 40 (1998) 110-112; Martins, Sturdza & Alonso, *The complex-step derivative
approximation*, ACM TOMS 29 (2003) 245-262): every operation here is analytic in the end
points on each branch (branches decided on real parts, |x| written x·sign(Re x), norms as
√(x·x), the iterative solves converged in complex arithmetic, whose imaginary parts then carry
the implicit-function derivative), so Im f(p + i h eₖ)/h with h = 1e-30 equals ∂f/∂pₖ to
rounding — no subtractive cancellation, no step-size error.  This is the derivative of the
length as computed (the piecewise-smooth polyline); OpenSim's ``computeMomentArm`` instead
holds the tangent points fixed in the ellipsoid's body, a slightly different quantity for
this non-shortest path (compared in the guide).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import MuscleError

NO_WRAP, INSIDE, MANDATORY = 0, -1, 2
ROUNDOFF_ERROR = 2e-13
EPS = np.finfo(float).eps
ELLIPSOID_TINY = 1e-8
MU_BLEND_MIN = 0.7073
MU_BLEND_MAX = 0.9
NUM_FAN_SAMPLES = 300
SV_BOUNDARY_BLEND = 0.3
SEGMENT = 0.001
#: complex step (any h below ~1e-20 gives the same derivative)
H = 1e-30
#: Newton steps after the real part has converged (the imaginary part converges in one)
POLISH = 3


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _norm(v):
    return np.sqrt(_dot(v, v))


def _unit(v):
    """``WrapMath::NormalizeOrZero`` on (..., 3), complex-safe (zero where |Re v| < eps)."""
    m = _norm(v)
    small = np.abs(m.real) < EPS
    return np.where(small[..., None], 0.0, v / np.where(small, 1.0, m)[..., None])


def _cabs(x):
    return x * np.where(x.real >= 0.0, 1.0, -1.0)


# ------------------------------------------------------------ closest point on the surface
def _ellipse(a, b, u, v):
    """``closestPointToEllipse`` (Graphics Gems IV) for points (u, v) of one batch (...,)."""
    a2, b2 = a * a, b * b
    nx = np.abs(u.real) <= ROUNDOFF_ERROR
    ny = np.abs(v.real) <= ROUNDOFF_ERROR
    if np.all(nx) and np.all(ny):
        if a < b:
            return np.where(u.real < 0, -a, a) + 0 * u, v
        return u, np.where(v.real < 0, -b, b) + 0 * v
    if np.all(nx):
        if a >= b or np.all(np.abs(v.real) >= b - a2 / b):
            return u, np.where(v.real >= 0, b, -b) + 0 * v
        y = b2 * v / (b2 - a2)
        ydb = y / b
        return a * np.sqrt(_cabs(1 - ydb * ydb)), y
    if np.all(ny):
        if b >= a or np.all(np.abs(u.real) >= a - b2 / a):
            return np.where(u.real >= 0, a, -a) + 0 * u, v
        x = a2 * u / (a2 - b2)
        xda = x / a
        return x, b * np.sqrt(_cabs(1 - xda * xda))
    a2u2, b2v2 = a2 * u * u, b2 * v * v
    inside = ((u.real / a) ** 2 + (v.real / b) ** 2) < 1.0
    t = np.where(inside, 0.0, max(a, b) * np.sqrt(u * u + v * v))
    extra = 0
    for _ in range(64 + POLISH):
        P, Q = t + a2, t + b2
        f = P * P * Q * Q - a2u2 * Q * Q - b2v2 * P * P
        if np.all(np.abs(f.real) < 1e-9):
            extra += 1
            if extra > POLISH:
                break
        fp = 2.0 * (P * Q * (P + Q) - a2u2 * Q - b2v2 * P)
        t = t - f / fp
    return a2 * u / (t + a2), b2 * v / (t + b2)


def _closest(a, X, axis=-1):
    """``findClosestPoint``: the closest surface point of the ellipsoid with radii ``a`` to
    each point X (..., 3); ``axis`` >= 0 reduces to that coordinate plane's ellipse."""
    X = np.asarray(X, dtype=complex)
    if axis == -1 and X.ndim == 2:  # one point (row 0 real): OpenSim's special cases
        near = np.abs(X[(0,) * (X.ndim - 1)].real) <= ROUNDOFF_ERROR
        best = np.inf
        for i in range(3):
            if near[i]:
                s = sum(a[j] for j in range(3) if j != i)
                if best > s:
                    axis, best = i, s
    out = np.empty_like(X)
    if axis == 0:
        out[..., 0] = X[..., 0]
        out[..., 1], out[..., 2] = _ellipse(a[1], a[2], X[..., 1], X[..., 2])
        return out
    if axis == 1:
        out[..., 1] = X[..., 1]
        out[..., 2], out[..., 0] = _ellipse(a[2], a[0], X[..., 2], X[..., 0])
        return out
    if axis == 2:
        out[..., 2] = X[..., 2]
        out[..., 0], out[..., 1] = _ellipse(a[0], a[1], X[..., 0], X[..., 1])
        return out
    # the fan's samples (X.ndim 3) take the general case: a sample within 2e-13 of a
    # coordinate plane (OpenSim's special case) gives the same point to ~1e-13
    a2 = a * a
    u2a2 = a2 * X * X
    inside = np.sum((X.real / a) ** 2, axis=-1) < 1.0
    t = np.where(inside, 0.0, a.max() * _norm(X))
    extra = 0
    for _ in range(64 + POLISH):
        P = t[..., None] + a2
        P2 = P * P
        f = P2[..., 0] * P2[..., 1] * P2[..., 2]
        f = f - u2a2[..., 0] * P2[..., 1] * P2[..., 2] - u2a2[..., 1] * P2[..., 0] * P2[..., 2]
        f = f - u2a2[..., 2] * P2[..., 0] * P2[..., 1]
        if np.all(np.abs(f.real) < 1e-9):
            extra += 1
            if extra > POLISH:
                break
        p, q, r = P[..., 0], P[..., 1], P[..., 2]
        pq, pr, qr = p * q, p * r, q * r
        fp = 2.0 * (
            p * q * r * (qr + pr + pq)
            - u2a2[..., 0] * qr * (q + r)
            - u2a2[..., 1] * pr * (p + r)
            - u2a2[..., 2] * pq * (p + q)
        )
        t = t - f / fp
    return a2 * X / (t[..., None] + a2)


# ------------------------------------------------------------------------ tangent points
def _residual(r, d1, p, a, vs, vs4):
    nr = 2.0 * r / (a * a)
    return np.stack(
        [
            _dot(vs, r) + vs4,
            np.sum((r / a) ** 2, axis=-1) - 1.0,
            _dot(nr, r) + d1,
            _dot(nr, p) + d1,
        ],
        axis=-1,
    )


def _lm_tangent(r, p, a, vs, vs4):
    """``WrapEllipsoid::calcTangentPoint``'s Levenberg-Marquardt search, real, one point
    (plain floats: it runs ~30 small steps)."""
    r = [float(v) for v in r]
    p = [float(v) for v in p]
    vs = [float(v) for v in vs]
    ia2 = [1.0 / float(v * v) for v in a]

    def residual(r, d1):
        rr = r[0] * r[0] * ia2[0] + r[1] * r[1] * ia2[1] + r[2] * r[2] * ia2[2]
        rp = r[0] * p[0] * ia2[0] + r[1] * p[1] * ia2[1] + r[2] * p[2] * ia2[2]
        e = (vs[0] * r[0] + vs[1] * r[1] + vs[2] * r[2] + vs4, rr - 1.0, 2 * rr + d1, 2 * rp + d1)
        return e, e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]

    pn = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    pu = [v / pn for v in p] if pn >= EPS else [0.0, 0.0, 0.0]
    d1 = -2.0 * (r[0] * r[0] * ia2[0] + r[1] * r[1] * ia2[1] + r[2] * r[2] * ia2[2])
    ee, ssq = residual(r, d1)
    ssqo = ssq
    alpha = 0.01
    nit = 0
    while ssq > ELLIPSOID_TINY and nit < 50:
        nit += 1
        dedth = np.zeros((4, 4))
        dedth[:3, 0] = vs
        dedth[:3, 1] = [2.0 * r[k] * ia2[k] for k in range(3)]
        dedth[:3, 2] = [4.0 * r[k] * ia2[k] for k in range(3)]
        dedth[:3, 3] = [2.0 * p[k] * ia2[k] for k in range(3)]
        dedth[3] = [0.0, 0.0, 1.0, 1.0]
        pr = [p[k] - r[k] for k in range(3)]
        prn = math.sqrt(pr[0] * pr[0] + pr[1] * pr[1] + pr[2] * pr[2])
        pcos = sum(pr[k] * pu[k] for k in range(3)) / prn if prn >= EPS else 0.0
        dd = 1.0 - pcos**100 if pcos > 0.1 else 1.0
        v = -dedth @ np.array(ee)
        dedth2 = dedth @ dedth.T
        diag = np.diag(dedth2).copy()
        vt = [0.0, 0.0, 0.0, 0.0]
        nit2 = 0
        while ssq >= ssqo and nit2 < 1000:
            dedth2[np.arange(4), np.arange(4)] = diag * (1.0 + alpha)
            try:
                vt = (dd * np.linalg.inv(dedth2) @ v / 16.0).tolist()
            except np.linalg.LinAlgError:
                return np.array(r)
            r = [r[k] + vt[k] for k in range(3)]
            d1 += vt[3]
            ssqo = ssq
            ee, ssq = residual(r, d1)
            alpha *= 4.0
            nit2 += 1
        alpha /= 8.0
        fakt = 0.5
        nit2 = 0
        while ssq <= ssqo and nit2 < 1000:
            fakt *= 2.0
            r = [r[k] + vt[k] * fakt for k in range(3)]
            d1 += vt[3] * fakt
            ssqo = ssq
            ee, ssq = residual(r, d1)
            nit2 += 1
        r = [r[k] - vt[k] * fakt for k in range(3)]
        d1 -= vt[3] * fakt
        ee, ssq = residual(r, d1)
        ssqo = ssq
    return np.array(r)


def _tangent(pe, r0, p, a, vs, vs4):
    """The tangent point from p (D, 3): OpenSim's search on the real parts, then Newton on
    the four equations (in the plane, on the surface, p on the tangent plane) in complex."""
    if abs(pe) < 1e-4:
        return p.copy()
    r = _lm_tangent(r0[0].real.copy(), p[0].real, a, vs[0].real, float(vs4[0].real))
    r = np.broadcast_to(r, p.shape).astype(complex)
    d1 = np.full(p.shape[0], -2.0, dtype=complex)
    ia2 = 1.0 / (a * a)
    for _ in range(12):
        F = _residual(r, d1, p, a, vs, vs4)
        J = np.zeros(p.shape[:1] + (4, 4), dtype=complex)
        J[:, 0, :3] = vs
        J[:, 1, :3] = 2.0 * r * ia2
        J[:, 2, :3] = 4.0 * r * ia2
        J[:, 2, 3] = 1.0
        J[:, 3, :3] = 2.0 * p * ia2
        J[:, 3, 3] = 1.0
        try:
            step = np.linalg.solve(J, F[..., None])[..., 0]
        except np.linalg.LinAlgError:
            break
        r = r - step[:, :3]
        d1 = d1 - step[:, 3]
        if np.max(np.abs(step[0].real)) < 1e-15:
            F = _residual(r, d1, p, a, vs, vs4)
            step = np.linalg.solve(J, F[..., None])[..., 0]
            r, d1 = r - step[:, :3], d1 - step[:, 3]
            break
    return r


# ----------------------------------------------------------------------- surface path
def _surface(r1, r2, a, vs, vs4, far_side, factor):
    """``CalcDistanceOnEllipsoid``: (wrap points (D, K, 3), length (D,)), scaled units."""
    length = _norm(r1 - r2) / factor
    if length[0].real < SEGMENT:
        return np.stack([r1, r2], axis=1), length * factor
    nseg = min(int(length[0].real / SEGMENT), 499)
    imax = int(np.argmax(np.abs(vs[0].real)))  # first of equal maxima, as OpenSim's loop
    mu = -vs4 / vs[:, imax]
    a0 = np.zeros_like(r1)
    a0[:, imax] = mu
    ar1, ar2 = _unit(r1 - a0), _unit(r2 - a0)
    phi0 = np.arccos(_dot(ar1, ar2))
    dphi = (-(2 * np.pi - phi0) if far_side else phi0) / nseg
    vsz = _unit(np.cross(ar1, ar2))
    vsy = np.cross(vsz, ar1)
    phi = np.arange(1, nseg)[None, :] * dphi[:, None]  # (D, K)
    ray = np.cos(phi)[..., None] * ar1[:, None] + np.sin(phi)[..., None] * vsy[:, None]
    f1 = ray / a
    f2 = (a0 / a)[:, None]
    aa, bb, cc = _dot(f1, f1), 2.0 * _dot(f1, f2), _dot(f2, f2) - 1.0
    mu3 = (-bb + np.sqrt(bb * bb - 4.0 * aa * cc)) / (2.0 * aa)
    pts = np.concatenate([r1[:, None], a0[:, None] + mu3[..., None] * ray, r2[:, None]], axis=1)
    return pts, _norm(np.diff(pts, axis=1)).sum(axis=1)


# ---------------------------------------------------------------------------- wrapLine
def _wrap(p1, p2, dims, quad, method):
    """``WrapEllipsoid::wrapLine`` on (D, 3) complex end points (branches on row 0's real
    part): (code, r1 (D, 3), r2 (D, 3), length (D,), surface path (D, K, 3) from r1 to r2),
    unscaled, in the ellipsoid's frame."""
    axis, wsign = quad
    # PathWrap::extendFinalizeFromProperties: an unknown method is hybrid
    method = method.lower() if method.lower() in ("hybrid", "midpoint", "axial") else "hybrid"
    factor = 3.0 / float(np.sum(dims))
    p1, p2, a = p1 * factor, p2 * factor, np.asarray(dims, dtype=float) * factor
    p1e = np.sum((p1 / a) ** 2, axis=-1) - 1.0
    p2e = np.sum((p2 / a) ** 2, axis=-1) - 1.0
    if p1e[0].real < -0.0001 or p2e[0].real < -0.0001:
        return INSIDE, None, None, None, None
    p1p2 = p1 - p2
    ppm = _dot(_unit(p1), _unit(p2)) - 1.0
    if abs(ppm[0].real) < 0.0001:
        return NO_WRAP, None, None, None, None
    f1, f2 = p1p2 / a, p2 / a
    aa, bb, cc = _dot(f1, f1), 2.0 * _dot(f1, f2), _dot(f2, f2) - 1.0
    disc = bb * bb - 4.0 * aa * cc
    if disc[0].real < 0.0:
        return NO_WRAP, None, None, None, None
    l1 = (-bb + np.sqrt(disc)) / (2.0 * aa)
    l2 = (-bb - np.sqrt(disc)) / (2.0 * aa)
    if not (0.0 < l1[0].real < 1.0) or not (0.0 < l2[0].real < 1.0):
        return NO_WRAP, None, None, None, None
    r1 = p2 + l1[:, None] * p1p2
    r2 = p2 + l2[:, None] * p1p2
    r1r2 = r2 - r1
    mu = _cabs(_unit(p1p2))
    best = int(np.argmax(mu[0].real))  # first of equal maxima
    mub = mu[:, best]
    fan_weight = -np.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        t_best = -r1[:, best] / r1r2[:, best]
    if method in ("hybrid", "axial"):
        sv_f = r1 + t_best[:, None] * r1r2
        c1_f = _closest(a, sv_f, best)
        c1 = None  # (OpenSim's sv, the chord point c1 came from, is not needed)
        if method == "hybrid" and mub[0].real > MU_BLEND_MIN:
            tb = t_best[0].real
            s = 1.0
            if tb < 0.0 or tb > 1.0:
                s = 0.0 * t_best
            elif tb < SV_BOUNDARY_BLEND:
                s = t_best / SV_BOUNDARY_BLEND
            elif tb > 1.0 - SV_BOUNDARY_BLEND:
                s = (1.0 - t_best) / SV_BOUNDARY_BLEND
            if np.real(np.atleast_1d(s)[0]) < 1.0:
                mub = MU_BLEND_MIN + s * (mub - MU_BLEND_MIN)
        if method == "axial" or mub[0].real > MU_BLEND_MIN:
            c1 = c1_f
        if method == "hybrid" and mub[0].real < MU_BLEND_MAX:
            sv_mid = r1 + 0.5 * r1r2
            tt = np.arange(1, NUM_FAN_SAMPLES - 1) / NUM_FAN_SAMPLES
            svs = r1[:, None] + tt[None, :, None] * r1r2[:, None]
            blades = _unit(_closest(a, svs) - svs)
            c1_fan = sv_mid + _unit(blades.sum(axis=1))
            if mub[0].real <= MU_BLEND_MIN:
                c1 = _closest(a, c1_fan)
                fan_weight = 1.0
            else:
                w = (mub - MU_BLEND_MIN) / (MU_BLEND_MAX - MU_BLEND_MIN)
                c1_1 = _closest(a, c1_fan)
                c1 = _closest(a, w[:, None] * c1 + (1.0 - w[:, None]) * c1_1)
                fan_weight = 1.0 - w
        if c1 is None:  # axial: not reached for hybrid
            c1 = c1_f
    else:  # midpoint
        c1 = _closest(a, r1 + 0.5 * r1r2)
    if method != "axial" or 0.0 < t_best[0].real < 1.0:
        r1 = r2 = c1
    if wsign != 0 and (1 if c1[0, axis].real >= 0.0 else -1) != wsign:
        orig = c1
        c1 = c1.copy()
        c1[:, axis] = -c1[:, axis]
        r1 = r2 = c1
        # OpenSim then sets a fan weight from mu when none was set, but its test
        # EQUAL_WITHIN_ERROR(fanWeight, -Infinity) is |-inf - -inf| = NaN <= 2e-13, false:
        # without the fan (Frans alone, axial, midpoint) c1 is only mirrored
        fw = np.atleast_1d(fan_weight)
        if fw[0].real > 1.0:
            fw = np.ones_like(fw)
        if fw[0].real > 0.0:
            bis = (orig[:, axis] + c1[:, axis]) / 2.0
            c1 = c1.copy()
            c1[:, axis] = c1[:, axis] + fw * (bis - c1[:, axis])
            c1 = _closest(a, c1)
    vs = _unit(np.cross(p1p2, p1 - c1))
    vs4 = -_dot(vs, c1)
    t1 = _tangent(p1e[0].real, r1, p1, a, vs, vs4)
    t2 = _tangent(p2e[0].real, r2, p2, a, vs, vs4)
    pts, length = _surface(t1, t2, a, vs, vs4, False, factor)
    if wsign != 0 and pts.shape[1] > 2:
        g1 = _unit(p1[0].real - t1[0].real) @ _unit(pts[0, 1].real - t1[0].real)
        g2 = _unit(p2[0].real - t2[0].real) @ _unit(pts[0, -2].real - t2[0].real)
        if g1 > 0.0 or g2 > 0.0:
            pts, length = _surface(t1, t2, a, vs, vs4, True, factor)
    return MANDATORY, t1 / factor, t2 / factor, length / factor, pts / factor


def wrap_line(p1, p2, dims, quad, method="hybrid"):
    """``WrapEllipsoid::wrapLine`` on complex-step rows: end points p1, p2 (D, 3) (the
    ellipsoid's frame, m; row 0 decides every branch) → (code, r1 (D, 3), r2 (D, 3), length
    (D,)), the tangent points and the surface path's length, None for a code other than
    ``MANDATORY``, and the surface path (D, K, 3): the polyline whose chords sum to the length,
    r1 first and r2 last (step 4 of the module docstring); ``dims``, ``quad`` and ``method`` as
    in :func:`~anthroarm.muscles.wrap_ellipsoid.ellipsoid`.  Im(row d) / h is the derivative
    along Im(p1, p2)(row d) / h (module docstring)."""
    p1 = np.asarray(p1, dtype=complex)
    p2 = np.asarray(p2, dtype=complex)
    code, r1, r2, length, pts = _wrap(p1, p2, dims, quad, method)
    if code != MANDATORY:
        return code, None, None, None, None
    if not (np.all(np.isfinite(r1)) and np.all(np.isfinite(r2)) and np.all(np.isfinite(length))):
        raise MuscleError("ellipsoid wrap: the tangent points did not converge")
    return code, r1, r2, length, pts


def ellipsoid(p1, p2, dims, quad, method="hybrid"):
    """``WrapEllipsoid::wrapLine`` of the segment p1 → p2 (the ellipsoid's frame, m) over
    the ellipsoid of radii ``dims`` with quadrant ``quad`` ((axis, sign), sign 0 for all) by
    the PathWrap's ``method`` (``hybrid``, ``midpoint`` or ``axial``; another is ``hybrid``, as
    in OpenSim).

    Returns (code, r1, r2, length, jac): the code (``NO_WRAP``, ``INSIDE``, ``MANDATORY``),
    the tangent points (3,), the surface path's length, and jac = (∂r1/∂(p1, p2) (3, 6),
    ∂r2/∂(p1, p2) (3, 6), ∂length/∂(p1, p2) (6,)) by the complex step (module docstring)."""
    p = np.concatenate([np.asarray(p1, dtype=float), np.asarray(p2, dtype=float)])
    P = np.tile(p.astype(complex), (7, 1))
    P[np.arange(1, 7), np.arange(6)] += 1j * H
    code, r1, r2, length, _ = wrap_line(P[:, :3], P[:, 3:], dims, quad, method)
    if code != MANDATORY:
        return code, None, None, 0.0, None
    jac = (r1[1:].imag.T / H, r2[1:].imag.T / H, length[1:].imag / H)
    return code, r1[0].real, r2[0].real, float(length[0].real), jac
