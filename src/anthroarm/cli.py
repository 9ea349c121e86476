"""The ``anthroarm`` command line.

User mistakes (unknown model, bad arguments, missing folders) and file errors (a folder or a
device as the output, a read-only or full disk, a permission denied) print one line to stderr
and exit with status 2, leaving the target untouched (every write is atomic:
:func:`anthroarm._io.atomic_write_text`); failed checks exit with status 1.  No tracebacks for
user mistakes (tested in ``tests/adversarial/test_cli_garbage.py`` and ``test_file_faults.py``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import AnthroarmError


class UserError(Exception):
    """A mistake in the command line; printed as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error (the usage is one ``--help`` away); subcommand parsers
    are of the same class.  ``recorded`` holds the actions its options made, in order (what
    the public ``add_argument`` returns, also through argument groups), so that the command
    line can be pre-read and options checked for without argparse's private tables."""

    def __init__(self, *args, **kwargs):
        self.recorded = []  # before argparse's __init__, which adds -h through add_argument
        super().__init__(*args, **kwargs)

    def add_argument(self, *args, **kwargs):
        action = super().add_argument(*args, **kwargs)
        self.recorded.append(action)
        return action

    def _recording(self, group):
        add = group.add_argument

        def add_argument(*args, **kwargs):
            action = add(*args, **kwargs)
            self.recorded.append(action)
            return action

        group.add_argument = add_argument
        return group

    def add_argument_group(self, *args, **kwargs):
        return self._recording(super().add_argument_group(*args, **kwargs))

    def add_mutually_exclusive_group(self, *args, **kwargs):
        return self._recording(super().add_mutually_exclusive_group(*args, **kwargs))

    def option_strings(self) -> set:
        """Every option string (``--tool``, ``-h`` ...) this parser takes."""
        return {s for a in self.recorded for s in a.option_strings}

    def error(self, message):
        self.exit(
            2, f"{self.prog}: error: {' '.join(message.split())} (see '{self.prog} --help')\n"
        )


#: Largest --samples / --workspace counts (beyond them the arrays alone need gigabytes).
MAX_SAMPLES = 1_000_000


def _add_robot_options(p, what: str = "the model"):
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


def _add_model_arguments(p, robot_options: bool = True):
    """The model a command works on, given the same way everywhere (see :func:`_load_model`)."""
    p.add_argument(
        "model",
        help="catalog name, example-robot-data name (see 'anthroarm models --all') or URDF path",
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="book-model parameter, e.g. height=1.62 (repeatable)",
    )
    if robot_options:
        _add_robot_options(p)


#: commands whose model (positional, or fixed) may be a book model with builder parameters
_MODEL_COMMANDS = {"urdf": None, "view": None, "teach": None, "ik": None, "demo": "human_arm7"}


def _model_params(model) -> list[tuple[str, object, str, str]] | None:
    """The builder parameters of a book model, ``[(name, default, kind, unit)]`` (kind: ``float``,
    ``pair`` (two numbers, e.g. a stroke), ``map`` (a dict of numbers, e.g. human_arm7's
    ``segment_lengths``, given as ``KEY=VALUE,KEY=VALUE``) or ``str``); None for any other model.
    Units: :func:`anthroarm.models.param_unit` (lengths in m, mass in kg, angles in rad)."""
    import inspect

    from . import models

    if not isinstance(model, str) or model not in models.BOOK_MODELS:
        return None
    out = []
    for p in inspect.signature(models.BOOK_MODELS[model]).parameters.values():
        d = p.default
        ann = (
            p.annotation if isinstance(p.annotation, str) else getattr(p.annotation, "__name__", "")
        )
        kind = (
            "pair"
            if isinstance(d, tuple)
            else "str"
            if isinstance(d, str)
            else "map"
            if isinstance(d, dict) or ann.split("|")[0].strip() == "dict"
            else "float"
        )
        unit = "" if kind == "str" else models.param_unit(model, p.name)
        out.append((p.name, d, kind, unit))
    return out


def _param_names(model) -> str:
    return ", ".join(f"--{n}" for n, *_ in _model_params(model) or [])


def _convert_param(model, name, kind, unit, text):
    """The builder value of ``--NAME TEXT`` / ``--param NAME=TEXT``."""
    import math

    if kind == "str":
        return text
    if kind == "map":
        out = {}
        for item in str(text).split(","):
            k, _, v = item.partition("=")
            try:
                x = float(v)
            except ValueError:
                x = math.nan
            if not k.strip() or not math.isfinite(x) or k.strip() in out:
                raise UserError(
                    f"{model} parameter {name} expects comma-separated KEY=VALUE pairs, each value a "
                    f"finite number ({unit}) and each KEY once; got {text!r} "
                    f"(see 'anthroarm urdf {model} --help')"
                )
            out[k.strip()] = x
        return out
    want = "two numbers MIN,MAX" if kind == "pair" else "a number"
    try:
        vals = [float(x) for x in str(text).split(",")]
    except ValueError:
        vals = []
    if len(vals) != (2 if kind == "pair" else 1) or not all(math.isfinite(v) for v in vals):
        raise UserError(f"{model} parameter {name} expects {want} ({unit}), got {text!r}")
    return tuple(vals) if kind == "pair" else vals[0]


