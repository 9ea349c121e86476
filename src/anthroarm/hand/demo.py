"""The README picture: the human upper limb holding an upright glass in front of the body.

:func:`cup_grasp` finds the configuration: a reachable five-fingertip cylinder grasp of the hand
(:func:`~anthroarm.hand.problems.reachable_grasps`: the fingers closed on a cylinder of radius
35–40 mm with the palm held), carried to an upright glass at ``center`` (base frame, m) by
solving the palm pose with :func:`anthroarm.ik.solve` over twelve turns about the vertical (and
the glass upside down), keeping the arm configuration nearest the comfortable posture.  The
grasp is checked with :func:`~anthroarm.hand.grasp.grasp_errors` (1 mm, 5°, on the glass's side,
inside the limits) before it is returned.

:func:`anthroarm.viewer.grasp_picture.readme_picture` draws it in the viewer
(:func:`~anthroarm.hand.overlays.show_grasp`: contact points, inward normals, the glass as a
meshcat cylinder) and takes a headless-Chromium screenshot:
``python -m anthroarm.viewer.grasp_picture docs/x.png``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .. import ik, models
from ..ik.qp import IKConfiguration
from ..ik.qp.tasks.posture import comfortable_posture
from ..robot import load
from .fingers import Hand
from .grasp import NORMAL_TOL, POSITION_TOL, grasp_errors
from .objects import Cylinder
from .problems import reachable_grasps

GLASS_HEIGHT = 0.18  # m, the drawn glass (the fingertips lie within ±9 cm of its centre)


def cup_grasp(robot=None, center=(0.05, 0.35, -0.30), seeds=range(100, 106)):
    """(robot, hand, q, glass) of the picture (see the module docstring).  ``RuntimeError`` if no
    draw gives a grasp that passes the checks."""
    robot = load(models.PERSON_ARM_WITH_HAND) if robot is None else robot
    h = Hand(robot)
    comfort = comfortable_posture(robot)
    aq = h.arm_q_indices
    best = None
    for seed in seeds:
        pb = reachable_grasps(robot, 1, rng=seed, hand=h, radius=(0.035, 0.04))[0]
        for yaw in np.linspace(0, 2 * np.pi, 12, endpoint=False):
            for flip in (np.eye(3), np.diag([1.0, -1.0, -1.0])):
                Tw = np.eye(4)
                Tw[:3, :3] = pin.rpy.rpyToMatrix(0.0, 0.0, yaw) @ flip
                Tw[:3, 3] = center
                res = ik.solve(
                    robot,
                    Tw @ np.linalg.inv(pb.T_palm_obj),
                    frame=h.palm,
                    q0=comfort,
                    max_time=0.02,
                )
                if not (res.success and robot.within_limits(res.q)):
                    continue
                q = pb.witness.copy()
                q[aq] = res.q[aq]
                glass = Cylinder(Tw[:3, 3], Tw[:3, 2], pb.obj.radius, length=GLASS_HEIGHT)
                pe, ne, _, on_side = grasp_errors(h, IKConfiguration(robot, q), glass)
                if pe.max() > POSITION_TOL or ne.max() > NORMAL_TOL or not on_side:
                    continue
                d = float(np.linalg.norm((res.q - comfort)[aq]))
                if best is None or d < best[0]:
                    best = (d, q, glass)
    if best is None:
        raise RuntimeError("no reachable upright-glass grasp found for the picture")
    return robot, h, best[1], best[2]
