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
  straight lines meet the helix within 0.1° (``_adjust``).  The geometry is that of Garner &
  Pandy, *The Obstacle-Set Method for Representing Muscle Paths in Musculoskeletal Models*,
  Comput Methods Biomech Biomed Engin 3 (2000) 1-30, single-cylinder obstacle.  Compiled
  kernels: :mod:`anthroarm.muscles.wrap_cylinder`.
* ``WrapSphere`` (``WrapSphere.cpp``): the great circle through both end points' tangent
  points, wrapping only where the straight segment crosses the sphere (Garner & Pandy 2000,
  sphere obstacle).
* ``WrapEllipsoid`` (``WrapEllipsoid.cpp``): :mod:`anthroarm.muscles.wrap_ellipsoid` (compiled
  kernels too).
  Tori are not evaluated (:class:`~anthroarm.errors.MuscleError`).

Derivative: the complex step (Squire & Trapp, *Using complex variables to estimate derivatives
of real functions*, SIAM Rev 40 (1998) 110-112; Martins, Sturdza & Alonso, *The complex-step
derivative approximation*, ACM TOMS 29 (2003) 245-262) through the whole path.  Every input
is a row of D = 1 + m: row 0 the real state, row d the state moved by i·h along the d-th
coordinate the path depends on (path points x + i h ∂x/∂q_d; wrap bodies' poses
(R + i h [ω_d]× R, o + i h v_d) from their Jacobians), h = 1e-30.  Every branch (which
segment wraps, the quadrant's side, the number of passes and of tangent-point adjustments) is
decided on row 0's real part, every operation on a branch is analytic (norms √(v·v),
``arctan2`` and clipped ``arccos`` by their first-order expansions), so Im l_d / h is ∂l/∂q_d
of the length exactly as computed, to rounding — with OpenSim's cached wrap-point positions of
a multi-pass path (``Point::getLocationInGround`` keeps a point's first ground position in a
state) differentiated as what they are: functions of the state through the pass that computed
them.

