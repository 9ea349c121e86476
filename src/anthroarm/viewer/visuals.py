"""What the viewer draws for a Robot: a list of rigid *bodies*, each driven by one joint or
frame of ``robot.chain`` and carrying meshcat geometry in its own frame.

Where the geometry comes from (:func:`robot_bodies`, ``style="auto"``):

* Book models (``robot.spec`` is set) whose links are plain segments, and robots without any
  visual geometry: a skeleton
  generated from ``robot.chain`` — a sphere at every joint centre, a cylinder along every joint
  axis, capsules from each joint to its children and to the tip frames, a sleeve over the stroke
  of prismatic joints, a small palm at the tool.  Sizes scale with the reach.  A book limb scaled
  to a person (its spec says ``person=True``) also gets a torso for context.
* A book model that designs its links' shapes (``LinkSpec.shapes``: the palm and phalanges of
  ``human_upper_limb``), and a robot with a URDF: the URDF's ``<visual>`` elements — meshes resolved with
  :func:`anthroarm.urdf_io.resolve_uri` (the same resolution the loader used), boxes, cylinders
  and spheres — each attached to its link's frame.  A mesh that cannot be found raises
  :class:`~anthroarm.errors.MeshNotFoundError` naming the link, the URI and the path.
* A robot loaded from a ``pin.Model`` with ``visual_model=`` (a ``pin.GeometryModel``): its
  geometry objects — mesh files, or the loaded triangles when there is no file, and the
  primitive shapes (box, sphere, cylinder, capsule, cone, ellipsoid) — on their parent joints.

All geometry is expressed in metres in the driving frame; nothing here talks to a server.
"""

from __future__ import annotations

import re
import stat
from dataclasses import dataclass, field
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from ..chain import PRISMATIC
from ..errors import MeshError, MeshNotFoundError, ViewerError
from ..spatial.rotations import homogeneous, rotation_between

LINK_RGB = (0.62, 0.68, 0.78)
JOINT_RGB = (0.90, 0.50, 0.20)
AXIS_RGB = (0.25, 0.25, 0.30)
SKIN_RGB = (0.93, 0.78, 0.66)
TORSO_RGB = (0.55, 0.60, 0.66)


def rgb_hex(rgb) -> int:
    r, g, b = (int(round(255 * max(0.0, min(1.0, float(c))))) for c in rgb[:3])
    return (r << 16) | (g << 8) | b


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


def _bounded(joint) -> bool:
    return bool(np.isfinite(joint.lower) and np.isfinite(joint.upper) and joint.upper > joint.lower)


# ---------------------------------------------------------------------- primitives
def _y_to(direction) -> np.ndarray:
    """Rotation taking +y (meshcat's cylinder axis) onto ``direction``."""
    return rotation_between((0.0, 1.0, 0.0), direction)


