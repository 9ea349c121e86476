"""The ``anthroarm ik-markers`` command on a real C3D file, and a marker set of one's own as
JSON."""

import json

import numpy as np
import pytest
from motion_synthetic import known_motion, pin_marker_positions

import anthroarm as aa
from anthroarm.cli import main
from anthroarm.motion import MarkerTrajectories, write_c3d
from anthroarm.motion.csv_io import read_joint_csv


def test_cli_ik_markers(tmp_path, capsys):
    person = aa.load("human_arm7", height=1.62, mass=55, sex="female")
    from anthroarm.motion import default_marker_set

    ms = default_marker_set(person)
    _, Q = known_motion(person, n=120, seed=9)
    P = pin_marker_positions(person, ms, Q)
    P[50:52] = np.nan
    write_c3d(
        tmp_path / "trial.c3d", MarkerTrajectories([f"S1:{n}" for n in ms.names], P, rate=100.0)
    )
    rc = main(
        [
            "ik-markers",
            str(tmp_path / "trial.c3d"),
            "--out",
            str(tmp_path / "angles.csv"),
            "--height",
            "1.62",
            "--mass",
            "55",
            "--sex",
            "female",
            "--no-progress",
        ]
    )
    out = capsys.readouterr().out.strip().splitlines()[-1]
    assert rc == 0
    summary = json.loads(out)
    assert summary["frames"] == 120 and summary["ok"] == 118 and summary["skipped"] == 2
    back = read_joint_csv(tmp_path / "angles.csv", person)
    ok = np.ones(120, bool)
    ok[50:52] = False
    assert np.max(np.abs(back.q[ok] - Q[ok])) < 1e-4
    # bad input: one line on stderr, exit 2, no output file
    rc = main(["ik-markers", str(tmp_path / "nope.c3d"), "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert (
        rc == 2
        and "C3D file not found" in err
        and err.count("\n") == 1
        and not (tmp_path / "x.csv").exists()
    )
    rc = main(["ik-markers", str(tmp_path / "trial.c3d"), "--out", str(tmp_path / "no" / "x.csv")])
    assert rc == 2 and "existing folder" in capsys.readouterr().err
    rc = main(
        [
            "ik-markers",
            str(tmp_path / "trial.c3d"),
            "--out",
            str(tmp_path / "p.csv"),
            "--model",
            "prosthetic_arm",
            "--height",
            "1.7",
        ]
    )  # the loader names what the model accepts
    assert rc == 2 and "accepted: ['L1', 'L2', 'L3']" in capsys.readouterr().err
    # every frame empty: a CSV of held postures, exit 1, and the summary is still strict JSON
    write_c3d(tmp_path / "nan.c3d", MarkerTrajectories(ms.names, np.full((5, len(ms), 3), np.nan)))
    rc = main(
        [
            "ik-markers",
            str(tmp_path / "nan.c3d"),
            "--out",
            str(tmp_path / "nan.csv"),
            "--no-progress",
        ]
    )
    cap = capsys.readouterr()
    summary = json.loads(
        cap.out.strip().splitlines()[-1], parse_constant=lambda c: pytest.fail(f"{c} in JSON")
    )
    assert (
        rc == 1
        and summary["skipped"] == 5
        and summary["rms_median_m"] is None
        and "no frame" in cap.err
    )
    rc = main(["ik-markers", str(tmp_path / "trial.c3d"), "--out", str(tmp_path)])  # a folder
    assert rc == 2 and "give a file name" in capsys.readouterr().err
    (tmp_path / "garbage.c3d").write_bytes(b"garbage")
    rc = main(["ik-markers", str(tmp_path / "garbage.c3d"), "--out", str(tmp_path / "g.csv")])
    err = capsys.readouterr().err
    assert (
        rc == 2
        and "not a C3D file" in err
        and err.count("\n") == 1
        and not (tmp_path / "g.csv").exists()
    )


def test_own_marker_set_as_json(tmp_path, arm, markers, capsys):
    """A lab's own set: written, read back equal, used by the CLI; bad files are typed errors."""
    from anthroarm.errors import MarkerSetError
    from anthroarm.motion import MarkerSet

    own = markers.subset(["UA", "EL", "EM", "RS", "US", "MC2", "MC5"])
    own.write_json(tmp_path / "own.json")
    back = MarkerSet.read_json(tmp_path / "own.json")
    assert back.names == own.names and np.array_equal(back.positions, own.positions)
    _, Q = known_motion(arm, n=20, seed=13)
    P = pin_marker_positions(arm, own, Q)
    write_c3d(tmp_path / "t.c3d", MarkerTrajectories(own.names, P, rate=100.0))
    rc = main(
        [
            "ik-markers",
            str(tmp_path / "t.c3d"),
            "--out",
            str(tmp_path / "a.csv"),
            "--markers",
            str(tmp_path / "own.json"),
            "--no-progress",
        ]
    )
    assert rc == 0 and json.loads(capsys.readouterr().out.strip().splitlines()[-1])["ok"] == 20
    assert np.abs(read_joint_csv(tmp_path / "a.csv", arm).q - Q).max() < 1e-4
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(MarkerSetError, match="not a JSON"):
        MarkerSet.read_json(tmp_path / "bad.json")
    (tmp_path / "bad2.json").write_text('{"markers": {"A": ["hand"]}}')
    with pytest.raises(MarkerSetError, match="expected"):
        MarkerSet.read_json(tmp_path / "bad2.json")
    with pytest.raises(MarkerSetError, match="not found"):
        MarkerSet.read_json(tmp_path / "none.json")
