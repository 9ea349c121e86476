"""Control of the book's §9-1 (industrial robots): servo, motor, bilateral teleoperation,
teaching and playback, interpolation, DDA pulse distribution, gripper behaviours.

* :mod:`~anthroarm.control.motor` — a DC motor with a gearbox: the torque–speed line of
  Eq. (9-1), stall torque, no-load speed, the thermal (RMS) limit, reflected inertia;
* :mod:`~anthroarm.control.servo` — the analog position servo (9-1)–(9-8) as an ODE and as
  transfer functions, its steady error and the load-torque estimator (Fig. 9-15, 9-16);
* :mod:`~anthroarm.control.bilateral` — the master–slave servos of Fig. 9-17 (symmetric,
  force-reflecting, force-feedback) and what the operator feels;
* :mod:`~anthroarm.control.teach` — teach, store and play back (sequence / position / time
  channels; fixed, program select, program jump, subroutine, random access);
* :mod:`~anthroarm.control.interpolation` — straight-line and circular-arc interpolation in
  Cartesian space (orientation by slerp);
* :mod:`~anthroarm.control.dda` — DDA pulse distribution (all axes end on the same tick);
* :mod:`~anthroarm.control.gripper` — tactile search, position/attitude correction,
  hard/soft/zero grasp, the slip controller (Fig. 9-11 … 9-14).

SI units throughout (the book prints kgf·cm); joint side unless a name says motor side.
"""

from . import bilateral, dda, gripper, interpolation, motor, servo, teach
from .bilateral import Bilateral, BilateralResult, Wall
from .dda import DDAResult, pulse_counts
from .dda import dda as distribute_pulses
from .gripper import (
    SlipController,
    correct_attitude,
    correct_position,
    grasp,
    simulate_slip,
    tactile_search,
)
from .interpolation import Arc, arc_poses, circle_through, line_points, line_poses, slerp
from .motor import DCMotor, ThermalCheck, rms
from .servo import PositionServo, ServoResponse
from .teach import (
    Call,
    Jump,
    Playback,
    Program,
    Step,
    play_fixed,
    play_jump,
    play_random_access,
    play_select,
    play_subroutines,
    record,
)

__all__ = [
    "bilateral",
    "dda",
    "gripper",
    "interpolation",
    "motor",
    "servo",
    "teach",
    "Bilateral",
    "BilateralResult",
    "Wall",
    "DDAResult",
    "distribute_pulses",
    "pulse_counts",
    "SlipController",
    "correct_attitude",
    "correct_position",
    "grasp",
    "simulate_slip",
    "tactile_search",
    "Arc",
    "arc_poses",
    "circle_through",
    "line_points",
    "line_poses",
    "slerp",
    "DCMotor",
    "ThermalCheck",
    "rms",
    "PositionServo",
    "ServoResponse",
    "Call",
    "Jump",
    "Playback",
    "Program",
    "Step",
    "play_fixed",
    "play_jump",
    "play_random_access",
    "play_select",
    "play_subroutines",
    "record",
]
