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

Written once as compiled kernels (:mod:`anthroarm.jit`) on (D, 3) ``complex128`` rows, as the
cylinder (:mod:`anthroarm.muscles.wrap_cylinder`): the interpreter runs the same source until the
background compilation is done.  The fan's 298 closest-point searches run on real numbers,
each point to its root, and then one complex Newton step carries the derivative
(:func:`closest_general`): a fan costs ~0.15 ms compiled (it was ~0.6 ms when every complex
row took the slowest point's iterations), ~10 ms in the interpreter.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ..errors import MuscleError
from ..jit import kernel
from .wrap_cylinder import axpy, cross, dot, row0_unit, sub, unit

NO_WRAP, INSIDE, MANDATORY = 0, -1, 2
ROUNDOFF_ERROR = 2e-13
EPS = float(np.finfo(float).eps)
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
#: the most Newton steps of a closest-point search (OpenSim's 64 to |f| < 1e-9, and on to the
#: root: near a double root the convergence is linear, ~1 bit a step)
ROOT_STEPS = 120
#: the PathWrap methods, as the kernels number them (another is hybrid, as in OpenSim)
METHODS = {"hybrid": 0, "midpoint": 1, "axial": 2}


@kernel
def cabs(x):
    """|x| of a complex-step number: x·sign(Re x) (analytic on each side)."""
    return x if x.real >= 0.0 else -x


@kernel
def solve4(A, b):
    """(solved, x) of A x = b for a 4×4 A (real or complex rows of the complex step): Gaussian
    elimination with partial pivoting on |Re|; not solved for a zero pivot (singular)."""
    M = A.copy()
    x = b.copy()
    for c in range(4):
        piv = c
        for i in range(c + 1, 4):
            if abs(M[i, c].real) > abs(M[piv, c].real):
                piv = i
        if M[piv, c] == 0.0:
            return False, x
        if piv != c:
            for j in range(4):
                M[c, j], M[piv, j] = M[piv, j], M[c, j]
            x[c], x[piv] = x[piv], x[c]
        for i in range(c + 1, 4):
            f = M[i, c] / M[c, c]
            for j in range(c, 4):
                M[i, j] = M[i, j] - f * M[c, j]
            x[i] = x[i] - f * x[c]
    for c in range(3, -1, -1):
        s = x[c]
        for j in range(c + 1, 4):
            s = s - M[c, j] * x[j]
        x[c] = s / M[c, c]
    return True, x


# ------------------------------------------------------------ closest point on the surface
@kernel
def ellipse(a, b, u, v):
    """``closestPointToEllipse`` (Graphics Gems IV) for the points (u, v) (D,) of one state's
    rows: the closest point (x (D,), y (D,)) of the ellipse of semi-axes a, b."""
    n = u.shape[0]
    a2, b2 = a * a, b * b
    x, y = np.empty(n, np.complex128), np.empty(n, np.complex128)
    nx = ny = True
    for d in range(n):
        nx = nx and abs(u[d].real) <= ROUNDOFF_ERROR
        ny = ny and abs(v[d].real) <= ROUNDOFF_ERROR
    if nx and ny:
        for d in range(n):
            if a < b:
                x[d], y[d] = (-a if u[d].real < 0 else a) + 0.0 * u[d], v[d]
            else:
                x[d], y[d] = u[d], (-b if v[d].real < 0 else b) + 0.0 * v[d]
        return x, y
    if nx:
        return ellipse_on_axis(a, b, u, v)
    if ny:  # the same with the axes swapped
        y, x = ellipse_on_axis(b, a, v, u)
        return x, y
    t = np.empty(n, np.complex128)
    for d in range(n):
        inside = (u[d].real / a) ** 2 + (v[d].real / b) ** 2 < 1.0
        t[d] = 0.0 if inside else max(a, b) * cmath.sqrt(u[d] * u[d] + v[d] * v[d])
    extra = 0
    f = np.empty(n, np.complex128)
    for _ in range(64 + POLISH):
        done = True
        for d in range(n):
            P, Q = t[d] + a2, t[d] + b2
            f[d] = P * P * Q * Q - a2 * u[d] * u[d] * Q * Q - b2 * v[d] * v[d] * P * P
            done = done and abs(f[d].real) < 1e-9
        if done:
            extra += 1
            if extra > POLISH:
                break
        for d in range(n):
            P, Q = t[d] + a2, t[d] + b2
            fp = 2.0 * (P * Q * (P + Q) - a2 * u[d] * u[d] * Q - b2 * v[d] * v[d] * P)
            t[d] = t[d] - f[d] / fp
    for d in range(n):
        x[d], y[d] = a2 * u[d] / (t[d] + a2), b2 * v[d] / (t[d] + b2)
    return x, y


@kernel
def ellipse_on_axis(a, b, u, v):
    """``closestPointToEllipse`` for points on the second axis (u ≈ 0 on every row): the end
    of that axis (x = u, y = ±b) when the point is far enough out (|v| ≥ b − a²/b) or a ≥ b,
    else the ellipse point y = b² v / (b² − a²), x = a √|1 − (y/b)²|."""
    n = u.shape[0]
    a2, b2 = a * a, b * b
    x, y = np.empty(n, np.complex128), np.empty(n, np.complex128)
    far = a >= b
    if not far:
        far = True
        for d in range(n):
            far = far and abs(v[d].real) >= b - a2 / b
    for d in range(n):
        if far:
            x[d], y[d] = u[d], (b if v[d].real >= 0 else -b) + 0.0 * v[d]
        else:
            y[d] = b2 * v[d] / (b2 - a2)
            ydb = y[d] / b
            x[d] = a * cmath.sqrt(cabs(1 - ydb * ydb))
    return x, y


@kernel
def closest_general(a, X, m):
    """The closest surface points of the ellipsoid with radii ``a`` (3,) to the points X
    (N, 3), complex-step rows in blocks of ``m`` whose real parts repeat the first block's:
    Hart's Newton iteration on the parameter t of x = a² X / (t + a²) (the general case of
    ``findClosestPoint``).

    Each point of the first block iterates on its real part to the root (:func:`_root`: past
    OpenSim's |f| < 1e-9, until its step is below 4 ulp); then one Newton step of every row
    from that root t₀ gives Im t = −Im f / f'(t₀), the implicit derivative of t along Im X,
    exactly.  Iterating all the complex rows together instead took the slowest point's steps
    on every row, and stopped 3 steps after |f| < 1e-9, which near a double root (a fan point
    near the ellipsoid's centre, where Newton converges only linearly) left the derivative off
    by a few per cent."""
    n = X.shape[0]
    a2 = a * a
    amax = max(a[0], max(a[1], a[2]))
    Xr = X[:m].real.copy()
    inside = np.sum((Xr / a) ** 2, axis=1) < 1.0
    t = amax * np.sqrt(np.sum(Xr * Xr, axis=1))
    t[inside] = 0.0
    t = _root(a2, a2 * Xr * Xr, t)
    tc = np.empty(n, np.complex128)
    for b in range(n // m):
        tc[b * m : (b + 1) * m] = t
    p, q, r = tc + a2[0], tc + a2[1], tc + a2[2]
    f, fp = _hart(a2 * X * X, p, q, r)
    return a2 * X / ((tc - f / fp).reshape(n, 1) + a2)


@kernel
def _hart(u, p, q, r):
    """Hart's f(t) = p²q²r² − u₀q²r² − u₁p²r² − u₂p²q² and f'(t) at p = t + a₀², q = t + a₁²,
    r = t + a₂² (arrays), u = a² X² (N, 3)."""
    u0, u1, u2 = u[:, 0].copy(), u[:, 1].copy(), u[:, 2].copy()
    p2, q2, r2 = p * p, q * q, r * r
    f = p2 * q2 * r2 - u0 * q2 * r2 - u1 * p2 * r2
    f = f - u2 * p2 * q2
    pq, pr, qr = p * q, p * r, q * r
    fp = 2.0 * (
        p * q * r * (qr + pr + pq) - u0 * qr * (q + r) - u1 * pr * (p + r) - u2 * pq * (p + q)
    )
    return f, fp


@kernel
def _root(a2, u, t):
    """Newton on Hart's f from ``t`` (N,) (real), each point until its step is below 4 ulp
    (at most :data:`ROOT_STEPS`)."""
    t = t.copy()
    A0, A1, A2 = a2[0], a2[1], a2[2]
    for i in range(t.shape[0]):
        ti, u0, u1, u2 = t[i], u[i, 0], u[i, 1], u[i, 2]
        for _ in range(ROOT_STEPS):
            p, q, r = ti + A0, ti + A1, ti + A2
            pq, pr, qr = p * q, p * r, q * r
            f = pq * pq * r * r - u0 * qr * qr - u1 * pr * pr - u2 * pq * pq
            fp = 2.0 * (
                pq * r * (qr + pr + pq) - u0 * qr * (q + r) - u1 * pr * (p + r) - u2 * pq * (p + q)
            )
            step = f / fp
            ti = ti - step
            if abs(step) <= 4.0 * EPS * (1.0 + abs(ti)):
                break
        t[i] = ti
    return t


@kernel
def closest(a, X, axis):
    """``findClosestPoint``: the closest surface point of the ellipsoid with radii ``a`` to
    one point's rows X (D, 3); ``axis`` >= 0 reduces to that coordinate plane's ellipse;
    -1 takes OpenSim's special cases (row 0 within 2e-13 of coordinate planes) first."""
    if axis == -1:
        best = math.inf
        for i in range(3):
            if abs(X[0, i].real) <= ROUNDOFF_ERROR:
                s = 0.0
                for jj in range(3):
                    if jj != i:
                        s += a[jj]
                if best > s:
                    axis, best = i, s
    if axis == -1:
        return closest_general(a, X, 1)
    j, k = (axis + 1) % 3, (axis + 2) % 3
    out = X.copy()
    x, y = ellipse(a[j], a[k], X[:, j].copy(), X[:, k].copy())
    out[:, j] = x
    out[:, k] = y
    return out


# ------------------------------------------------------------------------ tangent points
@kernel
def residual(r, d1, p, a, vs, vs4):
    """The four equations of a tangent point r (rows (D, 3)) from p: in the plane
    vs·r + vs4 = 0, on the surface, and p on the tangent plane (with multiplier d1)."""
    n = r.shape[0]
    F = np.empty((n, 4), np.complex128)
    for d in range(n):
        s = 0.0 + 0.0j
        rr = 0.0 + 0.0j
        rp = 0.0 + 0.0j
        for k in range(3):
            nr = 2.0 * r[d, k] / (a[k] * a[k])
            s = s + (r[d, k] / a[k]) ** 2
            rr = rr + nr * r[d, k]
            rp = rp + nr * p[d, k]
        F[d, 0] = vs[d, 0] * r[d, 0] + vs[d, 1] * r[d, 1] + vs[d, 2] * r[d, 2] + vs4[d]
        F[d, 1] = s - 1.0
        F[d, 2] = rr + d1[d]
        F[d, 3] = rp + d1[d]
    return F


@kernel
def lm_residual(r, d1, p, ia2, vs, vs4):
    """The same equations on real numbers (the search's residual e) and Σ e²."""
    rr = r[0] * r[0] * ia2[0] + r[1] * r[1] * ia2[1] + r[2] * r[2] * ia2[2]
    rp = r[0] * p[0] * ia2[0] + r[1] * p[1] * ia2[1] + r[2] * p[2] * ia2[2]
    e = np.empty(4)
    e[0] = vs[0] * r[0] + vs[1] * r[1] + vs[2] * r[2] + vs4
    e[1], e[2], e[3] = rr - 1.0, 2 * rr + d1, 2 * rp + d1
    return e, e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]


@kernel
def lm_tangent(r0, p, a, vs, vs4):
    """``WrapEllipsoid::calcTangentPoint``'s Levenberg-Marquardt search on real numbers (one
    point, from r0 (3,)); the damped normal equations solved by :func:`solve4`."""
    r = r0.copy()
    ia2 = 1.0 / (a * a)
    pn = math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])
    pu = p / pn if pn >= EPS else np.zeros(3)
    d1 = -2.0 * (r[0] * r[0] * ia2[0] + r[1] * r[1] * ia2[1] + r[2] * r[2] * ia2[2])
    ee, ssq = lm_residual(r, d1, p, ia2, vs, vs4)
    ssqo = ssq
    alpha = 0.01
    nit = 0
    dedth = np.zeros((4, 4))
    vt = np.zeros(4)
    while ssq > ELLIPSOID_TINY and nit < 50:
        nit += 1
        for k in range(3):
            dedth[k, 0] = vs[k]
            dedth[k, 1] = 2.0 * r[k] * ia2[k]
            dedth[k, 2] = 4.0 * r[k] * ia2[k]
            dedth[k, 3] = 2.0 * p[k] * ia2[k]
        dedth[3, 0], dedth[3, 1], dedth[3, 2], dedth[3, 3] = 0.0, 0.0, 1.0, 1.0
        pr = p - r
        prn = math.sqrt(pr[0] * pr[0] + pr[1] * pr[1] + pr[2] * pr[2])
        pcos = (pr[0] * pu[0] + pr[1] * pu[1] + pr[2] * pu[2]) / prn if prn >= EPS else 0.0
        dd = 1.0 - pcos**100 if pcos > 0.1 else 1.0
        v = np.zeros(4)
        dedth2 = np.zeros((4, 4))
        for i in range(4):
            for j in range(4):
                v[i] -= dedth[i, j] * ee[j]
                for k in range(4):
                    dedth2[i, j] += dedth[i, k] * dedth[j, k]
        diag = np.empty(4)
        for k in range(4):
            diag[k] = dedth2[k, k]
        vt[:] = 0.0
        nit2 = 0
        while ssq >= ssqo and nit2 < 1000:
            for k in range(4):
                dedth2[k, k] = diag[k] * (1.0 + alpha)
            ok, sol = solve4(dedth2, v)
            if not ok:
                return r
            for k in range(4):
                vt[k] = dd * sol[k] / 16.0
            for k in range(3):
                r[k] += vt[k]
            d1 += vt[3]
            ssqo = ssq
            ee, ssq = lm_residual(r, d1, p, ia2, vs, vs4)
            alpha *= 4.0
            nit2 += 1
        alpha /= 8.0
        fakt = 0.5
        nit2 = 0
        while ssq <= ssqo and nit2 < 1000:
            fakt *= 2.0
            for k in range(3):
                r[k] += vt[k] * fakt
            d1 += vt[3] * fakt
            ssqo = ssq
            ee, ssq = lm_residual(r, d1, p, ia2, vs, vs4)
            nit2 += 1
        for k in range(3):
            r[k] -= vt[k] * fakt
        d1 -= vt[3] * fakt
        ee, ssq = lm_residual(r, d1, p, ia2, vs, vs4)
        ssqo = ssq
    return r