def _add_model_param_options(p, model):
    """``--NAME VALUE`` for every builder parameter of a book model (shown by ``--help`` with its
    unit and default); an option the command already has stays reachable through --param."""
    from . import models

    params = _model_params(model)
    if not params:
        return
    paragraph = " ".join((models.BOOK_MODELS[model].__doc__ or "").strip().split("\n\n")[0].split())
    first = paragraph.split(". ")[0].rstrip(".") + "." if paragraph else ""
    g = p.add_argument_group(
        f"parameters of {model}", f"{first} Also accepted as --param NAME=VALUE.".strip()
    )
    for name, default, kind, unit in params:
        taken = p.option_strings()
        if f"--{name}" in taken:
            continue
        shown = (
            ",".join(f"{x:g}" for x in default)
            if kind == "pair"
            else "none"
            if kind == "map" and default is None
            else default
        )
        metavar = (
            "MIN,MAX" if kind == "pair" else "KEY=VALUE,..." if kind == "map" else name.upper()
        )
        help_ = (
            f"{unit + ', ' if unit else ''}{'min,max, ' if kind == 'pair' else ''}"
            f"{'comma-separated KEY=VALUE pairs, ' if kind == 'map' else ''}default {shown}"
        )
        flags = [f"--{name}"] + (
            [f"--{name.replace('_', '-')}"]
            if kind == "map" and "_" in name and f"--{name.replace('_', '-')}" not in taken
            else []
        )
        g.add_argument(
            *flags, dest=f"model_param:{name}", default=None, metavar=metavar, help=help_
        )
    p.set_defaults(_model=model)


class _PrescanError(Exception):
    pass


class _Prescan(argparse.ArgumentParser):
    def error(self, message):
        raise _PrescanError(message)


def _prescan_model(sp, rest):
    """The model named in ``rest`` (the arguments after the command) as ``sp`` would parse it,
    with its required options not yet enforced and unknown options (a model's parameters) let
    through; None if there is none."""
    pre = _Prescan(add_help=False, prog=sp.prog)
    for act in sp.recorded:
        if not act.option_strings:
            if act.dest == "model" and act.nargs is None:
                pre.add_argument("model", nargs="?")
            continue
        if act.nargs == 0:
            pre.add_argument(*act.option_strings, dest=act.dest, action="store_true")
        else:
            pre.add_argument(*act.option_strings, dest=act.dest, nargs=act.nargs)
    try:
        ns, _ = pre.parse_known_args(rest)
    except _PrescanError:
        return None
    return getattr(ns, "model", None)


def _parse_locked(text):
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


def _add_check(sub):
    p = sub.add_parser(
        "check",
        help="cross-check the closed forms, kinematics, dynamics and IK against Pinocchio",
        description="Cross-check every closed form against Pinocchio (and yourdfpy) on random configurations "
        "inside the limits.  Any robot gets the generic rows (FK and Jacobians, error propagation, "
        "Lagrange dynamics, aa.ik.solve round trips); the book models also get the book's rows.  "
        "Without a model: the whole catalog.  Exit status 1 unless every row passes.",
        epilog="examples:\n  anthroarm check\n  anthroarm check ur10\n  anthroarm check my_arm.urdf --tool tool0\n"
        "  anthroarm check --models prosthetic_arm,human_arm7,kinova --samples 500 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "model",
        nargs="*",
        metavar="MODEL_OR_URDF",
        help="catalog name, example-robot-data name (see 'anthroarm models --all') or URDF path",
    )
    p.add_argument(
        "--models",
        nargs="*",
        default=None,
        metavar="A,B,C",
        help="more models, comma- or space-separated (same kinds as MODEL_OR_URDF)",
    )
    _add_robot_options(p, "every model given")
    p.add_argument(
        "--samples", type=int, default=200, help="random configurations per model (default 200)"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.set_defaults(func=cmd_check)


def cmd_check(a) -> int:
    from . import crosscheck

    if not 1 <= a.samples <= MAX_SAMPLES:
        raise UserError(f"--samples must be in 1..{MAX_SAMPLES}, got {a.samples}")
    names = [n for item in [*a.model, *(a.models or [])] for n in item.split(",") if n]
    if (a.tool is not None or a.locked is not None) and not names:
        raise UserError(
            "--tool and --locked apply to the models given: name one (e.g. anthroarm check ur10 --tool tool0)"
        )
    rows = crosscheck.run(
        names or None,
        samples=a.samples,
        seed=a.seed,
        progress=not a.json and sys.stderr.isatty(),
        tool=a.tool,
        locked=_parse_locked(a.locked),
    )
    print(crosscheck.to_json(rows) if a.json else crosscheck.format_table(rows))
    return 0 if all(r.ok for r in rows) else 1


def _add_models(sub):
    p = sub.add_parser(
        "models",
        help="list the model catalog (and every example-robot-data robot with --all)",
        description="List the catalog (the book's models and the curated example-robot-data arms) with nq, nv and "
        "the joint kinds; --all adds every robot example-robot-data ships, loadable by name.",
        epilog="examples:\n  anthroarm models\n  anthroarm models --all --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--all", action="store_true", help="also list every example-robot-data robot")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_models)


