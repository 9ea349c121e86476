"""Marker IK on synthetic trials: markers by Pinocchio FK of a known motion (+ noise), written to
and read back from real C3D files (mm), solved, compared with the known angles, with the
noise-propagation bound σ·sqrt(diag((JᵀJ)⁻¹)) and with scipy's unconstrained least squares."""

import numpy as np
import pinocchio as pin
import pytest
from motion_synthetic import known_motion, pin_marker_positions
from scipy.optimize import least_squares

from anthroarm.errors import MarkerSetError, MotionDataError, UnconstrainedJointError
from anthroarm.ik.qp import MarkerTask, comfortable_posture
from anthroarm.motion import (
    Marker,
    MarkerIK,
    MarkerSet,
    MarkerTrajectories,
    marker_ik,
    read_c3d,
    write_c3d,
)


def _trial(robot, markers, tmp_path, sigma=0.0, n=200, seed=0, units="mm"):
    t, Q = known_motion(robot, n=n, seed=seed)
    P = pin_marker_positions(robot, markers, Q)
    P = P + np.random.default_rng(seed + 1).normal(0.0, sigma, P.shape) if sigma else P
    path = tmp_path / f"synthetic_{seed}_{units}.c3d"
    write_c3d(path, MarkerTrajectories(markers.names, P, rate=100.0), units=units)
    return Q, P, read_c3d(path)


def test_marker_positions_and_jacobian_match_pinocchio(arm, markers):
    """BoundMarkers/MarkerTask positions = Pinocchio frame placements; the task Jacobian = central
    finite differences of those placements."""
    _, Q = known_motion(arm, n=5, seed=3)
    b = markers.bind(arm)
    np.testing.assert_allclose(
        b.world_positions(Q), pin_marker_positions(arm, markers, Q), atol=1e-14
    )
    conf = __import__("anthroarm").ik.qp.IKConfiguration(arm, Q[2])
    task = MarkerTask(arm, b.joint, b.local)
    task.set_target(np.zeros((len(markers), 3)))
    J = task.compute_jacobian(conf)
    h = 1e-6
    Jfd = np.empty_like(J)
    for i in range(arm.nv):
        dq = np.zeros(arm.nv)
        dq[i] = h
        pp = pin_marker_positions(arm, markers, pin.integrate(arm.model, Q[2], dq))[0]
        pm = pin_marker_positions(arm, markers, pin.integrate(arm.model, Q[2], -dq))[0]
        Jfd[:, i] = ((pp - pm) / (2 * h)).ravel()
    np.testing.assert_allclose(J, Jfd, atol=1e-8)
    np.testing.assert_allclose(b.jacobian(Q[2]), J, atol=1e-14)
    # a configuration whose q is changed in place and updated: the task follows it (no stale cache)
    conf.q[:] = Q[4]
    conf.update()
    np.testing.assert_allclose(
        task.positions(conf), pin_marker_positions(arm, markers, Q[4])[0], atol=1e-14
    )
    np.testing.assert_allclose(task.compute_jacobian(conf), b.jacobian(Q[4]), atol=1e-14)


def test_noise_free_trial_recovers_the_motion(arm, markers, tmp_path):
    Q, P, trial = _trial(arm, markers, tmp_path)
    assert trial.meta["units"] == "mm"
    np.testing.assert_allclose(trial.positions, P, atol=1e-6)  # float32 mm in the file
    res = marker_ik(arm, trial, markers)
    assert (res.status == "ok").all()
    assert np.max(np.abs(res.q - Q)) < 1e-4  # float32 storage of the file
    assert res.rms.max() < 1e-6


