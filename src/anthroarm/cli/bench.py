"""``anthroarm bench``: the benchmark suite (parser; the run: :mod:`.bench_run`)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .common import add_out


def user_dir() -> Path:
    """Default folder of ``anthroarm bench``: the platform's user data folder
    (``$XDG_DATA_HOME/anthroarm/benchmarks``, else ``~/.local/share/anthroarm/benchmarks`` on
    Linux and other Unix; ``~/Library/Application Support`` on macOS; ``%LOCALAPPDATA%`` on
    Windows)."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        xdg = os.environ.get("XDG_DATA_HOME", "")
        base = Path(xdg) if xdg and Path(xdg).is_absolute() else Path.home() / ".local" / "share"
    return base / "anthroarm" / "benchmarks"


def add_parser(sub):
    p = sub.add_parser(
        "bench",
        help="run benchmarks (JSON + markdown in a user folder, or -o/--out)",
        description="Run the benchmark suite side by side with the peers and write JSON + markdown tables "
        f"(and figures) to -o/--out; default: {user_dir()} ($XDG_DATA_HOME honoured), "
        "its 'quick' subfolder with --quick.  The committed benchmarks/results/ of a source "
        "checkout is written only with --update-results (full runs).",
        epilog="examples:\n  anthroarm bench fk --quick\n  anthroarm bench ik -o ./my_results\n"
        "  anthroarm bench --update-results        # maintainers: refresh benchmarks/results/",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    p.add_argument(
        "--quick", action="store_true", help="fewer samples (never written to benchmarks/results/)"
    )
    p.add_argument("--list", action="store_true", help="list the benchmarks")
    add_out(p, metavar="FOLDER", help="output folder (created if missing)")
    p.add_argument(
        "--update-results",
        action="store_true",
        help="write into the committed benchmarks/results/ (full runs only)",
    )
    p.set_defaults(run="bench_run.run")
