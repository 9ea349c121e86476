"""The model catalog: committed URDFs equal the generator, parameters, limits, book numbers."""

from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.errors import UnknownModelError

deg = np.pi / 180
REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("name", aa.models.book_names())
def test_committed_urdf_equals_generator(name, same_urdf_text):
    committed = (REPO / "urdf" / f"{name}.urdf").read_text()
    assert same_urdf_text(committed, aa.models.urdf_text(name)), (
        f"urdf/{name}.urdf is stale: run aa.models.write_urdfs()"
    )


def test_write_urdfs_roundtrip(tmp_path):
    paths = aa.models.write_urdfs(tmp_path)
    assert sorted(p.name for p in paths) == sorted(f"{n}.urdf" for n in aa.models.book_names())
    for p in paths:
        spec = aa.models.spec(p.stem)
        r = aa.load(
            str(p), tool=spec.tool_name
        )  # a tree (the hand) has several tips: name the tool
        assert r.nq == spec.nq


def test_catalog_has_the_required_models():
    names = set(aa.models.names())
    assert {
        "prosthetic_arm",
        "human_arm7",
        "sixr_arm",
        "unimate5",
        "rrprr5",
        "planar2r",
        "panda",
        "ur5",
        "talos_arm",
        "human_right_arm",
    } <= names


@pytest.mark.parametrize("name", aa.models.names())
def test_every_model_loads_with_limits_and_tool(name):
    r = aa.load(name)
    assert r.nq == r.nv >= 2
    assert np.all(r.lower < r.upper)
    assert r.model.existFrame(r.tool)
    T = r.fk(r.neutral())
    assert np.allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    # every link of a book model carries a positive-definite inertia
    if name in aa.models.book_names():
        for i in range(1, r.model.njoints):
            Y = r.model.inertias[i]
            assert Y.mass > 0
            assert np.linalg.eigvalsh(Y.inertia).min() > 0


def test_prosthetic_arm_limits_are_the_books():
    r = aa.load("prosthetic_arm")
    # Fig. 7-2, l. 4925: θ1 0~-180, θ2 0~180, θ3 ±90, θ4 0~150, θ5 ±90, θ6 ±90 (degrees)
    np.testing.assert_allclose(np.rad2deg(r.lower), [-180, 0, -90, 0, -90, -90], atol=1e-12)
    np.testing.assert_allclose(np.rad2deg(r.upper), [0, 180, 90, 150, 90, 90], atol=1e-12)


def test_prosthetic_arm_zero_pose_hangs_down():
    # θ2 = 0 means the arm hangs straight down: E = L1 (c1 s2, s1 s2, -c2) (Eq. (7-17))
    r = aa.load("prosthetic_arm")
    q = np.zeros(6)
    E = r.fk(q, frame="link4")[:3, 3]  # link4 is the frame of joint 4 (the elbow)
    np.testing.assert_allclose(E, [0, 0, -0.340], atol=1e-15)


# Table 7.2 row 5 (l. 5119) is printed without misprint (ch7 notes §4 E1): its joint angles
# give its hand pose.  It reproduces with the forearm L2 = 260 mm, not the caption's 240 mm.
ROW5_THETA = [-74.2914, 86.6277, 0.1343, 87.7209, -3.3749, -50.2954]
ROW5_P_MM = [448.7884, -344.3675, -20.0]
ROW5_LMN = np.array([[-0.6, -0.8, 0.0], [0.0, 0.0, -1.0], [0.8, -0.6, 0.0]]).T  # columns l, m, n


def test_table_7_2_row5_pose_with_L2_260():
    T = aa.load("prosthetic_arm").fk(np.deg2rad(ROW5_THETA))
    np.testing.assert_allclose(
        T[:3, 3] * 1000, ROW5_P_MM, atol=0.01
    )  # printed to 4 decimals of degrees
    np.testing.assert_allclose(T[:3, :3], ROW5_LMN, atol=2e-5)


def test_table_7_1_caption_L2_240_fails_table_7_2():
    """Errata: the Fig. 7-2 caption's forearm 240 mm does not reproduce Table 7.2."""
    T = aa.load("prosthetic_arm", L2=0.240).fk(np.deg2rad(ROW5_THETA))
    assert np.linalg.norm(T[:3, 3] * 1000 - ROW5_P_MM) > 10.0


