"""The CLI on OpenSim models (issue 32): ``anthroarm ik-markers`` with a ``.trc`` trial, an
``.osim`` model and its ``Setup_IK.xml`` writes a ``.mot`` that agrees with OpenSim's own
``InverseKinematicsSolver`` on the same frames and reads back in OpenSim; ``anthroarm urdf``
writes the URDF of an uncoupled model (poses and mass matrix equal the model's, read back by
Pinocchio and yourdfpy) and refuses a model with nonlinear couplings."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
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


@pytest.mark.parametrize(
    "name, tool",
    [("arm26", "r_ulna_radius_hand"), ("Tug_of_War", "block")],
)
def test_urdf_of_an_uncoupled_osim_model(tmp_path, name, tool):
    """The written URDF, read by Pinocchio (aa.load) and yourdfpy, puts every OpenSim body and
    marker where the .osim import does (checked against OpenSim in tests/osim) and gives the
    same mass matrix."""
    import yourdfpy

    out = tmp_path / f"{name}.urdf"
    r = cli("urdf", aa.osim.path(name), "-o", out)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "gravity" in r.stdout  # the one thing a URDF cannot carry is said
    osim_robot = aa.load(aa.osim.path(name))
    urdf_robot = aa.load(str(out), tool=tool)
    assert urdf_robot.joint_names == osim_robot.joint_names
    np.testing.assert_array_equal(urdf_robot.lower, osim_robot.lower)
    np.testing.assert_array_equal(urdf_robot.upper, osim_robot.upper)
    u = yourdfpy.URDF.load(str(out))
    frames = [f for f in osim_robot.markers] + [tool]
    for q in osim_robot.random_q(5, rng=7):
        m, d = urdf_robot.model, urdf_robot.model.createData()
        M = np.triu(pin.crba(m, d, q))
        M = M + np.triu(M, 1).T
        np.testing.assert_allclose(M, osim_robot.mass_matrix(q), rtol=1e-12, atol=1e-14)
        m.gravity = osim_robot.model.gravity  # a URDF has no gravity: OpenSim's is along -y
        g = pin.computeGeneralizedGravity(m, d, q)
        np.testing.assert_allclose(g, osim_robot.gravity(q), rtol=1e-12, atol=1e-13)
        u.update_cfg(dict(zip(osim_robot.joint_names, q)))
        for f in frames:
            T = osim_robot.fk(q, f)
            np.testing.assert_allclose(urdf_robot.fk(q, f), T, atol=1e-12)
            np.testing.assert_allclose(u.get_transform(f, "root"), T, atol=1e-12)


def test_urdf_refuses_a_model_with_spline_couplings(tmp_path):
    out = tmp_path / "gait.urdf"
    r = cli("urdf", aa.osim.path("gait2392"), "-o", out)
    assert r.returncode != 0 and not out.exists()
    assert "knee_r_translation1" in r.stderr and "URDF" in r.stderr, r.stderr


def test_view_osim_takes_the_coordinates(tmp_path):
    """``anthroarm view gait.osim --deg --q`` (23 coordinates, degrees for the angles) writes a
    page whose knee is where robot.fk puts it (the tibia's spline translation included)."""
    import base64
    import json
    import re

    import umsgpack

    from anthroarm.viewer import Viewer

    gait = aa.load(aa.osim.path("gait2392"))
    values = ["0"] * gait.nq
    knee = gait.joint_names.index("knee_angle_r")
    values[knee] = "-60"
    values[gait.joint_names.index("pelvis_ty")] = "0.9"  # m: not converted by --deg
    out = tmp_path / "gait.html"
    r = cli("view", aa.osim.path("gait2392"), "-o", out, "--deg", "--q", *values)
    assert r.returncode == 0, r.stdout + r.stderr
    m = re.search(r"var cmds = (\[.*?\]);", out.read_text(), re.S)
    cmds = [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(m.group(1))]
    sent = {c["path"]: np.asarray(c["matrix"]).reshape(4, 4).T for c in cmds if "matrix" in c}
    q = np.zeros(gait.nq)
    q[knee], q[gait.joint_names.index("pelvis_ty")] = np.deg2rad(-60.0), 0.9
    v = Viewer(gait)
    tibia = gait.model.frames[gait.frame_id("tibia_r")]
    body = next(b for b in v.bodies if b.joint is not None and b.joint + 1 == tibia.parentJoint)
    want = gait.fk(q, "tibia_r") @ np.linalg.inv(tibia.placement.homogeneous)
    np.testing.assert_allclose(sent[v._bpath(body)], want, atol=1e-12)


def test_ik_on_a_coupled_model_solves_in_the_coordinates():
    """``anthroarm ik`` on gait2392 (spline knees): one value per coordinate, named after it,
    whose pose by Pinocchio's FK at φ(q) is the target."""
    r = cli(
        "ik", aa.osim.path("gait2392"), "--tool", "calcn_r", "--xyz", "0.1", "-0.8", "0.1", "--json"
    )
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    out = json.loads(r.stdout)
    gait = aa.load(aa.osim.path("gait2392"))
    assert out["success"] and list(out["q"]) == gait.joint_names
    q = np.array([out["q"][n] for n in gait.joint_names])
    d = gait.model.createData()
    pin.framesForwardKinematics(gait.model, d, gait.coupling.full(q))
    M = d.oMf[gait.frame_id("calcn_r")]
    np.testing.assert_allclose(M.translation, [0.1, -0.8, 0.1], atol=1e-6)
    np.testing.assert_allclose(M.rotation, np.eye(3), atol=1e-6)
