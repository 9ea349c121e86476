"""Lagrange dynamics on robots a user brings: continuous joints (kinova, a user URDF) and mimic
joints (the user URDF, baxter's left arm and gripper), against Pinocchio.

Oracles.  Continuous joints: ``crba``, ``rnea``, ``computeGeneralizedGravity``,
``computeCoriolisMatrix`` and ``aba`` of the same model.  Mimic joints: Pinocchio 4's ``crba``,
``rnea``, ``computeGeneralizedGravity`` and ``nonLinearEffects`` on the model built with
``mimic=True`` are the reduced quantities (checked here against mathematics: Gᵀ M_full G etc.
from the model built with ``mimic=False``, G the mimic coupling matrix, v_full = G v); its
``computeCoriolisMatrix`` is not (C q̇ + g ≠ nonLinearEffects on baxter, off by 0.58 N m) and its
``aba`` refuses mimic joints.  So C q̇ is checked against nonLinearEffects − g, the Christoffel
matrix against Gᵀ C_full G (G is constant, so the Christoffel symbols transform by G), and
forward dynamics against M⁻¹(τ − nle) with Pinocchio's M and nle.
"""

import ast
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.dynamics import lagrange as L

TOL = 1e-12
LEFT_ARM = [
    "left_s0",
    "left_s1",
    "left_e0",
    "left_e1",
    "left_w0",
    "left_w1",
    "left_w2",
    "l_gripper_l_finger_joint",
    "l_gripper_r_finger_joint",
]


@pytest.fixture(scope="module", autouse=True)
def _cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("ANTHROARM_CACHE", str(tmp_path_factory.mktemp("aacache")))
    yield
    mp.undo()


def user_urdf_text() -> str:
    """USER_URDF of tests/foundation/test_chain.py (continuous + mimic joints, inertias)."""
    src = (Path(__file__).parents[1] / "foundation" / "test_chain.py").read_text()
    for node in ast.parse(src).body:
        if isinstance(node, ast.Assign) and any(
            getattr(t, "id", None) == "USER_URDF" for t in node.targets
        ):
            return ast.literal_eval(node.value)
    raise LookupError("USER_URDF not found in tests/foundation/test_chain.py")


@pytest.fixture(scope="module")
def user_path(tmp_path_factory):
    p = tmp_path_factory.mktemp("user") / "user_arm.urdf"
    p.write_text(user_urdf_text())
    return p


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def sym(M):
    return np.triu(M) + np.triu(M, 1).T


def states(robot, n, seed):
    rng = np.random.default_rng(seed)
    return (
        robot.random_q(n, rng),
        rng.standard_normal((n, robot.nv)),
        rng.standard_normal((n, robot.nv)),
    )


def ours(dyn, Q, V, A, i=None):
    """Every quantity for one state (i) or the batch."""
    if i is not None:
        Q, V, A = Q[i], V[i], A[i]
    return dict(
        M=dyn.mass_matrix(Q),
        Cqd=dyn.coriolis(Q, V),
        C=dyn.coriolis_matrix(Q, V),
        g=dyn.gravity(Q),
        tau=dyn.tau(Q, V, A),
        T=dyn.kinetic_energy(Q, V),
        V=dyn.potential_energy(Q),
        fd=dyn.forward(Q, V, A),
    )


# ------------------------------------------------------------------ continuous joints
@pytest.mark.parametrize("name", ["kinova", "double_pendulum_continuous"])
def test_continuous_joints_vs_pinocchio(name):
    robot = aa.load(name)
    assert robot.chain.has_continuous and robot.nq > robot.nv
    dyn = L.load(robot)
    assert (dyn.nq, dyn.n) == (robot.nq, robot.nv)
    m, d = robot.model, robot.model.createData()
    Q, V, A = states(robot, 6, 0)
    batch = ours(dyn, Q, V, A)
    for i in range(len(Q)):
        q, v, a = Q[i], V[i], A[i]
        C = pin.computeCoriolisMatrix(m, d, q, v).copy()
        ref = dict(
            M=sym(pin.crba(m, d, q)),
            C=C,
            Cqd=C @ v,
            g=pin.computeGeneralizedGravity(m, d, q).copy(),
            tau=pin.rnea(m, d, q, v, a).copy(),
            T=pin.computeKineticEnergy(m, d, q, v),
            V=pin.computePotentialEnergy(m, d, q),
            fd=pin.aba(m, d, q, v, a).copy(),
        )
        single = ours(dyn, Q, V, A, i)
        for k in ref:
            assert rel(single[k], ref[k]) < (1e-10 if k == "fd" else TOL), (name, k, "single")
            assert rel(batch[k][i], ref[k]) < (1e-10 if k == "fd" else TOL), (name, k, "batch")


def test_continuous_joint_is_a_revolute_joint_without_limits():
    """The same angle through (cos, sin) far outside (−π, π]: θ and θ + 2π k give the same M."""
    robot = aa.load("kinova")
    dyn = L.load(robot)
    th = np.random.default_rng(3).uniform(-np.pi, np.pi, robot.nv)
    q = robot.chain.configuration(th)
    q2 = robot.chain.configuration(th + 2 * np.pi * np.array([3, 0, -5, 0, 0, 7])[: robot.nv])
    np.testing.assert_allclose(dyn.mass_matrix(q2), dyn.mass_matrix(q), atol=1e-13)


def test_non_unit_cos_sin_names_the_joint():
    robot = aa.load("kinova")
    dyn = L.load(robot)
    j = next(j for j in robot.chain.joints if j.kind == "continuous")
    q = robot.neutral()
    q[j.idx_q : j.idx_q + 2] = [2.0, 0.0]
    with pytest.raises(ValueError, match=j.name):
        dyn.mass_matrix(q)
    with pytest.raises(ValueError, match=j.name):
        dyn.gravity(np.vstack([robot.neutral(), q]))
    with pytest.raises(ValueError, match=r"shape \(9,\)"):
        dyn.gravity(np.zeros(robot.nv))  # an angle vector is not the robot's layout


