"""``anthroarm ik``: joint values for a tool pose (parser; the run: :mod:`.ik_run`)."""

from __future__ import annotations

import argparse

from .common import add_json, add_model_argument


def add_parser(sub):
    p = sub.add_parser(
        "ik",
        help="inverse kinematics of a tool pose",
        description="Joint values that put the tool frame at a pose given by a position (m) and roll-pitch-yaw "
        "angles (R = Rz(yaw) Ry(pitch) Rx(roll); radians unless --deg), in the model's base frame, "
        "by aa.ik.solve; arms with a closed form also list every branch inside the limits "
        "(aa.ik.analytic).  Exit status 1 when no solution is found.",
        epilog="example (hand to mouth): anthroarm ik human_arm7 --xyz 0.151 0.193 0.141 --rpy 179.5 6.1 -71.3 --deg --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_model_argument(p)
    p.add_argument(
        "--xyz", nargs=3, type=float, required=True, metavar=("X", "Y", "Z"), help="position, m"
    )
    p.add_argument(
        "--rpy",
        nargs=3,
        type=float,
        default=[0.0, 0.0, 0.0],
        metavar=("R", "P", "Y"),
        help="roll pitch yaw (default 0 0 0)",
    )
    p.add_argument(
        "--deg", action="store_true", help="--rpy, --q0 and the printed q are in degrees"
    )
    p.add_argument(
        "--q0", nargs="+", type=float, metavar="Q", help="initial guess (one value per joint)"
    )
    p.add_argument("--frame", default=None, help="frame to place (default: the model's tool)")
    add_json(p)
    p.set_defaults(run="ik_run.run", model_params=True)
