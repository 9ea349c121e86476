"""The muscles of an OpenSim ``.osim`` file: their ``GeometryPath`` (path points, wrap
references) and their Hill-type parameters, read from the model's ``ForceSet``.

The file is parsed by :func:`anthroarm.osim.xmlread.parse` (bounded read, DTD / entity
declarations refused, no network), the same safe reading as the model import.  Conventions
reproduced from opensim-core 4.x (``OpenSim/Simulation/Model``):

* ``PathPoint``: a ``location`` fixed in the frame its ``socket_parent_frame`` names;
* ``ConditionalPathPoint``: a path point that is part of the path only while its
  ``socket_coordinate`` lies in ``range`` (``ConditionalPathPoint::isActive``:
  ``range[0] <= value <= range[1]``);
* ``MovingPathPoint``: a location whose x, y and z are functions (``x_location`` ...) of the
  coordinates ``socket_x_coordinate`` ... (``MovingPathPoint::getLocation``);
* ``PathWrap``: a wrap object (a ``WrapCylinder``, ``WrapSphere``, ``WrapEllipsoid`` of a
  body's ``WrapObjectSet``) and the range of path points it acts between.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import MuscleError, OsimError, OsimUnsupportedError
from ..osim import functions as fn
from ..osim.build import body_fixed_xyz
from ..osim.xmlread import Values, parse
from .millard import CURVE_DEFAULTS, MILLARD_DEFAULTS

#: the muscle classes read (others in the ForceSet are skipped and listed in ``skipped``)
MUSCLE_TAGS = ("Thelen2003Muscle", "Millard2012EquilibriumMuscle")
#: the wrap surfaces read
WRAP_TAGS = ("WrapCylinder", "WrapSphere", "WrapEllipsoid", "WrapTorus")

#: the Thelen (2003) parameters with OpenSim 4's defaults (``Thelen2003Muscle.cpp``)
THELEN_DEFAULTS = {
    "FmaxTendonStrain": 0.04,
    "FmaxMuscleStrain": 0.6,
    "KshapeActive": 0.45,
    "KshapePassive": 5.0,
    "Af": 0.25,
    "Flen": 1.4,
    "fv_linear_extrap_threshold": 0.95,
    "maximum_pennation_angle": float(np.arccos(0.1)),
    "activation_time_constant": 0.015,
    "deactivation_time_constant": 0.05,
    "minimum_activation": 0.01,
}


@dataclass(frozen=True, eq=False)
class PathPoint:
    """One point of a muscle path.

    ``kind`` is ``"fixed"``, ``"conditional"`` (active while ``coordinate`` is in ``range``)
    or ``"moving"`` (``functions[k]`` of ``coordinates[k]`` gives location[k])."""

    name: str
    frame: str
    location: np.ndarray
    kind: str = "fixed"
    coordinate: str | None = None
    range: tuple = (-np.inf, np.inf)
    functions: tuple = ()
    coordinates: tuple = ()


@dataclass(frozen=True, eq=False)
class WrapObject:
    """A wrap surface fixed in ``frame``: ``rotation`` (body-fixed XYZ) and ``translation``
    place it; ``quadrant`` (``"all"``, ``"+x"``, ``"-y"`` ...) restricts the side the path may
    wrap on; ``radius`` / ``length`` (cylinder, sphere) or ``dimensions`` (ellipsoid radii)."""

    name: str
    kind: str
    frame: str
    translation: np.ndarray
    rotation: np.ndarray  # 3x3, wrap frame in the body frame
    quadrant: str
    active: bool
    radius: float = 0.0
    length: float = 0.0
    dimensions: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class PathWrap:
    """A path's use of a wrap object between path points ``range`` (1-based, -1: the ends)."""

    wrap: str
    method: str
    range: tuple


@dataclass(eq=False)
class Muscle:
    """A Hill-type muscle read from the ForceSet (lengths in m, forces in N, angles in rad,
    velocities in optimal fibre lengths per second)."""

    name: str
    type: str
    max_isometric_force: float
    optimal_fiber_length: float
    tendon_slack_length: float
    pennation_angle_at_optimal: float
    max_contraction_velocity: float
    points: list
    wraps: list
    ignore_tendon_compliance: bool = False
    params: dict = field(default_factory=dict)
    line: int | None = None


