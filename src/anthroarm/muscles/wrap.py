"""Muscle paths over wrap surfaces: OpenSim 4's path wrapping, reproduced step by step.

A path with ``PathWrap``\\ s is computed as OpenSim's ``GeometryPath::applyWrapObjects`` does
(opensim-core, ``OpenSim/Simulation/Model/GeometryPath.cpp``): for each wrap in turn, every
segment between consecutive points of its range is tried; a *mandatory* wrap (the straight
segment crosses the surface) is taken at once, otherwise the wrapped segment that lengthens the
path least; two tangent points are inserted in the path, fixed in the wrap object's frame, and
the length of the surface path between them is added.  With two or more wraps, up to eight
passes until the length changes by less than 0.5 mm.

The surfaces (each ``wrapLine`` in the wrap object's own frame):

* ``WrapCylinder`` (``WrapCylinder.cpp``): the tangent lines from each end point to the
  circle of the cylinder's cross-section, the quadrant's side chosen as OpenSim chooses it,
  the helical arc between the tangent points of length √((r θ)² + Δz²), and — when the path
  has more than one wrap — OpenSim's sliding of the tangent points along the axis until the
  straight lines meet the helix within 0.1° (``_adjust_tangent_point``).  The geometry is that
  of Garner & Pandy, *The Obstacle-Set Method for Representing Muscle Paths in
  Musculoskeletal Models*, Comput Methods Biomech Biomed Engin 3 (2000) 1-30, single-cylinder
  obstacle.
* ``WrapSphere`` (``WrapSphere.cpp``): the great circle through both end points' tangent
  points, wrapping only where the straight segment crosses the sphere (Garner & Pandy 2000,
  sphere obstacle).

Derivative.  The tangent points are fixed in the wrap object's frame while the path's length
is differentiated, and the surface arc between them is constant: ∂l/∂q is the sum of the unit
vectors of the straight segments times the derivatives of their end points — the moment arm
OpenSim's ``MomentArmSolver`` computes (unit tension applied at the points of
``GeometryPath::getPointForceDirections``: no force between two points of one body).  Where
the wrap path is the shortest one (a sphere, a cylinder without axial travel) this is the
exact −∂l/∂q (envelope theorem); along a cylinder's axis OpenSim's tangent points are not
exactly those of the shortest helix and the two differ slightly (measured in the guide).
``WrapEllipsoid`` (``WrapEllipsoid.cpp``) is :func:`anthroarm.muscles.wrap_ellipsoid.ellipsoid`:
its surface path is not a shortest one, so its tangent points move with the path's end points
and their derivatives (complex step, exact to rounding) enter ∂l/∂q.  Tori are not evaluated
(:class:`~anthroarm.errors.MuscleError`).
"""

from __future__ import annotations

import numpy as np

from ..errors import MuscleError
from .wrap_ellipsoid import ellipsoid

#: SimmMacros.h / WrapMath.cpp / WrapCylinder.cpp constants
ROUNDOFF_ERROR = 2e-13
LINE_EPSILON = 1e-5
EPS = np.finfo(float).eps
MAX_ITERATIONS = 100
TANGENCY_THRESHOLD = 0.1 * np.pi / 180.0
NO_WRAP, INSIDE, WRAPPED, MANDATORY = 0, -1, 1, 2
P0 = np.array([0.0, 0.0, -1.0])
DN = np.array([0.0, 0.0, 1.0])
QUADRANTS = {"x": (0, 1), "y": (1, 1), "z": (2, 1)}


def quadrant(name: str) -> tuple[int, int]:
    """(axis, sign) of a wrap object's quadrant, sign 0 for ``all`` (``WrapObject.cpp``)."""
    q = name.strip().lower()
    if q in ("all", "unassigned", ""):
        return 0, 0
    sign = -1 if q.startswith("-") else 1
    q = q.lstrip("+-")
    if q not in QUADRANTS:
        raise MuscleError(f"wrap quadrant {name!r} is not one of all, x, -x, y, -y, z, -z")
    return QUADRANTS[q][0], sign


