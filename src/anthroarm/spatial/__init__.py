"""The book's spatial mathematics (Ch. 5 and the 002 text).

One concept per module:

* :mod:`~anthroarm.spatial.rotations` — elementary rotations C_x, C_y, C_z (5-70)–(5-72),
  Rodrigues (5-84), validation of axes and rotation matrices, skew / unskew;
* :mod:`~anthroarm.spatial.euler` — Euler z–x–z (5-80)/(5-81) and X–Y–X (8-41) with inverses
  that report gimbal lock;
* :mod:`~anthroarm.spatial.rotation_tensor` — E^{wθ} = J₁ + J₂ cos θ + J₃ sin θ (5-105), its
  derivatives split into the book's terms (5-121)–(5-130), DCM kinematics (5-85)–(5-87);
* :mod:`~anthroarm.spatial.hand_angles` — hand direction angles (6-44)–(6-47), sign-corrected;
* :mod:`~anthroarm.spatial.screw` — 002 screw matrix (4-6), [W] and [E] matrices;
* :mod:`~anthroarm.spatial.dual` — dual numbers, lines, dual angles, dual orthogonal matrices;
* :mod:`~anthroarm.spatial.polar` — complex polar vectors (5-1)–(5-11), (5-23)/(5-24).

The names ``rotation_tensor`` and ``hand_angles`` are the *modules*; call
``spatial.rotation_tensor.rotation_tensor(w, θ)`` and ``spatial.hand_direction_angles(C)``.

Conventions: §5-4/§5-5 rotations are active (new → old, Pinocchio's ``oMi.rotation``); §5-6
dual matrices are passive (old → new).  SI units, radians.
"""

from . import dual, euler, hand_angles, polar, rotation_tensor, rotations, screw
from .dual import Dual, Line
from .euler import EulerAngles, euler_xyx, euler_xyx_inverse, euler_zxz, euler_zxz_inverse
from .hand_angles import hand_angles as hand_direction_angles
from .hand_angles import hand_matrix
from .rotation_tensor import J1, J2, J3, rotate, rotated_vector_motion
from .rotations import (
    axis_angle,
    check_rotation,
    check_unit_axis,
    homogeneous,
    rot_axis,
    rot_x,
    rot_y,
    rot_z,
    rotation_between,
    skew,
    unit_axis,
    unskew,
)
from .screw import acceleration_matrix, rotation_matrix, screw_matrix, screw_twist, velocity_matrix

__all__ = [
    "dual",
    "euler",
    "hand_angles",
    "polar",
    "rotation_tensor",
    "rotations",
    "screw",
    "Dual",
    "Line",
    "EulerAngles",
    "euler_xyx",
    "euler_xyx_inverse",
    "euler_zxz",
    "euler_zxz_inverse",
    "hand_direction_angles",
    "hand_matrix",
    "J1",
    "J2",
    "J3",
    "rotate",
    "rotated_vector_motion",
    "axis_angle",
    "check_rotation",
    "check_unit_axis",
    "homogeneous",
    "rot_axis",
    "rot_x",
    "rot_y",
    "rot_z",
    "rotation_between",
    "skew",
    "unit_axis",
    "unskew",
    "acceleration_matrix",
    "rotation_matrix",
    "screw_matrix",
    "screw_twist",
    "velocity_matrix",
]
