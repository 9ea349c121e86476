"""§6-4 rotation-tensor vector-loop method (6-48)–(6-65) on the Unimate 2600 (Fig. 6-10) and the
6R arm (Fig. 6-11).  Oracles: Pinocchio FK of the same arm (URDF from the loop), the book's
expanded component vectors (6-63)/(6-64) and (6-51), and the nested = product identity."""

import numpy as np
import pinocchio as pin
import pytest

from anthroarm.kinematics.vector_loop import (
    I,
    J,
    K,
    VectorLoop,
    loop_spec,
    nested_pose,
    product_pose,
)
from anthroarm.models.spec import to_urdf
from anthroarm.models.templates import tensor6r_loop, unimate2600_loop
from anthroarm.spatial.rotation_tensor import rotation_tensor

RNG = np.random.default_rng(3)


def pin_model(loop, lim):
    m = pin.buildModelFromXML(to_urdf(loop_spec(loop, lim)))
    return m, m.createData(), m.getFrameId("grip")


@pytest.mark.parametrize("make", [unimate2600_loop, tensor6r_loop])
def test_nested_and_product_forms_equal_pinocchio(make):
    loop, lim = make()
    m, d, fid = pin_model(loop, lim)
    assert m.nq == loop.nq == 6
    lo, hi = np.array(lim).T
    for _ in range(25):
        q = RNG.uniform(lo, hi)
        P, a, b = nested_pose(loop, q)  # (6-50)/(6-59), (6-53)
        P2, a2, b2 = product_pose(loop, q)  # (6-60)/(6-61)
        pin.framesForwardKinematics(m, d, q)
        T = d.oMf[fid]
        for x, y in ((P, P2), (a, a2), (b, b2)):
            np.testing.assert_allclose(x, y, atol=1e-14)
        np.testing.assert_allclose(P, T.translation, atol=1e-14)
        np.testing.assert_allclose(a, T.rotation @ loop.a0, atol=1e-14)
        np.testing.assert_allclose(b, T.rotation @ loop.b0, atol=1e-14)


def R_components(q, c):
    """(6-63)/(6-64) expanded, with the cos θ5 of the notes' reconstruction."""
    t1, t2, t3, t4, t5, _ = q
    C1, S1, C4, S4, C5, S5 = np.cos(t1), np.sin(t1), np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    C23, S23 = np.cos(t2 + t3), np.sin(t2 + t3)
    R12 = np.array([0, 0, c[0] + c[1]])
    R3 = c[2] * np.array([C1, S1, 0])
    R4 = c[3] * np.array([C1 * np.cos(t2), S1 * np.cos(t2), -np.sin(t2)])
    R56 = (c[4] + c[5]) * np.array([C1 * C23, S1 * C23, -S23])
    R78 = (c[6] + c[7]) * np.array(
        [
            C1 * C5 * C23 - S1 * S4 * S5 - C1 * C4 * S5 * S23,
            S1 * C5 * C23 + C1 * S4 * S5 - S1 * C4 * S5 * S23,
            -C5 * S23 - C4 * S5 * C23,
        ]
    )
    return R12, R3, R4, R56, R78


C6R = (0.3, 0.2, 0.05, 0.4, 0.2, 0.15, 0.05, 0.1)


def test_6r_expanded_components_6_63_6_64():
    loop, _ = tensor6r_loop(*C6R)
    for _ in range(25):
        q = RNG.uniform(-np.pi, np.pi, 6)
        P, _, _ = nested_pose(loop, q)
        np.testing.assert_allclose(sum(R_components(q, C6R)), P, atol=1e-14)  # (6-64)


def test_printed_R78_with_cos_theta3_fails():
    """(6-63) R_{7-8} x, y as printed carry cos θ3 where cos θ5 belongs (ch6 notes §2.6)."""
    loop, _ = tensor6r_loop(*C6R)
    q = np.array([0.3, -0.4, 0.9, 0.5, -0.7, 0.2])
    t1, t2, t3, t4, t5, _ = q
    C1, S1, C4, S4, S5 = np.cos(t1), np.sin(t1), np.cos(t4), np.sin(t4), np.sin(t5)
    C23, S23 = np.cos(t2 + t3), np.sin(t2 + t3)
    x_printed = (C6R[6] + C6R[7]) * (C1 * np.cos(t3) * C23 - S1 * S4 * S5 - C1 * C4 * S5 * S23)
    R78 = R_components(q, C6R)[4]
    P, _, _ = nested_pose(loop, q)
    assert abs(sum(R_components(q, C6R))[0] - P[0]) < 1e-14
    assert abs(x_printed - R78[0]) > 1e-3