def _sign(a: float) -> int:
    return 1 if a >= 0.0 else -1


def _unit(v):
    m = float(np.linalg.norm(v))
    return (v / m if m >= EPS else np.zeros(3)), m


def _closest_on_line(pt, line_pt, line):
    v1, mag = _unit(pt - line_pt)
    v2, mag2 = _unit(line)
    t = float(v1 @ v2) * mag
    return line_pt + t * v2, t / mag2


def _dist2_to_line(pt, line_pt, line):
    d = line_pt - pt
    n = line / np.linalg.norm(line)
    d = d - (d @ n) * n
    return float(d @ d)


def _intersect_lines(p1, p2, p3, p4):
    vec1, mag1 = _unit(p2 - p1)
    vec2, mag2 = _unit(p4 - p3)
    cp = np.cross(vec1, vec2)
    denom = float(cp @ cp)
    if abs(denom) <= ROUNDOFF_ERROR:
        return None, np.nan, None, np.nan
    mat = np.array([p3 - p1, vec1, cp])
    t = np.linalg.det(mat) / denom
    p_int2 = p3 + t * vec2
    mat[1] = vec2
    s = np.linalg.det(mat) / denom
    p_int1 = p1 + s * vec1
    return p_int1, s / mag1, p_int2, t / mag2


def _intersect_seg_plane(pt1, pt2, plane, d):
    vec = pt2 - pt1
    dot = float(vec @ plane)
    if abs(dot) < LINE_EPSILON:
        return None
    t = (-d - plane @ pt1) / dot
    if t < -LINE_EPSILON or t > 1.0 + LINE_EPSILON:
        return None
    return pt1 + t * vec


def _rotation(angle, axis):
    a = axis / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


