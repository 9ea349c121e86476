"""The §9-3 care robot: Table 9.5 (printed numbers, the 876/856 misprint), the model against
Pinocchio (total mass, closed-form IK round trip), its 10 cm cell table with motor pulses
(the printed 10 cm lattice and 1 cm accuracy; exact IK and FK as oracles), and Table 9.6."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ParameterError, UnknownCodeError
from anthroarm.ik.cells import CellTable, OutsideCellTableError, cell_table
from anthroarm.models import book_tables
from anthroarm.models.care_robot import (
    CELL_ACCURACY,
    CELL_D,
    TABLE_9_5,
    pulses_per_rad,
    table_9_5_length_sum_mm,
    table_9_5_mass_sum_kg,
)

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def robot():
    return aa.load("care_robot")


@pytest.fixture(scope="module")
def table(robot):
    return cell_table(robot)


def wrist(robot, q):
    """Wrist centre (m): the tool origin minus P along z6 (Pinocchio FK)."""
    T = robot.fk(q)
    return T[..., :3, 3] - robot.spec.params["P"] * T[..., :3, 2]


# ---------------------------------------------------------------- Table 9.5


def test_table_9_5_printed_values():
    # l. 7568-7572, verbatim
    assert [TABLE_9_5[k][0] for k in ("base", "upper_arm", "forearm", "finger_palm", "total")] == [
        115,
        295,
        280,
        186,
        856,
    ]
    assert [TABLE_9_5[k][1] for k in ("base", "upper_arm", "forearm", "finger_palm", "total")] == [
        2.38,
        1.82,
        1.16,
        0.57,
        5.93,
    ]


def test_table_9_5_masses_add_up():
    assert table_9_5_mass_sum_kg() == pytest.approx(TABLE_9_5["total"][1], abs=1e-12)


def test_table_9_5_printed_total_length_fails():
    """Erratum: the printed 全长 856 mm is not the sum of the printed parts, 876 mm."""
    assert 115 + 295 + 280 + 186 == 876
    assert table_9_5_length_sum_mm() == 876.0
    assert table_9_5_length_sum_mm() != TABLE_9_5["total"][0]


def test_model_mass_is_the_printed_total(robot):
    assert pin.computeTotalMass(robot.model) == pytest.approx(5.93, abs=1e-12)


def test_model_segment_lengths_are_the_printed_ones(robot):
    # distances between the joint origins (Pinocchio FK at q = 0): waist -> shoulder = base,
    # shoulder -> elbow = upper arm, elbow -> wrist centre = forearm, wrist centre -> grip =
    # finger-palm
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, robot.neutral())
    pin.updateFramePlacements(robot.model, data)
    o = [data.oMi[i].translation for i in range(1, robot.model.njoints)]
    tip = data.oMf[robot.tool_id].translation
    seg = [
        np.linalg.norm(o[1] - o[0]),
        np.linalg.norm(o[2] - o[1]),
        np.linalg.norm(o[4] - o[2]),
        np.linalg.norm(tip - o[4]),
    ]
    np.testing.assert_allclose(np.array(seg) * 1000, [115, 295, 280, 186], atol=1e-9)
    assert np.linalg.norm(o[0]) == 0.0


def test_closed_form_ik_round_trip(robot):
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = robot.random_q(None, rng, margin=0.05)
        res = aa.ik.analytic(robot, robot.fk(q))
        assert np.abs(res.solutions - q).max(1).min() < 1e-8
        for s in res.solutions:  # every returned branch reaches the pose (Pinocchio FK)
            assert np.abs(robot.fk(s) - robot.fk(q)).max() < 1e-9


def test_committed_urdf_is_the_generators():
    assert (REPO / "urdf" / "care_robot.urdf").read_text() == aa.models.urdf_text("care_robot")


def test_bad_lengths_are_typed_errors():
    with pytest.raises(ValueError, match="h2"):
        aa.models.spec("care_robot", h2=-0.1)
    with pytest.raises(ValueError, match="P"):
        aa.models.spec("care_robot", P=float("nan"))


# ---------------------------------------------------------------- cell table with pulses


def test_lattice_is_the_printed_10_cm(table):
    assert CELL_D == 0.10 and CELL_ACCURACY == 0.01
    assert table.D == 0.10
    # lattice points are integer multiples of 10 cm from the base origin
    k = table.origin / 0.10
    np.testing.assert_allclose(k, np.round(k), atol=1e-12)
    assert table.cell_ok.sum() >= 100


def test_pulses_are_round_q_times_scale(table):
    k = pulses_per_rad()
    assert k == pytest.approx(2000 * 200 / (2 * np.pi))
    v = table.valid
    assert table.pulses.dtype == np.int64
    assert np.abs(table.pulses[v] - table.Q[v] * k).max() <= 0.5
    assert (table.pulses[~v] == 0).all()


def test_lattice_points_reach_their_wrist_position(robot, table):
    """At a lattice point the stored pulses are the exact IK up to half a pulse: the wrist
    position error is far below the printed 1 cm (Pinocchio FK)."""
    idx = np.argwhere(table.valid)
    M = table.origin + table.D * idx
    q = table.pulses[table.valid] / table.pulses_per_rad
    err = np.abs(wrist(robot, q) - M).max()
    assert err < 1e-4
    R = robot.fk(q)[:, :3, :3]
    assert np.abs(R - table.rotation).max() < 1e-4


def test_table_branch_is_the_books_front_up_noflip(robot, table):
    """The stored branch is the book's shoulder front, elbow up, wrist no-flip: θ1 faces the
    wrist centre (Eq. (7-2): (cos θ1, sin θ1)·d > 0 for d the wrist centre above the shoulder),
    θ3 = asin k ∈ [−90°, 90°] (Eq. (7-6)) and θ5 ≥ 0 (Eq. (7-12): atan2 of a non-negative
    sine).  Oracle: the lattice points themselves and the printed lengths, not the IK labels."""
    idx = np.argwhere(table.valid)
    M = table.origin + table.D * idx
    q = table.Q[table.valid]
    d = M - np.array([0.0, 0.0, robot.spec.params["s0"]])
    assert (np.cos(q[:, 0]) * d[:, 0] + np.sin(q[:, 0]) * d[:, 1] > 0).all()
    assert (np.abs(q[:, 2]) <= np.pi / 2 + 1e-9).all()
    assert (q[:, 4] >= -1e-9).all()


def test_interpolated_wrist_within_the_printed_1_cm(robot, table):
    """The book's claim: 1 cm per axis with the 10 cm lattice.  On the assumed layout the
    claim holds for at least 90 % of random points of the covered cells and the median error
    is well inside it; the largest errors (near the reach boundary) exceed it."""
    rng = np.random.default_rng(0)
    lo, hi = table.bounds
    P = rng.uniform(lo, hi, (4000, 3))
    look = table.lookup_batch(P)
    assert look.ok.sum() > 1500
    err = np.abs(wrist(robot, look.q[look.ok]) - P[look.ok]).max(1)
    assert np.median(err) < CELL_ACCURACY
    assert (err <= CELL_ACCURACY).mean() >= 0.9
    assert err.max() < 3 * CELL_ACCURACY
    assert (
        err.max() > CELL_ACCURACY
    )  # ... but it is not a bound everywhere (docs/guide/book_systems.md)
    assert err.max() > 1e-3  # interpolation is not exact between lattice points


def test_lookup_pulses_equals_interpolated_q(robot, table):
    rng = np.random.default_rng(1)
    lo, hi = table.bounds
    n = 0
    for p in rng.uniform(lo, hi, (200, 3)):
        try:
            q = table.lookup(p)
        except OutsideCellTableError:
            continue
        pulses = table.lookup_pulses(p)
        assert pulses.dtype == np.int64
        # interpolating the rounded corner pulses differs from rounding the interpolated
        # angles by at most one pulse (the corners are each within half a pulse)
        assert np.abs(pulses - q * table.pulses_per_rad).max() <= 1.0
        n += 1
    assert n > 50


def test_relative_pulses_are_register_differences(table):
    a, b = np.array([0.3, 0.0, 0.1]), np.array([0.35, 0.12, 0.05])
    rel = table.relative_pulses(a, b)
    np.testing.assert_array_equal(rel, table.lookup_pulses(b) - table.lookup_pulses(a))
    np.testing.assert_array_equal(table.relative_pulses(a, a), np.zeros(6, np.int64))
    # between two lattice points: the difference of the stored ROM entries
    i, j = np.argwhere(table.valid)[:2]
    pa, pb = table.origin + table.D * i, table.origin + table.D * j
    np.testing.assert_array_equal(
        table.relative_pulses(pa, pb), table.pulses[tuple(j)] - table.pulses[tuple(i)]
    )


def test_one_newton_step_from_the_table(robot, table):
    p = np.array([0.32, 0.07, 0.13])
    q = table.refine(robot, p, table.pulses_to_q(table.lookup_pulses(p)), steps=2)
    assert np.abs(wrist(robot, q) - p).max() < 1e-4


def test_queries_outside_the_lattice_are_typed(table):
    with pytest.raises(OutsideCellTableError):
        table.lookup_pulses([5.0, 0.0, 0.0])
    with pytest.raises(OutsideCellTableError):
        table.relative_pulses([0.3, 0.0, 0.1], [0.3, 0.0, -3.0])
    with pytest.raises(ValueError, match="finite"):
        table.lookup_pulses([np.nan, 0.0, 0.0])


def test_bad_pulse_scales_are_typed(table):
    for bad in (0.0, -3.0, np.inf, [1.0, 2.0], "x"):
        with pytest.raises(ParameterError, match="pulses_per_rad"):
            table.with_pulses(bad)
    for bad in ((0, 200), (2000, np.nan), ("x", 200)):
        with pytest.raises(ParameterError, match="encoder_counts and gear_ratio"):
            pulses_per_rad(*bad)
    plain = CellTable(
        table.model, table.params, table.rotation, table.origin, table.D, table.Q, table.valid
    )
    with pytest.raises(ParameterError, match="no motor pulses"):
        plain.lookup_pulses([0.3, 0.0, 0.1])


def test_save_and_load_keep_pulses(table, tmp_path):
    back = CellTable.load(table.save(tmp_path / "care"))
    np.testing.assert_array_equal(back.pulses, table.pulses)
    np.testing.assert_array_equal(back.point, table.point)
    p = [0.31, 0.05, 0.12]
    np.testing.assert_array_equal(back.lookup_pulses(p), table.lookup_pulses(p))


# ---------------------------------------------------------------- Table 9.6


#: Table 9.6 as printed (l. 7625-7642; ../shared/book/notes/ch9-and-002.md), No. -> (display,
#: output)
TABLE_9_6_PRINT = {
    1: ("15", "请一会儿来"),
    2: ("25", "不是"),
    3: ("35", "是"),
    4: ("13", "请擦身"),
    5: ("23", "请梳头"),
    6: ("33", "请刷牙"),
    7: ("14", "您早"),
    8: ("24", "您好"),
    9: ("34", "晚上好"),
    10: ("5D", "是想吃什么吗?"),
    11: ("9D", "请让吃药"),
    12: ("BD", "请开窗"),
    13: ("ED", "请关窗"),
    14: ("57", "是想喝什么吗?"),
    15: ("B7", "请开门"),
    16: ("E7", "请关门"),
    17: ("5B", "对不起"),
    18: ("6B", "请开电视机"),
    19: ("DB", "请关电视机"),
    20: ("7B", "请开收音机"),
    21: ("9B", "请熄灯"),
    22: ("BB", "请拉开窗帘"),
    23: ("EB", "请关窗帘"),
    24: ("58", "请帮助"),
    25: ("68", "像是有点冷"),
    26: ("D8", "像是有点热"),
    27: ("78", "晚安"),
    28: ("98", "是想上厕所吗?"),
    29: ("B8", "请点灯"),
    30: ("E8", "请息灯"),
    31: ("5A", "请拿报纸来"),
    32: ("6A", "请拿书来"),
    33: ("DA", "请拿杂志来"),
    34: ("7A", "像是伤风了"),
    35: ("9A", "想要翻身吗?"),
    36: ("BA", "是否有点不舒服?"),
}


def test_table_9_6_is_the_print_row_by_row():
    rows = book_tables.melody_codes()
    assert {r.no: (r.display, r.output_zh) for r in rows} == TABLE_9_6_PRINT
    for no, (display, zh) in TABLE_9_6_PRINT.items():
        assert book_tables.melody_lookup(display.lower()).no == no


def test_table_9_6_rows():
    rows = book_tables.melody_codes()
    assert [r.no for r in rows] == list(range(1, 37))
    assert len({r.display for r in rows}) == 36  # display codes are unique
    assert all(len(r.display) == 2 and int(r.display, 16) >= 0 for r in rows)
    # spot checks against the print (l. 7627-7640)
    assert book_tables.melody_lookup("15").output_zh == "请一会儿来"
    assert book_tables.melody_lookup("5d").no == 10
    assert book_tables.melody_lookup("BA").output_zh == "是否有点不舒服?"
    # Nos. 21 and 30 say the same thing (熄灯 / 息灯: turn off the light)
    assert book_tables.melody_lookup("9B").output_en == book_tables.melody_lookup("E8").output_en
    assert book_tables.MELODY_CODES_3_NOTES == 104 and book_tables.MELODY_CODES_4_NOTES == 405


def test_table_9_6_unknown_code_is_typed():
    with pytest.raises(UnknownCodeError, match="5D"):
        book_tables.melody_lookup("FF")
    with pytest.raises(KeyError):
        book_tables.melody_lookup("")


def test_cell_table_of_another_robot_is_refused():
    """The table's wrist offset P and IK branch are the care robot's: a URDF-loaded copy (no
    parameter table) or another arm is a ParameterError, not a table built on a guessed P."""
    with pytest.raises(ParameterError, match="URDF"):
        cell_table(aa.load(str(REPO / "urdf" / "care_robot.urdf")))
    with pytest.raises(ParameterError, match="prosthetic_arm"):
        cell_table(aa.load("prosthetic_arm"))


def test_bad_table_parameters_and_pulse_vectors_are_typed(robot, table):
    for kw in (
        dict(D="x"),
        dict(D=np.nan),
        dict(rotation="abc"),
        dict(rotation=np.ones((3, 3))),
        dict(bounds=((0, 0, 0), (1, 1))),
        dict(D=1e-6),
    ):  # 2e17 lattice points: refused, not built
        with pytest.raises(ParameterError):
            cell_table(robot, **kw)
    for bad in ("abc", [1, 2], [np.nan] * 6):
        with pytest.raises(ParameterError, match="pulses must be"):
            table.pulses_to_q(bad)
    np.testing.assert_allclose(
        table.pulses_to_q(table.pulses[tuple(np.argwhere(table.valid)[0])]),
        table.Q[tuple(np.argwhere(table.valid)[0])],
        atol=0.5 / table.pulses_per_rad.min(),
    )
