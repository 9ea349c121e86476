"""The background compilation of the kernels (``python -m anthroarm.warmup``).

Started by the first kernel call of a process with an empty cache (:mod:`anthroarm.jit`, mode
``auto``), in its own process group of the caller's session, with ``ANTHROARM_JIT=compile``: it
runs the public entry points that use compiled kernels on every catalog arm whose chain has a
closed form or search class, on the search classes' user arms, on the subproblems and on arm26's
wrapped muscle paths, so every kernel is compiled for the types those entry points give it and
stored in Numba's disk cache; then it writes the ready stamp (:func:`anthroarm.jit.write_stamp`)
that tells every process to switch to compiled code. It keeps to one CPU
(``NUMBA_NUM_THREADS=1``) and takes the lowest priority (``nice`` 19), so the processes that
started it keep their pace on the reference path meanwhile (it stays in their session: Linux's
autogroup gives every session an equal share of the CPU whatever its nice; the measured effect on
a cold ``anthroarm check`` is in the guide, ``docs/guide/compiled.md``).

Run by hand, ``python -m anthroarm.warmup --report`` compiles in the foreground and lists the
kernels it did not reach (none: a test holds it).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings

import numpy as np

from . import jit, models, muscles, osim
from .errors import AnthroarmError
from .ik import analytic, analytic_batch, closed_form_info, geometric, solve
from .ik import subproblems as sp
from .loading import load
from .models.standard_dh import standard_dh_urdf

#: standard DH rows (alpha rad, a m, d m) of user 6R arms of the classes no catalog arm has:
#: the 1-D searches (joints 2 ∥ 3; joints 5 and 6 meeting), the 2-D search (a general arm) and
#: two closed classes
SEARCH_AND_RARE_ARMS = {
    "two_parallel": (
        [1.1, 0.0, -0.7, 0.9, -1.2, 0.5],
        [0.3, 0.2, 0.25, 0.1, 0.15, 0.2],
        [0.1, 0.2, 0.15, 0.3, 0.12, 0.1],
    ),
    "two_intersecting": (
        [1.1, -0.8, -0.7, 0.9, -1.2, 0.5],
        [0.3, 0.2, 0.25, 0.1, 0.0, 0.2],
        [0.1, 0.2, 0.15, 0.3, 0.12, 0.1],
    ),
    "gen_six_dof": (
        [1.1, -0.8, -0.7, 0.9, -1.2, 0.5],
        [0.3, 0.2, 0.25, 0.1, 0.15, 0.2],
        [0.1, 0.2, 0.15, 0.3, 0.12, 0.1],
    ),
    "spherical": (
        [1.1, -0.8, 0.6, 1.5708, -1.5708, 0.0],
        [0.3, 0.2, 0.25, 0.0, 0.0, 0.0],
        [0.1, 0.2, 0.15, 0.3, 0.0, 0.1],
    ),
    "three_parallel": (
        [1.1, 0.0, 0.0, 0.9, -1.2, 0.5],
        [0.3, 0.2, 0.25, 0.1, 0.15, 0.2],
        [0.1, 0.2, 0.15, 0.3, 0.12, 0.1],
    ),
}


def _closed_form_arms():
    """Catalog arms with a closed form (loaded), then one user arm of each search class."""
    for name in models.names():
        try:
            robot = load(name)
            info = closed_form_info(robot)
        except AnthroarmError:
            continue
        if info is not None:
            yield robot
    with tempfile.TemporaryDirectory() as folder:
        for name, (alpha, a, d) in SEARCH_AND_RARE_ARMS.items():
            path = os.path.join(folder, f"{name}.urdf")
            with open(path, "w") as f:
                f.write(standard_dh_urdf(name, alpha, a, d))
            yield load(path)


def _arm(robot, rng, n) -> None:
    Q = robot.random_q(n, rng)
    T = robot.fk(Q)
    info = closed_form_info(robot)
    kw = {}
    if info.swivel:
        kw = {"swivel": 0.3}
    for call in (
        lambda: analytic(robot, T[0], **kw).singular,
        lambda: analytic_batch(robot, T, **kw).singular,
        lambda: (
            geometric.solve(geometric.plan_for(robot), T)
            if info.family in geometric.CLOSED
            else None
        ),
        lambda: analytic(robot, T[0], **kw),
        lambda: analytic(robot, T[0]),
        lambda: analytic_batch(robot, T, **kw),
        lambda: analytic_batch(robot, T),
        lambda: analytic(robot, T[0], swivel=np.linspace(-1, 1, 5)) if info.swivel else None,
        lambda: solve(robot, T[0], max_time=10.0),
        lambda: solve(robot, T[: max(2, n // 2)], max_time=10.0),
    ):
        try:
            call()
        except AnthroarmError:
            pass


def _subproblems(rng) -> None:
    v = lambda: rng.normal(size=3)  # noqa: E731
    u = lambda: (lambda x: x / np.linalg.norm(x))(v())  # noqa: E731
    sp.sp1(v(), v(), u())
    sp.sp2(v(), v(), u(), u())
    sp.sp3(v(), v(), u(), 1.0)
    sp.sp4(u(), v(), u(), 0.3)
    sp.sp5(v(), v(), v(), v(), u(), u(), u())
    sp.sp6(
        np.array([u(), u(), u(), u()]),
        np.array([u(), u(), u(), u()]),
        rng.normal(size=(4, 3)),
        0.2,
        0.3,
    )


def _muscles(n) -> None:
    """The muscle paths over cylinder and ellipsoid wraps (arm26: TRIlong's three wraps,
    BIClong's ellipsoid), exact moment arms."""
    robot = load(osim.path("arm26"))
    muscles.lengths_and_moment_arms(robot, None, robot.random_q(max(2, n), rng=0))


def run(report: bool = False, n: int = 8) -> list[str]:
    """Compile every kernel through the entry points (``n`` poses an arm) (``ANTHROARM_JIT=compile``); the names of
    the kernels not reached (with an empty cache; with ``ANTHROARM_JIT=reference`` the kernels
    the entry points did not call)."""
    rng = np.random.default_rng(0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for robot in _closed_form_arms():
            _arm(robot, rng, n)
        _subproblems(rng)
        _muscles(n)
    if jit.STATE.compiled:  # compiled here: a kernel compiled by its caller has a signature
        missing = [repr(k) for k in jit.STATE.kernels if not k.dispatcher.signatures]
    else:  # the reference: the kernels called (their first call's types kept), and what
        # they call in their source (compiled with them, whichever branch ran)
        reached = {id(k): k for k in jit.STATE.kernels if k.seen is not None}
        todo = list(reached.values())
        while todo:
            for c in jit.callees(todo.pop()):
                if id(c) not in reached:
                    reached[id(c)] = c
                    todo.append(c)
        missing = [repr(k) for k in jit.STATE.kernels if id(k) not in reached]
    if report:
        for m in missing:
            print("not reached:", m)
    return missing


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if jit.mode() != "compile":
        os.environ["ANTHROARM_JIT"] = "compile"
    lock = jit.lock_path()
    if lock is not None and "--report" not in argv:
        try:
            holder = int(lock.read_text().strip() or 0)
        except (OSError, ValueError):
            holder = 0
        if holder and holder != os.getpid() and jit.running() == holder:
            return 0  # another one runs for this stamp
        try:
            os.nice(19)
        except OSError:
            pass
    t = time.perf_counter()
    jit.start()
    missing = run(report="--report" in argv)
    files = jit.write_stamp(complete=True)
    print(
        f"compiled {len(jit.STATE.kernels) - len(missing)} kernels, {len(files)} files, "
        f"in {time.perf_counter() - t:.1f} s"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