@dataclass(eq=False)
class MuscleSet:
    """The muscles of a model (``muscles``, in ForceSet order) and its wrap objects
    (``wrap_objects``: name -> :class:`WrapObject`); ``skipped``: forces that are not muscles
    read here (name, type)."""

    path: str
    muscles: list
    wrap_objects: dict
    skipped: list

    @property
    def names(self) -> list[str]:
        return [m.name for m in self.muscles]

    def __len__(self) -> int:
        return len(self.muscles)

    def __getitem__(self, name: str) -> Muscle:
        for m in self.muscles:
            if m.name == name:
                return m
        raise KeyError(name)

    def select(self, names) -> MuscleSet:
        """The same set restricted to ``names`` (in that order)."""
        return MuscleSet(self.path, [self[n] for n in names], self.wrap_objects, self.skipped)


def read_muscles(path) -> MuscleSet:
    """The muscles of the OpenSim 4.x model ``path`` (see the module docstring).

    Raises :class:`~anthroarm.errors.OsimError` (element and line named) for a malformed path,
    :class:`~anthroarm.errors.MuscleError` for a muscle with a non-positive optimal fibre
    length or maximum isometric force."""
    model_el, _ = parse(path)
    v = Values(path)
    wraps = {}
    for owner in [model_el.find("Ground"), *_objects(model_el.find("BodySet"))]:
        if owner is None:
            continue
        frame = owner.get("name") or "ground"
        ws = owner.find("WrapObjectSet")
        for w in _objects(ws):
            if w.tag in WRAP_TAGS:
                wraps[w.get("name")] = _wrap_object(v, w, frame)
    muscles, skipped = [], []
    for el in _objects(model_el.find("ForceSet")):
        if el.tag not in MUSCLE_TAGS:
            skipped.append((el.get("name"), el.tag))
            continue
        muscles.append(_muscle(v, el, path))
    for m in muscles:
        for pw in m.wraps:
            if pw.wrap not in wraps:
                raise OsimError(path, f"muscle {m.name!r} wraps over unknown {pw.wrap!r}")
    return MuscleSet(str(path), muscles, wraps, skipped)


def _objects(set_el):
    if set_el is None:
        return []
    objs = set_el.find("objects")
    return [c for c in (objs if objs is not None else []) if isinstance(c.tag, str)]


def _last(socket: str | None) -> str:
    return (socket or "").rstrip("/").split("/")[-1]


def _wrap_object(v: Values, el, frame: str) -> WrapObject:
    name = el.get("name")
    what = f"<{el.tag} name={name!r}>"
    rot = v.floats(el, "xyz_body_rotation", what, 3, [0.0, 0.0, 0.0])
    kw = {}
    if el.tag in ("WrapCylinder", "WrapSphere", "WrapTorus"):
        kw["radius"] = v.scalar(el, "radius", what, 0.05)
        if kw["radius"] <= 0:
            raise v.error(el, what, f"radius {kw['radius']} m is not positive")
    if el.tag == "WrapCylinder":
        kw["length"] = v.scalar(el, "length", what, 1.0)
    if el.tag == "WrapEllipsoid":
        kw["dimensions"] = v.floats(el, "dimensions", what, 3, [0.05] * 3)
    quadrant = (v.text(el, "quadrant", "all") or "all").strip()
    return WrapObject(
        name,
        el.tag,
        frame,
        v.floats(el, "translation", what, 3, [0.0, 0.0, 0.0]),
        body_fixed_xyz(rot),
        quadrant,
        v.boolean(el, "active", what, True),
        **kw,
    )


def _function(v: Values, el, what: str):
    """An OpenSim function element (the classes of :mod:`anthroarm.osim.functions`)."""
    kids = [c for c in el if isinstance(c.tag, str)]
    if el.tag in ("x_location", "y_location", "z_location", "function"):
        if not kids:
            raise v.error(el, what, f"<{el.tag}> holds no function")
        return _function(v, kids[0], what)
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
        x, y = v.floats(el, "x", where), v.floats(el, "y", where)
        if x.size != y.size or x.size < 2 or np.any(np.diff(x) <= 0):
            raise v.error(el, where, "a spline needs >= 2 increasing x values, as many y values")
        return fn.PiecewiseLinear(x, y) if tag == "PiecewiseLinearFunction" else fn.SimmSpline(x, y)
    if tag == "MultiplierFunction":
        inner = [c for c in kids if c.tag not in ("scale",)]
        if not inner:
            raise v.error(el, where, "a MultiplierFunction without a function")
        return fn.Multiplier(v.scalar(el, "scale", where, 1.0), _function(v, inner[0], where))
    raise v.error(el, where, f"function type <{tag}> is not evaluated", OsimUnsupportedError)


