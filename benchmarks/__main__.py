"""Runner: ``python -m benchmarks [NAME ...] [--quick] [--list]``."""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import pkgutil
import sys
from pathlib import Path

from .common import (
    QUICK_DIR,
    RESULTS_DIR,
    compiled_kernels,
    markdown_table,
    steady_state_allocator,
    write_result,
)


def available() -> list[str]:
    here = Path(__file__).resolve().parent
    return sorted(
        m.name[len("bench_") :]
        for m in pkgutil.iter_modules([str(here)])
        if m.name.startswith("bench_")
    )


#: import names of the packages of pyproject's ``bench`` extra (the peers)
BENCH_EXTRA = (
    "pink",
    "ikpy",
    "daqp",
    "quadprog",
    "proxsuite",
    "roboticstoolbox",
    "pytracik",
    "ik_geo",
    "mink",
)


def run(names=None, quick: bool = False, out_dir=None) -> list[Path]:
    """Run benchmarks and write their results: full runs to ``results/``, quick runs to
    ``results/quick/`` (git-ignored; never to ``results/``), or both to ``out_dir``."""
    names = names or available()
    unknown = [n for n in names if n not in available()]
    if unknown:
        raise SystemExit(f"unknown benchmark(s) {unknown}; available: {', '.join(available())}")
    missing = [m for m in BENCH_EXTRA if importlib.util.find_spec(m) is None]
    if missing and not quick and out_dir is None:
        # a full run into results/ without a peer would commit a table with its rows missing
        raise SystemExit(
            f"the peers {', '.join(missing)} are not installed: a full run writes the committed "
            "tables, which compare against every peer; pip install -e '.[bench]' (or run "
            "--quick, or --out FOLDER)"
        )
    if any(n != "cold_start" for n in names):  # cold_start makes its own fresh processes
        compiled_kernels(strict=not quick and out_dir is None)
    written = []
    for n in names:
        mod = importlib.import_module(f"benchmarks.bench_{n}")
        print(
            f"== benchmark {n}: {mod.__doc__.strip().splitlines()[0] if mod.__doc__ else ''}",
            flush=True,
        )
        steady_state_allocator()
        result = mod.run(quick=quick)
        if quick:
            result["quick"] = True
        jp, mp = write_result(n, result, out_dir)
        print(markdown_table(result["columns"], result["rows"]))
        print(f"-> {jp}\n-> {mp}\n", flush=True)
        written += [jp, mp]
    return written


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks", description="Run anthroarm's benchmarks."
    )
    ap.add_argument(
        "names", nargs="*", help=f"benchmarks to run (default: all): {', '.join(available())}"
    )
    ap.add_argument(
        "--quick",
        action="store_true",
        help=f"fewer samples, for smoke tests (written to {QUICK_DIR})",
    )
    ap.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    ap.add_argument(
        "--out",
        default=None,
        help=f"output folder (default {RESULTS_DIR}; with --quick {QUICK_DIR}, never {RESULTS_DIR})",
    )
    a = ap.parse_args(argv)
    if a.list:
        print("\n".join(available()))
        return 0
    run(a.names, quick=a.quick, out_dir=a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
