"""§8-3 X–Y–X Euler-angle chain, Eqs. (8-41)–(8-96), against scipy, finite differences and
Pinocchio spherical-joint chains (recipe R2/R3 of the notes); printed misprints fail."""

import numpy as np
import pinocchio as pin
import pytest
from dyn_chains import random_spd
from scipy.spatial.transform import Rotation

from anthroarm.dynamics import euler_chain as E
from anthroarm.errors import EulerSingularityError, InertiaError

H = 1e-6


def fd(f, x, dx):
    return (f(x + H * dx) - f(x - H * dx)) / (2 * H)


def state(rng):
    e = rng.uniform(-1, 1, 3)
    e[1] += 1.4  # away from gimbal lock
    return e, rng.standard_normal(3), rng.standard_normal(3)


@pytest.mark.parametrize("seed", range(3))
def test_single_body_kinematics(seed):
    rng = np.random.default_rng(seed)
    e, ed, edd = state(rng)
    R = E.rotation(e)
    assert np.allclose(R, Rotation.from_euler("XYX", e).as_matrix(), atol=1e-14)  # (8-42)
    Th, Ps, Ph = E.passive(e)
    assert np.allclose(Ph @ Ps @ Th, R.T, atol=1e-15)  # (8-41)
    Rdot = fd(E.rotation, e, ed)
    W = R.T @ Rdot
    w = np.array([W[2, 1], W[0, 2], W[1, 0]])
    assert np.allclose(E.Pi(e) @ ed, w, atol=1e-8)  # (8-45)
    assert abs(np.linalg.det(E.Pi(e)) + np.sin(e[1])) < 1e-14  # det Π = −sin ψ
    ex = np.array([ed[1] * ed[2], ed[2] * ed[0], ed[0] * ed[1]])
    wdot = fd(lambda t: E.Pi(e + t * ed) @ (ed + t * edd), 0.0, 1.0)
    assert np.allclose(E.Pi(e) @ edd + E.Pi1(e) @ ex, wdot, atol=1e-7)  # (8-46/47)
    P2, P3, P4, P5 = E.Pi2_to_5(e)
    e2 = ed**2
    assert np.allclose(P2 @ e2 + P3 @ ex, w**2, atol=1e-8)  # (8-53/54)
    assert np.allclose(
        P4 @ e2 + P5 @ ex, [w[1] * w[2], w[2] * w[0], w[0] * w[1]], atol=1e-8
    )  # (8-55/56)
    J = random_spd(rng)
    M = E.body_moment(J, e, ed, edd)  # (8-57)
    assert np.allclose(M, J @ wdot + np.cross(w, J @ w), atol=1e-6)
    D, Em, F = E.DEF(J, e)
    assert np.allclose(D @ edd + Em @ e2 + F @ ex, R @ M, atol=1e-12)  # (8-59/60)
    # l̈ = AΛë + BΛė² + CΛė×  (8-66)-(8-69)
    l = rng.standard_normal(3)
    A, B, C = E.ABC(e)
    h2 = 1e-4  # second central difference: truncation ~h2², rounding ~1e-16/h2²
    lddot = (
        E.rotation(e + h2 * ed + 0.5 * h2 * h2 * edd) @ l
        - 2 * R @ l
        + E.rotation(e - h2 * ed + 0.5 * h2 * h2 * edd) @ l
    ) / h2**2
    assert np.allclose(A @ E.Lam(l) @ edd + B @ E.Lam(l) @ e2 + C @ E.Lam(l) @ ex, lddot, atol=1e-6)


def test_printed_J1_J2_and_theta1_fail():
    rng = np.random.default_rng(7)
    J = random_spd(rng)
    w = rng.standard_normal(3)
    sq = w**2
    J1, J2 = E.J1_J2(J)
    assert np.allclose(
        J1 @ sq + J2 @ [w[1] * w[2], w[2] * w[0], w[0] * w[1]], np.cross(w, J @ w), atol=1e-14
    )
    P1, P2 = E.J1_J2_printed(J)
    assert not np.allclose(
        P1 @ sq + P2 @ [w[0] * w[1], w[0] * w[2], w[1] * w[2]], np.cross(w, J @ w), atol=1e-4
    )
    th = 0.8
    dTheta = (E.passive([th + H, 0, 0])[0] - E.passive([th - H, 0, 0])[0]) / (2 * H)
    assert np.allclose(
        E.derivative_matrices([th, 0.3, 0.2])[0], dTheta, atol=1e-8
    )  # (8-65) corrected
    assert not np.allclose(E.theta1_printed(th), dTheta, atol=1e-3)  # printed third row


def random_chain(rng, n):
    return E.EulerChain(
        m=rng.uniform(0.5, 2, n),
        J=[random_spd(rng) for _ in range(n)],
        d=rng.uniform(-0.2, 0.2, (n, 3)),
        l=rng.uniform(-0.4, 0.4, (n, 3)),
    )


