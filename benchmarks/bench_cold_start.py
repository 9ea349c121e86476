"""First calls in a fresh process with an empty cache, then warm: every public entry point that
runs compiled kernels, in the default mode (``ANTHROARM_JIT=auto``: the reference path while a
background process compiles) against ``compile`` (Numba's own behaviour: the kernels compile on
the caller's clock, what every release before this one did), and the same calls in a process
that finds the cache ready.

Each row is one fresh Python process (``python -c``) with a new ``ANTHROARM_CACHE`` and
``NUMBA_CACHE_DIR``; the time of a call is wall time around that call only (the imports of
``anthroarm`` and the model's load are timed apart).  The background compilation a cold ``auto``
process starts is stopped when the process ends, so rows do not load each other; the warm rows
run after one full background compilation (``python -m anthroarm.warmup``).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

SCRIPT = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import anthroarm as aa
from anthroarm import hand, motion
from anthroarm.ik import qp
t_import = time.perf_counter() - t0
name = sys.argv[1]
out = {"import": t_import}

def timed(label, fn):
    t = time.perf_counter()
    fn()
    out[label] = time.perf_counter() - t

if name == "analytic":
    r = aa.load("ur5"); T = r.fk(r.random_q(rng=3))
    timed("first", lambda: aa.ik.analytic(r, T))
    timed("second", lambda: aa.ik.analytic(r, T))
elif name == "analytic_batch":
    r = aa.load("ur5"); T = r.fk(r.random_q(100, rng=4))
    timed("first", lambda: aa.ik.analytic_batch(r, T))
    timed("second", lambda: aa.ik.analytic_batch(r, T))
elif name == "analytic human_arm7":
    r = aa.load("human_arm7"); T = r.fk(r.random_q(rng=3))
    timed("first", lambda: aa.ik.analytic(r, T, swivel=0.3))
    timed("second", lambda: aa.ik.analytic(r, T, swivel=0.3))
elif name == "solve":
    r = aa.load("ur5"); T = r.fk(r.random_q(rng=3))
    timed("first", lambda: aa.ik.solve(r, T))
    timed("second", lambda: aa.ik.solve(r, T))
elif name == "solve human_arm7":
    r = aa.load("human_arm7"); T = r.fk(r.random_q(rng=3))
    timed("first", lambda: aa.ik.solve(r, T))
    timed("second", lambda: aa.ik.solve(r, T))
elif name == "fk batch":
    r = aa.load("kinova"); Q = r.random_q(1000, rng=5)
    timed("first", lambda: (r.fk(Q), r.jacobian(Q)))
    timed("second", lambda: (r.fk(Q), r.jacobian(Q)))
elif name == "qp.step":
    r = aa.load("panda"); conf = qp.IKConfiguration(r)
    ee = qp.FrameTask(r, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
    ee.set_target(r.fk(r.random_q(rng=0)))
    timed("first", lambda: qp.step(conf, None, [ee], dt=0.01))
    timed("second", lambda: qp.step(conf, None, [ee], dt=0.01))
elif name == "lagrange":
    r = aa.load("planar2r")
    timed("first", lambda: aa.dynamics.lagrange.load(r).tau([0.1, 0.2], [0.0, 1.0], [0.5, 0.0]))
    timed("second", lambda: aa.dynamics.lagrange.load(r).tau([0.1, 0.2], [0.0, 1.0], [0.5, 0.0]))
elif name == "solve_grasp":
    limb = aa.load("human_upper_limb")
    cup = hand.Cylinder(center=[0.30, 0.25, -0.10], axis=[0, 0, 1], radius=0.035, length=0.1)
    timed("first", lambda: hand.solve_grasp(limb, cup))
    timed("second", lambda: hand.solve_grasp(limb, cup))
elif name == "marker_ik":
    arm = aa.load("human_arm7")
    ms = motion.default_marker_set(arm)
    bm = motion.markers.BoundMarkers(arm, ms)
    P = np.array([bm.world_positions(q) for q in arm.random_q(5, rng=6)])
    trial = motion.MarkerTrajectories([m.name for m in ms.markers], P, rate=100.0)
    timed("first", lambda: motion.marker_ik(arm, trial, ms))
    timed("second", lambda: motion.marker_ik(arm, trial, ms))
elif name == "reachability_map":
    arm = aa.load("human_arm7")
    f = lambda: aa.batch.reachability_map(arm, n=20000, voxel=0.05, progress=False)
    timed("first", f)
    timed("second", f)
from anthroarm import jit
out["jit"] = jit.status()
print("RESULT" + json.dumps(out))
"""

