"""Real roots of the small polynomials of SP5 and SP6 (degree ≤ 4): bracketed between the roots
of the derivative and refined, then polished with the subproblem's equations."""

from __future__ import annotations

from ...jit import kernel, local2, local_ints2
from ..vec3 import cross, dot, wrap


# ----------------------------------------------------------------------------- quartics
@kernel
def _poly_d(a, n, x):
    """p(x) and p'(x) of the degree-n polynomial a[0..n] (highest first), by Horner."""
    f, g = a[0], 0.0
    for i in range(1, n + 1):
        g = g * x + f
        f = f * x + a[i]
    return f, g


@kernel
def _refine_root(a, n, lo, hi, flo):
    """The root of a[0..n] in (lo, hi) where p changes sign (p(lo) = ``flo``): Newton's
    method safeguarded by bisection (Press et al., *Numerical Recipes*, 3rd ed., §9.4
    "rtsafe"); Newton steps until the step is at rounding level."""
    x = 0.5 * (lo + hi)
    dxold = hi - lo
    dx = dxold
    neg_lo = flo < 0.0
    for _ in range(200):
        f, g = _poly_d(a, n, x)
        if f == 0.0:
            return x
        if (f < 0.0) == neg_lo:
            lo = x
        else:
            hi = x
        xn = x - f / g if g != 0.0 else lo - 1.0
        if not (lo < xn < hi) or abs(2.0 * f) > abs(dxold * g):
            xn = 0.5 * (lo + hi)  # bisection: Newton leaves the bracket or stalls
        dxold = dx
        dx = xn - x
        if xn == x or abs(dx) <= 4.4e-16 * abs(x) or hi - lo <= 4.4e-16 * max(abs(lo), abs(hi)):
            return xn
        x = xn
    return x


@kernel
def _bracket_roots(a, n, crit, cmul, m, out, omul):
    """Distinct real roots (ascending, into ``out``) and their multiplicities (``omul``) of the
    degree-n polynomial a[0..n] (a[0] ≠ 0), given the distinct real roots ``crit[:m]``
    (ascending, multiplicities ``cmul``) of its derivative; returns their number.

    p is monotone between consecutive critical points, so each interval holds at most one
    simple root (found by :func:`_refine_root` where p changes sign).  A critical point c is a
    root of multiplicity ``cmul + 1`` where: p has an extremum there (odd ``cmul``) that is 0 or
    misses zero by a pair of complex roots c ± iβ with β ≤ 1e-6 max(1, abs(c)) (β² ≈
    2 p(c) / p''(c), the tangent case; an extremum whose computed value crosses zero, however
    slightly, gives two simple roots, so close pairs are not merged); p is monotone across c
    (even ``cmul``) and vanishes there to rounding (``abs(p(c)) ≤ 4 (n + 1) ε Σ abs(aᵢ) abs(c)ⁱ``,
    a triple or higher root)."""
    a0 = a[0]
    bound = 0.0  # Fujiwara's bound on abs(root)
    for i in range(1, n + 1):
        t = abs(a[i] / a0)
        if i == n:
            t *= 0.5
        if t > 0.0:
            bound = max(bound, t ** (1.0 / i))
    bound *= 2.0
    for j in range(m):
        bound = max(bound, abs(crit[j]))
    bound = 1.5 * bound + 1e-300
    cnt = 0
    px = -bound
    pv, _ = _poly_d(a, n, px)
    for j in range(m + 1):
        last = j == m
        cx = bound if last else crit[j]
        cv, _ = _poly_d(a, n, cx)
        root = False
        if not last:
            s, ax = 0.0, abs(cx)
            for i in range(n + 1):
                s = s * ax + abs(a[i])
            if cmul[j] % 2 == 0:  # p monotone across c: a root of
                root = abs(cv) <= 4.0 * (n + 1) * 2.220446049250313e-16 * s  # odd multiplicity?
            elif cv == 0.0:
                root = True
            else:  # an extremum: tangent within 1e-6?
                p2 = 0.0
                for i in range(n - 1):
                    p2 = p2 * cx + a[i] * (n - i) * (n - i - 1)
                beta = 1e-6 * max(1.0, ax)
                if cv * p2 > 0.0 and 2.0 * cv / p2 <= beta * beta:
                    root = True
            if root:
                cv = 0.0
        if pv * cv < 0.0:
            out[cnt] = _refine_root(a, n, px, cx, pv)
            omul[cnt] = 1
            cnt += 1
        if root:
            out[cnt] = cx
            omul[cnt] = cmul[j] + 1
            cnt += 1
        px, pv = cx, cv
    return cnt


