"""Scaling a person's arm: measured segment lengths (Pinocchio FK of the loaded model), and a
static C3D trial (in metres) of a person with known lengths fitted by least squares."""

import numpy as np
import pinocchio as pin
import pytest
from motion_synthetic import known_motion, pin_marker_positions

import anthroarm as aa
from anthroarm.errors import MarkerSetError
from anthroarm.ik.qp import comfortable_posture
from anthroarm.motion import MarkerTrajectories, default_marker_set, marker_ik, read_c3d, write_c3d
from anthroarm.motion.scaling import scale_from_static

TRUE = {"upperarm": 0.312, "forearm": 0.248, "hand": 0.095}


def test_measured_segment_lengths_set_the_model():
    robot = aa.load("human_arm7", height=1.68, mass=60, sex="female", segment_lengths=TRUE)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.zeros(robot.nq))
    np.testing.assert_allclose(
        data.oMf[robot.model.getFrameId("hand_point")].translation,
        [0, 0, -sum(TRUE.values())],
        atol=1e-12,
    )
    partial = aa.load("human_arm7", height=1.68, segment_lengths={"forearm": 0.25})
    default = aa.load("human_arm7", height=1.68)
    assert (
        partial.spec.params["l2"] == 0.25 and partial.spec.params["l1"] == default.spec.params["l1"]
    )
    # masses come from the body mass, unchanged by the lengths
    assert (
        abs(sum(j.mass for j in partial.chain.joints) - sum(j.mass for j in default.chain.joints))
        < 1e-12
    )
    with pytest.raises(ValueError, match="unknown segment .femur."):
        aa.load("human_arm7", segment_lengths={"femur": 0.4})
    with pytest.raises(ValueError, match="0.02"):
        aa.load("human_arm7", segment_lengths={"hand": float("nan")})


def test_static_trial_recovers_segment_lengths(tmp_path):
    person = aa.load("human_arm7", height=1.75, segment_lengths=TRUE)
    truth_markers = default_marker_set(person)
    q_static = comfortable_posture(person) + np.array([0.1, -0.1, 0.2, -0.4, 0.3, 0.05, 0.1])
    rng = np.random.default_rng(7)
    P = pin_marker_positions(person, truth_markers, np.tile(q_static, (100, 1)))
    P += rng.normal(0, 1e-3, P.shape)
    write_c3d(
        tmp_path / "static.c3d", MarkerTrajectories(truth_markers.names, P, rate=100.0), units="m"
    )
    static = read_c3d(tmp_path / "static.c3d")
    assert static.meta["units"] == "m"

    generic = aa.load("human_arm7", height=1.75)
    res = scale_from_static(generic, static)
    for k, L in TRUE.items():
        assert abs(res.segment_lengths[k] - L) < 1e-3, (k, res.segment_lengths[k], L)
    np.testing.assert_allclose(res.q, q_static, atol=0.02)
    assert res.rms < 1.5e-3  # the median of 100 noisy samples: ~0.1 mm + the fit

    # marker IK of a dynamic trial on the scaled model fits to the noise; on the generic one it
    # cannot
    _, Q = known_motion(person, n=60, seed=8)
    D = pin_marker_positions(person, truth_markers, Q) + rng.normal(
        0, 1e-3, (60, len(truth_markers), 3)
    )
    scaled = aa.load("human_arm7", **res.load_kwargs(generic))
    fit = marker_ik(scaled, MarkerTrajectories(truth_markers.names, D), res.marker_set)
    unscaled = marker_ik(
        generic, MarkerTrajectories(truth_markers.names, D), default_marker_set(generic)
    )
    # noise alone: the RMS marker distance of a 7-parameter fit to 30 coordinates with σ = 1 mm
    noise_rms = 1e-3 * np.sqrt(3 * (30 - 7) / 30)
    assert np.median(fit.rms) < 1.15 * noise_rms and np.median(unscaled.rms) > 3 * noise_rms
    assert np.sqrt(np.mean((fit.q[:, :4] - Q[:, :4]) ** 2)) < 0.02


def test_static_trial_without_hand_markers_leaves_the_hand_unscaled():
    person = aa.load("human_arm7", height=1.75, segment_lengths=TRUE)
    ms = default_marker_set(person)
    P = pin_marker_positions(person, ms, comfortable_posture(person))[0]
    P[[ms.names.index(n) for n in ("MC2", "MC3", "MC5")]] = np.nan
    res = scale_from_static(aa.load("human_arm7", height=1.75), P)
    assert set(res.segment_lengths) == {"upperarm", "forearm"}
    assert abs(res.segment_lengths["upperarm"] - TRUE["upperarm"]) < 1e-6
    with pytest.raises(MarkerSetError, match="no marker"):
        scale_from_static(aa.load("human_arm7"), np.full((len(ms), 3), np.nan))


def test_a_static_trial_that_does_not_fit_says_so(tmp_path, capsys):
    """A static trial three times too large (other units, another subject) hits the 2x bound and
    leaves centimetres of marker error: status large_error, and ik-markers --static refuses it."""
    from anthroarm.cli import main
    from anthroarm.errors import ParameterError

    arm = aa.load("human_arm7")
    ms = default_marker_set(arm)
    P = pin_marker_positions(arm, ms, comfortable_posture(arm))[0]
    assert scale_from_static(arm, P).status == "ok"
    big = scale_from_static(arm, 3 * P)
    assert big.status == "large_error" and big.rms > 0.02 and big.info["at_bound"]
    assert all(abs(f - 2.0) < 1e-6 for f in big.scales.values())
    near = scale_from_static(arm, 3 * P, max_rms=1e3)  # only the bound is left to say it
    assert near.status == "at_bound"
    for bad in ({"bounds": (1.2, 2.0)}, {"bounds": (0.5,)}, {"max_rms": -1.0}):
        with pytest.raises(ParameterError):
            scale_from_static(arm, P, **bad)
    with pytest.raises(ValueError, match="numbers"):
        scale_from_static(arm, [["a", "b", "c"]] * len(ms))
    write_c3d(tmp_path / "static.c3d", MarkerTrajectories(ms.names, np.repeat(3 * P[None], 10, 0)))
    write_c3d(tmp_path / "trial.c3d", MarkerTrajectories(ms.names, np.repeat(P[None], 10, 0)))
    rc = main(
        [
            "ik-markers",
            str(tmp_path / "trial.c3d"),
            "--out",
            str(tmp_path / "a.csv"),
            "--static",
            str(tmp_path / "static.c3d"),
            "--no-progress",
        ]
    )
    err = capsys.readouterr().err
    assert (
        rc == 2
        and "large_error" in err
        and err.count("\n") == 1
        and not (tmp_path / "a.csv").exists()
    )
