"""The commands that take a model take any robot the same way: catalog names, example-robot-data
names and URDF paths, with --tool for a tree and --locked for joints to freeze; a continuous
joint is given and printed as its angle."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import cli
from anthroarm.cli import runtime

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "foundation"))
from test_chain import USER_URDF  # noqa: E402


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


def test_view_example_robot_data_tree_needs_a_tool(tmp_path, capsys):
    out = tmp_path / "so101.html"
    assert cli.main(["view", "so101", "--html", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "gripper_frame_link" in err and "Traceback" not in err
    assert not out.exists()
    assert cli.main(["view", "so101", "--tool", "gripper_frame_link", "--html", str(out)]) == 0
    assert out.stat().st_size > 10_000


def test_view_user_urdf_takes_a_continuous_joint_as_its_angle(tmp_path, user_urdf, capsys):
    out = tmp_path / "user.html"
    # joints spin (continuous), shoulder, wrist (continuous), grip: four values, not nq = 6
    assert (
        cli.main(
            [
                "view",
                str(user_urdf),
                "--tool",
                "tool",
                "--q",
                "30",
                "10",
                "200",
                "20",
                "--deg",
                "--html",
                str(out),
            ]
        )
        == 0
    )
    assert out.is_file()
    assert (
        cli.main(
            ["view", str(user_urdf), "--tool", "tool", "--q", "1", "2", "3", "--html", str(out)]
        )
        == 2
    )
    assert "--q needs 4 values" in capsys.readouterr().err


def test_parse_q_maps_angles_to_cos_sin():
    r = aa.load("kinova")
    theta = np.deg2rad([170.0, 150.0, 60.0, -120.0, 90.0, 45.0])
    q = runtime.parse_q(r, np.rad2deg(theta).tolist(), deg=True)
    assert q.shape == (r.nq,)
    # oracle: Pinocchio's FK at the same angles built joint by joint
    qp = []
    for j, t in zip((r.model.joints[i] for i in range(1, r.model.njoints)), theta):
        qp += [np.cos(t), np.sin(t)] if j.nq == 2 else [t]
    np.testing.assert_allclose(q, qp, atol=1e-15)
    np.testing.assert_allclose(runtime.joint_values(r, q), theta, atol=1e-12)


def test_ik_on_continuous_joints_prints_one_angle_per_joint(capsys):
    r = aa.load("kinova")
    q = r.random_q(rng=1)
    d = r.model.createData()
    pin.framesForwardKinematics(r.model, d, q)
    M = d.oMf[r.tool_id]
    rpy = pin.rpy.matrixToRpy(M.rotation)
    rc = cli.main(
        ["ik", "kinova", "--xyz", *map(str, M.translation), "--rpy", *map(str, rpy), "--json"]
    )
    out = capsys.readouterr().out
    assert rc == 0, out

    res = json.loads(out)
    assert list(res["q"]) == r.joint_names and len(res["q"]) == 6 and res["method"] == "aa.ik.solve"
    qs = r.chain.configuration(np.array(list(res["q"].values())))
    pin.framesForwardKinematics(r.model, d, qs)
    assert np.linalg.norm(d.oMf[r.tool_id].translation - M.translation) < 1e-6
    # kinova's geometry (spherical wrist + two parallel axes) has a closed form: every branch
    # listed, as one angle per joint, reaches the pose by Pinocchio's FK
    assert res["closed_form_solutions"]
    for sol in res["closed_form_solutions"]:
        assert len(sol) == 6
        pin.framesForwardKinematics(r.model, d, r.chain.configuration(np.array(sol)))
        assert np.linalg.norm(d.oMf[r.tool_id].translation - M.translation) < 1e-6
        assert np.linalg.norm(pin.log3(d.oMf[r.tool_id].rotation.T @ M.rotation)) < 1e-6


def test_ik_book_arm_lists_its_closed_form_branches(capsys):
    r = aa.load("prosthetic_arm")
    T = r.fk(r.random_q(rng=4, margin=0.2))
    rpy = pin.rpy.matrixToRpy(T[:3, :3])
    rc = cli.main(
        ["ik", "prosthetic_arm", "--xyz", *map(str, T[:3, 3]), "--rpy", *map(str, rpy), "--json"]
    )

    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["success"]
    branches = np.array(res["closed_form_solutions"])
    assert len(branches) >= 1
    for qb in branches:  # every listed branch reaches the pose (Pinocchio)
        d = r.model.createData()
        pin.framesForwardKinematics(r.model, d, qb)
        assert np.linalg.norm(d.oMf[r.tool_id].translation - T[:3, 3]) < 1e-9
