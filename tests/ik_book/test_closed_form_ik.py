"""Closed-form IK (ik/closed_form.py): FK∘IK round trips against Pinocchio, branch counts,
the swivel family of human_arm7, non-default parameters, bad input.

Round trips use 2000 random poses per arm (the benchmark runs 10 000); expected values come
from Pinocchio's FK of random configurations, never from the IK itself."""

import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.errors import UnsupportedModelError
from anthroarm.ik import swivel_angle
from anthroarm.ik.closed_form import analytic_batch

N_ROUND_TRIP = 2000
ARMS = {
    "sixr_arm": {},
    "prosthetic_arm": {},
    "planar2r": {},
    "human_arm7": {},
    # non-default parameters: lengths must be read from robot.spec.params
    "sixr_arm:custom": dict(s0=0.3, h2=0.55, s3=0.25, P=0.05),
    "prosthetic_arm:caption": dict(L2=0.240),
    "human_arm7:female": dict(height=1.60, mass=55.0, sex="female"),
    "planar2r:custom": dict(l1=0.7, l2=0.4),
}


def _load(key):
    return aa.load(key.split(":")[0], **ARMS[key])


@pytest.mark.parametrize("key", list(ARMS))
def test_round_trip_fk_ik_pinocchio(key):
    robot = _load(key)
    # a stable seed per key (str hash() is salted per process)
    rng = np.random.default_rng(zlib.crc32(key.encode()))
    Q = robot.random_q(N_ROUND_TRIP, rng)
    T = robot.fk(Q)  # Pinocchio
    kw = {"swivel": swivel_angle(robot, Q)} if robot.spec.name == "human_arm7" else {}
    res = analytic_batch(robot, T, **kw)
    assert res.valid.any(1).all(), [r for r in res.reasons if r][:3]
    i, b = np.nonzero(res.valid)
    S = res.solutions[i, b]
    assert np.isfinite(S).all()
    assert robot.within_limits(S).all()
    Tfk = robot.fk(S)
    if robot.spec.name == "planar2r":
        err = np.abs(Tfk[:, :3, 3] - T[i, :3, 3]).max()
    else:
        err = np.abs(Tfk[:, :3, :] - T[i, :3, :]).max()
    assert err <= 1e-10
    # the configuration the pose came from is one of the solutions, wherever the pose determines
    # it well: a pose error e maps to a joint error of about e / σ_min(J), so near a singularity
    # (a straight elbow, an aligned wrist) the comparison is meaningless and is left out
    J = robot.jacobian(Q)
    if robot.spec.name == "planar2r":
        J = J[:, 1:3, :]  # the printed task: tip (y, z)
    sigma_min = np.linalg.svd(J, compute_uv=False)[:, -1]
    well = sigma_min > 1e-3
    assert well.mean() > 0.8  # most samples are well away from a singularity
    dist = np.where(res.valid[..., None], res.solutions, np.inf) - Q[:, None, :]
    assert np.nanmin(np.abs(dist).max(-1), axis=1)[well].max() < 1e-6


def test_sixr_eight_branches():
    """Fig. 7-1: a generic pose of the 6R arm has exactly 8 solutions (2 θ1 × 2 elbow × 2 wrist)."""
    robot = aa.load("sixr_arm")
    rng = np.random.default_rng(1)
    Q = robot.random_q(200, rng)
    res = analytic_batch(robot, robot.fk(Q))
    assert (res.n_solutions == 8).all()
    for k in range(5):
        sols = res[k].solutions
        d = np.abs(sols[:, None] - sols[None]).max(-1) + np.eye(8) * 10
        assert d.min() > 1e-6  # 8 distinct solutions
        assert len(set(res[k].branches)) == 8


def test_sixr_book_identities_7_12_7_15():
    """N = −cos θ5 (corrected (7-12)); the printed θ5 = acos(N) is wrong; tan θ5 = W/(U c4 + V s4)."""
    robot = aa.load("sixr_arm")
    rng = np.random.default_rng(2)
    from anthroarm.models import dh_matrix

    rows = robot.spec.dh
    for q in robot.random_q(20, rng):
        T = robot.fk(q)
        l_, m_, n_ = T[:3, 2]
        u, v, w = T[:3, 0]
        C03 = (dh_matrix(rows[0], q[0]) @ dh_matrix(rows[1], q[1]) @ dh_matrix(rows[2], q[2]))[
            :3, :3
        ]
        L, M, N = C03.T @ np.array([l_, m_, n_])
        U, V, W = C03.T @ np.array([u, v, w])
        assert abs(N + np.cos(q[4])) < 1e-12
        assert abs(L * np.sin(q[3]) - M * np.cos(q[3])) < 1e-12  # (7-8)
        t5 = np.arctan2(W, U * np.cos(q[3]) + V * np.sin(q[3]))
        assert abs(np.tan(t5) - np.tan(q[4])) < 1e-8 * (1 + np.tan(q[4]) ** 2)
        # printed (7-12): θ5 = acos(N) gives π − |θ5| instead of |θ5|
        if abs(np.cos(q[4])) > 0.1:
            assert abs(np.arccos(N) - abs(q[4])) > 0.1


