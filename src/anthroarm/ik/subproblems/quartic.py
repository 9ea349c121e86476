"""SP5 and SP6 (IK-Geo §III-E, §III-F): three rotations placing a point, and two pairs of
rotations meeting two heights — each a quartic, ≤ 4 solutions."""

from __future__ import annotations

import math

import numpy as np

from ...errors import ParameterError
from ...jit import kernel, local, local2, local_flags
from ..vec3 import add, cross, dot, neg, norm, rotate, scale, sub, vec, wrap
from .base import TOL_QUARTIC, Solutions, _finish, _inputs, _tol
from .roots import _keep_best, _solve3, real_roots


# ----------------------------------------------------------------------------- SP5
@kernel
def _circle_polynomials(o, k, p, k2, delta):
    """‖v‖² = P(z) ± √R(z) on the circle {o + rot(k, θ) p}, z = k2ᵀv: P (2 coeffs), R (3),
    and whether k ∥ k2 (IK-Geo §III-E)."""
    kxk2 = cross(k, k2)
    kkk2 = cross(k, kxk2)
    nk2 = dot(kxk2, kxk2)
    bad = nk2 <= 1e-20
    if bad:
        nk2 = 1.0
    kxp = cross(k, p)
    r2 = dot(kxp, kxp)
    alpha = dot(o, kkk2) / nk2
    beta = dot(o, kxk2) / nk2
    cen = add(o, scale(k, dot(k, p)))
    f = 4.0 * beta * beta
    return (
        (-2.0 * alpha, r2 + dot(cen, cen) + 2.0 * alpha * delta),
        (-f, 2.0 * delta * f, (-delta * delta + r2 * nk2) * f),
        bad,
    )


#: Newton steps at most on an SP5 candidate (:func:`_sp5_newton`; quadratic convergence: most
#: stop after one or two)
SP5_NEWTON = 6


@kernel
def _sp5_newton(p0, p1, p2, p3, k1, k2, k3, t, stop):
    """Newton's method on the SP5 equation (3 equations, 3 angles) from ``t``: at most
    :data:`SP5_NEWTON` steps, fewer once the residual is below ``stop``; returns the wrapped
    angles and the residual norm there.  (Three steps left a candidate near a close pair of
    quartic roots at a residual of ~1e-7, accepted under ``TOL_QUARTIC`` but 1.4e-6 rad from the
    converged copy of the same solution: a duplicate root.)"""
    res = math.inf
    for it in range(SP5_NEWTON + 1):
        r1 = rotate(k1, t[0], p1)
        r3 = rotate(k3, t[2], p3)
        w = rotate(k2, t[1], add(p2, r3))
        F = sub(add(p0, r1), w)  # the SP5 residual at t
        res = norm(F)
        if it == SP5_NEWTON or res <= stop:
            break
        c3v = rotate(k2, t[1], cross(k3, r3))
        j0, j1 = cross(k1, r1), neg(cross(k2, w))
        J = ((j0[0], j1[0], -c3v[0]), (j0[1], j1[1], -c3v[1]), (j0[2], j1[2], -c3v[2]))
        step, good = _solve3(J, F)
        if good:
            t = (t[0] - step[0], t[1] - step[1], t[2] - step[2])
    return (wrap(t[0]), wrap(t[1]), wrap(t[2])), res


