"""The command line: help texts, view / demo / ik, and one-line errors for user mistakes."""

from __future__ import annotations

import json
import re
import socket
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import cli

SUBCOMMANDS = ["check", "models", "ik", "view", "demo", "urdf", "bench"]


def page_commands(path) -> list[dict]:
    import base64

    import umsgpack

    m = re.search(r"var cmds = (\[.*?\]);", path.read_text(encoding="utf-8"), re.S)
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]


def run(argv, capsys):
    rc = cli.main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def assert_one_line_error(rc, err, *needles):
    assert rc == 2
    lines = [ln for ln in err.splitlines() if ln.strip() and "warning" not in ln]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for n in needles:
        assert n in lines[0], (n, lines[0])


def test_top_level_help_lists_every_subcommand():
    out = subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", "--help"], capture_output=True, text=True
    ).stdout
    for c in SUBCOMMANDS:
        assert re.search(rf"^\s+{c}\s", out, re.M), c


@pytest.mark.parametrize("cmd", SUBCOMMANDS)
def test_every_subcommand_help_has_an_example(cmd, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main([cmd, "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert "example" in out and f"anthroarm {cmd}" in out


def test_unknown_model_lists_the_catalog(capsys):
    for argv in (
        ["view", "robonaut"],
        ["ik", "robonaut", "--xyz", "0", "0", "0"],
        ["view", "robonaut", "--html", "x.html"],
    ):
        rc, out, err = run(argv, capsys)
        assert_one_line_error(rc, err, "robonaut", "human_arm7", "panda", "prosthetic_arm")


def test_q_of_wrong_length(capsys):
    rc, out, err = run(["view", "human_arm7", "--q", "1", "2", "3", "--html", "x.html"], capsys)
    assert_one_line_error(rc, err, "--q needs 7 values", "got 3", "elbow_flexion")


def test_html_in_missing_folder(tmp_path, capsys):
    target = tmp_path / "no" / "such" / "scene.html"
    for argv in (["view", "planar2r", "--html", str(target)], ["demo", "--html", str(target)]):
        rc, out, err = run(argv, capsys)
        assert_one_line_error(rc, err, "does not exist", str(target.parent))
    assert not target.parent.exists()


def test_port_in_use(capsys):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    s.listen()
    port = s.getsockname()[1]
    try:
        for argv in (
            ["view", "planar2r", "--port", str(port), "--no-browser", "--seconds", "0"],
            ["demo", "--port", str(port), "--no-browser", "--seconds", "0"],
        ):
            rc, out, err = run(argv, capsys)
            assert_one_line_error(rc, err, f"port {port}", "already in use")
    finally:
        s.close()


def test_user_errors_have_no_traceback_in_a_real_process(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", "view", "human_arm7", "--q", "0.1"],
        capture_output=True,
        text=True,
    )
    assert (
        r.returncode == 2
        and "Traceback" not in r.stderr
        and len(r.stderr.strip().splitlines()) == 1
    )


def test_view_writes_html(tmp_path, capsys):
    out_file = tmp_path / "arm.html"
    rc, out, err = run(
        [
            "view",
            "human_arm7",
            "--q",
            "40",
            "-20",
            "10",
            "70",
            "0",
            "0",
            "10",
            "--deg",
            "--limits",
            "--frames",
            "--workspace",
            "100",
            "--html",
            str(out_file),
        ],
        capsys,
    )
    assert rc == 0 and f"wrote {out_file}" in out
    cmds = page_commands(out_file)
    paths = {c["path"] for c in cmds}
    assert any(p.endswith("/overlays/workspace") for p in paths)
    assert sum("/overlays/frames/" in p for p in paths) >= 7
    assert any(c["type"] == "anthroarm_color" for c in cmds)  # --limits
    T = {
        c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T
        for c in cmds
        if c["type"] == "set_transform"
    }
    robot = aa.load("human_arm7")
    q = np.deg2rad([40, -20, 10, 70, 0, 0, 10])
    wrist = robot.fk(q, "wrist_flexion")  # joint frame of the last joint
    np.testing.assert_allclose(
        T["/meshcat/anthroarm/human_arm7/bodies/wrist_flexion"], wrist, atol=1e-12
    )


def test_view_live_starts_and_stops(capsys):
    rc, out, err = run(["view", "planar2r", "--no-browser", "--seconds", "0.2"], capsys)
    assert rc == 0 and re.search(r"viewer at http://127\.0\.0\.1:\d+/static/", out)


def test_demo_html_and_json(tmp_path, capsys):
    out_file = tmp_path / "demo.html"
    rc, out, err = run(["demo", "--html", str(out_file), "--json"], capsys)
    assert rc == 0
    data = json.loads(out)
    assert data["method"].startswith(("qp/", "dls"))
    assert len(data["targets"]) == 6
    # every target reached to better than a millimetre and a milliradian
    assert all(t["pos_err_m"] < 1e-3 and t["rot_err_rad"] < 1e-3 for t in data["targets"]), data
    anim = [c for c in page_commands(out_file) if c["type"] == "set_animation"]
    assert len(anim) == 1
    keys = anim[0]["animations"][0]["clip"]["tracks"][0]["keys"]
    assert len(keys) == data["steps"]


def test_ik_help_example_is_solved_and_checked_by_fk(capsys):
    """The example in `anthroarm ik --help` works, and FK of the answer is the asked pose."""
    with pytest.raises(SystemExit):
        cli.main(["ik", "--help"])
    help_text = capsys.readouterr().out
    example = re.search(r"example[^:]*: anthroarm ik (.+)", help_text).group(1).split()
    rc, out, err = run(["ik", *example], capsys)
    assert rc == 0, err
    res = json.loads(out)
    assert res["success"]
    robot = aa.load(res["model"])
    q = np.deg2rad([res["q"][n] for n in robot.joint_names])
    T = robot.fk(q)
    xyz = example[example.index("--xyz") + 1 : example.index("--xyz") + 4]
    rpy = np.deg2rad(
        [float(x) for x in example[example.index("--rpy") + 1 : example.index("--rpy") + 4]]
    )
    np.testing.assert_allclose(T[:3, 3], [float(x) for x in xyz], atol=1e-5)
    np.testing.assert_allclose(T[:3, :3], pin.rpy.rpyToMatrix(*rpy), atol=1e-5)


def test_ik_panda_text_output(capsys):
    robot = aa.load("panda")
    T = robot.fk(robot.random_q(rng=11, margin=0.2))
    rpy = pin.rpy.matrixToRpy(T[:3, :3])
    rc, out, err = run(
        ["ik", "panda", "--xyz", *map(str, T[:3, 3]), "--rpy", *map(str, rpy)], capsys
    )
    assert rc == 0, out + err
    assert "panda: solved" in out and "panda_joint7" in out


def test_ik_unreachable_exits_1(capsys):
    rc, out, err = run(["ik", "planar2r", "--xyz", "0", "5", "5", "--json"], capsys)
    assert rc == 1 and json.loads(out)["success"] is False


def test_ik_bad_numbers(capsys):
    rc, out, err = run(["ik", "human_arm7", "--xyz", "nan", "0", "0"], capsys)
    assert_one_line_error(rc, err, "finite")
    rc, out, err = run(["ik", "human_arm7", "--xyz", "0", "0", "-0.5", "--frame", "elbow"], capsys)
    assert_one_line_error(rc, err, "unknown frame", "hand_point")
