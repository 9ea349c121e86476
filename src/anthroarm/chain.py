"""The kinematic description every algorithm reads: ``robot.chain``.

A :class:`Chain` is built once per :class:`~anthroarm.robot.Robot` from its ``pin.Model`` and
never changes.  It holds, per joint (in Pinocchio's joint order, the universe left out):

* its **kind**: ``"revolute"``, ``"prismatic"`` or ``"continuous"`` (an unbounded revolute joint,
  Pinocchio's ``RUBX/RUBY/RUBZ`` or ``RevoluteUnboundedUnaligned``, whose configuration is the
  pair (cos θ, sin θ): it takes two entries of q and one of v);
* its unit **axis** in the joint frame and its **placement** (rotation, translation) in the
  parent joint's frame at zero configuration, in metres;
* its **parent** joint (a tree, not only a chain), its slices of q and v, its limits (rad or m,
  ±inf where there are none), velocity and effort limits;
* the **inertia** of the body it moves (mass kg, centre of mass m and rotational inertia about
  the centre of mass kg m², both in the joint frame);
* its **mimic** relation, where it copies another joint: θ_j = multiplier · θ_i + offset (the
  URDF ``<mimic>`` tag, modelled by Pinocchio as a joint without q or v of its own).

and every frame (name, parent joint, placement in the joint frame), the tool frame and the tip
frames (one per leaf of the tree).  The kind of a joint comes from its motion subspace S (a
constant 6-vector in the joint frame for every 1-DOF joint): angular only is revolute, linear
only is prismatic; joints with more degrees of freedom (free-flyer, spherical, planar,
translation, composite) or with a coupled screw motion (helical) raise
:class:`~anthroarm.errors.UnsupportedModelError` naming the joint and saying what to do.

Joint positions θ (one per joint, mimic joints included: the angle in rad or the displacement in
m) are what the closed forms, the Lagrange derivation and the batched FK take; :meth:`angles`
maps a configuration q (Pinocchio's layout) to θ and :meth:`configuration` maps the independent
joints' θ back to q.
"""

from __future__ import annotations

import functools
import hashlib
import math
import re
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

from .errors import AmbiguousToolError, ParameterError, UnknownFrameError, UnsupportedModelError
from .joint_kinds import CONTINUOUS as CONTINUOUS
from .joint_kinds import PRISMATIC as PRISMATIC
from .joint_kinds import REVOLUTE as REVOLUTE
from .serial_chain import SerialChain
from .threads import run_rows
from .urdf_io import MAX_MOVABLE_JOINTS

#: a joint limit this large (rad or m) means none (Pinocchio's default is ±DBL_MAX)
NO_LIMIT = 1e100

#: what to tell the user of a joint that no algorithm here handles
_UNSUPPORTED_ADVICE = (
    "lock it with locked={{{name!r}: value}} or pick the sub-chain you need with "
    "active=[...] (aa.load(..., locked=..., active=...))"
)


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


def _homogeneous(R, p) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


@functools.cache
def _kernels():
    """The compiled kernels of this module's methods, imported on first use: importing
    anthroarm or reading a model does not load Numba; the first :meth:`Chain.configuration`
    (also :meth:`Chain.random_q`) does, about 0.4 s once per process (the kernel itself comes
    from the disk cache, :mod:`anthroarm.jit`) — a choice: it is 3–4× faster than numpy on
    the few rows of one IK answer, where Numba is loaded anyway."""
    from . import chain_kernels

    return chain_kernels


@dataclass(frozen=True, eq=False)
class Mimic:
    """θ_joint = multiplier · θ_source + offset (URDF ``<mimic>``; rad or m)."""

    source: int  # index of the mimicked joint in Chain.joints
    multiplier: float
    offset: float


