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

from dataclasses import dataclass

import numpy as np

from ..errors import ControlError, DegenerateArcError
from ..spatial.rotations import axis_angle, check_rotation, rot_axis

__all__ = ["Arc", "arc_poses", "circle_through", "line_points", "line_poses", "slerp"]


def _s(s) -> np.ndarray:
    a = np.asarray(s, dtype=float)
    if a.ndim > 1 or not np.all(np.isfinite(a)):
        raise ControlError(f"s must be a finite scalar or 1-D array in [0, 1], got {s!r}")
    if np.any((a < -1e-12) | (a > 1 + 1e-12)):
        raise ControlError(f"s must lie in [0, 1], got values from {a.min()} to {a.max()}")
    return np.clip(a, 0.0, 1.0)


def _point(p, name) -> np.ndarray:
    a = np.asarray(p, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ControlError(f"{name} must be a finite point of shape (3,), got {p!r}")
    return a


def _pose(T, name) -> np.ndarray:
    a = np.asarray(T, dtype=float)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ControlError(f"{name} must be a finite 4x4 pose, got shape {a.shape}")
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


def line_points(p0, p1, s) -> np.ndarray:
    """Points ``p0 + s (p1 − p0)`` of the straight segment (m), shape (3,) or (N, 3)."""
    p0, p1 = _point(p0, "p0"), _point(p1, "p1")
    s = _s(s)
    return p0 + s[..., None] * (p1 - p0)


def line_poses(T0, T1, s) -> np.ndarray:
    """Straight-line interpolation of a pose: position on the segment, orientation by
    :func:`slerp`; shape (4, 4) or (N, 4, 4)."""
    T0, T1 = _pose(T0, "T0"), _pose(T1, "T1")
    s = _s(s)
    out = np.broadcast_to(np.eye(4), s.shape + (4, 4)).copy()
    out[..., :3, :3] = slerp(T0[:3, :3], T1[:3, :3], s)
    out[..., :3, 3] = line_points(T0[:3, 3], T1[:3, 3], s)
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
    """

    center: np.ndarray
    radius: float
    normal: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    sweep: float
    via_angle: float

    @property
    def length(self) -> float:
        """Arc length ``r · sweep``, m."""
        return self.radius * self.sweep

    def points(self, s) -> np.ndarray:
        """Points at the fraction ``s`` of the swept angle, ``c + r (cos sφ e1 + sin sφ e2)``
        (m), shape (3,) or (N, 3)."""
        a = _s(s)[..., None] * self.sweep
        return self.center + self.radius * (np.cos(a) * self.e1 + np.sin(a) * self.e2)

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
    # work in units of the largest coordinate difference, so no square overflows or underflows
    d = np.concatenate([p1 - p3, p2 - p3, p2 - p1])
    if not np.all(np.isfinite(d)):
        raise DegenerateArcError("the arc's points are too far apart for floating point")
    scale = float(np.max(np.abs(d)))
    if scale == 0.0:
        raise DegenerateArcError(f"the arc's three points coincide: {p1.tolist()}")
    a, b = (p1 - p3) / scale, (p2 - p3) / scale
    la, lb, lab = np.linalg.norm(a), np.linalg.norm(b), np.linalg.norm(b - a)
    if min(la, lb, lab) <= tol * max(la, lb, lab):
        raise DegenerateArcError(
            f"two of the arc's points coincide: p1={p1.tolist()}, p2={p2.tolist()}, "
            f"p3={p3.tolist()}"
        )
    axb = np.cross(a, b)
    n2 = float(axb @ axb)
    if np.sqrt(n2) <= tol * la * lb:
        raise DegenerateArcError(
            f"the arc's three points are collinear (no unique circle): p1={p1.tolist()}, "
            f"p2={p2.tolist()}, p3={p3.tolist()}; use a straight line"
        )
    c = p3 + scale * (np.cross(la * la * b - lb * lb * a, axb) / (2.0 * n2))
    r = float(np.linalg.norm(p1 - c))
    n = np.cross(b - a, -b)  # (p2 − p1) × (p3 − p2) over scale²
    n = n / np.linalg.norm(n)
    e1 = (p1 - c) / r
    e2 = np.cross(n, e1)

    def angle(p):
        d = p - c
        return float(np.mod(np.arctan2(d @ e2, d @ e1), 2 * np.pi))

    return Arc(center=c, radius=r, normal=n, e1=e1, e2=e2, sweep=angle(p3), via_angle=angle(p2))


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
    p2 = np.asarray(p2, dtype=float)
    if p2.shape == (4, 4):
        p2 = p2[:3, 3]
    arc = circle_through(T1[:3, 3], p2, T3[:3, 3])
    s = _s(s)
    out = np.broadcast_to(np.eye(4), s.shape + (4, 4)).copy()
    out[..., :3, :3] = slerp(T1[:3, :3], T3[:3, :3], s)
    out[..., :3, 3] = arc.points(s)
    return out
