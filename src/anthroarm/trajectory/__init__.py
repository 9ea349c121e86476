"""Trajectories: via-point polynomials, gradual approach, resolved-rate motion (book Ch. 7)."""

from .resolved_rate import LineMotionResult, straight_line_move
from .via_points import ViaPointTrajectory, joint_via_trajectory
