"""Lagrange engine (book §8-1, Eqs. (8-8)/(8-13), (8-105)): generated M, C q̇, g, τ, T, V
against Pinocchio, against an independent plain-sympy derivation, and bad input."""

import os

import numpy as np
import pinocchio as pin
import pytest
import sympy as sp
from dyn_chains import chain
from hypothesis import given, settings
from hypothesis import strategies as st

import anthroarm as aa
from anthroarm.dynamics import lagrange as L
from anthroarm.errors import InertiaError, UnsupportedModelError

TOL = 1e-10


@pytest.fixture(scope="module", autouse=True)
def _cache(tmp_path_factory):
    old = os.environ.get("ANTHROARM_CACHE")
    os.environ["ANTHROARM_CACHE"] = str(tmp_path_factory.mktemp("aacache"))
    yield
    if old is None:
        os.environ.pop("ANTHROARM_CACHE", None)
    else:
        os.environ["ANTHROARM_CACHE"] = old


def rel(a, b):
    return np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, np.max(np.abs(b)))


def pin_all(model, q, v, a, mimic=False):
    """Pinocchio's M, C, C q̇, g, τ, T, V.  With mimic joints Pinocchio's crba, rnea, gravity and
    nonLinearEffects are the reduced quantities, but computeCoriolisMatrix is not consistent with
    them and the energy functions refuse mimic joints (see anthroarm.dynamics.checks and
    test_lagrange_any_robot.py): there C q̇ = nonLinearEffects − g, T = ½ q̇ᵀ M q̇ and
    V = −m gᵀ c (centerOfMass), and the Christoffel matrix itself has no Pinocchio row."""
    d = model.createData()
    M = pin.crba(model, d, q)
    M = np.triu(M) + np.triu(M, 1).T
    g = pin.computeGeneralizedGravity(model, d, q).copy()
    out = dict(M=M, g=g, tau=pin.rnea(model, d, q, v, a).copy())
    if mimic:
        out.update(
            Cqd=pin.nonLinearEffects(model, d, q, v) - g,
            T=0.5 * v @ M @ v,
            V=-pin.computeTotalMass(model)
            * float(model.gravity.linear @ pin.centerOfMass(model, d, q)),
        )
    else:
        C = pin.computeCoriolisMatrix(model, d, q, v).copy()
        out.update(
            C=C,
            Cqd=C @ v,
            T=pin.computeKineticEnergy(model, d, q, v),
            V=pin.computePotentialEnergy(model, d, q),
        )
    return out


#: the catalog plus the linkage hand's plain URDF (mimic joints: the mimic rows of pin_all) until
#: it is a catalog entry itself
CATALOG_AND_MIMIC = aa.models.names() + [
    n for n in ("prosthetic_hand",) if n not in aa.models.names()
]


@pytest.mark.parametrize("name", CATALOG_AND_MIMIC)
def test_catalog_vs_pinocchio(name):
    robot = aa.load(name)
    dyn = L.load(robot)
    rng = np.random.default_rng(1)
    Q = robot.random_q(8, rng)
    V = rng.standard_normal((8, robot.nv))
    A = rng.standard_normal((8, robot.nv))
    batch = dict(
        M=dyn.mass_matrix(Q),
        C=dyn.coriolis_matrix(Q, V),
        Cqd=dyn.coriolis(Q, V),
        g=dyn.gravity(Q),
        tau=dyn.tau(Q, V, A),
        T=dyn.kinetic_energy(Q, V),
        V=dyn.potential_energy(Q),
    )
    mimic = robot.chain.has_mimic
    for i in range(len(Q)):
        ref = pin_all(robot.model, Q[i], V[i], A[i], mimic)
        single = dict(
            M=dyn.mass_matrix(Q[i]),
            C=dyn.coriolis_matrix(Q[i], V[i]),
            Cqd=dyn.coriolis(Q[i], V[i]),
            g=dyn.gravity(Q[i]),
            tau=dyn.tau(Q[i], V[i], A[i]),
            T=dyn.kinetic_energy(Q[i], V[i]),
            V=dyn.potential_energy(Q[i]),
        )
        for k in ref:
            assert rel(batch[k][i], ref[k]) < TOL, (name, k, "batch")
            assert rel(single[k], ref[k]) < TOL, (name, k, "single")
        fd = dyn.forward(Q[i], V[i], A[i])
        if mimic:  # aba refuses mimic joints: M⁻¹ (τ − nonLinearEffects) with Pinocchio's reduced M
            fd_ref = np.linalg.solve(ref["M"], A[i] - ref["Cqd"] - ref["g"])
        else:
            fd_ref = pin.aba(robot.model, robot.model.createData(), Q[i], V[i], A[i])
        assert rel(fd, fd_ref) < 1e-9