def test_printed_theta3_about_i_fails():
    """(6-62) as printed turns θ3 about i (E^{iθ3}); the printed matrix is C_y and the expansion
    (6-63)/(6-64) adds θ2 + θ3 (C23, S23), which needs θ3 about j like θ2.  With the printed
    axis the loop misses (6-64) by O(link length) at a generic q."""
    loop, _ = tensor6r_loop(*C6R)
    items = list(loop.items)
    rev = [n for n, (kind, _) in enumerate(items) if kind == "R"]
    assert np.allclose(items[rev[2]][1], J)  # the corrected θ3 axis
    items[rev[2]] = ("R", I)  # the printed one
    printed = VectorLoop(tuple(items), G=loop.G, a0=loop.a0, b0=loop.b0)
    q = np.array([0.3, -0.4, 0.9, 0.5, -0.7, 0.2])
    expanded = sum(R_components(q, C6R))
    np.testing.assert_allclose(nested_pose(loop, q)[0], expanded, atol=1e-14)
    assert np.abs(nested_pose(printed, q)[0] - expanded).max() > 0.05


def test_printed_6_65_b_about_k_fails():
    """(6-65) as printed ends with E^{kθ6}(b0ᵏ): that leaves b0 unchanged, so b would not depend
    on θ6; Pinocchio's tool frame does (θ6 about i)."""
    loop, lim = tensor6r_loop(*C6R)
    m, d, fid = pin_model(loop, lim)
    q = np.array([0.3, -0.4, 0.9, 0.5, -0.7, 0.2])
    E5 = np.eye(3)
    for w, t in zip((K, J, J, I, J), q[:5]):
        E5 = E5 @ rotation_tensor(w, t)
    b_printed = E5 @ rotation_tensor(K, q[5]) @ np.array(K)
    b_corrected = E5 @ rotation_tensor(I, q[5]) @ np.array(K)
    pin.framesForwardKinematics(m, d, q)
    b_pin = d.oMf[fid].rotation @ np.array(K)
    np.testing.assert_allclose(b_corrected, b_pin, atol=1e-14)
    assert np.abs(b_printed - b_pin).max() > 0.1


def test_unimate_expanded_6_51_and_attitude_vector():
    """(6-51): P = (C1 + C2) + E1E2(L3 + C4) + E1E2E3E4(C5) + E1E2E3E4E5(G6), using E^{wθ}(v) = v
    for v ∥ w (6-49); the grip vector G6 ∥ k is an attitude vector: E^{iθ5}(G6) ≠ G6."""
    c1, c2, c4, c5, g6 = 0.5, 0.3, 0.15, 0.1, 0.12
    loop, lim = unimate2600_loop(c1, c2, (0.3, 1.0), c4, c5, g6)
    k, i = np.array(K), np.array(I)
    for _ in range(20):
        t1, t2, L, t3, t4, t5 = RNG.uniform(np.array(lim)[:, 0], np.array(lim)[:, 1])
        E1, E2, E3, E4, E5 = (
            rotation_tensor(w, t) for w, t in ((K, t1), (J, t2), (I, t3), (J, t4), (I, t5))
        )
        P51 = (
            (c1 + c2) * k
            + E1 @ E2 @ ((L + c4) * i)
            + E1 @ E2 @ E3 @ E4 @ (c5 * k)
            + E1 @ E2 @ E3 @ E4 @ E5 @ (g6 * k)
        )
        P, a, _ = nested_pose(loop, [t1, t2, L, t3, t4, t5])
        np.testing.assert_allclose(P, P51, atol=1e-14)
        np.testing.assert_allclose(a, E1 @ E2 @ E3 @ E4 @ E5 @ k, atol=1e-14)  # (6-53)
        np.testing.assert_allclose(
            rotation_tensor(I, t3) @ i, i, atol=1e-15
        )  # (6-49) ordinary vector
        assert np.linalg.norm(E5 @ k - k) > 1e-6 or abs(np.sin(t5)) < 1e-6  # attitude vector


def test_bad_loops_are_value_errors():
    with pytest.raises(ValueError, match="kind"):
        VectorLoop((("X", I),), G=(0, 0, 1))
    with pytest.raises(ValueError, match="unit"):
        VectorLoop((("R", (0, 0, 2)),), G=(0, 0, 1))
    with pytest.raises(ValueError, match="finite"):
        VectorLoop((("C", (0, np.nan, 0)), ("R", K)), G=(0, 0, 1))
    loop, _ = tensor6r_loop()
    with pytest.raises(ValueError, match="6 finite joint values"):
        nested_pose(loop, np.zeros(5))
    with pytest.raises(ValueError, match="c4"):
        tensor6r_loop(c4=-1.0)
