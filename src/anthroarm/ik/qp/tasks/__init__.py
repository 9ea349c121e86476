"""Tasks of the QP differential IK (one concept per module, as in pink)."""

from .base import Task
from .contact_normal import ContactNormalTask
from .coupling import JointCouplingTask
from .damping import DampingTask
from .frame import FrameTask
from .joint_couplings import JointCouplingsTask
from .marker import MarkerTask
from .multi_frame import MultiFrameTask
from .orientation import OrientationTask
from .position import PositionTask
from .posture import PostureTask, comfortable_posture, has_comfortable_posture
from .relative_frame import RelativeFrameTask
from .surface_contact import SurfaceContactTask
from .swivel import SwivelTask, human_layout, swivel_angle, swivel_frames, swivel_from_points

__all__ = [
    "Task",
    "FrameTask",
    "MarkerTask",
    "PositionTask",
    "OrientationTask",
    "RelativeFrameTask",
    "PostureTask",
    "DampingTask",
    "JointCouplingTask",
    "SwivelTask",
    "comfortable_posture",
    "has_comfortable_posture",
    "ContactNormalTask",
    "SurfaceContactTask",
    "MultiFrameTask",
    "JointCouplingsTask",
    "human_layout",
    "swivel_angle",
    "swivel_frames",
    "swivel_from_points",
]
