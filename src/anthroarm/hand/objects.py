"""Grasped objects: a sphere and a cylinder, as signed-distance surfaces (world frame, m).

Each primitive gives, for a point p (3,) in world coordinates,

* ``distance(p)``: signed distance to the surface φ(p), m (negative inside);
* ``normal(p)``: outward unit normal m(p) = ∇φ(p) at the nearest surface point;
* ``normal_jacobian(p)``: N(p) = ∂m/∂p (3, 3), 1/m;
* ``project(p)``: the nearest surface point p − φ(p) m(p);

and ``point(...)`` places a contact from surface coordinates.  A cylinder is its side surface
(the caps are not contact surfaces); ``length`` (m, optional) bounds the side, and
:meth:`Cylinder.on_side` tells whether a point's axial coordinate lies on it.

Sphere, centre c, radius r, ρ = ‖p − c‖::

    φ = ρ − r,   m = (p − c)/ρ,   N = (I − m mᵀ)/ρ

Cylinder, axis through c along the unit u, w = (I − u uᵀ)(p − c), ρ = ‖w‖::

    φ = ρ − r,   m = w/ρ,   N = (I − u uᵀ − m mᵀ)/ρ

On the centre (sphere) or the axis (cylinder) the normal is not defined: a fixed perpendicular
is returned with N = 0 (a contact never lies there: ρ = r > 0 on the surface).
"""

from __future__ import annotations

import numpy as np

from .. import collision
from ..errors import GraspError
from ..ik.qp.tasks.contact_normal import unit_vector


def _point(p, what: str) -> np.ndarray:
    a = np.asarray(p, dtype=float)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise GraspError(f"{what} must be a finite 3-vector (m, world frame), got {p!r}")
    return a


def _radius(r) -> float:
    try:
        r = float(r)
    except (TypeError, ValueError):
        raise GraspError(f"radius must be a number of metres, got {r!r}") from None
    if not (np.isfinite(r) and r > 0):
        raise GraspError(f"radius must be finite and > 0 (m), got {r}")
    return r


def _perpendicular(u) -> np.ndarray:
    e = np.eye(3)[int(np.argmin(np.abs(u)))]
    v = e - (e @ u) * u
    return v / np.linalg.norm(v)


class Sphere:
    """Sphere of ``radius`` (m) centred at ``center`` (3,), world frame."""

    kind = "sphere"

    def __init__(self, center, radius):
        self.center = _point(center, "Sphere center")
        self.radius = _radius(radius)

    def __repr__(self) -> str:
        return f"Sphere(center={np.round(self.center, 4).tolist()}, radius={self.radius:g})"

    @property
    def size(self) -> float:
        """The diameter (m): what the hand must span."""
        return 2.0 * self.radius

    def _rho(self, p):
        d = np.asarray(p, dtype=float) - self.center
        return d, float(np.linalg.norm(d))

    def distance(self, p) -> float:
        return self._rho(p)[1] - self.radius

    def normal(self, p) -> np.ndarray:
        d, rho = self._rho(p)
        return d / rho if rho > 1e-12 else np.array([0.0, 0.0, 1.0])

    def normal_jacobian(self, p) -> np.ndarray:
        d, rho = self._rho(p)
        if rho <= 1e-12:
            return np.zeros((3, 3))
        m = d / rho
        return (np.eye(3) - np.outer(m, m)) / rho

    def project(self, p) -> np.ndarray:
        return np.asarray(p, dtype=float) - self.distance(p) * self.normal(p)

    def transformed(self, T) -> "Sphere":
        """The sphere moved by the rigid transform ``T`` (4×4)."""
        T = np.asarray(T, dtype=float)
        return Sphere(T[:3, :3] @ self.center + T[:3, 3], self.radius)

    def inflated(self, dr: float) -> "Sphere":
        """The sphere grown by ``dr`` (m): where a fingertip's axis point lies when its capsule
        of radius ``dr`` touches this sphere."""
        return Sphere(self.center, self.radius + float(dr))

    def obstacle(self, name: str = "object"):
        """This sphere as a collision body (:func:`anthroarm.collision.sphere`)."""
        return collision.sphere(self.radius, xyz=self.center, name=name)

    def point(self, direction) -> np.ndarray:
        """Surface point in ``direction`` (3,) from the centre (normalised)."""
        return self.center + self.radius * unit_vector(direction, "Sphere.point direction")