# long: SP5's closed form as one compiled kernel (the quartic, its roots, their polish)
@kernel
def sp5_one(p0, p1, p2, p3, k1, k2, k3, tol, out_theta):
    """SP5 of one problem (tuples): writes the solutions into ``out_theta`` (4, 3) (valid rows
    first) and returns (count, singular); see :func:`sp5`."""
    c1 = add(p0, scale(k1, dot(k1, p1)))  # centre of circle 1
    c3 = add(p2, scale(k3, dot(k3, p3)))  # centre of circle 3
    d1, d3 = dot(k2, c1), dot(k2, c3)
    P1, R1, bad1 = _circle_polynomials(p0, k1, p1, k2, d1)
    P3, R3, bad3 = _circle_polynomials(p2, k3, p3, k2, d3)
    sing = bad1 or bad3
    for j in range(4):
        for c in range(3):
            out_theta[j, c] = math.nan
    if sing:
        return 0, True
    a, b = P1[0] - P3[0], P1[1] - P3[1]  # P13 = a z + b
    sq = (a * a, 2.0 * a * b, b * b)  # P13²
    rhs = (R3[0] - R1[0] - sq[0], R3[1] - R1[1] - sq[1], R3[2] - R1[2] - sq[2])
    eq = local(5)  # rhs² − 4 P13² R1
    eq[0] = rhs[0] * rhs[0] - 4.0 * sq[0] * R1[0]
    eq[1] = 2.0 * rhs[0] * rhs[1] - 4.0 * (sq[0] * R1[1] + sq[1] * R1[0])
    eq[2] = (
        rhs[1] * rhs[1]
        + 2.0 * rhs[0] * rhs[2]
        - 4.0 * (sq[0] * R1[2] + sq[1] * R1[1] + sq[2] * R1[0])
    )
    eq[3] = 2.0 * rhs[1] * rhs[2] - 4.0 * (sq[1] * R1[2] + sq[2] * R1[1])
    eq[4] = rhs[2] * rhs[2] - 4.0 * sq[2] * R1[2]
    z, real = local(4), local_flags(4)
    real_roots(eq, z, real)
    k1p1, k3p3 = cross(k1, p1), cross(k3, p3)
    kk1p1, kk3p3 = cross(k1, k1p1), cross(k3, k3p3)
    a1 = (dot(k1p1, k2), -dot(kk1p1, k2))  # A1ᵀ k2
    a3 = (dot(k3p3, k2), -dot(kk3p3, k2))
    na1 = max(a1[0] * a1[0] + a1[1] * a1[1], 1e-300)
    na3 = max(a3[0] * a3[0] + a3[1] * a3[1], 1e-300)
    theta, ok, res = local2(16, 3), local_flags(16), local(16)
    for i in range(16):
        theta[i, 0], theta[i, 1], theta[i, 2], ok[i], res[i] = 0.0, 0.0, 0.0, False, math.inf
    scl = 1.0 + norm(p0) + norm(p1) + norm(p2) + norm(p3)
    # Newton stops early below this residual (far below tol: the same exact solutions)
    stop = min(1e-13 * scl, 1e-3 * tol)
    for r in range(4):
        if not real[r] or (r > 0 and z[r] == z[r - 1]):
            continue  # a double root: the same candidates
        e1, e3 = z[r] - d1, z[r] - d3
        s1 = math.sqrt(max(na1 - e1 * e1, 0.0))
        s3 = math.sqrt(max(na3 - e3 * e3, 0.0))
        for g in range(4):
            sg1 = 1.0 if g < 2 else -1.0
            sg3 = 1.0 if g % 2 == 0 else -1.0
            if (sg1 < 0.0 and s1 == 0.0) or (sg3 < 0.0 and s3 == 0.0):
                continue  # the same point as sign +1
            # the SP4 points at height z (IK-Geo Eqs. (4)-(6)): x = (sin θ, cos θ) unnormalised
            x10, x11 = a1[0] * e1 + sg1 * a1[1] * s1, a1[1] * e1 - sg1 * a1[0] * s1
            x30, x31 = a3[0] * e3 + sg3 * a3[1] * s3, a3[1] * e3 - sg3 * a3[0] * s3
            n1, n3 = math.hypot(x10, x11), math.hypot(x30, x31)
            if n1 > 0.0:
                x10, x11 = x10 / n1, x11 / n1
            else:
                x10, x11 = 0.0, 1.0  # atan2(0, 0) = 0
            if n3 > 0.0:
                x30, x31 = x30 / n3, x31 / n3
            else:
                x30, x31 = 0.0, 1.0
            v1 = add(c1, sub(scale(k1p1, x10), scale(kk1p1, x11)))  # p0 + rot(k1, θ1) p1
            v3 = add(c3, sub(scale(k3p3, x30), scale(kk3p3, x31)))  # p2 + rot(k3, θ3) p3
            # residual after θ2 by SP1 (rot(k2, θ2) v3 nearest v1): heights h and radii ρ about
            # k2 (the spurious sign pairs of the squared quartic have ‖v1‖ ≠ ‖v3‖)
            h1, h3 = dot(k2, v1), dot(k2, v3)
            rho1 = math.sqrt(max(dot(v1, v1) - h1 * h1, 0.0))
            rho3 = math.sqrt(max(dot(v3, v3) - h3 * h3, 0.0))
            if math.hypot(h1 - h3, rho1 - rho3) > 1e-2 * scl:
                continue
            t1, t3 = math.atan2(x10, x11), math.atan2(x30, x31)
            k2v3 = cross(k2, v3)
            t2 = math.atan2(dot(k2v3, v1), -dot(cross(k2, k2v3), v1))  # SP1: rot(k2, θ2) v3 = v1
            t, rs = _sp5_newton(p0, p1, p2, p3, k1, k2, k3, (t1, t2, t3), stop)
            i = 4 * r + g
            theta[i, 0], theta[i, 1], theta[i, 2] = t
            res[i] = rs
            ok[i] = rs <= tol
    return _keep_best(theta, ok, res, out_theta, 3), False