def cylinder_between(a, b, radius, rgb, group="links", opacity=1.0) -> list[Piece]:
    a, b = np.asarray(a, float), np.asarray(b, float)
    L = float(np.linalg.norm(b - a))
    if L < 1e-9:
        return []
    return [
        Piece(mg.Cylinder(L, radius), rgb, homogeneous(_y_to(b - a), (a + b) / 2), group, opacity)
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


# ---------------------------------------------------------------------- generated skeleton
def link_radius(robot) -> float:
    """Capsule radius: 6 % of the arm's reach, between 1.5 cm and 6 cm."""
    return float(np.clip(0.06 * robot.length_scale, 0.015, 0.06))


def _segments(t: np.ndarray, axis: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Segments from the joint origin to ``t``: along the joint axis first, then across it
    (the book's D-H offsets s then h), or straight if one part is negligible."""
    along = float(t @ axis) * axis
    across = t - along
    n = np.linalg.norm(t)
    if n < 1e-9:
        return []
    if np.linalg.norm(along) > 0.05 * n and np.linalg.norm(across) > 0.05 * n:
        return [(np.zeros(3), along), (along, t)]
    return [(np.zeros(3), t)]


def skeleton_bodies(robot) -> list[Body]:
    """Visuals generated from ``robot.chain`` (see the module docstring): one body per joint,
    capsules to its child joints and to the tip frames on it (the tool among them)."""
    chain = robot.chain
    r = link_radius(robot)
    tool = chain.frame(None)
    ends: dict[int, list[np.ndarray]] = {j: [] for j in range(-1, len(chain.joints))}
    for j in chain.joints:
        ends[j.parent].append(np.asarray(j.translation))
    tips = {chain.frame(t).index for t in chain.tips} | {tool.index}
    for fid in sorted(tips):
        f = chain.frames[fid]
        ends[f.joint].append(np.asarray(f.translation))

    # base: a pedestal (or the torso of a human limb) and the links to the first joints
    base: list[Piece] = []
    for t in ends[-1]:
        for a, b in _segments(t, np.array([0.0, 0.0, 1.0])):
            base += capsule(a, b, r)
    if robot.spec is not None and robot.spec.person:  # the limb of a person
        base += _torso(robot, r)
    else:
        base.append(
            Piece(
                mg.Cylinder(0.6 * r, 2.2 * r),
                TORSO_RGB,
                homogeneous(_y_to([0, 0, 1]), [0, 0, -0.3 * r]),
                "base",
            )
        )
    bodies: list[Body] = [Body("base", base)]
    by_joint: dict[int, Body] = {-1: bodies[0]}

    pending: dict[int, list[int]] = {}
    for j in chain.joints:
        axis = np.asarray(j.axis)
        pieces: list[Piece] = [Piece(mg.Sphere(1.25 * r), JOINT_RGB, np.eye(4), "joint")]
        pieces += cylinder_between(-1.7 * r * axis, 1.7 * r * axis, 0.55 * r, AXIS_RGB, "axis")
        for t in ends[j.index]:
            for a, b in _segments(t, axis):
                pieces += capsule(a, b, 0.8 * r)
        if j.kind == PRISMATIC:
            lo, hi = _stroke(robot, j)
            # the sliding member reaches back over the whole stroke so it never leaves its sleeve
            pieces += capsule(np.zeros(3), -(hi - lo) * axis, 0.7 * r)
            # the fixed sleeve lives on the parent body
            a = j.translation + j.rotation @ (lo * axis)
            b = j.translation + j.rotation @ (hi * axis)
            by_joint[j.parent].pieces += cylinder_between(a, b, 1.05 * r, TORSO_RGB, "axis", 0.55)
        if tool.joint == j.index:
            pieces += _palm(tool, r, axis)
        own = j.index if _bounded(j) else None
        link_joints = pending.get(j.parent, []) + ([own] if own is not None else [])
        if not any(p.group == "links" for p in pieces):
            pending[j.index] = (
                link_joints  # nothing to colour here: hand the joint on to the next link
            )
        body = by_joint[j.index] = Body(
            j.name, pieces, joint=j.index, limit_joint=own, link_joints=link_joints
        )
        bodies.append(body)
    return bodies


def _stroke(robot, joint) -> tuple[float, float]:
    """A prismatic joint's travel (m); ± half the reach where it has no limits."""
    if _bounded(joint):
        return float(joint.lower), float(joint.upper)
    return -0.5 * robot.length_scale, 0.5 * robot.length_scale


def _palm(tool_frame, r, axis) -> list[Piece]:
    """A flat palm at the tool: an ellipsoid whose long axis continues the last link."""
    t = np.asarray(tool_frame.translation)
    d = t / np.linalg.norm(t) if np.linalg.norm(t) > 1e-9 else axis
    R = _y_to(d)
    return [Piece(mg.Ellipsoid([1.6 * r, 1.6 * r, 0.7 * r]), SKIN_RGB, homogeneous(R, t), "palm")]


def _torso(robot, r) -> list[Piece]:
    """Context for the §6-3 human arm (right shoulder at the origin, x to the right, y forward,
    arm hanging along -z): a torso medial to the shoulder, a neck and a head.  Proportions
    scale with the arm's length L (shoulder to midline ≈ 0.3 L ≈ 0.19 m for a 1.75 m man)."""
    L = robot.length_scale
    w = 0.3 * L
    pieces = [
        Piece(
            mg.Ellipsoid([0.9 * w, 0.5 * w, 0.5 * L]),
            TORSO_RGB,
            homogeneous(r=[-w, 0.0, -0.42 * L]),
            "torso",
        )
    ]
    pieces += capsule(
        [-0.12 * w, 0.0, -0.03 * L], [-1.88 * w, 0.0, -0.03 * L], 0.8 * r, TORSO_RGB, "torso"
    )
    pieces += cylinder_between([-w, 0.0, 0.0], [-w, 0.0, 0.12 * L], 0.22 * w, SKIN_RGB, "torso")
    pieces.append(
        Piece(
            mg.Ellipsoid([0.33 * w, 0.38 * w, 0.45 * w]),
            SKIN_RGB,
            homogeneous(r=[-w, 0.02 * L, 0.25 * L]),
            "torso",
        )
    )
    return pieces


# ---------------------------------------------------------------------- URDF visuals
def _floats(text, n, default):
    if text is None:
        return list(default)
    vals = [float(x) for x in text.split()]
    return vals if len(vals) == n else list(default)


def _origin(el) -> np.ndarray:
    o = el.find("origin") if el is not None else None
    xyz = _floats(o.get("xyz") if o is not None else None, 3, (0, 0, 0))
    rpy = _floats(o.get("rpy") if o is not None else None, 3, (0, 0, 0))
    return homogeneous(pin.rpy.rpyToMatrix(*rpy), xyz)


def urdf_bodies(robot, max_triangles: int | None = None) -> list[Body]:
    """Bodies from the URDF's ``<visual>`` elements (meshes resolved like the loader did);
    ``max_triangles``: see :func:`load_mesh`."""
    from lxml import etree

    from ..urdf_io import resolve_uri

    info = robot.info
    root = etree.fromstring(
        info.text.encode(),
        etree.XMLParser(
            resolve_entities=False, no_network=True, load_dtd=False, remove_comments=True
        ),
    )
    named_colors = {}
    for m in root.findall("material"):
        c = m.find("color")
        if c is not None and m.get("name"):
            named_colors[m.get("name")] = _floats(c.get("rgba"), 4, (0.7, 0.7, 0.7, 1))
    links = {}
    for f in robot.chain.frames:  # the link's body frame (a joint may share its name)
        if f.is_body:
            links.setdefault(f.name, f)
    bodies: list[Body] = []
    mesh_cache: dict[Path, object] = {}
    for link in root.findall("link"):
        name = link.get("name")
        visuals = link.findall("visual")
        frame = links.get(name)
        if not visuals or frame is None:
            continue
        pieces: list[Piece] = []
        for vis in visuals:
            geo = vis.find("geometry")
            if geo is None or len(geo) == 0:
                continue
            shape = geo[0]
            offset = _origin(vis)
            rgba = (0.75, 0.75, 0.78, 1.0)
            mat = vis.find("material")
            if mat is not None:
                c = mat.find("color")
                if c is not None:
                    rgba = _floats(c.get("rgba"), 4, rgba)
                elif mat.get("name") in named_colors:
                    rgba = named_colors[mat.get("name")]
            if shape.tag == "mesh":
                uri = shape.get("filename", "")
                path = info.meshes.get(uri) or resolve_uri(uri, info.path, info.package_dirs)
                path = Path(path)
                if not path.is_file():
                    raise MeshNotFoundError(
                        info.path,
                        f"link {name!r}: mesh {uri!r} resolved to {path}, which does not "
                        f"exist; pass package_dirs={{...}} to aa.load",
                    )
                scale = _floats(shape.get("scale"), 3, (1, 1, 1))
                if path not in mesh_cache:
                    mesh_cache[path] = load_mesh(path, link=name, max_triangles=max_triangles)
                geom = mesh_cache[path]
                offset = offset @ np.diag([*scale, 1.0]) @ _placement(geom)
            elif shape.tag == "box":
                geom = mg.Box(_floats(shape.get("size"), 3, (0.1, 0.1, 0.1)))
            elif shape.tag == "cylinder":
                L = float(shape.get("length", 0.1))
                geom = mg.Cylinder(L, float(shape.get("radius", 0.05)))
                offset = offset @ homogeneous(_y_to([0, 0, 1]))  # URDF cylinders are along z
            elif shape.tag == "sphere":
                geom = mg.Sphere(float(shape.get("radius", 0.05)))
            else:
                continue
            pieces.append(
                Piece(
                    geom, tuple(rgba[:3]), offset, "mesh", float(rgba[3]) if len(rgba) > 3 else 1.0
                )
            )
        if pieces:
            bodies.append(
                Body(name, pieces, frame=frame.index, **_limit_kw(robot.chain, frame.joint))
            )
    return bodies


def _placement(geom) -> np.ndarray:
    """Where a mesh geometry's own coordinates sit in the mesh file's frame (a PackedMesh's grid)."""
    return geom.placement if isinstance(geom, PackedMesh) else np.eye(4)


def _limit_kw(chain, joint: int) -> dict:
    """Colouring of a body moved by chain joint ``joint`` (−1: the base): that joint if it has
    limits."""
    if joint >= 0 and _bounded(chain.joints[joint]):
        return {"limit_joint": joint, "link_joints": [joint]}
    return {}


# ---------------------------------------------------------------------- pin.GeometryModel
def geometry_bodies(robot, max_triangles: int | None = None) -> list[Body]:
    """Bodies from ``robot.visual_model`` (a ``pin.GeometryModel``): one body per joint that
    carries geometry, each object at its placement in the joint frame (Pinocchio's
    ``GeometryObject.placement``)."""
    chain = robot.chain
    by_joint: dict[int, list[Piece]] = {}
    mesh_cache: dict[Path, object] = {}
    for go in robot.visual_model.geometryObjects:
        by_joint.setdefault(int(go.parentJoint) - 1, []).extend(
            _geometry_pieces(go, mesh_cache, max_triangles)
        )
    bodies = []
    for j, pieces in sorted(by_joint.items()):
        if not pieces:
            continue
        if j < 0:
            bodies.append(Body("base", pieces))
        else:
            bodies.append(Body(chain.joints[j].name, pieces, joint=j, **_limit_kw(chain, j)))
    return bodies


#: shapes of infinite extent (nothing to draw)
_UNBOUNDED_SHAPES = ("Plane", "Halfspace")


def _geometry_pieces(go, mesh_cache, max_triangles=None) -> list[Piece]:
    """Pieces for one ``pin.GeometryObject``: a mesh file when ``meshPath`` names one (scaled
    by ``meshScale``), else the primitive shape or the loaded triangles (already scaled)."""
    g = go.geometry
    kind = type(g).__name__
    M = np.asarray(go.placement.homogeneous)
    rgba = np.asarray(go.meshColor, float)
    rgb, opacity = tuple(rgba[:3]), float(rgba[3])
    z_to_y = homogeneous(_y_to([0, 0, 1]))  # coal's round shapes are along z, meshcat's along y
    path = Path(go.meshPath) if go.meshPath else None
    if path is not None and path.is_file():
        if path not in mesh_cache:
            mesh_cache[path] = load_mesh(path, link=go.name, max_triangles=max_triangles)
        geom = mesh_cache[path]
        offset = M @ np.diag([*np.asarray(go.meshScale, float), 1.0]) @ _placement(geom)
    elif kind == "Box":
        geom, offset = mg.Box(2 * np.asarray(g.halfSide, float)), M
    elif kind == "Sphere":
        geom, offset = mg.Sphere(float(g.radius)), M
    elif kind == "Ellipsoid":
        geom, offset = mg.Ellipsoid(np.asarray(g.radii, float)), M
    elif kind == "Cylinder":
        geom, offset = mg.Cylinder(2 * g.halfLength, g.radius), M @ z_to_y
    elif kind == "Cone":  # apex at +z
        geom, offset = (
            mg.Cylinder(2 * g.halfLength, radiusTop=0.0, radiusBottom=g.radius),
            M @ z_to_y,
        )
    elif kind == "Capsule":
        h = float(g.halfLength)
        pieces = capsule([0, 0, -h], [0, 0, h], float(g.radius), rgb, "mesh") or [
            Piece(mg.Sphere(float(g.radius)), rgb, np.eye(4), "mesh")
        ]
        for pc in pieces:
            pc.offset, pc.opacity = M @ pc.offset, opacity
        return pieces
    elif hasattr(g, "tri_indices") and g.num_tris > 0:
        faces = np.array([list(g.tri_indices(i)) for i in range(g.num_tris)], dtype=np.uint32)
        geom, offset = mg.TriangularMeshGeometry(np.asarray(g.vertices(), float), faces), M
    elif kind in _UNBOUNDED_SHAPES:
        return []
    else:
        raise ViewerError(
            f"visual geometry {go.name!r} is a {kind} with no mesh file ({go.meshPath!r}); "
            "the viewer draws mesh files, triangle meshes, boxes, spheres, ellipsoids, "
            "cylinders, cones and capsules"
        )
    return [Piece(geom, rgb, offset, "mesh", opacity)]


#: Largest mesh file the viewer reads (bytes).  Its contents go to the browser in one message.
MAX_MESH_BYTES = 256 * 2**20
#: The mesh formats read directly (checked here, parsed by three.js in the browser); any other
#: extension goes through trimesh and is sent as a binary STL.
DIRECT_FORMATS = (".stl", ".obj", ".dae")

_STL_RECORD = np.dtype([("normal", "<f4", 3), ("v", "<f4", 9), ("attr", "<u2")])


def load_mesh(path, link: str | None = None, max_triangles: int | None = None):
    """A meshcat mesh geometry from a mesh file: .stl (binary or ASCII), .obj, .dae, or any
    format trimesh reads (sent as STL).  With ``max_triangles`` the file is parsed here and
    sent as a :class:`PackedMesh` of at most that many triangles (:func:`pack_mesh`) instead.

    The file is read once, checked, and only the checked bytes are sent: a file that is not a
    mesh (a text file, random bytes), empty, truncated, with non-finite coordinates, larger than
    :data:`MAX_MESH_BYTES`, or a .dae with a DTD raises :class:`~anthroarm.errors.MeshError`
    naming the file and ``link`` (the link or geometry object that uses it)."""
    path = Path(path)
    try:
        st = path.stat()
    except OSError as exc:
        raise MeshError(path, f"cannot be read ({exc.strerror or exc})", link) from None
    if not stat.S_ISREG(st.st_mode):
        raise MeshError(path, "is not a regular file", link)
    if st.st_size > MAX_MESH_BYTES:
        raise MeshError(
            path,
            f"is {st.st_size} bytes, larger than the viewer's bound of {MAX_MESH_BYTES} bytes "
            f"(anthroarm.viewer.visuals.MAX_MESH_BYTES); decimate the mesh",
            link,
        )
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_MESH_BYTES + 1)
    except OSError as exc:
        raise MeshError(path, f"cannot be read ({exc.strerror or exc})", link) from None
    if len(data) > MAX_MESH_BYTES:  # grew since stat
        raise MeshError(path, f"is larger than the viewer's bound of {MAX_MESH_BYTES} bytes", link)
    if not data:
        raise MeshError(path, "is empty", link)
    ext = path.suffix.lower()
    try:
        if ext == ".stl":
            _check_stl(data)
            geom, fmt, body = _stl_geometry(data), "stl", data
        elif ext == ".obj":
            body = _check_obj(data)
            geom, fmt = mg.MeshGeometry(body, "obj"), "obj"
        elif ext == ".dae":
            body = _check_dae(data)
            geom, fmt = mg.MeshGeometry(body, "dae"), "dae"
        else:
            body = _via_trimesh(data, ext)
            geom, fmt = _stl_geometry(body), "stl"
        if max_triangles is None:
            return geom
        return _packed(
            body, fmt, _check_budget(max_triangles), (str(path), st.st_mtime_ns, st.st_size)
        )
    except _NotAMesh as exc:
        raise MeshError(path, str(exc), link) from None


#: Default triangle budget of one mesh file in the viewer (``Viewer(mesh_triangles=...)``): the
#: Franka Panda's 10 visual mesh files (134 000 triangles, 10.5 MB of COLLADA text) become 44 000
#: triangles in 0.39 MB, so a Jupyter cell embeds well under 2 MB.
MESH_TRIANGLES = 5000


class PackedMesh(mg.Geometry):
    """An indexed triangle mesh in a compact form: vertex positions on a 16-bit grid over the
    mesh's bounding cube (``placement`` maps grid units to the mesh file's metres), indices as
    16-bit integers below 65 536 vertices.  No normals are sent: the page computes smooth
    vertex normals (``anthroarm_normals`` in :data:`~anthroarm.viewer._store.JS_PATCH`)."""

    def __init__(self, grid: np.ndarray, faces: np.ndarray, placement: np.ndarray):
        super().__init__()
        self.grid = np.ascontiguousarray(grid, dtype=np.uint16)
        self.faces = np.ascontiguousarray(
            faces, dtype=np.uint16 if len(self.grid) <= 65536 else np.uint32
        )
        self.placement = np.asarray(placement, float)

    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) vertex positions in the mesh file's frame (m)."""
        return self.grid.astype(float) @ self.placement[:3, :3].T + self.placement[:3, 3]

    def lower(self, object_data):
        import umsgpack

        def attr(a, size):
            code, name = (20, "Uint16Array") if a.dtype == np.uint16 else (22, "Uint32Array")
            return {
                "itemSize": size,
                "type": name,
                "array": umsgpack.Ext(code, a.tobytes()),
                "normalized": False,
            }

        return {
            "uuid": self.uuid,
            "type": "BufferGeometry",
            "data": {
                "attributes": {"position": attr(self.grid, 3)},
                "index": attr(self.faces.ravel(), 1),
            },
        }


def _check_budget(max_triangles) -> int:
    import numbers

    if (
        isinstance(max_triangles, bool)
        or not isinstance(max_triangles, numbers.Integral)
        or int(max_triangles) < 12
    ):
        from ..errors import ParameterError

        raise ParameterError(
            f"max_triangles (mesh_triangles) must be an integer >= 12 or None (the mesh files "
            f"as they are), got {max_triangles!r}"
        )
    return int(max_triangles)


def _cluster(V: np.ndarray, F: np.ndarray, n: int, count_only: bool = False):
    """Vertex clustering on a grid of ``n`` cells along the bounding cube's side: the vertices
    of a cell merge into their mean; triangles that collapse, or repeat, are dropped.
    ``count_only``: just the number of triangles that do not collapse (an upper bound)."""
    lo = V.min(0)
    side = float((V.max(0) - lo).max()) or 1.0
    key = np.minimum(np.floor((V - lo) / side * n).astype(np.int64), n - 1)
    flat = (key[:, 0] * n + key[:, 1]) * n + key[:, 2]
    if count_only:
        G = flat[F]
        return int(
            np.count_nonzero((G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2]))
        )
    _, inv = np.unique(flat, return_inverse=True)
    inv = inv.ravel()
    cnt = np.bincount(inv)
    W = np.stack([np.bincount(inv, V[:, k]) for k in range(3)], 1) / cnt[:, None]
    G = inv[F]
    G = G[(G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])]
    if len(G):
        r = np.argmin(
            G, 1
        )  # rotate each triangle to start at its smallest index: repeats become equal rows
        G = np.unique(np.stack([G[np.arange(len(G)), (r + k) % 3] for k in range(3)], 1), axis=0)
    used = np.unique(G)
    remap = np.full(len(W), -1, np.int64)
    remap[used] = np.arange(len(used))
    return W[used], remap[G]


