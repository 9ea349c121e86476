"""Hand direction angles (6-44)-(6-47): the printed (1,3) element and α formula fail; corrected
round trip."""

import numpy as np
import pinocchio as pin
import pytest
from _spatial_strategies import angle, rotation
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.spatial.hand_angles import hand_angles, hand_matrix, hand_pointing
from anthroarm.spatial.rotations import check_rotation

H = settings(max_examples=40, deadline=None)
beta_ok = st.floats(-1.5, 1.5)


def printed_6_44(a, b, g):
    """The result matrix of (6-44) as printed (l. 4021-4025): element (1,3) = +cα cβ."""
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    return np.array(
        [
            [sa * cg - ca * sb * sg, sa * sg + ca * sb * cg, ca * cb],
            [-ca * cg - sa * sb * sg, -ca * sg + sa * sb * cg, -sa * cb],
            [-cb * sg, cb * cg, sb],
        ]
    )


def printed_6_47(C):
    """(6-47) as printed: α = tan⁻¹(−c23/c13), β = sin⁻¹ c33, γ = tan⁻¹(−c31/c32)."""
    return np.arctan(-C[1, 2] / C[0, 2]), np.arcsin(C[2, 2]), np.arctan(-C[2, 0] / C[2, 1])


@H
@given(angle, beta_ok, angle)
def test_hand_matrix_is_the_printed_factor_product(a, b, g):
    C = hand_matrix(a, b, g)
    f = lambda ax, t: pin.utils.rotate(ax, t)
    assert np.allclose(
        C, f("z", -np.pi / 2) @ f("x", np.pi / 2) @ f("y", a) @ f("x", -b) @ f("z", -g), atol=1e-14
    )
    P = printed_6_44(a, b, g)
    mask = np.ones((3, 3), bool)
    mask[0, 2] = False
    assert np.allclose(P[mask], C[mask], atol=1e-14)  # every other printed element is right
    assert np.isclose(C[0, 2], -np.cos(a) * np.cos(b))
    assert np.allclose(hand_pointing(a, b), -C[:, 2])


def test_printed_6_44_is_not_a_rotation_and_printed_6_47_returns_minus_alpha():
    a, b, g = 0.6, 0.3, -0.9
    with pytest.raises(ValueError, match="not orthogonal"):
        check_rotation(printed_6_44(a, b, g))
    C = hand_matrix(a, b, g)
    pa, pb, pg = printed_6_47(C)
    assert np.isclose(pa, -a)  # the printed α formula gives −α
    assert np.isclose(pb, b) and np.isclose(pg, g)
    r = hand_angles(C)
    assert np.allclose(r.angles, [a, b, g])


@H
@given(angle, beta_ok, angle)
def test_hand_angles_round_trip(a, b, g):
    r = hand_angles(hand_matrix(a, b, g))
    assert not r.singular
    assert np.allclose(np.exp(1j * r.angles), np.exp(1j * np.array([a, b, g])), atol=1e-9)


@H
@given(rotation())
def test_hand_angles_of_any_rotation(C):
    r = hand_angles(C)
    assert np.allclose(hand_matrix(*r.angles), C, atol=1e-9)


@pytest.mark.parametrize("b", [np.pi / 2, -np.pi / 2])
def test_vertical_hand_is_reported(b):
    C = hand_matrix(0.4, b, 0.7)
    r = hand_angles(C)
    assert r.singular and "vertically" in r.status
    assert np.allclose(hand_matrix(*r.angles), C, atol=1e-12)


def test_hand_angles_of_the_human_arm_from_pinocchio():
    robot = aa.load("human_arm7")
    rng = np.random.default_rng(5)
    for q in robot.random_q(10, rng):
        C = robot.fk(q)[:3, :3]  # (6-45): total rotation of the arm (h_kl)
        r = hand_angles(C)
        assert np.allclose(hand_matrix(*r.angles), C, atol=1e-10)
