"""Multi-finger hands: fingers from the kinematic tree, grasped objects, fingertip grasps.

>>> import anthroarm as aa
>>> from anthroarm import hand
>>> robot = aa.load("allegro_right_hand", tool="link_3.0_tip")
>>> h = hand.Hand(robot)                              # fingertips = the tips of the tree
>>> ball = hand.Sphere(center=[0.06, 0.0, 0.08], radius=0.04)
>>> res = hand.solve_grasp(robot, ball, hand=h)       # sliding contacts, QP iterations
>>> res.status, res.position_errors.max() < 1e-3      # doctest: +SKIP

Modules: :mod:`~anthroarm.hand.fingers` (fingers, palm, pad normals, span, from
``robot.chain``), :mod:`~anthroarm.hand.objects` (sphere and cylinder surfaces),
:mod:`~anthroarm.hand.grasp` (tasks, solve loop, success criteria: 1 mm, 5°, limits),
:mod:`~anthroarm.hand.problems` (reachable random grasps with a witness),
:mod:`~anthroarm.hand.overlays` (object, contacts and normals in the viewer),
:mod:`~anthroarm.hand.demo` (the README picture).
"""

from .fingers import Finger, Hand
from .grasp import (
    NORMAL_TOL,
    POSITION_TOL,
    GraspResult,
    check_span,
    grasp_errors,
    grasp_tasks,
    solve_grasp,
)
from .objects import Cylinder, Sphere
from .overlays import show_grasp

__all__ = [
    "Hand",
    "Finger",
    "Sphere",
    "Cylinder",
    "solve_grasp",
    "GraspResult",
    "grasp_tasks",
    "grasp_errors",
    "check_span",
    "show_grasp",
    "POSITION_TOL",
    "NORMAL_TOL",
]