@dataclass(frozen=True, eq=False)
class Joint:
    """One joint of a :class:`Chain` (SI units, joint frame unless said otherwise)."""

    name: str
    index: int  # position in Chain.joints (= Pinocchio joint id − 1)
    parent: int  # index of the parent joint, −1 for the base
    kind: str  # "revolute" | "prismatic" | "continuous"
    axis: np.ndarray  # (3,) unit axis in the joint frame
    rotation: np.ndarray  # (3, 3) placement in the parent joint frame at θ = 0
    translation: np.ndarray  # (3,) m
    idx_q: int  # first entry in q (a mimic joint: its source's)
    nq: int  # 1, 2 for a continuous joint, 0 for a mimic joint
    idx_v: int
    nv: int  # 1, 0 for a mimic joint
    lower: float  # rad or m (−inf: none)
    upper: float
    velocity: float  # rad/s or m/s (inf: none given)
    effort: float  # N m or N (inf: none given)
    mass: float  # kg, of the body this joint moves
    com: np.ndarray  # (3,) m
    inertia: np.ndarray  # (3, 3) kg m², about the centre of mass
    mimic: Mimic | None = None

    @property
    def is_mimic(self) -> bool:
        return self.mimic is not None

    @property
    def placement(self) -> np.ndarray:
        """4×4 homogeneous placement in the parent joint frame at θ = 0."""
        return _homogeneous(self.rotation, self.translation)


@dataclass(frozen=True, eq=False)
class Frame:
    """A named frame fixed to a joint's body: ``joint`` is its index in Chain.joints (−1: the
    base); ``rotation``/``translation`` place it in that joint's frame (m)."""

    name: str
    index: int  # Pinocchio frame id
    joint: int
    rotation: np.ndarray
    translation: np.ndarray
    is_body: bool  # a URDF link (Pinocchio BODY frame)
    is_joint: bool  # a joint frame (Pinocchio JOINT or FIXED_JOINT)
    parent_frame: int  # Pinocchio id of the frame it hangs from
    kind: str = ""  # Pinocchio's frame type: "body", "op_frame", "joint", "fixed_joint", "sensor"

    @property
    def placement(self) -> np.ndarray:
        """4×4 homogeneous placement in the joint frame."""
        return _homogeneous(self.rotation, self.translation)


