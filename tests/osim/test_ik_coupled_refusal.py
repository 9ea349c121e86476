"""``aa.ik.solve`` and the QP layer on an OpenSim model with nonlinear couplings: both work in
Pinocchio's joints, which a spline knee moves as φ(q) of the coordinates, so they refuse with
a typed error naming the remedy (marker IK in the coordinates) instead of answering in the
wrong space (before: a 27-vector for gait2392's 23 coordinates)."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import UnsupportedModelError
from anthroarm.ik.qp import IKConfiguration


@pytest.fixture(scope="module")
def gait():
    return aa.load(aa.osim.path("gait2392"))


def test_solve_refuses_a_coupled_model(gait):
    assert gait.coupling is not None and gait.nq == 23 and gait.model.nq == 27
    T = gait.fk(gait.default_q(), "calcn_r")
    with pytest.raises(UnsupportedModelError, match="CoupledMarkerIK"):
        aa.ik.solve(gait, T, frame="calcn_r")


def test_qp_layer_refuses_a_coupled_model(gait):
    with pytest.raises(UnsupportedModelError, match="osim_marker_ik"):
        IKConfiguration(gait, gait.default_q())


def test_uncoupled_osim_model_still_solves():
    """arm26 has no coupling: its coordinates are Pinocchio's joints; the answer's pose is
    checked with Pinocchio's own FK."""
    arm = aa.load(aa.osim.path("arm26"))
    assert arm.coupling is None
    q = arm.random_q(rng=1)
    T = arm.fk(q, "r_ulna_radius_hand")
    r = aa.ik.solve(arm, T[:3, 3], frame="r_ulna_radius_hand", rng=0)
    assert r.success and r.q.shape == (2,)
    d = arm.model.createData()
    pin.framesForwardKinematics(arm.model, d, r.q)
    p = d.oMf[arm.model.getFrameId("r_ulna_radius_hand")].translation
    np.testing.assert_allclose(p, T[:3, 3], atol=1e-6)
