"""OpenSim ``.mot`` / ``.sto`` storage files and ``Setup_IK.xml``: anthroarm's readers and
``.mot`` writer against OpenSim's own ``Storage``, ``TimeSeriesTable`` and
``InverseKinematicsTool`` (the oracles), and bad input."""

import numpy as np
import pytest
from osim_recordings_data import PUBLISHED_IK, SETUP

from anthroarm.errors import MotionDataError
from anthroarm.motion import read_ik_setup, read_storage, write_mot


def opensim_table(osim, path):
    """(labels, time, values, inDegrees) read by OpenSim's TimeSeriesTable."""
    table = osim.TimeSeriesTable(str(path))
    mat = table.getMatrix()
    values = mat.to_numpy().copy()
    deg = (
        table.getTableMetaDataAsString("inDegrees")
        if table.hasTableMetaDataKey("inDegrees")
        else None
    )
    return tuple(table.getColumnLabels()), np.array(table.getIndependentColumn()), values, deg


def test_published_motion_equals_opensim(osim):
    table = read_storage(PUBLISHED_IK)
    labels, time, values, deg = opensim_table(osim, PUBLISHED_IK)
    assert table.labels == labels and len(labels) == 23 and table.in_degrees and deg == "yes"
    np.testing.assert_array_equal(table.time, time)
    np.testing.assert_array_equal(table.values, values)
    st = osim.Storage(str(PUBLISHED_IK))
    assert st.getSize() == len(table) == 73 and st.isInDegrees()


def test_written_motion_is_read_by_opensim(osim, tmp_path):
    rng = np.random.default_rng(3)
    t = np.arange(30) / 60.0
    V = rng.normal(size=(30, 4))
    labels = ["hip_flexion_r", "knee_angle_r", "pelvis_tx", "ankle_angle_r"]
    angles = ["hip_flexion_r", "knee_angle_r", "ankle_angle_r"]
    out = write_mot(tmp_path / "q.mot", t, V, labels, angles=angles)
    got_labels, got_t, got_V, deg = opensim_table(osim, out)
    assert got_labels == tuple(labels) and deg == "yes"
    np.testing.assert_array_equal(got_t, t)
    want = V.copy()
    want[:, [0, 1, 3]] = np.rad2deg(want[:, [0, 1, 3]])
    np.testing.assert_allclose(got_V, want, rtol=1e-15, atol=0)
    st = osim.Storage(str(out))
    assert st.isInDegrees() and st.getSize() == 30 and st.getColumnLabels().getSize() == 5
    back = read_storage(out)
    np.testing.assert_allclose(back.si(angles), V, rtol=1e-14, atol=0)
    rad = write_mot(tmp_path / "r.mot", t, V, labels, angles=angles, in_degrees=False)
    assert opensim_table(osim, rad)[3] == "no"
    np.testing.assert_allclose(read_storage(rad).values, V, rtol=0, atol=0)


def _lines():
    return PUBLISHED_IK.read_text().split("\n")


def _cell(line, k, value):
    cells = line.split("\t")
    cells[k] = value
    return "\t".join(cells)


