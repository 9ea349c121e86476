"""Marker IK on a real gait trial against OpenSim's own IK (issue 32 item 6).

The trial is the Gait2354 pipeline's ``subject01_walk1.trc`` with its ``Setup_IK.xml``
(31 marker weights, 4 coordinate tasks, 0.4-1.6 s: 73 frames), on the scaled subject01 model it
was recorded for, loaded by ``aa.load`` (knee translations are splines of the knee angle).
OpenSim 4.6 solves the same frames with the same weights (``InverseKinematicsSolver`` as its
``InverseKinematicsTool`` sets it up; the tool itself is run once too).  Required: per-frame
marker RMS error <= OpenSim's + 0.1 mm, coordinates within 0.5 deg RMS of OpenSim's.
"""

import numpy as np
import pinocchio as pin
import pytest
from osim_recordings_data import MODEL, SETUP, TRC

import anthroarm as aa
from anthroarm import osim as aosim
from anthroarm.errors import MarkerSetError, ParameterError, UnconstrainedJointError
from anthroarm.motion import (
    CoupledMarkerIK,
    MarkerIK,
    MarkerTrajectories,
    body_poses,
    opensim_ik,
    opensim_tool,
    osim_marker_ik,
    osim_marker_set,
    read_ik_setup,
    read_storage,
    read_trc,
    rotational_coordinates,
    write_mot,
)
from anthroarm.motion.osim_ik import FastCoupling


@pytest.fixture(scope="module")
def walk(osim):
    robot = aa.load(str(MODEL))
    trial = read_trc(TRC)
    setup = read_ik_setup(SETUP)
    ours = osim_marker_ik(robot, trial, setup)
    ref = opensim_ik(MODEL, TRC, setup)
    return robot, trial, setup, ours, ref


def _in_order(robot, ref):
    """OpenSim's coordinates in the robot's q order."""
    return ref.q[:, [ref.coordinates.index(n) for n in robot.joint_names]]


def test_same_frames_markers_and_all_solved(walk):
    robot, trial, setup, ours, ref = walk
    assert len(ours) == len(ref) == 73
    np.testing.assert_array_equal(ours.time, ref.time)
    assert set(ours.marker_names) == set(ref.markers) and len(ref.markers) == 31
    assert ours.missing_markers == ()
    assert ours.counts()["ok"] == 73


def test_marker_error_not_above_opensims(walk):
    robot, trial, setup, ours, ref = walk
    excess = ours.rms - ref.rms
    assert excess.max() <= 1e-4, f"worst frame {excess.argmax()}: {excess.max() * 1e3:.4f} mm"
    # the frames' errors are OpenSim's to a few micrometres: the same optimum
    assert np.abs(excess).max() < 2e-5


def test_coordinates_within_half_a_degree_of_opensims(walk):
    robot, trial, setup, ours, ref = walk
    d = ours.q - _in_order(robot, ref)
    rot = np.array([n in rotational_coordinates(robot) for n in robot.joint_names])
    assert rot.sum() == 20 and (~rot).sum() == 3  # pelvis_tx/ty/tz are lengths
    angle_rms = np.rad2deg(np.sqrt(np.mean(d[:, rot] ** 2, axis=0)))
    assert angle_rms.max() < 0.5, dict(zip(np.array(robot.joint_names)[rot], angle_rms))
    assert np.sqrt(np.mean(d[:, ~rot] ** 2)) < 1e-3  # m


def test_opensims_tool_gives_the_reference(walk, tmp_path):
    """The reference is what OpenSim's InverseKinematicsTool writes from the setup file."""
    robot, trial, setup, ours, ref = walk
    out, _ = opensim_tool(SETUP, MODEL, TRC, tmp_path)
    table = read_storage(out)
    q_tool = table.to_q(robot)
    # the .mot keeps 8 decimals of degrees
    np.testing.assert_allclose(q_tool, _in_order(robot, ref), rtol=0, atol=1e-6)


