"""anthroarm — anthropomorphic arms, prosthetic hands and their mechanisms.

The methods of the textbook 仿生机械学 (biomimetic mechanisms) — closed-form kinematics,
inverse kinematics, Lagrange dynamics — each proven against Pinocchio on URDF models.

>>> import anthroarm as aa
>>> robot = aa.load("human_arm7")
>>> robot.fk(robot.neutral())[:3, 3]        # hand point, m, base frame (shoulder)
"""

from __future__ import annotations

import importlib

from . import errors

__version__ = "0.1.0"

_LAZY = {
    "batch",
    "cache",
    "collision",
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
    "models",
    "osim",
}
#: names loaded from a submodule on first use, like the subpackages: ``import anthroarm`` (and
#: with it ``anthroarm --help``) loads neither numpy nor pinocchio until a model is needed
_LAZY_NAMES = {"Robot": "robot", "load": "loading"}


def __getattr__(name):  # lazy subpackages: `aa.ik.solve(...)` without importing everything up front
    if name in _LAZY:
        mod = importlib.import_module(f".{name}", __name__)
        globals()[name] = mod
        return mod
    if name in _LAZY_NAMES:
        value = getattr(importlib.import_module(f".{_LAZY_NAMES[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'anthroarm' has no attribute {name!r}")


__all__ = ["Robot", "load", "models", "errors", *sorted(_LAZY)]