@kernel
def tangent(pe, r0, p, a, vs, vs4):
    """The tangent point from p (D, 3): OpenSim's search on the real parts, then Newton on
    the four equations (in the plane, on the surface, p on the tangent plane) in complex."""
    if abs(pe) < 1e-4:
        return p.copy()
    n = p.shape[0]
    re = lm_tangent(r0[0].real.copy(), p[0].real.copy(), a, vs[0].real.copy(), vs4[0].real)
    r = np.empty((n, 3), np.complex128)
    d1 = np.empty(n, np.complex128)
    for d in range(n):
        d1[d] = -2.0
        for k in range(3):
            r[d, k] = re[k]
    ia2 = 1.0 / (a * a)
    J = np.zeros((n, 4, 4), np.complex128)
    step = np.zeros((n, 4), np.complex128)
    for _ in range(12):
        F = residual(r, d1, p, a, vs, vs4)
        ok = True
        for d in range(n):
            for k in range(3):
                J[d, 0, k] = vs[d, k]
                J[d, 1, k] = 2.0 * r[d, k] * ia2[k]
                J[d, 2, k] = 4.0 * r[d, k] * ia2[k]
                J[d, 3, k] = 2.0 * p[d, k] * ia2[k]
            J[d, 0, 3], J[d, 1, 3], J[d, 2, 3], J[d, 3, 3] = 0.0, 0.0, 1.0, 1.0
            okd, sd = solve4(J[d], F[d])
            step[d] = sd
            ok = ok and okd
        if not ok:
            break
        small = True
        for d in range(n):
            for k in range(3):
                r[d, k] = r[d, k] - step[d, k]
            d1[d] = d1[d] - step[d, 3]
        for k in range(4):
            small = small and abs(step[0, k].real) < 1e-15
        if small:
            F = residual(r, d1, p, a, vs, vs4)
            for d in range(n):
                okd, sd = solve4(J[d], F[d])
                step[d] = sd
                for k in range(3):
                    r[d, k] = r[d, k] - step[d, k]
                d1[d] = d1[d] - step[d, 3]
            break
    return r