# ------------------------------------------------------------------ mimic joints
def coupling(robot, full):
    """(G, q_full(q)) for the mimic=False model ``full`` with the same joints as ``robot``."""
    ch = robot.chain
    G = np.zeros((full.nv, robot.nv))
    for j in ch.joints:
        fj = full.joints[full.getJointId(j.name)]
        src = ch.joints[j.mimic.source] if j.is_mimic else j
        G[fj.idx_v, src.idx_v] = j.mimic.multiplier if j.is_mimic else 1.0

    def q_full(q):
        th = ch.angles(q)
        out = np.zeros(full.nq)
        for j in ch.joints:
            fj = full.joints[full.getJointId(j.name)]
            out[fj.idx_q : fj.idx_q + fj.nq] = (
                [np.cos(th[j.index]), np.sin(th[j.index])] if fj.nq == 2 else th[j.index]
            )
        return out

    return G, q_full


def mimic_robots(user_path):
    user = aa.load(user_path, tool="tool")
    user_full = pin.buildModelFromUrdf(str(user_path), mimic=False)
    baxter = aa.load("baxter", tool="left_gripper", active=LEFT_ARM)
    bfull = pin.buildModelFromUrdf(str(aa.models.erd_urdf_path("baxter")), mimic=False)
    lock = [i for i in range(1, bfull.njoints) if bfull.names[i] not in LEFT_ARM]
    bfull = pin.buildReducedModel(bfull, lock, pin.neutral(bfull))
    return {"user": (user, user_full), "baxter_left": (baxter, bfull)}


@pytest.mark.parametrize("which", ["user", "baxter_left"])
def test_mimic_joints_vs_pinocchio(which, user_path):
    robot, full = mimic_robots(user_path)[which]
    assert robot.chain.has_mimic and full.nv == robot.nv + 1
    dyn = L.load(robot)
    G, q_full = coupling(robot, full)
    m, d, fd = robot.model, robot.model.createData(), full.createData()
    Q, V, A = states(robot, 6, 1)
    batch = ours(dyn, Q, V, A)
    for i in range(len(Q)):
        q, v, a = Q[i], V[i], A[i]
        qf, vf, af = q_full(q), G @ v, G @ a
        # Pinocchio's mimic model gives the reduced M, τ, g, nle: the same as Gᵀ(·) of the full
        # model
        M = sym(pin.crba(m, d, q))
        nle = pin.nonLinearEffects(m, d, q, v).copy()
        g = pin.computeGeneralizedGravity(m, d, q).copy()
        tau = pin.rnea(m, d, q, v, a).copy()
        assert rel(M, G.T @ sym(pin.crba(full, fd, qf)) @ G) < TOL
        assert rel(tau, G.T @ pin.rnea(full, fd, qf, vf, af)) < TOL
        assert rel(g, G.T @ pin.computeGeneralizedGravity(full, fd, qf)) < TOL
        ref = dict(
            M=M,
            Cqd=nle - g,
            C=G.T @ pin.computeCoriolisMatrix(full, fd, qf, vf) @ G,
            g=g,
            tau=tau,
            T=pin.computeKineticEnergy(full, fd, qf, vf),
            V=pin.computePotentialEnergy(full, fd, qf),
            fd=np.linalg.solve(M, a - nle),
        )
        single = ours(dyn, Q, V, A, i)
        for k in ref:
            tol = 1e-10 if k == "fd" else TOL
            assert rel(single[k], ref[k]) < tol, (which, k, "single")
            assert rel(batch[k][i], ref[k]) < tol, (which, k, "batch")


def test_mimic_offset_enters_the_angles(user_path):
    """grip_mimic = −grip + 0.1: its 0.1 rad offset changes M (the finger's pose), the
    multiplier its velocity: M_grip,grip = Σ over both fingers with a² = 1."""
    robot = aa.load(user_path, tool="tool")
    j = robot.chain.joint("grip_mimic")
    assert (j.mimic.multiplier, j.mimic.offset) == (-1.0, 0.1)
    th = robot.chain.angles(robot.neutral())
    assert th[j.index] == pytest.approx(0.1)


def test_c_backend_on_continuous_and_mimic(user_path):
    if L.cache.compiler() is None:
        pytest.skip("no C compiler")
    robot = aa.load(user_path, tool="tool")
    dn, dc = L.load(robot), L.load(robot, backend="c")
    Q, V, A = states(robot, 5, 2)
    np.testing.assert_allclose(dc.tau(Q, V, A), dn.tau(Q, V, A), atol=1e-13)
    np.testing.assert_allclose(dc.mass_matrix(Q[0]), dn.mass_matrix(Q[0]), atol=1e-14)
    np.testing.assert_allclose(dc.coriolis(Q[1], V[1]), dn.coriolis(Q[1], V[1]), atol=1e-13)


@pytest.mark.parametrize("which", ["kinova", "user", "baxter_left"])
def test_check_rows_on_any_robot(which, user_path):
    """The rows of ``anthroarm check`` (dynamics.checks) run on continuous and mimic models."""
    from anthroarm.dynamics import checks

    robot = aa.load("kinova") if which == "kinova" else mimic_robots(user_path)[which][0]
    rows = checks.model_rows(robot, 4, np.random.default_rng(5))
    assert len(rows) == 8 and all(r.ok for r in rows), [
        (r.quantity, r.max_abs_err) for r in rows if not r.ok
    ]
    if robot.chain.has_mimic:
        assert any("mimic" in r.oracle for r in rows)
