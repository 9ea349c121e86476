"""From a person's recorded motion to joint trajectories (issue 17, items 1–4).

>>> import anthroarm as aa
>>> from anthroarm import motion
>>> robot = aa.load("human_arm7", height=1.62, mass=55, sex="female")
>>> markers = motion.default_marker_set(robot)            # ISB landmarks, scaled to the person
>>> trial = motion.read_c3d("trial.c3d")                   # doctest: +SKIP
>>> res = motion.marker_ik(robot, trial, markers)          # doctest: +SKIP
>>> res.q, res.rms, res.status                             # doctest: +SKIP

Modules: :mod:`~anthroarm.motion.trial` (marker trajectories in m), :mod:`~anthroarm.motion.c3d`
(C3D through ezc3d, units converted), :mod:`~anthroarm.motion.csv_io` (joint-angle CSV),
:mod:`~anthroarm.motion.markers` (marker sets and the default human-arm set),
:mod:`~anthroarm.motion.marker_ik` (frame-by-frame marker IK on the QP layer),
:mod:`~anthroarm.motion.scaling` (a person's arm from measured lengths or a static trial),
:mod:`~anthroarm.motion.activities` (the daily-living activity library),
:mod:`~anthroarm.motion.trc` and :mod:`~anthroarm.motion.storage` (OpenSim's ``.trc`` marker files
and ``.mot``/``.sto`` storages, read and written), :mod:`~anthroarm.motion.ik_setup` (OpenSim's
``Setup_IK.xml``: marker weights and coordinate tasks for marker IK on an ``.osim`` model),
:mod:`~anthroarm.motion.osim_ik` (marker IK in the coordinates of an ``.osim`` model, couplings
included: OpenSim's IK objective) and :mod:`~anthroarm.motion.opensim_oracle` (OpenSim's own IK,
run from Python, the reference it is checked against), :mod:`~anthroarm.motion.body_poses` (the
world pose of every body along a motion, one batched walk down the tree).

Algorithms here take arrays and a Robot; reading files is in ``c3d`` / ``csv_io`` and progress
bars are the CLI's (``anthroarm ik-markers``).
"""

from . import activities
from .activities import Activity, ActivityTrajectory, Keyframe, activity, activity_trajectory
from .body_poses import body_poses
from .c3d import read_c3d, write_c3d
from .csv_io import JointTrajectory, read_joint_csv, write_joint_csv
from .ik_setup import CoordinateTask, IKSetup, coordinate_targets, osim_marker_set, read_ik_setup
from .marker_ik import STATUSES, MarkerIK, MarkerIKResult, marker_ik, match_markers
from .markers import (
    HUMAN_ARM_LANDMARKS,
    BoundMarkers,
    Marker,
    MarkerSet,
    default_marker_set,
    human_arm_markers,
    segment_length,
)
from .opensim_oracle import OpenSimIK, opensim_ik, opensim_tool
from .osim_ik import CoupledMarkerIK, osim_marker_ik, rotational_coordinates
from .scaling import ScalingResult, scale_from_static
from .storage import StorageTable, read_storage, write_mot
from .timing import keyframe_trajectory, minimum_jerk
from .trc import read_trc, write_trc
from .trial import MarkerTrajectories

__all__ = [
    "MarkerTrajectories",
    "read_c3d",
    "write_c3d",
    "read_trc",
    "write_trc",
    "StorageTable",
    "read_storage",
    "write_mot",
    "IKSetup",
    "CoordinateTask",
    "read_ik_setup",
    "osim_marker_set",
    "coordinate_targets",
    "CoupledMarkerIK",
    "osim_marker_ik",
    "rotational_coordinates",
    "OpenSimIK",
    "opensim_ik",
    "opensim_tool",
    "body_poses",
    "JointTrajectory",
    "read_joint_csv",
    "write_joint_csv",
    "Marker",
    "MarkerSet",
    "BoundMarkers",
    "HUMAN_ARM_LANDMARKS",
    "default_marker_set",
    "human_arm_markers",
    "segment_length",
    "MarkerIK",
    "MarkerIKResult",
    "marker_ik",
    "match_markers",
    "STATUSES",
    "activities",
    "Activity",
    "ActivityTrajectory",
    "Keyframe",
    "activity",
    "activity_trajectory",
    "minimum_jerk",
    "keyframe_trajectory",
    "ScalingResult",
    "scale_from_static",
]
