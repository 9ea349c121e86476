"""Public entry points raise typed errors from :mod:`anthroarm.errors` (never a bare ValueError,
TypeError or a numpy error) whose message names the parameter, joint or path at fault.

Covers ``Robot.check_q`` (and ``jacobian(reference=)``, ``load()``), the ``human_arm7`` builder
(``segment_parameters``), the book builders' length/stroke checks (``models/book.py``), the
validators of ``mechanisms/_util`` and ``_io.atomic_write_text``.  The new classes subclass
ValueError (ParameterError also TypeError), so old ``except ValueError`` callers keep working.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import anthroarm as aa
from anthroarm._io import atomic_write_text
from anthroarm.errors import AnthroarmError, AnthropometryError, ParameterError
from anthroarm.mechanisms import _util
from anthroarm.models.human import segment_parameters

NAN, INF = float("nan"), float("inf")


@pytest.fixture(scope="module")
def arm():
    return aa.load("human_arm7")


# --------------------------------------------------------------------------- Robot.check_q


@pytest.mark.parametrize(
    "q, words",
    [
        ([NAN] * 7, ["q[0]", "shoulder_flexion", "nan", "finite"]),
        ([0.0] * 3 + [INF] + [0.0] * 3, ["q[3]", "elbow_flexion", "inf"]),
        (np.zeros(3), ["shape (7,)", "(3,)", "shoulder_flexion"]),
        (np.zeros((2, 2, 7)), ["shape (7,)", "(2, 2, 7)"]),
        (None, ["q is None", "7 joint values"]),
        ("a", ["q must be real numbers", "shoulder_flexion"]),
        (["0.1"] * 7, ["q must be real numbers"]),  # numpy would parse the strings
        ([None] * 7, ["q must be real numbers"]),  # numpy would turn None into NaN
        ([0.0] * 6 + ["x"], ["q must be real numbers"]),
        (1 + 2j, ["q must be real numbers"]),
        (object(), ["q must be real numbers"]),
    ],
)
def test_check_q_rejects_hostile_q_with_a_typed_error(arm, q, words):
    with pytest.raises(ParameterError) as e:
        arm.check_q(q)
    assert isinstance(e.value, ValueError) and isinstance(e.value, AnthroarmError)
    msg = str(e.value)
    assert msg.startswith("human_arm7:")
    for w in words:
        assert w in msg, (w, msg)


def test_check_q_batch_row_and_custom_name(arm):
    q = np.zeros((3, 7))
    q[2, 5] = NAN
    with pytest.raises(
        ParameterError, match=r"q_start\[5\] for joint 'wrist_deviation' is nan \(row 2\)"
    ):
        arm.check_q(q, "q_start")


def test_check_q_still_a_value_error_for_old_callers(arm):
    with pytest.raises(ValueError, match="shoulder_flexion"):
        arm.check_q([NAN] * 7)
    assert arm.check_q(np.zeros(7)).shape == (7,)
    assert arm.check_q([[0.1] * 7] * 2).shape == (2, 7)


def test_public_calls_through_check_q_raise_typed(arm):
    with pytest.raises(ParameterError, match="elbow_flexion"):
        arm.fk([0, 0, 0, NAN, 0, 0, 0])
    with pytest.raises(ParameterError, match="shape"):
        arm.jacobian(np.zeros(5))


def test_jacobian_reference_is_a_parameter_error(arm):
    with pytest.raises(
        ParameterError, match="reference must be one of LOCAL, WORLD, LOCAL_WORLD_ALIGNED"
    ):
        arm.jacobian(arm.neutral(), reference="world")
    with pytest.raises(ParameterError, match="reference"):
        arm.jacobian(arm.neutral(), reference=["WORLD"])  # unhashable: no bare TypeError


def test_load_with_a_bad_source_type_is_a_parameter_error():
    with pytest.raises(ParameterError, match="load"):
        aa.load(3.5)


# --------------------------------------------------------------------------- human_arm7


@pytest.mark.parametrize(
    "kw, name",
    [
        ({"height": NAN}, "height"),
        ({"height": INF}, "height"),
        ({"height": -1.0}, "height"),
        ({"height": 17.5}, "height"),
        ({"height": "1.75"}, "height"),
        ({"height": None}, "height"),
        ({"height": True}, "height"),
        ({"mass": NAN}, "mass"),
        ({"mass": -5}, "mass"),
        ({"mass": "75"}, "mass"),
        ({"mass": 1e6}, "mass"),
    ],
)
def test_human_arm7_body_measurements_raise_anthropometry_error(kw, name):
    for call in (
        lambda: aa.load("human_arm7", **kw),
        lambda: aa.models.spec("human_arm7", **kw),
        lambda: segment_parameters(**kw),
    ):
        with pytest.raises(AnthropometryError) as e:
            call()
        assert e.value.name == name
        v = kw[name]
        assert e.value.value is v or (
            isinstance(v, float) and math.isnan(v) and math.isnan(e.value.value)
        )
        assert name in str(e.value)
        assert isinstance(e.value, ValueError)


def test_human_arm7_range_is_in_the_message():
    with pytest.raises(AnthropometryError, match=r"0\.5…2\.6 m"):
        aa.load("human_arm7", height=-1)
    with pytest.raises(AnthropometryError, match=r"10…300 kg"):
        aa.load("human_arm7", mass=NAN)


@pytest.mark.parametrize("sex", ["x", None, 1, "Male"])
def test_human_arm7_sex_lists_the_choices(sex):
    with pytest.raises(ParameterError) as e:
        aa.load("human_arm7", sex=sex)
    assert "sex" in str(e.value) and "'male' or 'female'" in str(e.value)
    with pytest.raises(ParameterError, match="'male' or 'female'"):
        segment_parameters(sex=sex)


# --------------------------------------------------------------------------- models/book.py


@pytest.mark.parametrize("value", [-1, -0.1, NAN, INF, "0.3", None, [1, 2], True, b"1"])
def test_book_lengths_raise_parameter_error_naming_the_length(value):
    with pytest.raises(ParameterError) as e:
        aa.models.spec("care_robot", s0=value)
    msg = str(e.value)
    assert "s0 must be a finite length >= 0 (m)" in msg
    assert isinstance(e.value, ValueError)


@pytest.mark.parametrize(
    "model, name",
    [
        ("prosthetic_arm", "L1"),
        ("sixr_arm", "P"),
        ("unimate5", "h2"),
        ("rrprr5", "p"),
        ("planar2r", "l2"),
    ],
)
def test_every_book_builder_names_its_length(model, name):
    with pytest.raises(ParameterError, match=f"{model}: {name} must be a finite length"):
        aa.models.spec(model, **{name: -1.0})


@pytest.mark.parametrize("stroke", ["ab", None, 3.0, (1.0, NAN), (0.5, 0.2), (1, 2, 3)])
def test_book_strokes_raise_parameter_error(stroke):
    with pytest.raises(ParameterError, match="boom"):
        aa.models.spec("unimate5", boom=stroke)


def test_book_defaults_still_build():
    assert aa.models.spec("care_robot", s0=0.0) is not None
    assert aa.models.spec("unimate5", boom=(0.2, 0.8)) is not None


# --------------------------------------------------------------------------- mechanisms/_util


@pytest.mark.parametrize(
    "x, words",
    [
        (None, ["p must be a real array", "(3,)", "None"]),
        ("abc", ["p must be a real array"]),
        (["1", "2", "3"], ["p must be a real array"]),  # numpy would parse the strings
        ([1.0, None, 2.0], ["p must be a real array"]),  # numpy would turn None into NaN
        (np.array(["1", "2", "3"]), ["p must be a real array"]),
        (object(), ["p must be a real array"]),
        (1 + 2j, ["p must be a real array"]),
        ([[1.0], [1.0, 2.0]], ["p must be a real array"]),  # ragged
        ([1.0, NAN, 0.0], ["p must be finite"]),
        ([1.0, 2.0, INF], ["p must be finite"]),
        ([1.0, 2.0], ["p must have shape (3,)", "(2,)"]),
        ([[1.0, 2.0, 3.0]], ["p must have shape (3,)", "(1, 3)"]),
    ],
)
def test_finite_array_raises_parameter_error_naming_the_parameter(x, words):
    with pytest.raises(ParameterError) as e:
        _util.finite_array("p", x, (3,))
    assert isinstance(e.value, ValueError) and isinstance(e.value, TypeError)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_finite_array_accepts_real_arrays():
    np.testing.assert_array_equal(_util.finite_array("p", [1, 2, 3], (3,)), [1.0, 2.0, 3.0])
    assert _util.finite_array("p", np.zeros((4, 3)), (None, 3)).shape == (4, 3)
    assert _util.finite_array("p", 2.5).shape == ()


@pytest.mark.parametrize(
    "fn, x, words",
    [
        (_util.finite_scalar, None, ["L must be a finite real number", "None"]),
        (_util.finite_scalar, "1.0", ["L must be a finite real number"]),
        (_util.finite_scalar, NAN, ["L must be finite"]),
        (_util.finite_scalar, [1.0, 2.0], ["L must be a scalar"]),
        (_util.positive_length, -1.0, ["L must be a positive length"]),
        (_util.positive_length, 0.0, ["L must be a positive length"]),
        (_util.positive_length, INF, ["L must be finite"]),
        (_util.unit_axis, [0.0, 0.0, 2.0], ["L", "unit"]),
        (_util.unit_axis, [0.0, 0.0, 0.0], ["L"]),
    ],
)
def test_scalar_and_axis_validators_raise_parameter_error(fn, x, words):
    with pytest.raises(ParameterError) as e:
        fn("L", x)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_float_range_helpers_raise_parameter_error():
    with pytest.raises(ParameterError, match="beyond the float range"):
        _util.pow2_scale([INF, 1.0])
    with pytest.raises(ParameterError, match="^v is beyond the float range"):
        _util.norm("v", [INF, 1.0])
    with pytest.raises(ParameterError, match="^d cannot be represented"):
        _util.difference("d", [1e308], [-1e308])


def test_a_public_mechanism_call_raises_parameter_error():
    from anthroarm.mechanisms import fourbar

    with pytest.raises(ParameterError, match="theta2 must be finite"):
        fourbar(0.1, 0.03, 0.1, 0.08, NAN)
    with pytest.raises(ParameterError, match="theta2 must be a real array"):
        fourbar(0.1, 0.03, 0.1, 0.08, "0.5")
    with pytest.raises(ValueError, match="theta2"):  # old callers
        fourbar(0.1, 0.03, 0.1, 0.08, None)


# --------------------------------------------------------------------------- _io.atomic_write_text


def test_atomic_write_to_a_folder_keeps_oserror_semantics_with_an_actionable_message(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(IsADirectoryError) as e:
        atomic_write_text(folder, "x")
    assert e.value.filename == str(folder)
    assert "is a folder" in e.value.strerror and "give a file name" in e.value.strerror
    assert str(folder / "NAME") in e.value.strerror
    assert folder.is_dir() and list(folder.iterdir()) == []


def test_atomic_write_folder_is_one_line_in_the_cli_mapping(tmp_path):
    # cli.main maps OSError to "<filename>: <strerror>": both parts must say what to do
    folder = tmp_path / "out"
    folder.mkdir()
    with pytest.raises(OSError) as e:
        atomic_write_text(str(folder), b"x")
    line = f"{e.value.filename}: {e.value.strerror}"
    assert "\n" not in line and str(folder) in line and "file name" in line


@pytest.mark.parametrize("text", [None, 5, 1.5, ["a"], {"a": 1}])
def test_atomic_write_text_rejects_non_text(tmp_path, text):
    target = tmp_path / "f.txt"
    with pytest.raises(ParameterError, match="text must be str or bytes") as e:
        atomic_write_text(target, text)
    assert str(target) in str(e.value)
    assert not target.exists()  # bytes(5) used to write five NUL bytes


@pytest.mark.parametrize("path", [None, 3, "", ["a"]])
def test_atomic_write_text_rejects_a_non_path(path):
    with pytest.raises(ParameterError, match="path must be a file path"):
        atomic_write_text(path, "x")


def test_atomic_write_text_still_writes(tmp_path):
    atomic_write_text(tmp_path / "a.txt", "hé")
    atomic_write_text(str(tmp_path / "b.bin"), bytearray(b"\x00\x01"))
    assert (tmp_path / "a.txt").read_text(encoding="utf-8") == "hé"
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