@kernel
def _sp5_loop(p0, p1, p2, p3, k1, k2, k3, tol, theta, count, sing):
    for i in range(len(p0)):
        count[i], sing[i] = sp5_one(
            vec(p0[i]),
            vec(p1[i]),
            vec(p2[i]),
            vec(p3[i]),
            vec(k1[i]),
            vec(k2[i]),
            vec(k3[i]),
            tol,
            theta[i],
        )


def sp5(p0, p1, p2, p3, k1, k2, k3, tol: float = TOL_QUARTIC) -> Solutions:
    """Subproblem 5, three circles: (θ1, θ2, θ3) with
    p0 + rot(k1, θ1) p1 = rot(k2, θ2) (p2 + rot(k3, θ3) p3).

    IK-Geo §III-E: the height z = k2ᵀv of the common point v is the same on both sides and
    so is ‖v‖.  On circle i (i = 1: centre p0 + k1 k1ᵀp1, i = 3: centre p2 + k3 k3ᵀp3), fixing
    the height z leaves two points (the SP4 of Eqs. (4)–(6)), whose squared norm is
    Pᵢ(z) ± √Rᵢ(z) with Pᵢ linear and Rᵢ quadratic in z.  Equating the two sides and squaring
    twice gives the quartic (P1 − P3)² …::

        (R3 − R1 − (P1 − P3)²)² − 4 (P1 − P3)² R1 = 0

    whose real roots z give (θ1, θ3) by the two SP4s (4 sign pairs per root; the pairs with
    ‖v1‖ = ‖v3‖ are kept) and θ2 by SP1 (Eq. (3)).  Up to 4 solutions, each verified:
    the equation's residual (length unit) is at most ``tol``; no least-squares solution.
    ``singular``: k2 parallel to k1 or to k3, which this closed form excludes (the paper
    solves those cases with SP1–SP4); no solution returned then.

    Vectors ``(3,)``/``(N, 3)``; ``k1``, ``k2``, ``k3`` unit axes.  m = 3, S = 4."""
    tol = _tol(tol)
    (p0, p1, p2, p3, k1, k2, k3), batched = _inputs(
        {
            "p0": (p0, "vec"),
            "p1": (p1, "vec"),
            "p2": (p2, "vec"),
            "p3": (p3, "vec"),
            "k1": (k1, "axis"),
            "k2": (k2, "axis"),
            "k3": (k3, "axis"),
        }
    )
    n = len(p0)
    theta, count, sing = np.empty((n, 4, 3)), np.empty(n, np.int64), np.empty(n, bool)
    _sp5_loop(p0, p1, p2, p3, k1, k2, k3, tol, theta, count, sing)
    valid = np.arange(4)[None, :] < count[:, None]
    return _finish(theta, valid, valid.copy(), sing, batched)