def pack_mesh(vertices, faces, max_triangles: int = MESH_TRIANGLES) -> PackedMesh:
    """A :class:`PackedMesh` of at most ``max_triangles`` triangles: coincident vertices merged
    (a 16-bit grid: 1/65535 of the bounding cube), then, above the budget, vertex clustering on
    the finest grid that meets it (Rossignac & Borrel 1993, "Multi-resolution 3D approximations
    for rendering complex scenes")."""
    V = np.asarray(vertices, float)
    F = np.asarray(faces, np.int64).reshape(-1, 3)
    W, G = _cluster(V, F, 65535)
    if len(G) > max_triangles:
        lo, hi = 2, 4096
        while lo < hi:  # the finest grid whose surviving triangles fit (they grow with n)
            mid = (lo + hi + 1) // 2
            if _cluster(V, F, mid, count_only=True) <= max_triangles:
                lo = mid
            else:
                hi = mid - 1
        W, G = _cluster(V, F, lo)
    if len(W) == 0:
        W, G = np.zeros((1, 3)), np.zeros((0, 3), np.int64)
    lo = W.min(0)
    step = max(float((W.max(0) - lo).max()), 1e-12) / 65535.0
    grid = np.clip(np.round((W - lo) / step), 0, 65535)
    placement = np.diag([step, step, step, 1.0])
    placement[:3, 3] = lo
    return PackedMesh(grid, G, placement)


