"""The pass loop of a muscle path over its wrap objects, and ``WrapSphere::wrapLine``, as
compiled kernels.

:func:`passes` is OpenSim 4's ``GeometryPath::applyWrapObjects`` (opensim-core,
``OpenSim/Simulation/Model/GeometryPath.cpp``) on the states of one muscle whose active path
points are the same, as :mod:`anthroarm.muscles.wrap` describes it (the algorithm, the complex
step and which derivative): for each wrap in turn every segment of its range is tried, a
mandatory wrap taken at once, otherwise the one that lengthens the path least; up to eight
passes over two or more wraps until the length changes by less than 0.5 mm, the first two wraps
swapped after the first pass when the last segment the first tried did not wrap and the last
the second tried had an end point inside; the ground position of a wrap point kept from its first use in the state, as OpenSim's
``Point::getLocationInGround`` caches it.  Each state is a set of complex-step rows (row 0 the
real state, every branch decided on it).

Data layout (one call, N states of D rows, K active points, W wraps):

* the path: an int array of entries, k ≥ 0 the k-th active point, −(2j + 1) and −(2j + 2) the
  first and second tangent point of wrap j (OpenSim's ``PathWrapPoint``\\ s);
* ``x`` (N, D, K, 3): the active points in ground; ``rg`` (N, W, D, 3, 3) and ``og``
  (N, W, D, 3): each wrap object's frame in ground (its axes as columns, its origin);
* ``wint`` (W, 7): each wrap's kind (``CYLINDER``, ``SPHERE``, ``ELLIPSOID``,
  ``OTHER``), active flag, quadrant axis and sign (sign 0: all), ellipsoid method
  (``METHODS`` of :mod:`anthroarm.muscles.wrap_ellipsoid`) and the range of original path-point
  indices it applies to (zero-based, inclusive); ``wflt`` (W, 3): radius and length of a
  cylinder, radius of a sphere, the radii of an ellipsoid;
* the tangent points of a wrap are kept in the wrap object's frame (fixed there: a cylinder's or
  sphere's held real with ``hold``, :func:`anthroarm.muscles.wrap.wrapped_length`), their arc
  length beside them.

A failure (coinciding path points, a wrap kind not evaluated, a path through a sphere's centre,
an ellipsoid's tangent points not converged) stops the call with a status code
(``COINCIDE`` ...) that the Python caller turns into a
:class:`~anthroarm.errors.MuscleError`.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ..jit import kernel
from .wrap_cylinder import (
    INSIDE,
    MANDATORY,
    NO_WRAP,
    WRAPPED,
    closest_on_line,
    cross,
    dist2,
    dot,
    row0_unit,
    sign,
    sub,
    unit,
    wrap_cylinder,
)
from .wrap_ellipsoid import wrap as wrap_ellipsoid

#: complex step (the rows' imaginary parts are h times the derivatives)
H = 1e-30
#: wrap kinds, as ``wint`` numbers them
CYLINDER, SPHERE, ELLIPSOID, OTHER = 0, 1, 2, 3
#: the columns of ``wint``
KIND, ACTIVE, AXIS, SIGN, METHOD, FIRST, LAST = 0, 1, 2, 3, 4, 5, 6
#: :func:`wrap_sphere`'s code for a path through the sphere's centre (no wrap plane)
THROUGH_CENTRE = -2
#: the status of :func:`passes`
OK, COINCIDE, UNSUPPORTED, CENTRE, NOT_CONVERGED = 0, 1, 2, 3, 4
#: consecutive path points closer than this (m) coincide
COINCIDE_TOL = 1e-12
#: OpenSim's convergence of the passes (m) and their largest number
CONVERGED = 0.0005
MAX_PASSES = 8


# ---------------------------------------------------------------------------------- sphere
@kernel
def wrap_sphere(p1, p2, radius, axis, wsign):
    """``WrapSphere::wrapLine`` (``WrapSphere.cpp``; Garner & Pandy 2000, sphere obstacle) of
    end points p1, p2 (D, 3) complex rows (the sphere's frame; row 0 decides every branch):
    (code, r1 (D, 3), r2 (D, 3), arc length (D,), turn (D,)), the turn the signed angle about
    (r1 × r2)/|r1 × r2| from r1 to r2 along the great circle (OpenSim's −(2π − θ) on a far-side
    wrap, whose arc length it then takes negative, as OpenSim does); zero points, arc and turn
    for a code other than ``WRAPPED`` or ``MANDATORY``, ``THROUGH_CENTRE`` for a path
    through the centre (the wrap plane undefined)."""
    n = p1.shape[0]
    none = np.zeros((n, 3), np.complex128)
    code = WRAPPED
    far_side = False
    n1, n2 = np.empty(n, np.complex128), np.empty(n, np.complex128)
    q1, q2 = dot(p1, p1), dot(p2, p2)
    for d in range(n):
        n1[d], n2[d] = cmath.sqrt(q1[d]), cmath.sqrt(q2[d])
    if n1[0].real < radius or n2[0].real < radius:
        return INSIDE, none, none, none[:, 0].copy(), none[:, 0].copy()
    # the segment p2 + t (p1 − p2) meets the sphere at t = l1, l2 (row 0: decisions only)
    a = b = c = 0.0
    for k in range(3):
        ri, mp = (p1[0, k] - p2[0, k]).real, -p2[0, k].real
        a += ri * ri
        b += mp * ri
        c += mp * mp
    b, c = -2.0 * b, c - radius * radius
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
    l1 = (-b + math.sqrt(disc)) / (2.0 * a)
    l2 = (-b - math.sqrt(disc)) / (2.0 * a)
    if not (0.0 < l1 < 1.0) or not (0.0 < l2 < 1.0) or l1 < l2:
        return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
    p1p2 = unit(sub(p1, p2))[0]
    hp2 = cross(p1p2, unit(p2)[0])
    if cmath.sqrt(dot(hp2, hp2)[0]).real < 1e-5:
        return THROUGH_CENTRE, none, none, none[:, 0].copy(), none[:, 0].copy()
    nrm = unit(hp2)[0]
    r1a, r1b = _sphere_tangents(p1, n1, nrm, radius)
    r2a, r2b = _sphere_tangents(p2, n2, nrm, radius)
    r1am, r1bm = row0_unit(r1a, none), row0_unit(r1b, none)
    r2am, r2bm = row0_unit(r2a, none), row0_unit(r2b, none)
    j1, j2 = _dot3(r1am, r2am), _dot3(r1am, r2bm)
    j3, j4 = _dot3(r1bm, r2am), _dot3(r1bm, r2bm)
    if j1 > j2 and j1 > j3 and j1 > j4:
        r1, r2, r11, r22 = r1a, r2a, r1b, r2b
    elif j2 > j3 and j2 > j4:
        r1, r2, r11, r22 = r1a, r2b, r1b, r2a
    elif j3 > j4:
        r1, r2, r11, r22 = r1b, r2a, r1a, r2b
    else:
        r1, r2, r11, r22 = r1b, r2b, r1a, r2a
    if wsign != 0:
        s1, s2 = sign(p1[0, axis].real), sign(p2[0, axis].real)
        if s1 == wsign or s2 == wsign:
            # the point of the line through p1 along p1p2 closest to the centre
            mm, tt = closest_on_line(none[:1], p1[:1], p1p2[:1])
            m2 = 0.0
            for k in range(3):
                m2 += mm[0, k].real * mm[0, k].real
            t = -tt[0].real
            if m2 < radius * radius and 0.0 < t < 1.0:
                code = MANDATORY
            elif s1 != s2 and sign(mm[0, axis].real) != wsign:
                code = WRAPPED
            else:
                return NO_WRAP, none, none, none[:, 0].copy(), none[:, 0].copy()
        if s1 != wsign or s2 != wsign:
            mid = np.zeros((1, 3), np.complex128)
            for k in range(3):
                mid[0, k] = -p1[0, k].real - p2[0, k].real
            sm = row0_unit(mid, none)
            if _dot3(r1am, sm) > _dot3(r1bm, sm):
                r1, r11 = r1a, r1b
            else:
                r1, r11 = r1b, r1a
            if _dot3(r2am, sm) > _dot3(r2bm, sm):
                r2, r22 = r2a, r2b
            else:
                r2, r22 = r2b, r2a
            if row0_unit(_musc(r1, p1, r2, p2), none)[axis] * wsign < 0.0:
                r1, r2 = r11, r22
            musc = _musc(r1, p1, r2, p2)
            far = 0.0
            for k in range(3):
                far += (r1[0, k] + r2[0, k]).real * musc[0, k].real
            far_side = far < 0.0
    u1, u2 = unit(r1)[0], unit(r2)[0]
    cosine = dot(u1, u2)
    angle = np.empty(n, np.complex128)
    for d in range(n):
        x = cosine[d]
        if abs(x.real) > 1.0:  # clipped: this row keeps no derivative
            angle[d] = math.acos(min(max(x.real, -1.0), 1.0))
        else:
            angle[d] = cmath.acos(x)
        if far_side:
            angle[d] = -(2.0 * math.pi - angle[d])
    arc = np.empty(n, np.complex128)
    for d in range(n):
        arc[d] = radius * angle[d]
    return code, r1, r2, arc, angle


@kernel
def _sphere_tangents(p, pn, nrm, radius):
    """OpenSim's two tangent points from p (D, 3) to the sphere in the wrap plane of normal
    ``nrm``: the columns (n, y, z) rotated by ±asin(radius / |p|) about the first."""
    n = p.shape[0]
    neg = np.empty((n, 3), np.complex128)
    for d in range(n):
        for k in range(3):
            neg[d, k] = -p[d, k]
    y = unit(neg)[0]
    z = cross(nrm, y)
    ra, rb = np.empty((n, 3), np.complex128), np.empty((n, 3), np.complex128)
    for d in range(n):
        a1 = cmath.asin(radius / pn[d])
        c, s = cmath.cos(a1), cmath.sin(a1)
        dd = pn[d] * c
        for k in range(3):
            ra[d, k] = p[d, k] + (c * y[d, k] - s * z[d, k]) * dd
            rb[d, k] = p[d, k] + (c * y[d, k] + s * z[d, k]) * dd
    return ra, rb


@kernel
def _dot3(u, v):
    """u · v of two real 3-tuples."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@kernel
def _musc(r1, p1, r2, p2):
    """(r1 − p1) + (r2 − p2) of row 0, real (1, 3)."""
    out = np.zeros((1, 3), np.complex128)
    for k in range(3):
        out[0, k] = (r1[0, k] - p1[0, k]).real + (r2[0, k] - p2[0, k]).real
    return out


# ------------------------------------------------------------------------------ one wrap
@kernel
def _finite(r1, r2, arc):
    """Whether every row of r1, r2 (D, 3) and arc (D,) is finite."""
    for d in range(arc.shape[0]):
        for z in (arc[d], r1[d, 0], r1[d, 1], r1[d, 2], r2[d, 0], r2[d, 1], r2[d, 2]):
            if not (math.isfinite(z.real) and math.isfinite(z.imag)):
                return False
    return True


# ------------------------------------------------------------------------------- the path
@kernel
def _wrap_of(e):
    """(wrap j, 0 or 1) of a tangent-point entry e < 0 of a path."""
    return (-e - 1) // 2, (-e - 1) % 2


@kernel
def _ground(e, x, rg, og, wp, out):
    """out (D, 3) = the ground position of path entry e now (a tangent point from the current
    tangent points ``wp`` (W, 2, D, 3) in the wrap frames)."""
    if e >= 0:
        for d in range(out.shape[0]):
            for k in range(3):
                out[d, k] = x[d, e, k]
        return
    j, w = _wrap_of(e)
    for d in range(out.shape[0]):
        for k in range(3):
            out[d, k] = (
                rg[j, d, k, 0] * wp[j, w, d, 0]
                + rg[j, d, k, 1] * wp[j, w, d, 1]
                + rg[j, d, k, 2] * wp[j, w, d, 2]
                + og[j, d, k]
            )


@kernel
def _gpos(e, x, rg, og, wp, cached, stale, out):
    """``_ground`` as the path's length sees it: a tangent point's ground position at its
    first use in the state, kept in ``stale`` (OpenSim's ``Point::getLocationInGround`` cache;
    a wrap point moved by a later pass keeps it)."""
    if e >= 0:
        _ground(e, x, rg, og, wp, out)
        return
    j, w = _wrap_of(e)
    if not cached[j, w]:
        _ground(e, x, rg, og, wp, stale[j, w])
        cached[j, w] = True
    for d in range(out.shape[0]):
        for k in range(3):
            out[d, k] = stale[j, w, d, k]


@kernel
def _to_frame(rg, og, g, out):
    """out (D, 3) = g (D, 3) in the frame (rg (D, 3, 3), og (D, 3)): rgᵀ (g − og)."""
    for d in range(out.shape[0]):
        e0, e1, e2 = g[d, 0] - og[d, 0], g[d, 1] - og[d, 1], g[d, 2] - og[d, 2]
        for k in range(3):
            out[d, k] = rg[d, 0, k] * e0 + rg[d, 1, k] * e1 + rg[d, 2, k] * e2


@kernel
def _drop(path, n, j):
    """Remove wrap j's tangent points from the path's n entries: the new count."""
    m = 0
    for a in range(n):
        e = path[a]
        if e < 0 and _wrap_of(e)[0] == j:
            continue
        path[m] = e
        m += 1
    return m


@kernel
def _length(path, n, x, rg, og, wp, arcs, cached, stale, total, ga, gb, final):
    """total (D,) = the path's length (the straight segments between the ground positions
    ``_gpos``, the arc between a wrap's two tangent points); False when ``final`` and two
    consecutive points coincide (row 0)."""
    for d in range(total.shape[0]):
        total[d] = 0.0
    for a in range(n - 1):
        ea, eb = path[a], path[a + 1]
        if ea < 0 and eb < 0 and _wrap_of(ea)[0] == _wrap_of(eb)[0]:
            j = _wrap_of(eb)[0]
            for d in range(total.shape[0]):
                total[d] = total[d] + arcs[j, d]
            continue
        _gpos(eb, x, rg, og, wp, cached, stale, gb)
        _gpos(ea, x, rg, og, wp, cached, stale, ga)
        for d in range(total.shape[0]):
            e0, e1, e2 = gb[d, 0] - ga[d, 0], gb[d, 1] - ga[d, 1], gb[d, 2] - ga[d, 2]
            seg = cmath.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            if final and d == 0 and seg.real < COINCIDE_TOL:
                return False
            total[d] = total[d] + seg
    return True


@kernel
def _ground0(rg, og, r, out):
    """out (1, 3) = row 0 of the point r (the wrap frame, row 0) in ground, real."""
    for k in range(3):
        out[0, k] = (
            rg[0, k, 0] * r[0, 0] + rg[0, k, 1] * r[0, 1] + rg[0, k, 2] * r[0, 2] + og[0, k]
        ).real


@kernel
def status(wrapped, inside):
    """A wrap's outcome on one state: ``WRAPPED`` (1) when the path wraps over it, ``INSIDE``
    (-1) when it does not and a segment tried had an end point inside the surface (OpenSim
    then lets the path pass straight through the object), else ``NO_WRAP`` (0)."""
    return WRAPPED if wrapped else (INSIDE if inside else NO_WRAP)


@kernel
def passes(x, rg, og, wint, wflt, idx, hold, lengths, grads, codes, paths, npath, tang, ends):
    """The passes over every state s of x (N, D, K, 3), rg (N, W, D, 3, 3), og (N, W, D, 3)
    (the module docstring): ``lengths[s]`` the length (row 0), ``grads[s]`` (D − 1,) its
    derivatives (Im row d / h), ``codes[s]`` (W,) each wrap's outcome (:func:`status`),
    ``paths[s]`` the final path (its first ``npath[s]`` entries), ``tang[s]`` (W, 2, 3) its
    tangent points in ground (row 0, the positions the length uses) and ``ends[s]`` (W, 2, 3)
    the end points (row 0, the wrap frame) of the segment each wrap wraps.  Returns (status,
    wrap j, state s) of the first failure, (``OK``, −1, −1) without one.

    One kernel from the states down to the surfaces' kernels (each kernel that calls the
    cylinder's and the ellipsoid's compiles their code again: ~10 s a level)."""
    N, D, K, W = x.shape[0], x.shape[1], x.shape[2], wint.shape[0]
    single = W == 1
    wp = np.zeros((W, 2, D, 3), np.complex128)  # the tangent points, wrap frames
    arcs = np.zeros((W, D), np.complex128)
    stale = np.zeros((W, 2, D, 3), np.complex128)
    cached = np.zeros((W, 2), np.bool_)
    has = np.zeros(W, np.bool_)
    inside = np.zeros(W, np.bool_)
    results = np.zeros(W, np.int64)
    order = np.zeros(W, np.int64)
    total = np.empty(D, np.complex128)
    ga, gb = np.empty((D, 3), np.complex128), np.empty((D, 3), np.complex128)
    p1, p2 = np.empty((D, 3), np.complex128), np.empty((D, 3), np.complex128)
    h1, h2 = np.empty((1, 3), np.complex128), np.empty((1, 3), np.complex128)
    g1, g2 = np.empty((1, 3), np.complex128), np.empty((1, 3), np.complex128)
    for s in range(N):
        xs, rgs, ogs, path = x[s], rg[s], og[s], paths[s]
        for j in range(W):
            cached[j, 0] = cached[j, 1] = has[j] = inside[j] = False
            results[j], order[j] = NO_WRAP, j
        for k in range(K):
            path[k] = k
        n = K
        last = math.inf
        for kk in range(1 if W < 2 else MAX_PASSES):
            for i in range(W):
                j = order[i]
                results[i] = NO_WRAP
                n = _drop(path, n, j)
                has[j] = False
                if wint[j, ACTIVE] == 0:
                    continue
                first = lastk = -1
                for k in range(K):
                    if wint[j, FIRST] <= idx[k] <= wint[j, LAST]:
                        if first < 0:
                            first = k
                        lastk = k
                if first < 0:
                    break
                start = end = 0
                for a in range(n):
                    if path[a] == first:
                        start = a
                    if path[a] == lastk:
                        end = a
                kind, axis, wsign = wint[j, KIND], wint[j, AXIS], wint[j, SIGN]
                best, best_change = -1, math.inf
                for a in range(start, end):
                    ea, eb = path[a], path[a + 1]
                    if ea < 0 and eb < 0 and (-ea - 1) // 2 == (-eb - 1) // 2:
                        continue
                    _ground(ea, xs, rgs, ogs, wp, ga)
                    _to_frame(rgs[j], ogs[j], ga, p1)
                    _ground(eb, xs, rgs, ogs, wp, gb)
                    _to_frame(rgs[j], ogs[j], gb, p2)
                    # the wrapLine of the object, in its frame; held: from row 0, real
                    if kind == CYLINDER or kind == SPHERE:
                        q1, q2 = p1, p2
                        if hold:
                            for k in range(3):
                                h1[0, k], h2[0, k] = p1[0, k].real, p2[0, k].real
                            q1, q2 = h1, h2
                        radius = wflt[j, 0]
                        if kind == CYLINDER:
                            cyl = wrap_cylinder(q1, q2, radius, wflt[j, 1], axis, wsign, single)
                            code, r1, r2, arc = cyl[0], cyl[1], cyl[2], cyl[3]
                        else:
                            sph = wrap_sphere(q1, q2, radius, axis, wsign)
                            code, r1, r2, arc = sph[0], sph[1], sph[2], sph[3]
                    elif kind == ELLIPSOID:
                        ell = wrap_ellipsoid(p1, p2, wflt[j], axis, wsign, wint[j, METHOD])
                        code, r1, r2, arc = ell[0], ell[1], ell[2], ell[3]
                    else:
                        return UNSUPPORTED, j, s
                    results[i] = code
                    if code == INSIDE:
                        inside[j] = True
                    if code == THROUGH_CENTRE:
                        return CENTRE, j, s
                    if code != WRAPPED and code != MANDATORY:
                        continue
                    if kind == ELLIPSOID and not _finite(r1, r2, arc):
                        return NOT_CONVERGED, j, s
                    if code == WRAPPED:
                        _ground0(rgs[j], ogs[j], r1, g1)
                        _ground0(rgs[j], ogs[j], r2, g2)
                        _gpos(ea, xs, rgs, ogs, wp, cached, stale, ga)
                        _gpos(eb, xs, rgs, ogs, wp, cached, stale, gb)
                        d1, d2, d0 = dist2(g1, ga), dist2(gb, g2), dist2(gb, ga)
                        change = math.sqrt(d1) + arc[0].real + math.sqrt(d2) - math.sqrt(d0)
                        if not (change < best_change):
                            continue
                        best_change = change
                    best = a
                    m = r1.shape[0]  # 1 row when held
                    for d in range(D):
                        arcs[j, d] = arc[d if m > 1 else 0]
                        for k in range(3):
                            wp[j, 0, d, k] = r1[d if m > 1 else 0, k]
                            wp[j, 1, d, k] = r2[d if m > 1 else 0, k]
                    for k in range(3):
                        ends[s, j, 0, k], ends[s, j, 1, k] = p1[0, k].real, p2[0, k].real
                    if code == MANDATORY:
                        break
                if best >= 0:
                    has[j] = True
                    for a in range(n - 1, best, -1):
                        path[a + 2] = path[a]
                    path[best + 1], path[best + 2] = -(2 * j + 1), -(2 * j + 2)
                    n += 2
            _length(path, n, xs, rgs, ogs, wp, arcs, cached, stale, total, ga, gb, False)
            now = total[0].real
            if abs(now - last) < CONVERGED:
                break
            last = now
            if kk == 0 and W > 1 and results[0] == NO_WRAP and results[1] == INSIDE:
                order[0], order[1] = 1, 0
                n = _drop(path, n, 0)
                has[0] = False
        for j in range(W):
            codes[s, j] = status(has[j], inside[j])
        if not _length(path, n, xs, rgs, ogs, wp, arcs, cached, stale, total, ga, gb, True):
            return COINCIDE, -1, s
        for a in range(n):
            if path[a] < 0:
                j, w = _wrap_of(path[a])
                for k in range(3):
                    tang[s, j, w, k] = stale[j, w, 0, k].real
        npath[s] = n
        lengths[s] = total[0].real
        for d in range(1, D):
            grads[s, d - 1] = total[d].imag / H
    return OK, -1, -1
