"""Marker sets: which skin marker sits where on which body of a robot.

A :class:`Marker` is a point fixed in a body frame of the robot (any frame of ``robot.chain``:
a link, a joint frame, the tool), given by its position in that frame (m).  A
:class:`MarkerSet` is an ordered list of markers with unique names and weights (the w_i of the
marker IK residual Σ w_i ‖p_i(q) − m_i‖², see :mod:`anthroarm.motion.marker_ik`).

:func:`human_arm_markers` is the default set of a person's arm model
(:mod:`anthroarm.models.human`, bodies ``upper_arm``, ``forearm``, ``hand``): ten markers at the
ISB landmarks (Wu et al. 2005, J. Biomech. 38(5), 981–992), 9 on moving bodies.  The table is
model knowledge and lives with the model (:data:`anthroarm.models.human.HUMAN_ARM_LANDMARKS`:
link, position as fractions of the link's segment length, weight); this module scales it to the
robot's segment lengths read from ``robot.chain`` (:func:`segment_length`) and checks that the
links exist as frames.  A lab with its own protocol supplies its own set
(:meth:`MarkerSet.from_dict`, :meth:`MarkerSet.read_json`: a regular file of at most
:data:`MAX_MARKER_SET_BYTES`, nested at most :data:`MAX_MARKER_SET_DEPTH` deep).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from .._io import atomic_write_text, load_json_bounded
from ..errors import MarkerSetError, UnconstrainedJointError, UnknownFrameError
from ..ik.qp.tasks.marker import moved_by
from ..ik.qp.tasks.posture import comfortable_posture
from ..models.human import HUMAN_ARM_LANDMARKS, HUMAN_ARM_TRUNK_SCALE_LINK

#: the largest marker-set JSON file :meth:`MarkerSet.read_json` reads, bytes (1 MiB: thousands
#: of markers); a larger file is a MarkerSetError naming the bound
MAX_MARKER_SET_BYTES = 1 << 20
#: the deepest nesting of arrays/objects a marker-set JSON file may have (a set needs 4); checked
#: before parsing, so a deeply nested file is a MarkerSetError, not a RecursionError
MAX_MARKER_SET_DEPTH = 16


@dataclass(frozen=True)
class Marker:
    """One marker: ``name``, the robot frame it is fixed to (``body``), its ``position`` (3,)
    in that frame (m) and its weight ``weight`` (≥ 0, the w_i of Σ w_i ‖p_i − m_i‖²)."""

    name: str
    body: str
    position: tuple
    weight: float = 1.0


class MarkerSet:
    """An ordered set of markers with unique names.

    Parameters
    ----------
    markers : iterable of :class:`Marker`
    name : str
        A label (shown in reports).

    Raises
    ------
    MarkerSetError
        Empty set, duplicate names, a body that is not a frame name (a non-empty str: a
        ``null`` body would otherwise mean the tool), a position that is not 3 finite numbers,
        a negative or non-finite weight.
    """

    def __init__(self, markers, name: str = "markers"):
        self.markers = tuple(markers)
        self.name = str(name)
        if not self.markers:
            raise MarkerSetError(f"marker set {self.name!r} is empty")
        seen = set()
        for m in self.markers:
            if not isinstance(m, Marker):
                raise MarkerSetError(
                    f"marker set {self.name!r}: entries must be Marker objects, got {m!r}"
                )
            if not isinstance(m.name, str) or not m.name:
                raise MarkerSetError(
                    f"marker set {self.name!r}: a marker name must be a non-empty str, got "
                    f"{m.name!r}"
                )
            if m.name in seen:
                raise MarkerSetError(f"marker set {self.name!r}: duplicate marker name {m.name!r}")
            if not isinstance(m.body, str) or not m.body.strip():
                raise MarkerSetError(
                    f"marker {m.name!r}: body must be the name of a frame of the robot (a "
                    f"non-empty str), got {m.body!r}"
                )
            seen.add(m.name)
            p = np.asarray(m.position, dtype=float) if _numeric(m.position) else None
            if p is None or p.shape != (3,) or not np.isfinite(p).all():
                raise MarkerSetError(
                    f"marker {m.name!r}: position must be 3 finite numbers (m, in frame "
                    f"{m.body!r}), got {m.position!r}"
                )
            if not (
                isinstance(m.weight, (int, float, np.floating, np.integer))
                and not isinstance(m.weight, bool)
                and np.isfinite(m.weight)
                and m.weight >= 0
            ):
                raise MarkerSetError(
                    f"marker {m.name!r}: weight must be a finite number >= 0, got {m.weight!r}"
                )

    def __len__(self) -> int:
        return len(self.markers)

    def __iter__(self):
        return iter(self.markers)

    def __repr__(self) -> str:
        return f"MarkerSet({self.name!r}, {len(self)} markers: {', '.join(self.names)})"

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.markers)

    @property
    def bodies(self) -> tuple[str, ...]:
        return tuple(m.body for m in self.markers)

    @property
    def positions(self) -> np.ndarray:
        """(M, 3) positions in the markers' own frames (m)."""
        return np.array([m.position for m in self.markers], dtype=float)

    @property
    def weights(self) -> np.ndarray:
        """(M,) weights."""
        return np.array([m.weight for m in self.markers], dtype=float)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, d: dict, name: str = "markers") -> "MarkerSet":
        """From ``{name: (body, (x, y, z))}``, ``{name: (body, (x, y, z), weight)}`` or
        ``{name: {"body": ..., "position": [...], "weight": ...}}`` (m)."""
        if not isinstance(d, dict):
            raise MarkerSetError(
                "a marker set dict maps names to (body, position[, weight]), got "
                f"{type(d).__name__}"
            )
        out = []
        for k, v in d.items():
            try:
                if isinstance(v, dict):
                    out.append(Marker(k, v["body"], tuple(v["position"]), v.get("weight", 1.0)))
                else:
                    out.append(Marker(k, v[0], tuple(v[1]), v[2] if len(v) > 2 else 1.0))
            except (KeyError, IndexError, TypeError) as exc:
                raise MarkerSetError(
                    f"marker {k!r}: expected (body, (x, y, z)[, weight]) or a dict with body, "
                    f"position[, weight]; got {v!r} ({exc})"
                ) from None
        return cls(out, name=name)

    def to_dict(self) -> dict:
        return {
            m.name: {
                "body": m.body,
                "position": [float(x) for x in m.position],
                "weight": float(m.weight),
            }
            for m in self.markers
        }

    @classmethod
    def read_json(cls, path) -> "MarkerSet":
        """A set written by :meth:`write_json` (or by hand: ``{"name": ..., "markers": {...}}``
        with the entries of :meth:`from_dict`).  A :class:`~anthroarm.errors.MarkerSetError`
        naming the file for a missing file, one that is not a regular file, is larger than
        :data:`MAX_MARKER_SET_BYTES`, nested deeper than :data:`MAX_MARKER_SET_DEPTH`, is not
        JSON or not a valid set."""
        if not isinstance(path, (str, os.PathLike)) or path == "":
            raise MarkerSetError(
                f"read_json: path must be a file path, got {type(path).__name__} {path!r}"
            )
        p = Path(path)
        doc = load_json_bounded(
            p,
            MAX_MARKER_SET_BYTES,
            max_depth=MAX_MARKER_SET_DEPTH,
            what="marker set file",
            error=lambda problem: MarkerSetError(f"{p}: {problem}"),
        )
        if not isinstance(doc, dict) or not isinstance(doc.get("markers"), dict):
            raise MarkerSetError(f"{p}: expected an object with a 'markers' object")
        try:
            return cls.from_dict(doc["markers"], name=str(doc.get("name", p.stem)))
        except MarkerSetError as exc:
            raise MarkerSetError(f"{p}: {exc}") from None

    def write_json(self, path) -> None:
        """Write the set as JSON (atomically)."""
        atomic_write_text(
            path, json.dumps({"name": self.name, "markers": self.to_dict()}, indent=2) + "\n"
        )

    def subset(self, names) -> "MarkerSet":
        """The markers named in ``names`` (in this set's order)."""
        names = set(names)
        unknown = names - set(self.names)
        if unknown:
            raise MarkerSetError(
                f"markers {sorted(unknown)} are not in {self.name!r} ({', '.join(self.names)})"
            )
        return MarkerSet([m for m in self.markers if m.name in names], name=self.name)

    # ------------------------------------------------------------------ robot
    def bind(self, robot) -> "BoundMarkers":
        """The set on ``robot``: each marker's joint and its position in that joint's frame.
        An unknown body raises :class:`~anthroarm.errors.MarkerSetError` listing the frames."""
        return BoundMarkers(robot, self)

    def world_positions(self, robot, q) -> np.ndarray:
        """World positions (m) of the markers at ``q``: ``(nq,)`` -> ``(M, 3)``,
        ``(N, nq)`` -> ``(N, M, 3)`` (Pinocchio forward kinematics)."""
        return self.bind(robot).world_positions(q)


