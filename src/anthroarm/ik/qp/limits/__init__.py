"""Limits of the QP differential IK: boxes on the step Δq, combined by priority."""

from .acceleration import AccelerationLimit
from .base import Limit, combine
from .collision import CollisionLimit
from .collision_barrier import CollisionBarrier
from .configuration import ConfigurationLimit
from .velocity import VelocityLimit

__all__ = ["Limit", "combine", "ConfigurationLimit", "VelocityLimit", "AccelerationLimit"]
__all__ += ["CollisionLimit", "CollisionBarrier"]
