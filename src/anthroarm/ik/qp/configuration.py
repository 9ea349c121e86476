"""IKConfiguration: a robot at a configuration q, with cached kinematics for the QP tasks.

One ``update(q)`` runs ``pin.computeJointJacobians`` (forward kinematics + every joint Jacobian,
one pass); frame placements and frame Jacobians are then read lazily and cached until the next
update.  ``integrate(v, dt)`` maps a tangent velocity back onto the configuration space with
``pin.integrate`` (exact on Lie groups, plain ``q + v dt`` for revolute/prismatic joints).

Frames and units: placements are world poses (SE(3), m); Jacobians are 6 × nv with rows
(v; ω) in the requested reference frame (``LOCAL`` by default, the body Jacobian that the book
writes in the hand frame, Eq. (7-94)).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ...chain import CONTINUOUS
from ...errors import UnsupportedModelError

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
WORLD = pin.ReferenceFrame.WORLD


def ranged_joints(chain) -> list:
    """The joints of ``chain`` that have a position range of their own: the independent
    revolute and prismatic joints (one entry of q, one of v; their limits may be infinite).
    A continuous joint has no range and a mimic joint follows its source."""
    return [j for j in chain.joints if not j.is_mimic and j.kind != CONTINUOUS]


def refuse_coupled(robot, what: str) -> None:
    """Raise :class:`~anthroarm.errors.UnsupportedModelError` for a robot whose Pinocchio joints
    are nonlinear functions φ(q) of its coordinates (an OpenSim model with ``robot.coupling``):
    ``what`` works in Pinocchio's joints, whose values would not stay on the coupling."""
    c = getattr(robot, "coupling", None)
    if c is not None:
        raise UnsupportedModelError(
            f"{robot.name}: {what} works in Pinocchio's {c.nq_full} joints, but this OpenSim "
            f"model moves them as functions of its {c.nq} coordinates (robot.coupling: spline "
            "or coupler constraints); use anthroarm.motion.osim_ik.CoupledMarkerIK / "
            "osim_marker_ik (marker IK in the coordinates), with a frame's target as a marker "
            "(robot.fk, robot.jacobian are in the coordinates)"
        )


