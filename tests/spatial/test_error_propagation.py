"""§6-6 error propagation (6-117)-(6-119) for every catalog arm: J_L analytic vs finite
differences over perturbed Pinocchio placements, (6-119) for the 7-DOF arm, first-order
accuracy, batched perturbed FK vs Pinocchio, Monte Carlo vs the linear covariance."""

import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.kinematics import error_propagation as EP
from anthroarm.models.human import human_arm7_length_jacobian

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "foundation"))
from test_chain import USER_URDF  # noqa: E402

MODELS = aa.models.names()


@pytest.fixture(scope="module")
def robots():
    return {n: aa.load(n) for n in MODELS}


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("mode", ["length", "components"])
def test_length_jacobian_matches_finite_differences(robots, name, mode):
    r = robots[name]
    rng = np.random.default_rng(11)
    for q in r.random_q(3, rng):
        J = EP.length_jacobian(r, q, mode=mode)
        Jfd = EP.length_jacobian_fd(r, q, mode=mode)
        assert J.shape == Jfd.shape and J.shape[1] >= 1
        assert np.abs(J - Jfd).max() < 1e-10
        assert np.abs(Jfd[3:]).max() < 1e-10  # link dimensions do not rotate the hand


def test_6_119_human_arm7_is_the_length_jacobian(robots):
    r = robots["human_arm7"]
    ps = EP.link_parameters(r)
    assert [p.name for p in ps] == [
        "elbow_flexion.length",
        "wrist_deviation.length",
        "hand_point.length",
    ]
    l1, l2, l3 = (r.spec.params[k] for k in ("l1", "l2", "l3"))
    assert np.allclose([p.nominal for p in ps], [l1, l2, l3])
    for q in r.random_q(5, np.random.default_rng(3)):
        book = human_arm7_length_jacobian(q)  # (6-119): [-e.3, -w.3, -h.3]
        assert np.allclose(book, EP.length_jacobian_fd(r, q)[:3], atol=1e-10)
        # (6-119) is exact: P_H is linear in l_k
        dl = np.array([0.01, -0.02, 0.005])
        m = r.model
        for p, d in zip(ps, dl):
            m = EP._perturbed_model(m, p, d)
        dd = m.createData()
        pin.framesForwardKinematics(m, dd, q)
        exact = dd.oMf[r.tool_id].translation - r.fk(q)[:3, 3]
        assert np.allclose(exact, book @ dl, atol=1e-12)


@pytest.mark.parametrize("name", ["prosthetic_arm", "sixr_arm", "panda", "unimate5"])
def test_first_order_error_is_second_order_accurate(robots, name):
    """|x(q+Δq, L+ΔL) − x(q, L) − (J_q Δq + J_L ΔL)| = O(|Δ|²), Eq. (6-118)."""
    r = robots[name]
    rng = np.random.default_rng(4)
    q = r.random_q(rng=rng, margin=0.1)
    chain = EP.PerturbedChain(r)
    dq0 = rng.normal(size=r.nv)
    dL0 = rng.normal(size=len(chain.params))
    R0, x0 = chain.pose(q[None])
    errs = []
    for eps in (1e-3, 5e-4):
        res = EP.propagate(r, q, eps * dq0, eps * dL0)
        R, x = chain.pose((q + eps * dq0)[None], (eps * dL0)[None])
        errs.append(np.linalg.norm(x[0] - x0[0] - res.dp))
        drot = pin.log3(R[0] @ R0[0].T)
        assert np.linalg.norm(drot - res.dx[3:]) < 50 * eps**2
    assert errs[1] < errs[0] / 3.0  # quadratic: halving eps quarters the error


@pytest.mark.parametrize("name", MODELS)
def test_perturbed_chain_matches_pinocchio_on_perturbed_models(robots, name):
    r = robots[name]
    rng = np.random.default_rng(8)
    chain = EP.PerturbedChain(r, mode="components")
    Q = r.random_q(4, rng)
    dL = 0.01 * rng.normal(size=(4, len(chain.params)))
    R, x = chain.pose(Q, dL)
    for i in range(4):
        m = r.model
        for p, d in zip(chain.params, dL[i]):
            m = EP._perturbed_model(m, p, d)
        dd = m.createData()
        pin.framesForwardKinematics(m, dd, Q[i])
        assert np.allclose(x[i], dd.oMf[r.tool_id].translation, atol=1e-12)
        assert np.allclose(R[i], dd.oMf[r.tool_id].rotation, atol=1e-12)