# ------------------------------------------------------------------------------- cylinder
def cylinder(p1, p2, radius, length, quad, single):
    """``WrapCylinder::wrapLine``: (code, r1, r2, arc length) in the cylinder's frame."""
    r2_ = radius * radius
    axis, wsign = quad
    constrained = wsign != 0
    far_side = long_wrap = False
    code = WRAPPED
    if _dist2_to_line(p1, P0, DN) < r2_ or _dist2_to_line(p2, P0, DN) < r2_:
        return INSIDE, None, None, 0.0
    cs, ce = np.array([0, 0, -0.5 * length]), np.array([0, 0, 0.5 * length])
    near12, t12, near00, _ = _intersect_lines(p1, p2, cs, ce)
    crosses = near12 is not None and float(np.sum((near12 - near00) ** 2)) < r2_ and 0 < t12 < 1
    if not constrained:
        if crosses:
            code = MANDATORY
        else:
            return NO_WRAP, None, None, 0.0
    p11, _ = _closest_on_line(p1, P0, DN)
    p22, _ = _closest_on_line(p2, P0, DN)

    def tangents(p, pc):
        vv, dist_p = _unit(p - pc)
        sin_t = radius / dist_p
        d = radius * sin_t
        pp = pc + d * vv
        d = np.sqrt(r2_ - d * d)
        uu = np.cross(DN, vv)
        return pp + d * uu, pp - d * uu, dist_p

    r1a, r1b, p11_dist = tangents(p1, p11)
    r2a, r2b, p22_dist = tangents(p2, p22)
    if constrained:
        s1, s2 = _sign(p1[axis]), _sign(p2[axis])
        if s1 == wsign or s2 == wsign:
            if crosses:
                code = MANDATORY
            elif s1 != s2 and near12 is not None and _sign(near12[axis]) != wsign:
                code = WRAPPED
            else:
                return NO_WRAP, None, None, 0.0
        r1am, r1bm, r2am, r2bm = r1a - p11, r1b - p11, r2a - p22, r2b - p22
        alpha = np.arccos((r1am @ r2bm) / (np.linalg.norm(r1am) * np.linalg.norm(r2bm)))
        beta = np.arccos((r1bm @ r2am) / (np.linalg.norm(r1bm) * np.linalg.norm(r2am)))
        A, B = _sign(r1a[axis]) == wsign, _sign(r1b[axis]) == wsign
        if A and B:
            if _sign(r2a[axis]) == wsign:
                r1, r2, far_side = r1b, r2a, not (alpha > beta)
            else:
                r1, r2, far_side = r1a, r2b, alpha > beta
        elif A:
            r1, r2, far_side = r1a, r2b, alpha > beta
        elif B:
            r1, r2, far_side = r1b, r2a, not (alpha > beta)
        elif _sign(r2a[axis]) == wsign:
            r1, r2, far_side = r1b, r2a, not (alpha > beta)
        elif _sign(r2b[axis]) == wsign:
            r1, r2, far_side = r1a, r2b, alpha > beta
        else:
            r1, r2 = (r1a, r2b) if alpha > beta else (r1b, r2a)
            far_side = True
        sum_musc = (r1 - p1) + (r2 - p2)
        sum_r = (r1 - p11) + (r2 - p22)
        long_wrap = float(sum_r @ sum_musc) < 0.0
    else:
        ua, ub = _unit(r1a - p11)[0], _unit(r1b - p11)[0]
        va, vb = _unit(r2a - p22)[0], _unit(r2b - p22)[0]
        d1, d2, d3, d4 = ua @ va, ua @ vb, ub @ va, ub @ vb
        if d1 > d2 and d1 > d3 and d1 > d4:
            r1, r2 = r1a, r2a
        elif d2 > d3 and d2 > d4:
            r1, r2 = r1a, r2b
        elif d3 > d4:
            r1, r2 = r1b, r2a
        else:
            r1, r2 = r1b, r2b
    r1, r2 = r1.copy(), r2.copy()
    t = p11_dist / (p11_dist + p22_dist)
    mpt = p1 + t * (p2 - p1)
    axispt, _ = _closest_on_line(mpt, P0, DN)
    l1, l2 = _unit(p1 - axispt)[0], _unit(p2 - axispt)[0]
    normal = _unit(_unit(np.cross(l1, l2))[0])[0]
    vert1 = _unit(np.cross(DN, normal))[0]
    vert2 = _unit(np.cross(normal, DN))[0]
    apex1, apex2 = axispt + radius * vert1, axispt + radius * vert2
    dist1, dist2 = np.sum((mpt - apex1) ** 2), np.sum((mpt - apex2) ** 2)
    if far_side:
        apex = apex2 if dist1 < dist2 else apex1
    else:
        apex = apex1 if dist1 < dist2 else apex2
    uu, vv = _unit(p1 - apex)[0], _unit(p2 - apex)[0]
    normal = _unit(np.cross(uu, vv))[0]
    d = -(p1 @ normal)
    r1p = _intersect_seg_plane(r1 - 10.0 * DN, r1 + 10.0 * DN, normal, d)
    r2p = _intersect_seg_plane(r2 - 10.0 * DN, r2 + 10.0 * DN, normal, d)
    if r1p is not None:
        c, _ = _closest_on_line(r1p, p11, p22)
        if np.sum((c - p22) ** 2) < np.sum((p11 - p22) ** 2):
            r1 = r1p
    if r2p is not None:
        c, _ = _closest_on_line(r2p, p11, p22)
        if np.sum((c - p11) ** 2) < np.sum((p22 - p11) ** 2):
            r2 = r2p
    half = length / 2.0
    if (r1[2] < -half or r1[2] > half) and (r2[2] < -half or r2[2] > half):
        return NO_WRAP, None, None, 0.0
    r1, r2, arc = _spiral(p1, p2, r1, r2, radius, long_wrap, single)
    return code, r1, r2, arc


