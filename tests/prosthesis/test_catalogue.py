"""Motor and gearbox catalogues: the shipped example in SI units, and bad files as typed errors."""

import math

import pytest

from anthroarm.errors import CatalogueError
from anthroarm.prosthesis import catalogue as C


def test_shipped_catalogue_units_and_source():
    cat = C.load()
    re40 = next(m for m in cat.motors if m.name == "RE 40 24V")
    # the CSV row: 24 V, 0.299 ohm, 30.2 mNm/A, 142 g cm^2, 170 mNm, 12000 rpm, 480 g, 40 mm
    assert (re40.V_nom, re40.R) == (24.0, 0.299)
    assert re40.k_m == pytest.approx(0.0302, rel=1e-12)
    assert re40.J_m == pytest.approx(142e-7, rel=1e-12)  # 1 g cm^2 = 1e-7 kg m^2
    assert re40.tau_cont == pytest.approx(0.170, rel=1e-12)
    assert re40.max_speed == pytest.approx(12000 * 2 * math.pi / 60, rel=1e-12)
    assert (re40.mass, re40.diameter) == (pytest.approx(0.48), pytest.approx(0.04))
    gp = next(g for g in cat.gearboxes if g.name == "GP 42 C 156:1")
    assert gp.fits(re40) and not gp.fits(cat.motors[0])
    assert (gp.ratio, gp.efficiency, gp.tau_cont, gp.tau_max, gp.stages) == (
        156.0,
        0.64,
        15.0,
        22.5,
        4,
    )
    assert len(cat.combinations()) > 10
    note = C.source_note(cat.motor_source)
    assert "maxon" in note and "REPRESENTATIVE" in note
    # the motor as the servo model of Eq. (9-1): stall torque k_m V / R at the motor, x eta i at the joint
    dc = re40.dc_motor(gp)
    assert float(dc.stall_torque()) == pytest.approx(0.64 * 156 * 0.0302 * 24 / 0.299, rel=1e-12)


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


MOTOR_HEADER = ",".join(C.MOTOR_COLUMNS)
GEAR_HEADER = ",".join(C.GEARBOX_COLUMNS)
GOOD_MOTOR = "M1,X,20,24,1.0,20,10,30,10000,100"
GOOD_GEAR = "G1,X,20,2,20,0.8,2,3,8000,80"


@pytest.mark.parametrize(
    "text, line, column, words",
    [
        # a missing column
        ("name,series,diameter_mm\nM1,X,20\n", 1, "nominal_voltage_V", "missing column"),
        # a negative constant
        (
            f"{MOTOR_HEADER}\nM1,X,20,24,-1.0,20,10,30,10000,100\n",
            2,
            "terminal_resistance_ohm",
            "> 0",
        ),
        # zero torque constant
        (
            f"{MOTOR_HEADER}\n# comment\nM1,X,20,24,1.0,0,10,30,10000,100\n",
            3,
            "torque_constant_mNm_per_A",
            "> 0",
        ),
        # not a number
        (
            f"{MOTOR_HEADER}\nM1,X,20,24,1.0,abc,10,30,10000,100\n",
            2,
            "torque_constant_mNm_per_A",
            "not a number",
        ),
        (
            f"{MOTOR_HEADER}\nM1,X,20,24,1.0,nan,10,30,10000,100\n",
            2,
            "torque_constant_mNm_per_A",
            "not finite",
        ),
        # beyond any data sheet (a typo): 1e300 g cm^2
        (
            f"{MOTOR_HEADER}\nM1,X,20,24,1.0,20,1e300,30,10000,100\n",
            2,
            "rotor_inertia_gcm2",
            "typo",
        ),
        # duplicate name
        (f"{MOTOR_HEADER}\n{GOOD_MOTOR}\n{GOOD_MOTOR}\n", 3, "name", "duplicate"),
        # a short row
        (f"{MOTOR_HEADER}\nM1,X,20\n", 2, None, "fields"),
        # no rows
        (f"# only a header\n{MOTOR_HEADER}\n", None, None, "no rows"),
    ],
)
def test_bad_motor_files(tmp_path, text, line, column, words):
    p = _write(tmp_path, "motors.csv", text)
    with pytest.raises(CatalogueError, match=words) as ei:
        C.load_motors(p)
    assert ei.value.path == str(p)
    assert ei.value.line == line
    assert ei.value.column == column
    assert isinstance(ei.value, ValueError)


@pytest.mark.parametrize(
    "row, column, words",
    [
        ("G1,X,20,2,20,1.2,2,3,8000,80", "efficiency", "<= 1"),
        ("G1,X,20,2,20,0.8,2,1,8000,80", "max_intermittent_torque_Nm", "below"),
        ("G1,X,20;x,2,20,0.8,2,3,8000,80", "motor_diameters_mm", "list"),
        ("G1,X,20,2.5,20,0.8,2,3,8000,80", "stages", "whole"),
        ("G1,X,20,2,-20,0.8,2,3,8000,80", "ratio", "> 0"),
        ("G1,X,20,2,1e300,0.8,2,3,8000,80", "ratio", "typo"),  # would overflow the sizing
        ("G1,X,20;1e9,2,20,0.8,2,3,8000,80", "motor_diameters_mm", "> 0 mm"),
    ],
)
def test_bad_gearbox_files(tmp_path, row, column, words):
    p = _write(tmp_path, "gearboxes.csv", f"{GEAR_HEADER}\n{row}\n")
    with pytest.raises(CatalogueError, match=words) as ei:
        C.load_gearboxes(p)
    assert (ei.value.line, ei.value.column) == (2, column)


def test_missing_file_and_no_mounting_pair(tmp_path):
    with pytest.raises(CatalogueError, match="not found"):
        C.load_motors(tmp_path / "nope.csv")
    m = _write(tmp_path, "m.csv", f"{MOTOR_HEADER}\n{GOOD_MOTOR}\n")
    g = _write(tmp_path, "g.csv", f"{GEAR_HEADER}\nG1,X,30,2,20,0.8,2,3,8000,80\n")
    with pytest.raises(CatalogueError, match="mounts"):
        C.load(m, g)
    g2 = _write(tmp_path, "g2.csv", f"{GEAR_HEADER}\n{GOOD_GEAR}\n")
    assert len(C.load(m, g2).combinations()) == 1


def test_a_spreadsheet_bom_is_read(tmp_path):
    m = tmp_path / "m.csv"
    m.write_bytes(("\ufeff" + f"{MOTOR_HEADER}\n{GOOD_MOTOR}\n").encode("utf-8"))
    (motor,) = C.load_motors(m)
    assert motor.name == "M1" and motor.k_m == pytest.approx(0.020)
    bad = tmp_path / "bin.csv"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(CatalogueError, match="UTF-8"):
        C.load_motors(bad)