class Chain:
    """Immutable kinematic description of a fixed-base tree (see the module docstring).

    Build it with :meth:`from_model`; a :class:`~anthroarm.robot.Robot` has one as
    ``robot.chain``.  ``tool`` is the frame algorithms use by default, ``tips`` the leaf frames.
    """

    def __init__(self, name: str, joints, frames, tool: str, tips, nq: int, nv: int, gravity):
        self.name = name
        self.joints: tuple[Joint, ...] = tuple(joints)
        self.frames: tuple[Frame, ...] = tuple(frames)
        self._frame_ids = {}
        for f in self.frames:  # Pinocchio keeps the first of equal names
            self._frame_ids.setdefault(f.name, f.index)
        self._joint_ids = {j.name: j.index for j in self.joints}
        self.tips: tuple[str, ...] = tuple(tips)
        self.nq, self.nv = int(nq), int(nv)
        self.gravity = _frozen(gravity)
        self.tool = tool
        self.tool_frame = self.frame(tool).index

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_model(cls, model, tool: str | None = None, name: str | None = None) -> "Chain":
        """Read a ``pin.Model``: joints, axes, placements, limits, inertias, mimic relations,
        frames and tips.  ``tool=None`` picks the single tip (see :func:`leaf_frames`: a serial
        chain has one); a tree with several tips raises :class:`AmbiguousToolError` listing
        them, an unknown ``tool`` :class:`UnknownFrameError`."""
        name = name or getattr(model, "name", "") or "model"
        if model.njoints - 1 > MAX_MOVABLE_JOINTS:  # before createData: pin.Data grows as n³
            raise UnsupportedModelError(
                f"{name}: {model.njoints - 1} joints; anthroarm takes at most {MAX_MOVABLE_JOINTS} "
                "per model (Pinocchio's data grows as the cube of the joint count); lock joints "
                "with pin.buildReducedModel first or split the model"
            )
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        mimic_of = {}
        if hasattr(model, "mimicking_joints"):
            for mj, src in zip(model.mimicking_joints, model.mimicked_joints):
                mimic_of[int(mj)] = int(src)
        joints = []
        lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
        vel, eff = np.asarray(model.velocityLimit), np.asarray(model.effortLimit)
        for jid in range(1, model.njoints):
            jm = model.joints[jid]
            jname = model.names[jid]
            short = jm.shortname()
            mimic = None
            if jid in mimic_of:
                e = jm.extract()
                mult, off = float(e.scaling), float(e.offset)
                if mult == 0.0:
                    raise UnsupportedModelError(
                        f"{name}: mimic joint {jname!r} has multiplier 0; "
                        + _UNSUPPORTED_ADVICE.format(name=jname)
                    )
                mimic = Mimic(mimic_of[jid] - 1, mult, off)
                S = np.asarray(data.joints[jid].S).reshape(6) / mult
                nq = nv = 0
                idx_q, idx_v = int(e.idx_q), int(e.idx_v)
            else:
                if not ((jm.nq == 1 and jm.nv == 1) or (jm.nq == 2 and jm.nv == 1)):
                    raise UnsupportedModelError(
                        f"{name}: joint {jname!r} is {short} with nq={jm.nq}, nv={jm.nv}; "
                        "anthroarm handles revolute, continuous, prismatic and mimic joints on a "
                        "fixed base: " + _UNSUPPORTED_ADVICE.format(name=jname)
                    )
                S = np.asarray(data.joints[jid].S).reshape(6)
                nq, nv, idx_q, idx_v = jm.nq, jm.nv, jm.idx_q, jm.idx_v
            lin, ang = S[:3], S[3:]
            nl, na = float(np.linalg.norm(lin)), float(np.linalg.norm(ang))
            if na > 1e-12 and nl <= 1e-12:
                kind, axis = REVOLUTE, ang / na
            elif nl > 1e-12 and na <= 1e-12:
                kind, axis = PRISMATIC, lin / nl
            else:
                raise UnsupportedModelError(
                    f"{name}: joint {jname!r} ({short}) is neither a revolute nor a prismatic "
                    "motion; " + _UNSUPPORTED_ADVICE.format(name=jname)
                )
            if nq == 2:
                if kind != REVOLUTE:
                    raise UnsupportedModelError(
                        f"{name}: joint {jname!r} ({short}) has a 2-entry configuration "
                        "but is not a rotation; " + _UNSUPPORTED_ADVICE.format(name=jname)
                    )
                kind = CONTINUOUS
                lo, hi = -np.inf, np.inf
            elif nq == 1:
                lo, hi = float(lower[idx_q]), float(upper[idx_q])
                # a model built in code keeps Pinocchio's default ±DBL_MAX: no limit at all
                lo = -np.inf if lo <= -NO_LIMIT else lo
                hi = np.inf if hi >= NO_LIMIT else hi
            else:
                lo, hi = -np.inf, np.inf  # set below from the source's limits
            axis = np.where(np.abs(axis) < 1e-15, 0.0, axis)
            axis = axis / np.linalg.norm(axis)
            pl = model.jointPlacements[jid]
            Y = model.inertias[jid]
            Ic = np.asarray(Y.inertia, dtype=float)
            joints.append(
                dict(
                    name=jname,
                    index=jid - 1,
                    parent=int(model.parents[jid]) - 1,
                    kind=kind,
                    axis=_frozen(axis),
                    rotation=_frozen(pl.rotation),
                    translation=_frozen(pl.translation),
                    idx_q=int(idx_q),
                    nq=int(nq),
                    idx_v=int(idx_v),
                    nv=int(nv),
                    lower=lo,
                    upper=hi,
                    velocity=float(vel[idx_v]) if nv else np.inf,
                    effort=float(eff[idx_v]) if nv else np.inf,
                    mass=float(Y.mass),
                    com=_frozen(Y.lever),
                    inertia=_frozen(0.5 * (Ic + Ic.T)),
                    mimic=mimic,
                )
            )
        for j in joints:  # a mimic joint's range is its source's, mapped
            m = j["mimic"]
            if m is not None:
                src = joints[m.source]
                if src["mimic"] is not None:
                    raise UnsupportedModelError(
                        f"{name}: mimic joint {j['name']!r} copies another mimic joint"
                    )
                if src["kind"] != CONTINUOUS:
                    a = m.multiplier * src["lower"] + m.offset
                    b = m.multiplier * src["upper"] + m.offset
                    j["lower"], j["upper"] = min(a, b), max(a, b)
                j["velocity"] = abs(m.multiplier) * src["velocity"]
        joints = [Joint(**j) for j in joints]
        frames = []
        for fid, f in enumerate(model.frames):
            frames.append(
                Frame(
                    f.name,
                    fid,
                    int(f.parentJoint) - 1,
                    _frozen(f.placement.rotation),
                    _frozen(f.placement.translation),
                    f.type == pin.FrameType.BODY,
                    f.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT),
                    int(f.parentFrame),
                    str(f.type.name).lower(),
                )
            )
        tips = leaf_frames(joints, frames)
        if tool is None:
            tool = _default_tool(name, joints, frames, tips)
        elif tool not in {f.name for f in frames}:
            raise UnknownFrameError(
                f"{name}: unknown tool frame {tool!r}; tip frames: {', '.join(tips)}; "
                f"valid frames: {', '.join(f.name for f in frames)}"
            )
        return cls(name, joints, frames, tool, tips, model.nq, model.nv, model.gravity.linear)

    # ------------------------------------------------------------------ lookup
    def __repr__(self) -> str:
        kinds = ", ".join(f"{k}={n}" for k, n in self.kind_counts().items() if n)
        return (
            f"Chain({self.name!r}, joints={len(self.joints)} ({kinds}), nq={self.nq}, "
            f"nv={self.nv}, tool={self.tool!r})"
        )

    def kind_counts(self) -> dict:
        out = {REVOLUTE: 0, PRISMATIC: 0, CONTINUOUS: 0, "mimic": 0}
        for j in self.joints:
            out["mimic" if j.is_mimic else j.kind] += 1
        return out

    def joint(self, name: str) -> Joint:
        """The joint called ``name``; :class:`KeyError` listing the joints otherwise."""
        try:
            return self.joints[self._joint_ids[name]]
        except KeyError:
            raise UnknownFrameError(
                f"{self.name}: unknown joint {name!r}; joints: "
                f"{', '.join(j.name for j in self.joints)}"
            ) from None

    def frame(self, frame) -> Frame:
        """A frame by name or Pinocchio id (``None``: the tool)."""
        if frame is None:
            return self.frames[self.tool_frame]
        if isinstance(frame, (int, np.integer)) and not isinstance(frame, bool):
            if not 0 <= frame < len(self.frames):
                raise UnknownFrameError(
                    f"{self.name}: frame index {frame} out of range 0..{len(self.frames) - 1}"
                )
            return self.frames[int(frame)]
        if not isinstance(frame, str):
            raise UnknownFrameError(
                f"{self.name}: a frame is a name or an index, got {frame!r}; "
                f"valid frames: {', '.join(f.name for f in self.frames)}"
            )
        fid = self._frame_ids.get(frame)
        if fid is None:
            raise UnknownFrameError(
                f"{self.name}: unknown frame {frame!r}; tip frames: {', '.join(self.tips)}; "
                f"valid frames: {', '.join(f.name for f in self.frames)}"
            )
        return self.frames[fid]

    def path(self, frame=None) -> tuple[int, ...]:
        """Indices of the joints from the base to ``frame`` (default: the tool), base first;
        mimic joints included (they move the frame)."""
        j = self.frame(frame).joint
        out = []
        while j >= 0:
            out.append(j)
            j = self.joints[j].parent
        return tuple(reversed(out))

    def children(self, joint: int) -> tuple[int, ...]:
        return tuple(j.index for j in self.joints if j.parent == joint)

    @cached_property
    def independent(self) -> tuple[int, ...]:
        """Indices of the joints that carry their own configuration (not mimic), in q order."""
        return tuple(j.index for j in self.joints if not j.is_mimic)

    @cached_property
    def is_serial(self) -> bool:
        """No joint has two children."""
        return (
            all(len(self.children(j.index)) <= 1 for j in self.joints)
            and len(self.children(-1)) <= 1
        )

    @cached_property
    def has_continuous(self) -> bool:
        return any(j.kind == CONTINUOUS and not j.is_mimic for j in self.joints)

    @cached_property
    def has_mimic(self) -> bool:
        return any(j.is_mimic for j in self.joints)

    # ------------------------------------------------------------------ limits in q layout
    @cached_property
    def lower(self) -> np.ndarray:
        """Lower limits in q order (rad, m); −1 for both entries of a continuous joint's
        (cos, sin) pair (Pinocchio's convention)."""
        return self._q_limits(0)

    @cached_property
    def upper(self) -> np.ndarray:
        return self._q_limits(1)

    def _q_limits(self, which: int) -> np.ndarray:
        out = np.empty(self.nq)
        for j in self.joints:
            if j.is_mimic:
                continue
            if j.kind == CONTINUOUS:
                out[j.idx_q : j.idx_q + 2] = 1.0 if which else -1.0
            else:
                out[j.idx_q] = j.upper if which else j.lower
        return _frozen(out)

    @cached_property
    def velocity_limit(self) -> np.ndarray:
        """(nv,) rad/s or m/s."""
        out = np.full(self.nv, np.inf)
        for j in self.joints:
            if not j.is_mimic:
                out[j.idx_v] = j.velocity
        return _frozen(out)

    @cached_property
    def q_names(self) -> tuple[str, ...]:
        """A name per entry of q: the joint's name, ``name.cos`` / ``name.sin`` for a
        continuous joint."""
        out = [""] * self.nq
        for j in self.joints:
            if j.is_mimic:
                continue
            if j.kind == CONTINUOUS:
                out[j.idx_q], out[j.idx_q + 1] = f"{j.name}.cos", f"{j.name}.sin"
            else:
                out[j.idx_q] = j.name
        return tuple(out)

    # ------------------------------------------------------------------ configurations
    def angles(self, q) -> np.ndarray:
        """Joint positions θ (rad or m) of every joint, mimic joints included, from q
        (``(nq,)`` → ``(njoints,)``, ``(N, nq)`` → ``(N, njoints)``).  A continuous joint's
        angle is atan2(sin, cos) in (−π, π]."""
        q = np.asarray(q, dtype=float)
        out = np.empty(q.shape[:-1] + (len(self.joints),))
        for j in self.joints:
            if j.is_mimic:
                continue
            if j.kind == CONTINUOUS:
                out[..., j.index] = np.arctan2(q[..., j.idx_q + 1], q[..., j.idx_q])
            else:
                out[..., j.index] = q[..., j.idx_q]
        for j in self.joints:
            if j.is_mimic:
                m = j.mimic
                out[..., j.index] = m.multiplier * out[..., m.source] + m.offset
        return out

    def configuration(self, theta) -> np.ndarray:
        """q from the positions θ of the independent joints (in :attr:`independent` order,
        ``(n,)`` or ``(N, n)``): the inverse of :meth:`angles` restricted to them."""
        theta = np.asarray(theta, dtype=float)
        ind = self.independent
        if theta.ndim == 0 or theta.shape[-1] != len(ind):
            raise ValueError(
                f"{self.name}: theta must have {len(ind)} entries (one per independent joint: "
                f"{', '.join(self.joints[i].name for i in ind)}), got shape {theta.shape}"
            )
        th = np.ascontiguousarray(theta.reshape(math.prod(theta.shape[:-1]), len(ind)))
        q = np.empty((th.shape[0], self.nq))
        configure, index = _kernels().configure, self._configuration_index
        run_rows(lambda a, b: configure(th[a:b], index, q[a:b]), len(th))
        return q.reshape(theta.shape[:-1] + (self.nq,))

    @cached_property
    def _configuration_index(self) -> np.ndarray:
        """For :meth:`configuration`: row k (independent joint k) holds its first entry in q and
        whether it is continuous (q holds cos θ, sin θ)."""
        return np.array(
            [(self.joints[i].idx_q, self.joints[i].kind == CONTINUOUS) for i in self.independent],
            dtype=np.int64,
        ).reshape(-1, 2)

    @cached_property
    def sampling_box(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) of the independent joints' θ for uniform sampling: the limits, [−π, π] for
        unbounded revolute joints, ±1 m for an unbounded prismatic joint."""
        lo, hi = [], []
        for i in self.independent:
            j = self.joints[i]
            default = np.pi if j.kind != PRISMATIC else 1.0
            lo.append(j.lower if np.isfinite(j.lower) else -default)
            hi.append(j.upper if np.isfinite(j.upper) else default)
        return _frozen(lo), _frozen(hi)

    def random_q(self, n: int | None = None, rng=None, margin: float = 0.0) -> np.ndarray:
        """Uniform random configurations: each independent joint's θ uniform in its range
        (``margin`` rad/m inside the limits), a continuous joint's θ uniform in [−π, π) and
        then (cos θ, sin θ).

        ``n``: None (one configuration, shape ``(nq,)``) or a count >= 0 (``(n, nq)``);
        ``margin``: finite, >= 0 and at most half of every joint's range.  Anything else raises
        :class:`~anthroarm.errors.ParameterError`."""
        n, margin = _check_sampling(self.name, n, margin)
        rng = np.random.default_rng(rng)
        lo, hi = self.sampling_box
        if margin:
            tight = [
                self.joints[i].name
                for i, a, b in zip(self.independent, lo, hi)
                if b - a < 2 * margin
            ]
            if tight:
                raise ParameterError(
                    f"{self.name}: margin={margin} is more than half the range of joints "
                    f"{tight}: no configuration is that far inside their limits"
                )
        lo, hi = lo + margin, hi - margin
        shape = (len(lo),) if n is None else (n, len(lo))
        return self.configuration(lo + (hi - lo) * rng.random(shape))

    def check_unit(self, q, name: str = "q") -> None:
        """``ValueError`` naming the joint where a continuous joint's (cos, sin) pair is not a
        unit vector (to 1e-6)."""
        q = np.asarray(q, dtype=float)
        for j in self.joints:
            if j.kind == CONTINUOUS and not j.is_mimic:
                r = np.hypot(q[..., j.idx_q], q[..., j.idx_q + 1])
                bad = np.abs(r - 1.0) > 1e-6
                if np.any(bad):
                    where = ""
                    if q.ndim == 2:
                        where = f" (row {int(np.argmax(bad))})"
                        r = r[bad][0]
                    raise ValueError(
                        f"{self.name}: continuous joint {j.name!r} takes (cos θ, sin θ) in "
                        f"{name}[{j.idx_q}:{j.idx_q + 2}], a unit vector; its norm is "
                        f"{float(r):.6g}{where}"
                    )

    # ------------------------------------------------------------------ derived
    def reach(self, frame=None) -> float:
        """A bound on the distance of ``frame`` from the base (m): the sum of the joint offsets
        on its path, the frame's offset and the largest travel of its prismatic joints."""
        f = self.frame(frame)
        r = float(np.linalg.norm(f.translation))
        for i in self.path(f.index):
            j = self.joints[i]
            r += float(np.linalg.norm(j.translation))
            if j.kind == PRISMATIC:
                ext = max(abs(j.lower), abs(j.upper))
                r += ext if np.isfinite(ext) else 1.0
        return r

    def key(self) -> str:
        """Hash of everything kinematics and dynamics depend on (exact float bits)."""
        h = hashlib.sha256()
        h.update(self.gravity.tobytes())
        for j in self.joints:
            h.update(f"|{j.name}|{j.parent}|{j.kind}|{j.idx_q}|{j.nq}|{j.idx_v}|{j.nv}|".encode())
            for a in (
                j.axis,
                j.rotation,
                j.translation,
                np.array([j.mass, j.lower, j.upper]),
                j.com,
                j.inertia,
            ):
                h.update(np.ascontiguousarray(a, dtype=float).tobytes())
            if j.mimic is not None:
                h.update(
                    np.array([j.mimic.source, j.mimic.multiplier, j.mimic.offset], float).tobytes()
                )
        return h.hexdigest()

    def serial(self, frame=None):
        """The batched FK/Jacobian evaluator of the path to ``frame``
        (:class:`anthroarm.serial_chain.SerialChain`), built once per frame."""
        fid = self.frame(frame).index
        cache = self.__dict__.setdefault("_serial", {})
        s = cache.get(fid)
        if s is None:
            s = cache[fid] = SerialChain.from_chain(self, fid)
        return s


