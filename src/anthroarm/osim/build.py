"""Build a Pinocchio model and its coupling map from an :class:`~.reader.OsimModel`.

How OpenSim (Simbody) moves a joint, and how it is reproduced here:

* The joint connects a frame P on the parent body to a frame C on the child body; the child
  body's pose in ground is X_G,parent · X_parent,P · X_FM(q) · X_child,C⁻¹.
* ``X_FM`` of a ``CustomJoint`` is Simbody's ``MobilizedBody::FunctionBased``
  (``FunctionBasedImpl::calcMobilizerTransformFromQ`` in simbody's ``MobilizedBodyImpl.h``):
  with s_i the value of transform axis i's function,
  R = R(s_1, a_1) · R(s_2, a_2) · R(s_3, a_3) (each rotation about its axis in the frame the
  previous ones have rotated: body-fixed) and p = s_4 t_4 + s_5 t_5 + s_6 t_6 in the parent
  frame F; X_FM = (R, p).
* Here: the translations first (they are all along axes of F, so they commute), then the
  rotations in order; an axis whose function is constant becomes a fixed placement, every
  other axis a Pinocchio ``PrismaticUnaligned`` / ``RevoluteUnaligned`` joint whose value is
  that function of its coordinate (:mod:`.coupling`).

Names: a Pinocchio joint that is exactly an independent coordinate (its function is f(x) = x) is
named after the coordinate; the other moving axes are ``<joint>_<axis>``
(``knee_r_translation1``).  Every body is a BODY frame named after it (ground: ``ground``),
every marker an OP_FRAME named after it, every ``PhysicalOffsetFrame`` an OP_FRAME named by its
path under its owner (``hip_r/pelvis_offset``).
"""

from __future__ import annotations

import posixpath

import numpy as np
import pinocchio as pin

from ..errors import OsimError, OsimUnsupportedError
from .coupling import Coupling, Step
from .functions import Constant
from .reader import OsimModel

BIG = 1e300  # a "no limit" Pinocchio accepts (robot.chain reads >= 1e100 as none)


def rotation(axis, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues)."""
    return pin.AngleAxis(float(angle), np.asarray(axis, dtype=float)).toRotationMatrix()


def body_fixed_xyz(a) -> np.ndarray:
    """Simbody's ``setRotationToBodyFixedXYZ``: Rx(a0) · Ry(a1) · Rz(a2)."""
    E = np.eye(3)
    return rotation(E[0], a[0]) @ rotation(E[1], a[1]) @ rotation(E[2], a[2])


class _Frames:
    """Resolve component paths to (body, placement in the body)."""

    def __init__(self, m: OsimModel):
        self.m = m
        self.body_paths = {f"/bodyset/{b}": b for b in m.bodies if b != m.ground}
        self.body_paths[f"/{m.ground}"] = m.ground
        self.cache: dict[str, tuple[str, pin.SE3]] = {}

    def resolve(self, ref: str, owner: str, what: str, line) -> tuple[str, pin.SE3]:
        path = self._path(ref, owner)
        if path is None:
            raise OsimError(
                self.m.path,
                f"refers to frame {ref!r}, which is not a body or a frame of the model",
                what,
                line,
            )
        return self._place(path, what, line, ())

    def _path(self, ref: str, owner: str):
        """The absolute path of a socket's connectee: OpenSim resolves a relative path from the
        component that owns the socket (a joint's frames, ``..`` for a frame's owner)."""
        ref = ref.strip()
        path = posixpath.normpath(ref if ref.startswith("/") else posixpath.join(owner, ref))
        if path in self.body_paths or path in self.m.frames:
            return path
        return None

    def _place(self, path: str, what, line, seen) -> tuple[str, pin.SE3]:
        if path in self.body_paths:
            return self.body_paths[path], pin.SE3.Identity()
        hit = self.cache.get(path)
        if hit is not None:
            return hit
        if path in seen:
            raise OsimError(
                self.m.path,
                f"frames hang from each other in a circle: {' -> '.join(seen)}",
                what,
                line,
            )
        f = self.m.frames[path]
        ppath = self._path(f.parent, f.owner)
        if ppath is None:
            raise OsimError(
                self.m.path,
                f"socket_parent {f.parent!r} is not a body or a frame of the model",
                f"<PhysicalOffsetFrame name={f.name!r}>",
                f.line,
            )
        body, X = self._place(ppath, what, line, seen + (path,))
        out = body, X * pin.SE3(body_fixed_xyz(f.orientation), f.translation)
        self.cache[path] = out
        return out


