"""Fingers of a hand, read from the kinematic tree (``robot.chain``): which joints move which
fingertip, the palm, the pad normal of each fingertip and the hand's span.

A **fingertip** is a tip of the tree (:attr:`anthroarm.robot.Robot.tips`, one frame per leaf).
By default every tip is one, except tips that no joint of their own moves (a hand point on the
palm) and, of the tips moved by the same independent joints (the bars of a linkage finger
whose passive joints are mimic joints), all but the one at the end of the longest path.
The joints on the path from the base to a tip that no other tip shares are that **finger's
joints**; the joints every tip shares are the **arm** (the shoulder-to-wrist chain of a human
upper limb; none on a hand with a fixed palm such as ``allegro_right_hand``).  The **palm** is a
body frame on the last shared joint (the base when there is none): one whose name contains
``palm`` if there is one, else the last body frame there.

Pad normal convention (one rule for every hand, derived from the chain; document of record):
the pad of a fingertip faces the way the tip moves when its distal joint flexes.  With a the
distal joint's axis and r the tip frame's origin, both in that joint's frame, the pad normal is

    n = s · (a × r) / ‖a × r‖,   expressed in the tip frame (constant),

with s = +1 when the joint's range reaches further on its positive side (upper ≥ −lower: flexion
is positive, as in the book's finger models, the Allegro hand and the catalog's human hand) and
s = −1 otherwise.  For a fingertip whose origin lies on its distal axis (a × r = 0) there is no
such direction: pass ``pad_axes=`` to :class:`Hand`.  A fingertip touching an object presses n
against the object's outward surface normal: n = −m at the contact.

Span (m): an upper bound on the distance between any two fingertips of the hand,
max over finger pairs (i, j) of ‖o_i − o_j‖ + L_i + L_j, with o_i the origin of finger i's first
joint (at the neutral configuration, where every arm joint is shared so the distances do not
depend on the arm) and L_i the sum of the offsets along the finger (joint to joint, last joint to
the tip; prismatic travel added).  An object whose size (diameter) exceeds it cannot be grasped
by fingertips: :func:`anthroarm.hand.grasp.solve_grasp` raises
:class:`~anthroarm.errors.GraspError`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin

from ..chain import PRISMATIC
from ..errors import CouplingError, FingertipError
from ..ik.qp.tasks.contact_normal import unit_vector

_PALM = re.compile("palm", re.IGNORECASE)


@dataclass(frozen=True, eq=False)
class Finger:
    """One finger: its tip frame, the joints only it has (chain indices, base first; mimic joints
    included), the velocity indices of its independent joints and the pad normal (unit, in
    the tip frame's axes)."""

    tip: str
    tip_id: int
    joints: tuple
    v_indices: tuple
    pad_axis: np.ndarray
    length: float  # L: sum of the offsets from the first joint to the tip (m)

    @property
    def name(self) -> str:
        return self.tip


def _pad_axis(chain, frame, distal) -> np.ndarray | None:
    j = chain.joints[distal]
    v = np.cross(j.axis, frame.translation)
    n = float(np.linalg.norm(v))
    if n < 1e-9 * max(1.0, float(np.linalg.norm(frame.translation))):
        return None
    lo, hi = j.lower, j.upper
    if j.is_mimic:  # a follower's range is its source's, scaled
        src = chain.joints[j.mimic.source]
        a, b = (
            j.mimic.multiplier * src.lower + j.mimic.offset,
            j.mimic.multiplier * src.upper + j.mimic.offset,
        )
        lo, hi = min(a, b), max(a, b)
    s = 1.0 if not (np.isfinite(lo) and np.isfinite(hi)) or hi >= -lo else -1.0
    return s * (frame.rotation.T @ (v / n))


def _common(paths) -> int:
    """Length of the joint path every tip shares."""
    common = 0
    while all(len(p) > common and p[common] == paths[0][common] for p in paths):
        common += 1
    return common


class Hand:
    """The fingers, arm joints and palm of ``robot`` (see the module docstring).

    Parameters
    ----------
    robot : anthroarm.Robot
    tips : sequence of str, optional
        Fingertip frames (default: every tip of the tree).  A frame that is not a tip of the
        tree raises :class:`~anthroarm.errors.FingertipError` listing the tips.
    palm : str, optional
        Palm frame (default: see the module docstring).
    pad_axes : dict, optional
        tip name → pad normal (3,) in that tip's frame, overriding the convention.
    """

    def __init__(self, robot, tips=None, palm=None, pad_axes=None):
        chain = robot.chain
        self.robot = robot
        all_tips = tuple(robot.tips)
        tips = all_tips if tips is None else tuple(tips)
        if len(tips) < 2:
            raise FingertipError(
                f"{robot.name}: a hand needs at least two fingertips, got {list(tips)}; "
                f"tips of the tree: {', '.join(all_tips)}"
            )
        for t in tips:
            if not isinstance(t, str) or t not in all_tips:
                raise FingertipError(
                    f"{robot.name}: {t!r} is not a fingertip (a tip of the kinematic tree); "
                    f"fingertips: {', '.join(all_tips)}"
                )
        if len(set(tips)) != len(tips):
            raise FingertipError(f"{robot.name}: fingertips repeated in {list(tips)}")
        default = tips is all_tips
        paths = [chain.path(t) for t in tips]
        common = _common(paths)
        if default:
            # tips that no joint of their own moves (a hand point, the palm) are no fingertips
            keep = [k for k, p in enumerate(paths) if len(p) > common]
            tips = tuple(tips[k] for k in keep)
            paths = [paths[k] for k in keep]
            common = _common(paths)
            # a linkage's bars are leaves too: of the tips moved by the same independent joints
            # (one finger; a bar moved by mimic joints only counts their sources) keep the one
            # at the end of the longest path: the fingertip
            best: dict = {}
            for t, p in zip(tips, paths):
                own = frozenset(
                    chain.joints[i].idx_v for i in p[common:] if not chain.joints[i].is_mimic
                )
                drivers = own or frozenset(
                    chain.joints[chain.joints[i].mimic.source].idx_v
                    for i in p[common:]
                    if chain.joints[i].is_mimic
                )
                if drivers not in best or len(p) > len(best[drivers][1]):
                    best[drivers] = (t, p)
            tips = tuple(t for t, _ in best.values())
            paths = [p for _, p in best.values()]
            if len(tips) < 2:
                raise FingertipError(
                    f"{robot.name}: fewer than two tips move on joints of their own "
                    f"({', '.join(all_tips)}): not a hand"
                )
            common = _common(paths)
        self.arm_joints = tuple(paths[0][:common])
        last = self.arm_joints[-1] if self.arm_joints else -1
        pad_axes = dict(pad_axes or {})
        unknown = set(pad_axes) - set(tips)
        if unknown:
            raise FingertipError(
                f"{robot.name}: pad_axes for frames that are not fingertips: {sorted(unknown)}; "
                f"fingertips: {', '.join(tips)}"
            )
        fingers = []
        for t, p in zip(tips, paths):
            own = tuple(p[common:])
            if not own:
                raise FingertipError(
                    f"{robot.name}: tip {t!r} has no joint of its own (it does not move "
                    f"relative to the palm): not a fingertip"
                )
            f = chain.frame(t)
            if t in pad_axes:
                axis = unit_vector(pad_axes[t], f"pad axis of {t!r}")
            else:
                axis = _pad_axis(chain, f, f.joint)
                if axis is None:
                    raise FingertipError(
                        f"{robot.name}: fingertip {t!r} lies on its distal joint's axis, so the "
                        f"pad normal convention does not apply; give pad_axes={{{t!r}: (x, y, z)}}"
                    )
            length = float(np.linalg.norm(f.translation))
            for i in own[1:]:
                length += float(np.linalg.norm(chain.joints[i].translation))
            for i in own:
                j = chain.joints[i]
                if j.kind == PRISMATIC:
                    ext = max(abs(j.lower), abs(j.upper))
                    length += ext if np.isfinite(ext) else 1.0
            vidx = tuple(chain.joints[i].idx_v for i in own if not chain.joints[i].is_mimic)
            fingers.append(Finger(t, f.index, own, vidx, axis, length))
        self.fingers: tuple[Finger, ...] = tuple(fingers)
        if palm is None:
            bodies = [f for f in chain.frames if f.is_body and f.joint == last]
            named = [f for f in bodies if _PALM.search(f.name)]
            if not (named or bodies):
                raise FingertipError(f"{robot.name}: no body frame on the palm joint; give palm=")
            palm = (named or bodies)[-1].name
        self.palm = chain.frame(palm).name
        self.palm_id = chain.frame(palm).index

    def __repr__(self) -> str:
        return (
            f"Hand({self.robot.name!r}, fingers={list(self.tips)}, palm={self.palm!r}, "
            f"arm joints={len(self.arm_joints)})"
        )

    @property
    def tips(self) -> tuple[str, ...]:
        return tuple(f.tip for f in self.fingers)

    def finger(self, tip: str) -> Finger:
        for f in self.fingers:
            if f.tip == tip:
                return f
        raise FingertipError(
            f"{self.robot.name}: {tip!r} is not a fingertip of this hand; fingertips: "
            f"{', '.join(self.tips)}"
        )

    @cached_property
    def arm_v_indices(self) -> tuple:
        """Velocity indices of the arm's independent joints."""
        chain = self.robot.chain
        return tuple(chain.joints[i].idx_v for i in self.arm_joints if not chain.joints[i].is_mimic)

    @cached_property
    def arm_q_indices(self) -> np.ndarray:
        """Entries of q that belong to the arm joints."""
        chain = self.robot.chain
        out = []
        for i in self.arm_joints:
            j = chain.joints[i]
            out.extend(range(j.idx_q, j.idx_q + j.nq))
        return np.array(sorted(out), dtype=int)

    @cached_property
    def finger_q_indices(self) -> np.ndarray:
        """Entries of q that belong to the finger joints (every finger)."""
        chain = self.robot.chain
        out = []
        for f in self.fingers:
            for i in f.joints:
                j = chain.joints[i]
                out.extend(range(j.idx_q, j.idx_q + j.nq))
        return np.array(sorted(out), dtype=int)

    @cached_property
    def span(self) -> float:
        """Upper bound (m) on the distance between two fingertips (module docstring)."""
        model = self.robot.model
        data = model.createData()
        pin.forwardKinematics(model, data, pin.neutral(model))
        origins = [data.oMi[f.joints[0] + 1].translation.copy() for f in self.fingers]
        best = 0.0
        for i, fi in enumerate(self.fingers):
            for j in range(i + 1, len(self.fingers)):
                fj = self.fingers[j]
                best = max(
                    best, float(np.linalg.norm(origins[i] - origins[j])) + fi.length + fj.length
                )
        return best

    # ------------------------------------------------------------------ poses
    def tip_poses(self, q) -> list:
        """World poses (pin.SE3) of the fingertips at ``q`` (Pinocchio FK)."""
        model = self.robot.model
        data = model.createData()
        pin.framesForwardKinematics(model, data, self.robot.check_q(q))
        return [pin.SE3(data.oMf[f.tip_id]) for f in self.fingers]

    def pad_normals(self, q) -> np.ndarray:
        """(n_fingers, 3) pad normals in world axes at ``q``."""
        return np.array([M.rotation @ f.pad_axis for M, f in zip(self.tip_poses(q), self.fingers)])

    def configuration(self, values, q=None) -> np.ndarray:
        """``q`` (default: neutral) with the joints named in ``values`` (name → rad or m) set.

        A mimic joint may be named only with the value its source implies (multiplier ·
        θ_source + offset, to 1e-9); another value raises
        :class:`~anthroarm.errors.CouplingError` (the joint cannot take it: Pinocchio moves it
        with its source)."""
        chain = self.robot.chain
        q = self.robot.neutral() if q is None else self.robot.check_q(q).copy()
        mimic = {}
        for name, val in dict(values).items():
            j = chain.joint(name)
            val = float(val)
            if not np.isfinite(val):
                raise ValueError(
                    f"{self.robot.name}: joint {name!r} value must be finite, got {val}"
                )
            if j.is_mimic:
                mimic[name] = val
                continue
            if j.nq != 1:
                raise ValueError(
                    f"{self.robot.name}: set continuous joint {name!r} through q (cos, sin)"
                )
            q[j.idx_q] = val
        theta = chain.angles(q)
        for name, val in mimic.items():
            j = chain.joint(name)
            want = float(theta[j.index])
            if abs(want - val) > 1e-9 * max(1.0, abs(want)):
                src = chain.joints[j.mimic.source]
                raise CouplingError(
                    f"{self.robot.name}: joint {name!r} is coupled to {src.name!r} ({name} = "
                    f"{j.mimic.multiplier:g}·{src.name} + {j.mimic.offset:g}); with {src.name} = "
                    f"{theta[src.index]:.6g} it is {want:.6g}, not {val:.6g}"
                )
        return q
