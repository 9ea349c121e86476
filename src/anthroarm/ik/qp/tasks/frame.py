"""FrameTask: drive a frame to a target pose (position and orientation costs separate).

Residual (body twist in the frame, rows (v; ω), m and rad), as in pink:

    e(q) = log₆(T_b⁻¹ T_t),   J(q) = −Jlog₆(T_t⁻¹ T_b) · ᵇJ(q)

with T_b the world pose of the frame, T_t the target and ᵇJ the LOCAL frame Jacobian (the
hand-frame Jacobian of the book, Eq. (7-94)).  ``position_cost`` weights the three linear
rows ([cost]/m), ``orientation_cost`` the three angular rows ([cost]/rad); either may be a
3-vector (anisotropic costs; 0 frees an axis).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..configuration import LOCAL
from ..targets import as_se3
from .base import Task


class FrameTask(Task):
    """Pose task on ``frame`` (name or id; default the robot's tool)."""

    def __init__(self, robot, frame=None, position_cost=1.0, orientation_cost=1.0, gain: float = 1.0,
                 lm_damping: float = 0.0, target=None):
        pc = np.broadcast_to(np.asarray(position_cost, dtype=float), (3,))
        oc = np.broadcast_to(np.asarray(orientation_cost, dtype=float), (3,))
        super().__init__(cost=np.concatenate([pc, oc]), gain=gain, lm_damping=lm_damping)
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.model.frames[self.frame_id].name
        self._wcol = self.cost[:, None].copy()
        self._wg = self.cost * self.gain
        self.target: pin.SE3 | None = None
        if target is not None:
            self.set_target(target)

    def __repr__(self) -> str:
        return f"FrameTask({self.frame!r}, cost={self.cost.tolist()}, gain={self.gain}, lm_damping={self.lm_damping})"

    @property
    def position_cost(self) -> np.ndarray:
        return self.cost[:3]

    @property
    def orientation_cost(self) -> np.ndarray:
        return self.cost[3:]

    def set_target(self, T) -> None:
        """Target world pose: 4×4 rigid transform or ``pin.SE3`` (``ValueError`` otherwise)."""
        self.target = as_se3(T, "FrameTask target")

    def set_target_from_configuration(self, conf) -> None:
        """Target = the frame's current pose in ``conf``."""
        self.target = pin.SE3(conf.frame_placement(self.frame_id))

    def _require_target(self):
        if self.target is None:
            raise ValueError(f"FrameTask({self.frame!r}): no target set (call set_target)")
        return self.target

    def compute_error(self, conf) -> np.ndarray:
        T_t = self._require_target()
        return pin.log6(conf.frame_placement(self.frame_id).actInv(T_t)).vector

    def compute_jacobian(self, conf) -> np.ndarray:
        T_t = self._require_target()
        T_tb = T_t.actInv(conf.frame_placement(self.frame_id))
        return -pin.Jlog6(T_tb) @ conf.frame_jacobian(self.frame_id, LOCAL)

    def compute_qp_objective(self, conf):
        # Task._objective written out for speed, with Jl = Jlog6 · ᵇJ = −J:
        # H = (W Jl)ᵀ(W Jl) + μ I,  c = α JᵀW²e = −(W Jl)ᵀ(α W e)
        T_t = self.target
        if T_t is None:
            self._require_target()
        T_b = conf.frame_placement(self.frame_id)
        e = pin.log6(T_b.actInv(T_t)).vector
        WJ = self._wcol * (pin.Jlog6(T_t.actInv(T_b)) @ conf.frame_jacobian(self.frame_id, LOCAL))
        We = self._wg * e
        H = WJ.T @ WJ
        if self.lm_damping:
            H.flat[:: conf.nv + 1] += self.lm_damping * float(We @ We)
        return H, -(WJ.T @ We)
