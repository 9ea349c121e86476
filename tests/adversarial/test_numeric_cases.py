"""Numeric abuse of the public numeric API (issue 12, items 7, 8 and 12): each case a typed
error (anthroarm.errors or a documented ValueError/TypeError) or a correct answer."""

import math

import numpy as np
import pytest

import anthroarm as aa


@pytest.fixture(scope="module")
def arm():
    return aa.load("prosthetic_arm")


@pytest.mark.parametrize("tol", [-1.0, 0.0, math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("kw", ["tol", "tol_orthonormal"])
def test_analytic_rejects_bad_tolerances(arm, tol, kw):
    T = np.asarray(arm.fk(np.full(6, 0.3)))
    with pytest.raises(ValueError, match=kw):
        aa.ik.analytic(arm, T, **{kw: tol})
    with pytest.raises(ValueError, match=kw):
        aa.ik.analytic_batch(arm, T[None], **{kw: tol})


def test_analytic_rejects_non_numeric_tolerance(arm):
    T = np.asarray(arm.fk(np.full(6, 0.3)))
    with pytest.raises(TypeError, match="tol"):
        aa.ik.analytic(arm, T, tol="1e-9")


@pytest.mark.parametrize("name", ["prosthetic_arm", "sixr_arm", "planar2r", "human_arm7"])
@pytest.mark.parametrize("impl", ["auto", "python", "c", "general"])
def test_analytic_batch_of_zero_poses_is_empty(name, impl):
    robot = aa.load(name)
    b = aa.ik.analytic_batch(robot, np.zeros((0, 4, 4)), _impl=impl)
    assert len(b) == 0
    assert b.solutions.shape[0] == 0 and b.valid.shape[0] == 0
    assert b.n_solutions.shape == (0,)


@pytest.mark.parametrize("damping", [-10.0, -1e-12, math.nan, math.inf])
@pytest.mark.parametrize("solver", ["osqp", "proxqp"])
def test_qp_step_rejects_negative_or_non_finite_damping(arm, damping, solver):
    from anthroarm.ik import qp

    q0 = arm.random_q(rng=5, margin=0.2)
    conf = qp.IKConfiguration(arm, q0)
    ee = qp.FrameTask(arm, position_cost=1.0, orientation_cost=0.5)
    ee.set_target(arm.fk(arm.random_q(rng=6, margin=0.2)))
    with pytest.raises(ValueError, match="damping"):
        qp.step(conf, None, [ee], 0.01, solver=solver, damping=damping)


@pytest.mark.parametrize("samples", [0, -3, 2, 2.5, True])
def test_rssr_crank_test_rejects_bad_sample_counts(samples):
    from anthroarm.mechanisms.rssr import RSSRGeometry, rssr_crank_test

    g = RSSRGeometry(a0=[0, 0, 0], ua=[0, 0, 1], a1=[1, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 3])
    with pytest.raises(ValueError, match="samples"):
        rssr_crank_test(g, samples=samples)
