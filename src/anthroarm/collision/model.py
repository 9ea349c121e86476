"""The collision model of a robot: what its bodies occupy, as a Pinocchio ``GeometryModel``.

:func:`model` (kept on the robot with :meth:`Robot.derived <anthroarm.robot.Robot.derived>`)
builds it once from, in this order:

1. the ``collision_model`` the robot was loaded with (a ``pin.GeometryModel``);
2. the URDF's ``<collision>`` elements (meshes and primitives), read by
   ``pin.buildGeomFromUrdfString`` after every mesh file is resolved and loaded by coal — a
   missing or corrupt mesh is a :class:`~anthroarm.errors.CollisionError` naming the link and
   the file.  Meshes are replaced by their convex hulls (``convex=True``, the default): the
   hull contains the mesh, so a hull distance never exceeds the mesh distance (safe for
   avoidance) and GJK on a hull costs ~20 µs where the triangle BVH costs ~200 µs;
3. capsules along the links of the kinematic tree (from each joint to its child joints and
   tips) with the radii of the catalog arm's table (:mod:`anthroarm.models.collision_shapes`),
   plus its boxes (a palm, a torso); an arm not in the catalog gets radius 0.04 × its length
   scale.

Then the pairs are filtered (:mod:`anthroarm.collision.pairs`).  Units: m.
"""

from __future__ import annotations

import threading
import xml.etree.ElementTree as ET

import coal
import numpy as np
import pinocchio as pin

from ..errors import CollisionError, NoCollisionBodiesError, URDFError
from ..models.collision_shapes import shape_table
from ..urdf_io import resolve_uri
from .pairs import filter_pairs, set_pairs
from .shapes import load_mesh

#: shortest segment that gets a capsule (m); shorter links carry no collision body
MIN_SEGMENT = 1e-4


class CollisionModel:
    """The robot's collision bodies and the pairs that are checked.

    Attributes
    ----------
    geometry : pin.GeometryModel
        One ``GeometryObject`` per body (parent joint, placement in the joint frame, coal shape).
    links : list[str]
        The link of each body.
    pairs : (P, 2) int array
        The active self-collision pairs (indices into ``geometry.geometryObjects``).
    disabled : dict
        ``(link_a, link_b) -> reason`` of every pair that is not checked: ``"same body"``,
        ``"adjacent"``, ``"always"`` (in collision in every sampled configuration), ``"never"``
        (never closer than the margin over the samples), ``"srdf"``, ``"user"``.
    source : str
        ``"collision_model"``, ``"urdf"`` or ``"capsules"``.
    """

    def __init__(self, robot, geometry: pin.GeometryModel, links: list, source: str):
        self.robot_name = robot.name
        self.model = robot.model
        self.geometry = geometry
        self.links = list(links)
        self.source = source
        self.names = [g.name for g in geometry.geometryObjects]
        self.joint = np.array([g.parentJoint for g in geometry.geometryObjects], dtype=int)
        # bounding sphere of every body in its joint frame (broad phase)
        centers, radii = [], []
        for g in geometry.geometryObjects:
            shape = g.geometry
            shape.computeLocalAABB()
            centers.append(g.placement.act(np.asarray(shape.aabb_local.center())))
            radii.append(float(shape.aabb_radius))
        self.centers = np.array(centers).reshape(-1, 3)
        self.radii = np.array(radii)
        # capsules: axis end points in the joint frame and radii (the numpy fast path)
        self.is_capsule = np.array(
            [isinstance(g.geometry, coal.Capsule) for g in geometry.geometryObjects], dtype=bool
        )
        self.cap_ends = np.zeros((self.n, 2, 3))
        self.cap_radius = np.zeros(self.n)
        for i, g in enumerate(geometry.geometryObjects):
            if self.is_capsule[i]:
                h = float(g.geometry.halfLength)
                self.cap_ends[i, 0] = g.placement.act(np.array([0.0, 0.0, -h]))
                self.cap_ends[i, 1] = g.placement.act(np.array([0.0, 0.0, h]))
                self.cap_radius[i] = float(g.geometry.radius)
        self.pairs = np.zeros((0, 2), dtype=int)
        self.disabled: dict = {}
        self.support = support_mask(robot.model)
        self._local = threading.local()

    @property
    def n(self) -> int:
        return len(self.names)

    def geometry_data(self) -> pin.GeometryData:
        """A ``pin.GeometryData`` of the calling thread (made on first use)."""
        gd = getattr(self._local, "gd", None)
        if gd is None or getattr(self._local, "n", -1) != self.n:
            gd = self._local.gd = pin.GeometryData(self.geometry)
            self._local.n = self.n
        return gd

    def pair_names(self) -> list[tuple[str, str]]:
        """``(name_a, name_b)`` of the active pairs."""
        return [(self.names[a], self.names[b]) for a, b in self.pairs]

    def _index(self, name: str) -> list[int]:
        idx = [i for i, (g, link) in enumerate(zip(self.names, self.links)) if name in (g, link)]
        if not idx:
            raise CollisionError(
                f"{self.robot_name}: no collision body or link {name!r}; bodies: {', '.join(self.names)}"
            )
        return idx

    def disable(self, a: str, b: str, reason: str = "user") -> None:
        """Stop checking the bodies of link (or body) ``a`` against those of ``b``."""
        ia, ib = set(self._index(a)), set(self._index(b))
        keep = [
            (i, j) for i, j in self.pairs if not ((i in ia and j in ib) or (i in ib and j in ia))
        ]
        for i in ia:
            for j in ib:
                if i != j:
                    self.disabled[self.key(i, j)] = reason
        self.pairs = np.array(keep, dtype=int).reshape(-1, 2)
        set_pairs(self, self.pairs)

    def enable(self, a: str, b: str) -> None:
        """Check the bodies of ``a`` against those of ``b`` (undoes :meth:`disable` and the
        automatic filter)."""
        have = {(int(i), int(j)) for i, j in self.pairs}
        for i in self._index(a):
            for j in self._index(b):
                if i == j:
                    continue
                p = (min(i, j), max(i, j))
                have.add(p)
                self.disabled.pop(self.key(*p), None)
        self.pairs = np.array(sorted(have), dtype=int).reshape(-1, 2)
        set_pairs(self, self.pairs)

    def key(self, i: int, j: int) -> tuple[str, str]:
        return (self.names[min(i, j)], self.names[max(i, j)])

    def __repr__(self) -> str:
        return (
            f"CollisionModel({self.robot_name!r}, {self.n} bodies ({self.source}), "
            f"{len(self.pairs)} active pairs, {len(self.disabled)} disabled)"
        )


