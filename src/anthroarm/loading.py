"""``anthroarm.load``: one entry for every source of a robot — a catalog name, an
example-robot-data name, a URDF path, a ``pin.Model`` (:func:`anthroarm.robot.load`) or an
OpenSim model ``*.osim`` (:func:`anthroarm.osim.load_osim`).

It sits above both: :mod:`anthroarm.osim` builds its robots from :class:`~anthroarm.robot.Robot`,
so :mod:`anthroarm.robot` does not import it (no import circle, issue 29).
"""

from __future__ import annotations

import os

from . import osim
from .errors import ParameterError
from .robot import Robot
from .robot import load as load_robot


def load(
    source,
    *,
    tool: str | None = None,
    active=None,
    locked=None,
    package_dirs=None,
    check_meshes: bool = True,
    name: str | None = None,
    visual_model=None,
    collision_model=None,
    **params,
) -> Robot:
    """Load a robot: :func:`anthroarm.robot.load` for a catalog name, a URDF path, a
    ``pin.Model`` or a ``pin.RobotWrapper`` (see there for the keywords and errors); an OpenSim
    model path ``*.osim`` through :func:`anthroarm.osim.load_osim` (``strict=True`` turns any
    component the import drops into an :class:`~anthroarm.errors.OsimError`; ``tool``,
    ``name``, ``active`` and ``locked`` as for a URDF; no other keyword)."""
    if isinstance(source, (str, os.PathLike)) and os.fspath(source).lower().endswith(".osim"):
        strict = params.pop("strict", False)
        if params:
            raise ParameterError(
                f"the OpenSim model {os.fspath(source)} takes no parameters; unknown "
                f"keyword(s): {', '.join(sorted(params))}"
            )
        return osim.load_osim(
            os.fspath(source), tool=tool, name=name, strict=strict, active=active, locked=locked
        )
    return load_robot(
        source,
        tool=tool,
        active=active,
        locked=locked,
        package_dirs=package_dirs,
        check_meshes=check_meshes,
        name=name,
        visual_model=visual_model,
        collision_model=collision_model,
        **params,
    )


__all__ = ["load"]
