"""Shared helpers of the benchmarks: timing, environment description, result writing."""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path
from statistics import median

from anthroarm import jit
from anthroarm._io import atomic_write_text

RESULTS_DIR = Path(__file__).resolve().parent / "results"
#: where ``--quick`` runs write (git-ignored): results/ holds committed full runs only
QUICK_DIR = RESULTS_DIR / "quick"


#: how long a benchmark waits for the background compilation of anthroarm's kernels (s)
COMPILE_WAIT = 3600.0


def compiled_kernels(strict: bool) -> None:
    """Warm tables measure compiled kernels: wait until this process runs them (on a cache
    without them, the first call starts the background compilation, minutes; until it is done
    every kernel runs in the interpreter and a table would time that).  ``strict`` (a full run
    into results/) exits when the kernels still run in the interpreter (``ANTHROARM_JIT=
    reference``, or a compilation that failed); otherwise a warning."""
    if jit.wait(COMPILE_WAIT):
        return
    msg = f"anthroarm's kernels run in the interpreter ({jit.status()}): warm times would be wrong"
    if strict:
        raise SystemExit(msg + "; a full run into results/ needs compiled kernels")
    print("warning: " + msg, flush=True)


def time_call(fn, *, number: int = 1, repeat: int = 7, min_time: float = 0.0) -> float:
    """Median wall time (s) of one call of ``fn`` over ``repeat`` runs of ``number`` calls.

    ``number`` grows (doubling) until one run lasts at least ``min_time`` seconds."""
    fn()  # warm-up
    if min_time > 0:
        while True:
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            if time.perf_counter() - t0 >= min_time or number >= 1 << 20:
                break
            number *= 2
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        runs.append((time.perf_counter() - t0) / number)
    return median(runs)


def steady_state_allocator(nbytes: int = 16 * 1024 * 1024) -> None:
    """Bring the C allocator to the state a long-running program is in.

    glibc serves large allocations (> 128 kB at start) with fresh mmap pages, which page-fault
    on first touch; after the first large block is freed it raises that threshold, and later
    batches reuse heap memory.  Without this, whichever benchmark row runs first with N = 10 000
    pays ~0.3 µs per configuration of page faults that no later row pays.  Allocating and
    freeing one large block up front makes every row measure the steady state."""
    import numpy as np

    a = np.ones(nbytes // 8)
    del a


def environment() -> dict:
    import numpy
    import pinocchio

    return {
        "python": platform.python_version(),
        "machine": platform.machine(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        "numpy": numpy.__version__,
        "pinocchio": pinocchio.__version__,
        "date": time.strftime("%Y-%m-%d %H:%M:%S"),
    }


def markdown_table(columns: list[str], rows: list[list]) -> str:
    def fmt(x):
        if isinstance(x, float):
            if x == 0:
                return "0"
            if abs(x) >= 1000 or abs(x) < 0.01:
                return f"{x:.3g}"
            return f"{x:.3f}".rstrip("0").rstrip(".")
        return str(x)

    out = ["| " + " | ".join(columns) + " |", "|" + "|".join("---" for _ in columns) + "|"]
    out += ["| " + " | ".join(fmt(x) for x in r) + " |" for r in rows]
    return "\n".join(out)


def write_result(name: str, result: dict, out_dir: Path | None = None) -> tuple[Path, Path]:
    """Write ``<name>.json`` and ``<name>.md`` (and the figures, if any); ``result`` has title,
    columns, rows, notes, optionally ``figures`` {file name: matplotlib figure} and ``quick``.

    A quick run never writes into :data:`RESULTS_DIR` (the committed full runs): it goes to
    :data:`QUICK_DIR` unless ``out_dir`` names another folder."""
    result = dict(result)
    quick = bool(result.get("quick"))
    out = Path(out_dir) if out_dir else (QUICK_DIR if quick else RESULTS_DIR)
    if quick and out.resolve() == RESULTS_DIR.resolve():
        raise ValueError(
            f"a quick run does not write into {RESULTS_DIR} (committed full runs); "
            f"default for quick runs: {QUICK_DIR}"
        )
    out.mkdir(parents=True, exist_ok=True)
    figures = result.pop("figures", None) or {}
    result.setdefault("environment", environment())
    jp, mp = out / f"{name}.json", out / f"{name}.md"
    atomic_write_text(jp, json.dumps(result, indent=1, default=float))
    title = result.get("title", name) + (" (quick run)" if quick else "")
    md = [f"# {title}", ""]
    if result.get("notes"):
        md += [result["notes"], ""]
    md.append(markdown_table(result["columns"], result["rows"]))
    env = result["environment"]
    md += [
        "",
        f"Machine: {env['processor']}, {env['cpus']} CPUs, Python {env['python']}, numpy {env['numpy']}, "
        f"pinocchio {env['pinocchio']}; {env['date']}.",
    ]
    atomic_write_text(mp, "\n".join(md) + "\n")
    for fname, fig in figures.items():
        if fig is not None:
            import matplotlib.pyplot as plt

            fig.savefig(out / fname, dpi=110)
            plt.close(fig)
    return jp, mp
