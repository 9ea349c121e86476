"""What the commands share when they run (loaded with the first command module, never by
``--help``): loading a model the same way everywhere, joint values, progress bars."""

from __future__ import annotations

import difflib
import math
import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .. import models, osim
from ..errors import UnknownModelError
from ..loading import load
from .common import UserError, parse_locked
from .params import parse_params

__all__ = [
    "check_radians",
    "default_model",
    "joint_values",
    "input_file",
    "load_model",
    "model_from_args",
    "parse_params",
    "parse_q",
    "progress",
    "resolve_model",
]


def suggestions(name: str) -> list[str]:
    """Catalog and example-robot-data names close to a misspelled ``name`` (difflib)."""
    known = dict.fromkeys([*models.names(), *models.erd_names()])
    return difflib.get_close_matches(name, list(known), n=3, cutoff=0.6)


def load_model(name, params=None, tool=None, locked=None):
    """Load a catalog model, an example-robot-data robot or a URDF path (:func:`anthroarm.load`);
    its typed errors (unknown name, a tree without a tool, bad keywords) print as one line, an
    unknown name with the closest names ("did you mean")."""
    kw = {k: v for k, v in (("tool", tool), ("locked", locked)) if v is not None}
    if str(name).lower().endswith(".osim"):
        name = input_file(name)
    try:
        return load(name, **kw, **(params or {}))
    except UnknownModelError:
        close = suggestions(str(name)) if not Path(str(name)).suffix else []
        if not close:
            raise
        hint = " or ".join(repr(c) for c in close)
        raise UserError(
            f"unknown model {name!r}: did you mean {hint}? ('anthroarm models --all' lists "
            "every name; a URDF file is given by its path)"
        ) from None


def input_file(name) -> str:
    """A file a command reads: ``name`` itself, or, when no such file exists and ``name`` is a
    bare name of a file shipped with anthroarm (:func:`anthroarm.osim.shipped_file`:
    ``gait2392.osim``, ``subject01_walk1.trc``), the shipped copy, said on stderr."""
    if name is None or Path(str(name)).exists():
        return name
    shipped = osim.shipped_file(str(name))
    if shipped is None:
        return name
    print(
        f"anthroarm: {name}: not in this folder; using the copy shipped with anthroarm ({shipped})",
        file=sys.stderr,
    )
    return str(shipped)


def default_model() -> str:
    """The model of a command whose MODEL is optional: the catalog's arm of a person."""
    return models.PERSON_ARM


def resolve_model(a) -> None:
    """``a.model`` of a command whose MODEL is optional: the positional, else the deprecated
    ``--model``, else the catalog's arm of a person."""
    alias = getattr(a, "model_alias", None)
    if alias is not None:
        if a.model is not None and a.model != alias:
            raise UserError(f"two models given: {a.model} and --model {alias}; give one (MODEL)")
        a.model = alias
    if a.model is None:
        a.model = default_model()


def model_from_args(a, params=True):
    """The robot of a command's ``MODEL``, ``--param``/``--NAME`` options, ``--tool``, ``--locked``."""
    return load_model(
        a.model,
        parse_params(a.param, a.model, a) if params else None,
        getattr(a, "tool", None),
        parse_locked(getattr(a, "locked", None)),
    )


def parse_q(robot, values, deg: bool, what: str = "--q"):
    """A configuration from one value per joint (rad or m; degrees with --deg; a continuous
    joint takes its angle).  Values outside the limits are kept, with a warning."""
    if values is None:
        return robot.neutral()
    names = robot.joint_names
    if len(values) != len(names):
        raise UserError(
            f"{what} needs {len(names)} values for {robot.name} (joints: {', '.join(names)}), "
            f"got {len(values)}"
        )
    if getattr(robot, "coupling", None) is not None:  # an OpenSim model: q is its coordinates
        return _coordinates(robot, values, deg, what)
    joints = [robot.chain.joints[i] for i in robot.chain.independent]
    if not deg:
        check_radians(values, [j.kind != "prismatic" for j in joints], what)
    theta = np.deg2rad(values) if deg else np.asarray(values, float)
    q = robot.check_q(robot.chain.configuration(theta), what)
    bad = [j.name for j, t in zip(joints, theta) if not j.lower - 1e-9 <= t <= j.upper + 1e-9]
    if bad:
        print(
            f"anthroarm: warning: {what} is outside the joint limits of {', '.join(bad)}",
            file=sys.stderr,
        )
    return q


def _coordinates(robot, values, deg: bool, what: str):
    """``parse_q`` of an OpenSim model with couplings: one value per coordinate (degrees with
    --deg for the rotational ones; translations in m)."""
    # angles: the coordinates that drive a rotation axis (motion.osim_ik.rotational_coordinates)
    rot = {
        c for j in robot.osim.joints for a in j.axes if a.name.startswith("rot") for c in a.coords
    }
    angular = [n in rot for n in robot.joint_names]
    if not deg:
        check_radians(values, angular, what)
    q = np.array(
        [math.radians(float(v)) if deg and a else float(v) for v, a in zip(values, angular)]
    )
    q = robot.check_q(q, what)
    bad = [
        n
        for n, t, lo, hi in zip(robot.joint_names, q, robot.lower, robot.upper)
        if not lo - 1e-9 <= t <= hi + 1e-9
    ]
    if bad:
        print(
            f"anthroarm: warning: {what} is outside the coordinate ranges of {', '.join(bad)}",
            file=sys.stderr,
        )
    return q


def check_radians(values, angular, what: str) -> None:
    """Angles given without ``--deg`` are radians: a value beyond a full turn (|x| > 2π) is
    certainly degrees, refused with the remedy (add --deg, or convert)."""
    big = [float(x) for x, a in zip(values, angular) if a and abs(float(x)) > 2 * math.pi]
    if big:
        shown = " ".join(f"{x:g}" for x in values)
        raise UserError(
            f"{what} {shown}: {big[0]:g} rad is more than a full turn; angles are radians "
            "unless --deg (add --deg if these are degrees)"
        )


def joint_values(robot, q):
    """One value per joint of ``robot.joint_names`` (a continuous joint: its angle; an OpenSim
    model with couplings: q itself, its coordinates)."""
    if getattr(robot, "coupling", None) is not None:
        return np.array(q, dtype=float)
    return robot.angles(q)[list(robot.chain.independent)]


def progress(total: int, desc: str, enabled: bool):
    """A tqdm bar on stderr (only when stderr is a terminal and enabled)."""
    return tqdm(
        total=total,
        desc=desc,
        file=sys.stderr,
        disable=not (enabled and sys.stderr.isatty()),
        leave=False,
    )