_PACKED: dict = {}


def _packed(body, fmt: str, max_triangles: int, key) -> PackedMesh:
    """The checked mesh bytes/text parsed with trimesh and packed; the last 64 results are kept
    (key: file, modification time, size, budget), so a second Viewer of a robot is quick."""
    import io

    import trimesh

    k = (*key, max_triangles)
    if k in _PACKED:
        return _PACKED[k]
    data = body.encode("utf-8") if isinstance(body, str) else body
    try:
        m = trimesh.load(io.BytesIO(data), file_type=fmt, force="mesh")
        V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    except Exception as exc:  # noqa: BLE001 - trimesh/pycollada raise anything
        raise _NotAMesh(
            f"cannot be parsed for the viewer ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})"
        ) from None
    if len(F) and not np.all(np.isfinite(V)):
        raise _NotAMesh("has non-finite vertex coordinates")
    packed = (
        pack_mesh(V, F, max_triangles)
        if len(F)
        else PackedMesh(np.zeros((1, 3)), np.zeros((0, 3)), np.eye(4))
    )
    if len(_PACKED) >= 64:
        _PACKED.pop(next(iter(_PACKED)))
    _PACKED[k] = packed
    return packed


class _NotAMesh(Exception):
    """What is wrong with the bytes (turned into a MeshError naming the file and the link)."""


