"""Closed kinematic loops in Pinocchio: spanning tree as URDF + a closure list.

URDF cannot describe loops, so a closed-chain mechanism is given as

* a **spanning tree**: :class:`TreeJoint` s (revolute, prismatic, fixed, or ``"ball"`` — a
  spherical pair, written to the URDF as three revolute joints about x, y, z through one point),
  exported by :meth:`LoopSpec.urdf` and loaded with ``pin.buildModelFromXML``;
* a **closure list**: :class:`Closure` (frame_a, frame_b) pairs that must coincide — as points
  (``kind="point"``, a cut spherical/revolute pair; ``components`` restricts a planar loop to
  x, y) or as full poses (``kind="pose"``, a cut weld).

:class:`ClosedLoop` solves the loop for given input joint values by a least-norm Newton
iteration on the closure residual, using Pinocchio frame placements and frame Jacobians
(``LOCAL_WORLD_ALIGNED``); redundant directions (the passive spin of an S-S link, the
out-of-plane rows of a planar loop) are handled by the minimum-norm least-squares step.  The
same residual is also evaluated by ``pin.RigidConstraintModel`` (``CONTACT_3D`` / ``CONTACT_6D``,
:meth:`ClosedLoop.residual_pin`) as an independent check of the closure.  Velocities solve
J_c v = 0 and accelerations J_c a + gamma = 0, with gamma the constraint drift from Pinocchio's
*classical* frame accelerations at zero joint acceleration.

Units: SI (m, rad); vectors in the world frame of the tree's root link.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import AnthroarmError
from ._util import finite_array

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

__all__ = ["TreeJoint", "Closure", "LoopSpec", "LoopState", "ClosedLoop", "origin"]


def origin(xyz=(0.0, 0.0, 0.0), R=None) -> np.ndarray:
    """4x4 homogeneous joint origin from a translation and an optional rotation matrix."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(xyz, dtype=float)
    if R is not None:
        T[:3, :3] = np.asarray(R, dtype=float)
    return T


@dataclass(frozen=True)
class TreeJoint:
    """One joint of the spanning tree.  ``origin``: 4x4 pose of the joint frame in the parent
    link frame; ``axis``: joint axis in the joint frame (revolute/prismatic)."""

    name: str
    parent: str
    child: str
    type: str = "revolute"
    origin: np.ndarray = field(default_factory=lambda: np.eye(4))
    axis: tuple = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Closure:
    """Loop-closure condition: frame ``a`` and frame ``b`` coincide.

    ``kind="point"``: origins coincide (world ``components`` of p_a - p_b, default x, y, z);
    ``kind="pose"``: full placements coincide (position and orientation)."""

    frame_a: str
    frame_b: str
    kind: str = "point"
    components: tuple = (0, 1, 2)


