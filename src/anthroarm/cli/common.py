"""What the command modules share while the parser is built: light code only (argparse and the
standard library), so that ``anthroarm --help`` loads neither numpy nor pinocchio.

The convention every command follows (docs/guide/cli.md, tests/cli/test_cli_convention.py):
the model is the positional ``MODEL`` (:func:`add_model_argument`), a file or folder written is
``-o/--out`` (:func:`add_out`), JSON on stdout is asked for with ``--json`` (:func:`add_json`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

#: Largest --samples / --workspace counts (beyond them the arrays alone need gigabytes).
MAX_SAMPLES = 1_000_000

MODEL_HELP = "catalog name, example-robot-data name (see 'anthroarm models --all') or URDF path"


class UserError(Exception):
    """A mistake in the command line; printed as one line, exit status 2."""


class ProbeError(Exception):
    """A parse error while the command line is only being looked at (:class:`Parser` probing)."""


class Parser(argparse.ArgumentParser):
    """argparse with a one-line error (the usage is one ``--help`` away); subcommand parsers
    are of the same class.  While ``probing`` an error raises :class:`ProbeError` instead of
    exiting: the command line is read once to find the model (whose builder parameters then
    become options) before it is parsed for real."""

    probing = False

    def error(self, message):
        if self.probing:
            raise ProbeError(message)
        self.exit(
            2, f"{self.prog}: error: {' '.join(message.split())} (see '{self.prog} --help')\n"
        )


def add_robot_options(p, what: str = "the model"):
    """--tool and --locked: how to load a robot that is a tree or has joints to freeze."""
    p.add_argument(
        "--tool",
        default=None,
        metavar="FRAME",
        help=f"tool frame of {what} (a tree with several tips needs one; the error lists them)",
    )
    p.add_argument(
        "--locked",
        default=None,
        metavar="J1,J2=V",
        help="comma-separated joints to freeze: NAME (at its neutral value) or NAME=VALUE (rad or m)",
    )


def add_param_option(p, what: str = "book-model parameter"):
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"{what}, e.g. height=1.62 (repeatable)",
    )


def add_model_argument(p, robot_options: bool = True, params: bool = True, optional: bool = False):
    """The model a command works on, the positional ``MODEL`` everywhere.  An ``optional`` one
    (``batch``, ``size``, ``ik-markers``) defaults to the catalog's arm of a person
    (:data:`anthroarm.models.PERSON_ARM`), and ``--model NAME`` is still taken there: a
    deprecated alias of the positional (resolved by :func:`anthroarm.cli.runtime.resolve_model`)."""
    if not optional:
        p.add_argument("model", metavar="MODEL", help=MODEL_HELP)
    else:
        p.add_argument(
            "model",
            nargs="?",
            default=None,
            metavar="MODEL",
            help=f"{MODEL_HELP} (default: the catalog's arm of a person)",
        )
        p.add_argument(
            "--model",
            dest="model_alias",
            default=None,
            metavar="MODEL",
            help="deprecated alias of the positional MODEL",
        )
    if params:
        add_param_option(p)
    if robot_options:
        add_robot_options(p)


def add_out(p, *old: str, **kwargs):
    """``-o/--out``: the file or folder a command writes (``old`` spellings stay as aliases)."""
    kwargs.setdefault("default", None)
    return p.add_argument("-o", "--out", *old, dest="out", **kwargs)


def add_json(p, help: str = "print the result as JSON"):
    p.add_argument("--json", action="store_true", help=help)


def add_live_options(p):
    """A viewer is served live on 127.0.0.1, or written with -o/--out as one HTML file."""
    add_out(
        p,
        "--html",
        metavar="FILE.html",
        help="write a self-contained HTML file instead of starting a server",
    )
    p.add_argument(
        "--port",
        type=int,
        default=None,
        help="server port on 127.0.0.1 (default: first free from 7000)",
    )
    p.add_argument("--no-browser", action="store_true", help="do not open a browser tab")
    p.add_argument(
        "--seconds", type=float, default=None, help=argparse.SUPPRESS
    )  # tests: stop after N s


#: ``--camera`` views and ``--fit`` subjects (:data:`anthroarm.viewer.framing.VIEWS` and
#: :data:`~anthroarm.viewer.framing.FITS`, repeated here so the parser stays light; a test checks
#: they agree).
CAMERA_VIEWS = ("iso", "front", "side", "back", "top")
CAMERA_FITS = ("auto", "pose", "all", "reach", "hand")


def add_camera(p):
    """``--camera VIEW`` and ``--fit SUBJECT`` of a viewer command (``Viewer.set_camera``)."""
    p.add_argument(
        "--camera",
        choices=CAMERA_VIEWS,
        default="iso",
        help="where the camera looks from: iso (front-left-above, default), front (+x), side "
        "(+y), back or top",
    )
    p.add_argument(
        "--fit",
        choices=CAMERA_FITS,
        default="auto",
        help="what fills the view: auto (default: the hand of a limb that ends in one, else "
        "everything drawn), pose (the robot), all (robot and overlays), reach (its workspace), "
        "hand",
    )


def parse_locked(text):
    """``"a,b=0.5"`` -> {"a": None, "b": 0.5} (None: the neutral value)."""
    if text is None:
        return None
    out = {}
    for item in filter(None, (t.strip() for t in text.split(","))):
        name, eq, value = item.partition("=")
        try:
            out[name.strip()] = float(value) if eq else None
        except ValueError:
            raise UserError(
                f"--locked expects NAME or NAME=VALUE (a number), got {item!r}"
            ) from None
    if not out:
        raise UserError("--locked expects at least one joint name")
    return out


def check_out_file(path, example: str = "out.html") -> Path | None:
    """``-o/--out`` as a file name in an existing folder (None stays None)."""
    if path is None:
        return None
    out = Path(path)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist (for -o {path})")
    if out.is_dir():
        raise UserError(f"-o {path} is a folder; give a file name such as {out / example}")
    return out


def one_line_error(command: str, message: str) -> int:
    print(f"anthroarm {command}: error: {' '.join(message.split())}", file=sys.stderr)
    return 2
