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
:func:`path`, and the gait trial shipped with them (``subject01_walk1.trc``, its
``subject01_Setup_IK.xml``) by :func:`shipped_file`, which the command line uses for a file
name that is not in the working folder.
"""

from __future__ import annotations

import os
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


#: the folder of the shipped gait trial (``data/opensim/recordings/CREDITS.md``)
RECORDINGS_DIR = DATA_DIR / "recordings"


def shipped_file(name: str | os.PathLike) -> Path | None:
    """The shipped file a bare file name means, else None: a shipped model's file
    (``gait2392_thelen2003muscle.osim``) or ``<short name>.osim`` (``gait2392.osim``), or a
    file of the shipped trial (``subject01_walk1.trc``, ``subject01_Setup_IK.xml``).  A name
    with a folder in it is never a shipped file."""
    p = Path(name)
    if p.name != os.fspath(name):
        return None
    if p.suffix == ".osim" and p.stem in SHIPPED:
        return DATA_DIR / SHIPPED[p.stem]
    for folder in (DATA_DIR, RECORDINGS_DIR):
        f = folder / p.name
        if p.name != "CREDITS.md" and f.is_file():
            return f
    return None


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
    "shipped_file",
    "DATA_DIR",
    "RECORDINGS_DIR",
    "SHIPPED",
]