def chain_state(rng, n):
    S = rng.uniform(-1, 1, (n, 3))
    S[:, 1] += 1.5
    return S, rng.standard_normal((n, 3)), rng.standard_normal((n, 3))


@pytest.mark.parametrize("n", [1, 2, 4])
def test_chain_inverse_dynamics_vs_pinocchio(n):
    rng = np.random.default_rng(n)
    ch = random_chain(rng, n)
    model = ch.pin_model()
    data = model.createData()
    for _ in range(3):
        S, Sd, Sdd = chain_state(rng, n)
        Q = ch.inverse(S, Sd, Sdd)  # (8-91)
        assert np.allclose(Q, ch.inverse_direct(S, Sd, Sdd), atol=1e-12)  # (8-80) direct
        q, v, a = ch.to_pin_state(S, Sd, Sdd)
        tau = pin.rnea(model, data, q, v, a).reshape(n, 3)
        Qp = np.array([E.rotation(S[k]) @ tau[k] for k in range(n)])
        assert np.max(np.abs(Q - Qp)) < 1e-12 * max(1, np.max(np.abs(Qp)))
        # forward dynamics (8-92) against pin.aba
        Sdd2 = ch.forward(S, Sd, Q)
        assert np.allclose(Sdd2, Sdd, atol=1e-10)
        Qr = rng.standard_normal((n, 3))
        Sdd3 = ch.forward(S, Sd, Qr)
        taur = np.concatenate([E.rotation(S[k]).T @ Qr[k] for k in range(n)])
        _, _, a3 = ch.to_pin_state(S, Sd, Sdd3)
        assert np.allclose(a3, pin.aba(model, data, q, v, taur), atol=1e-9)


def test_gimbal_lock_guard():
    rng = np.random.default_rng(1)
    ch = random_chain(rng, 2)
    S, Sd, _ = chain_state(rng, 2)
    S[1, 1] = 0.0
    with pytest.raises(EulerSingularityError, match="link 2"):
        ch.forward(S, Sd, np.zeros((2, 3)))
    ch.inverse(S, Sd, np.zeros((2, 3)))  # inverse dynamics is fine at ψ = 0


def test_mixed_problem_corrected_and_printed():
    rng = np.random.default_rng(3)
    ch = random_chain(rng, 2)
    S, Sd, Sdd = chain_state(rng, 2)
    A, B, C, G = ch.matrices(S)
    Sd2, Sx = ch._products(Sd)
    h = B @ Sd2 + C @ Sx + G
    x = Sdd.reshape(-1)
    Q = A @ x + h
    q_rows, s_cols = [0, 1, 2, 4], [0, 3]  # known moments / known accelerations
    Qz, Sz = E.mixed(A, h, q_rows, Q[q_rows], s_cols, x[s_cols])
    assert np.allclose(Qz, Q[[3, 5]], atol=1e-10) and np.allclose(Sz, x[[1, 2, 4, 5]], atol=1e-10)
    Pz, Psz = E.mixed_printed(A, h, q_rows, Q[q_rows], s_cols, x[s_cols])
    assert not (
        np.allclose(Pz, Q[[3, 5]], atol=1e-3) and np.allclose(Psz, x[[1, 2, 4, 5]], atol=1e-3)
    )
    with pytest.raises(ValueError, match="as many"):
        E.mixed(A, h, [0], Q[[0]], s_cols, x[s_cols])


def test_bad_chain_input():
    with pytest.raises(InertiaError):
        E.EulerChain(m=[0.0], J=[np.eye(3)], d=[[0, 0, 0]], l=[[0, 0, 1]])
    with pytest.raises(InertiaError):
        E.EulerChain(m=[1.0], J=[np.diag([1, 1, -1.0])], d=[[0, 0, 0]], l=[[0, 0, 1]])
    ch = E.EulerChain(m=[1.0], J=[np.eye(3) * 0.01], d=[[0, 0, 0.1]], l=[[0, 0, 0.2]])
    with pytest.raises(ValueError, match="NaN"):
        ch.inverse([[np.nan, 1, 0]], [[0, 0, 0]], [[0, 0, 0]])
    with pytest.raises(ValueError, match="shape"):
        ch.inverse([[0, 1]], [[0, 0, 0]], [[0, 0, 0]])


def test_printed_skew_8_78_fails():
    """[d]× printed at l. 6446 as [[0, −d_x, d_y], [d_z, 0, −d_x], [−d_y, d_x, 0]] is not the
    cross-product matrix; the corrected E.skew is."""
    d, u = np.array([0.3, -0.2, 0.5]), np.array([1.0, 2.0, -0.7])
    assert np.allclose(E.skew(d) @ u, np.cross(d, u))
    printed = np.array([[0, -d[0], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
    assert not np.allclose(printed @ u, np.cross(d, u), atol=1e-3)
