"""Robot API: fk/jacobian shapes and batches, input validation, frames."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import UnknownFrameError


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


def test_fk_single_and_batch(arm):
    Q = arm.random_q(5, 0)
    Tb = arm.fk(Q)
    assert Tb.shape == (5, 4, 4)
    for q, T in zip(Q, Tb):
        np.testing.assert_array_equal(arm.fk(q), T)


def test_jacobian_matches_finite_differences(arm):
    """LOCAL_WORLD_ALIGNED rows (v; w) against central differences of fk (mathematics)."""
    q = arm.random_q(None, 1)
    J = arm.jacobian(q)
    h = 1e-6
    for k in range(arm.nv):
        dq = np.zeros(arm.nq)
        dq[k] = h
        Tp, Tm = arm.fk(q + dq), arm.fk(q - dq)
        v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ arm.fk(q)[:3, :3].T
        w = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        np.testing.assert_allclose(J[:3, k], v, atol=1e-8)
        np.testing.assert_allclose(J[3:, k], w, atol=1e-8)


def test_jacobian_reference_frames(arm):
    q = arm.random_q(None, 2)
    JL = arm.jacobian(q, reference="LOCAL")
    JW = arm.jacobian(q)
    R = arm.fk(q)[:3, :3]
    np.testing.assert_allclose(R @ JL[:3], JW[:3], atol=1e-14)
    np.testing.assert_allclose(R @ JL[3:], JW[3:], atol=1e-14)


def test_other_frames(arm):
    q = arm.random_q(None, 3)
    T = arm.fk(q, frame="forearm")
    pin.framesForwardKinematics(arm.model, arm.data, q)
    np.testing.assert_array_equal(T, arm.data.oMf[arm.model.getFrameId("forearm")].homogeneous)


def test_unknown_frame_lists_valid_frames(arm):
    with pytest.raises(UnknownFrameError) as e:
        arm.fk(arm.neutral(), frame="elbow_nope")
    assert "hand_point" in str(e.value)
    with pytest.raises(UnknownFrameError, match="name or an index"):
        arm.fk(arm.neutral(), frame=1.5)


def test_unknown_jacobian_reference_is_a_value_error(arm):
    with pytest.raises(ValueError, match="LOCAL_WORLD_ALIGNED"):
        arm.jacobian(arm.neutral(), reference="world")
    np.testing.assert_array_equal(
        arm.jacobian(arm.neutral(), reference=pin.ReferenceFrame.WORLD),
        arm.jacobian(arm.neutral(), reference="WORLD"),
    )


@pytest.mark.parametrize("bad", [np.zeros(6), np.zeros(8), np.zeros((2, 6)), np.zeros((2, 2, 7))])
def test_wrong_shape_raises_valueerror(arm, bad):
    with pytest.raises(ValueError, match=r"shape \(7,\)"):
        arm.fk(bad)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_nonfinite_names_the_joint(arm, value):
    q = arm.neutral()
    q[3] = value
    with pytest.raises(ValueError, match="elbow_flexion"):
        arm.jacobian(q)
    Q = arm.random_q(3, 0)
    Q[2, 5] = value
    with pytest.raises(ValueError, match="wrist_deviation.*row 2"):
        arm.fk(Q)


def test_random_q_inside_limits(arm):
    Q = arm.random_q(1000, 0)
    assert arm.within_limits(Q).all()
    assert not arm.within_limits(arm.upper + 0.1)


MIMIC_URDF = """<robot name="m"><link name="base"/><link name="l1"/><link name="l2"/>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/>
 <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0"/>
 <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/>
 <mimic joint="j1" multiplier="2" offset="0.1"/></joint></robot>"""


def test_mimic_joint_is_modelled_like_yourdfpy(tmp_path):
    """A mimic joint is driven by the joint it mimics in Pinocchio and in yourdfpy alike."""
    p = tmp_path / "mimic.urdf"
    p.write_text(MIMIC_URDF)
    r = aa.load(str(p))
    assert r.has_mimic and r.nq == 1 and r.joint_names == ["j1"]
    q = np.array([0.3])
    # l2 turns by q + (2 q + 0.1) about z (mathematics)
    ang = q[0] + 2 * q[0] + 0.1
    T = r.fk(q, frame="l2")
    np.testing.assert_allclose(
        T[:2, :2], [[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]], atol=1e-15
    )
    u = r.urdf
    u.update_cfg(r.yourdfpy_cfg(q))
    np.testing.assert_allclose(u.get_transform("l2", u.base_link), T, atol=1e-15)
