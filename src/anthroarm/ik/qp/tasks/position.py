"""PositionTask: drive the origin of a frame to a target point (world frame, m).

    e(q) = p(q) − p_t,   J(q) = ⁰J_v(q)  (linear rows of the LOCAL_WORLD_ALIGNED Jacobian)

The book's position-only iterations (Ch. 7 §7-6, f(Q) = Σ (x_i − x_i*)²) minimise ‖e‖².
"""

from __future__ import annotations

import numpy as np

from ..configuration import LWA
from ..targets import as_position
from .base import FrameAxesTask


class PositionTask(FrameAxesTask):
    """Position task on ``frame`` (default: the robot's tool).  ``cost`` may be a 3-vector
    (world x, y, z weights, [cost]/m); 0 frees an axis (e.g. the planar 2R arm uses (0, 1, 1))."""

    def set_target(self, p) -> None:
        """Target position (3,), m, world frame."""
        self.target = as_position(p, "PositionTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.frame_placement(self.frame_id).translation.copy()

    def compute_error(self, conf) -> np.ndarray:
        return conf.frame_placement(self.frame_id).translation - self._require_target()

    def compute_jacobian(self, conf) -> np.ndarray:
        return conf.frame_jacobian(self.frame_id, LWA)[:3]
