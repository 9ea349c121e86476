"""``anthroarm check model.osim``'s muscle rows (issue 34 item 6): lengths and moment arms
against OpenSim 4.6 (``getLength`` / ``computeMomentArm``) and moment arms against central
differences of our own lengths."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.muscles import checks


def _rows(robot, samples=20):
    return {r.quantity: r for r in checks.rows(robot, samples, np.random.default_rng(0))}


def test_leg6dof9musc_rows_pass():
    pytest.importorskip("opensim")
    rows = _rows(aa.load(aa.osim.path("leg6dof9musc")))
    assert set(rows) == {
        "muscle r = -dl/dq (central diff.)",
        "muscle lengths = OpenSim getLength",
        "muscle r = OpenSim computeMomentArm",
    }
    for r in rows.values():
        assert r.ok and r.tol == 1e-6, r
    assert rows["muscle lengths = OpenSim getLength"].max_abs_err < 1e-12


def test_arm26_cylinder_rows(tmp_path):
    """arm26 with its ellipsoids inactive: TRIlat, TRImed, BRA and TRIlong over cylinders (own
    row, 5e-4: OpenSim's tangent points), BIClong and BICshort straight."""
    pytest.importorskip("opensim")
    text = re.sub(
        r"(<WrapEllipsoid name=\"\w+\">\s*<!--[^>]*-->\s*<active>)true",
        r"\1false",
        aa.osim.path("arm26").read_text(),
    )
    p = tmp_path / "arm26_cylinders.osim"
    p.write_text(text)
    rows = _rows(aa.load(p), 10)
    assert rows["muscle r = -dl/dq (central diff.)"].max_abs_err < 1e-8
    wrapped = rows["muscle r = -dl/dq, wrapped paths (central diff.)"]
    assert wrapped.ok and wrapped.max_abs_err > 1e-6  # the tangent points' offset is real
    assert rows["muscle lengths = OpenSim getLength"].max_abs_err < 1e-12
    assert rows["muscle r = OpenSim computeMomentArm"].max_abs_err < 1e-12


def test_no_rows_without_muscles():
    assert checks.rows(aa.load("planar2r"), 10, np.random.default_rng(0)) == []


def test_cli_prints_the_muscle_rows():
    pytest.importorskip("opensim")
    out = subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", "check", str(aa.osim.path("leg6dof9musc"))]
        + ["--samples", "5"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    for row in ("muscle lengths = OpenSim getLength", "muscle r = -dl/dq (central diff.)"):
        assert row in out.stdout


def test_arm26_biceps_ellipsoid_rows(tmp_path):
    """arm26 with TRIlong's ellipsoid inactive: BIClong over its ellipsoid gets the row against
    central differences of OpenSim's lengths; every row passes."""
    pytest.importorskip("opensim")
    text = re.sub(
        r"(<WrapEllipsoid name=\"TRIlonghh\">\s*<!--[^>]*-->\s*<active>)true",
        r"\1false",
        aa.osim.path("arm26").read_text(),
    )
    p = tmp_path / "arm26_biceps_ellipsoid.osim"
    p.write_text(text)
    rows = _rows(aa.load(p), 5)
    ell = rows["muscle r over ellipsoids = -d(OpenSim getLength)/dq"]
    assert rows["muscle lengths = OpenSim getLength"].tol == 1e-4
    for r in rows.values():
        assert r.ok, r
    assert ell.max_abs_err > 0
