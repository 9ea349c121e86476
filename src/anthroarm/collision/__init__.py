"""Collision models, distances and obstacles: what a robot's bodies occupy (issue 33).

>>> import anthroarm as aa
>>> robot = aa.load("panda")
>>> cm = aa.collision.model(robot)            # URDF <collision> meshes as convex hulls, pairs filtered
>>> table = aa.collision.box((0.8, 1.2, 0.04), xyz=(0.5, 0, 0.2))
>>> aa.collision.min_distance(robot, robot.neutral(), [table])   # m, signed

Modules: :mod:`~anthroarm.collision.model` (bodies from the URDF or capsules),
:mod:`~anthroarm.collision.pairs` (the automatic filter, SRDF), :mod:`~anthroarm.collision.shapes`
(obstacles), :mod:`~anthroarm.collision.distance` (distances, witness points, normals,
Jacobians).  The QP limits are in :mod:`anthroarm.ik.qp.limits.collision`.
"""

from .distance import (
    MAX_OBSTACLES,
    Distances,
    Environment,
    distances,
    environment,
    in_collision,
    jacobians,
    min_distance,
)
from .model import CollisionModel, build, model
from .pairs import read_srdf
from .shapes import Obstacle, box, capsule, cylinder, mesh, sphere

__all__ = [
    "CollisionModel",
    "model",
    "build",
    "read_srdf",
    "Obstacle",
    "sphere",
    "box",
    "capsule",
    "cylinder",
    "mesh",
    "Environment",
    "environment",
    "Distances",
    "distances",
    "min_distance",
    "in_collision",
    "jacobians",
    "MAX_OBSTACLES",
]
