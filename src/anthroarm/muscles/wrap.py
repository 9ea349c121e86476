"""Muscle paths over wrap surfaces: OpenSim 4's path wrapping, reproduced step by step.

A path with ``PathWrap``\\ s is computed as OpenSim's ``GeometryPath::applyWrapObjects`` does
(opensim-core, ``OpenSim/Simulation/Model/GeometryPath.cpp``): for each wrap in turn, every
segment between consecutive points of its range is tried; a *mandatory* wrap (the straight
segment crosses the surface) is taken at once, otherwise the wrapped segment that lengthens the
path least; two tangent points are inserted in the path, fixed in the wrap object's frame, and
the length of the surface path between them is added.  With two or more wraps, up to eight
passes until the length changes by less than 0.5 mm.  That pass loop is a compiled kernel,
:func:`anthroarm.muscles.wrap_pass.passes` (its data layout: :mod:`anthroarm.muscles.wrap_pass`),
called once for all the states of a muscle whose active path points are the same; this module
packs its input (the complex-step rows, the wrap frames, the wrap objects' parameters), turns
its status into a :class:`~anthroarm.errors.MuscleError` and draws the final path
(:func:`current_path`).

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
  sphere obstacle).  Compiled kernel: :func:`anthroarm.muscles.wrap_pass.wrap_sphere`.
* ``WrapEllipsoid`` (``WrapEllipsoid.cpp``): :mod:`anthroarm.muscles.wrap_ellipsoid` (compiled
  kernels too).
  Tori are not evaluated (:class:`~anthroarm.errors.MuscleError`).

Derivative: the complex step (Squire & Trapp, *Using complex variables to estimate derivatives
of real functions*, SIAM Rev 40 (1998) 110-112; Martins, Sturdza & Alonso, *The complex-step
derivative approximation*, ACM TOMS 29 (2003) 245-262) through the whole path.  Every input
is a row of D = 1 + m: row 0 the real state, row d the state moved by i·h along the d-th
coordinate the path depends on in any of the states evaluated together (path points
x + i h ∂x/∂q_d; wrap bodies' poses (R + i h [ω_d]× R, o + i h v_d) from their Jacobians),
h = 1e-30.  Every branch (which
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
from .wrap_cylinder import INSIDE, MANDATORY, NO_WRAP, WRAPPED, rot_z, wrap_cylinder  # noqa: F401
from .wrap_ellipsoid import METHODS
from .wrap_ellipsoid import wrap_line as ellipsoid_line
from .wrap_pass import (
    ACTIVE,
    AXIS,
    CENTRE,
    COINCIDE,
    CYLINDER,
    ELLIPSOID,
    FIRST,
    KIND,
    LAST,
    METHOD,
    NOT_CONVERGED,
    OTHER,
    SIGN,
    SPHERE,
    THROUGH_CENTRE,
    UNSUPPORTED,
    H,
    passes,
    status,  # noqa: F401  (re-exported: a wrap's outcome code)
    wrap_sphere,
)

QUADRANTS = {"x": (0, 1), "y": (1, 1), "z": (2, 1)}
#: the wrap kinds the passes evaluate (:mod:`anthroarm.muscles.wrap_pass` numbers them)
KINDS = {"WrapCylinder": CYLINDER, "WrapSphere": SPHERE, "WrapEllipsoid": ELLIPSOID}
#: the largest amount (m) by which a drawn cylinder or sphere arc (a polyline of chords) may be
#: shorter than the arc itself (:func:`surface_points`)
ARC_TOLERANCE = 1e-7
CENTRE_MESSAGE = "the path passes through the sphere's centre: the wrap plane is undefined"


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


# ------------------------------------------------------------------------ one surface
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


def sphere(p1, p2, radius, quad):
    """``WrapSphere::wrapLine`` of end points p1, p2 (D, 3) (the sphere's frame; row 0
    decides every branch): (code, r1 (D, 3), r2 (D, 3), arc length (D,), turn (D,)), the
    turn the signed angle about (r1 × r2)/|r1 × r2| from r1 to r2 along the great circle
    (OpenSim's −(2π − θ) on a far-side wrap, whose arc length it then takes negative, as
    OpenSim does); None, None, 0 and None for a path that does not wrap; the compiled kernel
    :func:`anthroarm.muscles.wrap_pass.wrap_sphere` on complex rows."""
    p1 = np.ascontiguousarray(p1, dtype=complex)
    p2 = np.ascontiguousarray(p2, dtype=complex)
    axis, wsign = quad
    code, r1, r2, arc, turn = wrap_sphere(p1, p2, float(radius), int(axis), int(wsign))
    if code == THROUGH_CENTRE:
        raise MuscleError(CENTRE_MESSAGE)
    if code in (WRAPPED, MANDATORY):
        return code, r1, r2, arc, turn
    return code, None, None, 0.0, None


def _surface(pw, w, p1, p2, single):
    """(r1, r2, surface) of the wrap of segment p1 p2 (3,) (the wrap object's frame, real):
    what :func:`surface_points` draws, from the wrap's line function called once."""
    p1, p2, quad = p1[None], p2[None], quadrant(w.quadrant)
    if w.kind == "WrapCylinder":
        _, r1, r2, _, surf = cylinder(p1, p2, w.radius, w.length, quad, single)
    elif w.kind == "WrapSphere":
        _, r1, r2, _, surf = sphere(p1, p2, w.radius, quad)
    else:
        _, r1, r2, _, surf = ellipsoid_line(p1, p2, w.dimensions, quad, pw.method)
    return r1, r2, surf


# ------------------------------------------------------------------------------ the path
def wrapped_length(xs, dxs, idx, objs, muscle, codes=None):
    """Length (N,) and ∂l/∂q (N, nq) of one muscle's path over its wrap objects.

    ``xs`` (N, K, 3) and ``dxs`` (N, K, 3, nq): the active path points (original indices
    ``idx`` in the PathPointSet) in ground; ``objs``: (PathWrap, WrapObject, T (N,4,4) of the
    wrap's body, J (N,6,nq) of that body) for every PathWrap (inactive objects are skipped as
    OpenSim skips them, but count in the number of wraps).  The derivative: the module
    docstring (one complex-step row for each coordinate any of the N states' paths depends
    on).  ``codes`` (N, number of wraps), when given, receives each wrap's outcome
    (:func:`anthroarm.muscles.wrap_pass.status` of the codes).  One call of the kernel
    :func:`anthroarm.muscles.wrap_pass.passes` for all N states."""
    n, nq = xs.shape[0], dxs.shape[-1]
    # the coordinates the paths depend on: one complex-step row each
    used = np.any(dxs != 0.0, axis=(0, 1, 2))
    for *_, J in objs:
        used |= np.any(J != 0.0, axis=(0, 1))
    cols = np.flatnonzero(used)
    step = 1j * H * dxs[..., cols].transpose(0, 3, 1, 2)
    X = np.concatenate([xs[:, None].astype(complex), xs[:, None] + step], axis=1)
    frames = [_frames(T, J, cols, w) for _, w, T, J in objs]
    lengths, grads, out = _run(X, frames, idx, objs, muscle)
    if codes is not None:
        codes[:] = out[0]
    D = np.zeros((n, nq))
    D[:, cols] = grads
    return lengths, D


def _hold(objs) -> bool:
    """Whether a path's cylinder and sphere tangent points are held real (no active ellipsoid
    among its wraps: the module docstring's "which derivative")."""
    return not any(w.active and w.kind == "WrapEllipsoid" for _, w, *_ in objs)


def _pack(objs, npts):
    """The wrap objects' parameters as :func:`anthroarm.muscles.wrap_pass.passes` reads them:
    (wint (W, 7), wflt (W, 3))."""
    wint = np.zeros((len(objs), 7), dtype=np.int64)
    wflt = np.zeros((len(objs), 3))
    for j, (pw, w, *_) in enumerate(objs):
        kind = KINDS.get(w.kind, OTHER)
        wint[j, KIND], wint[j, ACTIVE] = kind, bool(w.active)
        if w.active and kind != OTHER:
            wint[j, AXIS], wint[j, SIGN] = quadrant(w.quadrant)
        # PathWrap::extendFinalizeFromProperties: an unknown method is hybrid
        wint[j, METHOD] = METHODS.get(pw.method.lower(), 0)
        wint[j, FIRST] = pw.range[0] - 1 if pw.range[0] >= 1 else 0
        wint[j, LAST] = pw.range[1] - 1 if pw.range[1] >= 1 else npts - 1
        if kind == ELLIPSOID:
            wflt[j] = w.dimensions
        elif kind != OTHER:
            wflt[j, :2] = w.radius, w.length
    return wint, wflt


def _run(X, frames, idx, objs, muscle):
    """:func:`anthroarm.muscles.wrap_pass.passes` on the complex-step rows X (N, D, K, 3) and
    the wrap frames ((Rg (N, D, 3, 3), og (N, D, 3)) each): (lengths (N,), derivatives
    (N, D − 1), (codes (N, W), paths, path lengths, tangent points, segment ends))."""
    n, _, k, _ = X.shape
    w = len(objs)
    rg = np.ascontiguousarray(np.stack([f[0] for f in frames], axis=1))
    og = np.ascontiguousarray(np.stack([f[1] for f in frames], axis=1))
    wint, wflt = _pack(objs, len(muscle.points))
    lengths, grads = np.zeros(n), np.zeros((n, X.shape[1] - 1))
    out = (
        np.zeros((n, w), dtype=np.int64),
        np.zeros((n, k + 2 * w), dtype=np.int64),
        np.zeros(n, dtype=np.int64),
        np.zeros((n, w, 2, 3)),
        np.zeros((n, w, 2, 3)),
    )
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    st, j, _ = passes(
        np.ascontiguousarray(X), rg, og, wint, wflt, idx, _hold(objs), lengths, grads, *out
    )
    if st == COINCIDE:
        raise MuscleError(f"muscle {muscle.name!r}: two consecutive path points coincide")
    if st == UNSUPPORTED:
        w = objs[j][1]
        raise MuscleError(
            f"wrap object {w.name!r} is a {w.kind}: only WrapCylinder, WrapSphere and "
            "WrapEllipsoid are evaluated; pass wrap=False or make it inactive"
        )
    if st == CENTRE:
        raise MuscleError(CENTRE_MESSAGE)
    if st == NOT_CONVERGED:
        raise MuscleError("ellipsoid wrap: the tangent points did not converge")
    return lengths, grads, out


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
    :mod:`anthroarm.muscles.wrap_pass`), the arc the one of the last pass, drawn by calling
    the wrap's line function once more on the segment it wraps."""
    xs = np.asarray(xs, dtype=float)
    frames = [_frames(T[None], np.zeros((1, 6, 0)), np.arange(0), w) for _, w, T in objs]
    _, _, (_, paths, npath, tang, ends) = _run(
        xs[None, None].astype(complex), frames, idx, objs, muscle
    )
    trace: list = []
    for e in paths[0, : npath[0]]:
        if e >= 0:
            trace.append(("point", int(idx[e]), xs[e]))
            continue
        j, which = divmod(-int(e) - 1, 2)
        trace.append(("tangent", j, tang[0, j, which]))
        if which == 0:
            pw, w, T = objs[j]
            r1, r2, surf = _surface(pw, w, ends[0, j, 0], ends[0, j, 1], len(objs) == 1)
            inner = surface_points(w, r1, r2, surf, tolerance)[1:-1]
            R, o = T[:3, :3], T[:3, 3]
            trace.append(("surface", j, (inner @ w.rotation.T + w.translation) @ R.T + o))
    return trace


