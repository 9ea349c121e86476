"""``anthroarm urdf``: a model's URDF (parser; the run: :mod:`.urdf_run`)."""

from __future__ import annotations

import argparse

from .common import add_model_argument, add_out


def add_parser(sub):
    p = sub.add_parser(
        "urdf",
        help="write the URDF of a model (a book model with chosen parameters)",
        description="Write the URDF of a model: a book model generated with the builder's keyword arguments "
        "(--NAME VALUE or --param NAME=VALUE; 'anthroarm urdf MODEL --help' lists them with units and defaults), "
        "or the validated text of an example-robot-data robot or a URDF file.",
        epilog="examples:\n  anthroarm urdf human_arm7 -o arm.urdf --height 1.62 --mass 55 --sex female\n"
        "  anthroarm urdf prosthetic_arm -o arm.urdf --param L2=0.240\n"
        "  anthroarm urdf ur10 -o ur10.urdf",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_model_argument(p, robot_options=False)
    add_out(p, "--output", required=True, metavar="FILE.urdf", help="output .urdf file")
    p.set_defaults(run="urdf_run.run", model_params=True)
