"""The book's Jacobians: trace formula (7-58)-(7-63) = Pinocchio WORLD (blocks swapped),
hand-frame Jacobian (7-90)-(7-94) = Pinocchio LOCAL, and the book's claim K ≡ 0 (7-65) is false
(K = Pinocchio's WORLD Jacobian time variation, and finite differences)."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik.book_jacobians import (
    DELTA,
    THETA,
    chain_derivatives,
    hand_frame_jacobian,
    trace_jacobian,
    trace_jacobian_derivative,
)

MODELS = ["sixr_arm", "prosthetic_arm", "human_arm7", "unimate5"]


def _swap(J):
    return np.vstack([J[3:], J[:3]])


def test_theta_orthogonality_7_60():
    """Corrected (7-60): tr(Θ_j Θ_kᵀ) = δ_jk / δ_j, i.e. diag(2, 2, 2, 1, 1, 1)."""
    G = np.einsum("jab,kab->jk", THETA, THETA)
    np.testing.assert_allclose(G, np.diag(1 / DELTA))


@pytest.mark.parametrize("name", MODELS)
def test_trace_jacobian_equals_pinocchio_world(name):
    robot = aa.load(name)
    for q in robot.random_q(10, np.random.default_rng(0)):
        J = trace_jacobian(robot, q)
        Jw = robot.jacobian(q, reference="WORLD")
        np.testing.assert_allclose(J, _swap(Jw), atol=1e-12)


@pytest.mark.parametrize("name", MODELS)
def test_hand_frame_jacobian_equals_pinocchio_local(name):
    robot = aa.load(name)
    for q in robot.random_q(10, np.random.default_rng(1)):
        np.testing.assert_allclose(
            hand_frame_jacobian(robot, q), robot.jacobian(q, reference="LOCAL"), atol=1e-12
        )


@pytest.mark.parametrize("name", ["sixr_arm", "prosthetic_arm"])
def test_K_exact_equals_pinocchio_and_finite_differences(name):
    robot = aa.load(name)
    rng = np.random.default_rng(2)
    for q in robot.random_q(5, rng):
        qd = rng.normal(size=robot.nv)
        K = trace_jacobian_derivative(robot, q, qd)
        pin.computeJointJacobiansTimeVariation(robot.model, robot.data, q, qd)
        dJ = pin.getFrameJacobianTimeVariation(
            robot.model, robot.data, robot.tool_id, pin.ReferenceFrame.WORLD
        )
        np.testing.assert_allclose(K, _swap(dJ), atol=1e-10)
        h = 1e-6
        fd = (trace_jacobian(robot, q + h * qd) - trace_jacobian(robot, q - h * qd)) / (2 * h)
        np.testing.assert_allclose(K, fd, atol=1e-7)


def test_book_K_identically_zero_is_false():
    """(7-64)/(7-65): the book's substitution ∂²T/∂q_k∂q_i = ∂T/∂q_i T⁻¹ ∂T/∂q_k makes K ≡ 0, but
    the true K (Pinocchio) is far from zero; the identity holds only for i < k."""
    robot = aa.load("sixr_arm")
    rng = np.random.default_rng(3)
    q = robot.random_q(None, rng)
    qd = rng.normal(size=6)
    K_book = trace_jacobian_derivative(robot, q, qd, variant="book")
    K_true = trace_jacobian_derivative(robot, q, qd)
    assert np.abs(K_book).max() < 1e-12
    assert np.abs(K_true).max() > 0.1
    T, dT, d2T = chain_derivatives(robot, q, second=True)
    Ti = np.linalg.inv(T)
    for i in range(6):
        for k in range(6):
            book = dT[i] @ Ti @ dT[k]
            if i <= k:
                np.testing.assert_allclose(d2T[k, i], book, atol=1e-12)  # holds for i ≤ k
    worst = max(np.abs(d2T[k, i] - dT[i] @ Ti @ dT[k]).max() for i in range(6) for k in range(i))
    assert worst > 0.1  # fails for k < i
