"""Static optimisation against OpenSim 4.6's ``StaticOptimization`` analysis (issue 34): the
shipped gait trial, ``subject01_simbody.osim`` (Gait2354, 54 Thelen2003 muscles, 23
coordinates) moving through OpenSim's own IK result ``subject01_walk1_ik.mot``, frames
0.60-0.75 s (10 frames at 60 Hz).

What both sides are given:

* OpenSim (:mod:`anthroarm.muscles.opensim_oracle`): ``AnalyzeTool`` on the .mot, no
  low-pass filter (``lowpass_cutoff_frequency`` -1), no external loads (the pipeline's GRF
  file is not shipped), ``StaticOptimization`` with
  ``use_model_force_set``, activation exponent 2, ``use_muscle_physiology`` on, convergence
  criterion 1e-10; the model's 54 muscles plus one ``CoordinateActuator`` per coordinate
  (bounds ±1e6): optimal force 1000 on the six pelvis coordinates (residuals: without ground
  reactions they hold the body up) and 1 on the 17 others (reserves).
* ours: :func:`anthroarm.muscles.static_optimization` with the same reserve strengths, q at the
  frames, q̇ and q̈ as the AnalyzeTool forms them (q̇ the derivative of a degree-5 GCV spline
  of the coordinates, ``GCVSplineSet(5, ·).constructStorage(1)``; q̈ that of a GCV spline of q̇,
  as ``StaticOptimization::begin`` builds its target accelerations), τ by our own inverse
  dynamics (``robot.inverse_dynamics``, Pinocchio), and OpenSim's problem: the muscles'
  force-velocity at q̇ (``qd``), no passive forces (OpenSim overrides each muscle's whole force
  with a·F_A: ``passive=False``), activations bounded below by each muscle's ``min_control``
  (= ``minimum_activation`` 0.01, ``lower``).

The objectives are then the same: Σ aᵢ² over muscles and reserve controls, forces a·F_A with
F_A = ``calcInextensibleTendonActiveFiberForce(s, 1)`` (f_L f_V cos φ F₀), and OpenSim's
acceleration constraints are our τ equations (M q̈ + h = τ).  The issue's target: activations
within 1e-3 of OpenSim's; measured 1.9e-5 at most (a muscle 1e-4 above its 0.01 floor, where
OpenSim's interior-point solver, IPOPT, stops short of the bound; 1e-6 elsewhere: OpenSim
prints 8 significant digits and its f_V inverse stops at 1e-6).  Both answers are KKT points
of the problem (ours ~1e-11; OpenSim's IPOPT, warm started, stops short of the optimum on a few
frames elsewhere in the trial, e.g. 0.55 s: benchmarks/results/muscles.md).  OpenSim's run
takes ~2 s.
"""

from __future__ import annotations

import numpy as np
import pytest

opensim = pytest.importorskip("opensim")

import anthroarm as aa  # noqa: E402
from anthroarm import muscles  # noqa: E402
from anthroarm.errors import MuscleError  # noqa: E402
from anthroarm.muscles.opensim_oracle import (  # noqa: E402
    opensim_kinematics,
    opensim_static_optimization,
    stationarity,
)

T0, T1 = 0.60, 0.75


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    out = tmp_path_factory.mktemp("so_vs_opensim")
    path = aa.osim.path("subject01_simbody")
    mot = path.parent / "recordings" / "subject01_walk1_ik.mot"
    robot = aa.load(path)
    ms = muscles.read_muscles(path)
    names = robot.joint_names
    strength = np.array([1000.0 if n.startswith("pelvis") else 1.0 for n in names])

    os_so = opensim_static_optimization(
        path, mot, names, strength, ms.names, T0, T1, out, criterion=1e-10, states=True
    )
    # the AnalyzeTool's q, q̇ (GCV spline of q) and StaticOptimization's q̈ (GCV spline of q̇)
    Q, QD, QDD = opensim_kinematics(path, mot, names, os_so.time)
    assert len(os_so) == 10
    return dict(
        robot=robot,
        ms=ms,
        strength=strength,
        Q=Q,
        QD=QD,
        QDD=QDD,
        opensim=os_so,
        tau=np.array([robot.inverse_dynamics(*x) for x in zip(Q, QD, QDD)]),
    )


def test_same_states_and_dynamics(trial):
    # q and q̇ are OpenSim's states (to the 1e-8 of its printed storage)
    assert np.abs(trial["opensim"].states_q - trial["Q"]).max() < 1e-7
    assert np.abs(trial["opensim"].states_u - trial["QD"]).max() < 1e-7
    # OpenSim's solution meets our inverse-dynamics torques: Rᵀ f + reserves = τ
    R = muscles.moment_arms(trial["robot"], trial["ms"], trial["Q"])
    total = np.einsum("nmk,nm->nk", R, trial["opensim"].force) + trial["opensim"].reserve
    scale = 1.0 + np.abs(trial["tau"])
    assert np.abs((total - trial["tau"]) / scale).max() < 1e-4


