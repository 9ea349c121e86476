"""RelativeFrameTask: drive the pose of ``frame`` relative to ``root`` to a target.

T_rf(q) = T_r⁻¹ T_f; target T_rt.  Same convention as FrameTask, with the relative body twist:

    e(q) = log₆(T_rf⁻¹ T_rt),   J(q) = −Jlog₆(T_rt⁻¹ T_rf) · (ᶠJ_f − Ad(T_rf⁻¹) ʳJ_r)

where ᶠJ_f, ʳJ_r are LOCAL frame Jacobians and Ad the 6×6 adjoint for (v; ω) rows.  Use it for
the hand relative to the forearm, or one hand relative to the other.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..configuration import LOCAL
from ..targets import as_se3
from .base import Task


class RelativeFrameTask(Task):
    def __init__(
        self,
        robot,
        frame,
        root,
        position_cost=1.0,
        orientation_cost=1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
        target=None,
    ):
        pc = np.broadcast_to(np.asarray(position_cost, dtype=float), (3,))
        oc = np.broadcast_to(np.asarray(orientation_cost, dtype=float), (3,))
        super().__init__(cost=np.concatenate([pc, oc]), gain=gain, lm_damping=lm_damping)
        self.frame_id = robot.frame_id(frame)
        self.root_id = robot.frame_id(root)
        self.frame = robot.chain.frame(self.frame_id).name
        self.root = robot.chain.frame(self.root_id).name
        self.target = None
        if target is not None:
            self.set_target(target)

    def set_target(self, T) -> None:
        """Target pose of ``frame`` in ``root`` (4×4 rigid or ``pin.SE3``)."""
        self.target = as_se3(T, "RelativeFrameTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.transform(self.frame_id, self.root_id)

    def _require_target(self):
        if self.target is None:
            raise ValueError(f"RelativeFrameTask({self.frame!r} in {self.root!r}): no target set")
        return self.target

    def compute_error(self, conf):
        T_rt = self._require_target()
        return pin.log6(conf.transform(self.frame_id, self.root_id).actInv(T_rt)).vector

    def compute_jacobian(self, conf):
        T_rt = self._require_target()
        T_rf = conf.transform(self.frame_id, self.root_id)
        J_rel = conf.frame_jacobian(
            self.frame_id, LOCAL
        ) - T_rf.inverse().action @ conf.frame_jacobian(self.root_id, LOCAL)
        return -pin.Jlog6(T_rt.actInv(T_rf)) @ J_rel
