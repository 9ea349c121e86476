"""The whole loop on the daily-living library and the report: statuses for unusable activities,
the report's numbers equal to the study's, the CLI end to end."""

import json
import re

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.cli import main
from anthroarm.dynamics.hand_model import minimum_jerk
from anthroarm.errors import ActivityError
from anthroarm.prosthesis import report, study
from anthroarm.viewer.pages import activities_html


@pytest.fixture(scope="module")
def person():
    return aa.load("human_arm7", height=1.75, mass=70.0, sex="male")


def test_adl_activities_carry_the_library_objects(person):
    acts = study.adl_activities(person, payload=0.5, names=["lift_to_table", "reach_shelf"])
    lift = acts[0]
    assert lift["name"] == "lift_to_table" and "status" not in lift
    assert np.max(lift["payload"]) == 1.0 and np.min(lift["payload"]) == 0.5  # 1 kg while held
    assert np.all(acts[1]["payload"] == 0.5)
    for bad in (-1.0, float("nan"), "heavy", [1.0]):
        with pytest.raises(ActivityError, match="payload must be a mass"):
            study.adl_activities(person, payload=bad, names=["reach_shelf"])


def test_adl_activity_out_of_reach_is_a_status(person):
    """Targets placed for a 2.4 m person: the 1.75 m arm cannot reach the door handle; the
    activity keeps status "unreachable", the keyframe and the distance, and stays out of the
    envelope."""
    acts = study.adl_activities(person, payload=0.5, names=["open_door", "reach_shelf"], height=2.4)
    door = acts[0]
    assert door["status"] == "unreachable" and "'handle' out of reach" in door["reason"]
    st = study.run(person, acts, payload=0.5)
    assert [a.name for a in st.envelope.skipped] == ["open_door"]
    assert [a.name for a in st.envelope.activities] == ["reach_shelf"]


def test_unreachable_activity_is_a_status_in_study_and_report(person, tmp_path):
    t = np.linspace(0, 1.0, 51)
    q0 = person.neutral()
    q, qd, qdd = minimum_jerk(q0, q0 + np.array([1.0, 0, 0, 1.0, 0, 0, 0]), 1.0, t)
    acts = [
        dict(name="reach", t=t, q=q, qd=qd, qdd=qdd),
        dict(
            name="far shelf",
            t=t,
            q=q,
            status="unreachable",
            reason="keyframe 'shelf' out of reach (120 mm short)",
        ),
    ]
    st = study.run(person, acts, payload=0.5)
    assert [a.status for a in st.activities] == ["ok", "unreachable"]
    assert [a.name for a in st.envelope.activities] == ["reach"]
    out = report.write(st, tmp_path / "r.html")
    text = out.read_text()
    assert "far shelf" in text and "120 mm short" in text
    # the report's drive mass is the study's
    m = re.search(r"Drive mass \(motors \+ gearboxes\): ([0-9.]+) kg", text)
    assert float(m.group(1)) == pytest.approx(st.sizing.drive_mass, abs=5e-4)
    assert text.count("data:image/png;base64,") == person.nv
    for bad in (float("nan"), "heavy", None, 51.0):
        with pytest.raises(ActivityError, match="payload must be a mass"):
            study.run(person, acts, payload=bad)
    with pytest.raises(ActivityError, match="no 'q'"):
        study.run(person, [dict(name="x", t=t)])
    with pytest.raises(ActivityError, match="dict"):
        study.run(person, [(t, q)])
    with pytest.raises(ActivityError, match="payload"):
        study.run(person, [dict(name="x", t=t, q=q, payload="heavy")])


def test_cli_size_end_to_end(tmp_path, capsys):
    out = tmp_path / "report.html"
    rc = main(
        [
            "size",
            "--height",
            "1.75",
            "--mass",
            "70",
            "--sex",
            "male",
            "--activities",
            "adl",
            "--payload",
            "0.5",
            "--no-viewer",
            "--no-progress",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["out"] == str(out) and out.stat().st_size > 10_000
    assert set(summary["joints"]) == set(aa.load("human_arm7").joint_names)
    assert summary["rules"]["L7441"] is True


@pytest.mark.parametrize(
    "args, words",
    [
        (["--out", "x.txt"], "HTML"),
        (["--payload", "-1"], "payload"),
        (["--activities", "nope.npz"], "not found"),
        (["--motors", "missing.csv"], "not found"),
        (["--model", "prosthetic_arm"], "person models: "),  # a book arm not scaled by a person
        (["--model", "ur5"], "person models"),
    ],
)
def test_cli_size_bad_input(tmp_path, capsys, args, words, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc = main(["size", "--no-progress", "--no-viewer", *args])
    assert rc == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "report.html").exists()


def test_report_embeds_one_viewer_page_with_the_activities(person, tmp_path):
    t = np.linspace(0, 0.5, 26)
    q0 = person.neutral()
    q, qd, qdd = minimum_jerk(q0, q0 + np.array([0.8, 0, 0, 0.9, 0, 0, 0]), 0.5, t)
    st = study.run(
        person,
        [dict(name="a", t=t, q=q, qd=qd, qdd=qdd), dict(name="b", t=t, q=q[::-1])],
        payload=0.2,
    )
    text = report.render(st, viewer=activities_html(st))
    assert text.count("<iframe srcdoc=") == 1 and "set_animation" not in text[:200]
    assert "a at 0.0 s; b at 0.5 s" in text
    assert text.count("MeshCat.Viewer(") == 1  # meshcat's page once, escaped in srcdoc


def test_cli_size_bad_trajectory_files(tmp_path, capsys, monkeypatch, person):
    """Files that are not trajectories: one line naming the file (and the line), no report."""
    monkeypatch.chdir(tmp_path)
    names = ",".join(["t", *person.joint_names])
    row = ",".join(["0.0"] * (person.nq + 1))
    (tmp_path / "junk.npz").write_bytes(b"not a zip archive")
    np.save(tmp_path / "one.npy", np.zeros(3))
    (tmp_path / "one.npy").rename(tmp_path / "one.npz")
    np.savez(tmp_path / "text.npz", t=np.array(["a"] * 5), q=np.zeros((5, person.nq)))
    (tmp_path / "ragged.csv").write_text(f"{names}\n{row}\n1.0,2.0\n")
    (tmp_path / "word.csv").write_text(f"{names}\n{row}\n{row.replace('0.0', 'x', 1)}\n")
    (tmp_path / "header.csv").write_text(f"# only a header\n{names}\n")
    for f, words in [
        ("junk.npz", "not a NumPy .npz archive"),
        ("one.npz", "not a NumPy .npz archive"),
        ("text.npz", "must be numbers"),
        ("ragged.csv", "line 3: 2 values"),
        ("word.csv", "line 3: a value is not a number"),
        ("header.csv", "no samples"),
    ]:
        rc = main(["size", "--no-progress", "--no-viewer", "--activities", f])
        err = capsys.readouterr().err
        assert rc == 2 and f in err and words in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "report.html").exists()


def test_every_submodule_is_an_attribute_of_the_package():
    """aa.prosthesis.NAME for every module file of the package (lazy imports), study included."""
    from pathlib import Path

    import anthroarm.prosthesis as P

    files = {p.stem for p in Path(P.__file__).parent.glob("*.py") if not p.stem.startswith("_")}
    assert set(P.__all__) == files
    for name in files:
        assert getattr(aa.prosthesis, name).__name__ == f"anthroarm.prosthesis.{name}"