# ----------------------------------------------------------------------- surface path
@kernel
def surface(r1, r2, a, vs, vs4, far_side, factor):
    """``CalcDistanceOnEllipsoid``: (wrap points (D, K, 3), length (D,)), scaled units."""
    n = r1.shape[0]
    length = np.empty(n, np.complex128)
    dr = sub(r1, r2)
    for d in range(n):
        length[d] = cmath.sqrt(dr[d, 0] ** 2 + dr[d, 1] ** 2 + dr[d, 2] ** 2) / factor
    if length[0].real < SEGMENT:
        pts = np.empty((n, 2, 3), np.complex128)
        pts[:, 0], pts[:, 1] = r1, r2
        for d in range(n):
            length[d] = length[d] * factor
        return pts, length
    nseg = min(int(length[0].real / SEGMENT), 499)
    imax = 0  # the first of equal maxima, as OpenSim's loop
    for k in range(1, 3):
        if abs(vs[0, k].real) > abs(vs[0, imax].real):
            imax = k
    a0 = np.zeros((n, 3), np.complex128)
    for d in range(n):
        a0[d, imax] = -vs4[d] / vs[d, imax]
    ar1, ar2 = unit(sub(r1, a0))[0], unit(sub(r2, a0))[0]
    c12 = dot(ar1, ar2)
    vsz = unit(cross(ar1, ar2))[0]
    vsy = cross(vsz, ar1)
    pts = np.empty((n, nseg + 1, 3), np.complex128)
    for d in range(n):
        phi0 = cmath.acos(c12[d])
        dphi = (-(2 * math.pi - phi0) if far_side else phi0) / nseg
        pts[d, 0] = r1[d]
        pts[d, nseg] = r2[d]
        f2 = (a0[d, 0] / a[0], a0[d, 1] / a[1], a0[d, 2] / a[2])
        cc = f2[0] * f2[0] + f2[1] * f2[1] + f2[2] * f2[2] - 1.0
        for j in range(1, nseg):
            phi = j * dphi
            c, s = cmath.cos(phi), cmath.sin(phi)
            ray = (
                c * ar1[d, 0] + s * vsy[d, 0],
                c * ar1[d, 1] + s * vsy[d, 1],
                c * ar1[d, 2] + s * vsy[d, 2],
            )
            f1 = (ray[0] / a[0], ray[1] / a[1], ray[2] / a[2])
            aa = f1[0] * f1[0] + f1[1] * f1[1] + f1[2] * f1[2]
            bb = 2.0 * (f1[0] * f2[0] + f1[1] * f2[1] + f1[2] * f2[2])
            mu3 = (-bb + cmath.sqrt(bb * bb - 4.0 * aa * cc)) / (2.0 * aa)
            for k in range(3):
                pts[d, j, k] = a0[d, k] + mu3 * ray[k]
        total = 0.0 + 0.0j
        for j in range(nseg):
            e0 = pts[d, j + 1, 0] - pts[d, j, 0]
            e1 = pts[d, j + 1, 1] - pts[d, j, 1]
            e2 = pts[d, j + 1, 2] - pts[d, j, 2]
            total = total + cmath.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        length[d] = total
    return pts, length