def test_noisy_trial_error_is_the_noise_propagation_bound(arm, markers, tmp_path):
    """With σ = 1 mm per coordinate, the linearised LS estimate has covariance σ²(JᵀJ)⁻¹; the
    per-joint RMS angle error over the trial must match sqrt(mean diag) within sampling spread."""
    sigma = 1e-3
    Q, P, trial = _trial(arm, markers, tmp_path, sigma=sigma, n=300, seed=1)
    res = marker_ik(arm, trial, markers)
    assert (res.status == "ok").all()
    err = np.sqrt(np.mean((res.q - Q) ** 2, axis=0))
    b = markers.bind(arm)
    var = np.mean(
        [np.diag(np.linalg.inv(b.jacobian(q).T @ b.jacobian(q))) for q in Q[::10]], axis=0
    )
    pred = sigma * np.sqrt(var)
    ratio = err / pred
    assert np.all(ratio > 0.7) and np.all(ratio < 1.4), (err, pred)
    # the residual of a 7-parameter least-squares fit to 30 noisy coordinates (10 markers, the
    # acromion's 3 on the fixed trunk included) is σ²·χ²(30 − 7) per frame, so the frame's RMS
    # over the 10 markers is σ·sqrt(χ²₂₃ / 10): its median over 300 frames is near σ·sqrt(median
    # χ²₂₃ / 10)
    from scipy.stats import chi2

    expected_rms = sigma * np.sqrt(chi2.median(3 * len(markers) - arm.nv) / len(markers))
    assert 0.95 < np.median(res.rms) / expected_rms < 1.05


def test_agrees_with_scipy_unconstrained_least_squares(arm, markers, tmp_path):
    """Same frames, scipy.optimize.least_squares (no limits, trust-region reflective, residuals by
    Pinocchio FK here): the two minimisers agree far below the noise's effect."""
    Q, P, trial = _trial(arm, markers, tmp_path, sigma=1.5e-3, n=40, seed=2)
    res = marker_ik(arm, trial, markers, tol=1e-9)
    moving = [k for k, m in enumerate(markers) if m.body != "base_link"]
    for n in range(0, 40, 4):

        def fun(q, n=n):
            return (pin_marker_positions(arm, markers, q)[0] - trial.positions[n])[moving].ravel()

        sol = least_squares(fun, Q[n], xtol=1e-12, ftol=1e-12, gtol=1e-12)
        assert np.all(sol.x >= arm.lower) and np.all(sol.x <= arm.upper)  # limits inactive here
        np.testing.assert_allclose(res.q[n], sol.x, atol=2e-5)
        d_scipy = np.linalg.norm(fun(sol.x).reshape(-1, 3), axis=1)
        np.testing.assert_allclose(res.marker_error[n, moving], d_scipy, atol=1e-7)


def test_joint_limits_hold_where_the_markers_ask_beyond_them(arm, markers):
    """Markers of a posture with the elbow hyper-extended 25° past its −5° limit: the solution
    stops at the limit (a box-constrained least squares), the unconstrained optimum does not."""
    q = comfortable_posture(arm)
    i = arm.joint_names.index("elbow_flexion")
    q_bad = q.copy()
    q_bad[i] = arm.lower[i] - np.deg2rad(25)
    P = pin_marker_positions(arm, markers, q_bad)
    res = marker_ik(arm, P, markers)
    assert np.all(res.q >= arm.lower - 1e-9) and np.all(res.q <= arm.upper + 1e-9)
    assert abs(res.q[0, i] - arm.lower[i]) < 1e-6
    assert res.rms[0] > 1e-3  # the markers cannot be matched inside the limits