def test_human_arm7_scales_with_height_and_mass():
    a = aa.load("human_arm7", height=1.75, mass=75)
    b = aa.load("human_arm7", height=1.75 * 1.1, mass=75 * 1.2)
    ta = a.fk(np.zeros(7))[:3, 3]
    tb = b.fk(np.zeros(7))[:3, 3]
    np.testing.assert_allclose(tb, 1.1 * ta, rtol=1e-12)
    # de Leva 1996: upper arm 2.71 %, forearm 1.62 %, hand 0.61 % of body mass (male)
    masses = {a.model.names[i]: a.model.inertias[i].mass for i in range(1, a.model.njoints)}
    assert masses["shoulder_rotation"] == pytest.approx(0.0271 * 75)
    assert masses["forearm_pronation"] == pytest.approx(0.0162 * 75)
    assert masses["wrist_flexion"] == pytest.approx(0.0061 * 75)
    segs = ("shoulder_rotation", "forearm_pronation", "wrist_flexion")
    mb = sum(b.model.inertias[b.model.getJointId(s)].mass for s in segs)
    assert mb == pytest.approx(1.2 * sum(masses[s] for s in segs))
    # arm length from de Leva: 281.7 + 268.9 + 86.2 mm at 1741 mm stature
    assert -ta[2] == pytest.approx((281.7 + 268.9 + 86.2) / 1741 * 1.75, rel=1e-12)


def test_human_arm7_axes_and_hanging_pose():
    r = aa.load("human_arm7")
    l1, l2, l3 = (r.spec.params[k] for k in ("l1", "l2", "l3"))
    np.testing.assert_allclose(r.fk(np.zeros(7))[:3, 3], [0, 0, -(l1 + l2 + l3)], atol=1e-15)
    # elbow flexion (about x) by 90° brings the forearm forward (+y)
    q = np.zeros(7)
    q[3] = np.pi / 2
    np.testing.assert_allclose(r.fk(q)[:3, 3], [0, l2 + l3, -l1], atol=1e-15)
    # limits: Table 2.2 elbow +145/-5, forearm ±90
    i = r.joint_names.index("elbow_flexion")
    assert np.rad2deg([r.lower[i], r.upper[i]]) == pytest.approx([-5, 145])


def test_human_arm7_bad_parameters():
    with pytest.raises(ValueError, match="sex"):
        aa.load("human_arm7", sex="x")
    with pytest.raises(ValueError, match="height"):
        aa.load("human_arm7", height=17.5)
    with pytest.raises(ValueError, match="accepted"):
        aa.load("prosthetic_arm", L4=0.1)
    with pytest.raises(ValueError, match="L1 must be a finite length"):
        aa.load("prosthetic_arm", L1=float("nan"))
    with pytest.raises(ValueError, match="P must be a finite length"):
        aa.load("sixr_arm", P=-0.1)
    with pytest.raises(ValueError, match="boom"):
        aa.load("unimate5", boom=(1.0, 0.3))
    with pytest.raises(ValueError, match="height and mass must be numbers"):
        aa.load("human_arm7", height="tall")


def test_unknown_model_lists_catalog():
    with pytest.raises(UnknownModelError) as e:
        aa.load("prosthetic_leg")
    assert "prosthetic_arm" in str(e.value) and "panda" in str(e.value)


def test_erd_arms_lock_unused_joints():
    p = aa.load("panda")
    assert p.nq == 7 and set(p.locked) == {"panda_finger_joint1", "panda_finger_joint2"}
    h = aa.load("human_right_arm")
    assert h.joint_names[0] == "right_shoulder_Z" and h.nq == 7
    assert "left_elbow_Z" in h.locked


def test_same_urdf_text_tells_a_stale_file(same_urdf_text):
    """The comparison forgives the 16th digit, not a changed number or tag."""
    a = '<origin xyz="0.1 0 -0.08994824117884934" rpy="-1.5707963267948966 -0.8591786503008974 0"/>'
    assert same_urdf_text(
        a, a.replace("0.08994824117884934", "0.08994824117884936").replace(" 0 ", " -6.9e-18 ")
    )
    assert not same_urdf_text(a, a.replace("0.08994824117884934", "0.0899482"))
    assert not same_urdf_text(a, a.replace("rpy", "xyz"))
    assert not same_urdf_text(a, a + '<axis xyz="0 0 1"/>')
