"""OpenSim's inverse-kinematics setup files (``Setup_IK.xml``) and the marker set they define.

An OpenSim IK setup (``<InverseKinematicsTool>``, opensim-core
``OpenSim/Tools/InverseKinematicsTool.cpp``; Delp et al. 2007, IEEE TBME 54(11), 1940–1950)
names the model and the marker file, the time range, the accuracy, and an ``<IKTaskSet>``:

* ``<IKMarkerTask name="R.ASIS">`` with ``<apply>`` and ``<weight>``: the marker's w_k in the
  objective Σ w_k ‖p_k(q) − m_k‖²; a marker with ``apply`` false is not tracked (OpenSim's
  ``MarkersReference`` tracks only the markers of its weight set);
* ``<IKCoordinateTask name="mtp_angle_r">`` with ``<weight>``, ``<value_type>``
  (``default_value``, ``manual_value``, ``from_file``) and ``<value>``: a term
  w_j (q_j − q_j⁰)² that holds a coordinate near a value.

:func:`read_ik_setup` reads it into an :class:`IKSetup` (relative file names resolved against
the setup's folder).  :func:`osim_marker_set` makes the :class:`~anthroarm.motion.markers.MarkerSet`
of a model loaded from an ``.osim`` file (``aa.load("model.osim")``: every OpenSim marker is a
frame named after the marker), weighted as the setup says; :func:`coordinate_targets` gives the
coordinate tasks' joints, weights and values, which :class:`~anthroarm.motion.marker_ik.MarkerIK`
takes as ``coordinate_tasks``.

The XML is read as the URDF reader reads it: DTD and entity declarations refused, no network,
at most :data:`MAX_SETUP_BYTES`.  Bad input is a :class:`~anthroarm.errors.MotionDataError`
naming the file and the line of the element: malformed XML, no ``<InverseKinematicsTool>``, a
weight that is not a finite number ≥ 0, ``apply`` other than true/false, an unknown
``value_type``, a time range that is not two increasing numbers.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import parse_xml, read_bounded
from ..errors import MarkerSetError, MotionDataError, UnknownFrameError
from .markers import Marker, MarkerSet

#: the largest setup file :func:`read_ik_setup` reads, bytes (4 MiB)
MAX_SETUP_BYTES = 4 << 20
VALUE_TYPES = ("default_value", "manual_value", "from_file")


@dataclass(frozen=True)
class CoordinateTask:
    """One ``<IKCoordinateTask>``: ``weight`` w_j, ``value_type`` and ``value`` (the
    coordinate's unit: rad, or m for a translation; OpenSim's setup files give it in the
    coordinate's internal unit)."""

    name: str
    weight: float
    value_type: str = "default_value"
    value: float = 0.0


@dataclass
class IKSetup:
    """An OpenSim IK setup.

    Attributes
    ----------
    name : str
    model_file, marker_file, coordinate_file, output_motion_file : Path or None
        Resolved against the setup's folder (None when empty).
    time_range : (2,) array or None
        s.
    accuracy : float or None
    constraint_weight : float or None
        ``inf`` for "Infinity" or unset.
    marker_weights : dict
        Marker name -> weight, the markers with ``apply`` true, in the file's order.
    disabled_markers : tuple of str
        Markers with ``apply`` false.
    coordinate_tasks : dict
        Coordinate name -> :class:`CoordinateTask`, those with ``apply`` true.
    source : str
    """

    name: str = ""
    model_file: Path | None = None
    marker_file: Path | None = None
    coordinate_file: Path | None = None
    output_motion_file: Path | None = None
    time_range: np.ndarray | None = None
    accuracy: float | None = None
    constraint_weight: float | None = None
    marker_weights: dict = field(default_factory=dict)
    disabled_markers: tuple = ()
    coordinate_tasks: dict = field(default_factory=dict)
    source: str = ""


def _text(el, tag: str) -> str | None:
    c = el.find(tag)
    return None if c is None or c.text is None else c.text.strip()


def _float(p, el, tag: str, *, low: float | None = None, default=None) -> float | None:
    t = _text(el, tag)
    if t is None or t == "":
        return default
    line = (el.find(tag).sourceline) or el.sourceline
    if t.lower() in ("infinity", "inf"):
        v = math.inf
    else:
        try:
            v = float(t)
        except ValueError:
            raise MotionDataError(
                f"line {line}: <{tag}> of <{el.tag} name={el.get('name')!r}> is {t!r}, not a "
                "number",
                p,
            ) from None
    if math.isnan(v) or (low is not None and not (v >= low and math.isfinite(v))):
        raise MotionDataError(
            f"line {line}: <{tag}> of <{el.tag} name={el.get('name')!r}> is {t!r}: give a "
            f"finite number >= {low:g}",
            p,
        )
    return v


def _apply(p, el) -> bool:
    t = _text(el, "apply")
    if t is None:
        return True
    if t.lower() not in ("true", "false"):
        raise MotionDataError(
            f"line {el.find('apply').sourceline}: <apply> of {el.get('name')!r} is {t!r}: "
            "true or false",
            p,
        )
    return t.lower() == "true"


def read_ik_setup(path) -> IKSetup:
    """The :class:`IKSetup` of an OpenSim ``Setup_IK.xml``.

    Raises
    ------
    MotionDataError
        As listed in the module docstring, naming the file and the line.

    References
    ----------
    OpenSim ``InverseKinematicsTool``, ``IKMarkerTask``, ``IKCoordinateTask`` (opensim-core,
    ``OpenSim/Tools/``): the properties read here.
    """
    if not isinstance(path, (str, os.PathLike)) or path == "":
        raise MotionDataError(f"read_ik_setup: path must be a file path, got {type(path).__name__}")
    p = Path(path)
    raw = read_bounded(
        p,
        MAX_SETUP_BYTES,
        what="IK setup file",
        encoding=None,
        error=lambda problem: MotionDataError(problem, p),
    )
    root = parse_xml(
        raw, lambda problem, line: MotionDataError(f"line {line}: {problem}", p), "a setup file"
    )
    tool = root if root.tag == "InverseKinematicsTool" else root.find("InverseKinematicsTool")
    if tool is None:
        raise MotionDataError(
            f"line {root.sourceline}: no <InverseKinematicsTool> in <{root.tag}>: not an "
            "OpenSim IK setup",
            p,
        )

    def file_of(tag):
        t = _text(tool, tag)
        return None if not t or t.lower() == "unassigned" else (p.parent / t)

    tr = _text(tool, "time_range")
    time_range = None
    if tr:
        try:
            time_range = np.array([float(x) for x in tr.split()])
        except ValueError:
            time_range = None
        if (
            time_range is None
            or time_range.shape != (2,)
            or not (np.isfinite(time_range).all() and time_range[0] <= time_range[1])
        ):
            raise MotionDataError(
                f"line {tool.find('time_range').sourceline}: <time_range> is {tr!r}: give two "
                "increasing times (s)",
                p,
            )
    weights, disabled, coords = {}, [], {}
    taskset = tool.find("IKTaskSet")
    for el in [] if taskset is None else taskset.iter("IKMarkerTask", "IKCoordinateTask"):
        name = el.get("name")
        if not name:
            raise MotionDataError(f"line {el.sourceline}: <{el.tag}> without a name", p)
        on = _apply(p, el)
        w = _float(p, el, "weight", low=0.0, default=1.0)
        if el.tag == "IKMarkerTask":
            if name in weights or name in disabled:
                raise MotionDataError(f"line {el.sourceline}: marker task {name!r} twice", p)
            if on:
                weights[name] = w
            else:
                disabled.append(name)
            continue
        vt = _text(el, "value_type") or "default_value"
        if vt not in VALUE_TYPES:
            raise MotionDataError(
                f"line {el.find('value_type').sourceline}: <value_type> of {name!r} is {vt!r}; "
                f"known: {', '.join(VALUE_TYPES)}",
                p,
            )
        value = _float(p, el, "value", default=0.0)
        if not math.isfinite(value):
            raise MotionDataError(f"line {el.sourceline}: <value> of {name!r} must be finite", p)
        if on:
            coords[name] = CoordinateTask(name, w, vt, value)
    return IKSetup(
        name=tool.get("name") or "",
        model_file=file_of("model_file"),
        marker_file=file_of("marker_file"),
        coordinate_file=file_of("coordinate_file"),
        output_motion_file=file_of("output_motion_file"),
        time_range=time_range,
        accuracy=_float(p, tool, "accuracy", low=0.0),
        constraint_weight=_float(p, tool, "constraint_weight", low=0.0, default=math.inf),
        marker_weights=weights,
        disabled_markers=tuple(disabled),
        coordinate_tasks=coords,
        source=str(p),
    )


def osim_marker_set(robot, setup: IKSetup | dict | None = None, *, name: str = "") -> MarkerSet:
    """The marker set of a model imported from OpenSim, weighted by an IK setup.

    Every OpenSim marker is a frame of ``robot`` named after the marker (the ``.osim``
    import's convention), so a marker here is that frame's origin.  With ``setup`` (an
    :class:`IKSetup` or a dict marker -> weight) the set holds its tracked markers that are
    frames of ``robot`` — the markers OpenSim's IK tool tracks: a task marker the model lacks
    is left out, as OpenSim leaves it out — with their weights.  Without, ``setup`` is every
    frame whose name is in ``robot.osim_markers`` (weight 1).

    Raises
    ------
    MarkerSetError
        No marker of the setup is a frame of ``robot`` (the message lists some frames), or no
        setup and the robot does not list its markers.
    """
    chain = robot.chain
    if setup is None:
        names = getattr(robot, "osim_markers", None)
        if not names:
            raise MarkerSetError(
                f"{robot.name} lists no OpenSim markers: give setup= (an IKSetup or a dict "
                "marker -> weight)"
            )
        weights = {n: 1.0 for n in names}
    else:
        weights = setup.marker_weights if isinstance(setup, IKSetup) else dict(setup)
    out = []
    for n, w in weights.items():
        try:
            chain.frame(n)
        except UnknownFrameError:
            continue
        out.append(Marker(n, n, (0.0, 0.0, 0.0), float(w)))
    if not out:
        frames = [f.name for f in chain.frames][:12]
        raise MarkerSetError(
            f"none of the markers {list(weights)[:12]} is a frame of {robot.name} "
            f"(frames: {', '.join(frames)} ...): is this the model the setup was made for?"
        )
    label = name or (setup.name if isinstance(setup, IKSetup) and setup.name else "osim_markers")
    return MarkerSet(out, name=label)


def coordinate_targets(robot, setup: IKSetup, default_q=None) -> dict:
    """The setup's coordinate tasks on ``robot``: joint name -> (weight, value) in the joint's
    unit.  A ``default_value`` task takes the value of ``default_q`` (a (nq,) configuration,
    the model's default coordinates; the joint's value at ``robot.neutral()`` when None), a
    ``manual_value`` task its ``<value>``.  A task on a coordinate that is not a joint of
    ``robot`` (a locked or dependent coordinate) is left out; ``from_file`` is a
    :class:`~anthroarm.errors.MotionDataError` (the coordinate file is not read)."""
    chain = robot.chain
    q = robot.neutral() if default_q is None else robot.check_q(default_q, name="default_q")
    out = {}
    for name, task in setup.coordinate_tasks.items():
        try:
            j = chain.joint(name)
        except (UnknownFrameError, KeyError):
            continue
        if j.is_mimic or j.nq != 1:
            continue
        if task.value_type == "from_file":
            raise MotionDataError(
                f"coordinate task {name!r} takes its value from a coordinate file, which "
                "anthroarm's marker IK does not read: use default_value or manual_value",
                setup.source or None,
            )
        value = q[j.idx_q] if task.value_type == "default_value" else task.value
        out[name] = (task.weight, float(value))
    return out
