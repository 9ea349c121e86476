"""Euler z-x-z (5-80)/(5-81) and X-Y-X (8-41) with inverses; printed (5-80)_32 fails."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rotation
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from anthroarm.spatial import euler as E
from anthroarm.spatial.rotations import rot_x, rot_z, unskew

H = settings(max_examples=40, deadline=None)


def printed_5_80(t, a, d):
    """Eq. (5-80) exactly as printed (line 2968): element (3,2) = sin δ cos δ."""
    ct, st_, ca, sa, cd, sd = np.cos(t), np.sin(t), np.cos(a), np.sin(a), np.cos(d), np.sin(d)
    return np.array(
        [
            [ct * cd - st_ * ca * sd, -ct * sd - st_ * ca * cd, st_ * sa],
            [st_ * cd + ct * ca * sd, -st_ * sd + ct * ca * cd, -ct * sa],
            [sa * sd, sd * cd, ca],
        ]
    )


@H
@given(angle, angle, angle)
def test_zxz_5_80_is_product_of_exp3(t, a, d):
    C = E.euler_zxz(t, a, d)
    ref = (
        pin.exp3(np.array([0, 0, t]))
        @ pin.exp3(np.array([a, 0, 0]))
        @ pin.exp3(np.array([0, 0, d]))
    )
    assert np.allclose(C, ref, atol=1e-14)
    assert np.allclose(
        E.euler_zxz_partial(t, a), ref @ pin.exp3(np.array([0, 0, -d])), atol=1e-14
    )  # (5-81)


def test_printed_5_80_element_32_is_wrong():
    t, a, d = 0.3, 1.1, -0.7
    P = printed_5_80(t, a, d)
    C = E.euler_zxz(t, a, d)
    assert not np.isclose(P[2, 1], C[2, 1])
    assert np.abs(P @ P.T - np.eye(3)).max() > 1e-2  # the printed matrix is not orthogonal
    P[2, 1] = np.sin(a) * np.cos(d)
    assert np.allclose(P, C)


@H
@given(angle, st.floats(0.01, np.pi - 0.01), angle)
def test_zxz_inverse_round_trip(t, a, d):
    r = E.euler_zxz_inverse(E.euler_zxz(t, a, d))
    assert not r.singular and r.status == "ok"
    assert np.allclose(np.exp(1j * r.angles), np.exp(1j * np.array([t, a, d])), atol=1e-9)


@pytest.mark.parametrize("alpha", [0.0, np.pi, 1e-12])
def test_zxz_gimbal_lock_reported(alpha):
    C = E.euler_zxz(0.4, alpha, 0.3)
    r = E.euler_zxz_inverse(C)
    assert r.singular and "gimbal lock" in r.status
    assert np.allclose(E.euler_zxz(*r.angles), C, atol=1e-9)


@H
@given(angle, angle, angle)
def test_xyx_matches_scipy_and_inverse(t, p, f):
    R = E.euler_xyx(t, p, f)
    assert np.allclose(R, Rotation.from_euler("XYX", [t, p, f]).as_matrix(), atol=1e-14)
    r = E.euler_xyx_inverse(R)
    assert np.allclose(E.euler_xyx(*r.angles), R, atol=1e-9)
    if abs(np.sin(p)) > 1e-3:
        assert not r.singular


def test_xyx_zero_posture_is_singular():
    r = E.euler_xyx_inverse(np.eye(3))
    assert r.singular and "ψ" in r.status


@H
@given(angle, angle, angle, angle, angle, angle)
def test_rate_matrices_give_body_angular_velocity(t, p, f, td, pd, fd):
    h = 1e-6
    e, ed = np.array([t, p, f]), np.array([td, pd, fd])
    for fun, rate in (
        (E.euler_xyx, lambda e: E.euler_xyx_rate_matrix(e[1], e[2])),
        (E.euler_zxz, lambda e: E.euler_zxz_rate_matrix(e[1], e[2])),
    ):
        Rd = (fun(*(e + h * ed)) - fun(*(e - h * ed))) / (2 * h)
        w_body = unskew(fun(*e).T @ Rd)
        assert np.allclose(rate(e) @ ed, w_body, atol=1e-7)
    assert np.isclose(np.linalg.det(E.euler_xyx_rate_matrix(p, f)), -np.sin(p))


def test_euler_bad_input():
    with pytest.raises(ValueError, match="not orthogonal"):
        E.euler_zxz_inverse(np.ones((3, 3)))
    with pytest.raises(ValueError, match="finite"):
        E.euler_zxz(np.nan, 0, 0)
    with pytest.raises(ValueError, match="one"):
        E.euler_xyx_inverse(np.stack([np.eye(3)] * 2))
    with pytest.raises(ValueError, match="psi must be finite"):
        E.euler_xyx_rate_matrix(np.nan, 0.0)
    with pytest.raises(ValueError, match="delta must be finite"):
        E.euler_zxz_rate_matrix(0.3, np.inf)


@H
@given(rotation())
def test_zxz_inverse_of_any_rotation(R):
    r = E.euler_zxz_inverse(R)
    assert np.allclose(E.euler_zxz(*r.angles), R, atol=1e-9)
    assert 0 <= r.angles[1] <= np.pi
    assert np.allclose(rot_z(r.angles[0]) @ rot_x(r.angles[1]) @ rot_z(r.angles[2]), R, atol=1e-9)