def test_written_motion_reproduces_our_markers_in_opensim(walk, osim, tmp_path):
    """write_mot -> OpenSim's Storage -> the model's coordinates -> OpenSim's marker positions
    equal anthroarm's marker positions at the solution."""
    robot, trial, setup, ours, ref = walk
    out = write_mot(tmp_path / "ours.mot", ours, robot=robot)
    st = osim.Storage(str(out))
    assert st.isInDegrees() and st.getSize() == len(ours)
    model = osim.Model(str(MODEL))
    state = model.initSystem()
    model.getSimbodyEngine().convertDegreesToRadians(st)
    labels = [st.getColumnLabels().get(i) for i in range(st.getColumnLabels().getSize())]
    cs = model.getCoordinateSet()
    ik = CoupledMarkerIK(robot, osim_marker_set(robot, setup))
    for n in range(0, len(ours), 9):
        row = st.getStateVector(n).getData()
        for k, name in enumerate(labels[1:]):
            cs.get(name).setValue(state, row.get(k), False)
        model.realizePosition(state)
        p_osim = np.array(
            [
                model.getMarkerSet().get(m).getLocationInGround(state).to_numpy()
                for m in ours.marker_names
            ]
        )
        M = len(ours.marker_names)
        p_ours, *_ = ik.normal_equations(ours.q[n], np.zeros((M, 3)), np.zeros(M))
        np.testing.assert_allclose(p_ours, p_osim, rtol=0, atol=1e-9)


def test_compiled_normal_equations_and_fast_coupling(walk):
    """The kernel equals JᵀJ, Jᵀr of the numpy evaluation; FastCoupling equals the model's
    coupling map (the one implementation of the splines) at random coordinates."""
    robot, trial, setup, ours, ref = walk
    ms = osim_marker_set(robot, setup)
    tasks = {n: (1000.0, 0.1) for n in setup.coordinate_tasks}
    ik = CoupledMarkerIK(robot, ms, coordinate_tasks=tasks)
    fast = FastCoupling(robot.coupling)
    rng = np.random.default_rng(7)
    cols = [trial.names.index(n) for n in ms.names]
    for q in robot.random_q(20, rng=rng):
        phi, G = robot.coupling.jacobian(q)
        phi2, G2 = fast.jacobian(q)
        np.testing.assert_allclose(phi2, phi, rtol=0, atol=1e-15)
        np.testing.assert_allclose(G2, G, rtol=0, atol=1e-15)
        target = trial.positions[rng.integers(len(trial)), cols]
        w = ms.weights * (rng.random(len(ms)) > 0.2)
        p, r, J = ik.evaluate(q, target, w)
        p2, H, g, cost = ik.normal_equations(q, target, w)
        np.testing.assert_allclose(p2, p, rtol=0, atol=1e-14)
        np.testing.assert_allclose(H, J.T @ J, rtol=1e-12, atol=1e-12 * np.abs(H).max())
        np.testing.assert_allclose(g, J.T @ r, rtol=1e-12, atol=1e-12 * np.abs(g).max())
        assert cost == pytest.approx(float(r @ r), rel=1e-12)


def _renamed(trial, old, new):
    names = tuple(new if n == old else n for n in trial.names)
    return MarkerTrajectories(names, trial.positions, rate=trial.rate, meta=trial.meta)