#: names preferred for the tip among several leaf links on the same joint
_TOOL_NAME = re.compile(r"tool|tcp|end_?effector|eef|ee_link|hand|gripper_frame", re.IGNORECASE)


def _check_sampling(name: str, n, margin) -> tuple[int | None, float]:
    """``(n, margin)`` of :meth:`Chain.random_q`, checked (bools are not counts)."""
    if n is not None:
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
            raise ParameterError(
                f"{name}: random_q(n) takes None or a whole number >= 0, got {n!r}"
            )
        if n < 0:
            raise ParameterError(f"{name}: random_q(n) takes a count >= 0, got {n}")
        n = int(n)
    try:
        margin = float(margin)
    except (TypeError, ValueError):
        raise ParameterError(
            f"{name}: random_q margin= is a number (rad or m), got {margin!r}"
        ) from None
    if not (np.isfinite(margin) and margin >= 0):
        raise ParameterError(
            f"{name}: random_q margin= must be finite and >= 0 (rad or m), got {margin}"
        )
    return n, margin


def leaf_frames(joints, frames) -> tuple[str, ...]:
    """One frame per leaf of the tree, read from the joint tree: a serial chain has one tip.

    A *leaf joint* is one no other joint hangs from (mimic joints count as joints).  Its tip is
    chosen among its *leaf links*, the body and operational frames on it from which no joint
    frame (moving or fixed) hangs: the one whose name says tool / tcp / end effector / eef / hand
    if there is one, else the last added (highest Pinocchio frame id) — a UR's ``ee_link`` and
    ``tool0`` are one tip, ``tool0``.  A leaf joint without leaf links is named by the last frame
    on it that is not a joint frame (a sensor), else by its joint frame; one without any frame
    has no tip.

    A leaf link fixed by a fixed joint (a URDF ``type="fixed"``) to a joint that is no leaf is a
    tip as well, one per such joint and chosen by the same rule: the URDF's author hung a frame
    there (an SO-101's ``gripper_frame_link`` beside its moving jaw, Baxter's range sensors), so
    that robot is a tree of tips.  Bodies of a model built in code hang from their joint's own
    frame, so they are no tips but on a leaf joint.  Links fixed to the base are no tips, unless
    nothing moves."""
    hangs = {f.parent_frame for f in frames if f.is_joint and f.parent_frame != f.index}
    by_id = {f.index: f for f in frames}
    has_child = {j.parent for j in joints}
    leaf_joints = [j.index for j in joints if j.index not in has_child] if joints else [-1]
    leaf_set = set(leaf_joints)

    def fixed_below(f) -> bool:  # hangs from a fixed joint's frame
        p = by_id.get(f.parent_frame)
        return p is not None and p.is_joint and p.kind != "joint"

    groups: dict[int, list] = {}
    for f in frames:
        if not (f.is_body or f.kind == "op_frame") or f.index in hangs or f.index == 0:
            continue
        if f.joint in leaf_set or (f.joint >= 0 and fixed_below(f)):
            groups.setdefault(f.joint, []).append(f)
    for j in leaf_joints:  # a leaf joint without leaf links: a sensor, else its joint frame
        if j not in groups:
            on = [f for f in frames if f.joint == j and f.index != 0]
            other = [f for f in on if not f.is_joint]
            if other or on:
                groups[j] = [(other or on)[-1]]
    out = []
    for group in sorted(groups.values(), key=lambda g: g[0].index):
        named = [f for f in group if _TOOL_NAME.search(f.name)]
        out.append((named or group)[-1].name)
    return tuple(out)


def _default_tool(name, joints, frames, tips) -> str:
    if len(tips) == 1:
        return tips[0]
    if not tips:
        return frames[-1].name
    raise AmbiguousToolError(
        f"{name}: this robot is a tree with {len(tips)} tips; say which frame is the tool with "
        f"tool=..., one of the tips: {', '.join(tips)}"
    )