def _numeric(x) -> bool:
    """``x`` is a sequence of real numbers (not text, not booleans: "1" or true in a JSON file
    is a mistake, not a coordinate)."""
    if isinstance(x, np.ndarray):
        return x.dtype.kind in "iuf"
    if isinstance(x, (str, bytes)):
        return False
    try:
        return all(
            isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)
            for v in x
        )
    except TypeError:  # not a sequence
        return False


class BoundMarkers:
    """A marker set attached to a robot (built by :meth:`MarkerSet.bind`).

    Attributes
    ----------
    joint : (M,) int
        Index in ``robot.chain.joints`` of the joint whose body carries each marker (−1: base).
    local : (M, 3)
        Marker positions in that joint's frame (m).
    downstream : (nv, M) bool
        ``downstream[v, k]``: velocity ``v`` moves marker ``k`` (the marker's body is on or below
        the joint in the tree).
    """

    def __init__(self, robot, marker_set: MarkerSet):
        chain = robot.chain
        self.robot = robot
        self.marker_set = marker_set
        M = len(marker_set)
        self.joint = np.empty(M, dtype=int)
        self.local = np.empty((M, 3))
        for k, m in enumerate(marker_set):
            try:
                f = chain.frame(m.body)
            except UnknownFrameError:
                raise MarkerSetError(
                    f"marker {m.name!r}: body {m.body!r} is not a frame of {robot.name}; frames: "
                    f"{', '.join(f.name for f in chain.frames)}"
                ) from None
            self.joint[k] = f.joint
            self.local[k] = f.rotation @ np.asarray(m.position, float) + f.translation
        self.downstream = moved_by(chain, self.joint).T
        self.bodies = np.unique(self.joint[self.joint >= 0])

    def _frame_of(self, k: int) -> int:
        return self.robot.chain.frame(self.marker_set.markers[k].body).index

    def unconstrained_joints(self, visible=None) -> list[str]:
        """Names of the velocity coordinates that no (visible) marker is downstream of."""
        cols = self.downstream if visible is None else self.downstream[:, np.asarray(visible, bool)]
        chain = self.robot.chain
        names = {}
        for j in chain.joints:
            if not j.is_mimic:
                names[j.idx_v] = j.name
        return [names.get(v, str(v)) for v in range(chain.nv) if not cols[v].any()]

    def world_positions(self, q) -> np.ndarray:
        """World positions (m): ``(nq,)`` -> ``(M, 3)``, ``(N, nq)`` -> ``(N, M, 3)``."""
        q = self.robot.check_q(q)
        model = self.robot.model
        data = self.robot.data
        one = q.ndim == 1
        Q = q[None] if one else q
        out = np.empty((Q.shape[0], len(self.joint), 3))
        jid = self.joint + 1
        for n, qi in enumerate(Q):
            pin.forwardKinematics(model, data, qi)
            for k, j in enumerate(jid):
                M = data.oMi[int(j)]
                out[n, k] = M.rotation @ self.local[k] + M.translation
        return out[0] if one else out

    def jacobian(self, q) -> np.ndarray:
        """Stacked marker Jacobian (3M, nv): rows x, y, z of each marker's world velocity
        (LOCAL_WORLD_ALIGNED: the point's velocity in world axes), from Pinocchio's joint
        Jacobians shifted to the marker, J_p = J_v + J_ω × (p − o_joint)."""
        q = self.robot.check_q(q)
        model, data = self.robot.model, self.robot.data
        pin.computeJointJacobians(model, data, q)
        nv = self.robot.nv
        J = np.zeros((3 * len(self.joint), nv))
        for k, j in enumerate(self.joint):
            if j < 0:
                continue
            Mi = data.oMi[int(j) + 1]
            Jj = pin.getJointJacobian(
                model, data, int(j) + 1, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
            r = Mi.rotation @ self.local[k]
            J[3 * k : 3 * k + 3] = Jj[:3] + np.cross(Jj[3:].T, r).T
        return J

    def check_constrains(self, q=None, rtol: float = 1e-8) -> None:
        """Raise :class:`~anthroarm.errors.UnconstrainedJointError` when the markers cannot
        determine every joint: a joint with no marker downstream (structural), or a marker
        Jacobian of rank < nv at ``q`` (default: the comfortable posture; singular values below
        ``rtol`` times the largest)."""
        free = self.unconstrained_joints()
        if free:
            raise UnconstrainedJointError(
                f"marker set {self.marker_set.name!r} does not constrain joints {free} of "
                f"{self.robot.name}: no marker on a body they move; add markers below them",
                joints=free,
            )
        if q is None:
            q = comfortable_posture(self.robot)
        J = self.jacobian(q) * np.repeat(np.sqrt(self.marker_set.weights), 3)[:, None]
        _, s, Vt = np.linalg.svd(J)
        nv = self.robot.nv
        s_full = np.zeros(nv)
        s_full[: len(s)] = s[:nv]
        weak = s_full <= rtol * max(s_full.max(), 1e-300)
        if weak.any():
            chain = self.robot.chain
            names = {j.idx_v: j.name for j in chain.joints if not j.is_mimic}
            joints = sorted(
                {names[int(np.argmax(np.abs(Vt[i])))] for i in np.flatnonzero(weak) if i < len(Vt)}
            )
            raise UnconstrainedJointError(
                f"marker set {self.marker_set.name!r} leaves {int(weak.sum())} direction(s) of "
                f"{self.robot.name}'s joints undetermined at the reference posture (marker "
                f"Jacobian rank {nv - int(weak.sum())} < {nv}); mostly joints {joints}: add "
                "markers off their axes",
                joints=joints,
            )


def segment_length(robot, body: str) -> float:
    """Length (m) of the segment carried by frame ``body``, read from ``robot.chain``: the
    distance from its joint to the tool frame when the tool is on this segment (a hand ends at
    its hand point even when finger joints branch off it), else to the next joint (past
    co-located virtual joints), else to the farthest frame fixed to it.  A segment whose child
    joints lie at different distances is ambiguous: :class:`~anthroarm.errors.MarkerSetError`."""
    chain = robot.chain
    f = chain.frame(body)
    if f.joint < 0:
        raise MarkerSetError(
            f"{body!r} is fixed to the base of {robot.name}: it has no segment length"
        )
    tool = chain.frame(chain.tool)
    if tool.joint == f.joint and np.linalg.norm(tool.translation) > 0:
        return float(np.linalg.norm(tool.translation))
    ends = []
    for k in chain.children(f.joint):
        t = np.linalg.norm(chain.joints[k].translation)
        if t == 0:  # a co-located virtual joint: follow it to the next offset on the chain
            t = next(
                (
                    d
                    for d in (
                        np.linalg.norm(chain.joints[kk].translation) for kk in chain.children(k)
                    )
                    if d > 0
                ),
                0.0,
            )
        if t > 0:
            ends.append((float(t), chain.joints[k].name))
    if ends:
        if max(e for e, _ in ends) - min(e for e, _ in ends) > 1e-9:
            raise MarkerSetError(
                f"{body!r} of {robot.name} branches to joints at different distances "
                f"({', '.join(f'{n} {e:.4f} m' for e, n in ends)}): its segment length is "
                "ambiguous; give the marker positions in m (MarkerSet)"
            )
        return ends[0][0]
    offs = [np.linalg.norm(g.translation) for g in chain.frames if g.joint == f.joint]
    if not offs or max(offs) == 0:
        raise MarkerSetError(
            f"{body!r} of {robot.name}: no joint or frame below it to measure a length"
        )
    return float(max(offs))


def human_arm_markers(robot, landmarks: dict | None = None) -> MarkerSet:
    """The default marker set of the human arm model
    (:data:`anthroarm.models.human.HUMAN_ARM_LANDMARKS`), scaled to ``robot``'s segment lengths
    (:func:`segment_length` of each link; markers on a frame fixed to the base by the length of
    :data:`~anthroarm.models.human.HUMAN_ARM_TRUNK_SCALE_LINK`).  ``landmarks`` replaces the
    table (same form).  A robot without those links raises
    :class:`~anthroarm.errors.MarkerSetError`."""
    table = HUMAN_ARM_LANDMARKS if landmarks is None else landmarks
    lengths = {}
    out = []
    for name, (body, frac, w, _desc) in table.items():
        try:
            scale_body = HUMAN_ARM_TRUNK_SCALE_LINK if robot.chain.frame(body).joint < 0 else body
            if scale_body not in lengths:
                lengths[scale_body] = segment_length(robot, scale_body)
        except UnknownFrameError as exc:
            raise MarkerSetError(
                "the human-arm marker set needs the links "
                f"{sorted({b for b, *_ in table.values()})} ({exc}): give your own MarkerSet"
            ) from None
        out.append(Marker(name, body, tuple(float(v) * lengths[scale_body] for v in frac), w))
    return MarkerSet(out, name="human_arm_isb10")


def default_marker_set(robot) -> MarkerSet:
    """The default marker set of a person's arm model (``robot.spec.person``): the human-arm
    landmarks of :func:`human_arm_markers`.  Other robots have none
    (:class:`~anthroarm.errors.MarkerSetError`: give a :class:`MarkerSet`)."""
    spec = getattr(robot, "spec", None)
    if spec is None or not getattr(spec, "person", False):
        raise MarkerSetError(
            f"{robot.name} is not a person's arm model: it has no default marker set; "
            "give one (MarkerSet.from_dict / read_json)"
        )
    return human_arm_markers(robot)