@kernel
def real_roots(c, x, real):
    """Real roots of a polynomial of degree ≤ 4 (coefficients ``c`` (5,), highest first) into
    ``x`` (4,) ascending with multiplicity (a double root twice) and ``real`` (4,) which are
    real (the real ones first; 0.0 in the other slots).  The coefficients are scaled by the largest abs(cᵢ);
    leading ones below 1e-10 (the first) or 1e-14 (the next) of it are dropped (lower degree);
    the zero polynomial and constants have no roots.

    Method: isolation by the derivatives (the real roots of p' split the line into intervals
    where p is monotone, so each holds at most one root; applied from the linear (deg−1)-th
    derivative up to p), each root found by bisection-safeguarded Newton iteration to rounding
    level (Press et al., *Numerical Recipes*, 3rd ed., §9.4; the derivative-bracketing scheme
    is e.g. that of Collins & Loos' real root isolation, see also Flocke, "Algorithm 954",
    ACM TOMS 41 (2015) for closed-form alternatives).  Double roots (tangent cases) are
    extrema of p that vanish or miss zero by a complex pair c ± iβ with β ≤ 1e-6 max(1, abs(c))
    (the tolerance of the former companion-matrix test), see :func:`_bracket_roots`."""
    big = 0.0
    for i in range(5):
        big = max(big, abs(c[i]))
    s = big if big > 0.0 else 1.0
    first = 0
    while first < 4 and abs(c[first] / s) <= (1e-10 if first == 0 else 1e-14):
        first += 1  # lower degree (rare)
    deg = 4 - first
    for i in range(4):
        x[i], real[i] = 0.0, False
    if deg == 0:
        return
    D = local2(4, 5)  # D[k]: k-th derivative, degree deg − k
    R = local2(4, 4)
    M = local_ints2(4, 4)
    for k in range(4):
        for i in range(5):
            D[k, i] = 0.0
        for i in range(4):
            R[k, i], M[k, i] = 0.0, 0
    for i in range(deg + 1):
        D[0, i] = c[first + i] / s
    for k in range(1, deg):
        mk = deg - k + 1
        for i in range(mk):
            D[k, i] = D[k - 1, i] * (mk - i)
    cnt = 1
    R[deg - 1, 0] = -D[deg - 1, 1] / D[deg - 1, 0]
    M[deg - 1, 0] = 1
    for k in range(deg - 2, -1, -1):
        cnt = _bracket_roots(D[k], deg - k, R[k + 1], M[k + 1], cnt, R[k], M[k])
    j = 0
    for r in range(cnt):
        for _ in range(M[0, r]):
            if j < 4:
                x[j] = R[0, r]
                real[j] = True
                j += 1


@kernel
def _solve3(J, F):
    """Solve the 3×3 system J x = F (J as row tuples) by Cramer's rule; (x, ok)."""
    det = dot(J[0], cross(J[1], J[2]))
    if abs(det) <= 1e-12:
        return (0.0, 0.0, 0.0), False
    c0, c1, c2 = cross(J[1], J[2]), cross(J[2], J[0]), cross(J[0], J[1])  # rows of adj(J)ᵀ
    return (
        (c0[0] * F[0] + c1[0] * F[1] + c2[0] * F[2]) / det,
        (c0[1] * F[0] + c1[1] * F[1] + c2[1] * F[2]) / det,
        (c0[2] * F[0] + c1[2] * F[1] + c2[2] * F[2]) / det,
    ), True


@kernel
def _keep_best(theta, ok, res, out_theta, m):
    """Sort candidate solutions by residual, drop the invalid and duplicates (within 1e-6 rad),
    keep the first 4 in ``out_theta`` (4, m); returns the count.  ``ok`` is consumed (the
    candidates are taken in order of residual, the first of equal ones first)."""
    cnt = 0
    while cnt < 4:
        j = -1
        for i in range(len(ok)):
            if ok[i] and (j < 0 or res[i] < res[j]):
                j = i
        if j < 0:
            break
        ok[j] = False
        dup = False
        for a in range(cnt):
            d = 0.0
            for c in range(m):
                d = max(d, abs(wrap(theta[j, c] - out_theta[a, c])))
            if d < 1e-6:
                dup = True
                break
        if not dup:
            for c in range(m):
                out_theta[cnt, c] = theta[j, c]
            cnt += 1
    return cnt