# the header of the published file is 10 lines (line 10 'endheader'), labels on line 11
BAD = {
    "no endheader": (lambda L: [s for s in L if s.strip() != "endheader"], "no 'endheader'"),
    "inDegrees": (lambda L: [s.replace("inDegrees=yes", "inDegrees=maybe") for s in L], "line 5"),
    "nColumns": (
        lambda L: [s.replace("nColumns=24", "nColumns=25") for s in L],
        "line 4: nColumns",
    ),
    "nRows": (lambda L: L[:-5], "line 3: nRows is 73, the file holds 69 rows"),
    "no time": (lambda L: [*L[:10], L[10].replace("time", "tijd"), *L[11:]], "line 11"),
    "ragged": (lambda L: [*L[:15], L[15].rsplit("\t", 2)[0], *L[16:]], "line 16: 22 cells"),
    "text": (lambda L: [*L[:15], _cell(L[15], 3, "abc"), *L[16:]], "line 16: column"),
    "inf": (lambda L: [*L[:15], _cell(L[15], 3, "inf"), *L[16:]], "line 16: column"),
    "backwards": (lambda L: [*L[:15], _cell(L[15], 0, "0.1"), *L[16:]], "line 16: time"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_storage_names_the_line(tmp_path, case):
    damage, text = BAD[case]
    p = tmp_path / "bad.mot"
    p.write_text("\n".join(damage(_lines())))
    with pytest.raises(MotionDataError) as err:
        read_storage(p)
    assert text in str(err.value), str(err.value)


def test_storage_partial_and_write_checks(tmp_path):
    p = tmp_path / "short.mot"
    p.write_text("\n".join(_lines()[:-5]))
    assert read_storage(p, partial=True).status == "truncated"
    with pytest.raises(MotionDataError, match="labels must be unique"):
        write_mot(tmp_path / "x.mot", [0.0], [[1.0, 2.0]], ["a", "a"])
    for bad in (np.inf, np.nan):  # OpenSim's Storage stops reading at a row with nan
        with pytest.raises(MotionDataError, match="row 1 is not"):
            write_mot(tmp_path / "x.mot", [0.0, 0.1], [[1.0], [bad]], ["a"])


def test_setup_equals_opensims_reading(osim):
    setup = read_ik_setup(SETUP)
    tool = osim.InverseKinematicsTool(str(SETUP))
    tasks = tool.getIKTaskSet()
    marker_w, coord_w = {}, {}
    for i in range(tasks.getSize()):
        task = tasks.get(i)
        if not task.getApply():
            continue
        is_marker = task.getConcreteClassName() == "IKMarkerTask"
        (marker_w if is_marker else coord_w)[task.getName()] = task.getWeight()
    assert setup.marker_weights == marker_w and len(marker_w) == 31
    assert {k: v.weight for k, v in setup.coordinate_tasks.items()} == coord_w
    assert setup.accuracy == tool.get_accuracy() == 1e-5
    assert setup.constraint_weight == tool.get_constraint_weight() == 20
    np.testing.assert_array_equal(setup.time_range, [tool.getStartTime(), tool.getEndTime()])
    assert setup.marker_file.name == "subject01_walk1.trc"


SETUP_BAD = {
    "entity": ('<?xml version="1.0"?>\n<!DOCTYPE x [<!ENTITY a "b">]>\n<x/>', "DTD/entity"),
    "malformed": ("<OpenSimDocument><InverseKinematicsTool>", "malformed XML"),
    "not ik": ("<OpenSimDocument>\n<ScaleTool/></OpenSimDocument>", "line 1: no <Inverse"),
    "weight": (
        "<InverseKinematicsTool><IKTaskSet><objects>\n<IKMarkerTask name='a'>"
        "<weight>-1</weight></IKMarkerTask></objects></IKTaskSet></InverseKinematicsTool>",
        "line 2: <weight>",
    ),
    "apply": (
        "<InverseKinematicsTool><IKTaskSet><objects>\n\n<IKMarkerTask name='a'>"
        "<apply>sometimes</apply></IKMarkerTask></objects></IKTaskSet></InverseKinematicsTool>",
        "line 3: <apply>",
    ),
    "time range": (
        "<InverseKinematicsTool>\n<time_range>2 1</time_range></InverseKinematicsTool>",
        "line 2: <time_range>",
    ),
    "value type": (
        "<InverseKinematicsTool><IKTaskSet><objects><IKCoordinateTask name='c'>\n"
        "<value_type>guess</value_type></IKCoordinateTask></objects></IKTaskSet>"
        "</InverseKinematicsTool>",
        "line 2: <value_type>",
    ),
}


@pytest.mark.parametrize("case", sorted(SETUP_BAD))
def test_bad_setup_names_the_line(tmp_path, case):
    text, expected = SETUP_BAD[case]
    p = tmp_path / "Setup_IK.xml"
    p.write_text(text)
    with pytest.raises(MotionDataError) as err:
        read_ik_setup(p)
    assert expected in str(err.value), str(err.value)


def test_sto_written_by_opensim(osim, tmp_path):
    """OpenSim 4's STOFileAdapter format (key=value header first, no name line, nan cells)."""
    table = osim.TimeSeriesTable()
    table.setColumnLabels(["a", "b"])
    table.appendRow(0.0, osim.RowVector([1.5, float("nan")]))
    table.appendRow(0.1, osim.RowVector([2.5, 3.5]))
    table.addTableMetaDataString("inDegrees", "no")
    osim.STOFileAdapter.write(table, str(tmp_path / "x.sto"))
    got = read_storage(tmp_path / "x.sto")
    assert got.labels == ("a", "b") and got.in_degrees is False and got.name == ""
    np.testing.assert_array_equal(got.time, [0.0, 0.1])
    np.testing.assert_array_equal(got.values, [[1.5, np.nan], [2.5, 3.5]])