def _stl_geometry(data: bytes):
    import umsgpack
    from meshcat.geometry import threejs_type

    _, extcode = threejs_type(np.uint8)
    return mg.MeshGeometry(umsgpack.Ext(extcode, bytes(data)), "stl")


def _check_stl(data: bytes) -> None:
    """A binary STL whose size matches its triangle count, or an ASCII STL of complete facets
    ending in 'endsolid'; every coordinate finite.  A well-formed STL without triangles (an
    empty solid) is accepted: it draws nothing."""
    n = len(data)
    if n >= 84:
        count = int.from_bytes(data[80:84], "little")
        expected = 84 + 50 * count
        if expected <= n and not (expected < n and data[:5].lower() == b"solid"):
            rec = np.frombuffer(data, dtype=_STL_RECORD, count=count, offset=84)
            bad = ~np.isfinite(rec["v"]).all(axis=1)
            if bad.any():
                raise _NotAMesh(
                    f"is a binary STL with non-finite vertex coordinates (triangle {int(np.argmax(bad))})"
                )
            return
    if data.lstrip()[:5].lower() == b"solid":
        _check_ascii_stl(data)
        return
    if n >= 84:
        count = int.from_bytes(data[80:84], "little")
        raise _NotAMesh(
            f"is not an STL file: as a binary STL its header promises {count} triangles "
            f"({84 + 50 * count} bytes) but the file has {n} bytes (truncated, or not a mesh), "
            "and it is not an ASCII STL ('solid ... endsolid')"
        )
    raise _NotAMesh(
        f"is not an STL file ({n} bytes: shorter than a binary STL header, and not an ASCII STL)"
    )


