"""Cold start: the first calls of a fresh process with an empty cache answer as a warm process
does (issues 28 and 30): the same results, statuses and typed errors from every public entry
point, and a time budget (``max_time``) that is for solving, never for compiling or loading
kernels (with an empty cache the first ``aa.ik.solve`` of human_arm7 spent its 50 ms compiling
and 19 of the 20 targets of ``anthroarm check`` were solved; that row of the check failed)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import pytest

SCRIPT = r"""
import json, sys, time
import numpy as np
import anthroarm as aa
from anthroarm import hand, motion
from anthroarm.ik import qp

def digest(x):
    a = np.asarray(x, dtype=float)
    return [list(a.shape), float(np.nansum(np.abs(a)))]

out, times = {}, {}
def run(name, fn):
    t = time.perf_counter()
    try:
        out[name] = fn()
    except Exception as exc:
        out[name] = f"{type(exc).__name__}: {exc}"
    times[name] = time.perf_counter() - t

ur5 = aa.load("ur5")
T = ur5.fk(ur5.random_q(rng=3))
run("analytic", lambda: digest(aa.ik.analytic(ur5, T).solutions))
Ts = ur5.fk(ur5.random_q(16, rng=4))
run("analytic_batch", lambda: int(aa.ik.analytic_batch(ur5, Ts).valid.sum()))
kin = aa.load("kinova")
Q = kin.random_q(32, rng=5)
run("fk_batch", lambda: digest(kin.fk(Q)))
run("jacobian_batch", lambda: digest(kin.jacobian(Q)))
run("solve", lambda: [bool(r.success) for r in [aa.ik.solve(ur5, T)]])
def qp_step():
    robot = aa.load("panda")
    conf = qp.IKConfiguration(robot)
    ee = qp.FrameTask(robot, position_cost=1.0, orientation_cost=1.0, lm_damping=1e-3)
    ee.set_target(robot.fk(robot.random_q(rng=0)))
    return digest(qp.step(conf, None, [ee, qp.PostureTask(robot, cost=1e-3)], dt=0.01))
run("qp_step", qp_step)
def lagrange():
    r = aa.load("planar2r")
    return digest(aa.dynamics.lagrange.load(r).tau([0.1, 0.2], [0.0, 1.0], [0.5, 0.0]))
run("lagrange", lagrange)
def grasp():
    limb = aa.load("human_upper_limb")
    cup = hand.Cylinder(center=[0.30, 0.25, -0.10], axis=[0, 0, 1], radius=0.035, length=0.1)
    r = hand.solve_grasp(limb, cup)
    return [r.status]
run("solve_grasp", grasp)
def marker():
    arm = aa.load("human_arm7")
    ms = motion.default_marker_set(arm)
    bm = motion.markers.BoundMarkers(arm, ms)
    Qm = arm.random_q(5, rng=6)
    P = np.array([bm.world_positions(q) for q in Qm])
    trial = motion.MarkerTrajectories([m.name for m in ms.markers], P, rate=100.0)
    r = motion.marker_ik(arm, trial, ms)
    return [float(np.max(r.rms)) < 1e-6]
run("marker_ik", marker)
def reach():
    arm = aa.load("human_arm7")
    r = aa.batch.reachability_map(arm, n=20000, voxel=0.05, progress=False)
    return {k: digest(v[-1] if isinstance(v, tuple) else v) for k, v in sorted(r.variables.items())}
run("reachability_map", reach)
for name in ("human_arm7", "prosthetic_arm"):  # the targets of `anthroarm check`, 50 ms each
    robot = aa.load(name)
    Qc = robot.random_q(20, np.random.default_rng(0))
    res = [aa.ik.solve(robot, robot.fk(q)) for q in Qc]
    out["solve_" + name] = [
        [bool(r.success), r.status, bool(robot.within_limits(r.q))] for r in res
    ]
far = np.eye(4)
far[:3, 3] = (5.0, 0.0, 0.0)
BAD = (("nan", np.full((4, 4), np.nan)), ("shape", np.ones((2, 2))), ("skew", np.ones((4, 4))))
for label, bad in BAD:
    run("error_" + label, lambda bad=bad: [aa.ik.solve(ur5, bad).status])