def _describe(name, source: str, description: str = "") -> dict:
    """One entry of ``anthroarm models``: nq, nv, joint kinds and tool of a robot loaded by
    name, or what it needs (tool=, with its tips) or why it does not load."""
    from . import load
    from .errors import AmbiguousToolError, AnthroarmError

    out = {
        "name": name,
        "source": source,
        "description": description,
        "nq": None,
        "nv": None,
        "kinds": {},
        "tool": None,
        "tips": [],
        "needs_tool": False,
        "error": None,
    }
    try:
        try:
            r = load(name)
        except AmbiguousToolError:
            out["needs_tool"] = True
            r = load(
                name, tool="universe"
            )  # the base frame: every model has it; only to count and list tips
        out.update(
            nq=r.nq,
            nv=r.nv,
            kinds={k: n for k, n in r.chain.kind_counts().items() if n},
            tool=None if out["needs_tool"] else r.tool,
            tips=list(r.tips),
            description=description or r.description,
        )
    except AnthroarmError as exc:
        out["error"] = " ".join(str(exc).split())
    return out


def _kinds_text(kinds: dict) -> str:
    return " + ".join(f"{n} {k}" for k, n in kinds.items()) or "no joints"


def cmd_models(a) -> int:
    from . import models

    out = []
    for n in models.names():
        if n in models.BOOK_MODELS:
            s = models.spec(n)
            out.append(_describe(n, s.source or "book", s.description))
        else:
            arm = models.ERD_ARMS[n]
            out.append(_describe(n, f"example-robot-data {arm.subpath}", arm.description))
    if a.all:
        out += [
            _describe(n, "example-robot-data")
            for n in models.erd_names()
            if n not in models.names()
        ]
    if a.json:
        print(json.dumps(out, indent=1))
        return 0
    w = max(len(o["name"]) for o in out)
    wk = max(len(_kinds_text(o["kinds"])) for o in out)
    catalog = set(models.names())
    for i, o in enumerate(out):
        if i == len(catalog):
            print("\nexample-robot-data (anthroarm.load(NAME); a tree needs tool=):")
        if o["error"] is not None:
            print(f"{o['name']:<{w}}  not loadable: {o['error']}")
            continue
        head = f"{o['name']:<{w}}  nq={o['nq']:<3} nv={o['nv']:<3} {_kinds_text(o['kinds']):<{wk}}"
        if o["needs_tool"]:
            print(f"{head}  needs tool=, one of: {', '.join(o['tips'])}")
        else:
            print(f"{head}  {o['description'] if o['name'] in catalog else 'tool ' + o['tool']}")
    return 0


def _add_urdf(sub):
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
    _add_model_arguments(p, robot_options=False)
    p.add_argument("-o", "--output", required=True, help="output .urdf file")
    p.set_defaults(func=cmd_urdf)


