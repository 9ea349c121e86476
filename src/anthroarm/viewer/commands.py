"""The ``anthroarm teach`` command: a model in the browser with one slider per joint.

    anthroarm teach human_arm7                  # live on 127.0.0.1, a browser tab opens
    anthroarm teach panda --html panda.html     # the same page as a self-contained file
    anthroarm teach human_arm7 --q 40 -20 10 70 0 0 10 --deg --limits

The sliders are in degrees (mm for prismatic joints) within the joint limits, continuous joints
±180°, and mimic joints follow (:meth:`~anthroarm.viewer.Viewer.teach`): the page itself moves
the robot, so the exported file works offline too.
"""

from __future__ import annotations

import argparse


def add_parser(sub):
    """Register ``teach`` on the CLI's subparsers (``anthroarm.cli.build_parser``)."""
    from .. import cli

    p = sub.add_parser(
        "teach",
        help="joint sliders that move a model in the browser (like RTB's teach), or the same page as HTML",
        description="Show a catalog model, an example-robot-data robot or a URDF file with one slider per joint "
        "(degrees within the joint limits, continuous joints ±180°, mimic joints follow) on a meshcat "
        "page served on 127.0.0.1, or write it as a self-contained HTML file.  Angles of --q are "
        "radians unless --deg.",
        epilog="examples:\n  anthroarm teach human_arm7\n  anthroarm teach panda --html panda_teach.html",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    cli._add_model_arguments(p)
    p.add_argument(
        "--q", nargs="+", type=float, metavar="Q", help="starting joint values, one per joint"
    )
    p.add_argument("--deg", action="store_true", help="--q is in degrees")
    p.add_argument(
        "--limits", action="store_true", help="colour links by joint-limit proximity (at the start)"
    )
    p.add_argument(
        "--style",
        choices=["auto", "generated", "urdf"],
        default="auto",
        help="visuals (default auto)",
    )
    cli._add_live_options(p)
    p.set_defaults(func=cmd_teach)
    return p


def cmd_teach(a) -> int:
    from .. import cli
    from .viewer import Viewer

    out = cli._check_html_path(a.html)
    cli._check_port_early(a)
    robot = cli._load_model(
        a.model, cli._parse_params(a.param, a.model, a), a.tool, cli._parse_locked(a.locked)
    )
    q = cli._parse_q(robot, a.q, a.deg)
    v = Viewer(robot, live=out is None, port=a.port, style=a.style, q=q)
    if a.limits:
        v.show_limits()
    v.teach()
    return cli._export_or_serve(v, out, a)
