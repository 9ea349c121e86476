"""The book's closed forms against Pinocchio, and the printed misprints failing.

Errata entries: docs/errata.md, Chapter 6 (6-17), (6-23) and 002 text (4-52), (4-54)."""

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import crosscheck
from anthroarm.kinematics import book_fk as cf
from anthroarm.kinematics.dh import dh_fk, dh_transform
from anthroarm.models import book as book_models
from anthroarm.models.spec import DHRow

N = 300


def test_sixr_zero_pose_from_notes():
    """ch6 notes §2.2: T06(0) = [I | (h2, 0, s0 - s3)], hand point at (h2, 0, s0 - s3 + P)."""
    r = aa.load("sixr_arm")
    p = r.spec.params
    T = cf.sixr_hand_pose(np.zeros(6), p["s0"], p["h2"], p["s3"], p["P"])
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-15)
    np.testing.assert_allclose(T[:3, 3], [p["h2"], 0, p["s0"] - p["s3"] + p["P"]], atol=1e-15)


def test_printed_hand_poses_vs_pinocchio():
    r = aa.load("sixr_arm")
    p = r.spec.params
    Q = r.random_q(N, 2)
    np.testing.assert_allclose(
        cf.sixr_hand_pose(Q, p["s0"], p["h2"], p["s3"], p["P"]), r.fk(Q), atol=1e-13
    )
    for name, P in (("unimate5", "P"), ("rrprr5", "p")):
        r = aa.load(name)
        p = r.spec.params
        Q = r.random_q(N, 3)
        np.testing.assert_allclose(
            cf.unimate_hand_pose(Q, p["s0"], p["h2"], p[P]), r.fk(Q), atol=1e-13
        )


def test_human_arm7_printed_forms_vs_pinocchio():
    r = aa.load("human_arm7", height=1.62, mass=55, sex="female")
    p = r.spec.params
    L = (p["l1"], p["l2"], p["l3"])
    Q = r.random_q(N, 4)
    np.testing.assert_allclose(cf.human_arm7_hand_pose(Q, *L), r.fk(Q), atol=1e-13)
    np.testing.assert_allclose(cf.human_arm7_jacobian(Q, *L), r.jacobian(Q), atol=1e-13)
    PE, PW, _, _ = cf.human_arm7_points(Q, *L)
    np.testing.assert_allclose(PE, r.fk(Q, frame="elbow_link")[:, :3, 3], atol=1e-13)
    np.testing.assert_allclose(PW, r.fk(Q, frame="wrist_link")[:, :3, 3], atol=1e-13)
    # single configuration gives the unbatched shape
    assert cf.human_arm7_jacobian(Q[0], *L).shape == (6, 7)


def test_prosthetic_arm_points():
    r = aa.load("prosthetic_arm")
    p = r.spec.params
    Q = r.random_q(N, 5)
    E, W, C = cf.prosthetic_arm_points(Q, p["L1"], p["L2"], p["L3"])
    t1, t2 = Q[:, 0], Q[:, 1]
    # Eq. (7-17): E = L1 (c1 s2, s1 s2, -c2)
    np.testing.assert_allclose(
        E,
        p["L1"] * np.stack([np.cos(t1) * np.sin(t2), np.sin(t1) * np.sin(t2), -np.cos(t2)], -1),
        atol=1e-15,
    )
    np.testing.assert_allclose(np.linalg.norm(W - E, axis=1), p["L2"], atol=1e-15)
    np.testing.assert_allclose(C, r.fk(Q)[:, :3, 3], atol=1e-15)


def test_bad_numbers_raise_value_errors():
    with pytest.raises(ValueError, match="theta must be finite"):
        dh_transform(np.nan, 0.0, 0.1, 0.2)
    with pytest.raises(ValueError, match="l2 must be finite"):
        cf.human_arm7_hand_pose(np.zeros(7), 0.3, np.nan, 0.1)
    with pytest.raises(ValueError, match="P must be finite"):
        cf.sixr_hand_pose(np.zeros(6), 0.5, 0.4, 0.35, np.inf)
    with pytest.raises(ValueError, match="row 2 h must be finite"):
        dh_fk([DHRow("R", 0.0), DHRow("R", 0.0, h=np.nan)], np.zeros(2))
    with pytest.raises(ValueError, match="tool"):
        dh_fk([DHRow("R", 0.0)], np.zeros(1), np.full((4, 4), np.nan))