def _parse_params(items, model=None, a=None) -> dict:
    """Builder keyword arguments from ``--param KEY=VALUE`` items and, for a book model, its
    ``--NAME VALUE`` options (in ``a``); a book model's names are checked against its builder
    and the values converted to the builder's kinds."""
    params = {}
    for it in items:
        if "=" not in it:
            raise UserError(f"--param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        params[k.strip()] = v
    spec = _model_params(model)
    if spec is None:  # not a book model: numbers as floats; load() rejects any parameter
        out = {}
        for k, v in params.items():
            try:
                out[k] = float(v)
            except ValueError:
                out[k] = v
        return out
    kinds = {n: (kind, unit) for n, _, kind, unit in spec}
    unknown = [k for k in params if k not in kinds]
    if unknown:
        raise UserError(
            f"unknown parameter {unknown[0]!r} of {model}; its parameters: "
            f"{', '.join(kinds)} (e.g. --param {spec[0][0]}=VALUE or --{spec[0][0]} VALUE)"
        )
    for n in kinds:
        v = getattr(a, f"model_param:{n}", None) if a is not None else None
        if v is not None:
            if n in params and params[n] != v:
                raise UserError(
                    f"{model} parameter {n} given twice (--{n} {v} and --param {n}={params[n]})"
                )
            params[n] = v
    return {k: _convert_param(model, k, *kinds[k], v) for k, v in params.items()}


def cmd_urdf(a) -> int:
    from ._io import atomic_write_text

    out = Path(a.output)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist")
    if out.is_dir():
        raise UserError(f"-o {a.output} is a folder; give a file name such as {out / 'robot.urdf'}")
    robot = _load_model(
        a.model, _parse_params(a.param, a.model, a), tool="universe"
    )  # any frame: only the text is written
    atomic_write_text(out, robot.info.text)
    print(f"wrote {out}")
    return 0


def _add_bench(sub):
    p = sub.add_parser(
        "bench",
        help="run benchmarks (JSON + markdown in a user folder, or --out)",
        description="Run the benchmark suite side by side with the peers and write JSON + markdown tables "
        f"(and figures) to --out; default: {_bench_user_dir()} ($XDG_DATA_HOME honoured), "
        "its 'quick' subfolder with --quick.  The committed benchmarks/results/ of a source "
        "checkout is written only with --update-results (full runs).",
        epilog="examples:\n  anthroarm bench fk --quick\n  anthroarm bench ik --out ./my_results\n"
        "  anthroarm bench --update-results        # maintainers: refresh benchmarks/results/",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    p.add_argument(
        "--quick", action="store_true", help="fewer samples (never written to benchmarks/results/)"
    )
    p.add_argument("--list", action="store_true", help="list the benchmarks")
    p.add_argument(
        "--out", default=None, metavar="FOLDER", help="output folder (created if missing)"
    )
    p.add_argument(
        "--update-results",
        action="store_true",
        help="write into the committed benchmarks/results/ (full runs only)",
    )
    p.set_defaults(func=cmd_bench)


def _bench_user_dir() -> Path:
    """Default folder of ``anthroarm bench``: the platform's user data folder
    (``$XDG_DATA_HOME/anthroarm/benchmarks``, else ``~/.local/share/anthroarm/benchmarks`` on
    Linux and other Unix; ``~/Library/Application Support`` on macOS; ``%LOCALAPPDATA%`` on
    Windows)."""
    import os

    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        xdg = os.environ.get("XDG_DATA_HOME", "")
        base = Path(xdg) if xdg and Path(xdg).is_absolute() else Path.home() / ".local" / "share"
    return base / "anthroarm" / "benchmarks"


def _benchmarks_module():
    root = Path(__file__).resolve().parents[2]
    if not (root / "benchmarks" / "__main__.py").is_file():
        raise UserError("the benchmarks/ folder is not available (run from a source checkout)")
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    import benchmarks.__main__ as bm

    return bm


def _bench_out(a, results_dir: Path) -> Path:
    """The folder ``anthroarm bench`` writes to, created and proven writable before any run."""
    import tempfile

    if a.update_results and a.out is not None:
        raise UserError("--update-results writes benchmarks/results/; it does not go with --out")
    if a.update_results and a.quick:
        raise UserError(
            "--update-results takes full runs only; a --quick run never replaces the committed results"
        )
    if a.update_results:
        out = results_dir
    elif a.out is not None:
        out = Path(a.out).expanduser()
    else:
        out = _bench_user_dir() / ("quick" if a.quick else "")
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise UserError(f"cannot write benchmark results to {out}: {exc.strerror or exc}") from None
    return out


def cmd_bench(a) -> int:
    bm = _benchmarks_module()
    if a.list:
        print("\n".join(bm.available()))
        return 0
    unknown = [n for n in a.names if n not in bm.available()]
    if unknown:
        raise UserError(f"unknown benchmark(s) {unknown}; available: {', '.join(bm.available())}")
    out = _bench_out(a, bm.RESULTS_DIR)
    bm.run(a.names or None, quick=a.quick, out_dir=out)
    return 0


# ---------------------------------------------------------------------------------- shared helpers
def _load_model(name, params=None, tool=None, locked=None):
    """Load a catalog model, an example-robot-data robot or a URDF path (:func:`anthroarm.load`);
    its typed errors (unknown name, a tree without a tool, bad keywords) print as one line."""
    from . import load

    kw = {k: v for k, v in (("tool", tool), ("locked", locked)) if v is not None}
    return load(name, **kw, **(params or {}))


def _parse_q(robot, values, deg: bool, what: str = "--q"):
    """A configuration from one value per joint (rad or m; degrees with --deg; a continuous
    joint takes its angle).  Values outside the limits are kept, with a warning."""
    import numpy as np

    if values is None:
        return robot.neutral()
    names = robot.joint_names
    if len(values) != len(names):
        raise UserError(
            f"{what} needs {len(names)} values for {robot.name} (joints: {', '.join(names)}), "
            f"got {len(values)}"
        )
    theta = np.deg2rad(values) if deg else np.asarray(values, float)
    q = robot.check_q(robot.chain.configuration(theta), what)
    joints = [robot.chain.joints[i] for i in robot.chain.independent]
    bad = [j.name for j, t in zip(joints, theta) if not j.lower - 1e-9 <= t <= j.upper + 1e-9]
    if bad:
        print(
            f"anthroarm: warning: {what} is outside the joint limits of {', '.join(bad)}",
            file=sys.stderr,
        )
    return q


def _joint_values(robot, q):
    """One value per joint of ``robot.joint_names`` (a continuous joint: its angle)."""
    return robot.angles(q)[list(robot.chain.independent)]


def _check_html_path(path):
    if path is None:
        return None
    out = Path(path)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist (for --html {path})")
    if out.is_dir():
        raise UserError(f"--html {path} is a folder; give a file name such as {out / 'scene.html'}")
    return out


def _progress(total: int, desc: str, enabled: bool):
    """A tqdm bar on stderr (only when stderr is a terminal and enabled)."""
    from tqdm import tqdm

    return tqdm(
        total=total,
        desc=desc,
        file=sys.stderr,
        disable=not (enabled and sys.stderr.isatty()),
        leave=False,
    )


def _serve(viewer, open_browser: bool, seconds: float | None) -> int:
    """Keep a live viewer running until Ctrl-C (or ``seconds``)."""
    import time

    print(f"viewer at {viewer.url}  (Ctrl-C to stop)", flush=True)
    if open_browser:
        viewer.open()
    try:
        if seconds is None:
            while viewer.server is not None and viewer.server.alive:
                time.sleep(0.5)
        else:
            time.sleep(max(0.0, seconds))
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
    return 0


def _export_or_serve(viewer, out, a, announce: bool = True) -> int:
    """Write the scene to ``out`` (``--html``), or serve it live until Ctrl-C / ``--seconds``."""
    if out is not None:
        viewer.export_html(out)
        if announce:
            print(f"wrote {out}")
        return 0
    return _serve(viewer, not a.no_browser, a.seconds)


def _check_port_early(a):
    """Fail before any long work (and before a server or a browser starts) when an explicit
    --port is taken or invalid, or --seconds is not a finite number >= 0."""
    import math

    if a.seconds is not None and not (math.isfinite(a.seconds) and a.seconds >= 0):
        raise UserError(f"--seconds must be a finite number >= 0, got {a.seconds}")
    if getattr(a, "html", None) is None and a.port is not None:
        from .viewer.server import _in_use_message, port_is_free

        if not 1 <= a.port <= 65535:
            raise UserError(f"--port must be in 1..65535, got {a.port}")
        if not port_is_free(a.port):
            raise UserError(_in_use_message(a.port))


def _add_live_options(p):
    p.add_argument(
        "--html",
        metavar="FILE",
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


# ---------------------------------------------------------------------------------- view
def _add_view(sub):
    p = sub.add_parser(
        "view",
        help="show a model in the browser (meshcat) or write it to HTML",
        description="Show a catalog model, an example-robot-data robot or a URDF file in a meshcat viewer on "
        "127.0.0.1, or write a self-contained HTML file.  Angles are radians unless --deg.",
        epilog="examples:\n  anthroarm view human_arm7 --q 40 -20 10 70 0 0 10 --deg --limits\n"
        "  anthroarm view panda --html panda.html --workspace 3000",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_model_arguments(p)
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
    p.add_argument(
        "--style",
        choices=["auto", "generated", "urdf"],
        default="auto",
        help="visuals (default auto)",
    )
    _add_live_options(p)
    p.set_defaults(func=cmd_view)


def cmd_view(a) -> int:
    from .viewer import Viewer

    out = _check_html_path(a.html)
    _check_port_early(a)
    robot = _load_model(
        a.model, _parse_params(a.param, a.model, a), a.tool, _parse_locked(a.locked)
    )
    if not 0 <= a.workspace <= MAX_SAMPLES:
        raise UserError(f"--workspace must be in 0..{MAX_SAMPLES}, got {a.workspace}")
    q = _parse_q(robot, a.q, a.deg)
    v = Viewer(robot, live=out is None, port=a.port, style=a.style, q=q)
    if a.frames:
        v.show_frames("joints")
    if a.workspace:
        v.show_workspace(a.workspace)
    if a.limits:
        v.show_limits()
    return _export_or_serve(v, out, a)


# ---------------------------------------------------------------------------------- demo
def _add_demo(sub):
    p = sub.add_parser(
        "demo",
        help="the human arm reaching for a sequence of targets (QP IK), in the browser or to HTML",
        description="The §6-3 human arm (human_arm7) reaches for five hand poses in turn and returns to rest, "
        "driven by QP differential IK (anthroarm.ik.qp; damped least squares if that layer is missing). "
        "The motion plays as a looping meshcat animation with the targets and the hand's path.",
        epilog="examples:\n  anthroarm demo\n  anthroarm demo --html demo.html",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="human_arm7 parameter, e.g. height=1.62 (repeatable)",
    )
    p.add_argument(
        "--method",
        choices=["auto", "qp", "dls"],
        default="auto",
        help="IK stepper (default auto: qp)",
    )
    p.add_argument("--solver", default="osqp", help="QP solver for --method qp (default osqp)")
    p.add_argument("--json", action="store_true", help="print the per-target errors as JSON")
    _add_live_options(p)
    p.set_defaults(func=cmd_demo)


def cmd_demo(a) -> int:
    from .viewer.demo import demo_viewer, reach_demo

    out = _check_html_path(a.html)
    _check_port_early(a)
    robot = _load_model("human_arm7", _parse_params(a.param, "human_arm7", a))
    bar = _progress(6, "reaching", not a.json)

    def tick(done, total):
        bar.total = total
        bar.update(done - bar.n)

    try:
        res = reach_demo(robot, method=a.method, solver=a.solver, progress=tick)
    finally:
        bar.close()
    if a.json:
        print(
            json.dumps(
                {
                    "method": res.method,
                    "dt": res.dt,
                    "steps": int(len(res.Q)),
                    "targets": [
                        {"name": n, "pos_err_m": pe, "rot_err_rad": re} for n, pe, re in res.errors
                    ],
                },
                indent=1,
            )
        )
    else:
        print(f"IK: {res.method}; {len(res.Q)} steps of {res.dt * 1000:.0f} ms")
        for n, pe, re in res.errors:
            print(f"  {n:<18} position error {pe * 1000:8.3f} mm   orientation error {re:.2e} rad")
    v = demo_viewer(res, live=out is None, port=a.port)
    return _export_or_serve(v, out, a, announce=not a.json)


# ---------------------------------------------------------------------------------- ik
def _add_ik(sub):
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
    _add_model_arguments(p)
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
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=cmd_ik)


def cmd_ik(a) -> int:
    import math

    import numpy as np
    import pinocchio as pin

    robot = _load_model(
        a.model, _parse_params(a.param, a.model, a), a.tool, _parse_locked(a.locked)
    )
    if not all(math.isfinite(x) for x in [*a.xyz, *a.rpy]):
        raise UserError("--xyz and --rpy must be finite numbers")
    from .urdf_io import MAX_LENGTH

    if max(map(abs, a.xyz)) > MAX_LENGTH:
        raise UserError(
            f"--xyz {' '.join(map(str, a.xyz))} is beyond the physical bound of {MAX_LENGTH:g} m"
        )
    rpy = np.deg2rad(a.rpy) if a.deg else np.asarray(a.rpy, float)
    T = np.eye(4)
    T[:3, :3] = pin.rpy.rpyToMatrix(*rpy)
    T[:3, 3] = a.xyz
    if a.frame is not None:
        robot.frame_id(a.frame)  # UnknownFrameError (one line, lists the frames)
    q0 = _parse_q(robot, a.q0, a.deg, "--q0") if a.q0 is not None else None
    bar = _progress(1, "ik", not a.json)
    try:
        res = solve_pose(robot, T, q0=q0, frame=a.frame)
    finally:
        bar.close()
    conv = (
        (lambda x: np.rad2deg(_joint_values(robot, x)))
        if a.deg
        else (lambda x: _joint_values(robot, x))
    )
    if a.json:
        out = {
            "model": robot.name,
            "frame": a.frame or robot.tool,
            "xyz": list(a.xyz),
            "rpy": list(a.rpy),
            "units": "deg" if a.deg else "rad",
            **res.to_dict(conv, robot.joint_names),
        }
        print(json.dumps(out, indent=1))
    else:
        unit = "deg" if a.deg else "rad"
        print(
            f"{robot.name}: {'solved' if res.success else 'NOT solved'} ({res.status}) by {res.method}"
        )
        if res.q is not None:
            for n, v in zip(robot.joint_names, conv(res.q)):
                print(f"  {n:<22} {v: .6f} {unit}")
            print(f"  position error {res.pos_err:.3e} m, orientation error {res.rot_err:.3e} rad")
        if len(res.solutions) > 1:
            print(
                f"  {len(res.solutions)} closed-form branches inside the limits (--json lists them)"
            )
    return 0 if res.success else 1


# ---------------------------------------------------------------------------------- ik glue
class _IKOutcome:
    """What ``anthroarm ik`` reports, whichever solver produced it."""

    def __init__(self, q, success, status, pos_err, rot_err, iterations, method, solutions=()):
        self.q, self.success, self.status = q, bool(success), str(status)
        self.pos_err, self.rot_err, self.iterations, self.method = (
            pos_err,
            rot_err,
            int(iterations),
            method,
        )
        self.solutions = list(solutions)

    def to_dict(self, conv, joint_names) -> dict:
        as_list = lambda x: [float(v) for v in conv(x)]  # noqa: E731
        return {
            "success": self.success,
            "status": self.status,
            "method": self.method,
            "q": dict(zip(joint_names, as_list(self.q))) if self.q is not None else None,
            "pos_err_m": self.pos_err,
            "rot_err_rad": self.rot_err,
            "iterations": self.iterations,
            "closed_form_solutions": [as_list(q) for q in self.solutions],
        }


def _pose_err(robot, q, T, frame):
    import numpy as np
    import pinocchio as pin

    F = robot.fk(q, frame)
    return float(np.linalg.norm(F[:3, 3] - T[:3, 3])), float(
        np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))
    )


def solve_pose(robot, T, q0=None, frame=None) -> _IKOutcome:
    """IK for the CLI: ``aa.ik.solve``, plus every closed-form branch inside the limits
    (``aa.ik.analytic``) for an arm that has one at the frame (default the tool).  Errors are recomputed here from
    ``robot.fk`` whatever the solver says."""
    import numpy as np

    from . import ik

    sols = []
    if ik.has_analytic(robot, frame):
        sols = list(np.reshape(ik.analytic(robot, T, frame=frame).solutions, (-1, robot.nq)))
    r = ik.solve(robot, T, q0=q0, frame=frame)
    pe, re = _pose_err(robot, r.q, T, frame)
    return _IKOutcome(r.q, r.success, r.status, pe, re, r.iterations, "aa.ik.solve", sols)


# ---------------------------------------------------------------------------------- cache
def _add_cache(sub):
    p = sub.add_parser(
        "cache",
        help="show or empty the cache of generated code",
        description="The disk cache of generated Lagrange code and compiled C kernels "
        "($ANTHROARM_CACHE, else $XDG_CACHE_HOME/anthroarm, else the user cache folder).",
        epilog="examples: anthroarm cache info --json; anthroarm cache clear",
    )
    p.add_argument(
        "action",
        choices=["info", "clear"],
        help="info: folder, entries, size and whether it is used; clear: delete the cache's "
        "own files (refused, exit status 2, if the folder is a link, another user's, or "
        "writable by group or others)",
    )
    p.add_argument("--json", action="store_true", help="print as JSON")
    p.set_defaults(func=cmd_cache)


def cmd_cache(a) -> int:
    from . import cache

    if a.action == "clear":
        where = str(cache.configured())  # the folder asked for; clear() refuses an unsafe one
        n = cache.clear()
        print(
            json.dumps({"folder": where, "removed": n})
            if a.json
            else f"removed {n} entries from {where}"
        )
        return 0
    i = cache.info()
    if a.json:
        print(json.dumps(i, indent=1))
    else:
        print(f"folder  {i['folder']}")
        print(f"entries {i['entries']} ({i['bytes'] / 1e6:.2f} MB)")
        for sub, (n, size) in i["by_folder"].items():
            print(f"  {sub:<9} {n:4d} entries {size / 1e6:8.2f} MB")
        print(f"status  {i['status']}")
    return 0


# ---------------------------------------------------------------------------- batch (anthroarm.batch)
def _batch_parser(sub):
    p = sub.add_parser(
        "batch",
        help="batch jobs, locally or on a Dask cluster (reach, comfort, population, tolerance, ik, cells)",
        description="Run a batch job of anthroarm.batch in this process (default), on a LocalCluster "
        "(--scheduler local --workers N) or on a running Dask scheduler (--scheduler tcp://HOST:8786); "
        "the same numbers either way. The result is written atomically when the job has finished.",
        epilog="example: anthroarm batch reach --model human_arm7 --param height=1.62 --n 1000000 "
        "--scheduler local --workers 2 --out reach.npz --plot reach.png",
    )
    p.add_argument("job", choices=["reach", "comfort", "population", "tolerance", "ik", "cells"])
    p.add_argument(
        "--model", default="human_arm7", help="catalog name, example-robot-data name or URDF path"
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="book-model parameter, e.g. height=1.62 (repeatable)",
    )
    _add_robot_options(p)
    p.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS|local",
        help="Dask scheduler address, or 'local' for a LocalCluster (default: this process)",
    )
    p.add_argument(
        "--workers", type=int, default=None, help="worker processes of --scheduler local"
    )
    p.add_argument(
        "--timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)"
    )
    p.add_argument(
        "--n",
        type=int,
        default=None,
        help="configurations (reach, comfort, population: per person), samples (tolerance), targets (ik)",
    )
    p.add_argument("--voxel", type=float, default=0.02, help="voxel side, m (default 0.02)")
    p.add_argument(
        "--chunk-size", type=int, default=None, help="work items per task (default: the job's)"
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--heights", default="1.55,1.65,1.75,1.85", help="population: heights, m (comma-separated)"
    )
    p.add_argument("--masses", default="60,75", help="population: masses, kg")
    p.add_argument("--sexes", default="female,male", help="population: sexes")
    p.add_argument(
        "--configs", type=int, default=10, help="tolerance: random configurations (default 10)"
    )
    p.add_argument(
        "--sigma-q", type=float, default=1e-3, help="tolerance: joint error, rad (default 1e-3)"
    )
    p.add_argument(
        "--sigma-l", type=float, default=1e-4, help="tolerance: link length error, m (default 1e-4)"
    )
    p.add_argument("--D", type=float, default=0.05, help="cells: lattice spacing, m (default 0.05)")
    p.add_argument(
        "--out", default=None, metavar="FILE.npz", help="write the result here (atomically)"
    )
    p.add_argument(
        "--plot",
        default=None,
        metavar="FILE.png",
        help="reach/comfort: a slice; population: volumes",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_batch)


