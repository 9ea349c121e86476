"""Joint-angle CSV (``anthroarm.motion.csv_io``): round trips of a marker-IK result, degrees, gaps
and errors."""

import numpy as np
import pytest
from motion_synthetic import known_motion, pin_marker_positions

from anthroarm.errors import MotionDataError
from anthroarm.motion import MarkerTrajectories, marker_ik
from anthroarm.motion.csv_io import read_joint_csv, write_joint_csv


def test_csv_round_trip_of_a_marker_ik_result(tmp_path, arm, markers):
    _, Q = known_motion(arm, n=30)
    P = pin_marker_positions(arm, markers, Q)
    P[10:12] = np.nan
    res = marker_ik(arm, MarkerTrajectories(markers.names, P, rate=100.0), markers)
    write_joint_csv(tmp_path / "a.csv", res)
    back = read_joint_csv(tmp_path / "a.csv", arm)
    np.testing.assert_array_equal(back.q, res.q)  # repr() of floats: exact
    np.testing.assert_array_equal(back.t, res.time)
    assert back.names == tuple(arm.joint_names) and back.valid.all()
    text = (tmp_path / "a.csv").read_text()
    assert "3 skipped" in text and text.splitlines()[2].startswith("t,shoulder_flexion")
    rows = [ln.split(",") for ln in text.splitlines() if ln and not ln.startswith("#")]
    assert rows[11][-1] == "3" and rows[11][-4] == "nan"  # frame 10: skipped


def test_csv_degrees_gaps_and_errors(tmp_path, arm):
    names = arm.joint_names
    lines = ["# a spreadsheet in degrees", "time_s," + ",".join(f"{n}_deg" for n in names)]
    lines.append("0.0," + ",".join(["10"] * 7))
    lines.append("0.1," + ",".join(["20"] * 6 + [""]))  # a gap in one joint
    lines.append("0.2," + ",".join(["30"] * 7))
    (tmp_path / "d.csv").write_text("\n".join(lines) + "\n")
    tr = read_joint_csv(tmp_path / "d.csv", arm)
    np.testing.assert_allclose(tr.q[0], np.deg2rad(10), rtol=1e-15)
    np.testing.assert_allclose(tr.q[2], np.deg2rad(30), rtol=1e-15)
    assert tr.valid.tolist() == [True, False, True]
    np.testing.assert_allclose(tr.q[1], tr.q[0])  # held, not NaN
    bad = {
        "nohead.csv": "# only a comment\n",
        "notime.csv": "a,b\n1,2\n",
        "word.csv": "t," + ",".join(names) + "\n0," + ",".join(["x"] * 7) + "\n",
        "short.csv": "t," + ",".join(names) + "\n0,1\n",
        "back.csv": "t,"
        + ",".join(names)
        + "\n1,"
        + ",".join(["0"] * 7)
        + "\n0,"
        + ",".join(["0"] * 7)
        + "\n",
        "joint.csv": "t,shoulder_flexion\n0,1\n",
        "inf.csv": "t," + ",".join(names) + "\n0," + ",".join(["0"] * 6 + ["inf"]) + "\n",
        "overflow.csv": "t," + ",".join(names) + "\n0," + ",".join(["1e400"] + ["0"] * 6) + "\n",
        "huge.csv": "t,"
        + ",".join(names)
        + "\n0,"
        + ",".join(["0"] * 7)
        + "\n1e7,"
        + ",".join(["0"] * 7)
        + "\n",
    }
    msgs = {
        "nohead.csv": "header",
        "notime.csv": "time column",
        "word.csv": "line 2",
        "short.csv": "line 2",
        "back.csv": "increase",
        "joint.csv": "missing joint",
        "inf.csv": "line 2, column 'wrist_flexion'",
        "overflow.csv": "line 2, column 'shoulder_flexion'",
        "huge.csv": "line 3, column 't'",
    }
    for f, body in bad.items():
        (tmp_path / f).write_text(body)
        with pytest.raises(MotionDataError, match=msgs[f]):
            read_joint_csv(tmp_path / f, arm)
    with pytest.raises(MotionDataError, match="not found"):
        read_joint_csv(tmp_path / "missing.csv")
    for name in ("b,c", "#b", ""):  # would shift or hide a column when read back
        with pytest.raises(MotionDataError, match="column names"):
            write_joint_csv(tmp_path / "n.csv", np.arange(3.0), np.zeros((3, 2)), ["a", name])
    assert not (tmp_path / "n.csv").exists()
