"""The compiled attempt of ``aa.ik.solve`` (:mod:`anthroarm.ik.solve.lm`) and the chain's one
forward kinematics it uses (:func:`anthroarm.ik.fk.chain_fk_jacobian`), against
Pinocchio: the frame's pose (``framesForwardKinematics``) and Jacobian
(``computeFrameJacobian``, LOCAL_WORLD_ALIGNED) on random configurations of catalog robots with
prismatic, mimic, continuous joints and trees, log₃/log₆ against ``pin.log3``/``pin.log6``
(near 0, generic, near π), the Cholesky solve against the normal equations solved by numpy, and
answers of ``aa.ik.solve`` checked by Pinocchio's FK of the full configuration."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik.fk import PathFrames, chain_fk_jacobian
from anthroarm.ik.solve import lm
from anthroarm.ik.solve.targets import Target
from anthroarm.ik.solve.workspace import workspace

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: catalog robots with prismatic joints (cartesian, cylindrical, spherical, rrprr5, unimate5),
#: mimic joints on a tree (prosthetic_hand), joints off the tool's path (human_upper_limb),
#: continuous joints (kinova) and ur5 from example-robot-data
ROBOTS = [
    "cartesian_robot",
    "cylindrical_robot",
    "spherical_robot",
    "rrprr5",
    "unimate5",
    "prosthetic_hand",
    "human_upper_limb",
    "panda",
    "kinova",
    "ur5",
]


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request):
    return aa.load(request.param)


def _frames(robot):
    """The tool and the other tips (a hand: every finger, most through mimic joints)."""
    return list(dict.fromkeys([robot.chain.tool, *robot.chain.tips]))


def test_fk_and_jacobian_match_pinocchio(robot):
    chain, model = robot.chain, robot.model
    data = model.createData()
    rng = np.random.default_rng(7)
    n = len(chain.independent)
    for name in _frames(robot):
        fid = robot.frame_id(name)
        path = PathFrames(chain, fid)
        J = np.zeros((6, n))
        W = np.zeros((max(path.P, 1), 6))
        for q in robot.random_q(5, rng=rng):
            th = chain.angles(q)[list(chain.independent)]
            R, p = chain_fk_jacobian(path.F, th, J, W, n)
            pin.framesForwardKinematics(model, data, q)
            M = data.oMf[fid]
            np.testing.assert_allclose(np.array(R), M.rotation, atol=1e-12)
            np.testing.assert_allclose(np.array(p), M.translation, atol=1e-12)
            Jp = pin.computeFrameJacobian(model, data, q, fid, LWA)
            np.testing.assert_allclose(J, Jp, atol=1e-12, err_msg=f"{robot.name} {name}")


def _rotation(axis, angle):
    return pin.exp3(np.asarray(axis, float) / np.linalg.norm(axis) * angle)


@pytest.mark.parametrize(
    "angle",
    [0.0, 1e-9, 1e-6, 3e-5, 0.3, 1.0, 2.5, math.pi - 1e-3, math.pi - 1e-6, math.pi - 1e-9, math.pi],
)
def test_log3_log6_match_pinocchio(angle):
    rng = np.random.default_rng(int(angle * 1e6) % 1000)
    for _ in range(5):
        R = _rotation(rng.normal(size=3), angle)
        p = rng.normal(size=3)
        Rt = tuple(tuple(float(x) for x in row) for row in R)
        w, _ = lm.log3(Rt)
        np.testing.assert_allclose(w, pin.log3(R), atol=1e-12)
        v = lm.log6(Rt, tuple(p))
        np.testing.assert_allclose(v, pin.log6(pin.SE3(R, p)).vector, atol=1e-10)


def test_cholesky_solve_matches_the_normal_equations():
    rng = np.random.default_rng(3)
    for m, n in ((6, 7), (6, 6), (3, 7), (6, 3)):
        J = rng.normal(size=(m, n))
        e = rng.normal(size=m)
        lam = 1e-3
        k = max(m, n)
        A, x, dq = np.zeros((k, k)), np.zeros(k), np.zeros(n)
        assert lm.solve_damped(J, m, n, e, lam, A, x, dq)
        expect = np.linalg.solve(J.T @ J + lam * np.eye(n), J.T @ e)
        np.testing.assert_allclose(dq, expect, rtol=1e-9, atol=1e-12)
    # not positive definite: refused as LAPACK's dpotrf refuses it
    A = -np.eye(3)
    assert not lm.cholesky_solve(A, 3, np.ones(3))
    A = np.full((2, 2), np.nan)
    assert not lm.cholesky_solve(A, 2, np.ones(2))


def _pinocchio_errors(robot, q, fid, T, mode):
    """(position error m, rotation error rad) of frame ``fid`` at the full configuration q,
    from Pinocchio's forwardKinematics and updateFramePlacements."""
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    pin.updateFramePlacements(robot.model, data)
    M = data.oMf[fid]
    pe = re = 0.0
    if mode != "orientation":
        pe = float(np.linalg.norm(T[:3, 3] - M.translation))
    if mode != "position":
        re = float(np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3])))
    return pe, re


@pytest.mark.parametrize("mode", ["pose", "position", "orientation"])
def test_solve_answers_checked_by_pinocchio(robot, mode):
    """Targets from the FK of random configurations (reachable by construction, also for the
    arms with fewer joints than the task: the hand's finger, the 3- and 5-joint arms)."""
    rng = np.random.default_rng(11)
    fid = robot.frame_id(None)
    for q in robot.random_q(4, rng=rng):
        T = robot.fk(q)
        T = T.homogeneous if isinstance(T, pin.SE3) else T
        target = {"pose": T, "position": T[:3, 3], "orientation": T[:3, :3]}[mode]
        res = aa.ik.solve(robot, target, analytic=False, posture=None, max_time=1.0)
        assert res.success, res.message
        assert robot.within_limits(res.q)
        pe, re = _pinocchio_errors(robot, res.q, fid, T, mode)
        assert pe <= 1e-6 and re <= 1e-6, (pe, re)
        assert res.pos_err == pytest.approx(pe, abs=1e-9)
        assert res.rot_err == pytest.approx(re, abs=1e-9)


def test_attempt_stops_at_the_deadline_and_reports_the_best_iterate():
    """An unreachable pose: the attempt ends (stall, or the deadline already past at its first
    look at the clock) not converged, with the errors of its last iterate and a best iterate
    whose error Pinocchio confirms."""
    robot = aa.load("panda")
    ws = workspace(robot, robot.frame_id(None))
    lm.warm(ws)
    sh = ws.sh
    T = np.eye(4)
    T[:3, 3] = (3.0, 0.0, 0.5)  # beyond the reach
    tg = Target("pose", T, 1e-6, 1e-6)
    for deadline in (-math.inf, math.inf):
        th, ok, it, pe2, re2, best, bE = lm.attempt(ws, tg, sh.ref.copy(), deadline)
        assert not ok and 1 <= it <= lm.MAX_ITER
        assert np.all(best >= sh.lo) and np.all(best <= sh.hi)
        pin.framesForwardKinematics(robot.model, ws.data, sh.q(best))
        M = ws.data.oMf[sh.fid].actInv(pin.SE3(T))
        e = pin.log6(M).vector
        assert bE == pytest.approx(float(e @ e), rel=1e-9)
        if deadline == -math.inf:
            assert it <= 8  # the first look at the clock ends it