def _spiral(p1, p2, r1, r2, radius, far_side, single):
    """``WrapCylinder::_make_spiral_path``: the helix's length, with the tangent points slid
    along the axis (``_adjust_tangent_point``) when the path has more than one wrap."""
    sense = -1.0 if far_side else 1.0
    iterations = 0
    while True:
        r1a, _ = _closest_on_line(r1, P0, DN)
        r2a, _ = _closest_on_line(r2, P0, DN)
        axial = float((r2a - r1a) @ DN)
        uu, vv = r1 - r1a, r2 - r2a
        theta = np.arctan2(np.cross(uu, vv) @ DN, uu @ vv)
        if far_side:
            theta = 2.0 * np.pi - theta
        arc = float(np.hypot(radius * theta, axial))
        if single:
            return r1, r2, arc
        nseg = max(1, int(arc / 0.002))
        if nseg < 2 or iterations >= MAX_ITERATIONS:
            return r1, r2, arc
        t = 1.0 / nseg
        w1 = _rotation(sense * t * theta, DN) @ r1 + DN * (t * axial)
        a1, r1n = _adjust(p1, r1, w1)
        # OpenSim's spiral-point lambda captures r1 by reference: the second point is placed
        # from the r1 just adjusted
        w2 = _rotation(sense * (1 - t) * theta, DN) @ r1n + DN * ((1 - t) * axial)
        a2, r2n = _adjust(p2, r2, w2)
        if not (a1 or a2):
            return r1, r2, arc
        r1, r2 = r1n, r2n
        iterations += 1


def _adjust(pt, r, w):
    pr, _ = _unit(r - pt)
    rw, _ = _unit(w - r)
    alpha = np.arccos(np.clip(pr @ DN, -1, 1)) if abs(pr @ DN) <= 1 else np.nan
    omega = np.arccos(np.clip(rw @ DN, -1, 1)) if abs(rw @ DN) <= 1 else np.nan
    if abs(alpha - omega) > TANGENCY_THRESHOLD:
        p1a, _ = _closest_on_line(pt, r, DN)
        w1a, _ = _closest_on_line(w, r, DN)
        _, _, hit, _ = _intersect_lines(pt, w, p1a, w1a)
        if hit is None:
            return False, r
        return True, r + 1.5 * (hit - r)
    return False, r


# ---------------------------------------------------------------------------------- sphere
def sphere(p1, p2, radius, quad):
    """``WrapSphere::wrapLine``: (code, r1, r2, arc length) in the sphere's frame."""
    axis, wsign = quad
    code = WRAPPED
    far_side = False
    n1, n2 = np.linalg.norm(p1), np.linalg.norm(p2)
    if n1 < radius or n2 < radius:
        return INSIDE, None, None, 0.0
    ri, mp = p1 - p2, -p2
    a, b, c = ri @ ri, -2.0 * (mp @ ri), mp @ mp - radius * radius
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return NO_WRAP, None, None, 0.0
    l1 = (-b + np.sqrt(disc)) / (2.0 * a)
    l2 = (-b - np.sqrt(disc)) / (2.0 * a)
    if not (0.0 < l1 < 1.0) or not (0.0 < l2 < 1.0) or l1 < l2:
        return NO_WRAP, None, None, 0.0
    p1p2, _ = _unit(p1 - p2)
    np2, _ = _unit(p2)
    hp2 = np.cross(p1p2, np2)
    if np.linalg.norm(hp2) < 1e-5:
        raise MuscleError(
            "the path passes through the sphere's centre: the wrap plane is undefined"
        )
    n, _ = _unit(hp2)

    def tangents(p, pn):
        y, _ = _unit(-p)
        z = np.cross(n, y)
        ra = np.column_stack([n, y, z])
        a1 = np.arcsin(radius / pn)
        out = []
        for ang in (a1, -a1):
            aa = ra @ _rotation(ang, np.array([1.0, 0, 0])).T
            out.append(p + aa[:, 1] * pn * np.cos(a1))
        return out

    r1a, r1b = tangents(p1, n1)
    r2a, r2b = tangents(p2, n2)
    r1am, r1bm, r2am, r2bm = (_unit(v)[0] for v in (r1a, r1b, r2a, r2b))
    j1, j2, j3, j4 = r1am @ r2am, r1am @ r2bm, r1bm @ r2am, r1bm @ r2bm
    if j1 > j2 and j1 > j3 and j1 > j4:
        r1, r2, r11, r22 = r1a, r2a, r1b, r2b
    elif j2 > j3 and j2 > j4:
        r1, r2, r11, r22 = r1a, r2b, r1b, r2a
    elif j3 > j4:
        r1, r2, r11, r22 = r1b, r2a, r1a, r2b
    else:
        r1, r2, r11, r22 = r1b, r2b, r1a, r2a
    if wsign != 0:
        s1, s2 = _sign(p1[axis]), _sign(p2[axis])
        if s1 == wsign or s2 == wsign:
            mm, tt = _closest_on_line(np.zeros(3), p1, p1p2)
            tt = -tt
            if mm @ mm < radius * radius and 0.0 < tt < 1.0:
                code = MANDATORY
            elif s1 != s2 and _sign(mm[axis]) != wsign:
                code = WRAPPED
            else:
                return NO_WRAP, None, None, 0.0
        if s1 != wsign or s2 != wsign:
            wrapaxis = np.zeros(3)
            wrapaxis[axis] = wsign
            sm, _ = _unit(-p1 - p2)
            r1, r11 = (r1a, r1b) if r1am @ sm > r1bm @ sm else (r1b, r1a)
            r2, r22 = (r2a, r2b) if r2am @ sm > r2bm @ sm else (r2b, r2a)
            sm, _ = _unit((r1 - p1) + (r2 - p2))
            if sm @ wrapaxis < 0.0:
                r1, r2 = r11, r22
            sum_musc = (r1 - p1) + (r2 - p2)
            far_side = float((r1 + r2) @ sum_musc) < 0.0
    r1n, _ = _unit(r1)
    r2n, _ = _unit(r2)
    angle = np.arccos(np.clip(r1n @ r2n, -1.0, 1.0))
    if far_side:
        angle = -(2 * np.pi - angle)
    return code, r1.copy(), r2.copy(), float(radius * angle)