# ---------------------------------------------------------------------------- wrapLine
@kernel
def wrap(p1, p2, dims, axis, wsign, method):
    """``WrapEllipsoid::wrapLine`` on (D, 3) complex end points (branches on row 0's real
    part), ``method`` numbered as in :data:`METHODS`: (code, r1 (D, 3), r2 (D, 3), length
    (D,), surface path (D, K, 3) from r1 to r2), unscaled, in the ellipsoid's frame; zero
    points and length and no surface points for a code other than ``MANDATORY``."""
    n = p1.shape[0]
    none = np.zeros((n, 3), np.complex128)
    factor = 3.0 / (dims[0] + dims[1] + dims[2])
    a = dims * factor
    P1, P2 = p1 * factor, p2 * factor
    p1e, p2e = -1.0, -1.0
    for k in range(3):
        p1e += (P1[0, k].real / a[k]) ** 2
        p2e += (P2[0, k].real / a[k]) ** 2
    if p1e < -0.0001 or p2e < -0.0001:
        return INSIDE, none, none, none[:, 0].copy(), np.zeros((n, 0, 3), np.complex128)
    p1p2 = sub(P1, P2)
    ppm = dot(unit(P1)[0], unit(P2)[0])
    if abs(ppm[0].real - 1.0) < 0.0001:
        return NO_WRAP, none, none, none[:, 0].copy(), np.zeros((n, 0, 3), np.complex128)
    f1, f2 = p1p2 / a, P2 / a
    aa, bb, cc = dot(f1, f1), 2.0 * dot(f1, f2), dot(f2, f2) - 1.0
    disc = bb * bb - 4.0 * aa * cc
    if disc[0].real < 0.0:
        return NO_WRAP, none, none, none[:, 0].copy(), np.zeros((n, 0, 3), np.complex128)
    l1 = (-bb + np.sqrt(disc)) / (2.0 * aa)
    l2 = (-bb - np.sqrt(disc)) / (2.0 * aa)
    if not (0.0 < l1[0].real < 1.0) or not (0.0 < l2[0].real < 1.0):
        return NO_WRAP, none, none, none[:, 0].copy(), np.zeros((n, 0, 3), np.complex128)
    r1 = axpy(P2, l1, p1p2)
    r2 = axpy(P2, l2, p1p2)
    r1r2 = sub(r2, r1)
    up = unit(p1p2)[0]
    best = 0  # the first of equal maxima
    for k in range(1, 3):
        if abs(up[0, k].real) > abs(up[0, best].real):
            best = k
    mub = np.empty(n, np.complex128)
    t_best = np.empty(n, np.complex128)
    fan_weight = np.empty(n, np.complex128)
    for d in range(n):
        mub[d] = cabs(up[d, best])
        t_best[d] = -r1[d, best] / r1r2[d, best]
        fan_weight[d] = -math.inf
    c1 = none
    if method == 0 or method == 2:  # hybrid, axial
        c1_f = closest(a, axpy(r1, t_best, r1r2), best)
        have = False
        if method == 0 and mub[0].real > MU_BLEND_MIN:
            tb = t_best[0].real
            s = np.ones(n, np.complex128)
            if tb < 0.0 or tb > 1.0:
                s = 0.0 * t_best
            elif tb < SV_BOUNDARY_BLEND:
                s = t_best / SV_BOUNDARY_BLEND
            elif tb > 1.0 - SV_BOUNDARY_BLEND:
                s = (1.0 - t_best) / SV_BOUNDARY_BLEND
            if s[0].real < 1.0:
                mub = MU_BLEND_MIN + s * (mub - MU_BLEND_MIN)
        if method == 2 or mub[0].real > MU_BLEND_MIN:
            c1, have = c1_f, True
        if method == 0 and mub[0].real < MU_BLEND_MAX:
            c1_fan = fan(a, r1, r1r2)
            if mub[0].real <= MU_BLEND_MIN:
                c1 = closest(a, c1_fan, -1)
                fan_weight[:] = 1.0
            else:
                w = (mub - MU_BLEND_MIN) / (MU_BLEND_MAX - MU_BLEND_MIN)
                c1_1 = closest(a, c1_fan, -1)
                mix = np.empty((n, 3), np.complex128)
                for d in range(n):
                    for k in range(3):
                        mix[d, k] = w[d] * c1[d, k] + (1.0 - w[d]) * c1_1[d, k]
                c1 = closest(a, mix, -1)
                fan_weight = 1.0 - w
            have = True
        if not have:  # axial: not reached for hybrid
            c1 = c1_f
    else:  # midpoint
        c1 = closest(a, axpy(r1, 0.5 + 0.0 * t_best, r1r2), -1)
    if method != 2 or 0.0 < t_best[0].real < 1.0:
        r1 = r2 = c1
    if wsign != 0 and (1 if c1[0, axis].real >= 0.0 else -1) != wsign:
        orig = c1
        c1 = c1.copy()
        c1[:, axis] = -c1[:, axis]
        r1 = r2 = c1
        # OpenSim then sets a fan weight from mu when none was set, but its test
        # EQUAL_WITHIN_ERROR(fanWeight, -Infinity) is |-inf - -inf| = NaN <= 2e-13, false:
        # without the fan (Frans alone, axial, midpoint) c1 is only mirrored
        fw = fan_weight.copy()
        if fw[0].real > 1.0:
            fw[:] = 1.0
        if fw[0].real > 0.0:
            c1 = c1.copy()
            for d in range(n):
                bis = (orig[d, axis] + c1[d, axis]) / 2.0
                c1[d, axis] = c1[d, axis] + fw[d] * (bis - c1[d, axis])
            c1 = closest(a, c1, -1)
    vs = unit(cross(p1p2, sub(P1, c1)))[0]
    vs4 = -dot(vs, c1)
    t1 = tangent(p1e, r1, P1, a, vs, vs4)
    t2 = tangent(p2e, r2, P2, a, vs, vs4)
    pts, length = surface(t1, t2, a, vs, vs4, False, factor)
    m = pts.shape[1]
    if wsign != 0 and m > 2:
        g1 = _cos0(P1, t1, pts[:, 1].copy())
        g2 = _cos0(P2, t2, pts[:, m - 2].copy())
        if g1 > 0.0 or g2 > 0.0:
            pts, length = surface(t1, t2, a, vs, vs4, True, factor)
    return MANDATORY, t1 / factor, t2 / factor, length / factor, pts / factor


