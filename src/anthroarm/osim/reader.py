"""Read an OpenSim 4.x ``<Model>`` element into plain descriptions: bodies, frames, joints as
six transform axes, coordinates, coordinate couplers and markers — and an import report row
for everything else.

Conventions reproduced from opensim-core (4.x):

* a joint's ``socket_parent_frame`` / ``socket_child_frame`` and a frame's ``socket_parent`` are
  component paths, absolute (``/bodyset/femur_r``) or relative to the component that owns the
  socket (``femur_r_offset`` inside a joint, ``..`` inside a body);
* a ``PhysicalOffsetFrame``'s ``orientation`` is body-fixed X-Y-Z Euler angles
  (``OffsetFrame.h``: ``setRotationToBodyFixedXYZ``);
* ``<inertia>`` is Ixx Iyy Izz Ixy Ixz Iyz about the centre of mass, in the body frame;
* every joint is written as a ``SpatialTransform`` of six axes (three rotations, three
  translations), each a function of its coordinates: a ``PinJoint`` rotates about Z, a
  ``SliderJoint`` translates along X, a ``UniversalJoint`` rotates about X then Y, a
  ``GimbalJoint`` about X, Y, Z, a ``PlanarJoint`` rotates about Z and translates along X, Y
  (the Simbody mobilizers OpenSim builds); a ``CustomJoint`` lists its axes.  A transform axis
  without a function gets OpenSim's default (``SpatialTransform::connectToJoint``): a
  ``LinearFunction`` (1, 0) of its one coordinate, or ``Constant`` 0.
* a ``CustomJoint``'s coordinates are in the order they first appear in its six axes
  (``SpatialTransform::getCoordinateNames``): the order of its mobilities.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import OsimError, OsimUnsupportedError
from . import functions as fn
from .report import DROPPED, KEPT, ImportReport
from .xmlread import Values

FUNCTION_TAGS = {
    "Constant",
    "LinearFunction",
    "SimmSpline",
    "NaturalCubicSpline",
    "PolynomialFunction",
    "MultiplierFunction",
    "PiecewiseLinearFunction",
}
#: OpenSim functions this import does not evaluate (a typed error names them)
OTHER_FUNCTIONS = {
    "GCVSpline",
    "Sine",
    "StepFunction",
    "PiecewiseConstantFunction",
    "MultivariatePolynomialFunction",
    "LinearFunction2",
    "FunctionThresholdCondition",
}
AXIS_NAMES = ("rotation1", "rotation2", "rotation3", "translation1", "translation2", "translation3")
E = np.eye(3)
#: joints other than CustomJoint: their axes (index in the six, unit axis) per coordinate
SIMPLE_JOINTS = {
    "PinJoint": [(2, E[2])],
    "SliderJoint": [(3, E[0])],
    "UniversalJoint": [(0, E[0]), (1, E[1])],
    "GimbalJoint": [(0, E[0]), (1, E[1]), (2, E[2])],
    "PlanarJoint": [(2, E[2]), (3, E[0]), (4, E[1])],
    "WeldJoint": [],
}
UNSUPPORTED_JOINTS = {
    "BallJoint": "a Simbody ball mobilizer (quaternions)",
    "FreeJoint": "a Simbody free mobilizer (quaternions)",
    "EllipsoidJoint": "a Simbody ellipsoid mobilizer",
    "ScapulothoracicJoint": "an ellipsoid-constrained scapula mobilizer",
    "ConstantCurvatureJoint": "a constant-curvature mobilizer",
}


@dataclass
class Body:
    name: str
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # 3x3 about the COM, body frame
    line: int | None


@dataclass
class FrameDef:
    path: str  # absolute component path
    name: str
    parent: str  # the socket's text
    owner: str  # the path relative references start from
    translation: np.ndarray
    orientation: np.ndarray  # body-fixed XYZ
    line: int | None


@dataclass
class Coordinate:
    name: str
    joint: str
    default: float
    lower: float
    upper: float
    locked: bool
    clamped: bool
    line: int | None
    dependent: bool = False


@dataclass
class Axis:
    name: str  # rotation1 ... translation3
    axis: np.ndarray  # unit
    coords: tuple  # coordinate names (0 or 1)
    function: fn.Function
    line: int | None

    @property
    def constant(self) -> bool:
        return self.function.constant or not self.coords


@dataclass
class JointDef:
    name: str
    type: str
    parent: str
    child: str
    coords: list  # Coordinate, in mobility order
    axes: list  # 6 Axis
    line: int | None


@dataclass
class Coupler:
    name: str
    dependent: str
    independent: str
    function: fn.Function
    scale: float
    line: int | None


@dataclass
class Marker:
    name: str
    parent: str
    location: np.ndarray
    line: int | None


@dataclass
class OsimModel:
    """What the import represents of an OpenSim model (read by :func:`read_model`)."""

    path: str
    name: str
    version: int
    gravity: np.ndarray
    credits: str
    publications: str
    bodies: dict = field(default_factory=dict)  # name -> Body
    frames: dict = field(default_factory=dict)  # path -> FrameDef
    joints: list = field(default_factory=list)  # JointDef
    couplers: list = field(default_factory=list)
    markers: list = field(default_factory=list)
    report: ImportReport | None = None
    ground: str = "ground"

    @property
    def coordinates(self) -> list:
        """Every coordinate, joint by joint in mobility order."""
        return [c for j in self.joints for c in j.coords]


def read_model(model_el, version: int, path) -> OsimModel:
    """The :class:`OsimModel` of a parsed ``<Model>`` element (OpenSim 4.x)."""
    v = Values(path)
    name = model_el.get("name") or "osim_model"
    m = OsimModel(
        path=str(path),
        name=name,
        version=version,
        gravity=v.floats(model_el, "gravity", "<Model>", 3, [0.0, -9.80665, 0.0]),
        credits=v.text(model_el, "credits", "") or "",
        publications=v.text(model_el, "publications", "") or "",
    )
    rep = m.report = ImportReport(str(path), name)
    units = (v.text(model_el, "length_units", "meters") or "meters").lower()
    if units not in ("meters", "m", "meter"):
        raise OsimUnsupportedError(
            path,
            f"length units {units!r}: the import reads models in meters (scale it in OpenSim)",
            "<length_units>",
            model_el.find("length_units").sourceline,
        )
    ground = model_el.find("Ground")
    m.bodies["ground"] = Body("ground", 0.0, np.zeros(3), np.zeros((3, 3)), None)
    gname = ground.get("name", "ground") if ground is not None else "ground"
    if gname != "ground":
        m.bodies[gname] = m.bodies.pop("ground")
        m.bodies[gname].name = gname
    m.ground = gname
    if ground is not None:
        _read_components(v, m, ground, f"/{gname}")
    _read_bodies(v, m, model_el)
    _read_joints(v, m, model_el)
    _read_constraints(v, m, model_el)
    _read_markers(v, m, model_el)
    _read_dropped_sets(m, model_el, rep)
    return m


# ---------------------------------------------------------------------------------------- bodies
def _inertia(v: Values, el, what: str) -> np.ndarray:
    i6 = v.floats(el, "inertia", what, 6, [0.0] * 6)
    xx, yy, zz, xy, xz, yz = i6
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    scale = max(1.0, float(np.abs(I).max()))
    w = np.linalg.eigvalsh(I)
    tol = 1e-12 * scale
    if w.min() < -tol:  # OpenSim models break the triangle inequality (planar toes): allowed
        raise v.error(
            el.find("inertia"),
            what,
            f"inertia {i6.tolist()} (Ixx Iyy Izz Ixy Ixz Iyz, kg m^2) is not positive "
            f"semi-definite (principal moments {np.round(w, 12).tolist()})",
        )
    return I


def _read_bodies(v: Values, m: OsimModel, model_el) -> None:
    bs = model_el.find("BodySet")
    if bs is None:
        return
    for el in _objects(bs):
        name = el.get("name")
        what = f"<{el.tag} name={name!r}>"
        if el.tag != "Body":
            raise v.error(el, what, f"a <{el.tag}> in the BodySet; only <Body> is known")
        if not name:
            raise v.error(el, f"<{el.tag}>", "a body without a name")
        if name in m.bodies:
            raise v.error(el, what, f"body {name!r} is defined twice")
        mass = v.scalar(el, "mass", what, 0.0)
        if mass < 0:
            raise v.error(el.find("mass"), what, f"negative mass {mass} kg")
        com = v.floats(el, "mass_center", what, 3, [0.0, 0.0, 0.0])
        m.bodies[name] = Body(name, mass, com, _inertia(v, el, what), el.sourceline)
        m.report.add(
            f"/bodyset/{name}", "Body", KEPT, "mass, centre of mass, inertia", el.sourceline
        )
        _read_components(v, m, el, f"/bodyset/{name}")


def _read_components(v: Values, m: OsimModel, el, owner: str) -> None:
    """Frames a body (or ground) owns in ``<components>``; wrap objects and geometry go to the
    report."""
    comps = el.find("components")
    if comps is not None:
        for c in comps:
            if c.tag == "PhysicalOffsetFrame":
                _read_frame(v, m, c, owner)
            else:
                m.report.add(
                    f"{owner}/{c.get('name', c.tag)}",
                    c.tag,
                    DROPPED,
                    "a component of a body the import does not represent",
                    c.sourceline,
                )
    wos = el.find("WrapObjectSet")
    if wos is not None:
        for w in _objects(wos):
            m.report.add(
                f"{owner}/wrapobjectset/{w.get('name')}",
                w.tag,
                DROPPED,
                "wrap surface of muscle paths (no muscles in the import yet)",
                w.sourceline,
            )
    geom = el.find("attached_geometry")
    if geom is not None and len(geom):
        m.report.add(
            f"{owner}/attached_geometry",
            "Geometry",
            DROPPED,
            "display meshes not loaded (.vtp files are not read)",
            geom.sourceline,
        )


def _read_frame(v: Values, m: OsimModel, el, owner: str) -> None:
    name = el.get("name")
    what = f"<PhysicalOffsetFrame name={name!r}>"
    if not name:
        raise v.error(el, "<PhysicalOffsetFrame>", "a frame without a name")
    parent = v.text(el, "socket_parent")
    if not parent:
        raise v.error(el, what, "<socket_parent> is missing: the frame hangs from nothing")
    path = f"{owner}/{name}"
    if path in m.frames:
        raise v.error(el, what, f"frame {path!r} is defined twice")
    m.frames[path] = FrameDef(
        path,
        name,
        parent,
        path,
        v.floats(el, "translation", what, 3, [0.0] * 3),
        v.floats(el, "orientation", what, 3, [0.0] * 3),
        el.sourceline,
    )
    m.report.add(path, "PhysicalOffsetFrame", KEPT, "an operational frame", el.sourceline)


# ---------------------------------------------------------------------------------------- joints
def _function(v: Values, el, what: str) -> fn.Function:
    """The function of an element that is one (``<SimmSpline>`` ...)."""
    tag = el.tag
    where = f"{what} <{tag}>"
    if tag == "Constant":
        return fn.Constant(v.scalar(el, "value", where, 0.0))
    if tag == "LinearFunction":
        c = v.floats(el, "coefficients", where, 2, [1.0, 0.0])
        return fn.Linear(float(c[0]), float(c[1]))
    if tag == "PolynomialFunction":
        c = v.floats(el, "coefficients", where, None, [1.0])
        return fn.Polynomial(tuple(float(a) for a in c))
    if tag in ("SimmSpline", "NaturalCubicSpline", "PiecewiseLinearFunction"):
        x = v.floats(el, "x", where)
        y = v.floats(el, "y", where)
        if x.size != y.size:
            raise v.error(el, where, f"{x.size} x values but {y.size} y values")
        if x.size < 2:
            raise v.error(el, where, f"{x.size} knot(s): a spline needs at least 2")
        if np.any(np.diff(x) <= 0):
            k = int(np.argmax(np.diff(x) <= 0))
            raise v.error(
                el,
                where,
                f"knots are not increasing: x[{k}] = {x[k]} >= x[{k + 1}] = {x[k + 1]}",
            )
        if tag == "PiecewiseLinearFunction":
            return fn.PiecewiseLinear(x, y)
        return fn.SimmSpline(x, y)
    if tag == "MultiplierFunction":
        inner = _child_function(v, el, where)
        if inner is None:
            raise v.error(el, where, "a MultiplierFunction without a <function>")
        return fn.Multiplier(v.scalar(el, "scale", where, 1.0), inner)
    if tag in OTHER_FUNCTIONS:
        raise v.error(
            el,
            where,
            f"function type {tag} is not evaluated by the import (known: "
            f"{', '.join(sorted(FUNCTION_TAGS))}); fit it with a SimmSpline in OpenSim",
            OsimUnsupportedError,
        )
    raise v.error(
        el, where, f"unknown function type <{tag}>; known: {', '.join(sorted(FUNCTION_TAGS))}"
    )


#: child elements of a transform axis / multiplier that are not its function
_STRUCTURAL = {"coordinates", "axis", "function", "scale", "is_rotation", "coordinate"}


def _child_function(v: Values, el, what: str):
    """The function held by ``el``: a child element that is a function (``<SimmSpline
    name="function">``), or a ``<function>`` wrapper holding one (both appear in 4.x files);
    None when there is none.  An unknown element raises, naming its type."""
    for c in el:
        if not isinstance(c.tag, str):
            continue
        if c.tag == "function":
            kids = [k for k in c if isinstance(k.tag, str)]
            if kids:
                return _function(v, kids[0], what)
            continue
        if c.tag in _STRUCTURAL:
            continue
        return _function(v, c, what)
    return None


def _coordinate(v: Values, el, joint: str) -> Coordinate:
    name = el.get("name")
    what = f"<Coordinate name={name!r}> of joint {joint!r}"
    if not name:
        raise v.error(el, f"<Coordinate> of joint {joint!r}", "a coordinate without a name")
    rng = v.floats(el, "range", what, 2, [-10.0, 10.0])
    if rng[0] > rng[1]:
        raise v.error(el.find("range"), what, f"range {rng.tolist()}: lower above upper")
    return Coordinate(
        name,
        joint,
        v.scalar(el, "default_value", what, 0.0),
        float(rng[0]),
        float(rng[1]),
        v.boolean(el, "locked", what),
        v.boolean(el, "clamped", what),
        el.sourceline,
    )


def _read_joints(v: Values, m: OsimModel, model_el) -> None:
    js = model_el.find("JointSet")
    if js is None:
        return
    seen_coords: dict[str, str] = {}
    for el in _objects(js):
        name = el.get("name")
        what = f"<{el.tag} name={name!r}>"
        if not name:
            raise v.error(el, f"<{el.tag}>", "a joint without a name")
        if el.tag in UNSUPPORTED_JOINTS:
            raise v.error(
                el,
                what,
                f"{el.tag} ({UNSUPPORTED_JOINTS[el.tag]}) is not imported; replace it by a "
                "CustomJoint with three rotation axes in OpenSim",
                OsimUnsupportedError,
            )
        if el.tag != "CustomJoint" and el.tag not in SIMPLE_JOINTS:
            raise v.error(
                el,
                what,
                f"unknown joint type <{el.tag}>; known: CustomJoint, {', '.join(SIMPLE_JOINTS)}",
            )
        jpath = f"/jointset/{name}"
        frames = el.find("frames")
        if frames is not None:
            for f in frames:
                if f.tag == "PhysicalOffsetFrame":
                    _read_frame(v, m, f, jpath)
        parent = v.text(el, "socket_parent_frame")
        child = v.text(el, "socket_child_frame")
        if not parent or not child:
            raise v.error(el, what, "<socket_parent_frame> and <socket_child_frame> are required")
        cel = el.find("coordinates")
        coords = [
            _coordinate(v, c, name)
            for c in (cel if cel is not None else [])
            if c.tag == "Coordinate"
        ]
        by_name = {c.name: c for c in coords}
        for c in coords:
            if c.name in seen_coords:
                raise v.error(
                    el,
                    what,
                    f"coordinate {c.name!r} is also a coordinate of {seen_coords[c.name]!r}",
                )
            seen_coords[c.name] = name
        if el.tag == "CustomJoint":
            axes = _custom_axes(v, el, what, by_name)
            order = []
            for a in axes:
                for c in a.coords:
                    if c not in order:
                        order.append(c)
            extra = [c.name for c in coords if c.name not in order]
            coords = [by_name[c] for c in order] + [by_name[c] for c in extra]
        else:
            spec = SIMPLE_JOINTS[el.tag]
            if len(coords) != len(spec):
                raise v.error(
                    el,
                    what,
                    f"a {el.tag} has {len(spec)} coordinate(s), the file gives {len(coords)}",
                )
            axes = [
                Axis(AXIS_NAMES[i], np.array(E[i % 3]), (), fn.Constant(0.0), el.sourceline)
                for i in range(6)
            ]
            for (i, ax), c in zip(spec, coords):
                axes[i] = Axis(
                    AXIS_NAMES[i], np.array(ax), (c.name,), fn.Linear(1.0, 0.0), el.sourceline
                )
        m.joints.append(JointDef(name, el.tag, parent, child, coords, axes, el.sourceline))
        m.report.add(jpath, el.tag, KEPT, f"{len(coords)} coordinate(s)", el.sourceline)
        for c in coords:
            note = "; clamped (flag kept: robot.osim_coordinates)" if c.clamped else ""
            if c.locked:
                note += f"; locked at its default {c.default:g} (not in q, as OpenSim holds it)"
            m.report.add(f"{jpath}/{c.name}", "Coordinate", KEPT, "range, default" + note, c.line)


def _custom_axes(v: Values, el, what: str, coords: dict) -> list:
    st = el.find("SpatialTransform")
    if st is None:
        raise v.error(el, what, "a CustomJoint without a <SpatialTransform>")
    found = {}
    for ta in st.findall("TransformAxis"):
        an = ta.get("name")
        if an not in AXIS_NAMES:
            raise v.error(
                ta, what, f"<TransformAxis name={an!r}>; names are {', '.join(AXIS_NAMES)}"
            )
        if an in found:
            raise v.error(ta, what, f"TransformAxis {an!r} given twice")
        awhat = f"{what} <TransformAxis name={an!r}>"
        axis = v.floats(ta, "axis", awhat, 3)
        nrm = float(np.linalg.norm(axis))
        if nrm < 1e-12:
            raise v.error(ta, awhat, f"axis {axis.tolist()} has zero length")
        names = tuple((v.text(ta, "coordinates", "") or "").split())
        for c in names:
            if c not in coords:
                raise v.error(
                    ta,
                    awhat,
                    f"is a function of coordinate {c!r}, which is not a coordinate of this joint "
                    f"({', '.join(coords) or 'none'})",
                )
        f = _child_function(v, ta, awhat)
        if f is None:
            if len(names) > 1:
                raise v.error(ta, awhat, "several coordinates and no function")
            f = fn.Linear(1.0, 0.0) if names else fn.Constant(0.0)
        if len(names) > 1 and not f.constant:
            raise v.error(
                ta,
                awhat,
                f"a function of {len(names)} coordinates ({', '.join(names)}): the import takes "
                "functions of one coordinate",
                OsimUnsupportedError,
            )
        if not names and not f.constant:
            raise v.error(ta, awhat, f"a {f.kind} of no coordinate: give <coordinates>")
        found[an] = Axis(an, axis / nrm, names, f, ta.sourceline)
    axes = []
    for i, an in enumerate(AXIS_NAMES):
        axes.append(
            found.get(an) or Axis(an, np.array(E[i % 3]), (), fn.Constant(0.0), st.sourceline)
        )
    for lo in (0, 3):  # CustomJoint::extendFinalizeFromProperties
        a = [axes[lo + i].axis for i in range(3)]
        for i, j in ((0, 1), (0, 2), (1, 2)):
            if np.linalg.norm(np.cross(a[i], a[j])) < 1e-5:
                raise v.error(
                    st,
                    what,
                    f"axes {AXIS_NAMES[lo + i]} and {AXIS_NAMES[lo + j]} are collinear "
                    "(OpenSim refuses this joint too)",
                )
    return axes


# ---------------------------------------------------------------------------------------- rest
def _read_constraints(v: Values, m: OsimModel, model_el) -> None:
    cs = model_el.find("ConstraintSet")
    if cs is None:
        return
    for el in _objects(cs):
        name = el.get("name") or el.tag
        what = f"<{el.tag} name={name!r}>"
        enforced = (
            v.boolean(el, "isEnforced", what, True) if el.find("isEnforced") is not None else True
        )
        if el.tag != "CoordinateCouplerConstraint":
            m.report.add(
                f"/constraintset/{name}",
                el.tag,
                DROPPED,
                "only CoordinateCouplerConstraints are represented",
                el.sourceline,
            )
            continue
        if not enforced:
            m.report.add(
                f"/constraintset/{name}",
                el.tag,
                DROPPED,
                "not enforced (isEnforced false)",
                el.sourceline,
            )
            continue
        ind = (v.text(el, "independent_coordinate_names", "") or "").split()
        dep = v.text(el, "dependent_coordinate_name", "") or ""
        if len(ind) != 1 or not dep:
            raise v.error(
                el,
                what,
                f"independent coordinates {ind} and dependent {dep!r}: the import takes one "
                "independent and one dependent coordinate",
                OsimUnsupportedError if len(ind) > 1 else OsimError,
            )
        wrap = el.find("coupled_coordinates_function")
        f = _child_function(v, wrap, what) if wrap is not None else None
        if f is None:
            raise v.error(el, what, "<coupled_coordinates_function> is missing")
        scale = v.scalar(el, "scale_factor", what, 1.0)
        m.couplers.append(Coupler(name, dep, ind[0], f, scale, el.sourceline))
        m.report.add(
            f"/constraintset/{name}",
            el.tag,
            KEPT,
            f"{dep} = {scale:g} * {f.kind}({ind[0]}) in the coupling map",
            el.sourceline,
        )


def _read_markers(v: Values, m: OsimModel, model_el) -> None:
    ms = model_el.find("MarkerSet")
    if ms is None:
        return
    seen = set()
    for el in _objects(ms):
        name = el.get("name")
        what = f"<Marker name={name!r}>"
        if not name:
            raise v.error(el, "<Marker>", "a marker without a name")
        if name in seen:
            raise v.error(el, what, f"marker {name!r} is defined twice")
        seen.add(name)
        parent = v.text(el, "socket_parent_frame") or v.text(el, "body")
        if not parent:
            raise v.error(el, what, "<socket_parent_frame> is missing")
        m.markers.append(
            Marker(name, parent, v.floats(el, "location", what, 3, [0.0] * 3), el.sourceline)
        )
        m.report.add(
            f"/markerset/{name}", "Marker", KEPT, "a frame named after the marker", el.sourceline
        )


_WHY = {
    "ForceSet": "forces (muscles and their paths, actuators, springs, contact) are not simulated",
    "ControllerSet": "controllers are not imported",
    "ProbeSet": "probes are not imported",
    "ContactGeometrySet": "contact geometry is not imported",
    "ComponentSet": "extra components are not imported",
}


def _read_dropped_sets(m: OsimModel, model_el, rep: ImportReport) -> None:
    for tag, why in _WHY.items():
        s = model_el.find(tag)
        if s is None:
            continue
        for el in _objects(s):
            name = el.get("name") or el.tag
            rep.add(f"/{tag.lower()}/{name}", el.tag, DROPPED, why, el.sourceline)


def _objects(set_el):
    """The elements of an OpenSim ``Set`` (its ``<objects>``), comments left out."""
    objs = set_el.find("objects")
    return [e for e in (objs if objs is not None else []) if isinstance(e.tag, str)]
