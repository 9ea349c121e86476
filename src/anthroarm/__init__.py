"""anthroarm — anthropomorphic arms, prosthetic hands and their mechanisms.

The methods of the textbook 仿生机械学 (biomimetic mechanisms) — closed-form kinematics,
inverse kinematics, Lagrange dynamics — each proven against Pinocchio on URDF models.

>>> import anthroarm as aa
>>> robot = aa.load("human_arm7")
>>> robot.fk(robot.neutral())[:3, 3]        # hand point, m, base frame (shoulder)
"""

from __future__ import annotations

import importlib

from . import errors, models
from .robot import Robot, load

__version__ = "0.1.0"

_LAZY = {
    "batch",
    "cache",
    "control",
    "crosscheck",
    "emg",
    "kinematics",
    "ik",
    "dynamics",
    "spatial",
    "mechanisms",
    "design",
    "viewer",
    "trajectory",
    "urdf_io",
    "motion",
    "hand",
    "prosthesis",
}


def __getattr__(name):  # lazy subpackages: `aa.ik.solve(...)` without importing everything up front
    if name in _LAZY:
        mod = importlib.import_module(f".{name}", __name__)
        globals()[name] = mod
        return mod
    raise AttributeError(f"module 'anthroarm' has no attribute {name!r}")


__all__ = ["Robot", "load", "models", "errors", *sorted(_LAZY)]