# ---------------------------------------------------------------- printed forms that fail


def _sixr_printed_uvw(q):
    """(6-17) u, v, w as printed (l. 3841-3847): the first factors carry θ5 where θ6 belongs."""
    t1, t2, t3, t4, t5, t6 = q.T
    C1, S1, C4, S4, C5, S5 = np.cos(t1), np.sin(t1), np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    C23, S23 = np.cos(t2 + t3), np.sin(t2 + t3)
    g = (C5 * C5 * C4 + S5 * S4) * C23 + C5 * S5 * S23
    f = C5 * C5 * S4 - S5 * C4
    return np.stack(
        [g * C1 + f * S1, g * S1 - f * C1, (C5 * C5 * C4 + S5 * S4) * S23 - C5 * S5 * C23], -1
    )


def test_printed_6_17_uvw_fails():
    r = aa.load("sixr_arm")
    Q = r.random_q(50, 7)
    b_true = r.fk(Q)[:, :3, 0]  # x6 axis from Pinocchio
    assert np.abs(_sixr_printed_uvw(Q) - b_true).max() > 0.1


def _unimate_printed_v(q):
    """(6-23) v as printed (l. 3891): (C5C4C2 + S5S2) S1 - C5 S4 S1."""
    t1, t2, _, t4, t5 = q.T
    return (np.cos(t5) * np.cos(t4) * np.cos(t2) + np.sin(t5) * np.sin(t2)) * np.sin(t1) - np.cos(
        t5
    ) * np.sin(t4) * np.sin(t1)


def test_printed_6_23_v_fails():
    r = aa.load("unimate5")
    Q = r.random_q(50, 8)
    assert np.abs(_unimate_printed_v(Q) - r.fk(Q)[:, 1, 0]).max() > 0.1


def test_printed_002_4_54_v_fails():
    """002 (4-54) prints the same v as (6-23), with sin θ1 in the last term."""
    r = aa.load("rrprr5")
    Q = r.random_q(50, 9)
    assert np.abs(_unimate_printed_v(Q) - r.fk(Q)[:, 1, 0]).max() > 0.1


def test_printed_002_4_52_x_fails():
    """002 (4-52) x as printed (l. 388): P(S5 C4 cos θ3 − C5 S2) where cos θ2 belongs (θ3 = 0 is the
    fixed angle of the prismatic row, so cos θ3 = 1)."""
    r = aa.load("rrprr5")
    p = r.spec.params
    Q = r.random_q(50, 10)
    t1, t2, s2, t4, t5 = Q.T
    C1, S1, C2, S2, C4, S4, C5, S5 = (f(t) for t in (t1, t2, t4, t5) for f in (np.cos, np.sin))
    x_printed = (p["p"] * (S5 * C4 * 1.0 - C5 * S2) + s2 * S2 + p["h2"] * C2) * C1 + p[
        "p"
    ] * S5 * S4 * S1
    assert np.abs(x_printed - r.fk(Q)[:, 0, 3]).max() > 0.01


# ---------------------------------------------------------------- the cross-check can fail


def test_crosscheck_passes_and_detects_a_wrong_closed_form(monkeypatch):
    rows = crosscheck.run(["sixr_arm", "human_arm7"], samples=20)
    assert rows and all(r.ok for r in rows)
    # plant the printed (6-17) error: the check must flag it
    real = book_models.sixr_hand_pose  # the form the spec declares looks it up here

    def wrong(q, *a):
        T = real(q, *a)
        T[..., :3, 0] = _sixr_printed_uvw(np.atleast_2d(q))
        return T

    monkeypatch.setattr(book_models, "sixr_hand_pose", wrong)
    rows = crosscheck.run(["sixr_arm"], samples=20)
    bad = [r for r in rows if not r.ok]
    assert [r.quantity for r in bad] == ["fk printed (6-16)/(6-17)"]
    assert "FAIL" in crosscheck.format_table(rows)
