"""Garbage for every subcommand: bad options, bad numbers, NaN, missing files, folders,
devices.  Each gets one line on stderr and exit status 2, never a traceback; ``view`` and
``demo`` start no server and no browser on garbage."""

from __future__ import annotations

import os
import subprocess
import sys

import psutil
import pytest

from anthroarm import cli

XYZ = ["--xyz", "0.1", "0.1", "0.1"]
Q6 = ["0.1"] * 6

#: argv with placeholders: {dir} a folder, {file} a regular file, {junk} a file of garbage bytes
#: named .urdf, {fifo} a FIFO, {tmp} the test's folder.
CASES = {
    # top level
    "unknown-command": ["frobnicate"],
    "unknown-top-option": ["--bogus"],
    # check
    "check-samples-0": ["check", "prosthetic_arm", "--samples", "0"],
    "check-samples-negative": ["check", "prosthetic_arm", "--samples", "-3"],
    "check-samples-text": ["check", "--samples", "abc"],
    "check-samples-nan": ["check", "--samples", "nan"],
    "check-samples-huge": ["check", "prosthetic_arm", "--samples", "10000000000"],
    "check-seed-text": ["check", "--seed", "x"],
    "check-unknown-model": ["check", "no_such_model"],
    "check-tool-without-model": ["check", "--tool", "x"],
    "check-locked-empty": ["check", "prosthetic_arm", "--locked", ","],
    "check-locked-text": ["check", "prosthetic_arm", "--locked", "elbow_flexion=abc"],
    "check-locked-nan": ["check", "prosthetic_arm", "--locked", "elbow_flexion=nan"],
    "check-locked-unknown": ["check", "prosthetic_arm", "--locked", "nosuch"],
    "check-folder": ["check", "{dir}"],
    "check-junk": ["check", "{junk}"],
    "check-bogus-option": ["check", "--bogus"],
    # models
    "models-bogus-option": ["models", "--bogus"],
    "models-extra-argument": ["models", "extra"],
    # ik
    "ik-no-xyz": ["ik", "prosthetic_arm"],
    "ik-xyz-nan": ["ik", "prosthetic_arm", "--xyz", "nan", "0", "0"],
    "ik-xyz-inf": ["ik", "prosthetic_arm", "--xyz", "0", "inf", "0"],
    "ik-xyz-text": ["ik", "prosthetic_arm", "--xyz", "a", "b", "c"],
    "ik-xyz-two": ["ik", "prosthetic_arm", "--xyz", "0", "0"],
    "ik-rpy-nan": ["ik", "prosthetic_arm", *XYZ, "--rpy", "nan", "0", "0"],
    "ik-q0-nan": ["ik", "prosthetic_arm", *XYZ, "--q0", "nan", *Q6[1:]],
    "ik-q0-count": ["ik", "prosthetic_arm", *XYZ, "--q0", "1"],
    "ik-frame-unknown": ["ik", "prosthetic_arm", *XYZ, "--frame", "nosuch"],
    "ik-folder": ["ik", "{dir}", *XYZ],
    "ik-missing-file": ["ik", "{tmp}/missing.urdf", *XYZ],
    "ik-fifo": ["ik", "{fifo}", *XYZ],
    "ik-device": ["ik", "/dev/null", *XYZ],
    "ik-param-nan": ["ik", "human_arm7", "--param", "height=nan", *XYZ],
    "ik-param-negative": ["ik", "human_arm7", "--param", "height=-1", *XYZ],
    "ik-param-1e308": ["ik", "human_arm7", "--param", "height=1e308", *XYZ],
    "ik-param-inf": ["ik", "human_arm7", "--param", "mass=inf", *XYZ],
    "ik-param-unknown": ["ik", "human_arm7", "--param", "nosuch=1", *XYZ],
    "ik-param-no-equals": ["ik", "human_arm7", "--param", "height", *XYZ],
    "ik-param-bad-choice": ["ik", "human_arm7", "--param", "sex=robot", *XYZ],
    "ik-locked-nan": ["ik", "prosthetic_arm", "--locked", "elbow_flexion=nan", *XYZ],
    "ik-tool-unknown": ["ik", "prosthetic_arm", "--tool", "nosuch", *XYZ],
    "ik-empty-model": ["ik", "", *XYZ],
    # view
    "view-q-nan": ["view", "prosthetic_arm", "--q", "nan", *Q6[1:]],
    "view-q-inf": ["view", "prosthetic_arm", "--q", "inf", *Q6[1:]],
    "view-q-count": ["view", "prosthetic_arm", "--q", "1"],
    "view-workspace-negative": ["view", "prosthetic_arm", "--workspace", "-1"],
    "view-workspace-text": ["view", "prosthetic_arm", "--workspace", "abc"],
    "view-workspace-huge": ["view", "prosthetic_arm", "--workspace", "100000000000"],
    "view-port-0": ["view", "prosthetic_arm", "--port", "0"],
    "view-port-70000": ["view", "prosthetic_arm", "--port", "70000"],
    "view-port-text": ["view", "prosthetic_arm", "--port", "abc"],
    "view-seconds-nan": ["view", "prosthetic_arm", "--seconds", "nan"],
    "view-seconds-negative": ["view", "prosthetic_arm", "--seconds", "-1"],
    "view-seconds-inf": ["view", "prosthetic_arm", "--seconds", "inf"],
    "view-html-folder": ["view", "prosthetic_arm", "--html", "{dir}"],
    "view-html-under-file": ["view", "prosthetic_arm", "--html", "{file}/x.html"],
    "view-html-missing-folder": ["view", "prosthetic_arm", "--html", "{tmp}/no/such/x.html"],
    "view-html-fifo": ["view", "prosthetic_arm", "--html", "{fifo}"],
    "view-html-sysfs": ["view", "prosthetic_arm", "--html", "/sys/anthroarm_x.html"],
    "view-style-bogus": ["view", "prosthetic_arm", "--style", "bogus"],
    "view-folder": ["view", "{dir}"],
    "view-junk": ["view", "{junk}"],
    "view-fifo": ["view", "{fifo}"],
    "view-device": ["view", "/dev/null"],
    "view-locked-unknown": ["view", "prosthetic_arm", "--locked", "x=1"],
    # demo
    "demo-method-bogus": ["demo", "--method", "bogus"],
    "demo-param-nan": ["demo", "--param", "height=nan"],
    "demo-param-no-equals": ["demo", "--param", "bogus"],
    "demo-seconds-nan": ["demo", "--seconds", "nan"],
    "demo-port-0": ["demo", "--port", "0"],
    "demo-html-folder": ["demo", "--html", "{dir}"],
    "demo-html-under-file": ["demo", "--html", "{file}/d.html"],
    # urdf
    "urdf-no-output": ["urdf", "prosthetic_arm"],
    "urdf-output-folder": ["urdf", "prosthetic_arm", "-o", "{dir}"],
    "urdf-output-under-file": ["urdf", "prosthetic_arm", "-o", "{file}/x.urdf"],
    "urdf-output-sysfs": ["urdf", "prosthetic_arm", "-o", "/sys/anthroarm_x.urdf"],
    "urdf-output-procfs": ["urdf", "prosthetic_arm", "-o", "/proc/anthroarm_x.urdf"],
    "urdf-output-fifo": ["urdf", "prosthetic_arm", "-o", "{fifo}"],
    "urdf-junk-input": ["urdf", "{junk}", "-o", "{tmp}/o.urdf"],
    "urdf-param-nan": ["urdf", "human_arm7", "--param", "height=nan", "-o", "{tmp}/o.urdf"],
    # bench
    "bench-unknown": ["bench", "nosuch"],
    "bench-bogus-option": ["bench", "--bogus"],
    # cache
    "cache-no-action": ["cache"],
    "cache-bogus-action": ["cache", "bogus"],
    "cache-bogus-option": ["cache", "info", "--bogus"],
}