def _point(v: Values, el, muscle: str) -> PathPoint:
    name = el.get("name")
    what = f"<{el.tag} name={name!r}> of muscle {muscle!r}"
    frame = _last(v.text(el, "socket_parent_frame"))
    if not frame:
        raise v.error(el, what, "no <socket_parent_frame>")
    if el.tag == "PathPoint":
        return PathPoint(name, frame, v.floats(el, "location", what, 3))
    if el.tag == "ConditionalPathPoint":
        rng = v.floats(el, "range", what, 2)
        coord = _last(v.text(el, "socket_coordinate"))
        if not coord:
            raise v.error(el, what, "no <socket_coordinate>")
        loc = v.floats(el, "location", what, 3)
        return PathPoint(name, frame, loc, "conditional", coord, (float(rng[0]), float(rng[1])))
    if el.tag == "MovingPathPoint":
        funcs, coords = [], []
        for ax in "xyz":
            f_el = el.find(f"{ax}_location")
            if f_el is None:
                funcs.append(fn.Constant(0.0))
                coords.append(None)
                continue
            funcs.append(_function(v, f_el, what))
            coords.append(_last(v.text(el, f"socket_{ax}_coordinate")) or None)
        return PathPoint(
            name, frame, np.zeros(3), "moving", functions=tuple(funcs), coordinates=tuple(coords)
        )
    raise v.error(el, what, f"path point type <{el.tag}> is not read", OsimUnsupportedError)


def _millard_params(v: Values, el, what: str) -> dict:
    """A Millard2012 muscle's properties and its curves' (``"<Curve>.<property>"``); an
    optional curve property left out stays out (the curve fills it in, as OpenSim's)."""
    params = {k: v.scalar(el, k, what, d) for k, d in MILLARD_DEFAULTS.items()}
    for curve, props in CURVE_DEFAULTS.items():
        c_el = el.find(curve)
        for k, d in props.items():
            if c_el is not None and (v.text(c_el, k) or "") != "":
                params[f"{curve}.{k}"] = v.scalar(c_el, k, f"{what} <{curve}>")
            elif d is not None:
                params[f"{curve}.{k}"] = d
    return params


_CORE = {
    "max_isometric_force": None,
    "optimal_fiber_length": None,
    "tendon_slack_length": None,
    "pennation_angle_at_optimal": 0.0,
    "max_contraction_velocity": 10.0,
}


def _muscle(v: Values, el, path) -> Muscle:
    name = el.get("name")
    what = f"<{el.tag} name={name!r}>"
    gp = el.find("GeometryPath")
    if gp is None:
        raise v.error(el, what, "no <GeometryPath>")
    points = [_point(v, p, name) for p in _objects(gp.find("PathPointSet"))]
    if len(points) < 2:
        raise v.error(gp, what, f"{len(points)} path point(s): a path needs at least 2")
    wraps = []
    for w in _objects(gp.find("PathWrapSet")):
        rng = v.floats(w, "range", what, 2, [-1.0, -1.0])
        wraps.append(
            PathWrap(v.text(w, "wrap_object", "") or "", v.text(w, "method", "hybrid") or "hybrid",
                     (int(rng[0]), int(rng[1])))
        )  # fmt: skip
    core = {k: v.scalar(el, k, what, d) for k, d in _CORE.items()}
    if not core["optimal_fiber_length"] > 0:
        raise MuscleError(
            f"{path}: {what} (line {el.sourceline}): optimal_fiber_length "
            f"{core['optimal_fiber_length']} m is not positive"
        )
    if not core["max_isometric_force"] > 0:
        raise MuscleError(
            f"{path}: {what} (line {el.sourceline}): max_isometric_force "
            f"{core['max_isometric_force']} N is not positive"
        )
    params = {}
    if el.tag == "Thelen2003Muscle":
        params = {k: v.scalar(el, k, what, d) for k, d in THELEN_DEFAULTS.items()}
    if el.tag == "Millard2012EquilibriumMuscle":
        params = _millard_params(v, el, what)
    return Muscle(
        name,
        el.tag,
        points=points,
        wraps=wraps,
        ignore_tendon_compliance=v.boolean(el, "ignore_tendon_compliance", what, False),
        params=params,
        line=el.sourceline,
        **core,
    )