# ------------------------------------------------------------------------------ the path
def _wrap_line(w, p1, p2, single, method="hybrid"):
    """(code, r1, r2, arc, jac) in the wrap object's frame; jac (ellipsoids only): the
    derivatives of r1, r2 and the arc with respect to (p1, p2), else None."""
    if w.kind == "WrapCylinder":
        return (*cylinder(p1, p2, w.radius, w.length, quadrant(w.quadrant), single), None)
    if w.kind == "WrapSphere":
        return (*sphere(p1, p2, w.radius, quadrant(w.quadrant)), None)
    if w.kind == "WrapEllipsoid":
        return ellipsoid(p1, p2, w.dimensions, quadrant(w.quadrant), method)
    raise MuscleError(
        f"wrap object {w.name!r} is a {w.kind}: only WrapCylinder, WrapSphere and "
        "WrapEllipsoid are evaluated; pass wrap=False or make it inactive"
    )


def wrapped_length(xs, dxs, idx, objs, muscle, codes=None):
    """Length (N,) and ∂l/∂q (N, nq) of one muscle's path over its wrap objects.

    ``xs`` (N, K, 3) and ``dxs`` (N, K, 3, nq): the active path points (original indices
    ``idx`` in the PathPointSet) in ground; ``objs``: (PathWrap, WrapObject, T (N,4,4) of the
    wrap's body, J (N,6,nq) of that body) for every PathWrap (inactive objects are skipped as
    OpenSim skips them, but count in the number of wraps).  ``codes`` (N, number of wraps),
    when given, receives each wrap's outcome (:func:`anthroarm.muscles.wrap.status` of the codes)."""
    n, nq = xs.shape[0], dxs.shape[-1]
    L, D = np.zeros(n), np.zeros((n, nq))
    npts = len(muscle.points)
    for s in range(n):
        out = None if codes is None else codes[s]
        L[s], D[s] = _one_state(xs[s], dxs[s], idx, objs, s, npts, nq, muscle.name, out)
    return L, D


def status(wrapped: bool, inside: bool) -> int:
    """A wrap's outcome on one state: ``WRAPPED`` (1) when the path wraps over it, ``INSIDE``
    (-1) when it does not and a segment tried had an end point inside the surface (OpenSim
    then lets the path pass straight through the object), else ``NO_WRAP`` (0)."""
    return WRAPPED if wrapped else (INSIDE if inside else NO_WRAP)


