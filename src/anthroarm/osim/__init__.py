"""OpenSim models in: ``.osim`` files read into a :class:`~anthroarm.robot.Robot`, exactly.

>>> import anthroarm as aa
>>> robot = aa.load(aa.osim.path("arm26"))          # or aa.load("my_model.osim")
>>> robot.joint_names                                # the model's coordinates
['r_shoulder_elev', 'r_elbow_flex']

Modules: :mod:`.xmlread` (safe parsing), :mod:`.functions` (OpenSim's functions, exactly),
:mod:`.reader` (the model's components), :mod:`.build` (the Pinocchio model), :mod:`.coupling`
(q → Pinocchio configuration with its derivatives), :mod:`.loader` (:class:`OsimRobot`,
:func:`load_osim`), :mod:`.report` (the import report).  The models shipped with anthroarm
(CC BY 3.0, from opensim-org/opensim-models; see ``data/opensim/CREDITS.md``) are found by
:func:`path`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import UnknownModelError
from .coupling import Coupling
from .loader import OsimRobot, load_osim, read
from .report import ImportReport

#: the folder of the shipped models
DATA_DIR = Path(__file__).resolve().parent.parent / "data" / "opensim"

#: short name -> file of the shipped models
SHIPPED = {
    "arm26": "arm26.osim",
    "leg6dof9musc": "leg6dof9musc.osim",
    "gait2392": "gait2392_thelen2003muscle.osim",
    "subject01_simbody": "subject01_simbody.osim",
    "Tug_of_War": "Tug_of_War.osim",
}


def names() -> list[str]:
    """The short names of the shipped OpenSim models."""
    return list(SHIPPED)


def path(name: str) -> Path:
    """The file of a shipped model (:data:`SHIPPED`)."""
    if name not in SHIPPED:
        raise UnknownModelError(f"no shipped OpenSim model {name!r}; shipped: {', '.join(SHIPPED)}")
    return DATA_DIR / SHIPPED[name]


__all__ = [
    "Coupling",
    "ImportReport",
    "OsimRobot",
    "load_osim",
    "read",
    "names",
    "path",
    "DATA_DIR",
    "SHIPPED",
]