class Cylinder:
    """Cylinder side surface of ``radius`` (m), axis through ``center`` along ``axis``
    (normalised), world frame; ``length`` (m) is the side's extent centred on ``center``
    (``None``: unbounded)."""

    kind = "cylinder"

    def __init__(self, center, axis, radius, length=None):
        self.center = _point(center, "Cylinder center")
        try:
            self.axis = unit_vector(axis, "Cylinder axis")
        except ValueError as e:
            raise GraspError(str(e)) from None
        self.radius = _radius(radius)
        if length is not None:
            length = float(length)
            if not (np.isfinite(length) and length > 0):
                raise GraspError(
                    f"Cylinder length must be finite and > 0 (m) or None, got {length}"
                )
        self.length = length
        self._P = np.eye(3) - np.outer(self.axis, self.axis)
        self._perp = _perpendicular(self.axis)

    def __repr__(self) -> str:
        return (
            f"Cylinder(center={np.round(self.center, 4).tolist()}, "
            f"axis={np.round(self.axis, 4).tolist()}, radius={self.radius:g}, length={self.length})"
        )

    @property
    def size(self) -> float:
        """The diameter (m): what the hand must span."""
        return 2.0 * self.radius

    def _w(self, p):
        w = self._P @ (np.asarray(p, dtype=float) - self.center)
        return w, float(np.linalg.norm(w))

    def height(self, p) -> float:
        """Axial coordinate (m) of ``p`` from the centre."""
        return float((np.asarray(p, dtype=float) - self.center) @ self.axis)

    def on_side(self, p, tol: float = 0.0) -> bool:
        """True when ``p``'s axial coordinate lies on the side (always, without a length)."""
        return self.length is None or abs(self.height(p)) <= 0.5 * self.length + tol

    def distance(self, p) -> float:
        return self._w(p)[1] - self.radius

    def normal(self, p) -> np.ndarray:
        w, rho = self._w(p)
        return w / rho if rho > 1e-12 else self._perp.copy()

    def normal_jacobian(self, p) -> np.ndarray:
        w, rho = self._w(p)
        if rho <= 1e-12:
            return np.zeros((3, 3))
        m = w / rho
        return (self._P - np.outer(m, m)) / rho

    def project(self, p) -> np.ndarray:
        return np.asarray(p, dtype=float) - self.distance(p) * self.normal(p)

    def transformed(self, T) -> "Cylinder":
        """The cylinder moved by the rigid transform ``T`` (4×4)."""
        T = np.asarray(T, dtype=float)
        return Cylinder(
            T[:3, :3] @ self.center + T[:3, 3], T[:3, :3] @ self.axis, self.radius, self.length
        )

    def inflated(self, dr: float) -> "Cylinder":
        """The cylinder grown by ``dr`` (m) in radius (its length kept)."""
        return Cylinder(self.center, self.axis, self.radius + float(dr), self.length)

    def obstacle(self, name: str = "object", unbounded_length: float = 2.0):
        """This cylinder as a collision body (:func:`anthroarm.collision.cylinder`; an
        unbounded one as ``unbounded_length`` m long)."""
        z = self.axis
        x = self._perp
        pose = np.eye(4)
        pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
        pose[:3, 3] = self.center
        L = self.length if self.length is not None else unbounded_length
        return collision.cylinder(self.radius, L, pose=pose, name=name)

    def point(self, angle: float, height: float = 0.0) -> np.ndarray:
        """Surface point at ``angle`` (rad, about the axis from a fixed perpendicular ``e₁``;
        ``e₂ = u × e₁``) and axial ``height`` (m) from the centre."""
        e1 = self._perp
        e2 = np.cross(self.axis, e1)
        return (
            self.center
            + height * self.axis
            + self.radius * (np.cos(angle) * e1 + np.sin(angle) * e2)
        )