def test_human_arm7_swivel_family():
    """Every swivel angle of the grid gives solutions; each solution's swivel angle equals the
    requested one; all reproduce the pose (Pinocchio FK)."""
    robot = aa.load("human_arm7")
    q0 = np.radians([40, -30, 20, 60, 10, 5, -10])
    T = robot.fk(q0)
    res = aa.ik.analytic(robot, T)  # default grid of 36 swivel angles
    assert res.success and res.swivel is not None and len(res.swivel) == len(res)
    assert len(np.unique(np.round(res.swivel, 9))) >= 5  # a genuine one-parameter family
    np.testing.assert_allclose(
        np.angle(np.exp(1j * (swivel_angle(robot, res.solutions) - res.swivel))), 0, atol=1e-9
    )
    for q in res.solutions:
        np.testing.assert_allclose(robot.fk(q)[:3], T[:3], atol=1e-10)
    # the scalar form and the swivel of q0 recover q0
    r0 = aa.ik.analytic(robot, T, swivel=swivel_angle(robot, q0))
    assert np.abs(r0.solutions - q0).max(1).min() < 1e-9


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_single_equals_batch(seed):
    """The single-pose (scalar) and the batched (structure-of-arrays) paths are separate
    implementations: same branches, solutions equal to rounding (both FK-verified)."""
    robot = aa.load("sixr_arm")
    q = robot.random_q(None, np.random.default_rng(seed))
    T = robot.fk(q)
    one = aa.ik.analytic(robot, T)
    batch = aa.ik.analytic(robot, T[None])
    assert one.branches == batch[0].branches
    np.testing.assert_allclose(one.solutions, batch[0].solutions, rtol=0, atol=1e-10)


def test_has_analytic():
    for name in ("sixr_arm", "prosthetic_arm", "planar2r", "human_arm7"):
        assert aa.ik.has_analytic(aa.load(name))
    assert aa.ik.has_analytic(aa.load("ur5"))  # by its geometry (tests/ik_geometric)
    for name in ("unimate5",):
        assert not aa.ik.has_analytic(aa.load(name))
    with pytest.raises(UnsupportedModelError):
        aa.ik.analytic(aa.load("unimate5"), np.eye(4))


def test_bad_input():
    robot = aa.load("sixr_arm")
    T = robot.fk(robot.neutral())
    bad = T.copy()
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match="not finite"):
        aa.ik.analytic(robot, bad)
    with pytest.raises(ValueError, match="shape"):
        aa.ik.analytic(robot, np.eye(3))
    skew = T.copy()
    skew[:3, :3] *= 1.01
    with pytest.raises(ValueError, match="rotation"):
        aa.ik.analytic(robot, skew)
    mirror = T.copy()
    mirror[:3, 0] *= -1
    with pytest.raises(ValueError, match="rotation"):
        aa.ik.analytic(robot, mirror)
    with pytest.raises(ValueError, match="swivel"):
        aa.ik.analytic(aa.load("human_arm7"), np.eye(4), swivel=[np.nan])


@pytest.mark.parametrize("name", ["sixr_arm", "prosthetic_arm", "planar2r", "human_arm7"])
def test_unreachable_gives_reason(name):
    robot = aa.load(name)
    T = np.eye(4)
    T[:3, 3] = [3.0, 0.0, 3.0] if name != "planar2r" else [0.0, 3.0, 3.0]
    res = aa.ik.analytic(robot, T)
    assert not res.success and res.solutions.shape == (0, robot.nq)
    assert "outside the workspace" in res.reason


def test_planar_out_of_plane_and_limits_reason():
    robot = aa.load("planar2r")
    res = aa.ik.analytic(robot, np.array([0.1, 1.0, 0.0]))
    assert not res.success and "plane" in res.reason
    # prosthetic arm: a reachable wrist position whose only solutions break the joint limits
    arm = aa.load("prosthetic_arm")
    q = np.radians([60.0, 80.0, 0.0, 80.0, 0.0, 0.0])  # θ1 = +60° is outside [-180°, 0]
    arm_free = arm.fk(np.clip(q, arm.lower, arm.upper))
    res = aa.ik.analytic(arm, arm_free)
    assert res.success
    import pinocchio as pin

    pin.framesForwardKinematics(arm.model, arm.data, q)
    Tq = arm.data.oMf[arm.tool_id].homogeneous
    res = aa.ik.analytic(arm, Tq)
    assert not res.success and "joint limits" in res.reason


def test_batch_mixed_reachable_and_not():
    robot = aa.load("prosthetic_arm")
    Q = robot.random_q(5, np.random.default_rng(3))
    T = robot.fk(Q)
    T[2, :3, 3] = [5.0, 0, 0]
    res = aa.ik.analytic_batch(robot, T)
    assert res.reasons[2] is not None and not res.valid[2].any()
    assert np.isnan(res.solutions[2]).all()
    assert all(res.reasons[i] is None for i in (0, 1, 3, 4))
    assert res[2].solutions.shape == (0, 6)