run("far_solve", lambda: [aa.ik.solve(ur5, far).status])
run("far_analytic", lambda: [len(aa.ik.analytic(ur5, far).solutions),
                             aa.ik.analytic(ur5, far).reason])
from anthroarm import jit
out["jit"] = jit.status()
out["times"] = times
print("RESULT" + json.dumps(out))
"""

ENTRY_POINTS = [
    "analytic",
    "analytic_batch",
    "fk_batch",
    "jacobian_batch",
    "solve",
    "qp_step",
    "lagrange",
    "solve_grasp",
    "marker_ik",
    "reachability_map",
    "error_nan",
    "error_shape",
    "error_skew",
    "far_solve",
    "far_analytic",
]


def _run(cache, mode):
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["ANTHROARM_CACHE"] = str(cache)
    env["ANTHROARM_JIT"] = mode
    p = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, timeout=1200
    )
    assert p.returncode == 0, p.stderr[-3000:]
    line = [s for s in p.stdout.splitlines() if s.startswith("RESULT")][-1]
    return json.loads(line[len("RESULT") :])


def _same(a, b) -> bool:
    """Equal, numbers to 1e-12 relative (the interpreter and the compiled code may round a
    sum's last bit differently)."""
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, float) and isinstance(b, (int, float)):
        return abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b))
    return a == b


def _stop_background(cache):
    """Stop the background compilation a cold process started (its pid in the lock file)."""
    for lock in (cache / "kernels").glob("*.lock"):
        try:
            os.killpg(int(lock.read_text()), signal.SIGKILL)
        except (ValueError, ProcessLookupError, PermissionError):
            pass


@pytest.fixture(scope="module")
def cold_and_warm(tmp_path_factory):
    cache = tmp_path_factory.mktemp("cold") / "cache"
    try:
        # a fresh process, an empty cache, the default mode: every answer from the reference
        # (the kernels' source in the interpreter) while a background process compiles
        cold = _run(cache, "auto")
    finally:
        _stop_background(cache)
    assert cold["jit"].startswith("reference"), cold["jit"]
    warm = _run(cache, "compile")  # the compiled kernels
    assert warm["jit"] == "compiled"
    return cold, warm


@pytest.mark.slow
@pytest.mark.parametrize("robot", ["human_arm7", "prosthetic_arm"])
def test_first_solves_are_not_charged_for_compilation(cold_and_warm, robot):
    cold, warm = cold_and_warm
    rows = cold["solve_" + robot]
    assert all(ok and status == "success" and inside for ok, status, inside in rows), rows
    assert _same(cold["solve_" + robot], warm["solve_" + robot])


@pytest.mark.slow
@pytest.mark.parametrize("entry", ENTRY_POINTS)
def test_cold_answers_as_warm(cold_and_warm, entry):
    """The reference path answers every public entry point as the compiled kernels do."""
    cold, warm = cold_and_warm
    assert _same(cold[entry], warm[entry]), (cold[entry], warm[entry])


@pytest.mark.slow
def test_cold_errors_are_typed(cold_and_warm):
    cold, _ = cold_and_warm
    for label in ("nan", "shape", "skew"):
        assert str(cold["error_" + label]).startswith("ValueError"), cold["error_" + label]
    assert cold["far_solve"] == ["out_of_reach"]
    assert cold["far_analytic"][0] == 0 and "reach" in cold["far_analytic"][1]


def test_one_time_imports_are_made_before_the_budget_starts():
    """A closed-form candidate at a singular pose is polished by bounded least squares, whose
    first use imports scipy.optimize (~1 s): the first aa.ik.solve of a process loads it before
    its clock starts, so no target pays it in its 50 ms (z1, CI, a fresh worker: one target
    failed 'after 8 iterations, 0 restarts')."""
    script = (
        "import sys, anthroarm as aa\n"
        "r = aa.load('z1')\n"
        "before = 'scipy.optimize' in sys.modules\n"
        "aa.ik.solve(r, r.fk(r.random_q(rng=1)))\n"
        "print('RESULT', before, 'scipy.optimize' in sys.modules)\n"
    )
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout.split("RESULT")[-1].split() == ["False", "True"]
