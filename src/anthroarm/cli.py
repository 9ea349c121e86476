"""The ``anthroarm`` command line.

User mistakes (unknown model, bad arguments, missing folders) print one line to stderr and
exit with status 2; failed checks exit with status 1.  No tracebacks for user mistakes.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import AnthroarmError


class UserError(Exception):
    """A mistake in the command line; printed as one line, exit status 2."""


def _add_check(sub):
    p = sub.add_parser(
        "check",
        help="cross-check the book's closed forms against Pinocchio",
        description="Cross-check every closed form against Pinocchio on random configurations inside the limits.",
        epilog="example: anthroarm check --models prosthetic_arm human_arm7 --samples 500 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--models", nargs="*", default=None, help="restrict to these catalog models")
    p.add_argument("--samples", type=int, default=200, help="random configurations per model (default 200)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.set_defaults(func=cmd_check)


def cmd_check(a) -> int:
    from . import crosscheck

    if a.samples < 1:
        raise UserError("--samples must be >= 1")
    rows = crosscheck.run(a.models, samples=a.samples, seed=a.seed, progress=not a.json and sys.stderr.isatty())
    print(crosscheck.to_json(rows) if a.json else crosscheck.format_table(rows))
    return 0 if all(r.ok for r in rows) else 1


def _add_models(sub):
    p = sub.add_parser(
        "models",
        help="list the model catalog",
        description="List the catalog: the book's models and the example-robot-data arms.",
        epilog="example: anthroarm models --json",
    )
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_models)


def cmd_models(a) -> int:
    from . import models

    out = []
    for n in models.names():
        if n in models.BOOK_MODELS:
            s = models.spec(n)
            out.append({"name": n, "nq": s.nq, "tool": s.tool_name, "source": s.source, "description": s.description})
        else:
            arm = models.ERD_ARMS[n]
            out.append({"name": n, "nq": len(arm.active) if arm.active else None, "tool": arm.tool,
                        "source": f"example-robot-data {arm.subpath}", "description": arm.description})
    if a.json:
        print(json.dumps(out, indent=1))
    else:
        w = max(len(o["name"]) for o in out)
        for o in out:
            print(f"{o['name']:<{w}}  nq={o['nq'] if o['nq'] is not None else '?':<2}  {o['description']}")
    return 0


def _add_urdf(sub):
    p = sub.add_parser(
        "urdf",
        help="write a catalog URDF with chosen parameters",
        description="Write the URDF of a book model; parameters are the model builder's keyword arguments.",
        epilog="example: anthroarm urdf human_arm7 -o arm.urdf --param height=1.62 --param mass=55 --param sex=female",
    )
    p.add_argument("model")
    p.add_argument("-o", "--output", required=True, help="output .urdf file")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE", help="builder parameter (repeatable)")
    p.set_defaults(func=cmd_urdf)


def _parse_params(items) -> dict:
    params = {}
    for it in items:
        if "=" not in it:
            raise UserError(f"--param expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        try:
            params[k] = float(v)
        except ValueError:
            params[k] = v
    return params


def cmd_urdf(a) -> int:
    from . import models
    from .urdf_io import atomic_write_text

    if a.model not in models.BOOK_MODELS:
        if a.model in models.ERD_ARMS:
            raise UserError(f"{a.model} comes from example-robot-data; its URDF is {models.urdf_path(a.model)}")
        raise UserError(f"unknown model {a.model!r}; the book models are: {', '.join(models.book_names())}")
    out = Path(a.output)
    if not out.parent.is_dir():
        raise UserError(f"folder {out.parent} does not exist")
    text = models.urdf_text(a.model, **_parse_params(a.param))
    atomic_write_text(out, text)
    print(f"wrote {out}")
    return 0


def _add_bench(sub):
    p = sub.add_parser(
        "bench",
        help="run benchmarks (JSON + markdown in benchmarks/results)",
        description="Run the benchmark suite side by side with the peers.",
        epilog="example: anthroarm bench fk --quick",
    )
    p.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    p.add_argument("--quick", action="store_true", help="fewer samples")
    p.add_argument("--list", action="store_true", help="list the benchmarks")
    p.set_defaults(func=cmd_bench)


def _benchmarks_module():
    root = Path(__file__).resolve().parents[2]
    if not (root / "benchmarks" / "__main__.py").is_file():
        raise UserError("the benchmarks/ folder is not available (run from a source checkout)")
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    import benchmarks.__main__ as bm

    return bm


def cmd_bench(a) -> int:
    bm = _benchmarks_module()
    if a.list:
        print("\n".join(bm.available()))
        return 0
    unknown = [n for n in a.names if n not in bm.available()]
    if unknown:
        raise UserError(f"unknown benchmark(s) {unknown}; available: {', '.join(bm.available())}")
    bm.run(a.names or None, quick=a.quick)
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="anthroarm",
        description="anthroarm: the book's arms, kinematics, IK and dynamics, proven against Pinocchio.",
        epilog="run 'anthroarm COMMAND --help' for the options and an example of each command",
    )
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    for add in (_add_check, _add_models, _add_urdf, _add_bench):
        add(sub)
    return ap


def main(argv=None) -> int:
    ap = build_parser()
    a = ap.parse_args(argv)
    if not getattr(a, "command", None):
        ap.print_help()
        return 2
    try:
        return int(a.func(a) or 0)
    except (UserError, AnthroarmError, ValueError, FileNotFoundError) as exc:
        print(f"anthroarm {a.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