def support_mask(robot_model) -> np.ndarray:
    """(njoints, nv) mask: 1 where velocity index k moves joint j's body (k belongs to j or one
    of its ancestors)."""
    S = np.zeros((robot_model.njoints, robot_model.nv))
    for j in range(1, robot_model.njoints):
        p = robot_model.parents[j]
        S[j] = S[p]
        jm = robot_model.joints[j]
        S[j, jm.idx_v : jm.idx_v + jm.nv] = 1.0
    return S


def _body_frame(model, joint: int) -> int:
    """The frame index of the link that joint ``joint`` moves (its first BODY frame)."""
    for fid, f in enumerate(model.frames):
        if f.parentJoint == joint and f.type == pin.FrameType.BODY:
            return fid
    return 0


def _collision_meshes(info) -> list[tuple[str, str, np.ndarray]]:
    """(link, uri, scale) of every ``<collision>`` mesh of the URDF."""
    out = []
    root = ET.fromstring(info.text)
    for link in root.iter("link"):
        for col in link.findall("collision"):
            for m in col.iter("mesh"):
                uri = m.get("filename", "")
                sc = m.get("scale")
                scale = np.array([float(v) for v in sc.split()]) if sc else np.ones(3)
                out.append((link.get("name", "?"), uri, scale))
    return out


def from_urdf(robot, convex: bool = True) -> pin.GeometryModel:
    """The ``<collision>`` bodies of ``robot``'s URDF as a ``pin.GeometryModel``.

    Every mesh is resolved (``package://``, relative paths) and loaded by coal first: a missing,
    empty or unreadable file raises :class:`~anthroarm.errors.CollisionError` naming the link
    and the file.  With ``convex`` meshes are replaced by their convex hulls (qhull, through
    coal's ``buildConvexHull``)."""
    info = robot.info
    text = info.text
    hulls: dict = {}
    for link, uri, scale in _collision_meshes(info):
        try:
            path = resolve_uri(uri, info.path, info.package_dirs)
        except URDFError as exc:
            raise CollisionError(
                f"collision mesh {uri!r} of link {link!r}: {exc}", link=link, path=uri
            ) from None
        geom = load_mesh(path, scale, link)
        if convex:
            geom.buildConvexHull(True, "Qt")
            hulls[link] = geom.convex
        text = text.replace(f'"{uri}"', f'"{path}"')
    try:
        gm = pin.buildGeomFromUrdfString(robot.model, text, pin.GeometryType.COLLISION)
    except Exception as exc:  # Pinocchio's C++ errors
        raise CollisionError(
            f"{info.path}: Pinocchio cannot read the collision geometry: {exc}"
        ) from None
    if convex:
        for g in gm.geometryObjects:
            if isinstance(g.geometry, coal.BVHModelBase):
                link = robot.model.frames[g.parentFrame].name
                hull = hulls.get(link)
                if hull is None:
                    g.geometry.buildConvexHull(True, "Qt")
                    hull = g.geometry.convex
                g.geometry = hull
    return gm


