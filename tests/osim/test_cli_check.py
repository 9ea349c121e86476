"""``anthroarm check model.osim`` (issue 32 items 3 and 4): the import report, the Pinocchio rows
and — with opensim installed — the OpenSim rows, exit status 0 when every row passes."""

from __future__ import annotations

import subprocess
import sys

import pytest

from anthroarm.osim import path


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", "check", *args],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_check_osim_prints_report_and_rows():
    pytest.importorskip("opensim")
    out = run(str(path("leg6dof9musc")), "--samples", "10")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "import report of leg6dof9musc" in out.stdout
    assert "dropped: 16" in out.stdout and "Thelen2003Muscle" in out.stdout
    for row in ("osim body poses = OpenSim", "osim tau = OpenSim ID", "osim J G = dFK/dq"):
        assert row in out.stdout
