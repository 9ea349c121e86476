"""Obstacles placed in the world: sphere, box, capsule, cylinder, mesh (coal geometries).

Every shape is validated where it is made: a radius, length or edge that is not a positive
finite number, or a pose that is not a finite rigid transform, raises
:class:`~anthroarm.errors.CollisionError` (coal itself accepts a zero-radius sphere and returns
distances to a point, and a NaN pose silently).  Units: m.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..errors import CollisionError


def positive(name: str, value) -> float:
    """``value`` as a float that is finite and > 0; :class:`CollisionError` otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise CollisionError(f"{name} must be a number (m), got {value!r}") from None
    if not (np.isfinite(v) and v > 0.0):
        raise CollisionError(f"{name} must be a finite number > 0 (m), got {value!r}")
    return v


def as_pose(pose, xyz=None) -> pin.SE3:
    """A ``pin.SE3`` from a 4×4 homogeneous matrix, a ``pin.SE3``, or ``None`` with a position
    ``xyz`` (identity rotation).  Non-finite entries or a rotation that is not orthonormal
    (|RᵀR − I| > 1e-6, det R ≠ 1) raise :class:`CollisionError`."""
    if isinstance(pose, pin.SE3):
        M = pose.homogeneous
    elif pose is None:
        M = np.eye(4)
    else:
        M = np.asarray(pose, dtype=float)
        if M.shape != (4, 4):
            raise CollisionError(f"pose must be a 4x4 homogeneous matrix, got shape {M.shape}")
    M = np.array(M, dtype=float)
    if xyz is not None:
        p = np.asarray(xyz, dtype=float)
        if p.shape != (3,):
            raise CollisionError(f"xyz must be 3 numbers (m), got {xyz!r}")
        M[:3, 3] = p
    if not np.all(np.isfinite(M)):
        raise CollisionError("pose has non-finite entries")
    R = M[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-6 or abs(np.linalg.det(R) - 1.0) > 1e-6:
        raise CollisionError("pose rotation is not a rotation matrix (RᵀR ≠ I or det R ≠ 1)")
    return pin.SE3(R.copy(), M[:3, 3].copy())


@dataclass
class Obstacle:
    """One obstacle: a coal geometry at a world pose.  Make it with :func:`sphere`,
    :func:`box`, :func:`capsule`, :func:`cylinder` or :func:`mesh`.

    ``radius`` is the radius of a sphere around ``pose``'s origin that contains the shape (the
    broad phase of :mod:`anthroarm.collision.distance` uses it)."""

    name: str
    geometry: object
    pose: pin.SE3
    radius: float
    kind: str

    @property
    def center(self) -> np.ndarray:
        return np.array(self.pose.translation)


def sphere(radius, xyz=(0, 0, 0), pose=None, name: str = "sphere") -> Obstacle:
    """A sphere of ``radius`` (m) centred at ``xyz`` (or ``pose``'s origin)."""
    r = positive("sphere radius", radius)
    return Obstacle(
        name, coal.Sphere(r), as_pose(pose, None if pose is not None else xyz), r, "sphere"
    )


def box(size, xyz=(0, 0, 0), pose=None, name: str = "box") -> Obstacle:
    """A box of full edge lengths ``size`` (3 numbers, m) centred at ``xyz`` / ``pose``."""
    s = np.atleast_1d(np.asarray(size, dtype=float))
    if s.shape != (3,):
        raise CollisionError(f"box size must be 3 edge lengths (m), got {size!r}")
    x, y, z = (positive(f"box size[{i}]", v) for i, v in enumerate(s))
    return Obstacle(
        name, coal.Box(x, y, z), as_pose(pose, None if pose is not None else xyz),
        0.5 * float(np.linalg.norm(s)), "box",
    )  # fmt: skip


def capsule(radius, length, xyz=(0, 0, 0), pose=None, name: str = "capsule") -> Obstacle:
    """A capsule: the points within ``radius`` of a segment of ``length`` along the pose's z
    axis, centred at ``xyz`` / ``pose`` (m)."""
    r = positive("capsule radius", radius)
    h = positive("capsule length", length)
    return Obstacle(
        name,
        coal.Capsule(r, h),
        as_pose(pose, None if pose is not None else xyz),
        r + h / 2,
        "capsule",
    )


def cylinder(radius, length, xyz=(0, 0, 0), pose=None, name: str = "cylinder") -> Obstacle:
    """A cylinder of ``radius`` and ``length`` along the pose's z axis, centred at ``xyz`` /
    ``pose`` (m)."""
    r = positive("cylinder radius", radius)
    h = positive("cylinder length", length)
    return Obstacle(
        name, coal.Cylinder(r, h), as_pose(pose, None if pose is not None else xyz),
        float(np.hypot(r, h / 2)), "cylinder",
    )  # fmt: skip


def load_mesh(path, scale=1.0, link: str | None = None):
    """A coal ``BVHModelOBBRSS`` of the mesh file at ``path`` (STL, OBJ, DAE: whatever coal's
    assimp loader reads) scaled by ``scale`` (a number or 3 numbers).  A missing, empty or
    unreadable file raises :class:`CollisionError` naming ``link`` and the file."""
    p = Path(path)
    where = f" (collision mesh of link {link!r})" if link else ""
    if not p.is_file():
        raise CollisionError(f"{p}{where}: file not found", link=link, path=p)
    if p.stat().st_size == 0:
        raise CollisionError(f"{p}{where}: file is empty", link=link, path=p)
    sc = np.broadcast_to(np.asarray(scale, dtype=float), (3,)).copy()
    if not np.all(np.isfinite(sc)) or np.any(sc <= 0):
        raise CollisionError(
            f"{p}{where}: mesh scale must be > 0, got {scale!r}", link=link, path=p
        )
    try:
        geom = coal.MeshLoader().load(str(p), sc)
    except Exception as exc:  # assimp's errors come as RuntimeError / ValueError
        raise CollisionError(
            f"{p}{where}: not a readable mesh ({' '.join(str(exc).split())[:200]})",
            link=link,
            path=p,
        ) from None
    if geom.num_tris == 0 or geom.num_vertices == 0:
        raise CollisionError(f"{p}{where}: mesh has no triangles", link=link, path=p)
    verts = np.asarray(geom.vertices())
    if not np.all(np.isfinite(verts)):
        raise CollisionError(f"{p}{where}: mesh has non-finite vertices", link=link, path=p)
    return geom


def mesh(path, xyz=(0, 0, 0), pose=None, scale=1.0, name: str = "mesh") -> Obstacle:
    """A triangle mesh read from ``path`` (see :func:`load_mesh`), at ``xyz`` / ``pose``."""
    geom = load_mesh(path, scale)
    verts = np.asarray(geom.vertices())
    return Obstacle(
        name, geom, as_pose(pose, None if pose is not None else xyz),
        float(np.linalg.norm(verts, axis=1).max()), "mesh",
    )  # fmt: skip


__all__ = ["Obstacle", "sphere", "box", "capsule", "cylinder", "mesh", "load_mesh", "as_pose"]
