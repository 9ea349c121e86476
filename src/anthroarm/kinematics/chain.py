"""Batched forward kinematics and Jacobians of any serial chain, read off a Pinocchio model.

:class:`SerialChain` extracts, once, each joint's placement in its parent and its axis
(revolute or prismatic, aligned with x, y, z or not) and the tool frame's placement; then
evaluates the product of exponentials

    T_0,tool(q) = M_1 exp(a_1 q_1) M_2 exp(a_2 q_2) … M_n exp(a_n q_n) M_tool

for a whole batch of configurations at once with numpy.  It is our closed form for robots
without a book formula (panda, ur5, …) and the workhorse of the batched benchmarks.  The
Jacobian is the geometric one, LOCAL_WORLD_ALIGNED, rows (v; ω).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import UnsupportedModelError


def _axis_and_kind(jm) -> tuple[str, np.ndarray]:
    name = jm.shortname()
    table = {
        "JointModelRX": ("R", (1, 0, 0)), "JointModelRY": ("R", (0, 1, 0)), "JointModelRZ": ("R", (0, 0, 1)),
        "JointModelPX": ("P", (1, 0, 0)), "JointModelPY": ("P", (0, 1, 0)), "JointModelPZ": ("P", (0, 0, 1)),
    }
    if name in table:
        k, a = table[name]
        return k, np.array(a, float)
    if name == "JointModelRevoluteUnaligned":
        return "R", np.array(jm.extract().axis, float)
    if name == "JointModelPrismaticUnaligned":
        return "P", np.array(jm.extract().axis, float)
    raise UnsupportedModelError(f"joint type {name} is not a 1-DOF revolute/prismatic joint")


def _rodrigues(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices exp([axis]× angle), shape (N, 3, 3); axis is a unit 3-vector."""
    x, y, z = axis
    c, s = np.cos(angle), np.sin(angle)
    C = 1.0 - c
    R = np.empty(angle.shape + (3, 3))
    R[..., 0, 0] = c + x * x * C
    R[..., 0, 1] = x * y * C - z * s
    R[..., 0, 2] = x * z * C + y * s
    R[..., 1, 0] = y * x * C + z * s
    R[..., 1, 1] = c + y * y * C
    R[..., 1, 2] = y * z * C - x * s
    R[..., 2, 0] = z * x * C - y * s
    R[..., 2, 1] = z * y * C + x * s
    R[..., 2, 2] = c + z * z * C
    return R


class SerialChain:
    """The serial chain from the base to ``frame`` of a Robot (or pin model)."""

    def __init__(self, model: pin.Model, frame_id: int):
        self.model = model
        f = model.frames[frame_id]
        chain = []
        jid = f.parentJoint
        while jid > 0:
            chain.append(jid)
            jid = model.parents[jid]
        chain.reverse()
        self.joint_ids = chain
        self.q_index = []
        self.kinds, self.axes, self.R0, self.p0 = [], [], [], []
        for jid in chain:
            jm = model.joints[jid]
            if jm.nq != 1 or jm.nv != 1:
                raise UnsupportedModelError(f"joint {model.names[jid]} has nq={jm.nq}; only 1-DOF joints are supported")
            k, a = _axis_and_kind(jm)
            self.kinds.append(k)
            self.axes.append(a / np.linalg.norm(a))
            M = model.jointPlacements[jid]
            self.R0.append(np.array(M.rotation))
            self.p0.append(np.array(M.translation))
            self.q_index.append(jm.idx_q)
        self.tool_R = np.array(f.placement.rotation)
        self.tool_p = np.array(f.placement.translation)
        self.nq = model.nq

    @classmethod
    def of(cls, robot, frame=None) -> "SerialChain":
        return cls(robot.model, robot.frame_id(frame))

    def _batch(self, q):
        q = np.asarray(q, float)
        single = q.ndim == 1
        q2 = q[None] if single else q
        if q2.ndim != 2 or q2.shape[1] != self.nq:
            raise ValueError(f"q must have shape ({self.nq},) or (N, {self.nq}), got {q.shape}")
        if not np.isfinite(q2).all():
            raise ValueError(f"q[{int(np.argwhere(~np.isfinite(q2))[0, 1])}] is not finite")
        return q2, single

    def _walk(self, q2):
        """World rotation/position of every joint frame (after its motion) and of the tool."""
        N = q2.shape[0]
        R = np.broadcast_to(np.eye(3), (N, 3, 3))
        p = np.zeros((N, 3))
        Rs, ps = [], []
        for k, a, R0, p0, iq in zip(self.kinds, self.axes, self.R0, self.p0, self.q_index):
            p = p + R @ p0
            R = R @ R0
            Rs.append(R)
            ps.append(p)
            qj = q2[:, iq]
            if k == "R":
                R = R @ _rodrigues(a, qj)
            else:
                p = p + (R @ a) * qj[:, None]
        p_tool = p + R @ self.tool_p
        R_tool = R @ self.tool_R
        return Rs, ps, R_tool, p_tool

    def fk(self, q) -> np.ndarray:
        """Tool pose in the base frame, (4, 4) or (N, 4, 4)."""
        q2, single = self._batch(q)
        _, _, R, p = self._walk(q2)
        T = np.zeros((q2.shape[0], 4, 4))
        T[:, :3, :3] = R
        T[:, :3, 3] = p
        T[:, 3, 3] = 1.0
        return T[0] if single else T

    def fk_jacobian(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Tool pose and its LOCAL_WORLD_ALIGNED Jacobian (6 × nv, rows (v; ω)) together."""
        q2, single = self._batch(q)
        Rs, ps, R, p = self._walk(q2)
        N = q2.shape[0]
        J = np.zeros((N, 6, self.model.nv))
        for k, a, Rj, pj, jid in zip(self.kinds, self.axes, Rs, ps, self.joint_ids):
            col = self.model.joints[jid].idx_v
            w = Rj @ a  # joint axis in world (the axis is invariant under its own rotation)
            if k == "R":
                J[:, :3, col] = np.cross(w, p - pj)
                J[:, 3:, col] = w
            else:
                J[:, :3, col] = w
        T = np.zeros((N, 4, 4))
        T[:, :3, :3] = R
        T[:, :3, 3] = p
        T[:, 3, 3] = 1.0
        return (T[0], J[0]) if single else (T, J)

    def jacobian(self, q) -> np.ndarray:
        return self.fk_jacobian(q)[1]