def _check_ascii_stl(data: bytes) -> None:
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise _NotAMesh(
            f"starts like an ASCII STL but has a non-ASCII byte at offset {exc.start}"
        ) from None
    facets = 0
    in_loop = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        key = parts[0].lower()
        if key == "vertex":
            try:
                xyz = [float(x) for x in parts[1:]]
            except ValueError:
                xyz = []
            if len(xyz) != 3 or not all(map(np.isfinite, xyz)):
                raise _NotAMesh(
                    f"is an ASCII STL with a bad vertex at line {lineno}: {line.strip()[:60]!r}"
                )
            in_loop += 1
        elif key == "outer":
            in_loop = 0
        elif key == "endloop":
            if in_loop != 3:
                raise _NotAMesh(
                    f"is an ASCII STL with a facet of {in_loop} vertices at line {lineno} (3 expected)"
                )
            facets += 1
    if not re.search(r"^\s*endsolid\b", text, re.MULTILINE | re.IGNORECASE):
        raise _NotAMesh("is an ASCII STL without 'endsolid' (truncated)")


def _utf8(data: bytes, what: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise _NotAMesh(
            f"is not UTF-8 text (a {what} file is text): byte {data[exc.start]:#04x} at offset "
            f"{exc.start}"
        ) from None


def _check_obj(data: bytes) -> str:
    """Wavefront OBJ text: finite vertices, faces of >= 3 vertices that refer to vertices
    defined before them; at least one face."""
    text = _utf8(data, "Wavefront .obj")
    nv = faces = 0
    for lineno, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "v":
            try:
                xyz = [float(x) for x in parts[1:4]]
            except ValueError:
                xyz = []
            if len(xyz) != 3 or not all(map(np.isfinite, xyz)):
                raise _NotAMesh(
                    f"is an OBJ with a bad vertex at line {lineno}: {line.strip()[:60]!r}"
                )
            nv += 1
        elif parts[0] == "f":
            if len(parts) < 4:
                raise _NotAMesh(f"is an OBJ with a face of fewer than 3 vertices at line {lineno}")
            for tok in parts[1:]:
                try:
                    i = int(tok.split("/")[0])
                except ValueError:
                    raise _NotAMesh(
                        f"is an OBJ with a bad face at line {lineno}: {line.strip()[:60]!r}"
                    ) from None
                if not (1 <= i <= nv or -nv <= i <= -1):
                    raise _NotAMesh(
                        f"is an OBJ whose face at line {lineno} refers to vertex {i}, but {nv} "
                        "vertices are defined before it (truncated, or not a mesh)"
                    )
            faces += 1
    if faces == 0:
        raise _NotAMesh(f"is not an OBJ mesh: no faces ({nv} vertices)")
    return text


def _check_dae(data: bytes) -> str:
    """COLLADA XML without a DTD, with at least one <geometry>; returned as text."""
    from lxml import etree

    parser = etree.XMLParser(
        resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False
    )
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise _NotAMesh(f"is not well-formed XML (a COLLADA .dae file is XML): {exc}") from None
    tree = root.getroottree()
    if tree.docinfo.doctype or tree.docinfo.internalDTD is not None:
        raise _NotAMesh(
            "declares a DTD (<!DOCTYPE ...>); refused: entity declarations can expand without bound "
            "or pull in other files"
        )
    name = etree.QName(root).localname if isinstance(root.tag, str) else str(root.tag)
    if name != "COLLADA":
        raise _NotAMesh(f"is XML but not COLLADA (root element <{name}>)")
    if next(root.iter("{*}geometry", "geometry"), None) is None:
        raise _NotAMesh("is a COLLADA file without any <geometry>")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:  # another declared encoding: send lxml's Unicode text
        return etree.tostring(root, encoding="unicode")


def _via_trimesh(data: bytes, ext: str) -> bytes:
    """Any other format trimesh reads, as a binary STL."""
    if not ext:
        raise _NotAMesh(
            "has no file extension; the viewer reads .stl, .obj, .dae and the formats trimesh "
            "reads (.ply, .glb, .off, ...)"
        )
    import io

    import trimesh

    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=ext[1:], force="mesh")
        faces = len(mesh.faces)
        finite = bool(np.isfinite(np.asarray(mesh.vertices)).all())
        out = mesh.export(file_type="stl") if faces and finite else b""
    except Exception as exc:  # noqa: BLE001 - trimesh raises anything (NotImplementedError, KeyError, ...)
        raise _NotAMesh(
            f"cannot be read as a {ext} mesh ({type(exc).__name__}: {' '.join(str(exc).split())[:200]})"
        ) from None
    if not faces:
        raise _NotAMesh(f"is a {ext} file without triangles")
    if not finite:
        raise _NotAMesh(f"is a {ext} mesh with non-finite vertex coordinates")
    _check_stl(out)
    return out


