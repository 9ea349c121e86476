"""Bad OpenSim models (issue 32, "Bad input"): each one a typed error naming the element at fault
and its line in the file — never a wrong model, a hang or a bare exception.

Every case edits the shipped arm26.osim (or leg6dof9musc.osim for couplers) at one place; the
line expected in the error is found in the edited text by the test itself.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.errors import OsimError, OsimSecurityError, OsimStrictError, OsimUnsupportedError
from anthroarm.osim import path
from anthroarm.osim.checks import OpenSimModel

ARM = path("arm26").read_text(encoding="utf-8")
LEG = path("leg6dof9musc").read_text(encoding="utf-8")


def edit(tmp_path, text: str, old: str, new: str, count: int = 1, name: str = "bad.osim"):
    """Write ``text`` with ``old`` replaced by ``new`` (it must occur); return the file and the
    line where ``new`` starts."""
    assert old in text, old
    out = text.replace(old, new, count)
    line = out[: out.index(new)].count("\n") + 1 if new else None
    p = tmp_path / name
    p.write_text(out, encoding="utf-8")
    return p, line


def load_error(p, cls=OsimError):
    with pytest.raises(cls) as info:
        aa.load(p)
    return info.value


def assert_names(e, element: str, line):
    assert isinstance(e, OsimError)
    assert element in str(e), str(e)
    if line is not None:
        assert e.line == line, (e.line, line, str(e))
        assert f"line {line}" in str(e)


def test_malformed_xml(tmp_path):
    p, line = edit(tmp_path, ARM, "<mass>1.8645719999999999</mass>", "<mass>1.86</mas>")
    e = load_error(p)
    assert "malformed XML" in str(e) and e.line == line


@pytest.mark.parametrize(
    "decl",
    [
        '<!DOCTYPE m [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>',
        '<!DOCTYPE m [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>',
        '<!DOCTYPE m SYSTEM "http://example.com/evil.dtd">',
    ],
)
def test_entity_attacks_refused(tmp_path, decl):
    p, line = edit(
        tmp_path,
        ARM,
        '<OpenSimDocument Version="40000">',
        decl + '\n<OpenSimDocument Version="40000">',
    )
    e = load_error(p, OsimSecurityError)
    assert "entity" in str(e).lower() and e.line == line


def test_not_an_opensim_document(tmp_path):
    p = tmp_path / "robot.osim"
    p.write_text('<?xml version="1.0"?>\n<robot name="x"/>\n')
    e = load_error(p)
    assert "<robot>" in str(e) and e.line == 2


def test_opensim_3_model_without_opensim_names_the_remedy(tmp_path):
    """Without the opensim package (made unimportable in a subprocess) a 3.x model is an
    OsimUnsupportedError naming the remedy; with it, OpenSim's updater reads it
    (tests/osim/test_joints_functions.py)."""
    p, _ = edit(tmp_path, ARM, 'Version="40000"', 'Version="30000"')
    code = (
        "import sys; sys.modules['opensim'] = None\n"
        "import anthroarm as aa\n"
        "from anthroarm.errors import OsimUnsupportedError\n"
        f"try:\n    aa.load({str(p)!r})\n"
        "except OsimUnsupportedError as e:\n    print('ERR', e.line, e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.startswith("ERR 1 "), out.stdout + out.stderr
    assert "3.x" in out.stdout and "OpenSim 4" in out.stdout and "printToXML" in out.stdout


def test_missing_file_folder_and_device(tmp_path):
    (tmp_path / "folder.osim").mkdir()
    for p in (tmp_path / "none.osim", tmp_path / "folder.osim"):
        e = load_error(p)
        assert str(p) in str(e)
    if os.path.exists("/dev/zero"):
        from anthroarm.osim import load_osim

        with pytest.raises(OsimError, match="device"):
            load_osim("/dev/zero")


def test_unknown_joint_type(tmp_path):
    i = ARM.index('<CustomJoint name="r_elbow">')
    j = ARM.index("</CustomJoint>", i)
    out = (
        ARM[:i] + '<HingeJoint name="r_elbow">' + ARM[i + 27 : j] + "</HingeJoint>" + ARM[j + 14 :]
    )
    p = tmp_path / "bad.osim"
    p.write_text(out)
    e = load_error(p)
    assert_names(e, "HingeJoint name='r_elbow'", ARM[:i].count("\n") + 1)
    assert "unknown joint type" in str(e)


def test_quaternion_joint_names_the_remedy(tmp_path):
    p, line = edit(tmp_path, ARM, '<WeldJoint name="offset">', '<FreeJoint name="offset">')
    p.write_text(p.read_text().replace("</WeldJoint>", "</FreeJoint>"))
    e = load_error(p, OsimUnsupportedError)
    assert_names(e, "FreeJoint name='offset'", line)
    assert "CustomJoint" in str(e)


FUNC = """<LinearFunction name="function">
								<coefficients> 1 0</coefficients>
							</LinearFunction>"""


def elbow_function(tmp_path, new: str):
    """arm26 with the elbow's rotation1 function replaced by ``new``."""
    i = ARM.index('<CustomJoint name="r_elbow">')
    j = ARM.index(FUNC, i)
    out = ARM[:j] + new + ARM[j + len(FUNC) :]
    p = tmp_path / "bad.osim"
    p.write_text(out)
    return p, out[:j].count("\n") + 1


