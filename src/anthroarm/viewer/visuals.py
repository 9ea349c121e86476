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

All geometry is expressed in metres in the driving frame; nothing here talks to a server.  The
pieces and primitive shapes are in :mod:`~anthroarm.viewer.shapes`, the mesh files in
:mod:`~anthroarm.viewer.meshes`, the colours in :mod:`~anthroarm.viewer.colors`; their names
are importable from here too.
"""

from __future__ import annotations

from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from .._io import parse_xml
from ..chain import PRISMATIC
from ..errors import MeshNotFoundError, ViewerError
from ..spatial.rotations import homogeneous
from ..urdf_io import resolve_uri
from .colors import AXIS_RGB, JOINT_RGB, LINK_RGB, SKIN_RGB, TORSO_RGB, rgb_hex
from .meshes import (
    DIRECT_FORMATS,
    MAX_MESH_BYTES,
    MESH_TRIANGLES,
    PackedMesh,
    load_mesh,
    mesh_placement,
    pack_mesh,
)
from .shapes import Body, Piece, capsule, cylinder_between, y_to

__all__ = [
    "AXIS_RGB",
    "DIRECT_FORMATS",
    "JOINT_RGB",
    "LINK_RGB",
    "MAX_MESH_BYTES",
    "MESH_TRIANGLES",
    "SKIN_RGB",
    "STYLES",
    "TORSO_RGB",
    "Body",
    "PackedMesh",
    "Piece",
    "capsule",
    "cylinder_between",
    "geometry_bodies",
    "link_radius",
    "load_mesh",
    "pack_mesh",
    "rgb_hex",
    "robot_bodies",
    "skeleton_bodies",
    "urdf_bodies",
]


def _bounded(joint) -> bool:
    return bool(np.isfinite(joint.lower) and np.isfinite(joint.upper) and joint.upper > joint.lower)


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
                homogeneous(y_to([0, 0, 1]), [0, 0, -0.3 * r]),
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
    R = y_to(d)
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
    info = robot.info
    root = parse_xml(info.text.encode(), lambda problem, line: ViewerError(problem), "a URDF")
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
                offset = offset @ np.diag([*scale, 1.0]) @ mesh_placement(geom)
            elif shape.tag == "box":
                geom = mg.Box(_floats(shape.get("size"), 3, (0.1, 0.1, 0.1)))
            elif shape.tag == "cylinder":
                L = float(shape.get("length", 0.1))
                geom = mg.Cylinder(L, float(shape.get("radius", 0.05)))
                offset = offset @ homogeneous(y_to([0, 0, 1]))  # URDF cylinders are along z
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
    z_to_y = homogeneous(y_to([0, 0, 1]))  # coal's round shapes are along z, meshcat's along y
    path = Path(go.meshPath) if go.meshPath else None
    if path is not None and path.is_file():
        if path not in mesh_cache:
            mesh_cache[path] = load_mesh(path, link=go.name, max_triangles=max_triangles)
        geom = mesh_cache[path]
        offset = M @ np.diag([*np.asarray(go.meshScale, float), 1.0]) @ mesh_placement(geom)
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
