"""Book Ch. 2 structure: Table 2.1, Eq. (2-1) F = 27 / 20, Eq. (2-2) 64 -> 4, reach (2-3)/(2-4)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.design import structure as S


def test_table_2_1_classes():
    # Table 2.1: R, P, H are class V (1 DOF); C class IV (2 DOF); S class III (3 DOF)
    expected = {"R": (1, 5), "P": (1, 5), "S": (3, 3), "C": (2, 4), "H": (1, 5)}
    assert {p.symbol: (p.dof, p.pair_class) for p in S.TABLE_2_1} == expected
    for p in S.PAIRS.values():
        assert p.dof + p.constraints == 6
    assert S.pair("U").class_name == "IV级"
    with pytest.raises(ValueError, match="unknown kinematic pair"):
        S.pair("Q")


def test_mobility_upper_limb_book_27():
    # l. 542-546: n = 19, p = (0, 1, 2, 6, 11) -> 6*19 - 87 = 27
    assert S.spatial_mobility(19, (0, 1, 2, 6, 11)) == 27
    m = S.upper_limb_mechanism()
    assert m.n_moving == 19
    assert m.pair_counts() == {1: 0, 2: 1, 3: 2, 4: 6, 5: 11}
    assert m.mobility() == 27
    assert m.loops == 1  # humerus-ulna-radius


def test_mobility_fingers_book_20():
    # l. 548-550: n = 15, p_IV = 5, p_V = 10 -> 90 - 70 = 20
    assert S.spatial_mobility(15, {4: 5, 5: 10}) == 20
    m = S.human_fingers()
    assert (m.n_moving, m.mobility(), m.loops) == (15, 20, 0)
    # the arm alone carries the rest: 27 - 20 = 7 = shoulder 3 + elbow 2 + wrist 2
    assert S.upper_limb_mechanism().mobility() - m.mobility() == 7


def test_mobility_rrss_local_dof_and_planar_sixbar():
    m = S.rrss_mechanism()
    assert S.spatial_mobility(3, {3: 2, 5: 2}) == 2  # raw (2-1): includes the rod spin
    assert m.mobility() == 1
    assert S.planar_mobility(5, 7) == 1  # six-bar finger, Fig. 2-8
    assert S.planar_mobility(3, 4) == 1  # four-bar


def test_mobility_bad_input():
    with pytest.raises(ValueError):
        S.spatial_mobility(3, (1, 2))
    with pytest.raises(ValueError):
        S.spatial_mobility(-1, (0, 0, 0, 0, 1))
    with pytest.raises(ValueError):
        S.spatial_mobility(2, {6: 1})
    m = S.Mechanism("x")
    m.add_link("a", "b")
    m.add_joint("j", "R", "ground", "a")
    with pytest.raises(ValueError, match="not connected"):
        m.mobility()
    with pytest.raises(ValueError, match="unknown link"):
        m.add_joint("k", "R", "a", "zzz")
    with pytest.raises(ValueError, match="itself"):
        m.add_joint("k", "R", "a", "a")


def test_layouts_64_to_book_4():
    assert S.count_layouts(2, 6) == 64
    assert len(S.enumerate_arm_layouts(n_R=None, forbid=())) == 64
    forms = S.enumerate_arm_layouts()
    assert len(forms) == 4 and set(forms) == set(S.BOOK_ARM_FORMS)
    assert len(S.enumerate_arm_layouts(forbid=())) == math.comb(6, 3)


def test_reach_min_self_derived_values():
    # planar FK |l1 + l2 e^{it} + l3 e^{2it}| (ch1-2 notes part 3) -- mathematics, not the book
    cases = [
        ((1, 1, 1), 90, 1.0),
        ((300, 250, 100), 90, 320.1562),
        ((300, 250, 100), 145, 138.5309),
        ((340, 240, 130), 150, 197.2934),
        ((340, 240, 130), 90, 318.9044),
    ]
    for ls, deg, val in cases:
        assert S.reach_min(*ls, np.deg2rad(deg)) == pytest.approx(val, abs=1e-4)
    assert S.reach_min(1, 2, 3, 0.0) == pytest.approx(S.reach_max(1, 2, 3))
    for bad in (np.nan, -1.0, 0.0):
        with pytest.raises(ValueError, match="positive and finite"):
            S.reach_min(1, bad, 3, 0.3)
        with pytest.raises(ValueError, match="positive and finite"):
            S.reach_max(1, 2, bad)


@settings(max_examples=50, deadline=None)
@given(st.floats(0.05, 1), st.floats(0.05, 1), st.floats(0.05, 1), st.floats(0, math.pi))
def test_reach_min_equals_planar_fk(l1, l2, l3, t):
    assert S.reach_min(l1, l2, l3, t) == pytest.approx(S.reach_min_fk(l1, l2, l3, t), abs=1e-9)


def test_reach_against_catalog_arm_fk():
    robot = aa.load("prosthetic_arm")
    L1, L2, L3 = (robot.spec.params[k] for k in ("L1", "L2", "L3"))
    rng = np.random.default_rng(1)
    th = rng.uniform(0, np.pi / 2, 200)
    assert robot.spec.reach.lengths == (L1, L2, L3) and robot.spec.reach.bend == (3, 5)
    q = S.bent_q(robot.spec.reach, robot.nq, th)
    # elbow and wrist flexion bent by θ3, the forearm rotation between them 0
    assert np.array_equal(q[:, [3, 5]], np.stack([th, th], 1)) and not q[:, [0, 1, 2, 4]].any()
    assert S.bent_q(robot.spec.reach, 6, 0.3, (0.1, 0.2, 0.3)).tolist() == [
        0.1,
        0.2,
        0.3,
        0.3,
        0.0,
        0.3,
    ]
    q[:, :3] = robot.random_q(200, rng)[:, :3]
    d = np.linalg.norm(robot.fk(q)[:, :3, 3], axis=1)
    np.testing.assert_allclose(d, S.reach_min(L1, L2, L3, th), atol=1e-12)
    # (2-3): no configuration reaches further than l1 + l2 + l3, q = 0 attains it
    qs = robot.random_q(2000, rng)
    assert np.linalg.norm(robot.fk(qs)[:, :3, 3], axis=1).max() <= S.reach_max(L1, L2, L3) + 1e-12
    assert np.linalg.norm(robot.fk(np.zeros(6))[:3, 3]) == pytest.approx(S.reach_max(L1, L2, L3))


def test_reach_provider_rows():
    rows = S.reach_rows(["prosthetic_arm"], 20, np.random.default_rng(0))
    assert len(rows) == 2 and all(r.ok for r in rows)
    assert S.reach_rows(["planar2r"], 20, np.random.default_rng(0)) == []  # spec.reach is None
    assert S.reach_rows(["panda"], 20, np.random.default_rng(0)) == []  # not a book model
    assert aa.models.spec("planar2r").reach is None


def printed_reach_min_2_4(l1, l2, l3, t):
    """(2-4) exactly as printed (l. 607): alpha = asin(l3 sin t / m)."""
    m = np.sqrt(l2**2 + l3**2 + 2 * l2 * l3 * np.cos(t))
    return np.sqrt(l1**2 + m**2 + 2 * l1 * m * np.cos(t + np.arcsin(l3 * np.sin(t) / m)))


def test_printed_2_4_asin_branch_fails_when_elbow_angle_obtuse():
    # l2 + l3 cos t < 0: the printed asin picks the wrong (acute) branch
    l1, l2, l3, t = 1.0, 0.25, 1.0, 2.0
    truth = S.reach_min_fk(l1, l2, l3, t)
    assert abs(printed_reach_min_2_4(l1, l2, l3, t) - truth) > 0.3
    assert S.reach_min(l1, l2, l3, t) == pytest.approx(truth, abs=1e-12)
    # where l2 + l3 cos t >= 0 the printed form is right (e.g. the book's arm)
    assert printed_reach_min_2_4(0.34, 0.26, 0.13, 1.2) == pytest.approx(
        S.reach_min_fk(0.34, 0.26, 0.13, 1.2)
    )
