"""Elementary rotations, Rodrigues (5-84), validation (book §5-4) against Pinocchio and
identities."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rotation, unit3, vec3
from hypothesis import given, settings

from anthroarm.spatial import rotations as R

H = settings(max_examples=40, deadline=None)


@H
@given(angle)
def test_elementary_rotations_match_pinocchio(a):
    assert np.allclose(R.rot_x(a), pin.utils.rotate("x", a), atol=1e-15)
    assert np.allclose(R.rot_y(a), pin.utils.rotate("y", a), atol=1e-15)
    assert np.allclose(R.rot_z(a), pin.utils.rotate("z", a), atol=1e-15)


def test_elementary_rotations_batch_shape():
    a = np.linspace(-1, 1, 5)
    assert R.rot_x(a).shape == (5, 3, 3)
    assert np.allclose(R.rot_z(a)[3], R.rot_z(a[3]))


@H
@given(unit3, angle)
def test_rodrigues_5_84_equals_exp3(n, phi):
    C = R.rot_axis(n, phi)
    assert np.allclose(C, pin.exp3(phi * n), atol=1e-14)
    # the printed element form (5-84), v = 1 - cos φ
    ca, cb, cg = n
    v, c, s = 1 - np.cos(phi), np.cos(phi), np.sin(phi)
    printed = np.array(
        [
            [ca * ca * v + c, ca * cb * v - cg * s, ca * cg * v + cb * s],
            [ca * cb * v + cg * s, cb * cb * v + c, cb * cg * v - ca * s],
            [cg * ca * v - cb * s, cb * cg * v + ca * s, cg * cg * v + c],
        ]
    )
    assert np.allclose(C, printed, atol=1e-14)


@H
@given(rotation())
def test_axis_angle_inverts_rodrigues_like_log3(Rm):
    n, phi = R.axis_angle(Rm)
    assert np.allclose(R.rot_axis(n, phi), Rm, atol=1e-12)
    w = pin.log3(Rm)
    if np.linalg.norm(w) < np.pi - 1e-6:
        assert np.allclose(n * phi, w, atol=1e-9)


def test_axis_angle_near_pi_and_zero():
    for phi in (np.pi, np.pi - 1e-9, 0.0, 1e-13):
        n0 = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
        n, p = R.axis_angle(R.rot_axis(n0, phi))
        assert np.allclose(R.rot_axis(n, p), R.rot_axis(n0, phi), atol=1e-9)


@H
@given(rotation())
def test_cofactor_identities_5_83(M):
    # det M = 1 so each element of the third column equals its cofactor
    assert np.isclose(M[0, 2], M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0])
    assert np.isclose(M[1, 2], M[0, 1] * M[2, 0] - M[0, 0] * M[2, 1])
    assert np.isclose(M[2, 2], M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0])


@H
@given(rotation(), vec3, vec3)
def test_homogeneous_5_67_and_translation_match_se3(Rm, p, x):
    A = R.homogeneous(Rm, p)
    assert np.allclose(A, pin.SE3(Rm, p).homogeneous)
    assert np.allclose((A @ np.append(x, 1))[:3], pin.SE3(Rm, p).act(x))
    L = R.translation(*p)
    assert np.allclose(L, pin.SE3(np.eye(3), p).homogeneous)


def test_composite_Bx_origin_uses_upper_index_m():
    # B_x = A_1..A_n L_1 A_{n+1}..A_m L_2: origin C^1_n l1 + C^1_m l2 (the print has C^1_n twice)
    rng = np.random.default_rng(0)
    A = [R.homogeneous(pin.exp3(rng.normal(size=3))) for _ in range(4)]
    l1, l2 = rng.normal(size=3), rng.normal(size=3)
    B = A[0] @ A[1] @ R.translation(*l1) @ A[2] @ A[3] @ R.translation(*l2)
    Cn = A[0][:3, :3] @ A[1][:3, :3]
    Cm = Cn @ A[2][:3, :3] @ A[3][:3, :3]
    assert np.allclose(B[:3, 3], Cn @ l1 + Cm @ l2)
    assert not np.allclose(B[:3, 3], Cn @ l1 + Cn @ l2)  # printed form
    assert np.allclose(B[:3, :3], Cm)


def test_planar_transform_5_62():
    T = R.planar_transform(0.4, 1.0, -2.0)
    x2 = np.array([0.3, 0.7, 1.0])
    x1 = T @ x2
    c, s = np.cos(0.4), np.sin(0.4)
    assert np.allclose(x1[:2], [0.3 * c - 0.7 * s + 1.0, 0.3 * s + 0.7 * c - 2.0])  # (5-61)


@H
@given(vec3)
def test_direction_cosines_5_31_5_32(a):
    if np.linalg.norm(a) < 1e-12:  # the zero-length threshold of unit_axis
        with pytest.raises(ValueError, match="zero length"):
            R.direction_cosines(a)
        return
    d = R.direction_cosines(a)
    assert np.isclose(d @ d, 1.0)
    assert np.allclose(d * np.linalg.norm(a), a)


@H
@given(vec3, vec3)
def test_skew_is_cross_product(a, b):
    assert np.allclose(R.skew(a) @ b, np.cross(a, b))
    assert np.allclose(R.skew(a), pin.skew(a))
    assert np.allclose(R.unskew(R.skew(a)), a)


@H
@given(vec3, vec3)
def test_rotation_between_is_the_smallest_turn(a, b):
    if min(np.linalg.norm(a), np.linalg.norm(b)) < 1e-3:
        return
    C = R.rotation_between(a, b)
    ah, bh = a / np.linalg.norm(a), b / np.linalg.norm(b)
    R.check_rotation(C)
    assert np.allclose(C @ ah, bh, atol=1e-12)
    # the turn angle is the angle between the directions (log3: pin, independent)
    angle = np.linalg.norm(pin.log3(C))
    assert np.isclose(angle, np.arccos(np.clip(ah @ bh, -1, 1)), atol=1e-6)


@pytest.mark.parametrize("a", [[0, 0, 1.0], [0, 1.0, 0], [1.0, 0, 0], [0.3, -0.2, 0.9]])
def test_rotation_between_antiparallel_is_a_half_turn(a):
    a = np.asarray(a) / np.linalg.norm(a)
    C = R.rotation_between(a, -2 * a)
    R.check_rotation(C)
    assert np.allclose(C @ a, -a, atol=1e-15)
    assert np.isclose(np.trace(C), -1.0)  # a half turn
    assert np.allclose(R.rotation_between(a, 3 * a), np.eye(3))
    with pytest.raises(ValueError, match="zero length"):
        R.rotation_between(a, [0, 0, 0])


# ----------------------------------------------------------------------------- bad input
def test_non_orthogonal_rotation_raises_with_value():
    M = np.eye(3)
    M[0, 1] = 0.1
    with pytest.raises(ValueError, match="not orthogonal.*0.1"):
        R.check_rotation(M)
    with pytest.raises(ValueError, match="reflection"):
        R.check_rotation(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match="NaN"):
        R.check_rotation(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match="shape"):
        R.check_rotation(np.eye(4))
    with pytest.raises(ValueError, match="not orthogonal"):
        R.axis_angle(2 * np.eye(3))


def test_bad_axes_raise_with_value():
    with pytest.raises(ValueError, match=r"zero length: \[0.0, 0.0, 0.0\]"):
        R.rot_axis([0, 0, 0], 0.3)
    with pytest.raises(ValueError, match=r"unit vector, got \[0.0, 0.0, 2.0\]"):
        R.rot_axis([0, 0, 2.0], 0.3)
    with pytest.raises(ValueError, match="shape"):
        R.rot_axis([1.0, 0], 0.3)
    with pytest.raises(ValueError, match="NaN"):
        R.rot_axis([np.nan, 0, 1], 0.3)
    with pytest.raises(ValueError, match="finite"):
        R.rot_x(np.inf)
    with pytest.raises(ValueError, match="theta must be finite"):
        R.planar_transform(np.nan, 0.0, 0.0)
    assert np.allclose(R.unit_axis([0, 0, 2.0]), [0, 0, 1])


@pytest.mark.parametrize("gap", [1e-3, 1e-6, 1e-9, 1e-11])
def test_rotation_between_nearly_antiparallel_stays_orthogonal(gap):
    """Beyond a quarter turn the (1 + c) denominator of the compact Rodrigues form loses
    orthogonality (a hand trace pointing along -y broke the viewer); the result must be a
    rotation to rounding and still map a onto b as well as the geometry allows (the axis of a
    near half turn is determined only to eps / gap)."""
    rng = np.random.default_rng(1)
    for _ in range(50):
        a = rng.normal(size=3)
        a /= np.linalg.norm(a)
        b = -a + gap * rng.normal(size=3)
        C = R.rotation_between(a, b)
        assert np.abs(C.T @ C - np.eye(3)).max() < 1e-14
        assert np.isclose(np.linalg.det(C), 1.0, atol=1e-14)
        assert np.linalg.norm(C @ a - b / np.linalg.norm(b)) < 1e-15 / gap + 1e-12