# ----------------------------------------------------------------------------- SP6
@kernel
def _sp6_residual(H, K, P, d1, d2, t0, t1):
    v0 = dot(H[0], rotate(K[0], t0, P[0]))
    v1 = dot(H[1], rotate(K[1], t1, P[1]))
    v2 = dot(H[2], rotate(K[2], t0, P[2]))
    v3 = dot(H[3], rotate(K[3], t1, P[3]))
    return v0 + v1 - d1, v2 + v3 - d2


@kernel
def _conic(xm0, xm1, n00, n01, n10, n11):
    """‖xm + N ξ‖² = 1 (xm (2,), N 2×2) as a ξ1² + b ξ1ξ2 + c ξ2² + d ξ1 + e ξ2 + f = 0."""
    return (
        n00 * n00 + n10 * n10,
        2.0 * (n00 * n01 + n10 * n11),
        n01 * n01 + n11 * n11,
        2.0 * (xm0 * n00 + xm1 * n10),
        2.0 * (xm0 * n01 + xm1 * n11),
        xm0 * xm0 + xm1 * xm1 - 1.0,
    )


# long: SP6's closed form as one compiled kernel (two conics, their quartic, its roots, their polish)
@kernel
def sp6_one(H, K, P, d1, d2, tol, out_theta):
    """SP6 of one problem (H, K, P: 4-tuples of vector tuples): writes the solutions into
    ``out_theta`` (4, 2) and returns (count, singular); see :func:`sp6`."""
    A, hk = local2(2, 4), local(4)
    for q in range(4):
        kxp = cross(K[q], P[q])
        row, col = q // 2, 2 * (q % 2)
        A[row, col] = dot(H[q], kxp)
        A[row, col + 1] = -dot(H[q], cross(K[q], kxp))
        hk[q] = dot(H[q], K[q]) * dot(K[q], P[q])
    b0, b1 = d1 - hk[0] - hk[1], d2 - hk[2] - hk[3]
    for j in range(4):
        out_theta[j, 0] = math.nan
        out_theta[j, 1] = math.nan
    # A = L Eᵀ: the rows of A orthonormalised (Gram–Schmidt), L lower triangular; the
    # product of A's singular values is |det L| = ‖a0‖ ‖w‖
    Vt, amax = local2(4, 4), 0.0
    n0 = 0.0
    for i in range(4):
        n0 += A[0, i] * A[0, i]
        amax = max(amax, abs(A[0, i]), abs(A[1, i]))
    n0 = math.sqrt(n0)
    if n0 <= 0.0:
        return 0, True
    l10, nw = 0.0, 0.0
    for i in range(4):
        Vt[0, i] = A[0, i] / n0
        l10 += Vt[0, i] * A[1, i]
    for i in range(4):
        Vt[1, i] = A[1, i] - l10 * Vt[0, i]
        nw += Vt[1, i] * Vt[1, i]
    nw = math.sqrt(nw)
    if n0 * nw <= 1e-12 * max(1.0, amax) ** 2:
        return 0, True  # the two equations are not independent
    for i in range(4):
        Vt[1, i] /= nw
    y0 = b0 / n0
    y1 = (b1 - l10 * y0) / nw
    xm = local(4)
    for i in range(4):
        xm[i] = Vt[0, i] * y0 + Vt[1, i] * y1  # minimum-norm solution of A x = b
    # the null space of A: the columns of I − E Eᵀ of largest norm, one after the other
    for r in (2, 3):
        best, kb = -1.0, 0
        for k in range(4):
            d = 1.0
            for m in range(r):
                d -= Vt[m, k] * Vt[m, k]
            if d > best:
                best, kb = d, k
        nn = 0.0
        for i in range(4):
            v = 1.0 if i == kb else 0.0
            for m in range(r):
                v -= Vt[m, i] * Vt[m, kb]
            Vt[r, i] = v
            nn += v * v
        nn = math.sqrt(nn)
        for i in range(4):
            Vt[r, i] /= nn
    # x = xm + N ξ with N = [Vt[2], Vt[3]]ᵀ (the null space of A)
    a, b_, c, d, e, f = _conic(xm[0], xm[1], Vt[2, 0], Vt[3, 0], Vt[2, 1], Vt[3, 1])
    a1, b1_, c1, dd1, e1, fq = _conic(xm[2], xm[3], Vt[2, 2], Vt[3, 2], Vt[2, 3], Vt[3, 3])
    b1 = b1_
    # resultant in ξ2 of the two conics (eliminating ξ1)
    z = local(5)
    z[4] = (
        f * a * dd1**2
        + a**2 * fq**2
        - d * a * dd1 * fq
        + a1**2 * f**2
        - 2 * a * fq * a1 * f
        - d * dd1 * a1 * f
        + a1 * d**2 * fq
    )
    z[3] = (
        e1 * d**2 * a1
        - fq * dd1 * a * b_
        - 2 * a * fq * a1 * e
        - f * a1 * b1 * d
        + 2 * dd1 * b1 * a * f
        + 2 * e1 * fq * a**2
        + dd1**2 * a * e
        - e1 * dd1 * a * d
        - 2 * a * e1 * a1 * f
        - f * a1 * dd1 * b_
        + 2 * f * e * a1**2
        - fq * b1 * a * d
        - e * a1 * dd1 * d
        + 2 * fq * b_ * a1 * d
    )
    z[2] = (
        e1**2 * a**2
        + 2 * c1 * fq * a**2
        - e * a1 * dd1 * b_
        + fq * a1 * b_**2
        - e * a1 * b1 * d
        - fq * b1 * a * b_
        - 2 * a * e1 * a1 * e
        + 2 * dd1 * b1 * a * e
        - c1 * dd1 * a * d
        - 2 * a * c1 * a1 * f
        + b1**2 * a * f
        + 2 * e1 * b_ * a1 * d
        + e**2 * a1**2
        - c * a1 * dd1 * d
        - e1 * b1 * a * d
        + 2 * f * c * a1**2
        - f * a1 * b1 * b_
        + c1 * d**2 * a1
        + dd1**2 * a * c
        - e1 * dd1 * a * b_
        - 2 * a * fq * a1 * c
    )
    z[1] = (
        -2 * a * a1 * c * e1
        + e1 * a1 * b_**2
        + 2 * c1 * b_ * a1 * d
        - c * a1 * b1 * d
        + b1**2 * a * e
        - e1 * b1 * a * b_
        - 2 * a * c1 * a1 * e
        - e * a1 * b1 * b_
        - c1 * b1 * a * d
        + 2 * e1 * c1 * a**2
        + 2 * e * c * a1**2
        - c * a1 * dd1 * b_
        + 2 * dd1 * b1 * a * c
        - c1 * dd1 * a * b_
    )
    z[0] = (
        a**2 * c1**2
        - 2 * a * c1 * a1 * c
        + a1**2 * c**2
        - b_ * a * b1 * c1
        - b_ * b1 * a1 * c
        + b_**2 * a1 * c1
        + c * a * b1**2
    )
    xi2s, real = local(4), local_flags(4)
    real_roots(z, xi2s, real)
    theta, ok, res = local2(4, 2), local_flags(4), local(4)
    for i in range(4):
        theta[i, 0], theta[i, 1], ok[i], res[i] = 0.0, 0.0, False, math.inf
    scl = 1.0 + norm(P[0]) + norm(P[1]) + norm(P[2]) + norm(P[3])
    for r in range(4):
        if not real[r]:
            continue
        xi2 = xi2s[r]
        den = a * b1 * xi2 + a * dd1 - a1 * b_ * xi2 - a1 * d
        if abs(den) <= 1e-300:
            continue
        xi1 = (
            -(a * fq + a * c1 * xi2**2 - a1 * c * xi2**2 + a * e1 * xi2 - a1 * e * xi2 - a1 * f)
            / den
        )
        x = local(4)
        for i in range(4):
            x[i] = xm[i] + Vt[2, i] * xi1 + Vt[3, i] * xi2
        t0, t1 = math.atan2(x[0], x[1]), math.atan2(x[2], x[3])
        if not (math.isfinite(t0) and math.isfinite(t1)):
            continue
        F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
        if max(abs(F0), abs(F1)) > 1e-2 * scl:
            continue
        for _ in range(3):  # Newton polish on the two equations
            F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
            g = local(4)
            for q in range(4):
                tq = t0 if q % 2 == 0 else t1
                g[q] = dot(H[q], cross(K[q], rotate(K[q], tq, P[q])))
            det = g[0] * g[3] - g[1] * g[2]
            if abs(det) > 1e-12:
                t0 -= (g[3] * F0 - g[1] * F1) / det
                t1 -= (-g[2] * F0 + g[0] * F1) / det
        t0, t1 = wrap(t0), wrap(t1)
        F0, F1 = _sp6_residual(H, K, P, d1, d2, t0, t1)
        theta[r, 0], theta[r, 1] = t0, t1
        res[r] = max(abs(F0), abs(F1))
        ok[r] = res[r] <= tol
    return _keep_best(theta, ok, res, out_theta, 2), False


