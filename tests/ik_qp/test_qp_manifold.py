"""QP-IK on robots whose configuration is not a vector of angles: kinova (three continuous
joints, nq = 9, nv = 6) and a user URDF with continuous and mimic joints (nq = 6, nv = 4).

Oracles: pink (same tasks and default limits; it integrates with pin.integrate), Pinocchio
(frame Jacobians, FK, joint limits, pin.difference), mathematics (first-order motion by finite
differences, the Newton step's quadratic convergence, the shortest angle on the circle)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.chain import CONTINUOUS
from anthroarm.ik import qp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "foundation"))
from test_chain import USER_URDF  # noqa: E402

BACKENDS = ["osqp", "daqp", "quadprog", "proxqp"]
DT = 0.01


@pytest.fixture(scope="module")
def kinova():
    return aa.load("kinova")


@pytest.fixture(scope="module")
def user(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return aa.load(p, tool="tool")


@pytest.fixture(params=["kinova", "user"])
def robot(request, kinova, user):
    return {"kinova": kinova, "user": user}[request.param]


def _continuous(robot):
    return [j for j in robot.chain.joints if j.kind == CONTINUOUS and not j.is_mimic]


def test_models_have_the_layout_under_test(kinova, user):
    assert (kinova.nq, kinova.nv, len(_continuous(kinova))) == (9, 6, 3)
    assert (user.nq, user.nv, len(_continuous(user))) == (6, 4, 2) and user.chain.has_mimic


@pytest.mark.parametrize("solver", BACKENDS)
def test_step_matches_pink(robot, solver):
    """Same tasks, pink's default limits (configuration gain 0.5 + velocity), integrated on the
    manifold by both: the same velocity at every step (pink with its dense quadprog)."""
    import pink
    from pink.tasks import FrameTask as PFT
    from pink.tasks import PostureTask as PPT

    q0 = robot.random_q(rng=5, margin=0.2)
    q1 = robot.random_q(rng=6, margin=0.2)
    conf = qp.IKConfiguration(robot, q0)
    ee = qp.FrameTask(robot, position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)
    post = qp.PostureTask(robot, cost=1e-2, target=q0)
    pee = PFT(robot.tool, position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)
    ppost = PPT(cost=1e-2)
    ppost.set_target(q0)
    saturated = 0
    for k in range(30):
        T = robot.fk(pin.interpolate(robot.model, q0, q1, 1e-3 * k * k))  # accelerating
        ee.set_target(T)
        pee.set_target(pin.SE3(T))
        v = qp.step(conf, None, [ee, post], DT, solver=solver)
        pc = pink.Configuration(robot.model, robot.model.createData(), conf.q)
        vp = pink.solve_ik(pc, [pee, ppost], DT, solver="quadprog", damping=1e-12)
        assert v.shape == (robot.nv,)
        assert np.abs(v - vp).max() * DT < 1e-9, (k, np.abs(v - vp).max())
        saturated += bool(np.any(np.isclose(np.abs(v), robot.chain.velocity_limit, rtol=1e-9)))
        conf.integrate_inplace(v, DT)
        robot.check_q(conf.q)  # unit (cos, sin) pairs after pin.integrate
    assert 0 < saturated < 30  # both active and inactive velocity bounds were compared


def test_step_moves_the_frame_as_predicted(kinova):
    """First order: log6(T(q)⁻¹ T(q ⊕ v h)) / h → ᵇJ(q) v (Pinocchio's LOCAL Jacobian), the
    error shrinking like h; and without limits the step is Newton's: the pose error after it is
    O(‖e‖²)."""
    r = kinova
    q = r.random_q(rng=2, margin=0.3)
    dq = 0.02 * np.random.default_rng(3).normal(size=r.nv)
    T_target = r.fk(pin.integrate(r.model, q, dq))
    conf = qp.IKConfiguration(r, q)
    ee = qp.FrameTask(r, target=T_target)
    v = qp.step(conf, None, [ee], DT, limits=None, solver="quadprog")
    fid = r.tool_id
    J = pin.computeFrameJacobian(r.model, r.model.createData(), q, fid, pin.LOCAL)
    T0 = pin.SE3(r.fk(q))
    errs = []
    for h in (1e-3, 1e-4, 1e-5):
        Th = pin.SE3(r.fk(pin.integrate(r.model, q, v * h)))
        errs.append(np.abs(pin.log6(T0.actInv(Th)).vector / h - J @ v).max())
    assert errs[1] < 0.15 * errs[0] and errs[2] < 0.15 * errs[1], errs
    assert errs[2] < 1e-4 * np.abs(J @ v).max()
    # Newton: halving the initial error quarters the error after one step
    out = []
    for scale in (0.02, 0.01):
        Tt = pin.SE3(r.fk(pin.integrate(r.model, q, scale / 0.02 * dq)))
        ee.set_target(Tt)
        v = qp.step(conf, None, [ee], DT, limits=None, solver="quadprog")
        q1 = pin.integrate(r.model, q, v * DT)
        out.append([np.linalg.norm(pin.log6(pin.SE3(r.fk(x)).actInv(Tt)).vector) for x in (q, q1)])
    (e0, e1), (f0, f1) = out
    assert f0 == pytest.approx(e0 / 2, rel=0.05) and f1 == pytest.approx(e1 / 4, rel=0.1), out


def test_posture_error_is_the_shortest_angle(kinova):
    """A continuous joint at θ = 3.0 with its reference at −3.0 is 2π − 6 ≈ 0.283 rad away (not
    6): the posture error says so, and a posture step turns it the short way through π, where
    its cos entry is −1 (no box on (cos, sin))."""
    r = kinova
    j = _continuous(r)[0]
    k = r.chain.independent.index(j.index)
    theta = r.chain.angles(r.random_q(rng=1, margin=0.3))[list(r.chain.independent)]
    th_ref = theta.copy()
    theta[k], th_ref[k] = 3.0, -3.0
    q, q_ref = r.chain.configuration(theta), r.chain.configuration(th_ref)
    conf = qp.IKConfiguration(r, q)
    post = qp.PostureTask(r, cost=1.0, target=q_ref)
    e = post.compute_error(conf)
    np.testing.assert_allclose(e, pin.difference(r.model, q_ref, q), atol=1e-15)
    assert e[j.idx_v] == pytest.approx(3.0 - (-3.0) - 2 * np.pi, abs=1e-12)
    np.testing.assert_allclose(np.delete(e, j.idx_v), 0.0, atol=1e-12)
    dt = 1.0  # the whole way in one step: 0.283 rad at 0.628 rad/s fits in 1 s
    v = qp.step(conf, None, [post], dt, solver="quadprog")
    assert v[j.idx_v] > 0 and v[j.idx_v] * dt == pytest.approx(2 * np.pi - 6.0, rel=1e-9)
    conf.integrate_inplace(v, dt)
    assert r.chain.angles(conf.q)[j.index] == pytest.approx(-3.0, abs=1e-9)


def test_configuration_limits_only_on_bounded_joints(robot):
    """The box of ConfigurationLimit: gain·(limit − θ) on the revolute joints with a range
    (limits from Pinocchio's model), unbounded on continuous joints, whatever their (cos, sin)."""
    lim = qp.ConfigurationLimit(robot, gain=0.5)
    conf = qp.IKConfiguration(robot, robot.random_q(rng=4, margin=0.1))
    lo, hi = lim.box(conf, DT)
    assert lo.shape == hi.shape == (robot.nv,)
    m = robot.model
    for jid in range(1, m.njoints):
        jm = m.joints[jid]
        if jm.nv != 1:
            continue  # a mimic joint: no velocity of its own
        if jm.nq == 2:  # continuous
            assert lo[jm.idx_v] == -np.inf and hi[jm.idx_v] == np.inf
        else:
            th = conf.q[jm.idx_q]
            assert lo[jm.idx_v] == pytest.approx(
                0.5 * (m.lowerPositionLimit[jm.idx_q] - th), abs=1e-15
            )
            assert hi[jm.idx_v] == pytest.approx(
                0.5 * (m.upperPositionLimit[jm.idx_q] - th), abs=1e-15
            )
    # a continuous joint parked on cos = −1 or sin = +1 is not "at a limit"
    assert conf.within_limits()
    for j in _continuous(robot):
        theta = robot.chain.angles(conf.q)[list(robot.chain.independent)]
        theta[robot.chain.independent.index(j.index)] = np.pi / 2
        conf.update(robot.chain.configuration(theta))
        assert conf.within_limits() and conf.limit_violations() == []
        lo, hi = lim.box(conf, DT)
        assert lo[j.idx_v] == -np.inf and hi[j.idx_v] == np.inf


def test_velocity_limits_are_per_velocity(robot):
    vl = qp.VelocityLimit(robot)
    np.testing.assert_array_equal(
        vl.v_max, np.where(robot.model.velocityLimit > 0, robot.model.velocityLimit, np.inf)
    )
    conf = qp.IKConfiguration(robot, robot.random_q(rng=8, margin=0.2))
    far = qp.PostureTask(robot, cost=1.0, target=robot.random_q(rng=9, margin=0.2))
    res = qp.step(conf, None, [far], DT, limits=[vl], solver="quadprog", full=True)
    assert res.ok and res.v.shape == (robot.nv,)
    assert np.all(np.abs(res.v) <= vl.v_max * (1 + 1e-12))
    assert np.any(np.isclose(np.abs(res.v), vl.v_max, rtol=1e-12))


def test_configuration_checks_on_continuous_joints(kinova):
    r = kinova
    conf = qp.IKConfiguration(r, r.random_q(rng=0))
    j = _continuous(r)[1]
    q = conf.q.copy()
    q[j.idx_q : j.idx_q + 2] = (0.6, 0.6)
    with pytest.raises(ValueError, match=j.name):
        conf.update(q)
    assert not any(".cos" in s or ".sin" in s for s in conf.limit_violations())
    post = qp.PostureTask(r)  # the comfortable posture: a valid configuration
    r.check_q(post.target)
    th = r.chain.angles(post.target)
    for jj in r.chain.joints:
        expect = 0.0 if jj.kind == CONTINUOUS else 0.5 * (jj.lower + jj.upper)
        assert th[jj.index] == pytest.approx(expect, abs=1e-12)


def test_mimic_joint_follows_and_cannot_be_coupled(user):
    """The finger on the mimic joint moves with its source as Pinocchio says: a PositionTask
    on it is solved through the source's velocity; coupling the mimic joint itself is refused
    with a message naming the source."""
    r = user
    mim = next(j for j in r.chain.joints if j.is_mimic)
    src = r.chain.joints[mim.mimic.source]
    q = r.random_q(rng=2, margin=0.1)
    conf = qp.IKConfiguration(r, q)
    fid = r.frame_id("finger_b")
    J = pin.computeFrameJacobian(r.model, r.model.createData(), q, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
    np.testing.assert_allclose(qp.PositionTask(r, "finger_b").compute_jacobian(conf), J, atol=1e-15)
    dq = np.zeros(r.nv)
    dq[src.idx_v] = 0.01
    p_t = r.fk(pin.integrate(r.model, q, dq), "finger_b")[:3, 3]
    task = qp.PositionTask(r, "finger_b", target=p_t)
    v = qp.step(conf, None, [task], 1.0, limits=None, solver="quadprog", damping=1e-12)
    conf.integrate_inplace(v, 1.0)
    assert np.linalg.norm(conf.frame_placement(fid).translation - p_t) < 1e-6
    with pytest.raises(ValueError, match=f"moves it with {src.name!r}"):
        qp.JointCouplingTask(r, [mim.name], [1.0])
