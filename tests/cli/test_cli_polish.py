"""Issue 14 item 3: a book model's builder parameters are options of the commands that take a
model (listed by ``--help`` with units and defaults, also accepted as ``--param``), and
``anthroarm bench`` writes to ``--out`` or a user folder, never the committed results unless
``--update-results``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from anthroarm import cli, models

ROOT = Path(__file__).resolve().parents[2]


def _run(*args, env=None):
    return subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", *args],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )


def test_urdf_help_lists_the_model_parameters_with_units_and_defaults():
    r = _run("urdf", "human_arm7", "--help")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "parameters of human_arm7" in out
    lines = {ln.split()[0]: ln for ln in out.splitlines() if ln.strip().startswith("--")}
    assert "m (0.5–2.6), default 1.75" in lines["--height"]
    assert "kg (10–300), default 75.0" in lines["--mass"]
    assert "default male" in lines["--sex"]


def test_urdf_help_of_another_book_model_lists_its_own_parameters(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["urdf", "prosthetic_arm", "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    opts = {ln.split()[0]: ln for ln in out.splitlines() if ln.strip().startswith("--")}
    assert "m, default 0.26" in opts["--L2"] and "--height" not in opts


def test_urdf_accepts_parameters_as_options_and_as_param(tmp_path, capsys):
    a, b, c = tmp_path / "a.urdf", tmp_path / "b.urdf", tmp_path / "c.urdf"
    assert (
        cli.main(["urdf", "human_arm7", "-o", str(a), "--height", "1.62", "--sex", "female"]) == 0
    )
    assert (
        cli.main(
            ["urdf", "human_arm7", "-o", str(b), "--param", "height=1.62", "--param", "sex=female"]
        )
        == 0
    )
    assert cli.main(["urdf", "human_arm7", "-o", str(c)]) == 0
    assert (
        a.read_text() == b.read_text() == models.urdf_text("human_arm7", height=1.62, sex="female")
    )
    assert a.read_text() != c.read_text()
    # a pair parameter (the boom stroke) as MIN,MAX
    d = tmp_path / "d.urdf"
    assert cli.main(["urdf", "unimate5", "-o", str(d), "--boom", "0.2,0.9"]) == 0
    assert d.read_text() == models.urdf_text("unimate5", boom=(0.2, 0.9))


@pytest.mark.parametrize(
    "args, needle",
    [
        (["urdf", "human_arm7", "--heigth", "1.62"], "--heigth: did you mean --height?"),
        (["urdf", "human_arm7", "--heigth", "1.62"], "--height, --mass, --sex"),
        (["urdf", "human_arm7", "--param", "heigth=1.62"], "height, mass, sex"),
        (["urdf", "ur10", "--height", "1.62"], "ur10 has no builder parameters"),
        (["urdf", "human_arm7", "--height", "tall"], "expects a number"),
        (["urdf", "unimate5", "--boom", "0.2"], "two numbers"),
        (["urdf", "human_arm7", "--height", "1.6", "--param", "height=1.7"], "given twice"),
    ],
)
def test_bad_model_parameters_are_one_line_errors(tmp_path, capsys, args, needle):
    out = tmp_path / "x.urdf"
    assert cli.main([*args, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not out.exists()


def test_unknown_model_parameter_in_a_subprocess_exits_2_with_the_choices(tmp_path):
    r = _run("urdf", "human_arm7", "-o", str(tmp_path / "x.urdf"), "--weight", "70")
    assert r.returncode == 2
    assert (
        r.stderr.count("\n") == 1
        and "--height, --mass, --sex" in r.stderr
        and "Traceback" not in r.stderr
    )


def test_view_takes_the_model_parameters_too(tmp_path, capsys):
    out = tmp_path / "v.html"
    assert cli.main(["view", "human_arm7", "--height", "1.62", "--html", str(out)]) == 0
    assert out.stat().st_size > 1000


# ------------------------------------------------------------------------------------------- bench
def test_bench_list_and_help():
    r = _run("bench", "--list")
    assert r.returncode == 0 and "tolerance" in r.stdout.split()
    h = _run("bench", "--help")
    assert "--out" in h.stdout and "--update-results" in h.stdout


def test_bench_out_into_a_path_under_a_file_is_one_line_error(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    r = _run("bench", "tolerance", "--quick", "--out", str(f / "sub"))
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "cannot write" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize(
    "args", [["--quick", "--update-results"], ["--out", "x", "--update-results"]]
)
def test_bench_update_results_conflicts(capsys, args):
    before = {p: p.stat().st_mtime_ns for p in (ROOT / "benchmarks" / "results").glob("*.*")}
    assert cli.main(["bench", "tolerance", *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--update-results" in err
    assert {
        p: p.stat().st_mtime_ns for p in (ROOT / "benchmarks" / "results").glob("*.*")
    } == before


def test_bench_writes_to_out_and_by_default_to_the_user_folder(tmp_path):
    """A tiny quick benchmark (~2 s): --out gets the files; without --out they go under
    $XDG_DATA_HOME/anthroarm/benchmarks/quick; benchmarks/results/ is untouched."""
    import os

    results = ROOT / "benchmarks" / "results"
    before = {p: p.stat().st_mtime_ns for p in results.glob("*.*")}
    out = tmp_path / "mine"
    r = _run("bench", "tolerance", "--quick", "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert (out / "tolerance.json").is_file() and (out / "tolerance.md").is_file()
    if sys.platform.startswith("linux"):
        env = {**os.environ, "XDG_DATA_HOME": str(tmp_path / "xdg")}
        r = _run("bench", "tolerance", "--quick", env=env)
        assert r.returncode == 0, r.stderr
        assert (
            tmp_path / "xdg" / "anthroarm" / "benchmarks" / "quick" / "tolerance.json"
        ).is_file()
    assert {p: p.stat().st_mtime_ns for p in results.glob("*.*")} == before


def test_urdf_help_gives_angle_ranges_in_rad_and_they_are_used_as_rad(tmp_path, capsys):
    """A template's joint ranges are angles: --help says rad, and the value given becomes the
    revolute joint's limits in Pinocchio's model as given (no degree or metre conversion)."""
    with pytest.raises(SystemExit) as e:
        cli.main(["urdf", "spherical_robot", "--help"])
    assert e.value.code == 0
    opts = {
        ln.split()[0]: ln
        for ln in capsys.readouterr().out.splitlines()
        if ln.strip().startswith("--")
    }
    assert opts["--elevation"].split()[2] == "rad," and opts["--base"].split()[2] == "rad,"
    assert opts["--reach"].split()[2] == "m,"
    out = tmp_path / "s.urdf"
    assert cli.main(["urdf", "spherical_robot", "-o", str(out), "--elevation=-0.5,0.75"]) == 0
    import pinocchio as pin

    m = pin.buildModelFromUrdf(str(out))
    revolute = [j for j in range(1, m.njoints) if m.joints[j].shortname().startswith("JointModelR")]
    lims = sorted(
        (
            float(m.lowerPositionLimit[m.joints[j].idx_q]),
            float(m.upperPositionLimit[m.joints[j].idx_q]),
        )
        for j in revolute
    )
    assert (-0.5, 0.75) in [(round(a, 12), round(b, 12)) for a, b in lims]
