"""PositionTask: drive the origin of a frame to a target point (world frame, m).

    e(q) = p(q) − p_t,   J(q) = ⁰J_v(q)  (linear rows of the LOCAL_WORLD_ALIGNED Jacobian)

The book's position-only iterations (Ch. 7 §7-6, f(Q) = Σ (x_i − x_i*)²) minimise ‖e‖².
"""

from __future__ import annotations

import numpy as np

from ..configuration import LWA
from ..targets import as_position
from .base import Task


class PositionTask(Task):
    """Position task on ``frame`` (default: the robot's tool).  ``cost`` may be a 3-vector
    (world x, y, z weights, [cost]/m); 0 frees an axis (e.g. the planar 2R arm uses (0, 1, 1))."""

    def __init__(self, robot, frame=None, cost=1.0, gain: float = 1.0, lm_damping: float = 0.0, target=None):
        super().__init__(cost=np.broadcast_to(np.asarray(cost, dtype=float), (3,)).copy(), gain=gain,
                         lm_damping=lm_damping)
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.model.frames[self.frame_id].name
        self.target = None
        if target is not None:
            self.set_target(target)

    def set_target(self, p) -> None:
        """Target position (3,), m, world frame."""
        self.target = as_position(p, "PositionTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.frame_placement(self.frame_id).translation.copy()

    def compute_error(self, conf) -> np.ndarray:
        if self.target is None:
            raise ValueError(f"PositionTask({self.frame!r}): no target set (call set_target)")
        return conf.frame_placement(self.frame_id).translation - self.target

    def compute_jacobian(self, conf) -> np.ndarray:
        return conf.frame_jacobian(self.frame_id, LWA)[:3]
