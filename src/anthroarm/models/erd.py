"""Robots from example-robot-data (the ``example-robot-data-loaders`` wheel ships the files).

:data:`ERD_ARMS` are the catalog's curated arms: each names the URDF inside the package, the
joints kept active (all others are locked at the stated value with ``pin.buildReducedModel``)
and the tool frame.  Every other robot the package ships loads by its name too
(:func:`erd_names`, :func:`erd_urdf_path`), read offline from the same files.  The URDF file
itself is used unchanged, so Pinocchio and yourdfpy read the same text.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from os.path import join
from pathlib import Path


@dataclass(frozen=True)
class ErdArm:
    name: str
    subpath: str  # inside example-robot-data/robots
    tool: str
    description: str
    active: tuple[str, ...] | None = None  # None: every joint of the URDF
    locked_values: dict = field(
        default_factory=dict
    )  # joint -> value for locked joints (default 0)

    def urdf_path(self) -> Path:
        from example_robot_data import getModelPath

        return Path(getModelPath(self.subpath)) / self.subpath


ERD_ARMS: dict[str, ErdArm] = {
    a.name: a
    for a in [
        ErdArm(
            "panda",
            "panda_description/urdf/panda.urdf",
            tool="panda_hand",
            description="Franka Emika Panda, 7 DOF; fingers locked closed (example-robot-data).",
            active=tuple(f"panda_joint{i}" for i in range(1, 8)),
        ),
        ErdArm(
            "ur5",
            "ur_description/urdf/ur5_robot.urdf",
            tool="tool0",
            description="Universal Robots UR5, 6 DOF (example-robot-data).",
        ),
        ErdArm(
            "talos_arm",
            "talos_data/robots/talos_left_arm.urdf",
            tool="gripper_left_base_link",
            description="PAL TALOS left arm, joints 2-7; gripper locked (example-robot-data).",
            active=tuple(f"arm_left_{i}_joint" for i in range(2, 8)),
        ),
        ErdArm(
            "human_right_arm",
            "human_description/robots/human.urdf",
            tool="right_hand",
            description=(
                "Right arm of example-robot-data's 'human' (shoulder Z-X-Y, elbow Z-Y, wrist Z-X) "
                "as a fixed-base sub-chain; the rest of the body, the clavicle included, is "
                "locked at zero."
            ),
            active=(
                "right_shoulder_Z",
                "right_shoulder_X",
                "right_shoulder_Y",
                "right_elbow_Z",
                "right_elbow_Y",
                "right_wrist_Z",
                "right_wrist_X",
            ),
        ),
    ]
}


@lru_cache(maxsize=1)
def _erd_loaders() -> dict:
    """name -> loader class of every example-robot-data robot described by a URDF."""
    from example_robot_data.robots_loader import ROBOTS

    return {n: L for n, L in ROBOTS.items() if getattr(L, "urdf_filename", "")}


def erd_names() -> list[str]:
    """Every example-robot-data robot that has a URDF (sorted)."""
    return sorted(_erd_loaders())


def erd_urdf_path(name: str) -> Path:
    """Path of the URDF of an example-robot-data robot (the file its loader reads); the
    robot's own floating base, if its loader adds one, is not part of the URDF."""
    from example_robot_data import getModelPath

    L = _erd_loaders()[name]
    rel = join(L.path, L.urdf_subpath, L.urdf_filename)
    return Path(getModelPath(rel)) / rel
