"""Limits of the QP differential IK: boxes on the step Δq, combined by priority."""

from .acceleration import AccelerationLimit
from .base import Limit, combine
from .configuration import ConfigurationLimit
from .velocity import VelocityLimit

__all__ = ["Limit", "combine", "ConfigurationLimit", "VelocityLimit", "AccelerationLimit"]
