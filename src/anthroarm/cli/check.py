"""``anthroarm check``: every closed form against Pinocchio (parser; the run: :mod:`.check_run`)."""

from __future__ import annotations

import argparse

from .common import MODEL_HELP, add_json, add_robot_options


def add_parser(sub):
    p = sub.add_parser(
        "check",
        help="cross-check the closed forms, kinematics, dynamics and IK against Pinocchio",
        description="Cross-check every closed form against Pinocchio (and yourdfpy) on random configurations "
        "inside the limits.  Any robot gets the generic rows (FK and Jacobians, error propagation, "
        "Lagrange dynamics, aa.ik.solve round trips); the book models also get the book's rows.  "
        "Without a model: the whole catalog.  Exit status 1 unless every row passes.",
        epilog="examples:\n  anthroarm check\n  anthroarm check ur10\n  anthroarm check my_arm.urdf --tool tool0\n"
        "  anthroarm check prosthetic_arm human_arm7 kinova --samples 500 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("model", nargs="*", metavar="MODEL", help=f"{MODEL_HELP}; several allowed")
    p.add_argument(
        "--models",
        nargs="*",
        default=None,
        metavar="A,B,C",
        help="more models, comma- or space-separated (same kinds as MODEL)",
    )
    add_robot_options(p, "every model given")
    p.add_argument(
        "--samples", type=int, default=200, help="random configurations per model (default 200)"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        metavar="N",
        help="processes to run the checks in (default: one per CPU this process may use for the "
        "catalog or 4 models or more, else 1); the rows are the same",
    )
    add_json(p, "print the rows as JSON")
    p.set_defaults(run="check_run.run")
