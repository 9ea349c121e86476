"""``anthroarm ik-markers`` on an OpenSim model: a ``.trc`` (or C3D) trial, an ``.osim``
model and optionally its ``Setup_IK.xml`` in, a ``.mot`` (or CSV) out.

The solve is :func:`anthroarm.motion.osim_marker_ik` — marker IK in the model's coordinates,
spline couplings included (:class:`~anthroarm.motion.osim_ik.CoupledMarkerIK`), with the
setup's marker weights, coordinate tasks and time range (without a setup: every marker of the
model, weight 1, every frame).  ``--time-range T0 T1`` overrides the setup's range.  The
``.mot`` is OpenSim's motion format (:func:`anthroarm.motion.write_mot`: angles in degrees),
which OpenSim's GUI and tools read back.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from ..motion import (
    IKSetup,
    osim_marker_ik,
    read_c3d,
    read_ik_setup,
    read_trc,
    write_mot,
)
from ..motion.csv_io import write_joint_csv
from .common import UserError
from .runtime import input_file, load_model, progress


def is_osim(a) -> bool:
    """The run goes the OpenSim way: an ``.osim`` model, a ``.trc`` trial or a ``--setup``."""
    model = str(a.model or "")
    return (
        model.lower().endswith(".osim")
        or str(a.trial).lower().endswith(".trc")
        or getattr(a, "setup", None) is not None
    )


def run(a) -> int:
    """The OpenSim branch of ``anthroarm ik-markers`` (see the module docstring)."""
    if not str(a.model or "").lower().endswith(".osim"):
        raise UserError(
            f"a .trc trial or --setup needs an OpenSim model (MODEL ending in .osim), got "
            f"{a.model!r}; a catalog arm takes a C3D trial"
        )
    for flag, given in (
        ("--static", a.static),
        ("--markers", a.markers),
        ("--subject", a.subject),
        ("--height", getattr(a, "height", None)),
        ("--mass", getattr(a, "mass", None)),
        ("--sex", getattr(a, "sex", None)),
    ):
        if given is not None:
            raise UserError(
                f"{flag} is for a catalog arm; an OpenSim model is used as it is scaled "
                "(its markers and weights come from the model and --setup)"
            )
    a.trial, a.setup = input_file(a.trial), input_file(a.setup)
    rename = {}
    for item in a.rename:
        if "=" not in item:
            raise UserError(f"--rename expects LABEL=MARKER, got {item!r}")
        k, v = item.split("=", 1)
        rename[k.strip()] = v.strip()
    for flag, given in (("MODEL", a.model), ("--setup", a.setup)):
        if given is not None and same_file(Path(a.out), Path(given)):
            raise UserError(f"--out {a.out} is an input ({flag} {given}); give another file")
    trial_path = str(a.trial)
    trial = read_trc(trial_path) if trial_path.lower().endswith(".trc") else read_c3d(trial_path)
    robot = load_model(a.model)
    if a.setup is not None:
        setup = read_ik_setup(a.setup)
    else:
        names = list(getattr(robot, "osim_markers", None) or [])
        if not names:
            raise UserError(f"{a.model} has no markers: give --setup Setup_IK.xml")
        setup = IKSetup(name="model markers", marker_weights={n: 1.0 for n in names})
    bar = progress(trial.n_frames, "marker IK", not a.no_progress)
    try:
        res = osim_marker_ik(
            robot,
            trial,
            setup,
            time_range=a.time_range,
            rename=rename or None,
            progress=lambda n, N: _advance(bar, n, N),
        )
    finally:
        bar.close()
    if str(a.out).lower().endswith(".mot"):
        write_mot(a.out, res, robot=robot)
    else:
        write_joint_csv(
            a.out,
            res,
            comment=f"source: {trial.source}; model {robot.name}; setup {setup.name}",
        )
    summary = {"out": str(Path(a.out)), **res.summary()}
    print(json.dumps(summary))
    if res.counts()["ok"] == 0:
        print("anthroarm ik-markers: no frame solved with status ok", file=sys.stderr)
        return 1
    return 0


def _advance(bar, n: int, total: int) -> None:
    """Move the bar to ``n`` of ``total`` frames (the time range may select fewer frames than
    the trial has)."""
    bar.total = total
    bar.update(n - bar.n)


def same_file(a, b) -> bool:
    """``a`` and ``b`` name the same file (the same inode, or the same resolved path when one
    does not exist yet)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