def christoffel(M, q):
    """Christoffel symbols of the first kind, written here (not anthroarm's helper):
    Γ[i][j][k] = ½(∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)."""
    n = M.shape[0]
    return [
        [
            [(M[i, j].diff(q[k]) + M[i, k].diff(q[j]) - M[j, k].diff(q[i])) / 2 for k in range(n)]
            for j in range(n)
        ]
        for i in range(n)
    ]


def _sympy_oracle(params, gravity):
    """Plain sympy: world poses by matrix products, T = Σ ½m|ċ|² + ½ωᵀIω with ω from RᵀṘ,
    M = ∂²T/∂q̇², Γ from M, g = ∂V/∂q.  No code shared with anthroarm."""
    n = len(params)
    q = sp.symbols(f"q0:{n}", real=True)
    qd = sp.symbols(f"qd0:{n}", real=True)
    R = sp.eye(3)
    p = sp.zeros(3, 1)
    M = sp.zeros(n, n)
    V = 0
    qdv = sp.Matrix(qd)
    for k, (R0, p0, kind, axis, m, c, I) in enumerate(params):
        p = p + R * sp.Matrix(p0)
        R = R * sp.Matrix(R0)
        a = sp.Matrix(axis)
        if kind == "R":
            K = sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
            Rj = sp.eye(3) + sp.sin(q[k]) * K + (1 - sp.cos(q[k])) * K * K
            R = R * Rj
        else:
            p = p + R * a * q[k]
        cw = p + R * sp.Matrix(c)
        Jv = cw.jacobian(q)  # ċ = Jv q̇
        Rdot = sum((R.diff(q[j]) * qd[j] for j in range(n)), sp.zeros(3, 3))
        W = R.T * Rdot  # body angular velocity, skew form
        Jw = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]]).jacobian(qd)
        # T_k = ½ m |ċ|² + ½ ωᵀ I ω  ->  its Hessian in q̇:
        M += m * Jv.T * Jv + Jw.T * sp.Matrix(I) * Jw
        V += -m * (sp.Matrix(gravity).T * cw)[0]
    T = (qdv.T * M * qdv)[0] / 2
    G = christoffel(M, q)
    Cqd = sp.Matrix(
        [sum(G[i][j][k] * qd[j] * qd[k] for j in range(n) for k in range(n)) for i in range(n)]
    )
    g = sp.Matrix([V.diff(q[i]) for i in range(n)])

    def f(qv, qdv_):
        sub = {
            **{q[i]: sp.Float(qv[i]) for i in range(n)},
            **{qd[i]: sp.Float(qdv_[i]) for i in range(n)},
        }
        return [
            np.array(x.xreplace(sub).evalf(), dtype=float)
            if isinstance(x, sp.MatrixBase)
            else float(x.xreplace(sub))
            for x in (M, Cqd, g, T, V)
        ]

    return f


@pytest.mark.parametrize(
    "types,seed", [(["RZ", "RX"], 3), (["RY", "PX", ("RU", (1.0, 2.0, -0.5))], 4)]
)
def test_against_independent_sympy_christoffel(types, seed):
    rng = np.random.default_rng(seed)
    model, params = chain(types, rng)
    f = _sympy_oracle(params, model.gravity.linear)
    dyn = L.load(model, name=f"chain{seed}")
    for _ in range(3):
        q = rng.uniform(-2, 2, len(types))
        v = rng.standard_normal(len(types))
        M, Cqd, g, T, V = f(q, v)
        assert rel(dyn.mass_matrix(q), np.array(M, float)) < TOL
        assert rel(dyn.coriolis(q, v), np.array(Cqd, float).ravel()) < TOL
        assert rel(dyn.gravity(q), np.array(g, float).ravel()) < TOL
        assert abs(dyn.kinetic_energy(q, v) - float(T)) < TOL
        assert abs(dyn.potential_energy(q) - float(V)) < TOL


