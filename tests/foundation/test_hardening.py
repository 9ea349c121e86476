"""Issue 12 (hardening), loader side: argument abuse gets typed errors, random_q stays inside
the limits, yourdfpy reads the validated text, and the reach bound counts axis-aligned sliders."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import errors


@pytest.fixture(scope="module")
def arm():
    return aa.load("prosthetic_arm")


@pytest.mark.parametrize(
    "args, kw, needle",
    [
        ((-1,), {}, "count >= 0"),
        ((2.5,), {}, "whole number"),
        (("3",), {}, "whole number"),
        ((True,), {}, "whole"),
        ((None,), {"margin": 5}, "more than half the range"),
        ((None,), {"margin": -1}, ">= 0"),
        ((None,), {"margin": float("nan")}, "finite"),
        ((None,), {"margin": float("inf")}, "finite"),
        ((None,), {"margin": "x"}, "a number"),
    ],
)
def test_random_q_rejects_bad_counts_and_margins(arm, args, kw, needle):
    with pytest.raises(errors.ParameterError, match=needle):
        arm.random_q(*args, **kw)


def test_random_q_margin_keeps_samples_inside(arm):
    half = float(np.min(arm.upper - arm.lower)) / 2
    q = arm.random_q(500, rng=0, margin=0.9 * half)
    assert q.shape == (500, arm.nq) and np.all(arm.within_limits(q, tol=-0.9 * half + 1e-12))
    assert arm.random_q(0, rng=0).shape == (0, arm.nq)
    assert arm.random_q(np.int64(3), rng=0).shape == (3, arm.nq)


@pytest.mark.parametrize(
    "kw, needle",
    [
        ({"tool": 123}, "tool= is a frame name"),
        ({"active": "abc"}, "active= is a list"),
        ({"active": 5}, "active= is a list"),
        ({"active": [1, 2]}, "joint names"),
        ({"locked": {"elbow_flexion": "x"}}, "must be a number"),
        ({"locked": {"elbow_flexion": float("nan")}}, "finite"),
        ({"locked": {"elbow_flexion": [1, 2]}}, "1 finite number"),
        ({"locked": 5}, "locked= is a list"),
        ({"locked": "elbow_flexion"}, "locked= is a list"),
        ({"package_dirs": {"x": None}}, "root of package 'x'"),
        ({"package_dirs": {"": "/"}}, "not a package name"),
        ({"name": 5}, "name= is a str"),
        ({"check_meshes": "no"}, "check_meshes"),
    ],
)
def test_loader_argument_abuse_is_a_parameter_error(kw, needle):
    with pytest.raises(errors.ParameterError, match=needle):
        aa.load("prosthetic_arm", **kw)


def test_pin_model_with_too_many_joints_is_refused_before_allocating():
    """Pinocchio's data grows as n³ (1000 joints: an out-of-memory kill); refused up front."""
    m = pin.Model()
    j = 0
    for i in range(201):
        j = m.addJoint(j, pin.JointModelRZ(), pin.SE3.Identity(), f"j{i}")
    with pytest.raises(errors.UnsupportedModelError, match="at most 200"):
        aa.load(m)


def test_urdf_of_a_robot_is_the_validated_text_not_the_file_now(tmp_path):
    """robot.urdf (yourdfpy) reads the text that was validated and built, not the file again."""
    src = aa.models.REPO_URDF_DIR / "rrprr5.urdf"
    p = tmp_path / "arm.urdf"
    p.write_text(src.read_text(encoding="utf-8"), encoding="utf-8")
    r = aa.load(str(p))
    other = (aa.models.REPO_URDF_DIR / "planar2r.urdf").read_text(encoding="utf-8")
    p.write_text(other, encoding="utf-8")  # swapped after loading
    u = r.urdf
    assert set(u.actuated_joint_names) == set(r.joint_names)
    q = r.random_q(rng=3)
    u.update_cfg(r.yourdfpy_cfg(q))
    link = [f.name for f in r.chain.frames if f.is_body][-1]
    np.testing.assert_allclose(u.get_transform(link), r.fk(q, link), atol=1e-12)


@pytest.mark.parametrize("name", ["rrprr5", "unimate5"])
def test_reach_counts_axis_aligned_sliders_and_ik_does_not_refuse_reachable_poses(name):
    """Pinocchio builds an axis-aligned prismatic joint as JointModelPX/PY/PZ; the reach bound
    counts its travel (Joint.kind == "prismatic"), so no reachable pose is out_of_reach."""
    r = aa.load(name)
    kinds = {
        r.model.joints[j.index + 1].shortname() for j in r.chain.joints if j.kind == "prismatic"
    }
    assert kinds and kinds <= {"JointModelPX", "JointModelPY", "JointModelPZ"}, kinds
    q = r.random_q(2000, rng=0)
    far = float(np.max(np.linalg.norm(r.fk(q)[:, :3, 3], axis=1)))
    travel = sum(max(abs(j.lower), abs(j.upper)) for j in r.chain.joints if j.kind == "prismatic")
    assert far <= r.chain.reach() + 1e-12
    assert r.chain.reach() >= far and r.chain.reach() >= travel
    statuses = []
    for qi in r.random_q(200, rng=1):
        res = aa.ik.solve(r, r.fk(qi))
        statuses.append(res.status)
        assert res.q is None or np.all(np.isfinite(res.q))
    assert "out_of_reach" not in statuses, statuses.count("out_of_reach")