def _cmd_batch(a) -> int:
    import numpy as np

    from . import batch

    def floats(text, what):
        try:
            return [float(x) for x in text.split(",") if x.strip()]
        except ValueError:
            raise UserError(f"--{what} expects comma-separated numbers, got {text!r}") from None

    if a.workers is not None and a.scheduler != "local":
        raise UserError(
            "--workers goes with --scheduler local (a running scheduler has its own workers)"
        )
    params = _parse_params(a.param, a.model)
    kw = dict(progress=not a.no_progress, seed=a.seed)
    if a.chunk_size is not None:
        kw["chunk_size"] = a.chunk_size
    if a.n is not None:
        kw["n"] = a.n
    args = ()
    if a.job == "population":
        kw.update(
            model=a.model,
            heights=floats(a.heights, "heights"),
            masses=floats(a.masses, "masses"),
            sexes=[s.strip() for s in a.sexes.split(",") if s.strip()],
            voxel=a.voxel,
        )
    else:
        robot = _load_model(a.model, params, a.tool, _parse_locked(a.locked))
        args = (robot,)
        if a.job in ("reach", "comfort"):
            kw["voxel"] = a.voxel
        elif a.job == "tolerance":
            args += (robot.random_q(a.configs, rng=a.seed, margin=0.05),)
            kw.update(sigma_q=a.sigma_q, sigma_L=a.sigma_l)
        elif a.job == "ik":
            n = kw.pop("n", 1000)
            args += (robot.fk(robot.random_q(n, rng=a.seed, margin=0.05)),)  # reachable targets
        elif a.job == "cells":
            kw.pop("seed")
            kw.pop("n", None)
            kw["D"] = a.D
    res = batch.run_job(
        a.job,
        *args,
        out=a.out,
        plot=a.plot,
        scheduler=a.scheduler,
        workers=a.workers,
        timeout=a.timeout,
        **kw,
    )
    summary = {"job": res.job, **{k: list(v.shape) for k, (_, v) in res.variables.items()}}
    for k in ("volume", "n", "outside"):
        if k in res.attrs:
            summary[k] = res.attrs[k]
    if a.job == "ik":
        summary["success_rate"] = float(np.mean(res["success"]))
    if a.job == "population":
        summary["volume_m3"] = [round(float(v), 6) for v in res["volume"].ravel()]
    if a.out:
        summary["out"] = a.out
    print(json.dumps(summary))
    return 0


