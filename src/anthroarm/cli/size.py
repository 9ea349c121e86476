"""``anthroarm size``: a person → activities → joint demands → motors → an HTML report (parser;
the run: :mod:`.size_run`).

    anthroarm size --height 1.75 --mass 70 --sex male --activities adl --payload 0.5 -o report.html

``--activities`` is ``adl`` (the daily-living activity library of :mod:`anthroarm.motion`, turned
into joint trajectories for this person) or a comma-separated list of joint-trajectory files:
``.npz`` with arrays ``t`` (N,) s and ``q`` (N, nq) rad, or ``.csv`` with a header ``t`` and the
arm's joint names (rad; ``#`` lines are comments).  Progress bars (stderr, on a terminal) follow
the activities and the joints; the last line printed is a JSON summary.

With a person's residual muscles (``--muscles arm26.osim --muscle-joints
elbow_flexion=r_elbow_flex --remaining BIClong,BICshort --strength 0.4``) the muscles cover part
of each mapped joint's torque and the motors are sized for the rest
(:mod:`anthroarm.prosthesis.residual`); the summary's ``muscles`` gives per joint the peak
demand, muscle and motor torque and the share covered.
"""

from __future__ import annotations

from .common import add_json, add_model_argument, add_out
from .person import add_person_options


def add_parser(sub):
    p = sub.add_parser(
        "size",
        help="size a prosthesis's motors for a person's activities and write an HTML report",
        description="From a person (height, mass, sex) and a set of activities to joint torques with a held "
        "object (Eq. (8-5)), their envelope, the lightest catalogue motor + gearbox per joint (servo "
        "model of Eq. (9-1)), the book's weight rules, and a self-contained HTML report.  MODEL is "
        "a catalog model built from a person's height, mass and sex.  A JSON summary is printed "
        "(with or without --json).",
        epilog="example: anthroarm size --height 1.75 --mass 70 --sex male --activities adl --payload 0.5 "
        "-o report.html",
    )
    add_model_argument(p, robot_options=False, params=False, optional=True)
    add_person_options(p)
    p.add_argument(
        "--activities",
        default="adl",
        metavar="adl|NAME|FILE[,...]",
        help="'adl' (the whole daily-living library), comma-separated activities of the library "
        "(hand_to_mouth, pour, ...: 'anthroarm size --activities ?' lists them) or joint-trajectory "
        "files (.npz with t, q; .csv with t and joint-name columns, rad)",
    )
    p.add_argument(
        "--payload",
        type=float,
        default=None,
        help="mass held in the hand all the time, kg (adl: at least this, the library's objects while "
        "they are held; default: the library's objects only; files: default 0)",
    )
    p.add_argument(
        "--margin", type=float, default=0.2, help="demand margin, fraction (default 0.2 = 20 %%)"
    )
    p.add_argument(
        "--motors",
        default=None,
        metavar="CSV",
        help="motor catalogue (default: the shipped example)",
    )
    p.add_argument(
        "--gearboxes",
        default=None,
        metavar="CSV",
        help="gearbox catalogue (default: the shipped example)",
    )
    add_out(p, default="report.html", metavar="FILE.html", help="the report (written atomically)")
    p.add_argument(
        "--no-viewer",
        action="store_true",
        help="leave the 3-D animation out of the report (smaller file)",
    )
    m = p.add_argument_group(
        "residual muscles",
        "the person's remaining muscles take part of each joint's torque; the motors are sized "
        "for the rest (the summary's 'muscles': per joint the peak demand, muscle and motor "
        "torque and the share the muscles cover)",
    )
    m.add_argument(
        "--muscles",
        default=None,
        metavar="MODEL.osim",
        help="an OpenSim model with the person's muscles (e.g. arm26.osim)",
    )
    m.add_argument(
        "--muscle-joints",
        default=None,
        metavar="JOINT=COORD[,...]",
        help="the arm's joints the muscles act on, each mapped to a coordinate of the model "
        "(-COORD: counted the other way), e.g. elbow_flexion=r_elbow_flex",
    )
    m.add_argument(
        "--remaining",
        default=None,
        metavar="NAME[,...]",
        help="the muscles that remain (default: all of the model's)",
    )
    m.add_argument(
        "--strength",
        type=float,
        default=1.0,
        help="factor on the remaining muscles' maximum isometric force (default 1)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    add_json(p, "print the summary as JSON (the default: it is always JSON)")
    p.set_defaults(run="size_run.run")
