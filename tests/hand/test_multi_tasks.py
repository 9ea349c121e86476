"""MultiFrameTask and JointCouplingsTask: the stacked objective is the sum of the single tasks'
objectives; the step they give is the damped least-squares closed form (numpy) when no limit
is active; Jacobians against finite differences; residuals against Pinocchio FK (log6)."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik import qp
from anthroarm.ik.qp.step import _Workspace

FRAMES = ["index_tip", "little_tip", "middle_tip", "ring_tip", "thumb_tip", "palm"]
COUPLED = [("index_dip", "index_pip"), ("ring_dip", "ring_pip")]


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def _targets(robot, q):
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    return [d.oMf[robot.model.getFrameId(f)].homogeneous for f in FRAMES]


def test_multi_frame_residual_jacobian_and_objective(limb):
    q = limb.random_q(rng=1)
    Ts = _targets(limb, limb.random_q(rng=2))
    pc = np.array([1.0, 2.0, 0.5, 1.0, 3.0, 0.7])
    multi = qp.MultiFrameTask(
        limb,
        FRAMES,
        position_cost=pc,
        orientation_cost=[0.1, 0.2, 0.3],
        lm_damping=1e-2,
        targets=Ts,
    )
    singles = [
        qp.FrameTask(
            limb, f, position_cost=c, orientation_cost=[0.1, 0.2, 0.3], lm_damping=1e-2, target=T
        )
        for f, c, T in zip(FRAMES, pc, Ts)
    ]
    conf = qp.IKConfiguration(limb, q)
    d = limb.model.createData()
    pin.framesForwardKinematics(limb.model, d, q)
    e_fk = np.concatenate(
        [
            pin.log6(d.oMf[limb.model.getFrameId(f)].actInv(pin.SE3(T))).vector
            for f, T in zip(FRAMES, Ts)
        ]
    )
    np.testing.assert_allclose(multi.compute_error(conf), e_fk, atol=1e-12)
    # Jacobian of the residual by central differences on the manifold
    J = multi.compute_jacobian(conf)
    h = 1e-6
    for i in range(0, limb.nv, 5):
        dv = np.zeros(limb.nv)
        dv[i] = h
        conf.update(pin.integrate(limb.model, q, dv))
        ep = multi.compute_error(conf)
        conf.update(pin.integrate(limb.model, q, -dv))
        em = multi.compute_error(conf)
        np.testing.assert_allclose(J[:, i], (ep - em) / (2 * h), atol=1e-6)
    conf.update(q)
    # objective (in place) = the sum of the six FrameTasks' objectives
    ws = _Workspace(limb.nv)
    diag = multi._accumulate(conf, ws, True)
    H = sum(t.compute_qp_objective(conf)[0] for t in singles)
    c = sum(t.compute_qp_objective(conf)[1] for t in singles)
    np.testing.assert_allclose(ws.H + diag * np.eye(limb.nv), H, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ws.c, c, rtol=1e-12, atol=1e-12)


def test_joint_couplings_objective_and_step(limb):
    q = limb.random_q(rng=3)
    cs = [
        qp.JointCouplingTask.mimic(limb, a, b, 2.0 / 3.0, cost=w)
        for (a, b), w in zip(COUPLED, (1.0, 2.0))
    ]
    many = qp.JointCouplingsTask(limb, cs, lm_damping=1e-3)
    conf = qp.IKConfiguration(limb, q)
    names = limb.chain.q_names
    e = many.compute_error(conf)
    for k, (a, b) in enumerate(COUPLED):  # q_dip − 2/3 q_pip, read from q by name
        assert e[k] == pytest.approx(q[names.index(a)] - 2.0 / 3.0 * q[names.index(b)], abs=1e-15)
    post = qp.PostureTask(limb, cost=0.1)
    Ts = _targets(limb, limb.random_q(rng=4))
    multi = qp.MultiFrameTask(
        limb, FRAMES, position_cost=1.0, orientation_cost=0.1, lm_damping=1e-3, targets=Ts
    )
    big = qp.Limit()
    big.box = lambda conf, dt: (np.full(limb.nv, -100.0), np.full(limb.nv, 100.0))
    dq = qp.step(
        conf, None, [multi, many, post], 1.0, limits=[big], solver="quadprog", damping=1e-9
    )
    # closed form of the QP without active limits: (Σ JᵀW²J + μI + λI) Δq = −Σ α JᵀW²e
    Hs, cs_ = 1e-9 * np.eye(limb.nv), np.zeros(limb.nv)
    for t in [multi, many, post]:
        J, err = t.compute_jacobian(conf), t.compute_error(conf)
        w = np.broadcast_to(t.cost, err.shape)
        Hs += J.T @ (w[:, None] ** 2 * J) + t.lm_damping * float((w * err) @ (w * err)) * np.eye(
            limb.nv
        )
        cs_ += t.gain * J.T @ (w**2 * err)
    np.testing.assert_allclose(dq, np.linalg.solve(Hs, -cs_), atol=1e-8)


def test_bad_input(limb):
    with pytest.raises(ValueError, match="at least one"):
        qp.MultiFrameTask(limb, [])
    with pytest.raises(ValueError, match="one per frame"):
        qp.MultiFrameTask(limb, FRAMES, position_cost=[1.0, 2.0])
    t = qp.MultiFrameTask(limb, FRAMES)
    with pytest.raises(ValueError, match="no target"):
        t.compute_error(qp.IKConfiguration(limb))
    with pytest.raises(ValueError, match="targets for"):
        t.set_targets([np.eye(4)])
    with pytest.raises(ValueError, match="rigid|rotation"):
        t.set_target("palm", 2 * np.eye(4))
    with pytest.raises(ValueError):
        qp.JointCouplingsTask(limb, [])