def _one_state(x, dx, idx, objs, s, npts, nq, name, codes=None):
    # a path entry: (kind, payload); "p": original point k; "w": (wrap j, 1|2)
    path = [("p", int(k)) for k in idx]
    pos = {("p", int(k)): i for i, k in enumerate(idx)}
    wpts: dict = {}  # j -> (r1 body, r2 body, arc)
    frames = []
    for pw, w, T, _ in objs:
        Tb = T[s]
        Tw = np.eye(4)
        Tw[:3, :3], Tw[:3, 3] = w.rotation, w.translation
        frames.append((Tb, Tw))

    def ground(e):
        if e[0] == "p":
            return x[pos[e]]
        j, which = e[1]
        Tb = frames[j][0]
        return Tb[:3, :3] @ wpts[j][which - 1] + Tb[:3, 3]

    # OpenSim's Point::getLocationInGround caches a point's ground position at its first use
    # in a state; a wrap point moved by a later pass keeps the old one in the path's length
    # and in calcPathLengthChange (the wrap computations themselves use the new one)
    stale: dict = {}

    def gpos(e):
        if e[0] == "p":
            return x[pos[e]]
        if e[1] not in stale:
            stale[e[1]] = ground(e)
        return stale[e[1]]

    def length():
        total = 0.0
        for a, b in zip(path[:-1], path[1:]):
            if a[0] == "w" and b[0] == "w" and a[1][0] == b[1][0]:
                total += wpts[b[1][0]][2]
            else:
                total += float(np.linalg.norm(gpos(b) - gpos(a)))
        return total

    nw = len(objs)
    order = list(range(nw))
    results = [NO_WRAP] * nw
    inside = [False] * nw
    last = np.inf
    for kk in range(1 if nw < 2 else 8):
        for i in range(nw):
            j = order[i]
            pw, w = objs[j][0], objs[j][1]
            results[i] = NO_WRAP
            path = [e for e in path if not (e[0] == "w" and e[1][0] == j)]
            wpts.pop(j, None)
            if not w.active:
                continue
            ws = pw.range[0] - 1 if pw.range[0] >= 1 else 0
            we = pw.range[1] - 1 if pw.range[1] >= 1 else npts - 1
            act = [k for k in idx if ws <= k <= we]
            if not act:
                break
            start, end = path.index(("p", act[0])), path.index(("p", act[-1]))
            Tb, Tw = frames[j]
            to_w = np.linalg.inv(Tb @ Tw)
            best, best_change = None, np.inf
            for a in range(start, end):
                ea, eb = path[a], path[a + 1]
                if ea[0] == "w" and eb[0] == "w" and ea[1][0] == eb[1][0]:
                    continue
                ga, gb = ground(ea), ground(eb)
                p1 = to_w[:3, :3] @ ga + to_w[:3, 3]
                p2 = to_w[:3, :3] @ gb + to_w[:3, 3]
                code, r1, r2, arc, jac = _wrap_line(w, p1, p2, nw == 1, pw.method)
                results[i] = code
                inside[j] = inside[j] or code == INSIDE
                if code in (WRAPPED, MANDATORY):
                    r1b = Tw[:3, :3] @ r1 + Tw[:3, 3]
                    r2b = Tw[:3, :3] @ r2 + Tw[:3, 3]
                    used = (jac, ea, eb, ga, gb)
                    if code == MANDATORY:
                        best = (a, r1b, r2b, arc, used)
                        break
                    g1 = Tb[:3, :3] @ r1b + Tb[:3, 3]
                    g2 = Tb[:3, :3] @ r2b + Tb[:3, 3]
                    ca, cb = gpos(ea), gpos(eb)
                    change = (
                        np.linalg.norm(g1 - ca) + arc + np.linalg.norm(cb - g2)
                    ) - np.linalg.norm(cb - ca)
                    if change < best_change:
                        best, best_change = (a, r1b, r2b, arc, used), change
            if best is not None:
                a, r1b, r2b, arc, used = best
                wpts[j] = (r1b, r2b, arc, used)
                path[a + 1 : a + 1] = [("w", (j, 1)), ("w", (j, 2))]
        total = length()
        if abs(total - last) < 0.0005:
            break
        last = total
        if kk == 0 and nw > 1 and results[0] == NO_WRAP and results[1] == INSIDE:
            order[0], order[1] = 1, 0
            path = [e for e in path if not (e[0] == "w" and e[1][0] == 0)]
            wpts.pop(0, None)
    # the gradient: straight segments; tangent points fixed in their wrap object's body, but
    # an ellipsoid's move with its end points (wrap_ellipsoid: its path is not the shortest)
    # (a stale tangent point: fixed in its body at its cached position)
    fresh = {
        j: all(np.linalg.norm(gpos(("w", (j, k))) - ground(("w", (j, k)))) <= 1e-12 for k in (1, 2))
        for j in wpts
    }
    moving = {
        j: _ellipsoid_motion(j, wpts[j], ground, dx, pos, objs, frames, s) if fresh[j] else None
        for j in wpts
    }
    grad = np.zeros(nq)
    total = 0.0
    for a, b in zip(path[:-1], path[1:]):
        if a[0] == "w" and b[0] == "w" and a[1][0] == b[1][0]:
            j = b[1][0]
            total += wpts[j][2]
            if moving[j] is not None:
                grad += moving[j][2]
            continue
        ga, gb = gpos(a), gpos(b)
        d = gb - ga
        seg = float(np.linalg.norm(d))
        if seg < 1e-12:
            raise MuscleError(f"muscle {name!r}: two consecutive path points coincide")
        total += seg
        db = _dpoint(b, gb, dx, pos, objs, frames, s, moving)
        grad += (d / seg) @ (db - _dpoint(a, ga, dx, pos, objs, frames, s, moving))
    if codes is not None:
        codes[:] = [status(j in wpts, inside[j]) for j in range(nw)]
    return total, grad


