"""qp.step from several threads sharing one Robot, and no Robot kept alive by the QP layer.

Oracle: the same calls made from one thread (the step is deterministic: every backend's answer
is exact on its active set), and the garbage collector (weak references to dropped Robots)."""

from __future__ import annotations

import gc
import threading
import weakref

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.ik import qp

N, THREADS = 160, 4


def _problems(robot):
    Q = robot.random_q(N, rng=1, margin=0.05)
    T = robot.fk(robot.random_q(N, rng=2, margin=0.05))
    return Q, T


def _run(robot, Q, T, solver, mode, out, idx, barrier=None):
    conf = qp.IKConfiguration(robot, Q[0]) if mode == "conf" else None
    ee = qp.FrameTask(robot, lm_damping=1e-3)
    post = qp.PostureTask(robot, cost=1e-2)
    if barrier is not None:
        barrier.wait()
    for i in idx:
        ee.set_target(T[i])
        out[i] = qp.step(conf if mode == "conf" else robot, Q[i], [ee, post], 0.01, solver=solver)


@pytest.mark.parametrize("mode", ["robot", "conf"])
@pytest.mark.parametrize("solver", ["osqp", "daqp", "quadprog", "proxqp"])
def test_threads_get_the_single_threaded_velocities(mode, solver):
    """4 threads share one Robot; each has its own tasks (and IKConfiguration in "conf" mode,
    none in "robot" mode: step(robot, q, ...) must keep one per thread)."""
    robot = aa.load("panda")
    Q, T = _problems(robot)
    ref = np.zeros((N, robot.nv))
    _run(robot, Q, T, solver, mode, ref, range(N))
    got = np.full((N, robot.nv), np.nan)
    barrier = threading.Barrier(THREADS)
    ths = [
        threading.Thread(
            target=_run, args=(robot, Q, T, solver, mode, got, range(k, N, THREADS), barrier)
        )
        for k in range(THREADS)
    ]
    for t in ths:
        t.start()
    for t in ths:
        t.join()
    wrong = int((np.abs(got - ref).max(axis=1) > 1e-10).sum())
    assert wrong == 0, f"{wrong} of {N} velocities differ from the single-threaded ones"


def test_dropped_robots_are_freed():
    """Robots used through step(robot, ...), step(conf, ...) with every backend, and from a
    worker thread, are collected once the caller drops them."""
    refs = []
    for _ in range(3):
        r = aa.load("panda")
        ee = qp.FrameTask(r, target=r.fk(r.random_q(rng=1)))
        for solver in ("osqp", "daqp", "quadprog", "proxqp"):
            qp.step(r, r.neutral(), [ee, qp.PostureTask(r)], 0.01, solver=solver)
            qp.step(qp.IKConfiguration(r), None, [ee], 0.01, solver=solver)
        t = threading.Thread(target=qp.step, args=(r, r.neutral(), [ee], 0.01))
        t.start()
        t.join()
        refs.append(weakref.ref(r))
        del r, ee, t
    gc.collect()
    assert [x() for x in refs] == [None, None, None]