def test_renamed_missing_and_gappy_markers(walk):
    robot, trial, setup, ours, ref = walk
    # a renamed marker is missing: listed, the frame still solved from the others
    res = osim_marker_ik(robot, _renamed(trial, "R.Heel", "R.Heal"), setup, time_range=(0.4, 0.6))
    assert res.missing_markers == ("R.Heel",) and res.counts()["ok"] == len(res)
    # the same marker by its new name: rename= maps it back
    res2 = osim_marker_ik(
        robot,
        _renamed(trial, "R.Heel", "R.Heal"),
        setup,
        time_range=(0.4, 0.6),
        rename={"R.Heal": "R.Heel"},
    )
    np.testing.assert_allclose(res2.q, ours.q[: len(res2)], atol=1e-7)
    # every marker of the right foot gone: the ankle has nothing to follow
    foot = [n for n in trial.names if n.startswith(("R.Heel", "R.Midfoot", "R.Toe"))]
    keep = [i for i, n in enumerate(trial.names) if n not in foot]
    cut = MarkerTrajectories(
        tuple(trial.names[i] for i in keep), trial.positions[:, keep], rate=60.0, meta=trial.meta
    )
    with pytest.raises(UnconstrainedJointError, match="ankle_angle_r"):
        osim_marker_ik(robot, cut, setup)
    # gaps: a marker missing in some frames has zero weight there
    P = trial.positions.copy()
    P[30:40, trial.names.index("L.Thigh.Front")] = np.nan
    gappy = MarkerTrajectories(trial.names, P, rate=60.0, meta=trial.meta)
    res3 = osim_marker_ik(robot, gappy, setup)
    assert res3.counts()["ok"] == 73 and np.isfinite(res3.q).all()
    assert (res3.n_markers[30 - 24 : 40 - 24] == 30).all()  # frame 24 is t = 0.4 s
    # no marker of the set in the trial
    none = MarkerTrajectories(("a", "b"), P[:, :2], rate=60.0, meta=trial.meta)
    with pytest.raises(MarkerSetError, match="none of the markers"):
        osim_marker_ik(robot, none, setup)


def test_qp_marker_ik_refuses_a_coupled_model(walk):
    robot, trial, setup, ours, ref = walk
    with pytest.raises(ParameterError, match="CoupledMarkerIK"):
        MarkerIK(robot, osim_marker_set(robot, setup))


@pytest.mark.parametrize("name", ["subject01", "arm26", "human_arm7"])
def test_body_poses_equal_pinocchio(name):
    """motion.body_poses (one batched tree walk) against Pinocchio's framesForwardKinematics,
    on a coupled OpenSim model, an uncoupled one and a catalog arm."""
    robot = (
        aa.load(str(MODEL))
        if name == "subject01"
        else (aa.load(str(aosim.path(name))) if name == "arm26" else aa.load(name))
    )
    Q = robot.random_q(40, rng=3)
    poses = body_poses(robot, Q)
    assert len(poses) >= 3
    model, data = robot.model, robot.model.createData()
    full = getattr(robot, "coupling", None)
    for n, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q if full is None else full.full(q))
        for frame, T in poses.items():
            np.testing.assert_allclose(
                T[n], data.oMf[model.getFrameId(frame)].homogeneous, rtol=0, atol=1e-14
            )
    one = body_poses(robot, Q[0])
    assert all(v.shape == (4, 4) for v in one.values())


def test_both_marker_iks_recover_arm26_motion_placed_by_opensim(osim):
    """arm26 (no coupling): markers placed by OpenSim along a known motion; the QP marker IK
    (MarkerIK) and CoupledMarkerIK both recover the motion through osim_marker_set."""
    arm = aa.load(str(aosim.path("arm26")))
    t = np.linspace(0.0, 3.0, 40)[:, None]
    Q = np.clip(arm.default_q() + np.deg2rad(30) * np.sin(t) * [1.0, 2.0], arm.lower, arm.upper)
    model = osim.Model(str(aosim.path("arm26")))
    state = model.initSystem()
    cs = model.getCoordinateSet()
    P = np.empty((len(Q), len(arm.markers), 3))
    for n, q in enumerate(Q):
        for name, v in zip(arm.joint_names, q):
            cs.get(name).setValue(state, float(v), False)
        model.realizePosition(state)
        for k, m in enumerate(arm.markers):
            P[n, k] = model.getMarkerSet().get(m).getLocationInGround(state).to_numpy()
    trial = MarkerTrajectories(tuple(arm.markers), P, rate=100.0)
    ms = osim_marker_set(arm, {m: 1.0 for m in arm.markers})
    qp_res = MarkerIK(arm, ms, seeds=0).solve(trial, q0=Q[0])
    lm_res = CoupledMarkerIK(arm, ms).solve(trial, q0=Q[0])
    for res in (qp_res, lm_res):
        assert res.counts()["ok"] == len(Q)
        np.testing.assert_allclose(res.q, Q, atol=1e-6)
        assert res.rms.max() < 1e-7