def _dpoint(e, g, dx, pos, objs, frames, s, moving=None):
    """∂x/∂q (3, nq) of path entry e at ground position g."""
    if e[0] == "p":
        return dx[pos[e]]
    j = e[1][0]
    out = _dfixed(g, j, objs, frames, s)
    if moving is not None and moving.get(j) is not None:
        out = out + moving[j][e[1][1] - 1]
    return out


def _dfixed(g, j, objs, frames, s):
    """∂x/∂q of the point of wrap j's body at ground position g."""
    Tb = frames[j][0]
    J = objs[j][3][s]
    rs = g - Tb[:3, 3]
    return J[:3] - np.cross(rs[:, None], J[3:], axis=0)


def _ellipsoid_motion(j, wp, ground, dx, pos, objs, frames, s):
    """For an ellipsoid wrap j: (∂r1/∂q, ∂r2/∂q relative to its body (3, nq) each, ∂arc/∂q
    (nq,)) through the end points it was computed from; None for other surfaces, or when an
    end point has moved since (a later pass of a multi-wrap path: the tangent points are then
    held fixed in the body, OpenSim's convention)."""
    jac, ea, eb, ga, gb = wp[3]
    if jac is None:
        return None
    if np.linalg.norm(ground(ea) - ga) > 1e-12 or np.linalg.norm(ground(eb) - gb) > 1e-12:
        return None
    Tb, Tw = frames[j]
    R = Tb[:3, :3] @ Tw[:3, :3]  # the wrap frame in ground
    # the end points' motion relative to the wrap body, in the wrap frame (6, nq)
    dP = np.concatenate(
        [
            R.T @ (_dpoint(e, g, dx, pos, objs, frames, s) - _dfixed(g, j, objs, frames, s))
            for e, g in ((ea, ga), (eb, gb))
        ]
    )
    dr1, dr2, darc = jac
    return R @ (dr1 @ dP), R @ (dr2 @ dP), darc @ dP