ENTRIES = [
    "analytic",
    "analytic human_arm7",
    "analytic_batch",
    "solve",
    "solve human_arm7",
    "fk batch",
    "qp.step",
    "lagrange",
    "solve_grasp",
    "marker_ik",
    "reachability_map",
]


def _env(cache: Path, mode: str) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "ANTHROARM_"))}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.update(ANTHROARM_CACHE=str(cache), NUMBA_CACHE_DIR=str(cache / "numba"))
    env["ANTHROARM_JIT"] = mode
    return env


def _stop_background(cache: Path) -> None:
    for lock in (cache / "kernels").glob("*.lock"):
        try:
            os.killpg(int(lock.read_text()), signal.SIGKILL)
        except (ValueError, ProcessLookupError, PermissionError):
            pass


def fresh_process(script: str, arg: str, cache: Path, mode: str) -> dict:
    """``script`` run with ``arg`` in a fresh Python process on ``cache`` in ``mode``; the
    JSON it prints after ``RESULT``.  Its background compilation is stopped when it ends."""
    p = subprocess.run(
        [sys.executable, "-c", script, arg],
        env=_env(cache, mode),
        capture_output=True,
        text=True,
        timeout=1800,
    )
    _stop_background(cache)
    if p.returncode:
        raise RuntimeError(f"{arg} ({mode}): {p.stderr[-2000:]}")
    line = [s for s in p.stdout.splitlines() if s.startswith("RESULT")][-1]
    return json.loads(line[len("RESULT") :])


def _one(entry: str, cache: Path, mode: str) -> dict:
    return fresh_process(SCRIPT, entry, cache, mode)


def run(quick: bool = False) -> dict:
    entries = ENTRIES[:3] if quick else ENTRIES
    reps = 1 if quick else 3
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        warm_cache = Path(tmp) / "warm"
        t = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "anthroarm.warmup"],
            env=_env(warm_cache, "compile"),
            check=True,
            capture_output=True,
            timeout=3600,
        )
        warmup_s = time.perf_counter() - t
        for entry in entries:
            got = {}
            for mode in ("auto", "compile", "warm"):
                runs = []
                for r in range(reps if mode != "compile" else 1):
                    cache = warm_cache if mode == "warm" else Path(tmp) / f"{mode}-{entry}-{r}"
                    runs.append(_one(entry, cache, "auto" if mode == "warm" else mode))
                got[mode] = runs
            first = [x["first"] for x in got["auto"]]
            rows.append(
                [
                    entry,
                    median(first),
                    max(first),
                    got["compile"][0]["first"],
                    median(x["first"] for x in got["warm"]),
                    median(x["second"] for x in got["warm"]),
                    median(x["import"] for x in got["auto"]),
                    got["auto"][0]["jit"].split(" (")[0],
                    got["warm"][0]["jit"],
                ]
            )
    return dict(
        title="First calls with an empty cache, and warm (fresh processes)",
        columns=[
            "entry point",
            "first call s, empty cache (auto: median)",
            "worst s",
            "first call s, empty cache, compile on call (before)",
            "first call s, cache ready",
            "second call s, cache ready",
            "import s",
            "cold runs",
            "warm runs",
        ],
        rows=rows,
        notes=(
            f"Fresh process per row and mode ({reps} runs of 'auto' and of the warm process; 1 of "
            "'compile', which compiles on the caller's clock as every earlier release did). "
            "'auto' (the default) answers from the reference path (the kernels' source in the "
            "interpreter) while one background process compiles; a process that finds the cache "
            f"ready runs compiled. One full background compilation took {warmup_s:.0f} s here. "
            "Wall time around the call only; 'import s' is `import anthroarm` with its "
            "subpackages. Shared 2-core machine: read times ±30 %."
        ),
    )