@dataclass(frozen=True)
class LoopSpec:
    """Spanning tree + closures + driven joints of a closed-chain mechanism.

    ``sites`` are extra frames (name, parent link, 4x4 pose) used by closures and outputs;
    ``inputs`` are the names of the driven joints; ``length_scale`` (m) makes residuals relative."""

    name: str
    joints: tuple
    closures: tuple
    inputs: tuple
    sites: tuple = ()
    root: str = "ground"
    length_scale: float = 1.0

    def urdf(self) -> str:
        """The spanning tree as URDF text (balls expanded to three revolute joints)."""
        links = [self.root]
        lines = [f'<robot name="{self.name}">']
        jl = []

        def add_link(n):
            if n not in links:
                links.append(n)

        def joint_xml(name, jtype, parent, child, T, axis):
            rpy = [float(x) for x in pin.rpy.matrixToRpy(np.asarray(T[:3, :3], dtype=float))]
            xyz = [float(x) for x in T[:3, 3]]
            s = (
                f'  <joint name="{name}" type="{jtype}">\n'
                f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
                f'    <origin xyz="{xyz[0]!r} {xyz[1]!r} {xyz[2]!r}" rpy="{rpy[0]!r} {rpy[1]!r} '
                f'{rpy[2]!r}"/>\n'
            )
            if jtype in ("revolute", "prismatic"):
                a = [float(x) for x in axis]
                s += (
                    f'    <axis xyz="{a[0]!r} {a[1]!r} {a[2]!r}"/>\n'
                    '    <limit lower="-1e3" upper="1e3" effort="1" velocity="1"/>\n'
                )
            return s + "  </joint>"

        for j in self.joints:
            add_link(j.parent)
            if j.type == "ball":
                bx, by = f"{j.name}__bx", f"{j.name}__by"
                for n in (bx, by, j.child):
                    add_link(n)
                jl.append(
                    joint_xml(
                        f"{j.name}_x", "revolute", j.parent, bx, np.asarray(j.origin), (1, 0, 0)
                    )
                )
                jl.append(joint_xml(f"{j.name}_y", "revolute", bx, by, np.eye(4), (0, 1, 0)))
                jl.append(joint_xml(f"{j.name}_z", "revolute", by, j.child, np.eye(4), (0, 0, 1)))
            elif j.type in ("revolute", "prismatic", "fixed"):
                add_link(j.child)
                jl.append(
                    joint_xml(j.name, j.type, j.parent, j.child, np.asarray(j.origin), j.axis)
                )
            else:
                raise ValueError(
                    f"joint {j.name}: unknown type {j.type!r} (revolute, prismatic, fixed, ball)"
                )
        for name, parent, T in self.sites:
            add_link(name)
            jl.append(joint_xml(f"{name}__site", "fixed", parent, name, np.asarray(T), None))
        lines += [f'  <link name="{n}"/>' for n in links]
        lines += jl
        lines.append("</robot>")
        return "\n".join(lines)


@dataclass(frozen=True)
class LoopState:
    """Solved loop: tree configuration ``q``, velocity ``v``, acceleration ``a`` (Pinocchio order),
    the closure residual (m / rad, absolute), and a status ("ok", "not_converged", "singular")."""

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    residual: float
    iterations: int
    status: str
    reason: str

    @property
    def ok(self) -> bool:
        return self.status == "ok"


