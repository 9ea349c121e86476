"""The ``anthroarm`` command line: ``anthroarm check|models|ik|view|teach|demo|bench|urdf|cache|
size|ik-markers|batch``.

The package's rule, so that ``anthroarm --help`` stays fast (no numpy, no pinocchio):

* each command group has a light module (``check``, ``models``, ``ik``, ``view`` (view, teach,
  demo), ``urdf``, ``bench``, ``cache``, ``batch``, ``size``, ``ik_markers``) whose
  ``add_parser(sub)`` defines its options and names the function that runs it
  (``set_defaults(run="ik_run.run")``); light modules import only the standard library and
  :mod:`.common`;
* the run lives in the group's ``*_run`` module, which imports what it needs (numpy, pinocchio,
  the algorithms) at its top, with :mod:`.runtime` (loading a model, joint values, progress
  bars) and :mod:`.params` (a book model's builder parameters as options);
* those heavy modules are imported in one place only, :func:`command_module` (importlib), when a
  command runs or a command line names a book model whose parameters become options.

Options follow one convention (docs/guide/cli.md, tests/cli/test_cli_convention.py): the model
is the positional ``MODEL``; a file or folder written is ``-o/--out``; JSON on stdout is
``--json``; a misspelled model name gets a "did you mean".

User mistakes (unknown model, bad arguments, missing folders) and file errors (a folder or a
device as the output, a read-only or full disk, a permission denied) print one line to stderr
and exit with status 2, leaving the target untouched (every write is atomic:
:func:`anthroarm._io.atomic_write_text`); failed checks exit with status 1.  No tracebacks for
user mistakes (tested in ``tests/adversarial/test_cli_garbage.py`` and ``test_file_faults.py``).
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import os
import re
import sys

from .. import __version__
from ..errors import AnthroarmError
from . import batch, bench, cache, check, ik, ik_markers, models, size, urdf, view
from .common import Parser, ProbeError, UserError, one_line_error

#: the command groups, in the order ``anthroarm --help`` lists them
GROUPS = (check, models, ik, view, urdf, bench, cache, batch, size, ik_markers)


def command_module(name: str):
    """The heavy module ``anthroarm.cli.NAME`` (a ``*_run`` module, :mod:`.params`,
    :mod:`.runtime`): the one place they are imported."""
    return importlib.import_module(f"{__name__}.{name}")


def _probe_model(sp, rest: list[str]):
    """The model ``rest`` (the arguments after the command) names, as the command's own parser
    reads it (unknown options, a model's parameters, are let through and a missing required
    option is no error yet); for ``demo``, whose model is fixed, the person's arm; None if no
    model is named."""
    ns = argparse.Namespace()
    sp.probing = True
    try:
        sp.parse_known_args([t for t in rest if t not in ("-h", "--help")], ns)
    except ProbeError:
        pass  # what was read before the error is in ns
    finally:
        sp.probing = False
    model = getattr(ns, "model_alias", None) or getattr(ns, "model", None)
    if model is None and sp.get_default("fixed_model"):
        model = command_module("runtime").default_model()
    return model


def build_parser(argv=None) -> argparse.ArgumentParser:
    """The parser; given the command line, a book model's builder parameters become options of
    the commands that take them (``anthroarm urdf human_arm7 --height 1.62``, listed by
    ``--help``)."""
    ap = Parser(
        prog="anthroarm",
        description="anthroarm: the book's arms, kinematics, IK and dynamics, proven against Pinocchio.",
        epilog="run 'anthroarm COMMAND --help' for the options and an example of each command",
    )
    ap.add_argument("--version", action="version", version=f"anthroarm {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    for group in GROUPS:
        group.add_parser(sub)
    ap.commands = sub.choices  # command -> its parser (the options a "did you mean" offers)
    argv = list(sys.argv[1:] if argv is None else argv)
    cmd = next((i for i, t in enumerate(argv) if not t.startswith("-")), None)
    sp = sub.choices.get(argv[cmd]) if cmd is not None else None
    if sp is not None and sp.get_default("model_params"):
        model = _probe_model(sp, argv[cmd + 1 :])
        if isinstance(model, str):
            command_module("params").add_model_param_options(sp, model)
    return ap


def close_options(parser, extras) -> list[tuple[str, str]]:
    """(given, closest option) for each unknown ``--flag`` of ``extras`` that is close to an
    option of ``parser`` (difflib over the options its help lists, a model's parameters too)."""
    options = sorted(set(re.findall(r"(?<![\w-])--[A-Za-z][\w-]*", parser.format_help())))
    out = []
    for e in extras:
        flag = e.split("=", 1)[0]
        if flag.startswith("--") and flag not in options:
            bare = {o[2:]: o for o in options}  # compared without the dashes all share
            close = difflib.get_close_matches(flag[2:], list(bare), n=1, cutoff=0.6)
            if close:
                out.append((flag, bare[close[0]]))
    return out


def _unknown_options_error(a, extras, parser=None) -> int:
    """One line for arguments no option takes: the closest option of the command ("did you
    mean"); for a command that takes a book model's parameters, name them (or say the model
    has none)."""
    close = close_options(parser, extras) if parser is not None else []
    model = getattr(a, "_model", None) or getattr(a, "model", None)
    if close:
        hint = "; ".join(f"{g}: did you mean {c}?" for g, c in close)
        names = (
            command_module("params").param_names(model)
            if getattr(a, "model_params", False) and isinstance(model, str)
            else ""
        )
        also = f" {model}'s parameters: {names};" if names else ""
        return one_line_error(
            a.command, f"unknown option {hint}{also} (see 'anthroarm {a.command} --help')"
        )
    if (
        getattr(a, "model_params", False)
        and isinstance(model, str)
        and any(e.startswith("--") for e in extras)
    ):
        msg = command_module("params").unknown_options_message(model, extras)
        return one_line_error(a.command, msg + f" (see 'anthroarm {a.command} {model} --help')")
    return one_line_error(
        a.command or "", f"unrecognized arguments: {' '.join(extras)} (see 'anthroarm --help')"
    )


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    ap = build_parser(argv)
    a, extras = ap.parse_known_args(argv)
    if not getattr(a, "command", None):
        if extras:
            ap.error(f"unrecognized arguments: {' '.join(extras)}")
        ap.print_help()
        return 2
    if extras:
        return _unknown_options_error(a, extras, ap.commands.get(a.command))
    module, function = a.run.rsplit(".", 1)
    try:
        return int(getattr(command_module(module), function)(a) or 0)
    except (UserError, AnthroarmError, ValueError, FileNotFoundError) as exc:
        return one_line_error(a.command, str(exc))
    except KeyboardInterrupt:
        print(f"anthroarm {a.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` etc.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (
        OSError
    ) as exc:  # a folder or device as the target, read-only or full disk, no permission
        where = f"{exc.filename}: " if exc.filename else ""
        return one_line_error(a.command, f"{where}{exc.strerror or exc}")
    except MemoryError:
        return one_line_error(a.command, "out of memory (ask for fewer samples or points)")


__all__ = ["UserError", "build_parser", "command_module", "main"]
