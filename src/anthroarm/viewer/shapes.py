"""The pieces the viewer draws with: :class:`Piece` (one meshcat object in a body frame) and
:class:`Body` (pieces moving with one joint or frame), the primitive shapes built from them
(cylinders, capsules, coordinate triads), shaded arrow and tube meshes, and the bounding boxes
of meshcat geometry.  Lengths in metres; meshcat's cylinders run along their y axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import meshcat.geometry as mg
import numpy as np

from ..spatial.rotations import homogeneous, rotation_between
from .colors import LINK_RGB
from .meshes import PackedMesh


@dataclass
class Piece:
    """One meshcat object at ``offset`` (4×4) in its body frame; ``group`` names the sub-node
    ("links", "joint", "axis", "mesh") so that colouring can target the links only."""

    geometry: object
    rgb: tuple = LINK_RGB
    offset: np.ndarray = field(default_factory=lambda: np.eye(4))
    group: str = "links"
    opacity: float = 1.0


@dataclass
class Body:
    """Pieces moving with one placement: ``joint`` (index in ``robot.chain.joints``, pose
    ``data.oMi[joint + 1]``) or ``frame`` (index in ``robot.chain.frames`` = Pinocchio frame
    id, pose ``data.oMf[frame]``); both None means fixed to the base.

    ``limit_joint`` is the chain joint whose limit proximity colours the joint centre (None:
    unbounded, never coloured); ``link_joints`` are the chain joints whose proximity colours
    the links: its own joint and the joints that sit at the same point just before it (the
    shoulder's x-y-z, the elbow and forearm rotation), so a link turns red when any joint that
    moves it is at a limit."""

    name: str
    pieces: list[Piece]
    joint: int | None = None
    frame: int | None = None
    limit_joint: int | None = None
    link_joints: list = field(default_factory=list)


def y_to(direction) -> np.ndarray:
    """Rotation taking +y (meshcat's cylinder axis) onto ``direction``."""
    return rotation_between((0.0, 1.0, 0.0), direction)


def cylinder_between(a, b, radius, rgb, group="links", opacity=1.0) -> list[Piece]:
    """A cylinder of ``radius`` from ``a`` to ``b`` (none when they coincide)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    L = float(np.linalg.norm(b - a))
    if L < 1e-9:
        return []
    return [
        Piece(mg.Cylinder(L, radius), rgb, homogeneous(y_to(b - a), (a + b) / 2), group, opacity)
    ]


def capsule(a, b, radius, rgb=LINK_RGB, group="links") -> list[Piece]:
    """A capsule from ``a`` to ``b``: a cylinder and two hemispherical caps (spheres)."""
    out = cylinder_between(a, b, radius, rgb, group)
    if not out:
        return []
    return out + [
        Piece(mg.Sphere(radius), rgb, homogeneous(r=a), group),
        Piece(mg.Sphere(radius), rgb, homogeneous(r=b), group),
    ]


def triad(size: float, radius: float | None = None, opacity: float = 1.0) -> list[Piece]:
    """Coordinate axes ``size`` long from the origin: x red, y green, z blue (group "triad")."""
    r = radius if radius is not None else 0.06 * size
    cols = [(0.9, 0.1, 0.1), (0.1, 0.75, 0.1), (0.1, 0.25, 0.95)]
    out = []
    for i, c in enumerate(cols):
        e = np.zeros(3)
        e[i] = size
        out += cylinder_between(np.zeros(3), e, r, c, "triad", opacity)
    return out


class ShadedMesh(mg.TriangularMeshGeometry):
    """A triangle mesh with per-vertex normals (meshcat's own sends none, so Phong shading
    would leave it flat black) and per-vertex colours."""

    def __init__(self, vertices, faces, normals, color):
        super().__init__(vertices, faces, color)
        self.normals = np.asarray(normals, dtype=np.float32)

    def lower(self, object_data):
        d = super().lower(object_data)
        d["data"]["attributes"]["normal"] = mg.pack_numpy_array(self.normals.T)
        return d


def arrow_mesh(origins, vectors, radius, colors, head_length=None, segments: int = 10):
    """One shaded triangle mesh of arrows: a shaft (cylinder) of ``radius`` and a cone head from
    each origin along its vector (both (N, 3), m).  ``colors`` (N, 3) in [0, 1].  The head is
    ``head_length`` long (default 3.5 radii, at most half the arrow) and 2.2 radii wide.
    Zero-length vectors draw nothing."""
    O, V = np.asarray(origins, float), np.asarray(vectors, float)
    verts, norms, cols, faces = [], [], [], []
    ang = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], 1)
    count = 0
    for o, v, c in zip(O, V, np.asarray(colors, float)):
        L = float(np.linalg.norm(v))
        if L < 1e-12:
            continue
        d = v / L
        R = rotation_between((0.0, 0.0, 1.0), d)
        ex, ey = R[:, 0], R[:, 1]
        hl = min(head_length if head_length is not None else 3.5 * radius, 0.5 * L)
        rim = ring[:, :1] * ex + ring[:, 1:] * ey  # (s, 3) unit radial directions
        a, b = o, o + (L - hl) * d  # shaft
        tip = o + v
        # shaft: 2s vertices with radial normals
        vs = np.concatenate([a + radius * rim, b + radius * rim])
        ns = np.concatenate([rim, rim])
        # cone: rim at b (2.2 r) and the tip, normals tilted by the cone's half-angle
        rc = 2.2 * radius
        slope = rc / hl
        nc = (rim + slope * d) / math.sqrt(1 + slope * slope)
        vc = np.concatenate([b + rc * rim, np.repeat(tip[None], segments, 0)])
        ncs = np.concatenate([nc, nc])
        # the cone's base disc (facing back)
        vb = np.concatenate([b + rc * rim, b[None]])
        nb = np.tile(-d, (segments + 1, 1))
        base = count
        k = np.arange(segments)
        k1 = (k + 1) % segments
        f_shaft = np.concatenate(
            [np.stack([k, k1, segments + k1], 1), np.stack([k, segments + k1, segments + k], 1)]
        )
        f_cone = np.stack([k, k1, segments + k], 1) + 2 * segments
        f_base = np.stack([np.full(segments, segments), k1, k], 1) + 4 * segments
        faces.append(np.concatenate([f_shaft, f_cone, f_base]) + base)
        vv = np.concatenate([vs, vc, vb])
        verts.append(vv)
        norms.append(np.concatenate([ns, ncs, nb]))
        cols.append(np.tile(c, (len(vv), 1)))
        count += len(vv)
    if not verts:
        return None
    return ShadedMesh(
        np.concatenate(verts), np.concatenate(faces), np.concatenate(norms), np.concatenate(cols)
    )


def tube_mesh(points, radius: float, rgb, segments: int = 8) -> ShadedMesh | None:
    """One shaded triangle mesh of a tube of ``radius`` along the polyline ``points`` (K, 3),
    m: a ring of ``segments`` vertices round each point, in the plane normal to the mean of its
    two segments' directions, the rings' first axis carried along the path by projection (no
    twist), consecutive rings joined by quads (open ends).  Consecutive points closer than
    1e-9 m are merged.  ``rgb`` one colour (3,).  Vertex k·segments + i belongs to point k.
    None for fewer than two distinct points."""
    P = np.asarray(points, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > 1e-9])
    P = P[keep]
    if len(P) < 2:
        return None
    d = np.diff(P, axis=0)
    d /= np.linalg.norm(d, axis=1)[:, None]
    t = np.concatenate([d[:1], d[:-1] + d[1:], d[-1:]])
    bad = np.linalg.norm(t, axis=1) < 1e-9  # a path turning back on itself
    t[bad] = np.concatenate([d, d[-1:]])[bad]
    t /= np.linalg.norm(t, axis=1)[:, None]
    ang = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    e1 = rotation_between((0.0, 0.0, 1.0), t[0])[:, 0]
    verts, norms = [], []
    for p, tk in zip(P, t):
        e1 = e1 - (e1 @ tk) * tk
        n1 = np.linalg.norm(e1)
        e1 = e1 / n1 if n1 > 1e-9 else rotation_between((0.0, 0.0, 1.0), tk)[:, 0]
        rim = np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * np.cross(tk, e1)
        verts.append(p + radius * rim)
        norms.append(rim)
    k = np.arange(segments)
    k1 = (k + 1) % segments
    quad = np.concatenate(
        [np.stack([k, k1, segments + k1], 1), np.stack([k, segments + k1, segments + k], 1)]
    )
    faces = np.concatenate([quad + i * segments for i in range(len(P) - 1)])
    V = np.concatenate(verts)
    return ShadedMesh(
        V, faces, np.concatenate(norms), np.tile(np.asarray(rgb, float)[:3], (len(V), 1))
    )


def box_corners(lo, hi) -> np.ndarray:
    """The 8 corners (8, 3) of the axis-aligned box from ``lo`` to ``hi``."""
    return np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])], float
    )


def local_corners(g) -> np.ndarray | None:
    """The 8 corners of a meshcat geometry's bounding box in its own frame (cylinders along y),
    or None for geometry without known bounds (a mesh file sent as it is)."""
    kind = type(g).__name__
    if isinstance(g, PackedMesh):
        return box_corners(g.grid.min(0), g.grid.max(0)) if len(g.faces) else None
    if kind == "Sphere":
        e = np.full(3, float(g.radius))
    elif kind == "Ellipsoid":
        e = np.asarray(g.radii, float)
    elif kind == "Cylinder":
        rr = max(float(g.radiusTop), float(g.radiusBottom))
        e = np.array([rr, g.height / 2, rr])
    elif kind == "Box":
        e = np.asarray(g.lengths, float) / 2
    else:
        return None
    return box_corners(-e, e)