class ClosedLoop:
    """A closed-chain mechanism in Pinocchio (see the module docstring).

    >>> loop = ClosedLoop(spec)
    >>> st = loop.solve({"crank": 0.3}, {"crank": 1.0}, {"crank": 0.0}, q0=guess)
    >>> loop.frame_position(st.q, "B")
    """

    def __init__(self, spec: LoopSpec):
        self.spec = spec
        self.urdf = spec.urdf()
        try:
            self.model = pin.buildModelFromXML(self.urdf)
        except Exception as exc:  # C++ exceptions surface as RuntimeError/ValueError
            raise AnthroarmError(
                f"{spec.name}: Pinocchio cannot build the spanning tree: {exc}"
            ) from None
        self.data = self.model.createData()
        for n in spec.inputs:
            if not self.model.existJointName(n):
                raise ValueError(
                    f"{spec.name}: input joint {n!r} is not in the tree "
                    f"({list(self.model.names)[1:]})"
                )
        self.input_idx = np.array(
            [self.model.joints[self.model.getJointId(n)].idx_v for n in spec.inputs], dtype=int
        )
        self.free_idx = np.array(
            [i for i in range(self.model.nv) if i not in set(self.input_idx)], dtype=int
        )
        self._fid = {}
        for c in spec.closures:
            for f in (c.frame_a, c.frame_b):
                self._fid[f] = self.frame_id(f)
        self._constraints = self._build_pin_constraints()

    # ------------------------------------------------------------------ frames
    def frame_id(self, name: str) -> int:
        if not self.model.existFrame(name):
            raise ValueError(f"{self.spec.name}: unknown frame {name!r}")
        return self.model.getFrameId(name)

    def joint_q_index(self, name: str) -> int:
        return self.model.joints[self.model.getJointId(name)].idx_q

    def _fk(self, q, v=None, a=None):
        if v is None:
            pin.forwardKinematics(self.model, self.data, q)
        elif a is None:
            pin.forwardKinematics(self.model, self.data, q, v)
        else:
            pin.forwardKinematics(self.model, self.data, q, v, a)
        pin.updateFramePlacements(self.model, self.data)

    def frame_position(self, q, name: str) -> np.ndarray:
        self._fk(np.asarray(q, float))
        return self.data.oMf[self.frame_id(name)].translation.copy()

    def frame_placement(self, q, name: str) -> np.ndarray:
        self._fk(np.asarray(q, float))
        return self.data.oMf[self.frame_id(name)].homogeneous.copy()

    def frame_velocity(self, q, v, name: str) -> np.ndarray:
        """Linear velocity (m/s) of the frame origin, world-aligned (LOCAL_WORLD_ALIGNED)."""
        self._fk(np.asarray(q, float), np.asarray(v, float))
        return pin.getFrameVelocity(self.model, self.data, self.frame_id(name), LWA).linear.copy()

    def frame_acceleration(self, q, v, a, name: str) -> np.ndarray:
        """*Classical* linear acceleration (m/s^2) of the frame origin, world-aligned."""
        self._fk(np.asarray(q, float), np.asarray(v, float), np.asarray(a, float))
        return pin.getFrameClassicalAcceleration(
            self.model, self.data, self.frame_id(name), LWA
        ).linear.copy()

    # ------------------------------------------------------------------ closure residual / Jacobian
    def residual(self, q) -> np.ndarray:
        """Stacked closure residuals: p_a - p_b (selected world components) for point closures;
        p_a - p_b and log3(R_b^T R_a) for pose closures."""
        self._fk(np.asarray(q, float))
        return self._residual()

    def _residual(self):
        r = []
        for c in self.spec.closures:
            Ma, Mb = self.data.oMf[self._fid[c.frame_a]], self.data.oMf[self._fid[c.frame_b]]
            dp = Ma.translation - Mb.translation
            if c.kind == "point":
                r.append(dp[list(c.components)])
            else:
                r.append(dp)
                r.append(pin.log3(Mb.rotation.T @ Ma.rotation))
        return np.concatenate(r)

    def _jacobian(self, q):
        """Closure Jacobian (rows as in :meth:`residual`, columns = all nv) at the current q."""
        pin.computeJointJacobians(self.model, self.data, q)
        rows = []
        for c in self.spec.closures:
            Ja = pin.getFrameJacobian(self.model, self.data, self._fid[c.frame_a], LWA)
            Jb = pin.getFrameJacobian(self.model, self.data, self._fid[c.frame_b], LWA)
            D = Ja - Jb
            if c.kind == "point":
                rows.append(D[list(c.components)])
            else:
                Ma = self.data.oMf[self._fid[c.frame_a]]
                Mb = self.data.oMf[self._fid[c.frame_b]]
                rows.append(D[:3])
                rows.append(pin.Jlog3(Mb.rotation.T @ Ma.rotation) @ Ma.rotation.T @ D[3:])
        return np.vstack(rows)

    def _vel_jacobian(self, q):
        """Velocity-level constraint Jacobian (world-aligned linear / angular differences)."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        rows = []
        for c in self.spec.closures:
            D = pin.getFrameJacobian(
                self.model, self.data, self._fid[c.frame_a], LWA
            ) - pin.getFrameJacobian(self.model, self.data, self._fid[c.frame_b], LWA)
            rows.append(D[list(c.components)] if c.kind == "point" else D)
        return np.vstack(rows)

    def _drift(self, q, v):
        """gamma = (d/dt J_c) v: constraint acceleration at zero joint acceleration (classical)."""
        self._fk(q, v, np.zeros(self.model.nv))
        g = []
        for c in self.spec.closures:
            Aa = pin.getFrameClassicalAcceleration(self.model, self.data, self._fid[c.frame_a], LWA)
            Ab = pin.getFrameClassicalAcceleration(self.model, self.data, self._fid[c.frame_b], LWA)
            if c.kind == "point":
                g.append((Aa.linear - Ab.linear)[list(c.components)])
            else:
                g.append(Aa.linear - Ab.linear)
                g.append(Aa.angular - Ab.angular)
        return np.concatenate(g)

    # ------------------------------------------------------------------ pin RigidConstraintModel
    def _build_pin_constraints(self):
        cons = []
        for c in self.spec.closures:
            fa, fb = (
                self.model.frames[self._fid[c.frame_a]],
                self.model.frames[self._fid[c.frame_b]],
            )
            ctype = pin.ContactType.CONTACT_3D if c.kind == "point" else pin.ContactType.CONTACT_6D
            cm = pin.RigidConstraintModel(
                ctype,
                self.model,
                fa.parentJoint,
                fa.placement,
                fb.parentJoint,
                fb.placement,
                pin.ReferenceFrame.LOCAL,
            )
            cons.append((c, cm, cm.createData()))
        return cons

    def residual_pin(self, q) -> float:
        """Largest closure error computed by ``pin.RigidConstraintModel.calc`` (c1Mc2): the
        distance between the closure points (m), and for pose closures also |log3| (rad)."""
        self._fk(np.asarray(q, float))
        worst = 0.0
        for c, cm, cd in self._constraints:
            cm.calc(self.model, self.data, cd)
            M = cd.c1Mc2
            if c.kind == "point":
                dp = (
                    self.data.oMf[self._fid[c.frame_a]].rotation @ M.translation
                )  # world components
                worst = max(worst, float(np.linalg.norm(dp[list(c.components)])))
            else:
                worst = max(
                    worst,
                    float(np.linalg.norm(M.translation)),
                    float(np.linalg.norm(pin.log3(M.rotation))),
                )
        return worst

    # ------------------------------------------------------------------ solvers
    def _inputs(self, x, what):
        if isinstance(x, dict):
            unknown = set(x) - set(self.spec.inputs)
            if unknown:
                raise ValueError(
                    f"{self.spec.name}: {what} names unknown inputs {sorted(unknown)} (inputs: "
                    f"{list(self.spec.inputs)})"
                )
            x = [x.get(n, 0.0) for n in self.spec.inputs]
        return finite_array(
            what, np.atleast_1d(np.asarray(x, dtype=float)), (len(self.spec.inputs),)
        )

    def solve_position(self, inputs, q0=None, tol: float = 1e-13, max_iter: int = 60):
        """Newton (least-norm, with backtracking) on the closure residual with the inputs fixed.

        ``q0``: initial tree configuration (selects the assembly branch); default zeros.
        Returns (q, residual_norm, iterations, converged).  ``tol`` is relative to
        ``spec.length_scale``."""
        q = (
            np.zeros(self.model.nq)
            if q0 is None
            else finite_array("q0", q0, (self.model.nq,)).copy()
        )
        q[self.input_idx] = self._inputs(inputs, "inputs")
        scale = self.spec.length_scale
        self._fk(q)
        r = self._residual()
        nr = float(np.linalg.norm(r))
        it = 0
        for it in range(1, max_iter + 1):
            if nr <= tol * scale:
                return q, nr, it - 1, True
            J = self._jacobian(q)[:, self.free_idx]
            dx = np.linalg.lstsq(J, -r, rcond=1e-12)[0]
            step = 1.0
            while True:
                qn = q.copy()
                qn[self.free_idx] += step * dx
                self._fk(qn)
                rn = self._residual()
                nrn = float(np.linalg.norm(rn))
                if nrn < nr or step < 1e-4:
                    break
                step *= 0.5
            if nrn >= nr and step < 1e-4:
                return q, nr, it, False
            q, r, nr = qn, rn, nrn
        return q, nr, it, nr <= tol * scale

    def solve_velocity(self, q, input_velocities) -> tuple[np.ndarray, float]:
        """v with J_c v = 0 and the inputs' rates imposed (least-norm for passive spins).
        Returns (v, consistency error |J_c v|)."""
        q = np.asarray(q, float)
        v = np.zeros(self.model.nv)
        v[self.input_idx] = self._inputs(input_velocities, "input_velocities")
        self._fk(q)
        J = self._vel_jacobian(q)
        rhs = -J[:, self.input_idx] @ v[self.input_idx]
        v[self.free_idx] = np.linalg.lstsq(J[:, self.free_idx], rhs, rcond=1e-12)[0]
        return v, float(np.linalg.norm(J @ v))

    def solve_acceleration(self, q, v, input_accelerations) -> tuple[np.ndarray, float]:
        """a with J_c a + gamma = 0 (gamma from classical accelerations at a = 0); least-norm.
        Returns (a, consistency error)."""
        q, v = np.asarray(q, float), np.asarray(v, float)
        a = np.zeros(self.model.nv)
        a[self.input_idx] = self._inputs(input_accelerations, "input_accelerations")
        gamma = self._drift(q, v)
        J = self._vel_jacobian(q)
        rhs = -gamma - J[:, self.input_idx] @ a[self.input_idx]
        a[self.free_idx] = np.linalg.lstsq(J[:, self.free_idx], rhs, rcond=1e-12)[0]
        return a, float(np.linalg.norm(J @ a + gamma))

    def solve(
        self,
        inputs,
        input_velocities=None,
        input_accelerations=None,
        q0=None,
        tol: float = 1e-13,
        consistency_tol: float = 1e-9,
    ) -> LoopState:
        """Positions, velocities and accelerations of the whole tree for the given inputs."""
        nin = len(self.spec.inputs)
        iv = np.zeros(nin) if input_velocities is None else input_velocities
        ia = np.zeros(nin) if input_accelerations is None else input_accelerations
        q, res, it, conv = self.solve_position(inputs, q0, tol=tol)
        if not conv:
            z = np.zeros(self.model.nv)
            return LoopState(
                q,
                z,
                z.copy(),
                res,
                it,
                "not_converged",
                f"Newton did not close the loop (|residual| = {res:.3e}): the inputs may be "
                "outside the assembly range, or q0 is too far from a solution",
            )
        v, ev = self.solve_velocity(q, iv)
        a, ea = self.solve_acceleration(q, v, ia)
        scale = self.spec.length_scale
        vnorm = 1.0 + float(np.linalg.norm(self._inputs(iv, "input_velocities")))
        if ev > consistency_tol * scale * vnorm or ea > consistency_tol * scale * vnorm**2:
            return LoopState(
                q,
                v,
                a,
                res,
                it,
                "singular",
                f"closure Jacobian is singular here (velocity inconsistency {ev:.3e}): dead point "
                "/ branch point",
            )
        return LoopState(q, v, a, res, it, "ok", "ok")

    def track(self, input_path, q0=None, tol: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
        """Continuation: solve for each row of ``input_path`` (K x n_inputs) starting from the
        previous solution moved along the tangent (the velocity solution).  Keep the steps small
        compared with the distance between assembly branches.  Returns (Q (K x nq), converged
        (K,))."""
        P = finite_array(
            "input_path",
            np.asarray(input_path, float).reshape(len(input_path), -1),
            (None, len(self.spec.inputs)),
        )
        Q = np.zeros((len(P), self.model.nq))
        ok = np.zeros(len(P), dtype=bool)
        q = None if q0 is None else np.asarray(q0, float)
        x_prev = None
        for k, x in enumerate(P):
            guess = q
            if q is not None and x_prev is not None:
                # tangent predictor: q + dq/dx (x - x_prev), from the velocity solution
                v, _ = self.solve_velocity(q, x - x_prev)
                guess = q + v  # revolute/prismatic trees: nq == nv, q integrates additively
            qk, _, _, conv = self.solve_position(x, guess, tol=tol)
            Q[k], ok[k] = qk, conv
            if conv:
                q, x_prev = qk, x
        return Q, ok
