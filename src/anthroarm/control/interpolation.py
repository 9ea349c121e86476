"""Straight-line and circular-arc interpolation in Cartesian space (§9-1 一.3 (iii): random-access
playback "uses straight-line or circular-arc interpolation between two points").

The book names the two interpolations and nothing more; the forms here are the standard ones of
robot path generation (e.g. Paul, *Robot Manipulators*, MIT Press 1981, ch. 5, the book's
reference [18]; Siciliano et al., *Robotics: Modelling, Planning and Control*, Springer 2009,
§4.3): position along the segment or along the circle through three taught points, and the
orientation by spherical linear interpolation (slerp) of the rotation from the first pose to the
last, ``R(s) = R_0 exp(s log(R_0ᵀ R_1))`` (an assumption: the book does not say how the gripper
turns).  The path parameter ``s`` ∈ [0, 1] is the fraction of length (line) or of swept angle
(arc), so a uniform ``s`` is a constant speed.

Frames and units: points in m in one fixed (base) frame; poses are 4×4 homogeneous matrices
(active, new → old, as everywhere in :mod:`anthroarm.spatial`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import input_checks as _check
from ..errors import ControlError, DegenerateArcError
from ..spatial.rotations import axis_angle, check_rotation, rot_axis

__all__ = ["Arc", "arc_poses", "circle_through", "line_points", "line_poses", "slerp"]


def _s(s) -> np.ndarray:
    try:
        a = np.asarray(s, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ControlError(f"s must be a finite scalar or 1-D array in [0, 1], got {s!r}") from None
    if a.ndim > 1 or not np.all(np.isfinite(a)):
        raise ControlError(f"s must be a finite scalar or 1-D array in [0, 1], got {s!r}")
    if np.any((a < -1e-12) | (a > 1 + 1e-12)):
        raise ControlError(f"s must lie in [0, 1], got values from {a.min()} to {a.max()}")
    return np.clip(a, 0.0, 1.0)


def _point(p, name) -> np.ndarray:
    try:
        a = np.asarray(p, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ControlError(f"{name} must be a finite point of shape (3,), got {p!r}") from None
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ControlError(f"{name} must be a finite point of shape (3,), got {p!r}")
    return a


def _pose(T, name) -> np.ndarray:
    try:
        a = np.asarray(T, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ControlError(f"{name} must be a finite 4x4 pose, got {T!r}") from None
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ControlError(f"{name} must be a finite 4x4 pose, got shape {a.shape}")
    if np.max(np.abs(a[3] - (0.0, 0.0, 0.0, 1.0))) > 1e-12:
        raise ControlError(
            f"{name} is not a homogeneous pose: its last row is {a[3].tolist()}, not [0, 0, 0, 1]"
        )
    try:
        check_rotation(a[:3, :3], f"{name} rotation")
    except ValueError as exc:
        raise ControlError(str(exc)) from None
    return a


def slerp(R0, R1, s) -> np.ndarray:
    """Rotation a fraction ``s`` of the way from ``R0`` to ``R1`` about the fixed axis of
    ``R0ᵀ R1`` (Rodrigues, Eq. (5-84), through :func:`~anthroarm.spatial.rotations.axis_angle`
    and :func:`~anthroarm.spatial.rotations.rot_axis`): ``R0 rot_axis(n, s φ)``.

    Parameters
    ----------
    R0, R1 : array_like, shape (3, 3)
        Rotations (active, body → base).
    s : float or array_like, shape (N,)
        Fractions in [0, 1].

    Returns
    -------
    numpy.ndarray, shape (3, 3) or (N, 3, 3)
    """
    try:
        R0 = check_rotation(R0, "R0")
        R1 = check_rotation(R1, "R1")
    except ValueError as exc:
        raise ControlError(str(exc)) from None
    n, phi = axis_angle(R0.T @ R1)
    return R0 @ rot_axis(n, _s(s) * phi)


def _lerp(p0: np.ndarray, p1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """``p0 + s (p1 − p0)`` for ``s`` of shape (N,) or (), ``p`` of any shape; where the
    difference overflows (ends near ±1e308) the same point as ``(1 − s) p0 + s p1``."""
    s = s.reshape(s.shape + (1,) * p0.ndim)
    with np.errstate(over="ignore", invalid="ignore"):
        out = p0 + s * (p1 - p0)
        if not np.all(np.isfinite(out)):
            out = (1.0 - s) * p0 + s * p1
    return _check.finite(out, "the interpolated point", "the ends are too large")


def line_points(p0, p1, s) -> np.ndarray:
    """Points ``p0 + s (p1 − p0)`` of the straight segment (m), shape (3,) or (N, 3)."""
    p0, p1 = _point(p0, "p0"), _point(p1, "p1")
    return _lerp(p0, p1, _s(s))


def line_poses(T0, T1, s) -> np.ndarray:
    """Straight-line interpolation of a pose: position on the segment, orientation by
    :func:`slerp`; shape (4, 4) or (N, 4, 4)."""
    T0, T1 = _pose(T0, "T0"), _pose(T1, "T1")
    s = _s(s)
    out = np.broadcast_to(np.eye(4), s.shape + (4, 4)).copy()
    out[..., :3, :3] = slerp(T0[:3, :3], T1[:3, :3], s)
    out[..., :3, 3] = _lerp(T0[:3, 3], T1[:3, 3], s)
    return out


@dataclass(frozen=True)
class Arc:
    """The circular arc from ``p1`` through ``p2`` to ``p3`` (:func:`circle_through`).

    Attributes
    ----------
    center : numpy.ndarray, shape (3,)
        Centre of the circle, m.
    radius : float
        Radius, m.
    normal : numpy.ndarray, shape (3,)
        Unit normal of the circle's plane; the arc turns positively about it.
    e1, e2 : numpy.ndarray, shape (3,)
        In-plane unit vectors: ``e1`` from the centre to ``p1``, ``e2 = normal × e1``.
    sweep : float
        Angle swept from ``p1`` to ``p3`` (passing ``p2``), rad, in (0, 2π).
    via_angle : float
        Angle of ``p2`` from ``p1``, rad, in (0, sweep).
    start : numpy.ndarray, shape (3,), optional
        ``p1``; the points are computed from it (``p1 + r((cos a − 1) e1 + sin a e2)``), which
        stays accurate on a huge, nearly straight arc.  Default ``center + radius e1``.
    """

    center: np.ndarray
    radius: float
    normal: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    sweep: float
    via_angle: float
    start: np.ndarray | None = None

    @property
    def length(self) -> float:
        """Arc length ``r · sweep``, m."""
        return self.radius * self.sweep

    def points(self, s) -> np.ndarray:
        """Points at the fraction ``s`` of the swept angle, ``c + r (cos sφ e1 + sin sφ e2)``
        (m), shape (3,) or (N, 3)."""
        a = _s(s)[..., None] * self.sweep
        if self.start is None:
            return self.center + self.radius * (np.cos(a) * self.e1 + np.sin(a) * self.e2)
        h = np.sin(0.5 * a)
        with np.errstate(over="ignore", invalid="ignore"):
            out = self.start + self.radius * (-2.0 * h * h * self.e1 + np.sin(a) * self.e2)
        return _check.finite(out, "a point of the arc", "the arc is too large")

    def tangents(self, s) -> np.ndarray:
        """Unit tangents (direction of travel) at ``s``, shape (3,) or (N, 3)."""
        a = _s(s)[..., None] * self.sweep
        return -np.sin(a) * self.e1 + np.cos(a) * self.e2


def circle_through(p1, p2, p3, tol: float = 1e-9) -> Arc:
    """The arc through three taught points, in the order p1 → p2 → p3.

    The centre is ``c = p3 + ((|a|² b − |b|² a) × (a × b)) / (2 |a × b|²)`` with ``a = p1 − p3``,
    ``b = p2 − p3`` (the circumcentre of the triangle); the normal is the direction of
    ``(p2 − p1) × (p3 − p2)`` so that the arc turns positively about it.

    Parameters
    ----------
    p1, p2, p3 : array_like, shape (3,)
        Start, via and end point, m.
    tol : float
        Relative tolerance: the points are collinear when ``|a × b| ≤ tol |a| |b|``.

    Returns
    -------
    Arc

    Raises
    ------
    anthroarm.errors.DegenerateArcError
        Two points coincide or the three are collinear (no unique circle).
    """
    p1, p2, p3 = _point(p1, "p1"), _point(p2, "p2"), _point(p3, "p3")
    tol = _check.scalar(tol, "tol (relative collinearity tolerance)")
    if not 0.0 <= tol < 1.0:
        raise ControlError(f"tol (relative collinearity tolerance) must be in [0, 1), got {tol}")
    # Everything is computed in units of the largest coordinate difference (a, b, the centre u
    # relative to p3, the radius), so no square overflows or underflows whatever the scale;
    # only the final radius and centre are scaled back, and checked.
    with np.errstate(over="ignore", invalid="ignore"):
        d = np.concatenate([p1 - p3, p2 - p3, p2 - p1])
    if not np.all(np.isfinite(d)):
        raise DegenerateArcError("the arc's points are too far apart for floating point")
    scale = float(np.max(np.abs(d)))
    if scale == 0.0:
        raise DegenerateArcError(f"the arc's three points coincide: {p1.tolist()}")
    a, b = (p1 - p3) / scale, (p2 - p3) / scale
    la, lb, lab = np.linalg.norm(a), np.linalg.norm(b), np.linalg.norm(b - a)
    if min(la, lb, lab) <= tol * max(la, lb, lab) or min(la, lb, lab) == 0.0:
        raise DegenerateArcError(
            f"two of the arc's points coincide: p1={p1.tolist()}, p2={p2.tolist()}, "
            f"p3={p3.tolist()}"
        )
    axb = np.cross(a, b)
    n2 = float(axb @ axb)
    if n2 == 0.0 or np.sqrt(n2) <= tol * la * lb:
        raise DegenerateArcError(
            f"the arc's three points are collinear (no unique circle): p1={p1.tolist()}, "
            f"p2={p2.tolist()}, p3={p3.tolist()}; use a straight line"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        u = np.cross(la * la * b - lb * lb * a, axb) / (2.0 * n2)  # centre − p3, scaled
        w = a - u  # p1 − centre, scaled
        rs = float(np.linalg.norm(w))
        r = scale * rs
        c = p3 + scale * u
    if not (math.isfinite(r) and r > 0.0 and np.all(np.isfinite(c))):
        raise DegenerateArcError(
            f"the arc's radius ({scale:g} x {rs:g} m) or centre is beyond the floating-point "
            f"range: the points p1={p1.tolist()}, p2={p2.tolist()}, p3={p3.tolist()} are too "
            "nearly collinear at this scale; use a straight line"
        )
    n = np.cross(b - a, -b)  # (p2 − p1) × (p3 − p2) over scale²
    n = n / np.linalg.norm(n)
    e1 = w / rs
    e2 = np.cross(n, e1)

    def angle(q):
        dq = q - u
        return float(np.mod(np.arctan2(dq @ e2, dq @ e1), 2 * np.pi))

    sweep, via = angle(np.zeros(3)), angle(b)  # p3 and p2 in scaled units relative to p3
    if not (0.0 < via < sweep <= 2 * np.pi and math.isfinite(r * sweep)):
        raise DegenerateArcError(
            f"the arc through p1={p1.tolist()}, p2={p2.tolist()}, p3={p3.tolist()} has no "
            f"resolvable sweep (sweep {sweep}, via angle {via} rad); use a straight line"
        )
    return Arc(
        center=c, radius=r, normal=n, e1=e1, e2=e2, sweep=sweep, via_angle=via, start=p1.copy()
    )


def arc_poses(T1, p2, T3, s) -> np.ndarray:
    """Circular-arc interpolation of a pose: the position on the arc from ``T1``'s origin through
    the point ``p2`` to ``T3``'s origin (:func:`circle_through`), the orientation by
    :func:`slerp` from ``T1`` to ``T3`` with the same fraction of the swept angle.

    Parameters
    ----------
    T1, T3 : array_like, shape (4, 4)
        Start and end pose.
    p2 : array_like, shape (3,)
        The via point (m); a 4×4 pose is accepted and its origin used.
    s : float or array_like, shape (N,)
        Fractions of the swept angle in [0, 1].

    Returns
    -------
    numpy.ndarray, shape (4, 4) or (N, 4, 4)
    """
    T1, T3 = _pose(T1, "T1"), _pose(T3, "T3")
    if np.shape(p2) == (4, 4):
        p2 = _pose(p2, "p2")[:3, 3]
    arc = circle_through(T1[:3, 3], p2, T3[:3, 3])
    s = _s(s)
    out = np.broadcast_to(np.eye(4), s.shape + (4, 4)).copy()
    out[..., :3, :3] = slerp(T1[:3, :3], T3[:3, :3], s)
    out[..., :3, 3] = arc.points(s)
    return out
