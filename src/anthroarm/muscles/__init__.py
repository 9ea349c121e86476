"""Muscles of OpenSim models: paths, lengths, moment arms and Hill-type forces.

>>> import anthroarm as aa
>>> from anthroarm import muscles
>>> robot = aa.load(aa.osim.path("gait2392"))
>>> ms = muscles.read_muscles(aa.osim.path("gait2392"))     # 92 Thelen2003 muscles
>>> L = muscles.lengths(robot, ms, robot.default_q())         # (92,) m
>>> R = muscles.moment_arms(robot, ms, robot.default_q())     # (92, 23) m, = -dl/dq
>>> P = muscles.path_points(robot, ms, robot.default_q())     # {name: MusclePath}, ground, m

Modules: :mod:`.reader` (the ForceSet's muscles, safe XML), :mod:`.paths` (lengths and exact
moment arms, batched; the paths as points), :mod:`.wrap` (wrapping over cylinders and spheres;
the compiled pass loop in :mod:`.wrap_pass`), :mod:`.wrap_ellipsoid` (over ellipsoids),
:mod:`.hill` (Thelen2003 forces at static equilibrium, joint torques τ = Rᵀ f),
:mod:`.millard` (Millard2012EquilibriumMuscle curves and equilibrium), :mod:`.optimize` (static optimisation through the QP layer), :mod:`.emg` (the
EMG-driven chain: envelope → excitation → activation → forces → joint torques, beside the
torques an activity needs), :mod:`.checks` (``anthroarm check``'s muscle rows),
:mod:`.opensim_oracle` (OpenSim's own ``StaticOptimization``, the reference of the static
optimisation).
"""

from __future__ import annotations

from . import emg
from .hill import (
    Equilibrium,
    active_force_length,
    equilibrium,
    joint_torques,
    passive_force_length,
    tendon_force_strain,
)
from .optimize import (
    StaticOptimization,
    force_coefficients,
    static_optimization,
    thelen_force_velocity,
)
from .paths import (
    MusclePath,
    lengths,
    lengths_and_moment_arms,
    moment_arms,
    muscle_set,
    path_points,
    wrap_status,
)
from .reader import Muscle, MuscleSet, PathPoint, PathWrap, WrapObject, read_muscles

__all__ = [
    "emg",
    "StaticOptimization",
    "force_coefficients",
    "static_optimization",
    "thelen_force_velocity",
    "Equilibrium",
    "active_force_length",
    "equilibrium",
    "joint_torques",
    "passive_force_length",
    "tendon_force_strain",
    "Muscle",
    "MuscleSet",
    "PathPoint",
    "PathWrap",
    "WrapObject",
    "MusclePath",
    "path_points",
    "lengths",
    "lengths_and_moment_arms",
    "moment_arms",
    "muscle_set",
    "wrap_status",
    "read_muscles",
]