STYLES = ("auto", "generated", "urdf", "visual_model")


def robot_bodies(robot, style: str = "auto", max_triangles: int | None = None) -> list[Body]:
    """Bodies for any Robot.  ``style``: "generated" (the skeleton from ``robot.chain``),
    "urdf" (the URDF's ``<visual>`` elements), "visual_model" (``robot.visual_model``), or
    "auto": generated for book models whose links are plain segments, the URDF's visuals for
    book models that design their links' shapes (``LinkSpec.shapes``: a hand's palm and
    phalanges; a person's limb keeps its torso), else the robot's own visuals (URDF, then
    visual model), and the skeleton when it has none.  ``max_triangles``: each mesh file as a
    :class:`PackedMesh` of at most that many triangles (None: the files as they are)."""
    if style not in STYLES:
        raise ValueError(f"style must be one of {', '.join(map(repr, STYLES))}, got {style!r}")
    if style == "urdf" and robot.info is None:
        raise ViewerError(
            f"{robot.name} has no URDF (it was loaded from a pin.Model): use style='auto'"
        )
    if style == "visual_model" and robot.visual_model is None:
        raise ViewerError(
            f"{robot.name} has no visual_model: pass visual_model= to aa.load, or use style='auto'"
        )
    designed = robot.spec is not None and any(
        j.link is not None and j.link.shapes is not None for j in robot.spec.joints
    )
    if style == "generated" or (style == "auto" and robot.spec is not None and not designed):
        return skeleton_bodies(robot)
    bodies = []
    if style in ("auto", "urdf") and robot.info is not None:
        bodies = urdf_bodies(robot, max_triangles)
        if bodies and designed and robot.spec.person:  # the limb of a person: the torso for context
            bodies.insert(0, Body("torso", _torso(robot, link_radius(robot))))
    elif style in ("auto", "visual_model") and robot.visual_model is not None:
        bodies = geometry_bodies(robot, max_triangles)
    return bodies or skeleton_bodies(robot)  # no visual geometry at all: the skeleton
