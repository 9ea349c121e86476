"""What the viewer draws for a Robot: a list of rigid *bodies*, each driven by one Pinocchio
joint or frame placement and carrying meshcat geometry in its own frame.

* Book models (``robot.spec`` is set): generated visuals — a sphere at every joint centre, a
  cylinder along every joint axis, capsules (cylinder + two end spheres) from each joint to its
  children and to the tool, a sleeve for prismatic joints, a small palm at the tool, and for the
  human arm a torso for context.  Sizes scale with the arm's reach.
* Any other URDF (example-robot-data arms): the URDF's ``<visual>`` elements — meshes resolved
  with :func:`anthroarm.urdf_io.resolve_uri` (the same resolution the loader used), boxes,
  cylinders and spheres — each attached to its link's frame.  A mesh that cannot be found
  raises :class:`~anthroarm.errors.MeshNotFoundError` naming the link, the URI and the path.

All geometry is expressed in metres in the driving frame; nothing here talks to a server.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from ..errors import MeshNotFoundError
from ..spatial.rotations import homogeneous, rotation_between

LINK_RGB = (0.62, 0.68, 0.78)
JOINT_RGB = (0.90, 0.50, 0.20)
AXIS_RGB = (0.25, 0.25, 0.30)
SKIN_RGB = (0.93, 0.78, 0.66)
TORSO_RGB = (0.55, 0.60, 0.66)


def rgb_hex(rgb) -> int:
    r, g, b = (int(round(255 * max(0.0, min(1.0, float(c))))) for c in rgb[:3])
    return (r << 16) | (g << 8) | b


def material(rgb, opacity: float = 1.0) -> mg.MeshPhongMaterial:
    kw = {"color": rgb_hex(rgb)}
    if opacity < 1.0:
        kw.update(opacity=float(opacity), transparent=True)
    return mg.MeshPhongMaterial(**kw)


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
    """Pieces moving with one placement: ``joint`` (pin joint id, pose ``data.oMi``) or
    ``frame`` (pin frame id, pose ``data.oMf``); both None means fixed to the base.
    ``dof`` is the configuration index whose limit proximity colours the body (or None)."""

    name: str
    pieces: list[Piece]
    joint: int | None = None
    frame: int | None = None
    dof: int | None = None
    #: configuration indices whose limit proximity colours this body's links: its own joint
    #: and the joints that sit at the same point just before it (the shoulder's x-y-z, the
    #: elbow and forearm rotation), so a link turns red when any joint that moves it is at a limit
    link_dofs: list = field(default_factory=list)


# ---------------------------------------------------------------------- primitives
def _y_to(direction) -> np.ndarray:
    """Rotation taking +y (meshcat's cylinder axis) onto ``direction``."""
    return rotation_between((0.0, 1.0, 0.0), direction)


def cylinder_between(a, b, radius, rgb, group="links", opacity=1.0) -> list[Piece]:
    a, b = np.asarray(a, float), np.asarray(b, float)
    L = float(np.linalg.norm(b - a))
    if L < 1e-9:
        return []
    return [Piece(mg.Cylinder(L, radius), rgb, homogeneous(_y_to(b - a), (a + b) / 2), group, opacity)]


def capsule(a, b, radius, rgb=LINK_RGB, group="links") -> list[Piece]:
    """A capsule from ``a`` to ``b``: a cylinder and two hemispherical caps (spheres)."""
    out = cylinder_between(a, b, radius, rgb, group)
    if not out:
        return []
    return out + [Piece(mg.Sphere(radius), rgb, homogeneous(r=a), group), Piece(mg.Sphere(radius), rgb, homogeneous(r=b), group)]


def joint_axis(model: pin.Model, jid: int) -> tuple[np.ndarray, str]:
    """Unit axis of a 1-DoF joint in its own frame and its kind ("revolute"/"prismatic"),
    read from the motion subspace ``S`` (rows: linear; angular)."""
    jm = model.joints[jid]
    jd = jm.createData()
    jm.calc(jd, np.zeros(model.nq))
    S = np.asarray(jd.S)[:, 0] if np.asarray(jd.S).ndim == 2 else np.asarray(jd.S)
    if np.linalg.norm(S[3:]) > 1e-9:
        return S[3:] / np.linalg.norm(S[3:]), "revolute"
    return S[:3] / np.linalg.norm(S[:3]), "prismatic"


# ---------------------------------------------------------------------- book models
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


def book_bodies(robot) -> list[Body]:
    """Generated visuals for a catalog book model (see the module docstring)."""
    model = robot.model
    r = link_radius(robot)
    bodies: list[Body] = []
    children: dict[int, list[int]] = {j: [] for j in range(model.njoints)}
    for j in range(1, model.njoints):
        children[model.parents[j]].append(j)
    tool = model.frames[robot.tool_id]

    # base: a pedestal (or the torso of the human arm) and the links from the base to the first joints
    base: list[Piece] = []
    for c in children[0]:
        t = np.asarray(model.jointPlacements[c].translation)
        for a, b in _segments(t, np.array([0.0, 0.0, 1.0])):
            base += capsule(a, b, r)
    if robot.name.startswith("human_arm"):
        base += _torso(robot, r)
    else:
        base.append(Piece(mg.Cylinder(0.6 * r, 2.2 * r), TORSO_RGB, homogeneous(_y_to([0, 0, 1]), [0, 0, -0.3 * r]), "base"))
    bodies.append(Body("base", base))

    pending: dict[int, list[int]] = {}
    for j in range(1, model.njoints):
        axis, kind = joint_axis(model, j)
        pieces: list[Piece] = []
        pieces.append(Piece(mg.Sphere(1.25 * r), JOINT_RGB, np.eye(4), "joint"))
        pieces += cylinder_between(-1.7 * r * axis, 1.7 * r * axis, 0.55 * r, AXIS_RGB, "axis")
        ends = [np.asarray(model.jointPlacements[c].translation) for c in children[j]]
        if tool.parentJoint == j:
            ends.append(np.asarray(tool.placement.translation))
        for t in ends:
            for a, b in _segments(t, axis):
                pieces += capsule(a, b, 0.8 * r)
        if kind == "prismatic":
            lo, hi = _range(robot, j)
            # the sliding member reaches back over the whole stroke so it never leaves its sleeve
            pieces += capsule(np.zeros(3), -(hi - lo) * axis, 0.7 * r)
        if tool.parentJoint == j:
            pieces += _palm(tool, r, axis)
        dof = model.joints[j].idx_q if model.joints[j].nq == 1 else None
        inherited = pending.get(model.parents[j], [])
        link_dofs = inherited + ([dof] if dof is not None else [])
        if not any(p.group == "links" for p in pieces):
            pending[j] = link_dofs  # nothing to colour here: hand the joint on to the next link
        bodies.append(Body(model.names[j], pieces, joint=j, dof=dof, link_dofs=link_dofs))
        if kind == "prismatic":
            # the fixed sleeve lives on the parent body
            lo, hi = _range(robot, j)
            pj = model.parents[j]
            M = model.jointPlacements[j]
            a = M.translation + M.rotation @ (lo * axis)
            b = M.translation + M.rotation @ (hi * axis)
            sleeve = cylinder_between(a, b, 1.05 * r, TORSO_RGB, "axis", 0.55)
            target = bodies[0] if pj == 0 else next(bb for bb in bodies if bb.joint == pj)
            target.pieces += sleeve
    return bodies


def _range(robot, jid: int) -> tuple[float, float]:
    i = robot.model.joints[jid].idx_q
    lo, hi = float(robot.lower[i]), float(robot.upper[i])
    if not np.isfinite(lo) or not np.isfinite(hi):
        lo, hi = -0.5 * robot.length_scale, 0.5 * robot.length_scale
    return lo, hi


def _palm(tool_frame, r, axis) -> list[Piece]:
    """A flat palm at the tool: an ellipsoid whose long axis continues the last link."""
    t = np.asarray(tool_frame.placement.translation)
    d = t / np.linalg.norm(t) if np.linalg.norm(t) > 1e-9 else axis
    R = _y_to(d)
    return [Piece(mg.Ellipsoid([1.6 * r, 1.6 * r, 0.7 * r]), SKIN_RGB, homogeneous(R, t), "palm")]


def _torso(robot, r) -> list[Piece]:
    """Context for the §6-3 human arm (right shoulder at the origin, x to the right, y forward,
    arm hanging along -z): a torso medial to the shoulder, a neck and a head.  Proportions
    scale with the arm's length L (shoulder to midline ≈ 0.3 L ≈ 0.19 m for a 1.75 m man)."""
    L = robot.length_scale
    w = 0.3 * L
    pieces = [Piece(mg.Ellipsoid([0.9 * w, 0.5 * w, 0.5 * L]), TORSO_RGB, homogeneous(r=[-w, 0.0, -0.42 * L]), "torso")]
    pieces += capsule([-0.12 * w, 0.0, -0.03 * L], [-1.88 * w, 0.0, -0.03 * L], 0.8 * r, TORSO_RGB, "torso")
    pieces += cylinder_between([-w, 0.0, 0.0], [-w, 0.0, 0.12 * L], 0.22 * w, SKIN_RGB, "torso")
    pieces.append(Piece(mg.Ellipsoid([0.33 * w, 0.38 * w, 0.45 * w]), SKIN_RGB, homogeneous(r=[-w, 0.02 * L, 0.25 * L]), "torso"))
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


def urdf_bodies(robot) -> list[Body]:
    """Bodies from the URDF's ``<visual>`` elements (meshes resolved like the loader did)."""
    from lxml import etree

    from ..urdf_io import resolve_uri

    info = robot.info
    root = etree.fromstring(info.text.encode(), etree.XMLParser(resolve_entities=False, no_network=True,
                                                                load_dtd=False, remove_comments=True))
    named_colors = {}
    for m in root.findall("material"):
        c = m.find("color")
        if c is not None and m.get("name"):
            named_colors[m.get("name")] = _floats(c.get("rgba"), 4, (0.7, 0.7, 0.7, 1))
    model = robot.model
    bodies: list[Body] = []
    mesh_cache: dict[Path, object] = {}
    for link in root.findall("link"):
        name = link.get("name")
        visuals = link.findall("visual")
        if not visuals or not model.existFrame(name):
            continue
        fid = model.getFrameId(name)
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
                    raise MeshNotFoundError(info.path, f"link {name!r}: mesh {uri!r} resolved to {path}, which does not "
                                                       f"exist; pass package_dirs={{...}} to aa.load")
                scale = _floats(shape.get("scale"), 3, (1, 1, 1))
                if path not in mesh_cache:
                    mesh_cache[path] = load_mesh(path)
                geom = mesh_cache[path]
                offset = offset @ np.diag([*scale, 1.0])
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
            pieces.append(Piece(geom, tuple(rgba[:3]), offset, "mesh", float(rgba[3]) if len(rgba) > 3 else 1.0))
        if pieces:
            pj = model.frames[fid].parentJoint
            dof = model.joints[pj].idx_q if pj > 0 and model.joints[pj].nq == 1 else None
            bodies.append(Body(name, pieces, frame=fid, dof=dof, link_dofs=[dof] if dof is not None else []))
    return bodies


def load_mesh(path: Path):
    """A meshcat mesh geometry from an .stl / .dae / .obj file (others via trimesh -> STL)."""
    ext = path.suffix.lower()
    if ext == ".stl":
        return mg.StlMeshGeometry.from_file(str(path))
    if ext == ".dae":
        return mg.DaeMeshGeometry.from_file(str(path))
    if ext == ".obj":
        return mg.ObjMeshGeometry.from_file(str(path))
    import io

    import trimesh

    mesh = trimesh.load(str(path), force="mesh")
    buf = io.BytesIO(mesh.export(file_type="stl"))
    return mg.StlMeshGeometry.from_stream(buf)


def robot_bodies(robot, style: str = "auto") -> list[Body]:
    """Bodies for any Robot.  ``style``: "auto" (generated for book models, URDF visuals
    otherwise), "generated" or "urdf"."""
    if style not in ("auto", "generated", "urdf"):
        raise ValueError(f"style must be 'auto', 'generated' or 'urdf', got {style!r}")
    if style == "generated" or (style == "auto" and robot.spec is not None):
        return book_bodies(robot)
    bodies = urdf_bodies(robot)
    if not bodies:  # a URDF without visuals: fall back to the generated skeleton
        return book_bodies(robot)
    return bodies