def build(m: OsimModel):
    """(pin.Model, Coupling or None, info dict) of ``m``; see the module docstring."""
    frames = _Frames(m)
    # --- the tree of bodies
    parent_of: dict[str, object] = {}
    for j in m.joints:
        what = f"<{j.type} name={j.name!r}>"
        pb, XP = frames.resolve(j.parent, f"/jointset/{j.name}", what, j.line)
        cb, XC = frames.resolve(j.child, f"/jointset/{j.name}", what, j.line)
        if cb == m.ground:
            raise OsimError(
                m.path,
                "ground is the child of this joint (a reversed joint): the import takes joints "
                "whose child is further from ground; swap parent and child in OpenSim",
                what,
                j.line,
            )
        if cb == pb:
            raise OsimError(m.path, f"joins body {cb!r} to itself", what, j.line)
        if cb in parent_of:
            raise OsimError(
                m.path,
                f"body {cb!r} is already the child of joint {parent_of[cb][0].name!r}: a closed "
                "loop (model it with a constraint in OpenSim)",
                what,
                j.line,
            )
        parent_of[cb] = (j, pb, XP, XC)
    # depth first from ground, children in the JointSet's order: Pinocchio's algorithms
    # (crba's subtree ranges) need every subtree's joints contiguous
    children: dict[str, list] = {}
    for cb, (j, pb, _, _) in parent_of.items():
        children.setdefault(pb, []).append(cb)
    order, stack = [], list(reversed(children.get(m.ground, [])))
    while stack:
        b = stack.pop()
        order.append(b)
        stack.extend(reversed(children.get(b, [])))
    placed = {m.ground, *order}
    pending = [b for b in parent_of if b not in placed]
    if pending:
        j = parent_of[pending[0]][0]
        raise OsimError(
            m.path,
            f"bodies {pending} are not connected to ground (their joints form a loop or hang "
            "from a body no joint connects)",
            f"<{j.type} name={j.name!r}>",
            j.line,
        )
    loose = [b for b in m.bodies if b not in placed]
    if loose:
        b = m.bodies[loose[0]]
        raise OsimError(
            m.path, f"body {loose[0]!r} has no joint to ground", f"<Body name={loose[0]!r}>", b.line
        )

    coords = {c.name: c for c in m.coordinates}
    dependent = {}
    for cp in m.couplers:
        what = f"<CoordinateCouplerConstraint name={cp.name!r}>"
        for n in (cp.dependent, cp.independent):
            if n not in coords:
                raise OsimError(m.path, f"coordinate {n!r} does not exist", what, cp.line)
        if cp.dependent in dependent:
            raise OsimError(m.path, f"coordinate {cp.dependent!r} is coupled twice", what, cp.line)
        dependent[cp.dependent] = cp
    dep_order = _coupler_order(m, dependent)
    for n in dependent:
        coords[n].dependent = True

    # --- names: frames are found by name, so a marker may not take a body's
    reserved = set(m.bodies) | {mk.name for mk in m.markers}
    for mk in m.markers:
        if mk.name in m.bodies:
            raise OsimUnsupportedError(
                m.path,
                f"marker {mk.name!r} has the name of a body; frames are found by name: rename "
                "the marker (or the body) in OpenSim",
                f"<Marker name={mk.name!r}>",
                mk.line,
            )

    # --- Pinocchio
    model = pin.Model()
    model.name = m.name
    model.gravity = pin.Motion(np.r_[m.gravity, 0.0, 0.0, 0.0])
    body_joint = {m.ground: 0}
    body_place = {m.ground: pin.SE3.Identity()}
    model.addFrame(pin.Frame(m.ground, 0, 0, pin.SE3.Identity(), pin.FrameType.BODY))
    joint_steps, used_names, identity_of = [], set(model.names), {}
    cindex = {c.name: i for i, c in enumerate(m.coordinates)}
    for b in order:
        j, pb, XP, XC = parent_of[b]
        cur = body_joint[pb]
        place = body_place[pb] * XP
        p0 = np.zeros(3)
        for a in j.axes[3:]:
            if a.constant:
                p0 += a.function.value(0.0) * a.axis
        place = place * pin.SE3(np.eye(3), p0)
        for k in (3, 4, 5, 0, 1, 2):
            a = j.axes[k]
            if a.constant:
                if k < 3:
                    place = place * pin.SE3(rotation(a.axis, a.function.value(0.0)), np.zeros(3))
                continue
            cname = a.coords[0]
            c = coords[cname]
            ident = a.function.identity and not c.dependent and cname not in identity_of
            name = cname if ident else f"{j.name}_{a.name}"
            while name in used_names:
                name += "_"
            used_names.add(name)
            jm = (
                pin.JointModelRevoluteUnaligned(a.axis)
                if k < 3
                else pin.JointModelPrismaticUnaligned(a.axis)
            )
            lo, hi = (c.lower, c.upper) if ident else (-BIG, BIG)
            cur = model.addJoint(
                cur,
                jm,
                place,
                name,
                np.array([BIG]),
                np.array([BIG]),
                np.array([lo]),
                np.array([hi]),
            )
            fid = model.addJointFrame(cur)
            if name in reserved:  # a body or marker has the coordinate's name: it keeps the name
                f = model.frames[fid]
                f.name = f"{name}_joint"
                model.frames[fid] = f
            place = pin.SE3.Identity()
            if ident:
                identity_of[cname] = model.idx_qs[cur]
            joint_steps.append(Step(model.idx_qs[cur], cindex[cname], a.function))
        bplace = place * XC.inverse()
        body_joint[b], body_place[b] = cur, bplace
        bd = m.bodies[b]
        model.appendBodyToJoint(cur, pin.Inertia(bd.mass, bd.com, bd.inertia), bplace)
        fparent = model.getFrameId(model.names[cur]) if cur else 0
        model.addFrame(pin.Frame(b, cur, fparent, bplace, pin.FrameType.BODY))
    for path, f in m.frames.items():
        body, X = frames.resolve(path, "/", f"<PhysicalOffsetFrame name={f.name!r}>", f.line)
        jid = body_joint[body]
        short = path.split("/", 2)[-1] if path.startswith(("/jointset/", "/bodyset/")) else path[1:]
        model.addFrame(
            pin.Frame(
                short, jid, model.getFrameId(body), body_place[body] * X, pin.FrameType.OP_FRAME
            )
        )
    for mk in m.markers:
        body, X = frames.resolve(
            mk.parent, f"/markerset/{mk.name}", f"<Marker name={mk.name!r}>", mk.line
        )
        jid = body_joint[body]
        place = body_place[body] * X * pin.SE3(np.eye(3), mk.location)
        model.addFrame(
            pin.Frame(mk.name, jid, model.getFrameId(body), place, pin.FrameType.OP_FRAME)
        )

    # --- the coupling map
    # q: OpenSim's coordinate order (the JointSet's, each joint's mobilities in order) without
    # the dependent coordinates; Pinocchio's q is q itself when every moving axis is one
    # coordinate exactly, in that order
    # a locked coordinate stays at its default value, as OpenSim holds it: not part of q
    locked = [c for c in m.coordinates if c.locked and not c.dependent]
    independent = [c for c in m.coordinates if not c.dependent and not c.locked]
    plain = (
        not dependent
        and not locked
        and len(joint_steps) == len(independent) == model.nq
        and all(s.function.identity for s in joint_steps)
        and [m.coordinates[s.source].name for s in sorted(joint_steps, key=lambda s: s.target)]
        == [c.name for c in independent]
    )
    info = dict(body_joint=body_joint, body_place=body_place, order=order)
    if plain:
        return model, None, info
    steps = [Step(cindex[c.name], cindex[c.name], Constant(c.default)) for c in locked]
    steps += [
        Step(cindex[n], cindex[dependent[n].independent], dependent[n].function, dependent[n].scale)
        for n in dep_order
    ]
    qnames = [""] * model.nq
    for jid in range(1, model.njoints):
        qnames[model.idx_qs[jid]] = model.names[jid]
    coupling = Coupling(
        [c.name for c in independent],
        [c.name for c in m.coordinates],
        [cindex[c.name] for c in independent],
        steps,
        joint_steps,
        model.nq,
        [c.lower for c in independent],
        [c.upper for c in independent],
        [c.default for c in independent],
        qnames,
    )
    return model, coupling, info


def _coupler_order(m: OsimModel, dependent: dict) -> list[str]:
    """The dependent coordinates in an order where each one's source comes first; a circle of
    couplers raises naming them."""
    out, done = [], set()
    for start in dependent:
        chain, n = [], start
        while n in dependent and n not in done:
            if n in chain:
                cyc = chain[chain.index(n) :] + [n]
                cp = dependent[n]
                raise OsimError(
                    m.path,
                    f"coordinate couplers form a circle: {' <- '.join(cyc)}",
                    f"<CoordinateCouplerConstraint name={cp.name!r}>",
                    cp.line,
                )
            chain.append(n)
            n = dependent[n].independent
        for n in reversed(chain):
            if n not in done:
                out.append(n)
                done.add(n)
    return out