def test_activations_match_opensim(trial):
    so = muscles.static_optimization(
        trial["robot"],
        trial["ms"],
        trial["Q"],
        trial["tau"],
        reserve=trial["strength"],
        qd=trial["QD"],
        passive=False,
        lower=[m.params["minimum_activation"] for m in trial["ms"].muscles],
    )
    assert all(s == "optimal" for s in so.status)
    theirs = trial["opensim"]
    err = np.abs(so.activation - theirs.activation)
    assert err.max() < 1e-3, err.max()  # the target
    assert err.max() < 1e-4  # measured 1.9e-5 (grac_r at 0.0101, next to its bound 0.01)
    # the muscles carry the legs: activations well above the floor on several muscles
    assert (theirs.activation > 0.1).sum() >= 10
    # the same optimum: equal objectives (OpenSim's meets the dynamics to ~1e-6 N m, which
    # moves its objective by ~1e-6 relative), and both answers are KKT points of the problem
    j_os = (theirs.activation**2).sum(1) + ((theirs.reserve / trial["strength"]) ** 2).sum(1)
    j_ours = (so.activation**2).sum(1) + ((so.reserve_torque / trial["strength"]) ** 2).sum(1)
    assert np.all(np.abs(j_os - j_ours) < 1e-5 * j_os), j_ours - j_os
    L, R = muscles.lengths_and_moment_arms(trial["robot"], trial["ms"], trial["Q"])
    FA, _ = muscles.force_coefficients(trial["ms"], L, -np.einsum("nmk,nk->nm", R, trial["QD"]))
    M = len(trial["ms"])
    lower = np.array([m.params["minimum_activation"] for m in trial["ms"].muscles])
    for k in range(len(R)):
        C = np.hstack([R[k].T * FA[k], np.diag(trial["strength"])])
        ours = np.concatenate([so.activation[k], so.reserve_torque[k] / trial["strength"]])
        x_os = np.concatenate([theirs.activation[k], theirs.reserve[k] / trial["strength"]])
        assert stationarity(ours, C, M, lower) < 1e-8
        assert stationarity(x_os, C, M, lower) < 1e-4
    np.testing.assert_allclose(so.force, theirs.force, rtol=1e-4, atol=1e-2)
    np.testing.assert_allclose(so.reserve_torque, theirs.reserve, rtol=1e-4, atol=1e-3)


def test_the_problem_differs_without_those_options(trial):
    """Each option matters: at rest (no force-velocity), or with passive forces, the answer is
    not OpenSim's."""
    args = (trial["robot"], trial["ms"], trial["Q"], trial["tau"])
    for kw in ({"qd": None, "passive": False}, {"qd": trial["QD"], "passive": True}):
        so = muscles.static_optimization(*args, reserve=trial["strength"], lower=0.01, **kw)
        assert np.abs(so.activation - trial["opensim"].activation).max() > 1e-2


def test_oracle_refuses_bad_input(tmp_path):
    """OpenSim's side (:mod:`anthroarm.muscles.opensim_oracle`) given a strength per coordinate
    that is missing or not positive, an empty time range, times that are not rows of the
    motion, or a muscle OpenSim did not report: a MuscleError, before or instead of a run."""
    path = aa.osim.path("arm26")
    mot = aa.osim.path("subject01_simbody").parent / "recordings" / "subject01_walk1_ik.mot"
    names = ["r_shoulder_elev", "r_elbow_flex"]
    args = (path, mot, names)
    with pytest.raises(MuscleError, match="strength"):
        opensim_static_optimization(*args, [1.0], ["BIClong"], 0.0, 1.0, tmp_path)
    with pytest.raises(MuscleError, match="strength"):
        opensim_static_optimization(*args, [1.0, 0.0], ["BIClong"], 0.0, 1.0, tmp_path)
    with pytest.raises(MuscleError, match="empty"):
        opensim_static_optimization(*args, [1.0, 1.0], ["BIClong"], 1.0, 1.0, tmp_path)
    gait = aa.osim.path("subject01_simbody")
    with pytest.raises(MuscleError, match="not rows"):
        opensim_kinematics(gait, mot, ["hip_flexion_r"], [0.601234])
    with pytest.raises(MuscleError, match="no column 'not_a_coordinate'"):
        opensim_kinematics(gait, mot, ["not_a_coordinate"], [0.6])