class IKConfiguration:
    """A configuration ``q`` of ``robot`` plus the kinematic quantities tasks need.

    Parameters
    ----------
    robot : anthroarm.Robot
        The arm (its ``model`` is shared; this object owns a fresh ``pin.Data``).
    q : array (nq,), optional
        Initial configuration (default ``robot.neutral()``), Pinocchio's layout ((cos θ, sin θ)
        for a continuous joint).  It may lie outside the joint limits: the limits of
        :func:`anthroarm.ik.qp.step` then pull it back inside.

    Notes
    -----
    ``lower``/``upper`` are the limits in q order (``robot.chain.lower``/``upper``, read-only;
    ±1 on a continuous joint's entries, which :meth:`within_limits` does not test).
    """

    def __init__(self, robot, q=None):
        refuse_coupled(robot, "the QP layer (IKConfiguration)")
        self.robot = robot
        self.model: pin.Model = robot.model
        self.data: pin.Data = robot.model.createData()
        chain = robot.chain
        self.nq = chain.nq
        self.nv = chain.nv
        self.lower = chain.lower
        self.upper = chain.upper
        # q indices of the bounded joints (continuous and mimic joints have no range of their own)
        bounded = [j.idx_q for j in ranged_joints(chain)]
        self._bounded = None if bounded == list(range(self.nq)) else np.array(bounded, dtype=int)
        self._unit = chain.has_continuous
        self.q = np.zeros(self.nq)
        self._placements: dict = {}
        self._jacobians: dict = {}
        self._dt = None
        self._dtv = None
        self.update(robot.neutral() if q is None else q)

    def __repr__(self) -> str:
        return f"IKConfiguration({self.robot.name!r}, q={np.array2string(self.q, precision=4)})"

    # ------------------------------------------------------------------ state
    def update(self, q=None) -> None:
        """Set ``q`` (a copy is kept) and recompute the kinematics.  ``ValueError`` for a wrong
        shape, a non-finite entry or a continuous joint's (cos, sin) pair that is not a unit
        vector (naming the joint)."""
        if q is not None:
            q = np.asarray(q, dtype=float)
            if q.shape != (self.nq,) or not np.isfinite(q).all():
                self.robot.check_q(q if q.ndim == 1 else q, name="q")  # raises with the joint name
                if q.shape != (self.nq,):
                    raise ValueError(
                        f"{self.robot.name}: q must have shape ({self.nq},), got {q.shape}"
                    )
            if self._unit:
                self.robot.chain.check_unit(q)
            self.q = q.copy()
        pin.computeJointJacobians(self.model, self.data, self.q)
        self._placements.clear()
        self._jacobians.clear()

    def frame_placement(self, frame_id: int) -> pin.SE3:
        """World pose of frame ``frame_id`` (SE(3), m)."""
        M = self._placements.get(frame_id)
        if M is None:
            M = self._placements[frame_id] = pin.updateFramePlacement(
                self.model, self.data, frame_id
            )
        return M

    def frame_jacobian(self, frame_id: int, reference=LOCAL) -> np.ndarray:
        """Frame Jacobian 6 × nv, rows (v; ω), in ``reference`` (default LOCAL)."""
        key = (frame_id, reference)
        J = self._jacobians.get(key)
        if J is None:
            self.frame_placement(frame_id)
            J = pin.getFrameJacobian(self.model, self.data, frame_id, reference)
            self._jacobians[key] = J
        return J

    def transform(self, frame_id: int, root_id: int) -> pin.SE3:
        """Pose of ``frame_id`` relative to ``root_id``: T_root⁻¹ T_frame."""
        return self.frame_placement(root_id).actInv(self.frame_placement(frame_id))

    # ------------------------------------------------------------------ motion
    def integrate(self, v, dt: float) -> np.ndarray:
        """Configuration reached by moving at tangent velocity ``v`` (nv,) for ``dt`` seconds."""
        return pin.integrate(self.model, self.q, np.asarray(v, dtype=float) * dt)

    def integrate_inplace(self, v, dt: float) -> None:
        """``update(integrate(v, dt))``."""
        v = np.asarray(v, dtype=float)
        if v.shape != (self.nv,) or not math.isfinite(v.dot(v)):
            raise ValueError(
                f"{self.robot.name}: v must be a finite array of shape ({self.nv},), got {v!r}"
            )
        if dt.__class__ is float:  # dt as an array: v·dt array-wise costs less
            if dt != self._dt:
                if not math.isfinite(dt):
                    raise ValueError(f"dt must be a finite time step (s), got {dt}")
                self._dtv = np.full(self.nv, dt)
                self._dt = dt
            dq = v * self._dtv
        else:
            if not np.all(np.isfinite(dt)):
                raise ValueError(f"dt must be a finite time step (s), got {dt!r}")
            dq = v * dt
        self.q = pin.integrate(self.model, self.q, dq)  # finite q + finite step: no re-check
        pin.computeJointJacobians(self.model, self.data, self.q)
        self._placements.clear()
        self._jacobians.clear()

    def within_limits(self, tol: float = 0.0) -> bool:
        """True when every bounded joint lies within [lower − tol, upper + tol]."""
        b = self._bounded
        if b is None:
            return bool(np.all(self.q >= self.lower - tol) and np.all(self.q <= self.upper + tol))
        q = self.q[b]
        return bool(np.all(q >= self.lower[b] - tol) and np.all(q <= self.upper[b] + tol))

    def limit_violations(self, tol: float = 0.0) -> list[str]:
        """Names of the bounded joints outside their limits (with the value and the range)."""
        idx = range(self.nq) if self._bounded is None else self._bounded.tolist()
        names = self.robot.chain.q_names
        out = []
        for i in idx:
            v, lo, hi = self.q[i], self.lower[i], self.upper[i]
            if v < lo - tol or v > hi + tol:
                out.append(f"{names[i]}={v:.6g} not in [{lo:.6g}, {hi:.6g}]")
        return out