def capsules(robot) -> tuple[pin.GeometryModel, list]:
    """Capsules along the links of ``robot`` (from each joint to its child joints and to the
    tips on its body) and the boxes of its catalog table, as a ``pin.GeometryModel``."""
    m = robot.model
    spec = robot.spec
    table = shape_table(robot.name, getattr(spec, "params", None))
    default_r = table.default_radius if table is not None else 0.04 * float(robot.length_scale)
    if not (np.isfinite(default_r) and default_r > 0):
        default_r = 0.02
    gm = pin.GeometryModel()
    links = []
    boxed = {b.link for b in table.boxes} if table is not None else set()
    tip_frames = {m.getFrameId(t) for t in robot.tips if m.existFrame(t)}
    for j in range(1, m.njoints):
        fid = _body_frame(m, j)
        link = m.frames[fid].name if fid else m.names[j]
        if table is not None and link in table.skip:
            continue
        ends = [
            np.array(m.jointPlacements[c].translation)
            for c in range(1, m.njoints)
            if m.parents[c] == j
        ]
        ends += [
            np.array(m.frames[f].placement.translation)
            for f in tip_frames
            if m.frames[f].parentJoint == j
        ]
        if link in boxed:
            continue
        r = table.radius.get(link, default_r) if table is not None else default_r
        k = 0
        for e in ends:
            L = float(np.linalg.norm(e))
            if L < MIN_SEGMENT:
                continue
            z = e / L
            # rotation taking the capsule's z axis to the segment
            x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
            x /= np.linalg.norm(x)
            R = np.column_stack([x, np.cross(z, x), z])
            g = pin.GeometryObject(f"{link}_{k}", j, fid, pin.SE3(R, e / 2), coal.Capsule(r, L))
            gm.addGeometryObject(g)
            links.append(link)
            k += 1
    for b in table.boxes if table is not None else ():
        if b.link == "universe":
            j, fid = 0, 0
        else:
            if not m.existFrame(b.link):
                continue
            fid = m.getFrameId(b.link)
            j = int(m.frames[fid].parentJoint)
            # box given in the link frame: the frame's placement in its joint
        place = (m.frames[fid].placement if fid else pin.SE3.Identity()) * pin.SE3(
            np.eye(3), np.array(b.xyz, dtype=float)
        )
        gm.addGeometryObject(pin.GeometryObject(b.name, j, fid, place, coal.Box(*b.size)))
        links.append(b.link)
    return gm, links


def build(
    robot, convex: bool = True, srdf=None, samples: int = 500, never_margin: float = 0.05, rng=0
):
    """A new :class:`CollisionModel` of ``robot`` with its pairs filtered (see the module
    docstring and :func:`anthroarm.collision.pairs.filter_pairs`)."""
    if robot.collision_model is not None:
        gm, source = robot.collision_model.copy(), "collision_model"
        links = [robot.model.frames[g.parentFrame].name for g in gm.geometryObjects]
    elif robot.info is not None and "<collision" in robot.info.text:
        gm, source = from_urdf(robot, convex), "urdf"
        links = [robot.model.frames[g.parentFrame].name for g in gm.geometryObjects]
    else:
        gm, links = capsules(robot)
        source = "capsules"
    if gm.ngeoms == 0:
        raise NoCollisionBodiesError(
            f"{robot.name}: no collision bodies (no <collision> and no links to wrap)"
        )
    cm = CollisionModel(robot, gm, links, source)
    filter_pairs(robot, cm, srdf=srdf, samples=samples, never_margin=never_margin, rng=rng)
    return cm


def model(robot) -> CollisionModel:
    """The robot's :class:`CollisionModel`, built on first use and kept on the robot
    (``robot.derived("collision.model", ...)``): edit its pairs with
    :meth:`CollisionModel.disable` / :meth:`CollisionModel.enable`; :func:`build` makes a fresh
    one with other options (an SRDF, convex hulls off)."""
    return robot.derived("collision.model", build)


__all__ = [
    "CollisionModel",
    "support_mask",
    "model",
    "build",
    "from_urdf",
    "capsules",
    "MIN_SEGMENT",
]