def test_gaps_nan_frames_and_too_few_markers(arm, markers, tmp_path):
    Q, P, _ = _trial(arm, markers, tmp_path, n=60, seed=4)
    P = P.copy()
    names = list(markers.names)
    P[10:20, names.index("MC5")] = np.nan  # a gap: still determined
    P[30:33] = np.nan  # whole frames lost
    for nm in ("MC2", "MC3", "MC5"):  # hand unseen: wrist undetermined
        P[40:45, names.index(nm)] = np.nan
    path = tmp_path / "gaps.c3d"
    write_c3d(path, MarkerTrajectories(markers.names, P, rate=100.0))
    trial = read_c3d(path)
    assert not trial.visible[30].any() and trial.visible[10].sum() == len(markers) - 1
    res = marker_ik(arm, trial, markers)
    assert np.isfinite(res.q).all()
    assert (res.status[10:20] == "ok").all() and np.max(np.abs(res.q[10:20] - Q[10:20])) < 1e-4
    assert (res.status[30:33] == "skipped").all()
    np.testing.assert_array_equal(res.q[30], res.q[29])  # held
    assert np.isnan(res.rms[30:33]).all() and (res.n_markers[30:33] == 0).all()
    assert (res.status[40:45] == "too_few_markers").all()
    # the shoulder and elbow are still seen: those angles stay right
    assert np.max(np.abs(res.q[40:45, :4] - Q[40:45, :4])) < 1e-4
    assert (res.status[50:] == "ok").all() and np.max(np.abs(res.q[50:] - Q[50:])) < 1e-4
    assert res.counts()["skipped"] == 3


def test_renamed_and_missing_markers(arm, markers, tmp_path):
    Q, P, _ = _trial(arm, markers, tmp_path, n=10, seed=5)
    labels = [f"Subject1:{n}" for n in markers.names]
    labels[labels.index("Subject1:FA")] = "FOREARM"
    trial = MarkerTrajectories(labels, P, rate=100.0)
    res = marker_ik(arm, trial, markers, rename={"FOREARM": "FA"})
    assert res.missing_markers == () and np.max(np.abs(res.q - Q)) < 1e-5
    with pytest.raises(MarkerSetError, match=r"\['FX'\], which are not markers"):
        marker_ik(arm, trial, markers, rename={"FOREARM": "FX"})  # a typo in the target
    res2 = marker_ik(arm, trial, markers)  # FA not found: solved without it
    assert res2.missing_markers == ("FA",) and (res2.status == "ok").all()
    no_hand = MarkerTrajectories(
        [n for n in markers.names if not n.startswith("MC")],
        P[:, [k for k, n in enumerate(markers.names) if not n.startswith("MC")]],
    )
    with pytest.raises(UnconstrainedJointError) as ei:
        marker_ik(arm, no_hand, markers)
    assert set(ei.value.joints) == {"wrist_deviation", "wrist_flexion"}
    with pytest.raises(MarkerSetError, match="none of the markers"):
        marker_ik(arm, MarkerTrajectories(["X", "Y"], P[:, :2]), markers)


def test_a_set_that_does_not_constrain_a_joint_is_refused(arm):
    upper_only = MarkerSet(
        [Marker("EL", "upper_arm", (0.03, 0, -0.28)), Marker("EM", "upper_arm", (-0.03, 0, -0.28))]
    )
    with pytest.raises(UnconstrainedJointError) as ei:
        MarkerIK(arm, upper_only)
    assert set(ei.value.joints) == {
        "forearm_pronation",
        "wrist_deviation",
        "wrist_flexion",
        "elbow_flexion",
    }
    # every joint has a marker below it, but the forearm and hand markers lie on the long axis
    # (the wrist is straight at the reference posture): pronation is invisible (rank deficiency,
    # found numerically)
    on_axis = MarkerSet(
        [
            Marker("EL", "upper_arm", (0.03, 0, -0.28)),
            Marker("EM", "upper_arm", (-0.03, 0, -0.28)),
            Marker("W", "forearm", (0, 0, -0.27)),
            Marker("H", "hand", (0.0, 0.0, -0.08)),
        ]
    )
    with pytest.raises(UnconstrainedJointError, match="rank"):
        MarkerIK(arm, on_axis)
    # forced through (check=False), every frame of a straight-wrist motion is flagged, not "ok"
    _, Q = known_motion(arm, n=5, seed=6)
    Q[:, arm.joint_names.index("wrist_deviation") :] = 0.0
    res = marker_ik(arm, pin_marker_positions(arm, on_axis, Q), on_axis, check=False)
    assert (res.status == "too_few_markers").all() and res.rms.max() < 1e-6
    with pytest.raises(MarkerSetError, match="frames"):
        MarkerSet([Marker("A", "no_such_body", (0, 0, 0))]).bind(arm)
    with pytest.raises(MarkerSetError, match="duplicate"):
        MarkerSet([Marker("A", "hand", (0, 0, 0)), Marker("A", "hand", (0, 0, 1))])
    with pytest.raises(MarkerSetError, match="finite"):
        MarkerSet([Marker("A", "hand", (0, np.nan, 0))])


