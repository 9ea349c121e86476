"""The CLI on OpenSim models (issue 32): ``anthroarm ik-markers`` with a ``.trc`` trial, an
``.osim`` model and its ``Setup_IK.xml`` writes a ``.mot`` that agrees with OpenSim's own
``InverseKinematicsSolver`` on the same frames and reads back in OpenSim; ``anthroarm urdf``
writes the URDF of an uncoupled model (poses and mass matrix equal the model's, read back by
Pinocchio and yourdfpy) and refuses a model with nonlinear couplings."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import anthroarm as aa
from anthroarm.motion import read_ik_setup, read_storage, rotational_coordinates

REC = Path(aa.__file__).parent / "data" / "opensim" / "recordings"
TRC, SETUP = REC / "subject01_walk1.trc", REC / "subject01_Setup_IK.xml"
MODEL = REC.parent / "subject01_simbody.osim"


def cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "anthroarm.cli", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )


def test_ik_markers_trc_osim_setup_writes_a_mot_like_opensims(tmp_path):
    osim = pytest.importorskip("opensim")
    from anthroarm.motion import opensim_ik

    out = tmp_path / "walk_ik.mot"
    r = cli("ik-markers", TRC, MODEL, "--setup", SETUP, "-o", out, "--time-range", 0.4, 0.5)
    assert r.returncode == 0, r.stdout + r.stderr
    ours = read_storage(out)
    assert ours.in_degrees and len(ours) == 7  # 60 Hz from 0.4 to 0.5 s
    ref = opensim_ik(MODEL, TRC, read_ik_setup(SETUP), time_range=(0.4, 0.5))
    np.testing.assert_allclose(ours.time, ref.time, atol=1e-9)
    robot = aa.load(str(MODEL))
    rot = set(rotational_coordinates(robot))
    for k, name in enumerate(ours.labels):
        mine = ours.values[:, k]
        theirs = ref.q[:, ref.coordinates.index(name)]
        if name in rot:
            assert np.sqrt(np.mean((np.deg2rad(mine) - theirs) ** 2)) < np.deg2rad(0.5), name
        else:
            assert np.sqrt(np.mean((mine - theirs) ** 2)) < 1e-3, name  # m
    # OpenSim reads the file back
    st = osim.Storage(str(out))
    assert st.getSize() == 7 and st.isInDegrees()


def test_ik_markers_trc_needs_an_osim_model(tmp_path):
    r = cli("ik-markers", TRC, "human_arm7", "-o", tmp_path / "q.csv")
    assert r.returncode != 0 and ".osim" in r.stderr, r.stderr
    assert not (tmp_path / "q.csv").exists()