@pytest.fixture
def places(tmp_path):
    d = tmp_path / "a_folder"
    d.mkdir()
    f = tmp_path / "a_file"
    f.write_text("not a folder")
    junk = tmp_path / "junk.urdf"
    junk.write_bytes(os.urandom(4096))
    fifo = tmp_path / "a_fifo"
    os.mkfifo(fifo)
    return {
        "dir": str(d),
        "file": str(f),
        "junk": str(junk),
        "fifo": str(fifo),
        "tmp": str(tmp_path),
    }


def run_cli(argv, capsys):
    try:
        rc = cli.main(argv)
    except SystemExit as e:  # argparse
        rc = e.code
    out, err = capsys.readouterr()
    return rc, out, err


def children() -> set[int]:
    return {p.pid for p in psutil.Process().children(recursive=True)}


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_garbage_is_one_line_and_exit_2(case, places, capsys, tmp_path):
    argv = [a.format(**places) for a in CASES[case]]
    before = children()
    rc, out, err = run_cli(argv, capsys)
    lines = [ln for ln in err.splitlines() if ln.strip() and "warning" not in ln]
    assert rc == 2, (rc, out[-500:], err[-2000:])
    assert "Traceback" not in err and len(lines) == 1, err
    assert "error" in lines[0], lines[0]
    if argv[0] in ("view", "demo"):
        assert children() <= before, "a server or browser process was started on garbage"
    if "{fifo}" in " ".join(CASES[case]):
        assert os.path.exists(places["fifo"]) and not os.path.isfile(places["fifo"])  # not replaced
    assert os.listdir(places["dir"]) == []


def test_garbage_in_a_real_process_has_no_traceback(tmp_path):
    """The installed entry point, not only main(): argparse, file and number errors."""
    for argv in (
        ["ik", "prosthetic_arm", "--xyz", "nan", "0", "0"],
        ["urdf", "prosthetic_arm", "-o", str(tmp_path)],
        ["view", "prosthetic_arm", "--seconds", "nan"],
        ["cache", "bogus"],
    ):
        r = subprocess.run(
            [sys.executable, "-m", "anthroarm.cli", *argv],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode == 2 and "Traceback" not in r.stderr, (argv, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1, (argv, r.stderr)


def test_absurd_target_is_refused_and_a_far_one_fails_cleanly(capsys):
    """A target at 1e308 m made the reported position error inf ("Infinity" in the JSON): it is
    beyond the physical bound (urdf_io.MAX_LENGTH); a target 100 m away is a clean NOT solved
    (exit 1) with finite numbers."""
    rc, out, err = run_cli(["ik", "prosthetic_arm", "--xyz", "1e308", "0", "0", "--json"], capsys)
    assert rc == 2 and "Traceback" not in err and "physical bound" in err
    rc, out, err = run_cli(["ik", "prosthetic_arm", "--xyz", "100", "0", "0", "--json"], capsys)
    assert rc == 1 and "Traceback" not in err
    assert "NaN" not in out and "Infinity" not in out