def test_monte_carlo_matches_linear_covariance(robots):
    r = robots["human_arm7"]
    q = r.random_q(rng=1, margin=0.1)
    res = EP.monte_carlo(r, q, sigma_q=1e-3, sigma_L=1e-3, n=20000, rng=0, progress=False)
    sd_mc = np.sqrt(np.diag(res.cov))
    sd_lin = np.sqrt(np.diag(res.linear_cov))
    assert np.allclose(sd_mc, sd_lin, rtol=0.05)  # 20000 samples: ~1% sampling error
    assert res.dx.shape == (20000, 6) and res.max_position >= res.p95_position > 0
    u = EP.monte_carlo(
        r, q, sigma_q=1e-3, sigma_L=0.0, n=20000, rng=0, distribution="uniform", progress=False
    )
    assert np.allclose(np.sqrt(np.diag(u.cov)), np.sqrt(np.diag(u.linear_cov)), rtol=0.05)
    z = EP.monte_carlo(r, q, n=10, rng=0, progress=False)
    assert np.allclose(z.dx, 0)


def test_error_propagation_bad_input(robots):
    r = robots["prosthetic_arm"]
    q = r.neutral()
    with pytest.raises(ValueError, match="dq"):
        EP.propagate(r, q, dq=np.ones(3))
    with pytest.raises(ValueError, match="NaN"):
        EP.propagate(r, q, dL=[np.nan, 0, 0])
    with pytest.raises(ValueError, match="mode"):
        EP.link_parameters(r, mode="angles")
    with pytest.raises(ValueError, match="non-negative"):
        EP.monte_carlo(r, q, sigma_q=-1.0, n=10, progress=False)
    with pytest.raises(ValueError, match="positive integer"):
        EP.monte_carlo(r, q, n=0, progress=False)
    with pytest.raises(ValueError, match="distribution"):
        EP.monte_carlo(r, q, n=10, distribution="cauchy", progress=False)
    with pytest.raises(ValueError, match="shape"):
        EP.length_jacobian(r, np.zeros(2))
    with pytest.raises(aa.errors.UnknownFrameError):
        EP.link_parameters(r, frame="nope")
    chain = EP.PerturbedChain(r)
    with pytest.raises(ValueError, match="dL has a NaN"):
        chain.pose(q[None], np.full((1, len(chain.params)), np.nan))


@pytest.fixture(scope="module")
def user_urdf(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(USER_URDF)
    return p


@pytest.mark.parametrize(
    "name,kw",
    [("kinova", {}), ("user", {"tool": "tool"}), ("baxter", {"tool": "l_gripper_r_finger_tip"})],
)
def test_perturbed_chain_continuous_and_mimic_joints(name, kw, user_urdf):
    """PerturbedChain reads robot.chain: continuous joints ((cos, sin) in q), mimic joints (baxter's
    finger, the user arm's grip_mimic) and joint errors dq (on the circle: pin.integrate) equal
    Pinocchio on the perturbed model at pin.integrate(q, dq); J_L equals its finite differences."""
    r = aa.load(str(user_urdf) if name == "user" else name, **kw)
    rng = np.random.default_rng(5)
    chain = EP.PerturbedChain(r, mode="components")
    assert [j.name for j in chain.joints] == [
        r.model.names[i] for i in _support(r.model, r.tool_id)
    ]
    Q = r.random_q(4, rng)
    dL = 0.01 * rng.normal(size=(4, len(chain.params)))
    dq = 0.05 * rng.normal(size=(4, r.nv))
    R, x = chain.pose(Q, dL, dq)
    for i in range(4):
        m = r.model
        for p, d in zip(chain.params, dL[i]):
            m = EP._perturbed_model(m, p, d)
        dd = m.createData()
        pin.framesForwardKinematics(m, dd, pin.integrate(r.model, Q[i], dq[i]))
        assert np.allclose(x[i], dd.oMf[r.tool_id].translation, atol=1e-12)
        assert np.allclose(R[i], dd.oMf[r.tool_id].rotation, atol=1e-12)
        J = EP.length_jacobian(r, Q[i], mode="components")
        assert np.abs(J - EP.length_jacobian_fd(r, Q[i], mode="components")).max() < 1e-10


def test_monte_carlo_on_continuous_joints_matches_linear_covariance():
    r = aa.load("kinova")
    q = r.random_q(rng=2)
    res = EP.monte_carlo(r, q, sigma_q=1e-3, sigma_L=1e-3, n=20000, rng=0, progress=False)
    assert np.allclose(np.sqrt(np.diag(res.cov)), np.sqrt(np.diag(res.linear_cov)), rtol=0.05)


def _support(model, fid):
    """Pinocchio joint ids from the base to frame ``fid`` (the oracle of the chain's path)."""
    j, out = model.frames[fid].parentJoint, []
    while j > 0:
        out.append(j)
        j = model.parents[j]
    return out[::-1]
