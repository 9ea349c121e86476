"""``anthroarm view``, ``teach`` and ``demo``: a model in the browser, or as one HTML file
(parsers; the runs: :mod:`.view_run`).

    anthroarm teach human_arm7                  # live on 127.0.0.1, a browser tab opens
    anthroarm teach panda -o panda.html         # the same page as a self-contained file
    anthroarm teach human_arm7 --q 40 -20 10 70 0 0 10 --deg --limits

The teach sliders are in degrees (mm for prismatic joints) within the joint limits, continuous
joints ±180°, and mimic joints follow (:meth:`~anthroarm.viewer.Viewer.teach`): the page itself
moves the robot, so the exported file works offline too.
"""

from __future__ import annotations

import argparse

from .common import add_camera, add_json, add_live_options, add_model_argument, add_param_option
from .person import add_person_options

STYLE = dict(choices=["auto", "generated", "urdf"], default="auto", help="visuals (default auto)")


def add_parser(sub):
    _add_view(sub)
    _add_teach(sub)
    _add_demo(sub)


def _add_view(sub):
    p = sub.add_parser(
        "view",
        help="show a model in the browser (meshcat) or write it to HTML",
        description="Show a catalog model, an example-robot-data robot or a URDF file in a meshcat viewer on "
        "127.0.0.1, or write a self-contained HTML file.  Angles are radians unless --deg.",
        epilog="examples:\n  anthroarm view human_arm7 --q 40 -20 10 70 0 0 10 --deg --limits\n"
        "  anthroarm view panda -o panda.html --workspace 3000 --camera front --fit all",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_model_argument(p)
    p.add_argument("--q", nargs="+", type=float, metavar="Q", help="joint values, one per joint")
    p.add_argument("--deg", action="store_true", help="--q is in degrees")
    p.add_argument("--limits", action="store_true", help="colour links by joint-limit proximity")
    p.add_argument("--frames", action="store_true", help="draw the joint frames")
    p.add_argument(
        "--workspace",
        type=int,
        default=0,
        metavar="N",
        help="draw N workspace points coloured by manipulability",
    )
    p.add_argument("--style", **STYLE)
    add_camera(p)
    add_live_options(p)
    p.set_defaults(run="view_run.view", model_params=True)


def _add_teach(sub):
    p = sub.add_parser(
        "teach",
        help="joint sliders that move a model in the browser (like RTB's teach), or the same page as HTML",
        description="Show a catalog model, an example-robot-data robot or a URDF file with one slider per joint "
        "(degrees within the joint limits, continuous joints ±180°, mimic joints follow) on a meshcat "
        "page served on 127.0.0.1, or write it as a self-contained HTML file.  Angles of --q are "
        "radians unless --deg.",
        epilog="examples:\n  anthroarm teach human_arm7\n  anthroarm teach panda -o panda_teach.html",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_model_argument(p)
    p.add_argument(
        "--q", nargs="+", type=float, metavar="Q", help="starting joint values, one per joint"
    )
    p.add_argument("--deg", action="store_true", help="--q is in degrees")
    p.add_argument(
        "--limits", action="store_true", help="colour links by joint-limit proximity (at the start)"
    )
    p.add_argument("--style", **STYLE)
    add_camera(p)
    add_live_options(p)
    p.set_defaults(run="view_run.teach", model_params=True)


def _add_demo(sub):
    p = sub.add_parser(
        "demo",
        help="the human arm reaching for a sequence of targets (QP IK), in the browser or to HTML",
        description="The §6-3 human arm (the catalog's arm of a person) reaches for five hand poses in "
        "turn and returns to rest, driven by QP differential IK (anthroarm.ik.qp; damped least "
        "squares if that layer is missing). The motion plays as a looping meshcat animation with "
        "the targets and the hand's path.",
        epilog="examples:\n  anthroarm demo\n  anthroarm demo -o demo.html --height 1.62",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_param_option(p, "another parameter of the arm (segment_lengths=...)")
    p.add_argument(
        "--method",
        choices=["auto", "qp", "dls"],
        default="auto",
        help="IK stepper (default auto: qp)",
    )
    p.add_argument("--solver", default="osqp", help="QP solver for --method qp (default osqp)")
    add_json(p, "print the per-target errors as JSON")
    add_camera(p)
    add_live_options(p)
    # the model is fixed: the person's arm; the person's options are the CLI's one person
    # (cli/person.py: light, so 'demo --help' loads no catalog), other parameters via --param
    add_person_options(p)
    p.set_defaults(run="view_run.demo", model=None)
