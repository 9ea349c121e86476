"""Closed-chain mechanisms: four-bar, RSSR, RRSS, RCCC, dyads, finger and thumb linkages.

Part B (four-bar, RSSR, RRSS, dyads, thumb, finger, Pinocchio closed loops):

>>> from anthroarm.mechanisms import fourbar
>>> s = fourbar(4.0, 1.5, 3.5, 3.0, 0.7, omega2=2.0)     # book Fig. 5-1, corrected (5-12)-(5-22)
"""

from .closed_loop import ClosedLoop, Closure, LoopSpec, LoopState, TreeJoint
from .dyads import DyadState, RigidBodyPoint, dyad, rigid_body_point
from .finger import FingerGeometry, FingerState, design_finger, finger, finger_f, finger_spec
from .fourbar import (
    CouplerPoint,
    FourBarRange,
    FourBarState,
    coupler_point,
    fourbar,
    fourbar_acceleration,
    fourbar_cartesian,
    fourbar_grashof,
    fourbar_input_range,
    fourbar_points,
    fourbar_position,
    fourbar_velocity,
    transmission_angle,
)
from .pin_models import fourbar_spec, rrss_spec, rssr_spec

# Part A: RCCC by dual-number matrices (§5-6) and relative motion (002 §4-1)
from .rccc import (
    RCCCGeometry,
    RCCCResult,
    RCCCSolution,
    rccc_acceleration,
    rccc_position,  # noqa: E402
    rccc_velocity,
)
from .relative_motion import (
    RelativeMotionGeometry,
    relative_acceleration,
    relative_position,  # noqa: E402
    relative_velocity,
)
from .rrss import (
    RRSSGeometry,
    RRSSPoint,
    RRSSState,
    rrss,
    rrss_branch_through,
    rrss_newton,
    rrss_point,
    rrss_position,
    rrss_track,
)
from .rssr import (
    RSSRCrankTest,
    RSSRGeometry,
    RSSRState,
    rssr,
    rssr_branch_through,
    rssr_crank_test,
    rssr_polar,
    rssr_position,
)
from .thumb import ThumbGeometry, ThumbState, thumb, thumb_f2, thumb_f3, thumb_spec