@kernel
def _sp6_loop(H, K, P, d1, d2, tol, theta, count, sing):
    for i in range(len(d1)):
        Hi = (vec(H[i, 0]), vec(H[i, 1]), vec(H[i, 2]), vec(H[i, 3]))
        Ki = (vec(K[i, 0]), vec(K[i, 1]), vec(K[i, 2]), vec(K[i, 3]))
        Pi = (vec(P[i, 0]), vec(P[i, 1]), vec(P[i, 2]), vec(P[i, 3]))
        count[i], sing[i] = sp6_one(Hi, Ki, Pi, d1[i], d2[i], tol, theta[i])


def sp6(h, k, p, d1, d2, tol: float = TOL_QUARTIC) -> Solutions:
    """Subproblem 6, four circles: (θ1, θ2) with::

        h1ᵀ rot(k1, θ1) p1 + h2ᵀ rot(k2, θ2) p2 = d1
        h3ᵀ rot(k3, θ1) p3 + h4ᵀ rot(k4, θ2) p4 = d2

    IK-Geo §III-F: with x = (sin θ1, cos θ1, sin θ2, cos θ2) both equations are linear,
    A x = b (A 2×4 built from Eq. (2)); x = x_min + N ξ with the minimum-norm solution and the
    null space of A (here by Gram–Schmidt on the rows of A), and the two unit-circle constraints
    ‖x[0:2]‖ = ‖x[2:4]‖ = 1 are two ellipses in ξ ∈ ℝ², whose intersection is a quartic in ξ₂
    (closed-form ellipse–ellipse elimination).  Up to 4 solutions, each verified: both
    residuals (length unit) at most ``tol``; no least-squares solution.  ``singular``: the
    two equations are not independent (rank A < 2).

    ``h``, ``k``: unit axes ``(4, 3)`` or ``(N, 4, 3)`` (rows h1…h4, k1…k4); ``p``:
    ``(4, 3)``/``(N, 4, 3)``; ``d1``, ``d2``: scalar/``(N,)``.  m = 2, S = 4."""
    tol = _tol(tol)
    arrs = {}
    for name, v in (("h", h), ("k", k), ("p", p)):
        try:
            a = np.asarray(v, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"{name}: not an array of numbers ({exc})") from None
        if a.ndim not in (2, 3) or a.shape[-2:] != (4, 3):
            raise ParameterError(f"{name}: expected shape (4, 3) or (N, 4, 3), got {a.shape}")
        arrs[name] = a
    spec = {
        f"{name}{i + 1}": (arrs[name][..., i, :], "axis" if name != "p" else "vec")
        for name in ("h", "k", "p")
        for i in range(4)
    }
    spec.update({"d1": (d1, "scalar"), "d2": (d2, "scalar")})
    vals, batched = _inputs(spec)
    H, K, P = (
        np.ascontiguousarray(np.stack(vals[4 * j : 4 * j + 4], 1)) for j in range(3)
    )  # (N, 4, 3)
    d1, d2 = vals[12], vals[13]
    n = len(d1)
    theta, count, sing = np.empty((n, 4, 2)), np.empty(n, np.int64), np.empty(n, bool)
    _sp6_loop(H, K, P, d1, d2, tol, theta, count, sing)
    valid = np.arange(4)[None, :] < count[:, None]
    return _finish(theta, valid, valid.copy(), sing, batched)
