"""Closed-form IK of poses whose configurations put joints exactly on their limits (issue 30):
4 of 40 such poses of the prosthetic arm had no solution and some were refused at a 1.6e-9
residual.  Causes, each fixed: a joint on a limit came out of the closed form at the limit
± 2π and the exact wrap left it an ulp outside; a subproblem's least-squares root at the
singular pose (flagged inexact) was not polished; the bounded polish crept towards a solution
on a bound and stopped near 1e-9.

Oracle: Pinocchio's FK of the configuration the pose came from (the pose has a solution inside
the limits: that configuration) and of every returned solution."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa


def _on_limit_configs(robot, n, seed):
    lo, hi = robot.lower, robot.upper
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = robot.random_q(rng=rng)
        on = rng.random(q.size) < 0.4
        out.append(np.where(on, np.where(rng.random(q.size) < 0.5, lo, hi), q))
    return np.array(out)


def _fk(robot, q):
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    return d.oMf[robot.tool_id].homogeneous


@pytest.mark.parametrize("path", ["single", "batch"])
def test_every_pose_from_a_configuration_on_its_limits_is_solved(path):
    robot = aa.load("prosthetic_arm")
    Q = _on_limit_configs(robot, 120, seed=1)
    Ts = np.array([_fk(robot, q) for q in Q])
    if path == "single":
        sols = [aa.ik.analytic(robot, T).solutions for T in Ts]
    else:
        res = aa.ik.analytic_batch(robot, Ts)
        sols = [res.solutions[i][res.valid[i]] for i in range(len(Ts))]
    unsolved = [i for i, S in enumerate(sols) if len(S) == 0]
    assert not unsolved, f"{len(unsolved)} of {len(Ts)} poses without a solution: {Q[unsolved[0]]}"
    for T, S in zip(Ts, sols):
        for q in S:
            assert robot.within_limits(q)
            assert np.abs(_fk(robot, q)[:3] - T[:3]).max() <= 1e-9
