"""IKConfiguration: a robot at a configuration q, with cached kinematics for the QP tasks.

One ``update(q)`` runs ``pin.computeJointJacobians`` (forward kinematics + every joint Jacobian,
one pass); frame placements and frame Jacobians are then read lazily and cached until the next
update.  ``integrate(v, dt)`` maps a tangent velocity back onto the configuration space with
``pin.integrate`` (exact on Lie groups, plain ``q + v dt`` for revolute/prismatic joints).

Frames and units: placements are world poses (SE(3), m); Jacobians are 6 × nv with rows
(v; ω) in the requested reference frame (``LOCAL`` by default, the body Jacobian that the book
writes in the hand frame, Eq. (7-94)).

An OpenSim model with nonlinear couplings (``robot.coupling``: gait2392's spline knees) is
configured in its independent coordinates: ``q`` is ``robot.nq`` coordinates (rad or m, within
``robot.lower``/``upper``, named ``robot.joint_names``), Pinocchio's kinematics are computed at
φ(q), every frame Jacobian is J(φ(q)) · G(q) with G = dφ/dq (the chain rule; Jain, *Robot and
Multibody Dynamics* (2011), §8), and ``integrate`` is q + v dt.  The tasks and limits read
these, so they all work in the coordinates.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ...chain import CONTINUOUS
from ...osim.coupling import FastCoupling

LOCAL = pin.ReferenceFrame.LOCAL
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
WORLD = pin.ReferenceFrame.WORLD


def ranged_joints(chain) -> list:
    """The joints of ``chain`` that have a position range of their own: the independent
    revolute and prismatic joints (one entry of q, one of v; their limits may be infinite).
    A continuous joint has no range and a mimic joint follows its source."""
    return [j for j in chain.joints if not j.is_mimic and j.kind != CONTINUOUS]


class IKConfiguration:
    """A configuration ``q`` of ``robot`` plus the kinematic quantities tasks need.

    Parameters
    ----------
    robot : anthroarm.Robot
        The arm (its ``model`` is shared; this object owns a fresh ``pin.Data``).
    q : array (nq,), optional
        Initial configuration (default ``robot.neutral()``), Pinocchio's layout ((cos θ, sin θ)
        for a continuous joint); the independent coordinates for a model with
        ``robot.coupling``.  It may lie outside the joint limits: the limits of
        :func:`anthroarm.ik.qp.step` then pull it back inside.

    Notes
    -----
    ``lower``/``upper`` are the limits in q order (``robot.chain.lower``/``upper``, read-only;
    ±1 on a continuous joint's entries, which :meth:`within_limits` does not test; the
    coordinate ranges ``robot.lower``/``upper`` with a coupling).  ``coupling`` is None, or the
    :class:`~anthroarm.osim.coupling.FastCoupling` of ``robot.coupling``; then ``G`` is dφ/dq at
    ``q`` (``model.nv`` × nv) and ``q_full`` = φ(q), the configuration Pinocchio's ``data``
    holds.
    """

    def __init__(self, robot, q=None):
        self.robot = robot
        self.model: pin.Model = robot.model
        self.data: pin.Data = robot.model.createData()
        c = getattr(robot, "coupling", None)
        self.coupling = None if c is None else FastCoupling(c)
        self.G = None
        self.q_full = None
        if c is not None:  # the independent coordinates, each with its range
            self.nq = self.nv = robot.nq
            self.lower, self.upper = robot.lower, robot.upper
            self._bounded, self._unit = None, False
            self._names = list(robot.joint_names)
        else:
            chain = robot.chain
            self.nq = chain.nq
            self.nv = chain.nv
            self.lower = chain.lower
            self.upper = chain.upper
            # q indices of the bounded joints (continuous and mimic joints have no range of
            # their own)
            bounded = [j.idx_q for j in ranged_joints(chain)]
            self._bounded = (
                None if bounded == list(range(self.nq)) else np.array(bounded, dtype=int)
            )
            self._unit = chain.has_continuous
            self._names = chain.q_names
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
        self._kinematics()

    def _kinematics(self) -> None:
        # every joint Jacobian at q (at φ(q) with a coupling, then G = dφ/dq), caches cleared
        if self.coupling is None:
            pin.computeJointJacobians(self.model, self.data, self.q)
        else:
            self.q_full, self.G = self.coupling.jacobian(self.q)
            pin.computeJointJacobians(self.model, self.data, self.q_full)
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
        """Frame Jacobian 6 × nv, rows (v; ω), in ``reference`` (default LOCAL); J(φ(q)) G
        in the coordinates of a model with a coupling."""
        key = (frame_id, reference)
        J = self._jacobians.get(key)
        if J is None:
            self.frame_placement(frame_id)
            J = pin.getFrameJacobian(self.model, self.data, frame_id, reference)
            if self.G is not None:
                J = J @ self.G
            self._jacobians[key] = J
        return J

    def transform(self, frame_id: int, root_id: int) -> pin.SE3:
        """Pose of ``frame_id`` relative to ``root_id``: T_root⁻¹ T_frame."""
        return self.frame_placement(root_id).actInv(self.frame_placement(frame_id))

    # ------------------------------------------------------------------ motion
    def integrate(self, v, dt: float) -> np.ndarray:
        """Configuration reached by moving at tangent velocity ``v`` (nv,) for ``dt`` seconds
        (q + v dt in the coordinates of a model with a coupling)."""
        if self.coupling is not None:
            return self.q + np.asarray(v, dtype=float) * dt
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
        # finite q + finite step: no re-check
        self.q = self.q + dq if self.coupling is not None else pin.integrate(self.model, self.q, dq)
        self._kinematics()

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
        names = self._names
        out = []
        for i in idx:
            v, lo, hi = self.q[i], self.lower[i], self.upper[i]
            if v < lo - tol or v > hi + tol:
                out.append(f"{names[i]}={v:.6g} not in [{lo:.6g}, {hi:.6g}]")
        return out