@kernel
def fan(a, r1, r1r2):
    """The "fan": the chord's midpoint moved by the unit mean direction from 298 points of the
    chord r1 + t (r2 − r1), t = k / 300, to their closest surface points."""
    n = r1.shape[0]
    K = NUM_FAN_SAMPLES - 2
    tt = np.arange(1, K + 1) / NUM_FAN_SAMPLES
    svs = np.empty((n * K, 3), np.complex128)
    for d in range(n):
        for k in range(3):
            svs[d * K : (d + 1) * K, k] = r1[d, k] + tt * r1r2[d, k]
    blades = unit(sub(closest_general(a, svs, K), svs))[0]
    total = np.empty((n, 3), np.complex128)
    mid = np.empty((n, 3), np.complex128)
    for d in range(n):
        for k in range(3):
            total[d, k] = np.sum(blades[d * K : (d + 1) * K, k])
            mid[d, k] = r1[d, k] + 0.5 * r1r2[d, k]
    return mid + unit(total)[0]


@kernel
def _cos0(p, t, q):
    """cos of the angle at t between p − t and q − t, row 0's real parts."""
    u, v = row0_unit(p, t), row0_unit(q, t)
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def wrap_line(p1, p2, dims, quad, method="hybrid"):
    """``WrapEllipsoid::wrapLine`` on complex-step rows: end points p1, p2 (D, 3) (the
    ellipsoid's frame, m; row 0 decides every branch) → (code, r1 (D, 3), r2 (D, 3), length
    (D,)), the tangent points and the surface path's length, None for a code other than
    ``MANDATORY``; ``dims``, ``quad`` and ``method`` as in
    :func:`~anthroarm.muscles.wrap_ellipsoid.ellipsoid`.  Im(row d) / h
    is the derivative along Im(p1, p2)(row d) / h (module docstring); and the surface path
    (D, K, 3): the polyline whose chords sum to the length, r1 first and r2 last (step 4 of the
    module docstring).  The compiled kernel :func:`wrap`."""
    p1 = np.ascontiguousarray(p1, dtype=complex)
    p2 = np.ascontiguousarray(p2, dtype=complex)
    axis, wsign = quad
    # PathWrap::extendFinalizeFromProperties: an unknown method is hybrid
    m = METHODS.get(method.lower(), 0)
    dims = np.ascontiguousarray(dims, dtype=float)
    code, r1, r2, length, pts = wrap(p1, p2, dims, int(axis), int(wsign), m)
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