Which derivative.  On a path with an active ``WrapEllipsoid`` r = −∂l/∂q exactly (the
ellipsoid's surface path is not a shortest one: its tangent points move with the path).  On a
path over cylinders and spheres only, the tangent points and arcs are taken real (fixed in
their wrap body, at the ground position the path's length uses): ∂l/∂q is then the sum of the
straight segments' unit vectors times their end points' derivatives, the moment arm OpenSim's
``MomentArmSolver`` computes (unit tension at the points of
``GeometryPath::getPointForceDirections``), equal to OpenSim's ``computeMomentArm`` to
rounding and the exact −∂l/∂q wherever the wrap path is a shortest one (envelope theorem);
along a cylinder's axis, and over the slid tangent points of a multi-wrap path, the two differ
slightly (measured in the guide).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import MuscleError
from .wrap_cylinder import EPS, INSIDE, MANDATORY, NO_WRAP, WRAPPED, rot_z, wrap_cylinder
from .wrap_ellipsoid import wrap_line as ellipsoid_line

QUADRANTS = {"x": (0, 1), "y": (1, 1), "z": (2, 1)}
#: complex step (any h below ~1e-20 gives the same derivative)
H = 1e-30
#: the largest amount (m) by which a drawn cylinder or sphere arc (a polyline of chords) may be
#: shorter than the arc itself (:func:`surface_points`)
ARC_TOLERANCE = 1e-7


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


# ---------------------------------------------- vectors (D, 3), real or complex-step rows
def _re(a) -> float:
    """Row 0's real part of a (D,) array (branches are decided on it)."""
    return float(np.real(a[0]))


def _sign(a: float) -> int:
    return 1 if a >= 0.0 else -1


def _dot(a, b):
    return np.add.reduce(a * b, axis=-1)


def _norm(v):
    return np.sqrt(_dot(v, v))


def _cross(a, b):
    return a.take(_I1, -1) * b.take(_I2, -1) - a.take(_I2, -1) * b.take(_I1, -1)


_I1, _I2 = np.array([1, 2, 0]), np.array([2, 0, 1])


def _unit(v):
    """(v / |v|, |v|), zero where |v| < eps (``WrapMath::NormalizeOrZero``)."""
    m = _norm(v)
    small = np.real(m) < EPS  # √ of a sum of squares: Re ≥ 0
    if small.any():
        return np.where(small[..., None], 0.0, v / np.where(small, 1.0, m)[..., None]), m
    return v / m[..., None], m


def _acos(x):
    """arccos, its argument clipped to [-1, 1] (a clipped row keeps no derivative)."""
    out = np.abs(np.real(x)) > 1.0
    return np.arccos(np.where(out, np.clip(np.real(x), -1.0, 1.0), x))


def _closest_on_line(pt, line_pt, line):
    v1, mag = _unit(pt - line_pt)
    v2, mag2 = _unit(line)
    t = _dot(v1, v2) * mag
    return line_pt + t[..., None] * v2, t / mag2


# ------------------------------------------------------------------------------- cylinder
def cylinder(p1, p2, radius, length, quad, single):
    """``WrapCylinder::wrapLine`` of end points p1, p2 (D, 3) (the cylinder's frame; row 0
    decides every branch): (code, r1 (D, 3), r2 (D, 3), arc length (D,), turn (D,)), the turn
    the signed angle about the cylinder's z axis from r1 to r2 along the helix
    (:func:`surface_points`); None, None, 0 and None for a path that does not wrap; the
    compiled kernel :func:`anthroarm.muscles.wrap_cylinder.wrap_cylinder` on complex rows."""
    p1 = np.ascontiguousarray(p1, dtype=complex)
    p2 = np.ascontiguousarray(p2, dtype=complex)
    axis, wsign = quad
    code, r1, r2, arc, turn = wrap_cylinder(
        p1, p2, float(radius), float(length), int(axis), int(wsign), bool(single)
    )
    if code in (WRAPPED, MANDATORY):
        return code, r1, r2, arc, turn
    return code, None, None, 0.0, None


# ---------------------------------------------------------------------------------- sphere
def sphere(p1, p2, radius, quad):
    """``WrapSphere::wrapLine`` of end points p1, p2 (D, 3) (the sphere's frame; row 0
    decides every branch): (code, r1 (D, 3), r2 (D, 3), arc length (D,), turn (D,)), the
    turn the signed angle about (r1 × r2)/|r1 × r2| from r1 to r2 along the great circle
    (OpenSim's −(2π − θ) on a far-side wrap, whose arc length it then takes negative, as
    OpenSim does)."""
    axis, wsign = quad
    code = WRAPPED
    far_side = False
    n1, n2 = _norm(p1), _norm(p2)
    if _re(n1) < radius or _re(n2) < radius:
        return INSIDE, None, None, 0.0, None
    ri, mp = p1 - p2, -p2
    a, b, c = _dot(ri, ri), -2.0 * _dot(mp, ri), _dot(mp, mp) - radius * radius
    a, b, c = _re(a), _re(b), _re(c)  # decisions only
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return NO_WRAP, None, None, 0.0, None
    l1 = (-b + np.sqrt(disc)) / (2.0 * a)
    l2 = (-b - np.sqrt(disc)) / (2.0 * a)
    if not (0.0 < l1 < 1.0) or not (0.0 < l2 < 1.0) or l1 < l2:
        return NO_WRAP, None, None, 0.0, None
    p1p2, _ = _unit(p1 - p2)
    hp2 = _cross(p1p2, _unit(p2)[0])
    if _re(_norm(hp2)) < 1e-5:
        raise MuscleError(
            "the path passes through the sphere's centre: the wrap plane is undefined"
        )
    n, _ = _unit(hp2)

    def tangents(p, pn):
        # OpenSim: the columns (n, y, z) rotated by ±asin(radius / |p|) about the first
        y, _ = _unit(-p)
        z = _cross(n, y)
        a1 = np.arcsin(radius / pn)
        d = (pn * np.cos(a1))[:, None]
        c, s = np.cos(a1)[:, None], np.sin(a1)[:, None]
        return p + (c * y - s * z) * d, p + (c * y + s * z) * d

    r1a, r1b = tangents(p1, n1)
    r2a, r2b = tangents(p2, n2)
    r1am, r1bm, r2am, r2bm = (_unit(v[:1].real)[0][0] for v in (r1a, r1b, r2a, r2b))
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
        q1, q2 = p1[0].real, p2[0].real
        s1, s2 = _sign(q1[axis]), _sign(q2[axis])
        if s1 == wsign or s2 == wsign:
            mm, tt = _closest_on_line(np.zeros(3), q1, p1p2[0].real)
            tt = -tt
            if mm @ mm < radius * radius and 0.0 < tt < 1.0:
                code = MANDATORY
            elif s1 != s2 and _sign(mm[axis]) != wsign:
                code = WRAPPED
            else:
                return NO_WRAP, None, None, 0.0, None
        if s1 != wsign or s2 != wsign:
            wrapaxis = np.zeros(3)
            wrapaxis[axis] = wsign
            sm, _ = _unit(-q1 - q2)
            r1, r11 = (r1a, r1b) if r1am @ sm > r1bm @ sm else (r1b, r1a)
            r2, r22 = (r2a, r2b) if r2am @ sm > r2bm @ sm else (r2b, r2a)
            sm, _ = _unit(((r1 - p1) + (r2 - p2))[0].real)
            if sm @ wrapaxis < 0.0:
                r1, r2 = r11, r22
            sum_musc = ((r1 - p1) + (r2 - p2))[0].real
            far_side = float((r1 + r2)[0].real @ sum_musc) < 0.0
    angle = _acos(_dot(_unit(r1)[0], _unit(r2)[0]))
    if far_side:
        angle = -(2 * np.pi - angle)
    return code, r1, r2, radius * angle, angle


# ------------------------------------------------------------------------------ the path
def _wrap_line(w, p1, p2, single, method="hybrid", hold=False):
    """(code, r1 (D, 3), r2 (D, 3), arc (D,), surface) in the wrap object's frame, surface
    what :func:`surface_points` draws the arc from; ``hold``: a cylinder's or sphere's tangent
    points and arc from row 0 alone, real (fixed in the body)."""
    if w.kind in ("WrapCylinder", "WrapSphere"):
        if hold:
            p1, p2 = p1[:1].real, p2[:1].real
        if w.kind == "WrapCylinder":
            return cylinder(p1, p2, w.radius, w.length, quadrant(w.quadrant), single)
        return sphere(p1, p2, w.radius, quadrant(w.quadrant))
    if w.kind == "WrapEllipsoid":
        return ellipsoid_line(p1, p2, w.dimensions, quadrant(w.quadrant), method)
    raise MuscleError(
        f"wrap object {w.name!r} is a {w.kind}: only WrapCylinder, WrapSphere and "
        "WrapEllipsoid are evaluated; pass wrap=False or make it inactive"
    )


def wrapped_length(xs, dxs, idx, objs, muscle, codes=None):
    """Length (N,) and ∂l/∂q (N, nq) of one muscle's path over its wrap objects.

    ``xs`` (N, K, 3) and ``dxs`` (N, K, 3, nq): the active path points (original indices
    ``idx`` in the PathPointSet) in ground; ``objs``: (PathWrap, WrapObject, T (N,4,4) of the
    wrap's body, J (N,6,nq) of that body) for every PathWrap (inactive objects are skipped as
    OpenSim skips them, but count in the number of wraps).  The derivative: the module
    docstring.  ``codes`` (N, number of wraps), when given, receives each wrap's outcome
    (:func:`anthroarm.muscles.wrap.status` of the codes)."""
    n, nq = xs.shape[0], dxs.shape[-1]
    L, D = np.zeros(n), np.zeros((n, nq))
    npts = len(muscle.points)
    hold = _hold(objs)
    for s in range(n):
        out = None if codes is None else codes[s]
        # the coordinates this state's path depends on: one complex-step row each
        used = np.any(dxs[s] != 0.0, axis=(0, 1))
        for *_, J in objs:
            used |= np.any(J[s] != 0.0, axis=0)
        cols = np.flatnonzero(used)
        X = np.concatenate(
            [xs[s][None], xs[s][None] + 1j * H * dxs[s][..., cols].transpose(2, 0, 1)]
        )
        frames = [_frame(T[s], J[s], cols, w) for _, w, T, J in objs]
        total = _one_state(X, frames, idx, objs, npts, muscle.name, hold, out)
        L[s], D[s, cols] = total[0].real, total[1:].imag / H
    return L, D


def _hold(objs) -> bool:
    """Whether a path's cylinder and sphere tangent points are held real (no active ellipsoid
    among its wraps: the module docstring's "which derivative")."""
    return not any(w.active and w.kind == "WrapEllipsoid" for _, w, *_ in objs)


def current_path(xs, idx, objs, muscle, tolerance: float = ARC_TOLERANCE) -> list:
    """One state's path over its wrap objects, as drawn: ``xs`` (K, 3) the active path points
    in ground (original indices ``idx``), ``objs`` (PathWrap, WrapObject, T (4, 4) of the
    wrap's body) for every PathWrap.  Returns the path's entries in order, each
    ``("point", k, x (3,))`` (path point k of the PathPointSet), ``("tangent", j, x (3,))`` (a
    tangent point of wrap j: OpenSim's ``PathWrapPoint``) or ``("surface", j, X (n, 3))`` (the
    points of wrap j's surface arc strictly between its tangent points, drawn to
    ``tolerance``: :func:`surface_points`), all in ground, m.

    The same evaluation as :func:`wrapped_length` (one real row): with two or more wraps the
    tangent points are where OpenSim's ``getLocationInGround`` reports them and the length
    adds them up (the ground position of a wrap point's first use in the state, see
    ``_one_state``), the arc the one of the last pass."""
    frames = [_frame(T, np.zeros((6, 0)), np.arange(0), w) for _, w, T in objs]
    wraps = [(pw, w, T, None) for pw, w, T in objs]
    trace: list = []
    x = np.asarray(xs, dtype=float)[None]
    _one_state(
        x, frames, idx, wraps, len(muscle.points), muscle.name, _hold(objs), None, trace, tolerance
    )
    return trace


def surface_points(w, r1, r2, surface, tolerance: float = ARC_TOLERANCE) -> np.ndarray:
    """The points (n + 1, 3) of wrap object ``w``'s surface path from r1 to r2 (its own frame,
    m; rows 0 of the (D, 3) tangent points and of ``surface``, what :func:`_wrap_line` returns
    beside them), r1 first and r2 last.

    * cylinder: the helix x(t) = R_z(t φ) r1 + t (r2 − r1)_z ẑ, t ∈ [0, 1], φ the turn;
    * sphere: the great circle x(t) = cos(t φ) r1 + sin(t φ) k × r1, k = (r1 × r2)/|r1 × r2|
      (Rodrigues' rotation of r1 ⟂ k);
    * ellipsoid: OpenSim's polyline itself (its chords are the wrap's length).

    A helix of radius r turned by φ in n equal steps δ = φ/n: each chord is shorter than its
    arc by at most r δ³/24 (chord² = 4 r² sin²(δ/2) + b², arc² = r² δ² + b², b the axial step,
    4 sin²(δ/2) ≥ δ² − δ⁴/12), so n = ⌈|φ| √(r |φ| / (24 tol))⌉ steps keep the polyline's
    length within ``tol`` of the arc's."""
    a, b = np.real(r1[0]), np.real(r2[0])
    if w.kind == "WrapEllipsoid":
        pts = np.real(surface[0]).copy()
    else:
        phi = float(np.real(surface[0]))
        n = max(1, math.ceil(abs(phi) * math.sqrt(w.radius * abs(phi) / (24.0 * tolerance))))
        t = np.linspace(0.0, 1.0, n + 1)
        if w.kind == "WrapCylinder":
            v = np.ascontiguousarray(np.broadcast_to(a, (n + 1, 3)), dtype=complex)
            pts = rot_z((t * phi).astype(complex), v).real
            pts[:, 2] = a[2] + t * (b[2] - a[2])
        else:
            k = np.cross(a, b)
            k = k / np.linalg.norm(k)
            c, s = np.cos(t * phi)[:, None], np.sin(t * phi)[:, None]
            pts = c * a + s * np.cross(k, a)  # k ⟂ a
    pts[0], pts[-1] = a, b
    return pts


def _frame(T, J, cols, w):
    """(R (D, 3, 3), o (D, 3)) of a wrap body in ground, rows moved by i h along ``cols``
    (R + i h [ω]× R, o + i h v), and the wrap object's placement in it (Rw, tw)."""
    R, o = T[:3, :3], T[:3, 3]
    v, om = J[:3, cols].T, J[3:, cols].T  # (m, 3)
    Rs = R[None] + 1j * H * _cross(om[:, None, :], R.T[None]).transpose(0, 2, 1)
    Rc = np.concatenate([R[None].astype(complex), Rs])
    oc = np.concatenate([o[None].astype(complex), o[None] + 1j * H * v])
    return Rc, oc, np.asarray(w.rotation, dtype=float), np.asarray(w.translation, dtype=float)


def status(wrapped: bool, inside: bool) -> int:
    """A wrap's outcome on one state: ``WRAPPED`` (1) when the path wraps over it, ``INSIDE``
    (-1) when it does not and a segment tried had an end point inside the surface (OpenSim
    then lets the path pass straight through the object), else ``NO_WRAP`` (0)."""
    return WRAPPED if wrapped else (INSIDE if inside else NO_WRAP)


def _one_state(x, frames, idx, objs, npts, name, hold, codes=None, trace=None, tolerance=None):
    """The path's length (D,) on one state, x (D, K, 3) its active points (complex-step
    rows), ``frames`` each wrap body's (R, o, Rw, tw) (:func:`_frame`); ``trace``, when given
    (a list), receives the final path, its arcs drawn to ``tolerance`` (:func:`current_path`)."""
    # a path entry: (kind, payload); "p": original point k; "w": (wrap j, 1|2)
    path = [("p", int(k)) for k in idx]
    pos = {("p", int(k)): i for i, k in enumerate(idx)}
    wpts: dict = {}  # j -> (r1 body, r2 body, arc, (r1, r2, surface) in the wrap's frame)

    def ground(e):
        if e[0] == "p":
            return x[:, pos[e]]
        j, which = e[1]
        return _to_ground(frames[j][0], frames[j][1], wpts[j][which - 1])

    # OpenSim's Point::getLocationInGround caches a point's ground position at its first use
    # in a state; a wrap point moved by a later pass keeps the old one in the path's length
    # and in calcPathLengthChange (the wrap computations themselves use the new one)
    stale: dict = {}

    def gpos(e):
        if e[0] == "p":
            return x[:, pos[e]]
        if e[1] not in stale:
            stale[e[1]] = ground(e)
        return stale[e[1]]

    def length(final=False):
        total = np.zeros(x.shape[0], dtype=x.dtype)
        for a, b in zip(path[:-1], path[1:]):
            if a[0] == "w" and b[0] == "w" and a[1][0] == b[1][0]:
                total = total + wpts[b[1][0]][2]
            else:
                seg = _norm(gpos(b) - gpos(a))
                if final and _re(seg) < 1e-12:
                    raise MuscleError(f"muscle {name!r}: two consecutive path points coincide")
                total = total + seg
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
            R, o, Rw, tw = frames[j]
            Rg = R @ Rw  # the wrap frame in ground (D, 3, 3) and its origin
            og = o + R @ tw
            best, best_change = None, np.inf
            for a in range(start, end):
                ea, eb = path[a], path[a + 1]
                if ea[0] == "w" and eb[0] == "w" and ea[1][0] == eb[1][0]:
                    continue
                p1 = np.einsum("dji,dj->di", Rg, ground(ea) - og)
                p2 = np.einsum("dji,dj->di", Rg, ground(eb) - og)
                code, r1, r2, arc, surf = _wrap_line(w, p1, p2, nw == 1, pw.method, hold)
                results[i] = code
                inside[j] = inside[j] or code == INSIDE
                if code in (WRAPPED, MANDATORY):
                    r1b, r2b = r1 @ Rw.T + tw, r2 @ Rw.T + tw
                    if code == MANDATORY:
                        best = (a, r1b, r2b, arc, (r1, r2, surf))
                        break
                    g1, g2 = _to_ground(R, o, r1b), _to_ground(R, o, r2b)
                    ca, cb = gpos(ea), gpos(eb)
                    change = _re(_norm(g1 - ca) + arc + _norm(cb - g2) - _norm(cb - ca))
                    if change < best_change:
                        best, best_change = (a, r1b, r2b, arc, (r1, r2, surf)), change
            if best is not None:
                a, r1b, r2b, arc, on_wrap = best
                wpts[j] = (r1b, r2b, arc, on_wrap)
                path[a + 1 : a + 1] = [("w", (j, 1)), ("w", (j, 2))]
        total = _re(length())
        if abs(total - last) < 0.0005:
            break
        last = total
        if kk == 0 and nw > 1 and results[0] == NO_WRAP and results[1] == INSIDE:
            order[0], order[1] = 1, 0
            path = [e for e in path if not (e[0] == "w" and e[1][0] == 0)]
            wpts.pop(0, None)
    if codes is not None:
        codes[:] = [status(j in wpts, inside[j]) for j in range(nw)]
    total = length(final=True)
    if trace is not None:
        for e in path:
            if e[0] == "p":
                trace.append(("point", e[1], np.real(x[0, pos[e]])))
                continue
            j, which = e[1]
            trace.append(("tangent", j, np.real(gpos(e)[0])))
            if which == 1:
                R, o, Rw, tw = frames[j]
                R, o = R[0].real, o[0].real
                r1, r2, surf = wpts[j][3]
                inner = surface_points(objs[j][1], r1, r2, surf, tolerance)[1:-1]
                trace.append(("surface", j, (inner @ Rw.T + tw) @ R.T + o))
    return total


def _to_ground(R, o, rb):
    """Ground position (D, 3) of the point rb ((D, 3) or (1, 3)) of a body at (R, o)."""
    return np.einsum("dij,dj->di", R, np.broadcast_to(rb, o.shape)) + o
