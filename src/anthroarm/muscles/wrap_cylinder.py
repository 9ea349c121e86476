"""``WrapCylinder::wrapLine`` on complex-step rows, as compiled kernels.

The cylinder of :mod:`anthroarm.muscles.wrap` (its docstring: OpenSim 4's
``WrapCylinder.cpp``, the single-cylinder obstacle of Garner & Pandy 2000, the complex step),
written once as kernels (:mod:`anthroarm.jit`): every argument a (D, 3) ``complex128`` array of
rows (row 0 the real state, row d moved by i·h along one coordinate), every branch decided on
row 0's real part, every operation row by row, so that a compiled call and the interpreter's
(the reference) give the same numbers.  Scalar functions of a complex row are those of
``cmath`` (√, cos, sin: analytic, so Im f(x + i h ẋ) / h = f'(x) ẋ); the angle of the helix
is ``atan2`` of the real parts plus i times its first-order change,
(x Im y − y Im x) / (x² + y²).
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ..jit import kernel

#: SimmMacros.h / WrapMath.cpp / WrapCylinder.cpp constants
ROUNDOFF_ERROR = 2e-13
LINE_EPSILON = 1e-5
EPS = float(np.finfo(float).eps)
MAX_ITERATIONS = 100
TANGENCY_THRESHOLD = 0.1 * math.pi / 180.0
NO_WRAP, INSIDE, WRAPPED, MANDATORY = 0, -1, 1, 2


# ---------------------------------------------- rows of vectors (D, 3), complex128
@kernel
def dot(a, b):
    """a · b row by row: (D,)."""
    out = np.empty(a.shape[0], np.complex128)
    for d in range(a.shape[0]):
        out[d] = a[d, 0] * b[d, 0] + a[d, 1] * b[d, 1] + a[d, 2] * b[d, 2]
    return out


@kernel
def cross(a, b):
    """a × b row by row: (D, 3)."""
    out = np.empty(a.shape, np.complex128)
    for d in range(a.shape[0]):
        out[d, 0] = a[d, 1] * b[d, 2] - a[d, 2] * b[d, 1]
        out[d, 1] = a[d, 2] * b[d, 0] - a[d, 0] * b[d, 2]
        out[d, 2] = a[d, 0] * b[d, 1] - a[d, 1] * b[d, 0]
    return out


@kernel
def unit3(x, y, z):
    """(x, y, z) / m and m = √(x² + y² + z²) of one complex row; zero where Re m < eps
    (``WrapMath::NormalizeOrZero``)."""
    m = cmath.sqrt(x * x + y * y + z * z)
    if m.real < EPS:
        return 0j, 0j, 0j, m
    return x / m, y / m, z / m, m


@kernel
def unit(v):
    """(v / |v|, |v|) row by row (:func:`unit3`)."""
    out = np.empty(v.shape, np.complex128)
    m = np.empty(v.shape[0], np.complex128)
    for d in range(v.shape[0]):
        out[d, 0], out[d, 1], out[d, 2], m[d] = unit3(v[d, 0], v[d, 1], v[d, 2])
    return out, m


@kernel
def axpy(x, t, v):
    """x + t v row by row (t (D,))."""
    out = np.empty(x.shape, np.complex128)
    for d in range(x.shape[0]):
        for k in range(3):
            out[d, k] = x[d, k] + t[d] * v[d, k]
    return out


@kernel
def sub(a, b):
    """a − b."""
    out = np.empty(a.shape, np.complex128)
    for d in range(a.shape[0]):
        for k in range(3):
            out[d, k] = a[d, k] - b[d, k]
    return out


@kernel
def dist2(a, b):
    """Re |a₀ − b₀|² of row 0 (a decision)."""
    s = 0.0
    for k in range(3):
        e = a[0, k].real - b[0, k].real
        s += e * e
    return s


@kernel
def row0_unit(a, b):
    """Re(a₀ − b₀) of row 0, normalised (zero below eps): a real 3-vector for decisions."""
    x, y, z = (a[0, 0] - b[0, 0]).real, (a[0, 1] - b[0, 1]).real, (a[0, 2] - b[0, 2]).real
    m = math.sqrt(x * x + y * y + z * z)
    if m < EPS:
        return 0.0, 0.0, 0.0
    return x / m, y / m, z / m


@kernel
def closest_on_line(pt, line_pt, line):
    """The point of the line through ``line_pt`` along ``line`` closest to ``pt``
    (``WrapMath::GetClosestPointOnLineToPoint``): (point, its parameter along ``line``).  A line
    of zero length gives ``line_pt`` and a NaN parameter (Numba's compiled complex division by
    zero raises, whatever its error model: the end points of a path in a cylinder's mid-plane
    have the same point on its axis)."""
    v1, mag = unit(sub(pt, line_pt))
    v2, mag2 = unit(line)
    t = dot(v1, v2)
    for d in range(t.shape[0]):
        t[d] = t[d] * mag[d]
    par = np.empty(t.shape[0], np.complex128)
    for d in range(t.shape[0]):  # a line of zero length: NaN, as numpy's 0 / 0j gives
        par[d] = t[d] / mag2[d] if mag2[d] != 0.0 else complex(math.nan, math.nan)
    return axpy(line_pt, t, v2), par


@kernel
def on_axis(pt):
    """:func:`closest_on_line` of ``pt`` to the cylinder's axis (the line through (0, 0, −1)
    along z)."""
    n = pt.shape[0]
    p0 = np.zeros((n, 3), np.complex128)
    dn = np.zeros((n, 3), np.complex128)
    for d in range(n):
        p0[d, 2] = -1.0
        dn[d, 2] = 1.0
    return closest_on_line(pt, p0, dn)[0]


@kernel
def along_z(pt, line_pt):
    """The point of the line through ``line_pt`` along z closest to pt: (x₀, y₀, z) (what
    :func:`closest_on_line` computes for a z line, to rounding)."""
    out = line_pt.copy()
    for d in range(pt.shape[0]):
        out[d, 2] = pt[d, 2]
    return out


@kernel
def intersect_lines(p1, p2, p3, p4):
    """``WrapMath::IntersectLines``: (found, the point of line p1p2 nearest line p3p4, its
    parameter, the point of p3p4 nearest p1p2, its parameter); not found for parallel lines
    (decided on row 0).  With the unit directions v₁, v₂ and c = v₁ × v₂, the parameters are
    s = (p₃ − p₁)·(v₂ × c) / |c|² and t = (p₃ − p₁)·(v₁ × c) / |c|²."""
    n = p1.shape[0]
    near1, near2 = np.empty((n, 3), np.complex128), np.empty((n, 3), np.complex128)
    sp, tp = np.empty(n, np.complex128), np.empty(n, np.complex128)
    for d in range(n):
        a0, a1, a2, mag1 = unit3(p2[d, 0] - p1[d, 0], p2[d, 1] - p1[d, 1], p2[d, 2] - p1[d, 2])
        b0, b1, b2, mag2 = unit3(p4[d, 0] - p3[d, 0], p4[d, 1] - p3[d, 1], p4[d, 2] - p3[d, 2])
        c0, c1, c2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        denom = c0 * c0 + c1 * c1 + c2 * c2
        if d == 0 and abs(denom.real) <= ROUNDOFF_ERROR:
            return False, near1, sp, near2, tp
        e0, e1, e2 = p3[d, 0] - p1[d, 0], p3[d, 1] - p1[d, 1], p3[d, 2] - p1[d, 2]
        # det([p3 - p1; vec1; cp]) and det([p3 - p1; vec2; cp])
        t = e0 * (a1 * c2 - a2 * c1) + e1 * (a2 * c0 - a0 * c2) + e2 * (a0 * c1 - a1 * c0)
        s = e0 * (b1 * c2 - b2 * c1) + e1 * (b2 * c0 - b0 * c2) + e2 * (b0 * c1 - b1 * c0)
        t, s = t / denom, s / denom
        near1[d, 0], near1[d, 1], near1[d, 2] = (
            p1[d, 0] + s * a0,
            p1[d, 1] + s * a1,
            p1[d, 2] + s * a2,
        )
        near2[d, 0], near2[d, 1], near2[d, 2] = (
            p3[d, 0] + t * b0,
            p3[d, 1] + t * b1,
            p3[d, 2] + t * b2,
        )
        sp[d], tp[d] = s / mag1, t / mag2
    return True, near1, sp, near2, tp


@kernel
def intersect_seg_plane(pt1, pt2, plane, dd):
    """``WrapMath::IntersectLineSegPlane``: (found, the point where segment pt1 pt2 meets the
    plane n·x + d = 0)."""
    vec = sub(pt2, pt1)
    dt = dot(vec, plane)
    if abs(dt[0].real) < LINE_EPSILON:
        return False, pt1
    t = dot(plane, pt1)
    for d in range(t.shape[0]):
        t[d] = (-dd[d] - t[d]) / dt[d]
    if t[0].real < -LINE_EPSILON or t[0].real > 1.0 + LINE_EPSILON:
        return False, pt1
    return True, axpy(pt1, t, vec)


@kernel
def rot_z(angle, v):
    """v rotated by angle (D,) about the z axis."""
    out = np.empty(v.shape, np.complex128)
    for d in range(v.shape[0]):
        c, s = cmath.cos(angle[d]), cmath.sin(angle[d])
        out[d, 0] = c * v[d, 0] - s * v[d, 1]
        out[d, 1] = s * v[d, 0] + c * v[d, 1]
        out[d, 2] = v[d, 2]
    return out


@kernel
def sign(a):
    """+1 for a ≥ 0, else −1 (``DSIGN``)."""
    return 1 if a >= 0.0 else -1


# ------------------------------------------------------------------------------- cylinder
@kernel
def tangents(p, pc, radius):
    """The two tangent points from p (D, 3) to the circle of the cross-section through pc
    (p's foot on the axis), and |p − pc|."""
    vv, dist_p = unit(sub(p, pc))
    n = p.shape[0]
    a, b = np.empty((n, 3), np.complex128), np.empty((n, 3), np.complex128)
    for d in range(n):
        dd = radius * (radius / dist_p[d])
        h = cmath.sqrt(radius * radius - dd * dd)
        uu = (-vv[d, 1], vv[d, 0], 0.0 * vv[d, 2])  # DN × vv
        for k in range(3):
            pp = pc[d, k] + dd * vv[d, k]
            a[d, k] = pp + h * uu[k]
            b[d, k] = pp - h * uu[k]
    return a, b, dist_p


@kernel
def wrap_cylinder(p1, p2, radius, length, axis, wsign, single):
    """``WrapCylinder::wrapLine`` of end points p1, p2 (D, 3) (the cylinder's frame; row 0
    decides every branch): (code, r1 (D, 3), r2 (D, 3), arc length (D,), turn (D,)), the turn
    the signed angle about the cylinder's z axis from r1 to r2 along the helix; the points, arc
    and turn are zero for a code other than ``WRAPPED`` or ``MANDATORY``."""
    n = p1.shape[0]
    none = np.zeros((n, 3), np.complex128)
    r2_ = radius * radius
    constrained = wsign != 0
    far_side = False
    long_wrap = False
    code = WRAPPED
    # distance² to the axis (the line through P0 along DN)
    if (
        p1[0, 0].real ** 2 + p1[0, 1].real ** 2 < r2_
        or p2[0, 0].real ** 2 + p2[0, 1].real ** 2 < r2_
    ):
        return INSIDE, none, none, none[:, 0].copy(), none[:, 0].copy()
    cs, ce = np.zeros((n, 3), np.complex128), np.zeros((n, 3), np.complex128)
    for d in range(n):
        cs[d, 2], ce[d, 2] = -0.5 * length, 0.5 * length
    found, near12, t12, near00, _ = intersect_lines(p1, p2, cs, ce)
    crosses = found and dist2(near12, near00) < r2_ and 0 < t12[0].real < 1
    if not constrained:
        if crosses:
            code = MANDATORY
        else:
            return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
    p11, p22 = on_axis(p1), on_axis(p2)
    r1a, r1b, p11_dist = tangents(p1, p11, radius)
    r2a, r2b, p22_dist = tangents(p2, p22, radius)
    r1, r2 = r1a, r2a
    if constrained:
        s1, s2 = sign(p1[0, axis].real), sign(p2[0, axis].real)
        if s1 == wsign or s2 == wsign:
            if crosses:
                code = MANDATORY
            elif s1 != s2 and found and sign(near12[0, axis].real) != wsign:
                code = WRAPPED
            else:
                return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
        # decisions only: NaN compares false, as in C++
        m1a, m1b, m2a, m2b = sub(r1a, p11), sub(r1b, p11), sub(r2a, p22), sub(r2b, p22)
        alpha = _angle(m1a, m2b)
        beta = _angle(m1b, m2a)
        A, B = sign(r1a[0, axis].real) == wsign, sign(r1b[0, axis].real) == wsign
        if A and B:
            if sign(r2a[0, axis].real) == wsign:
                r1, r2, far_side = r1b, r2a, not (alpha > beta)
            else:
                r1, r2, far_side = r1a, r2b, alpha > beta
        elif A:
            r1, r2, far_side = r1a, r2b, alpha > beta
        elif B:
            r1, r2, far_side = r1b, r2a, not (alpha > beta)
        elif sign(r2a[0, axis].real) == wsign:
            r1, r2, far_side = r1b, r2a, not (alpha > beta)
        elif sign(r2b[0, axis].real) == wsign:
            r1, r2, far_side = r1a, r2b, alpha > beta
        else:
            if alpha > beta:
                r1, r2 = r1a, r2b
            else:
                r1, r2 = r1b, r2a
            far_side = True
        sm = 0.0
        for k in range(3):
            musc = (r1[0, k] - p1[0, k]).real + (r2[0, k] - p2[0, k]).real
            sm += ((r1[0, k] - p11[0, k]).real + (r2[0, k] - p22[0, k]).real) * musc
        long_wrap = sm < 0.0
    else:
        ua, ub = row0_unit(r1a, p11), row0_unit(r1b, p11)
        va, vb = row0_unit(r2a, p22), row0_unit(r2b, p22)
        d1 = ua[0] * va[0] + ua[1] * va[1] + ua[2] * va[2]
        d2 = ua[0] * vb[0] + ua[1] * vb[1] + ua[2] * vb[2]
        d3 = ub[0] * va[0] + ub[1] * va[1] + ub[2] * va[2]
        d4 = ub[0] * vb[0] + ub[1] * vb[1] + ub[2] * vb[2]
        if d1 > d2 and d1 > d3 and d1 > d4:
            r1, r2 = r1a, r2a
        elif d2 > d3 and d2 > d4:
            r1, r2 = r1a, r2b
        elif d3 > d4:
            r1, r2 = r1b, r2a
        else:
            r1, r2 = r1b, r2b
    t = np.empty(n, np.complex128)
    for d in range(n):
        t[d] = p11_dist[d] / (p11_dist[d] + p22_dist[d])
    mpt = axpy(p1, t, sub(p2, p1))
    axispt = on_axis(mpt)
    l1, l2 = unit(sub(p1, axispt))[0], unit(sub(p2, axispt))[0]
    normal = unit(unit(cross(l1, l2))[0])[0]
    dn = np.zeros((n, 3), np.complex128)
    rad = np.empty(n, np.complex128)
    for d in range(n):
        dn[d, 2] = 1.0
        rad[d] = radius
    vert1 = unit(cross(dn, normal))[0]
    vert2 = unit(cross(normal, dn))[0]
    apex1, apex2 = axpy(axispt, rad, vert1), axpy(axispt, rad, vert2)
    dist1, dist2_ = dist2(mpt, apex1), dist2(mpt, apex2)
    if far_side:
        apex = apex2 if dist1 < dist2_ else apex1
    else:
        apex = apex1 if dist1 < dist2_ else apex2
    uu, vv = unit(sub(p1, apex))[0], unit(sub(p2, apex))[0]
    normal = unit(cross(uu, vv))[0]
    dd = dot(p1, normal)
    ten = np.empty(n, np.complex128)
    for d in range(n):
        dd[d] = -dd[d]
        ten[d] = 10.0
    ok1, r1p = intersect_seg_plane(axpy(r1, -ten, dn), axpy(r1, ten, dn), normal, dd)
    ok2, r2p = intersect_seg_plane(axpy(r2, -ten, dn), axpy(r2, ten, dn), normal, dd)
    d12 = dist2(p11, p22)
    if ok1:
        c = closest_on_line(r1p, p11, p22)[0]
        if dist2(c, p22) < d12:
            r1 = r1p
    if ok2:
        c = closest_on_line(r2p, p11, p22)[0]
        if dist2(c, p11) < d12:
            r2 = r2p
    half = length / 2.0
    z1, z2 = r1[0, 2].real, r2[0, 2].real
    if (z1 < -half or z1 > half) and (z2 < -half or z2 > half):
        return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
    r1, r2, arc, turn = spiral(p1, p2, r1, r2, radius, long_wrap, single)
    return code, r1, r2, arc, turn


@kernel
def _angle(a, b):
    """The angle between row 0's real parts of a and b (NaN for a zero vector)."""
    x, y = a[0], b[0]
    ab = (x[0] * y[0] + x[1] * y[1] + x[2] * y[2]).real
    na = math.sqrt(x[0].real ** 2 + x[1].real ** 2 + x[2].real ** 2)
    nb = math.sqrt(y[0].real ** 2 + y[1].real ** 2 + y[2].real ** 2)
    return math.acos(ab / (na * nb))


@kernel
def spiral(p1, p2, r1, r2, radius, far_side, single):
    """``WrapCylinder::_make_spiral_path``: the helix's length √((r θ)² + Δz²) and turn (the
    signed angle about z from r1 to r2 along the helix: θ = atan2((û × v̂)_z, û·v̂) seen from
    the axis, 2π − θ the other way round on a far-side wrap), with the tangent points slid
    along the axis (``_adjust_tangent_point``) when the path has more than one wrap
    (``single`` False)."""
    n = p1.shape[0]
    sense = -1.0 if far_side else 1.0
    iterations = 0
    axial = np.empty(n, np.complex128)
    theta = np.empty(n, np.complex128)
    arc = np.empty(n, np.complex128)
    while True:
        for d in range(n):
            axial[d] = r2[d, 2] - r1[d, 2]
            # uu, vv: r1, r2 projected normal to the axis
            y = r1[d, 0] * r2[d, 1] - r1[d, 1] * r2[d, 0]
            x = r1[d, 0] * r2[d, 0] + r1[d, 1] * r2[d, 1]
            yr, xr = y.real, x.real
            th = math.atan2(yr, xr) + 1j * (xr * y.imag - yr * x.imag) / (xr * xr + yr * yr)
            if far_side:
                th = 2.0 * math.pi - th
            theta[d] = th
            rt = radius * th
            arc[d] = cmath.sqrt(rt * rt + axial[d] * axial[d])
        if single:
            return r1, r2, arc, sense * theta
        nseg = max(1, int(arc[0].real / 0.002))
        if nseg < 2 or iterations >= MAX_ITERATIONS:
            return r1, r2, arc, sense * theta
        t = 1.0 / nseg
        w1 = rot_z(sense * t * theta, r1)
        for d in range(n):
            w1[d, 2] += t * axial[d]
        a1, r1n = adjust(p1, r1, w1)
        # OpenSim's spiral-point lambda captures r1 by reference: the second point is placed
        # from the r1 just adjusted
        w2 = rot_z(sense * (1 - t) * theta, r1n)
        for d in range(n):
            w2[d, 2] += (1 - t) * axial[d]
        a2, r2n = adjust(p2, r2, w2)
        if not (a1 or a2):
            return r1, r2, arc, sense * theta
        r1, r2 = r1n, r2n
        iterations += 1


@kernel
def adjust(pt, r, w):
    """``WrapCylinder::_adjust_tangent_point``: (moved, r) — r moved 1.5 times towards where
    the line pt w meets the axis-parallel line through r, when the angles of r − pt and
    w − r to the axis differ by more than 0.1°."""
    pz = row0_unit(r, pt)[2]
    wz = row0_unit(w, r)[2]
    alpha = math.acos(min(max(pz, -1.0), 1.0)) if abs(pz) <= 1 else math.nan
    omega = math.acos(min(max(wz, -1.0), 1.0)) if abs(wz) <= 1 else math.nan
    if abs(alpha - omega) > TANGENCY_THRESHOLD:
        found, _, _, hit, _ = intersect_lines(pt, w, along_z(pt, r), along_z(w, r))
        if not found:
            return False, r
        out = np.empty(r.shape, np.complex128)
        for d in range(r.shape[0]):
            for k in range(3):
                out[d, k] = r[d, k] + 1.5 * (hit[d, k] - r[d, k])
        return True, out
    return False, r
