"""ContactNormalTask: align an axis fixed in a frame with a direction in the world.

A fingertip touching an object presses its pad against the surface: the pad's outward normal
``a`` (a unit vector fixed in the fingertip frame) must point against the object's outward
surface normal ``m`` at the contact, i.e. along the target direction ``d = −m``.  Residual
(world frame, unitless, 3 rows) and Jacobian::

    e(q) = R(q) a − d,        J(q) = −[R(q) a]ₓ ⁰J_ω(q)

with R the frame's world rotation, [·]ₓ the cross-product matrix and ⁰J_ω the angular rows of
the LOCAL_WORLD_ALIGNED frame Jacobian (ω in world axes): the axis moves as d(Ra)/dt = ω × Ra
= −[Ra]ₓ ω.  ‖e‖ = 2 sin(θ/2) for the angle θ between Ra and d, so the residual grows
monotonically with the misalignment up to θ = π; J has rank 2 (a rotation about the axis itself
does not change it: the task leaves that rotation free, unlike an
:class:`~anthroarm.ik.qp.tasks.orientation.OrientationTask`).  This is the contact-normal
condition of a fingertip (point contact with friction) grasp, written as a cost, as the
orientation half of a soft-finger contact in Murray, Li & Sastry, *A Mathematical Introduction
to Robotic Manipulation* (1994), §5.2.
"""

from __future__ import annotations

import numpy as np

from ..configuration import LWA
from .base import FrameAxesTask


def unit_vector(v, what: str) -> np.ndarray:
    """``v`` as a unit (3,) float vector; ``ValueError`` naming ``what`` for a wrong shape, a
    non-finite entry or a (near-)zero vector."""
    a = np.asarray(v, dtype=float)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"{what} must be a finite 3-vector, got {v!r}")
    n = float(np.linalg.norm(a))
    if not n > 1e-12:
        raise ValueError(f"{what} must be a nonzero 3-vector (it is normalised), got {v!r}")
    return a / n


def cross_matrix(a) -> np.ndarray:
    """[a]ₓ (3, 3): [a]ₓ b = a × b."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


class ContactNormalTask(FrameAxesTask):
    """Axis ``axis`` of ``frame`` (unit, in the frame's own axes; default z) along the world
    direction set by :meth:`set_target`.  ``cost`` is unitless per unit of residual (scalar or
    a 3-vector over the world axes).

    Parameters
    ----------
    robot : anthroarm.Robot
    frame : str or int, optional
        Frame name or id (default: the robot's tool).
    axis : array (3,)
        The axis in the frame (normalised; a zero or non-finite vector is a ``ValueError``).
    cost, gain, lm_damping
        As for every :class:`~anthroarm.ik.qp.tasks.base.Task`.
    target : array (3,), optional
        Target direction in world axes (normalised).
    """

    def __init__(
        self,
        robot,
        frame=None,
        axis=(0.0, 0.0, 1.0),
        cost=1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
        target=None,
    ):
        self.axis = unit_vector(axis, "ContactNormalTask axis")
        super().__init__(
            robot, frame=frame, cost=cost, gain=gain, lm_damping=lm_damping, target=target
        )

    def __repr__(self) -> str:
        return (
            f"ContactNormalTask({self.frame!r}, axis={self.axis.tolist()}, "
            f"cost={self.cost.tolist()})"
        )

    def set_target(self, d) -> None:
        """Target direction (3,) in world axes; normalised (``ValueError`` for zero or NaN)."""
        self.target = unit_vector(d, "ContactNormalTask target")

    def set_target_from_configuration(self, conf) -> None:
        self.target = self.world_axis(conf)

    def world_axis(self, conf) -> np.ndarray:
        """R(q) a: the axis in world axes at ``conf`` (unit)."""
        return conf.frame_placement(self.frame_id).rotation @ self.axis

    def angle(self, conf) -> float:
        """Angle (rad) between the axis and the target direction at ``conf``."""
        c = float(np.clip(self.world_axis(conf) @ self._require_target(), -1.0, 1.0))
        return float(np.arccos(c))

    def compute_error(self, conf) -> np.ndarray:
        return self.world_axis(conf) - self._require_target()

    def compute_jacobian(self, conf) -> np.ndarray:
        self._require_target()
        return -cross_matrix(self.world_axis(conf)) @ conf.frame_jacobian(self.frame_id, LWA)[3:]