def test_unknown_function_type(tmp_path):
    p, line = elbow_function(
        tmp_path, '<WavyFunction name="function"><value>1</value></WavyFunction>'
    )
    e = load_error(p)
    assert_names(e, "<WavyFunction>", line)
    assert "unknown function type" in str(e) and "r_elbow" in str(e)


def test_function_not_evaluated_names_it(tmp_path):
    p, line = elbow_function(
        tmp_path, '<GCVSpline name="function"><x>0 1 2</x><y>0 1 2</y></GCVSpline>'
    )
    e = load_error(p, OsimUnsupportedError)
    assert_names(e, "<GCVSpline>", line)


@pytest.mark.parametrize(
    "x, y, problem",
    [
        ("0 1 1 2", "0 1 2 3", "not increasing"),
        ("0 2 1 3", "0 1 2 3", "not increasing"),
        ("0.5", "1", "1 knot"),
        ("0 1 2", "0 1", "3 x values but 2 y values"),
        ("0 nan 2", "0 1 2", "non-finite"),
        ("0 a 2", "0 1 2", "not numbers"),
    ],
)
def test_bad_splines(tmp_path, x, y, problem):
    p, line = elbow_function(
        tmp_path, f'<SimmSpline name="function"><x>{x}</x><y>{y}</y></SimmSpline>'
    )
    e = load_error(p)
    assert "<SimmSpline>" in str(e) and problem in str(e), str(e)
    assert e.line == line


def test_function_of_a_coordinate_that_does_not_exist(tmp_path):
    p, line = edit(
        tmp_path,
        ARM,
        "<coordinates>r_elbow_flex</coordinates>",
        "<coordinates>r_elbow_flexion</coordinates>",
    )
    e = load_error(p)
    text = p.read_text()
    axis_line = (
        text.count("\n", 0, text.rindex("<TransformAxis", 0, text.index("r_elbow_flexion"))) + 1
    )
    assert_names(e, "TransformAxis name='rotation1'", axis_line)
    assert line == axis_line + 2


COUPLER = "<independent_coordinate_names>knee_angle_r</independent_coordinate_names>"


def test_coupler_of_a_coordinate_that_does_not_exist(tmp_path):
    p, _ = edit(tmp_path, LEG, COUPLER, COUPLER.replace("knee_angle_r", "knee_angel_r"))
    e = load_error(p)
    line = (
        p.read_text().count(
            "\n", 0, p.read_text().index('<CoordinateCouplerConstraint name="pat_angle_r">')
        )
        + 1
    )
    assert_names(e, "CoordinateCouplerConstraint name='pat_angle_r'", line)
    assert "'knee_angel_r'" in str(e)


def test_couplings_in_a_cycle(tmp_path):
    i = LEG.index('<CoordinateCouplerConstraint name="pat_angle_r">')
    j = LEG.index("</CoordinateCouplerConstraint>", i) + len("</CoordinateCouplerConstraint>")
    block = LEG[i:j]
    back = (
        block.replace('name="pat_angle_r"', 'name="back"')
        .replace(
            COUPLER, "<independent_coordinate_names>knee_angle_pat_r</independent_coordinate_names>"
        )
        .replace(
            "<dependent_coordinate_name>knee_angle_pat_r</dependent_coordinate_name>",
            "<dependent_coordinate_name>knee_angle_r</dependent_coordinate_name>",
        )
    )
    p, _ = edit(tmp_path, LEG, block, block + "\n\t\t\t\t" + back)
    e = load_error(p)
    assert "circle" in str(e) and "knee_angle_r" in str(e) and "knee_angle_pat_r" in str(e)
    assert e.line is not None


def test_negative_mass(tmp_path):
    p, line = edit(tmp_path, ARM, "<mass>1.8645719999999999</mass>", "<mass>-1.86</mass>")
    e = load_error(p)
    assert_names(e, "Body name='r_humerus'", line)
    assert "negative mass" in str(e)


def test_inertia_not_positive_semidefinite(tmp_path):
    i = ARM.index('<Body name="r_humerus">')
    old = ARM[ARM.index("<inertia>", i) : ARM.index("</inertia>", i) + len("</inertia>")]
    p, line = edit(tmp_path, ARM, old, "<inertia>0.01 0.01 0.01 0.02 0 0</inertia>")
    e = load_error(p)
    assert_names(e, "Body name='r_humerus'", line)
    assert "semi-definite" in str(e)


