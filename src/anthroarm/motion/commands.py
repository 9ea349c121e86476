"""The ``anthroarm ik-markers`` command: a C3D trial in, joint angles (CSV) out.

    anthroarm ik-markers trial.c3d --out angles.csv [--height 1.62 --mass 55 --sex female]
                         [--static static.c3d] [--markers set.json] [--rename LABEL=MARKER ...]
                         [--subject NAME]

The arm is ``human_arm7`` scaled to the person (``--height/--mass/--sex``), or to a static
trial (``--static``: :func:`anthroarm.motion.scaling.scale_from_static`); the marker set is the
default ISB set or ``--markers`` (JSON, :meth:`~anthroarm.motion.markers.MarkerSet.read_json`).
A progress bar on stderr (on a terminal) follows the frames; the last line printed is a JSON
summary (frames per status, median and largest RMS marker error, ms per frame).

``--out`` must not be one of the inputs (the trial, ``--static``, ``--markers``; compared as
files: the same path written differently, a symlink or a hard link to it): that is refused
before anything is read or written.  The CSV is written atomically after the solve
(:func:`anthroarm._io.atomic_write_text`), so a failed run leaves an existing file as it was.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from ..robot import load as load_robot
from . import MarkerSet, marker_ik, read_c3d, scale_from_static
from .csv_io import write_joint_csv


def add_parser(sub):
    """Register ``ik-markers`` on the CLI's subparsers (``anthroarm.cli.build_parser``)."""
    p = sub.add_parser(
        "ik-markers",
        help="marker-based IK of a C3D trial: joint angles per frame to CSV",
        description="Frame-by-frame marker IK (weighted least squares of marker errors within the joint limits, "
        "warm-started, gaps handled by weights) of a C3D trial on a person's arm model; writes t, the "
        "joint angles (rad) and per-frame RMS / max marker error and status to CSV.",
        epilog="example: anthroarm ik-markers trial.c3d --out angles.csv --height 1.62 --mass 55 --sex female "
        "--static static.c3d",
    )
    p.add_argument("trial", help="C3D file of the trial (POINT:UNITS mm, cm or m)")
    p.add_argument(
        "--out", required=True, metavar="FILE.csv", help="joint angles, written atomically"
    )
    p.add_argument("--model", default="human_arm7", help="arm model (default human_arm7)")
    p.add_argument(
        "--height",
        type=float,
        default=None,
        help="body height, m (a person's arm model: human_arm7, human_upper_limb; default 1.75)",
    )
    p.add_argument(
        "--mass", type=float, default=None, help="body mass, kg (a person's arm model; default 75)"
    )
    p.add_argument("--sex", default=None, choices=["male", "female"])
    p.add_argument(
        "--static",
        default=None,
        metavar="STATIC.c3d",
        help="static trial: scale the segments to it before the IK",
    )
    p.add_argument(
        "--markers",
        default=None,
        metavar="SET.json",
        help="marker set (default: the ISB human-arm set)",
    )
    p.add_argument(
        "--rename",
        action="append",
        default=[],
        metavar="LABEL=MARKER",
        help="map a trial label to a marker of the set (repeatable)",
    )
    p.add_argument(
        "--subject",
        default=None,
        metavar="NAME",
        help="whose markers to use in a trial of several subjects (labels NAME:MARKER)",
    )
    p.add_argument("--solver", default="daqp", help="QP backend (default daqp)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_ik_markers)
    return p


def cmd_ik_markers(a) -> int:
    from ..cli import UserError, _progress  # upward (faces), and cli imports this module

    rename = {}
    for item in a.rename:
        if "=" not in item:
            raise UserError(f"--rename expects LABEL=MARKER, got {item!r}")
        k, v = item.split("=", 1)
        rename[k.strip()] = v.strip()

    out = Path(a.out)
    if out.is_dir() or not out.parent.is_dir():
        raise UserError(f"--out {a.out}: give a file name in an existing folder")
    if out.exists() and not out.is_file():
        raise UserError(
            f"--out {a.out}: not a regular file (a device, FIFO or socket); give a file name"
        )
    for flag, given in (("the trial", a.trial), ("--static", a.static), ("--markers", a.markers)):
        if given is not None and _same_file(out, Path(given)):
            raise UserError(
                f"--out {a.out} is an input ({flag} {given}): it would be overwritten; "
                "give another output file"
            )
    person = {
        k: v for k, v in (("height", a.height), ("mass", a.mass), ("sex", a.sex)) if v is not None
    }
    trial = read_c3d(a.trial)
    robot = load_robot(a.model, **person)
    markers = MarkerSet.read_json(a.markers) if a.markers else None
    info = {}
    if a.static:
        sc = scale_from_static(robot, read_c3d(a.static), markers, rename=rename, subject=a.subject)
        if sc.status != "ok":
            raise UserError(
                f"--static {a.static}: the static trial does not fit {a.model} ({sc.status}: RMS marker "
                f"error {sc.rms * 1e3:.1f} mm, scale factors "
                f"{ {k: round(v, 2) for k, v in sc.scales.items()} }); check the markers' labels (--rename) "
                "and that it is a static trial of this person"
            )
        robot = load_robot(a.model, **sc.load_kwargs(robot))
        markers = sc.marker_set
        info["segment_lengths_m"] = {k: round(v, 4) for k, v in sc.segment_lengths.items()}
        info["static_rms_m"] = sc.rms
    bar = _progress(trial.n_frames, "marker IK", not a.no_progress)
    try:
        res = marker_ik(
            robot,
            trial,
            markers,
            rename=rename,
            subject=a.subject,
            solver=a.solver,
            progress=lambda n, N: bar.update(n - bar.n),
        )
    finally:
        bar.close()
    write_joint_csv(
        a.out,
        res,
        comment=f"source: {trial.source} ({trial.n_frames} frames at {trial.rate:g} Hz); "
        f"model {robot.name}; marker set {res.info['marker_set']}",
    )
    summary = {"out": a.out, **res.summary(), **info}
    print(json.dumps(summary))
    if res.counts()["ok"] == 0:
        print("anthroarm ik-markers: no frame solved with status ok", file=sys.stderr)
        return 1
    return 0


def _same_file(a, b) -> bool:
    """``a`` and ``b`` name the same file: the same inode (a hard link, a symlink, the same path
    written differently) or, when one does not exist yet, the same resolved path."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)
