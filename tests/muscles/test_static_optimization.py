"""Static optimisation (issue 34 item 3) against mathematics: where no activation bound is
active, min Σ a² + Σ ρ² subject to C x = d has the closed form x = Cᵀ (C Cᵀ)⁻¹ d
(the minimum-norm solution); every QP backend must return it.  Where the torque is beyond the
muscles, the reserves carry the rest and the activations sit at their bounds."""

from __future__ import annotations

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import muscles
from anthroarm.errors import MuscleError


@pytest.fixture(scope="module")
def arm():
    robot = aa.load(aa.osim.path("arm26"))
    ms = muscles.read_muscles(aa.osim.path("arm26"))
    Q = robot.random_q(40, rng=0)
    L, R = muscles.lengths_and_moment_arms(robot, ms, Q, wrap=False)
    FA, FP = muscles.force_coefficients(ms, L)
    return robot, ms, Q, R, FA, FP


@pytest.mark.parametrize("solver", ["quadprog", "daqp", "proxqp", "osqp"])
def test_minimum_norm_solution(arm, solver):
    robot, ms, Q, R, FA, FP = arm
    rng = np.random.default_rng(1)
    a_true = rng.uniform(0.05, 0.3, (len(Q), len(ms)))
    tau = np.einsum("nmk,nm->nk", R, a_true * FA + FP)
    reserve = 0.5
    so = muscles.static_optimization(robot, ms, Q, tau, reserve=reserve, solver=solver, wrap=False)
    assert all(s == "optimal" for s in so.status)
    interior = 0
    M = len(ms)
    for k in range(len(Q)):
        C = np.hstack([R[k].T * FA[k], reserve * np.eye(robot.nq)])
        d = tau[k] - R[k].T @ FP[k]
        x = C.T @ np.linalg.solve(C @ C.T, d)
        if np.all(x[:M] > 1e-9) and np.all(x[:M] < 1):
            interior += 1
            np.testing.assert_allclose(so.activation[k], x[:M], atol=1e-7)
            np.testing.assert_allclose(so.reserve_torque[k], reserve * x[M:], atol=1e-7)
        # KKT certificate on every frame: 2x + C^T lam = mu, mu = 0 on free variables,
        # mu >= 0 where a = 0, mu <= 0 where a = 1
        xs = np.concatenate([so.activation[k], so.reserve_torque[k] / reserve])
        low, up = xs[:M] < 1e-8, xs[:M] > 1 - 1e-8
        free = ~np.concatenate([low | up, np.zeros(robot.nq, dtype=bool)])
        lam = np.linalg.lstsq(C[:, free].T, -2 * xs[free], rcond=None)[0]
        mu = 2 * xs + C.T @ lam
        assert np.abs(mu[free]).max() < 1e-6
        assert np.all(mu[:M][low] > -1e-6) and np.all(mu[:M][up] < 1e-6)
    assert interior >= 2
    # the torques are met by muscles and reserves together
    np.testing.assert_allclose(so.muscle_torque + so.reserve_torque, tau, atol=1e-9)
    assert (so.activation**2).sum() <= (a_true**2).sum() + 1e-9


def test_beyond_the_muscles_reserves_carry_it(arm):
    robot, ms, Q, R, FA, FP = arm
    tau = np.tile([0.0, 500.0], (len(Q), 1))  # 500 N m at the elbow: far beyond arm26
    so = muscles.static_optimization(robot, ms, Q, tau, wrap=False)
    assert np.all(np.abs(so.reserve_torque[:, 1]) > 100)
    assert np.all((so.activation >= 0) & (so.activation <= 1))
    assert np.isclose(so.activation.max(), 1.0)


def test_bad_input(arm):
    robot, ms, Q, R, FA, FP = arm
    with pytest.raises(MuscleError):
        muscles.static_optimization(robot, ms, Q, np.full(Q.shape, np.nan), wrap=False)
    with pytest.raises(MuscleError):
        muscles.static_optimization(robot, ms, Q, np.zeros(Q.shape), reserve=0.0, wrap=False)
