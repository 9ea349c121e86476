"""``anthroarm models``: the catalog (parser; the run: :mod:`.models_run`)."""

from __future__ import annotations

import argparse

from .common import add_json


def add_parser(sub):
    p = sub.add_parser(
        "models",
        help="list the model catalog (and every example-robot-data robot with --all)",
        description="List the catalog (the book's models and the curated example-robot-data arms) with nq, nv and "
        "the joint kinds; --all adds every robot example-robot-data ships, loadable by name.",
        epilog="examples:\n  anthroarm models\n  anthroarm models --all --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--all", action="store_true", help="also list every example-robot-data robot")
    add_json(p, "print the list as JSON")
    p.set_defaults(run="models_run.run")