def surface_points(w, r1, r2, surface, tolerance: float = ARC_TOLERANCE) -> np.ndarray:
    """The points (n + 1, 3) of wrap object ``w``'s surface path from r1 to r2 (its own frame,
    m; rows 0 of the (D, 3) tangent points and of ``surface``, what :func:`cylinder`,
    :func:`sphere` or :func:`anthroarm.muscles.wrap_ellipsoid.wrap_line` returns beside them),
    r1 first and r2 last.

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


def _frames(T, J, cols, w):
    """(Rg (N, D, 3, 3), og (N, D, 3)): the wrap object's frame in ground on N states (its
    axes as columns, its origin), from its body's poses T (N, 4, 4) and Jacobians J (N, 6, nq),
    rows moved by i h along ``cols`` (the body at R + i h [ω]× R, o + i h v; the wrap object
    placed in it by its rotation and translation)."""
    R, o = T[:, :3, :3], T[:, :3, 3]
    v = J[:, :3][:, :, cols].transpose(0, 2, 1)  # (N, m, 3)
    om = J[:, 3:][:, :, cols].transpose(0, 2, 1)
    dR = np.cross(om[:, :, None, :], np.swapaxes(R, 1, 2)[:, None]).swapaxes(2, 3)
    Rc = np.concatenate([R[:, None].astype(complex), R[:, None] + 1j * H * dR], axis=1)
    oc = np.concatenate([o[:, None].astype(complex), o[:, None] + 1j * H * v], axis=1)
    Rw, tw = np.asarray(w.rotation, dtype=float), np.asarray(w.translation, dtype=float)
    return Rc @ Rw, oc + Rc @ tw