def test_array_input_checks(arm, markers):
    with pytest.raises(MotionDataError, match="shape"):
        marker_ik(arm, np.zeros((5, 3, 3)), markers)
    from anthroarm.errors import ParameterError

    for bad in ({"seeds": -1}, {"seeds": "24"}, {"max_iter": 2.5}, {"tol": float("nan")}):
        with pytest.raises(ParameterError, match=next(iter(bad))):
            MarkerIK(arm, markers, **bad)
    P = pin_marker_positions(arm, markers, comfortable_posture(arm))
    P[0, 2] = np.inf  # an inf sample is a missing one
    res = marker_ik(arm, P, markers)
    assert res.n_markers[0] == len(markers) - 1 and np.isfinite(res.q).all()


def test_first_frame_far_from_the_comfortable_posture(arm, markers):
    """Marker IK is non-convex: a first frame anywhere in the joint range is found by the
    multi-start (a single Gauss–Newton start from the comfortable posture fails on some)."""
    Q = arm.random_q(25, rng=11, margin=0.05)
    P = pin_marker_positions(arm, markers, Q)
    single = [marker_ik(arm, P[i : i + 1], markers, seeds=0) for i in range(25)]
    multi = [marker_ik(arm, P[i : i + 1], markers) for i in range(25)]
    assert sum(np.abs(r.q[0] - Q[i]).max() > 1e-3 for i, r in enumerate(single)) >= 2
    for i, r in enumerate(multi):
        assert np.abs(r.q[0] - Q[i]).max() < 1e-4 and r.status[0] == "ok"


def test_swapped_labels_give_large_error_frames(arm, markers):
    _, Q = known_motion(arm, n=30, seed=12)
    P = pin_marker_positions(arm, markers, Q)
    el, rs = markers.names.index("EL"), markers.names.index("RS")
    P[10:13, [el, rs]] = P[10:13, [rs, el]]  # mislabelled for three frames
    res = marker_ik(arm, P, markers)
    assert (res.status[10:13] == "large_error").all() and (res.rms[10:13] > 0.02).all()
    assert (res.status[13:] == "ok").all() and np.abs(res.q[13:] - Q[13:]).max() < 1e-4


def test_default_set_is_the_models_table_scaled_by_chain_lengths():
    """The landmark table lives in models.human; its fractions times the segment lengths the
    builder used (spec.params l1, l2, l3) give the set, for human_arm7 and for human_upper_limb
    (whose hand also carries finger joints: the hand's length ends at its hand point, the tool)."""
    import anthroarm as aa
    from anthroarm.models.human import HUMAN_ARM_LANDMARKS
    from anthroarm.motion import default_marker_set, human_arm_markers, segment_length

    for name in ("human_arm7", "human_upper_limb"):
        robot = aa.load(name, height=1.62, mass=55, sex="female")
        p = robot.spec.params
        L = {"base_link": p["l1"], "upper_arm": p["l1"], "forearm": p["l2"], "hand": p["l3"]}
        ms = default_marker_set(robot)
        assert ms.names == tuple(HUMAN_ARM_LANDMARKS)
        for m in ms:
            body, frac, _w, _d = HUMAN_ARM_LANDMARKS[m.name]
            np.testing.assert_allclose(m.position, np.array(frac) * L[body], atol=1e-15)
    # with the tool on a finger the hand branches to five joints at different distances: ambiguous
    with pytest.raises(MarkerSetError, match="ambiguous"):
        segment_length(aa.load("human_upper_limb", tool="index_tip"), "hand")
    with pytest.raises(MarkerSetError, match="needs the links"):
        human_arm_markers(aa.load("prosthetic_arm"))