def test_planar2r_symbolic_christoffel_and_latex():
    """Symbolically: the derived C q̇ equals Σ Γ_ijk q̇_j q̇_k with Γ from the derived M (Γ by the
    test's own :func:`christoffel`; the engine computes C q̇ as Ṁ q̇ − ∂T/∂q)."""
    d = L.derive(aa.load("planar2r"))
    mats = L.sympy_matrices(d, which=("M", "Cqd", "g"))
    q, qd, _ = L.symbols(2)
    G = christoffel(mats["M"], q)
    C2 = sp.Matrix(
        [sum(G[i][j][k] * qd[j] * qd[k] for j in range(2) for k in range(2)) for i in range(2)]
    )
    assert all(abs(sp.N(sp.simplify(e))) < 1e-12 for e in (mats["Cqd"] - C2))
    # the book's two-link arm (Fig. 7-14): M12 depends on cos q2 only, M22 is constant
    assert mats["M"][1, 1].free_symbols == set()
    assert mats["M"][0, 1].free_symbols == {q[1]}
    tex = L.latex(d)
    assert r"\cos{\left(q_{2} \right)}" in tex and r"\tau &=" in tex


def test_fixed_axis_rotation_eq_8_9():
    """(8-9): one body about a fixed vertical axis, no gravity moment: J θ̈ = L_z with
    J = I_zz + m(c_x² + c_y²)."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "z")
    I = np.diag([0.02, 0.03, 0.04])
    model.appendBodyToJoint(jid, pin.Inertia(1.5, np.array([0.3, 0.1, 0.2]), I), pin.SE3.Identity())
    dyn = L.load(model, name="fixed_axis")
    J = 0.04 + 1.5 * (0.3**2 + 0.1**2)
    assert abs(dyn.mass_matrix(np.array([0.7]))[0, 0] - J) < 1e-14
    assert abs(dyn.tau(np.array([0.7]), np.array([2.0]), np.array([3.0]))[0] - J * 3.0) < 1e-13


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_mdot_minus_2c_is_skew(seed):
    """Property of the Christoffel C: Ṁ − 2C is skew-symmetric (Ṁ by central differences)."""
    robot = aa.load("panda")
    dyn = L.load(robot)
    rng = np.random.default_rng(seed)
    q = robot.random_q(rng=rng)
    v = rng.standard_normal(7)
    h = 1e-6
    Mdot = (dyn.mass_matrix(q + h * v) - dyn.mass_matrix(q - h * v)) / (2 * h)
    S = Mdot - 2 * dyn.coriolis_matrix(q, v)
    assert np.max(np.abs(S + S.T)) < 1e-7
    M = dyn.mass_matrix(q)
    assert np.allclose(M, M.T, atol=0) and np.linalg.eigvalsh(M)[0] > 0
    assert abs(dyn.kinetic_energy(q, v) - 0.5 * v @ M @ v) < 1e-12
    assert np.allclose(dyn.coriolis_matrix(q, v) @ v, dyn.coriolis(q, v), atol=1e-12)


def test_cache_roundtrip_and_generator_reproduces_cached_file(tmp_path, monkeypatch):
    monkeypatch.setenv("ANTHROARM_CACHE", str(tmp_path))
    robot = aa.load("human_arm7", height=1.62, mass=55.0)
    info = L.chain_info(robot.model, "h")
    key = info.key()
    L._MEMO.pop(key, None)
    mod, src = L.generated_module(info)
    assert src == "derived"
    path = tmp_path / "lagrange" / f"lagrange_{key}.py"
    assert path.is_file() and not list(path.parent.glob("*.tmp"))
    # the generator is deterministic: a fresh derivation reproduces the cached file byte for byte
    # (without the Coriolis matrix: its module is made on first use, below)
    assert path.read_text() == L.generate_python(L.derive(info, coriolis_matrix=False))
    assert "def coriolis_matrix" not in path.read_text()
    cmat, src = L.generated_module(info, coriolis_matrix=True)
    cpath = tmp_path / "lagrange" / f"coriolis_{key}.py"
    assert src == "derived" and cpath.read_text() == L.generate_python(
        L.derive(info), only=("coriolis_matrix",)
    )
    assert cmat.coriolis_matrix_1 is not None and not hasattr(cmat, "tau_1")
    L._MEMO.pop(key, None)
    _, src = L.generated_module(info)
    assert src == "cache"
    # a corrupt cache file is replaced by a fresh derivation
    path.write_text("raise RuntimeError('corrupt')\n")
    L._MEMO.pop(key, None)
    _, src = L.generated_module(info)
    assert src == "derived" and "def mass_matrix" in path.read_text()
    # other body parameters -> other key
    other = L.chain_info(aa.load("human_arm7", height=1.9, mass=90.0).model, "h2")
    assert other.key() != key


# ------------------------------------------------------------------ bad input
def test_nan_and_shape_errors():
    dyn = L.load(aa.load("planar2r"))
    assert L.load("planar2r").n == 2  # a catalog name works too
    with pytest.raises(UnsupportedModelError, match="pin.Model"):
        L.load(3)
    with pytest.raises(ValueError, match=r"q\[1\] \(joint 'joint2'\)"):
        dyn.mass_matrix([0.0, np.nan])
    with pytest.raises(ValueError, match="finite"):
        dyn.mass_matrix([np.nan, 0.0])
    with pytest.raises(ValueError, match="qd"):
        dyn.coriolis([0.0, 0.0], [0.0, np.inf])
    with pytest.raises(ValueError, match="shape"):
        dyn.gravity([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="batch"):
        dyn.tau(np.zeros((3, 2)), np.zeros((4, 2)), np.zeros(2))


@pytest.mark.parametrize(
    "jm", [pin.JointModelSpherical(), pin.JointModelFreeFlyer(), pin.JointModelPlanar()]
)
def test_unsupported_joints(jm):
    model = pin.Model()
    jid = model.addJoint(0, jm, pin.SE3.Identity(), "j")
    model.appendBodyToJoint(jid, pin.Inertia.Random(), pin.SE3.Identity())
    with pytest.raises(UnsupportedModelError, match="'j'.*prismatic"):
        L.derive(model, name="bad")


def _one_body(m, I, c=(0.1, 0, 0)):
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    Y = pin.Inertia(1.0, np.zeros(3), np.eye(3))
    Y.mass = m
    Y.lever = np.asarray(c, float)
    Y.inertia = np.asarray(I, float)
    model.appendBodyToJoint(jid, Y, pin.SE3.Identity())
    return model


def test_bad_inertias():
    with pytest.raises(InertiaError, match="mass"):
        L.derive(_one_body(-1.0, np.eye(3) * 0.01), name="neg")
    with pytest.raises(InertiaError, match="positive"):
        L.derive(_one_body(1.0, np.diag([0.01, 0.01, -0.02])), name="indef")
    with pytest.raises(InertiaError, match="massless"):
        L.derive(_one_body(0.0, np.zeros((3, 3))), name="zero")


def test_joint_moving_no_mass_is_refused():
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "a")
    model.appendBodyToJoint(
        j1, pin.Inertia(1.0, np.array([0.3, 0, 0]), np.eye(3) * 0.01), pin.SE3.Identity()
    )
    model.addJoint(
        j1, pin.JointModelRX(), pin.SE3(np.eye(3), np.array([0.5, 0, 0])), "b"
    )  # massless link
    with pytest.raises(InertiaError, match="positive definite"):
        L.load(model, name="tipless")


def test_printed_lagrange_equation_8_8_fails():
    """(8-8) prints d/dt ∂T/∂q̇ − ∂T/∂q̇ = Q; the correct second term is ∂T/∂q.  With
    τ = d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q (our derivation), the printed form gives τ + ∂T/∂q − p."""
    robot = aa.load("planar2r")
    dyn = L.load(robot)
    q, v, a = np.array([0.4, 0.9]), np.array([1.5, -2.0]), np.array([0.3, 0.1])
    ref = pin.rnea(robot.model, robot.model.createData(), q, v, a)
    assert rel(dyn.tau(q, v, a), ref) < TOL
    h = 1e-6
    dTdq = np.array(
        [
            (dyn.kinetic_energy(q + h * e, v) - dyn.kinetic_energy(q - h * e, v)) / (2 * h)
            for e in np.eye(2)
        ]
    )
    printed = dyn.tau(q, v, a) + dTdq - dyn.momentum(q, v)
    assert rel(printed, ref) > 1e-2


@pytest.mark.skipif(
    __import__("anthroarm.dynamics.ccode", fromlist=["compiler"]).compiler() is None,
    reason="no C compiler",
)
def test_c_backend_matches_numpy_and_pin():
    robot = aa.load("planar2r")
    dc, dn = L.load(robot, backend="c"), L.load(robot)
    rng = np.random.default_rng(5)
    Q, V, A = rng.standard_normal((3, 6, 2))
    assert np.allclose(dc.tau(Q, V, A), dn.tau(Q, V, A), atol=1e-13)
    assert np.allclose(dc.mass_matrix(Q[0]), dn.mass_matrix(Q[0]), atol=1e-14)
    assert abs(dc.kinetic_energy(Q[1], V[1]) - dn.kinetic_energy(Q[1], V[1])) < 1e-14
    assert rel(dc.gravity(Q[2]), pin.computeGeneralizedGravity(robot.model, robot.data, Q[2])) < TOL
    with pytest.raises(ValueError):
        dc.gravity([np.nan, 0.0])
