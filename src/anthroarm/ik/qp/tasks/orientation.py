"""OrientationTask: drive the orientation of a frame to a target rotation (rad).

    e(q) = log₃(R(q)ᵀ R_t)  (in the frame),   J(q) = −Jlog₃(R_tᵀ R(q)) · ᵇJ_ω(q)

with ᵇJ_ω the angular rows of the LOCAL frame Jacobian.  Same convention as the angular half
of :class:`~anthroarm.ik.qp.tasks.frame.FrameTask`.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..configuration import LOCAL
from ..targets import as_rotation
from .base import Task


class OrientationTask(Task):
    """Orientation task on ``frame`` (default: the robot's tool); ``cost`` [cost]/rad, scalar
    or a 3-vector over the frame's axes."""

    def __init__(self, robot, frame=None, cost=1.0, gain: float = 1.0, lm_damping: float = 0.0, target=None):
        super().__init__(cost=np.broadcast_to(np.asarray(cost, dtype=float), (3,)).copy(), gain=gain,
                         lm_damping=lm_damping)
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.model.frames[self.frame_id].name
        self.target = None
        if target is not None:
            self.set_target(target)

    def set_target(self, R) -> None:
        """Target rotation (3×3, world frame); a 4×4 transform uses its rotation block."""
        R = np.asarray(R, dtype=float)
        if R.shape == (4, 4):
            R = R[:3, :3]
        self.target = as_rotation(R, "OrientationTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.frame_placement(self.frame_id).rotation.copy()

    def compute_error(self, conf) -> np.ndarray:
        if self.target is None:
            raise ValueError(f"OrientationTask({self.frame!r}): no target set (call set_target)")
        R = conf.frame_placement(self.frame_id).rotation
        return pin.log3(R.T @ self.target)

    def compute_jacobian(self, conf) -> np.ndarray:
        if self.target is None:
            raise ValueError(f"OrientationTask({self.frame!r}): no target set (call set_target)")
        R = conf.frame_placement(self.frame_id).rotation
        return -pin.Jlog3(self.target.T @ R) @ conf.frame_jacobian(self.frame_id, LOCAL)[3:]