def test_reference_to_a_missing_body(tmp_path):
    p, line = edit(
        tmp_path,
        ARM,
        "<socket_parent>/bodyset/r_humerus</socket_parent>",
        "<socket_parent>/bodyset/r_humerous</socket_parent>",
    )
    e = load_error(p)
    assert "'/bodyset/r_humerous'" in str(e) and "PhysicalOffsetFrame" in str(e)
    text = p.read_text()
    at = text.index("/bodyset/r_humerous")
    assert e.line == text.count("\n", 0, text.rindex("<PhysicalOffsetFrame", 0, at)) + 1 < line


def test_reference_to_a_missing_frame(tmp_path):
    p, _ = edit(
        tmp_path,
        ARM,
        "<socket_child_frame>r_ulna_radius_hand_offset</socket_child_frame>",
        "<socket_child_frame>r_hand_offset</socket_child_frame>",
    )
    e = load_error(p)
    line = p.read_text().count("\n", 0, p.read_text().index('<CustomJoint name="r_elbow">')) + 1
    assert_names(e, "CustomJoint name='r_elbow'", line)
    assert "'r_hand_offset'" in str(e)


def test_marker_on_a_missing_body(tmp_path):
    i = ARM.index('<Marker name="r_acromion">')
    out = ARM[:i] + ARM[i:].replace("/bodyset/base<", "/bodyset/bass<", 1)
    p = tmp_path / "bad.osim"
    p.write_text(out)
    e = load_error(p)
    assert_names(e, "Marker name='r_acromion'", ARM[:i].count("\n") + 1)
    assert "'/bodyset/bass'" in str(e)


def test_two_joints_to_one_body_is_a_loop(tmp_path):
    p, _ = edit(
        tmp_path,
        ARM,
        "<socket_child_frame>r_ulna_radius_hand_offset</socket_child_frame>",
        "<socket_child_frame>r_humerus_offset</socket_child_frame>",
    )
    out = p.read_text()
    i = out.index('<CustomJoint name="r_elbow">')
    j = out.index('<PhysicalOffsetFrame name="r_ulna_radius_hand_offset">', i)
    out = out[:j] + out[j:].replace(
        'name="r_ulna_radius_hand_offset"', 'name="r_humerus_offset"', 1
    )
    p.write_text(out)
    e = load_error(p)
    assert "closed loop" in str(e) or "defined twice" in str(e)
    assert e.line is not None


def test_collinear_axes(tmp_path):
    p, _ = edit(
        tmp_path,
        ARM,
        "<axis>0.99826135999999999 -0 0.058898020000000002</axis>",
        "<axis>-0.058898020000000002 0.0023 0.99826135999999999</axis>",
    )
    e = load_error(p)
    assert "collinear" in str(e) and "r_shoulder" in str(e)


def test_strict_turns_drops_into_an_error():
    with pytest.raises(OsimStrictError) as info:
        aa.load(path("Tug_of_War"), strict=True)
    assert "dropped" in str(info.value) and info.value.line is not None
    robot = aa.load(path("Tug_of_War"))
    assert robot.report.dropped and not robot.report.approximated
    assert np.isfinite(robot.fk(robot.neutral())).all()


def test_bad_configuration_is_a_parameter_error():
    robot = aa.load(path("gait2392"))
    for bad in (np.zeros(5), np.full(robot.nq, np.nan), "x", None):
        with pytest.raises(aa.errors.ParameterError):
            robot.fk(bad)


def test_marker_with_a_body_name(tmp_path):
    p, line = edit(tmp_path, ARM, '<Marker name="r_acromion">', '<Marker name="r_humerus">')
    e = load_error(p, OsimUnsupportedError)
    assert_names(e, "Marker name='r_humerus'", line)
    assert "name of a body" in str(e)


def test_coordinate_with_a_body_name_keeps_both(tmp_path):
    """A coordinate named like a body: the joint keeps the coordinate's name, the body frame
    its own, the joint frame becomes ``<name>_joint`` (a frame lookup never finds the wrong
    one)."""
    out = ARM.replace("r_elbow_flex", "r_ulna_radius_hand")
    p = tmp_path / "renamed.osim"
    p.write_text(out)
    robot = aa.load(p)
    ref = aa.load(path("arm26"))
    assert robot.joint_names == ["r_shoulder_elev", "r_ulna_radius_hand"]
    q = ref.random_q(None, 0)
    assert np.abs(robot.fk(q, "r_ulna_radius_hand") - ref.fk(q, "r_ulna_radius_hand")).max() == 0
    assert "r_ulna_radius_hand_joint" in robot.frame_names
    assert robot.chain.frame("r_ulna_radius_hand").is_body  # the body, not the joint's frame


def test_opensim_model_with_an_unknown_coordinate():
    """OpenSim's side of the checks (:class:`anthroarm.osim.checks.OpenSimModel`) given a
    coordinate the model does not have: an OsimError naming it, not a KeyError later."""
    pytest.importorskip("opensim")
    with pytest.raises(OsimError, match="not_a_coordinate"):
        OpenSimModel(path("arm26"), ["r_shoulder_elev", "not_a_coordinate"])
