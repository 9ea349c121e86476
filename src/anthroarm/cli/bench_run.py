"""``anthroarm bench``: the run (the parser: :mod:`.bench`); needs a source checkout (the
repository's ``benchmarks/`` package)."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from .bench import user_dir
from .common import UserError

#: the repository of a source checkout (src/anthroarm/cli/ -> the root)
ROOT = Path(__file__).resolve().parents[3]


def benchmarks_module():
    if not (ROOT / "benchmarks" / "__main__.py").is_file():
        raise UserError("the benchmarks/ folder is not available (run from a source checkout)")
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    import benchmarks.__main__ as bm

    return bm


def out_folder(a, results_dir: Path) -> Path:
    """The folder ``anthroarm bench`` writes to, created and proven writable before any run."""
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
        out = user_dir() / ("quick" if a.quick else "")
    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise UserError(f"cannot write benchmark results to {out}: {exc.strerror or exc}") from None
    return out


def run(a) -> int:
    bm = benchmarks_module()
    if a.list:
        print("\n".join(bm.available()))
        return 0
    unknown = [n for n in a.names if n not in bm.available()]
    if unknown:
        raise UserError(f"unknown benchmark(s) {unknown}; available: {', '.join(bm.available())}")
    out = out_folder(a, bm.RESULTS_DIR)
    bm.run(a.names or None, quick=a.quick, out_dir=out)
    return 0
