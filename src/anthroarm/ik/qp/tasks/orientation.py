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
from .base import FrameAxesTask


class OrientationTask(FrameAxesTask):
    """Orientation task on ``frame`` (default: the robot's tool); ``cost`` [cost]/rad, scalar
    or a 3-vector over the frame's axes."""

    def set_target(self, R) -> None:
        """Target rotation (3×3, world frame); a 4×4 transform uses its rotation block."""
        R = np.asarray(R, dtype=float)
        if R.shape == (4, 4):
            R = R[:3, :3]
        self.target = as_rotation(R, "OrientationTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.frame_placement(self.frame_id).rotation.copy()

    def compute_error(self, conf) -> np.ndarray:
        R = conf.frame_placement(self.frame_id).rotation
        return pin.log3(R.T @ self._require_target())

    def compute_jacobian(self, conf) -> np.ndarray:
        R = conf.frame_placement(self.frame_id).rotation
        return (
            -pin.Jlog3(self._require_target().T @ R) @ conf.frame_jacobian(self.frame_id, LOCAL)[3:]
        )