def build_parser(argv=None) -> argparse.ArgumentParser:
    """The parser; given the command line, a book model's builder parameters become options of
    the commands that take a model (``anthroarm urdf human_arm7 --height 1.62``, listed by
    ``--help``)."""
    ap = _Parser(
        prog="anthroarm",
        description="anthroarm: the book's arms, kinematics, IK and dynamics, proven against Pinocchio.",
        epilog="run 'anthroarm COMMAND --help' for the options and an example of each command",
    )
    from . import __version__

    ap.add_argument("--version", action="version", version=f"anthroarm {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    from .motion.commands import add_parser as _ik_markers_parser
    from .prosthesis.commands import add_parser as _size_parser
    from .viewer.commands import add_parser as _teach_parser

    for add in (
        _add_check,
        _add_models,
        _add_ik,
        _add_view,
        _teach_parser,
        _add_demo,
        _add_urdf,
        _add_bench,
        _add_cache,
        _batch_parser,
        _size_parser,
        _ik_markers_parser,
    ):
        add(sub)
    argv = list(sys.argv[1:] if argv is None else argv)
    cmd = next((i for i, t in enumerate(argv) if not t.startswith("-")), None)
    if cmd is not None and argv[cmd] in _MODEL_COMMANDS:
        sp = sub.choices[argv[cmd]]
        model = _MODEL_COMMANDS[argv[cmd]] or _prescan_model(sp, argv[cmd + 1 :])
        _add_model_param_options(sp, model)
    return ap


def _unknown_options_error(a, extras) -> int:
    """One line for arguments no option takes: for a command that takes a model, name the
    model's parameters (or say it has none)."""
    model = getattr(a, "_model", None) or getattr(a, "model", None)
    if (
        a.command in _MODEL_COMMANDS
        and isinstance(model, str)
        and any(e.startswith("--") for e in extras)
    ):
        names = _param_names(model)
        if names:
            msg = f"unknown option(s) {' '.join(extras)} for {model}; its parameters: {names} (or --param NAME=VALUE)"
        else:
            from . import models

            msg = (
                f"unrecognized arguments: {' '.join(extras)} ({model} has no builder parameters; "
                f"the book models have: {', '.join(models.book_names())})"
            )
        return _one_line_error(a.command, msg + f" (see 'anthroarm {a.command} {model} --help')")
    return _one_line_error(
        a.command or "", f"unrecognized arguments: {' '.join(extras)} (see 'anthroarm --help')"
    )


def main(argv=None) -> int:
    ap = build_parser(argv)
    a, extras = ap.parse_known_args(argv)
    if not getattr(a, "command", None):
        if extras:
            ap.error(f"unrecognized arguments: {' '.join(extras)}")
        ap.print_help()
        return 2
    if extras:
        return _unknown_options_error(a, extras)
    try:
        return int(a.func(a) or 0)
    except (UserError, AnthroarmError, ValueError, FileNotFoundError) as exc:
        return _one_line_error(a.command, str(exc))
    except KeyboardInterrupt:
        print(f"anthroarm {a.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` etc.
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (
        OSError
    ) as exc:  # a folder or device as the target, read-only or full disk, no permission
        where = f"{exc.filename}: " if exc.filename else ""
        return _one_line_error(a.command, f"{where}{exc.strerror or exc}")
    except MemoryError:
        return _one_line_error(a.command, "out of memory (ask for fewer samples or points)")


def _one_line_error(command: str, message: str) -> int:
    print(f"anthroarm {command}: error: {' '.join(message.split())}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
