"""A person's residual muscles in ``anthroarm size`` (issue 34 item 5): the torque the muscles
cover is the bounded least-squares optimum (against scipy's ``lsq_linear``, an independent
solver), for one joint the demand clipped to the muscles' range, a reachable demand is covered
whole; the study's demand is the sum of the muscles' and the motors' parts; bad input is a
typed error; the CLI end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import lsq_linear

import anthroarm as aa
from anthroarm import muscles
from anthroarm.cli import main
from anthroarm.dynamics.hand_model import minimum_jerk
from anthroarm.errors import MuscleError
from anthroarm.prosthesis import study
from anthroarm.prosthesis.residual import ResidualMuscles, parse_joints

ARM26 = aa.osim.path("arm26")


@pytest.fixture(scope="module")
def person():
    return aa.load("human_arm7", height=1.75, mass=70.0, sex="male")


def _B_p(rm, C, cols, sign):
    """The muscles' torque τ = B a + p about the mapped coordinates, from anthroarm.muscles
    (moment arms and forces checked against OpenSim in tests/muscles)."""
    L, R = muscles.lengths_and_moment_arms(rm.robot, rm.muscles, C)
    FA, FP = muscles.force_coefficients(rm.muscles, L)
    Rk = R[:, :, cols] * sign
    return np.einsum("nmj,nm->njm", Rk, rm.strength * FA), np.einsum(
        "nmj,nm->nj", Rk, rm.strength * FP
    )


def test_one_joint_is_the_demand_clipped_to_the_muscles_range(person):
    rm = ResidualMuscles.from_osim(ARM26, "elbow_flexion=r_elbow_flex", ["BIClong", "BRA"], 0.4)
    n = 12
    q = np.zeros((n, person.nq))
    q[:, 3] = np.linspace(0.0, 2.0, n)
    tau = np.zeros((n, person.nv))
    tau[:, 3] = np.linspace(-6.0, 30.0, n)
    tau[:, 0] = 5.0  # an unmapped joint: all for the motor
    mus, motor = rm.cover(person.joint_names, q, tau)
    B, p = _B_p(rm, rm.coordinates(person.joint_names, q), [1], np.array([1.0]))
    lo = p[:, 0] + np.minimum(B[:, 0], 0).sum(axis=1)
    hi = p[:, 0] + np.maximum(B[:, 0], 0).sum(axis=1)
    assert np.abs(mus[:, 3] - np.clip(tau[:, 3], lo, hi)).max() < 1e-6
    assert np.any(tau[:, 3] > hi) and np.any((tau[:, 3] > lo) & (tau[:, 3] < hi))
    np.testing.assert_array_equal(mus[:, [0, 1, 2, 4, 5, 6]], 0.0)
    np.testing.assert_allclose(mus + motor, tau, rtol=0, atol=1e-12)
    rlo, rhi = rm.range(person.joint_names, q)
    assert np.abs(rlo[:, 3] - lo).max() < 1e-12 and np.abs(rhi[:, 3] - hi).max() < 1e-12


def test_two_joints_are_the_bounded_least_squares_optimum(person):
    rm = ResidualMuscles.from_osim(
        ARM26, "shoulder_flexion=-r_shoulder_elev,elbow_flexion=r_elbow_flex", strength=0.7
    )
    rng = np.random.default_rng(4)
    n = 6
    q = np.zeros((n, person.nq))
    q[:, 0] = -rng.uniform(0.0, 1.2, n)
    q[:, 3] = rng.uniform(0.2, 1.8, n)
    tau = np.zeros((n, person.nv))
    tau[:, [0, 3]] = rng.normal(0, 40, (n, 2))  # beyond the muscles, often
    mus, _ = rm.cover(person.joint_names, q, tau)
    B, p = _B_p(rm, rm.coordinates(person.joint_names, q), [0, 1], np.array([-1.0, 1.0]))
    for k in range(n):
        ref = lsq_linear(B[k], tau[k, [0, 3]] - p[k], bounds=(0, 1), tol=1e-14)
        best = np.sum((B[k] @ ref.x + p[k] - tau[k, [0, 3]]) ** 2)
        ours = np.sum((mus[k, [0, 3]] - tau[k, [0, 3]]) ** 2)
        assert ours <= best + 1e-6 * max(1.0, best), (k, ours, best)
    # a demand the muscles can make is covered whole
    a = rng.uniform(0.1, 0.9, (n, len(rm.muscles)))
    reach = np.zeros_like(tau)
    reach[:, [0, 3]] = np.einsum("njm,nm->nj", B, a) + p
    mus, motor = rm.cover(person.joint_names, q, reach)
    assert np.abs(motor).max() < 1e-6


def test_study_splits_the_demand(person):
    t = np.linspace(0, 1.0, 21)
    q0 = person.neutral()
    q, qd, qdd = minimum_jerk(q0, q0 + np.array([0.5, 0, 0, 1.0, 0, 0, 0]), 1.0, t)
    acts = [dict(name="lift", t=t, q=q, qd=qd, qdd=qdd)]
    rm = ResidualMuscles.from_osim(ARM26, "elbow_flexion=r_elbow_flex", ["BIClong"], 0.2)
    plain = study.run(person, acts, payload=1.0)
    st = study.run(person, acts, payload=1.0, residual=rm)
    a0, a1 = plain.activities[0], st.activities[0]
    np.testing.assert_allclose(a1.tau + a1.muscle_tau, a0.tau, atol=1e-9)
    assert np.abs(a1.muscle_tau[:, 3]).max() > 0.5
    [row] = st.muscles()
    assert row["joint"] == "elbow_flexion" and 0 < row["covered"] <= 1
    assert row["peak_demand"] == pytest.approx(np.abs(a0.tau[:, 3]).max())
    assert st.envelope.rows()[3]["peak_torque"] == pytest.approx(np.abs(a1.tau[:, 3]).max())
    assert "muscles" in st.summary() and "muscles" not in plain.summary()


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(joints="elbow_flexion=nope"), "coordinate 'nope'"),
        (dict(joints="elbow_flexion=r_elbow_flex", remaining=["BIClong", "XYZ"]), "XYZ"),
        (dict(joints="elbow_flexion=r_elbow_flex", strength=0.0), "strength"),
        (dict(joints="elbow_flexion=r_elbow_flex", strength=float("nan")), "strength"),
        (dict(joints="elbow_flexion"), "ARM_JOINT=OSIM_COORDINATE"),
        (dict(joints=","), "empty"),
    ],
)
def test_bad_input(kw, match):
    with pytest.raises(MuscleError, match=match):
        ResidualMuscles.from_osim(ARM26, **kw)


def test_parse_joints_and_unknown_arm_joint(person):
    assert parse_joints("a=b, c=-d") == {"a": ("b", 1.0), "c": ("d", -1.0)}
    rm = ResidualMuscles.from_osim(ARM26, "knee=r_elbow_flex")
    with pytest.raises(MuscleError, match="knee"):
        rm.cover(person.joint_names, np.zeros((1, 7)), np.zeros((1, 7)))


def test_cli_size_with_residual_muscles(tmp_path, capsys, person):
    t = np.linspace(0, 1.0, 21)
    q0 = person.neutral()
    q, _, _ = minimum_jerk(q0, q0 + np.array([0.3, 0, 0, 1.0, 0, 0, 0]), 1.0, t)
    traj = tmp_path / "lift.npz"
    np.savez(traj, t=t, q=q)
    out = tmp_path / "r.html"
    args = ["size", "--activities", str(traj), "--payload", "1", "--no-viewer", "--no-progress"]
    args += ["--out", str(out), "--muscles", str(ARM26), "--remaining", "BIClong,BICshort"]
    rc = main([*args, "--muscle-joints", "elbow_flexion=r_elbow_flex", "--strength", "0.3"])
    assert rc == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    elbow = summary["muscles"]["elbow_flexion"]
    assert list(summary["muscles"]) == ["elbow_flexion"]
    assert elbow["peak_muscle"] > 0 and 0 < elbow["covered"] <= 1
    assert "Residual muscles and motors" in out.read_text()
    # options of the muscles without --muscles, and --muscles without the joint map
    assert main(["size", "--strength", "0.5", "--out", str(out)]) == 2
    assert "--muscles" in capsys.readouterr().err
    assert main([*args]) == 2
    assert "--muscle-joints" in capsys.readouterr().err
