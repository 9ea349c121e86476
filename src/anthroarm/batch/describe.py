"""Robots as descriptions a Dask worker can rebuild: a catalog name with its builder's
parameters, or the validated URDF text, plus the load keywords (``tool``, locked joints).

A Pinocchio model is never pickled.  The description carries the kinematic hash of the robot
it was made from (:meth:`anthroarm.chain.Chain.key`: the exact float bits of every placement,
axis, limit and inertia); a worker that rebuilds a robot with another hash raises
:class:`~anthroarm.batch.errors.RobotRebuildError`, so a result computed on a cluster is always
computed on the same kinematics, bit for bit, as the local one.

Each process keeps the robots it rebuilt in a small LRU cache (:data:`CACHE_SIZE` entries)
keyed by the description, so that a worker builds a robot once per job, not once per task.
"""

from __future__ import annotations

import inspect
import threading
from collections import OrderedDict
from dataclasses import dataclass, field

from .. import models
from ..loading import load
from ..robot import build_model, make_robot
from ..urdf_io import parse_urdf_bytes
from .errors import RobotDescriptionError, RobotRebuildError

#: robots kept per process (a population job has one robot per person)
CACHE_SIZE = 16

_cache: "OrderedDict[tuple, object]" = OrderedDict()
_lock = threading.Lock()


@dataclass(frozen=True)
class RobotDescription:
    """What a worker needs to rebuild a robot.

    ``kind`` is ``"catalog"`` (``source`` a catalog name, ``params`` its builder's keywords)
    or ``"urdf"`` (``source`` the URDF text).  ``tool`` is the default frame, ``locked`` the
    locked joints' values (rad or m), ``name`` the robot's name and ``key`` the kinematic hash
    the rebuilt robot must have ("" = do not check)."""

    kind: str
    source: str
    name: str
    params: tuple = ()
    tool: str | None = None
    locked: tuple = ()
    key: str = field(default="", compare=False)

    def ident(self) -> tuple:
        return (self.kind, self.source, self.name, self.params, self.tool, self.locked, self.key)

    def build(self):
        """A fresh :class:`~anthroarm.robot.Robot` (no cache); raises RobotRebuildError."""
        locked = dict(self.locked) or None
        try:
            if self.kind == "catalog":
                robot = load(
                    self.source, tool=self.tool, locked=locked, name=self.name, **dict(self.params)
                )
            elif self.kind == "urdf":
                info = parse_urdf_bytes(
                    self.source.encode("utf-8"), f"<batch>/{self.name}.urdf", check_meshes=False
                )
                robot = make_robot(
                    build_model(info), name=self.name, info=info, tool=self.tool, locked=locked
                )
            else:
                raise RobotRebuildError(
                    f"unknown robot description kind {self.kind!r} (expected 'catalog' or 'urdf')"
                )
        except RobotRebuildError:
            raise
        except Exception as exc:
            raise RobotRebuildError(
                f"the worker could not rebuild robot {self.name!r} from its {self.kind} "
                f"description: {type(exc).__name__}: {exc}. Remedy: make sure every worker runs "
                "the same anthroarm version as the client (pip install the same wheel/commit in "
                "the workers' environment)"
            ) from None
        if self.key and robot.chain.key() != self.key:
            raise RobotRebuildError(
                f"the worker rebuilt robot {self.name!r} with different kinematics (chain hash "
                f"{robot.chain.key()[:12]} != {self.key[:12]}); the workers run another anthroarm "
                "or Pinocchio version than the client. Remedy: install the same versions on the "
                "workers"
            )
        return robot


def describe(robot, **params) -> RobotDescription:
    """The :class:`RobotDescription` of ``robot``: a :class:`~anthroarm.robot.Robot`, a catalog
    name (with builder ``params``, e.g. ``height=1.62``), a URDF path, or a description.

    A catalog model is described by its name and builder parameters, any other robot loaded
    from a URDF by its validated text.  A robot made from an in-memory ``pin.Model`` has
    neither: :class:`~anthroarm.batch.errors.RobotDescriptionError` with the remedy."""
    if isinstance(robot, RobotDescription):
        return robot
    if isinstance(robot, str) or hasattr(robot, "__fspath__"):
        robot = load(robot, **params)
    elif params:
        raise TypeError(f"builder parameters {sorted(params)} go with a catalog name, not a Robot")
    # kept on the robot (Robot.derived): made again when its chain or tool change
    return robot.derived("batch.describe", _describe)


def _describe(robot) -> RobotDescription:
    locked = tuple(sorted((str(k), float(v)) for k, v in robot.locked.items()))
    spec = robot.spec
    if spec is not None and spec.name in models.BOOK_MODELS:
        accepted = inspect.signature(models.BOOK_MODELS[spec.name]).parameters
        p = tuple(sorted((k, v) for k, v in spec.params.items() if k in accepted))
        d = RobotDescription(
            "catalog", spec.name, robot.name, p, robot.tool, locked, robot.chain.key()
        )
        try:  # the builder must give the same kinematics back (it does unless the spec was edited)
            same = d.build().chain.key() == d.key
        except Exception:
            same = False
        if same:
            return d
    if robot.info is not None and robot.info.text:
        return RobotDescription(
            "urdf", robot.info.text, robot.name, (), robot.tool, locked, robot.chain.key()
        )
    raise RobotDescriptionError(
        f"robot {robot.name!r} was built from an in-memory pin.Model: a Dask worker cannot rebuild "
        "it (Pinocchio models are not shipped). Remedy: write it as a URDF and load that "
        "(pinocchio: robot.urdf / your exporter; then aa.load('arm.urdf')), or use a catalog "
        "name; or run the job locally with client=None"
    )


def robot_from(desc: RobotDescription):
    """The robot of ``desc``, rebuilt once per process (LRU cache of :data:`CACHE_SIZE`)."""
    k = desc.ident()
    with _lock:
        r = _cache.get(k)
        if r is not None:
            _cache.move_to_end(k)
            return r
    r = desc.build()
    with _lock:
        _cache[k] = r
        while len(_cache) > CACHE_SIZE:
            _cache.popitem(last=False)
    return r


def clear_cache() -> None:
    """Forget the rebuilt robots of this process."""
    with _lock:
        _cache.clear()
