"""``anthroarm ik-markers``: a C3D trial in, joint angles (CSV) out (parser; the run:
:mod:`.ik_markers_run`; an OpenSim model, ``.trc`` trial and ``Setup_IK.xml``:
:mod:`.ik_markers_osim`, writing a ``.mot``).

    anthroarm ik-markers walk.trc model.osim -o walk_ik.mot [--setup Setup_IK.xml]
                         [--time-range 0.4 1.6]

    anthroarm ik-markers trial.c3d [MODEL] -o angles.csv [--height 1.62 --mass 55 --sex female]
                         [--static static.c3d] [--markers set.json] [--rename LABEL=MARKER ...]
                         [--subject NAME]

The arm is MODEL (default: the catalog's arm of a person) scaled to the person (``--height/--mass/--sex``), or to a static
trial (``--static``: :func:`anthroarm.motion.scaling.scale_from_static`); the marker set is the
default ISB set or ``--markers`` (JSON, :meth:`~anthroarm.motion.markers.MarkerSet.read_json`).
A progress bar on stderr (on a terminal) follows the frames; the last line printed is a JSON
summary (frames per status, median and largest RMS marker error, ms per frame).

``-o/--out`` must not be one of the inputs (the trial, ``--static``, ``--markers``; compared as
files: the same path written differently, a symlink or a hard link to it): that is refused
before anything is read or written.  The CSV is written atomically after the solve
(:func:`anthroarm._io.atomic_write_text`), so a failed run leaves an existing file as it was.
"""

from __future__ import annotations

from .common import add_json, add_model_argument, add_out
from .person import add_person_options


def add_parser(sub):
    p = sub.add_parser(
        "ik-markers",
        help="marker-based IK of a C3D trial: joint angles per frame to CSV",
        description="Frame-by-frame marker IK (weighted least squares of marker errors within the joint limits, "
        "warm-started, gaps handled by weights) of a C3D trial on a person's arm model; writes t, the "
        "joint angles (rad) and per-frame RMS / max marker error and status to CSV.",
        epilog="example: anthroarm ik-markers trial.c3d -o angles.csv --height 1.62 --mass 55 --sex female "
        "--static static.c3d",
    )
    p.add_argument(
        "trial",
        help="C3D file of the trial (POINT:UNITS mm, cm or m), or an OpenSim .trc with an .osim MODEL",
    )
    add_model_argument(p, robot_options=False, params=False, optional=True)
    add_out(p, required=True, metavar="FILE.csv", help="joint angles, written atomically")
    add_person_options(p, given_only=True)
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
    p.add_argument(
        "--setup",
        default=None,
        metavar="SETUP_IK.xml",
        help="OpenSim IK setup (an .osim MODEL): marker weights, coordinate tasks, time range",
    )
    p.add_argument(
        "--time-range",
        type=float,
        nargs=2,
        default=None,
        metavar=("T0", "T1"),
        help="an .osim MODEL: solve the frames from T0 to T1 s (default: the setup's, or all)",
    )
    p.add_argument("--solver", default="daqp", help="QP backend (default daqp)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_json(p, "print the summary as JSON (the default: it is always JSON)")
    p.set_defaults(run="ik_markers_run.run")
