"""§8-2/§8-3 inertia forces and couples (8-30)–(8-40) and the oblique joint frame
(8-84)–(8-86).  Oracles: pin.rnea split into M q̈, C q̇ and g (pin.computeGeneralizedGravity),
Pinocchio's body inertia (vxiv), finite differences of the angular momentum, and mathematics."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.dynamics.inertia_forces import (
    angular_momentum,
    axis_projections,
    dalembert_torques,
    inertia_couple,
    inertia_couple_expanded,
    inertia_couple_fixed,
    inertia_force,
    inertia_force_body,
    joint_frame,
    joint_frame_from_links,
    link_inertia_loads,
    oblique_components,
    oblique_components_printed,
    torque_terms,
)
from anthroarm.spatial.rotations import rot_axis

RNG = np.random.default_rng(11)


def random_inertia(rng):
    A = rng.normal(size=(3, 3))
    return A @ A.T + 0.1 * np.eye(3)


def pin_terms(r, q, v, a):
    m, d = r.model, r.model.createData()
    z = np.zeros(r.nv)
    g = pin.computeGeneralizedGravity(m, d, q)
    return {
        "M_qdd": pin.rnea(m, d, q, z, a) - g,
        "C_qd": pin.rnea(m, d, q, v, z) - g,
        "g": g,
        "tau": pin.rnea(m, d, q, v, a),
    }


@pytest.mark.parametrize(
    "name",
    [
        "care_robot",
        "prosthetic_arm",
        "unimate5",
        "human_arm7",
        "spherical_robot",
        "cartesian_robot",
        "ur10",
    ],
)
def test_dalembert_terms_equal_rnea_split(name):
    r = aa.load(name)
    for _ in range(3):
        q = r.random_q(None, RNG)
        v, a = RNG.normal(size=r.nv), RNG.normal(size=r.nv)
        ours, ref = torque_terms(r, q, v, a), pin_terms(r, q, v, a)
        scale = 1.0 + max(np.abs(x).max() for x in ref.values())
        for k in ("M_qdd", "C_qd", "g", "tau"):
            np.testing.assert_allclose(ours[k], ref[k], atol=1e-12 * scale, err_msg=k)
        # M q̈ is linear in q̈: the columns are crba's
        M = pin.crba(r.model, r.model.createData(), q)
        np.testing.assert_allclose(
            ours["M_qdd"], np.triu(M) @ a + np.triu(M, 1).T @ a, atol=1e-12 * scale
        )


MIMIC_URDF = """<?xml version="1.0"?>
<robot name="mimic3">
  <link name="base_link"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"
      effort="10" velocity="2"/></joint>
  <link name="l1"><inertial><origin xyz="0.1 0 0"/><mass value="1.0"/><inertia ixx="0.01"
    ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.2 0 0" rpy="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3"
      effort="10" velocity="2"/></joint>
  <link name="l2"><inertial><origin xyz="0.1 0.02 0"/><mass value="0.7"/><inertia ixx="0.01"
    ixy="0" ixz="0.002" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.2 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3"
      effort="10" velocity="2"/>
    <mimic joint="j2" multiplier="0.6" offset="0.1"/></joint>
  <link name="l3"><inertial><origin xyz="0.05 0 0"/><mass value="0.3"/><inertia ixx="0.002"
    ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.003"/></inertial></link>
  <joint name="j4" type="prismatic"><parent link="l3"/><child link="l4"/>
    <origin xyz="0.1 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.2"
      effort="10" velocity="1"/></joint>
  <link name="l4"><inertial><origin xyz="0.02 0 0.01"/><mass value="0.2"/><inertia ixx="0.001"
    ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>
"""


def test_mimic_and_prismatic_joints_against_a_coupled_reference(tmp_path):
    """A mimic joint (θ3 = 0.6 θ2 + 0.1) as generalised force: τ = Gᵀ τ_full with G = ∂θ/∂q,
    τ_full from pin.rnea of the same URDF without the coupling (every joint independent)."""
    p = tmp_path / "mimic3.urdf"
    p.write_text(MIMIC_URDF)
    r = aa.load(str(p))
    assert r.nv == 3
    free = pin.buildModelFromXML(
        MIMIC_URDF.replace('<mimic joint="j2" multiplier="0.6" offset="0.1"/>', "")
    )
    G = np.array([[1, 0, 0], [0, 1, 0], [0, 0.6, 0], [0, 0, 1.0]])
    for _ in range(3):
        q = r.random_q(None, RNG)
        v, a = RNG.normal(size=3), RNG.normal(size=3)
        th = np.array([q[0], q[1], 0.6 * q[1] + 0.1, q[2]])
        tau_full = pin.rnea(free, free.createData(), th, G @ v, G @ a)
        np.testing.assert_allclose(dalembert_torques(r, q, v, a), G.T @ tau_full, atol=1e-12)


def test_inertia_couple_expanded_is_the_vector_form():
    """(8-39) as printed = (8-38) −(Jε + ω × Jω), for full tensors (products of inertia)."""
    for _ in range(20):
        J, w, e = random_inertia(RNG), RNG.normal(size=3), RNG.normal(size=3)
        np.testing.assert_allclose(
            inertia_couple_expanded(J, w, e), inertia_couple(J, w, e), atol=1e-12
        )


def test_inertia_couple_is_pinocchios_body_wrench():
    """Pinocchio's body inertia at the CoM: I·a + v ×* (I·v) with zero linear velocity and
    acceleration is the moment Jε + ω × Jω: our couple is its negative."""
    J, m = random_inertia(RNG), 1.7
    w, e = RNG.normal(size=3), RNG.normal(size=3)
    Y = pin.Inertia(m, np.zeros(3), J)
    f = Y * pin.Motion(np.zeros(3), e) + pin.Motion(np.zeros(3), w).cross(
        Y * pin.Motion(np.zeros(3), w)
    )
    np.testing.assert_allclose(inertia_couple(J, w, e), -f.angular, atol=1e-12)
    np.testing.assert_allclose(inertia_force(m, [1.0, -2.0, 0.5]), -m * np.array([1.0, -2.0, 0.5]))


def test_couple_is_minus_the_rate_of_angular_momentum():
    """(8-36): M⁽⁰⁾ = −d/dt (R J ωᵦ), by central differences along a rotation R(t) = exp(t Ω)·R0
    with a time-varying body rate; (8-40) maps the body couple to the fixed frame."""
    J = random_inertia(RNG)
    w0, w1 = RNG.normal(size=3), RNG.normal(size=3)

    def state(t):
        wb = w0 + t * w1  # body angular velocity ωᵦ(t)
        return wb

    # integrate R' = R [ωᵦ]× with a fine RK-free exact step: piecewise-constant rate over tiny steps
    def R_of(t, n=2000):
        R = np.eye(3)
        h = t / n
        for k in range(n):
            wb = state((k + 0.5) * h)
            R = R @ rot_axis(wb / np.linalg.norm(wb), np.linalg.norm(wb) * h)
        return R

    t, h = 0.3, 1e-3
    H = lambda s: R_of(s) @ angular_momentum(J, state(s))  # noqa: E731
    dH = (H(t + h) - H(t - h)) / (2 * h)
    M0 = inertia_couple_fixed(R_of(t), inertia_couple(J, state(t), w1))
    np.testing.assert_allclose(M0, -dH, atol=2e-4 * (1 + np.abs(dH).max()))


def test_inertia_force_in_the_body_frame():
    R = rot_axis(np.array([1.0, 2.0, 2.0]) / 3, 0.7)
    F = inertia_force(2.0, [0.3, -0.1, 9.0])
    np.testing.assert_allclose(R @ inertia_force_body(R, F), F, atol=1e-15)


def test_link_loads_are_zero_at_rest_and_balance_gravity():
    r = aa.load("care_robot")
    q = r.random_q(None, RNG)
    z = np.zeros(r.nv)
    L = link_inertia_loads(r, q, z, z)
    assert np.abs(L.F).max() == 0.0 and np.abs(L.M).max() == 0.0
    # gravity alone: the d'Alembert torques are Pinocchio's generalized gravity
    np.testing.assert_allclose(
        dalembert_torques(r, q, z, z),
        pin.computeGeneralizedGravity(r.model, r.model.createData(), q),
        atol=1e-12,
    )


def test_bad_inputs_are_value_errors():
    r = aa.load("care_robot")
    with pytest.raises(ValueError):
        dalembert_torques(r, np.zeros(6), np.full(6, np.nan), np.zeros(6))
    with pytest.raises(ValueError):
        dalembert_torques(r, np.zeros(6), np.zeros(5), np.zeros(6))
    with pytest.raises(ValueError, match="mass"):
        inertia_force(-1.0, [0, 0, 1])
    with pytest.raises(ValueError, match="parallel"):
        joint_frame([0, 0, 1], [0, 0, 2])


# ---------------------------------------------------------------- oblique joint frame (8-84)-(8-86)


def test_joint_frame_third_axis():
    p1, p2 = np.array([1.0, 0, 0]), np.array([np.cos(1.0), np.sin(1.0), 0.0]) * 2
    A = joint_frame(p1, p2)
    np.testing.assert_allclose(np.linalg.norm(A, axis=0), 1.0)
    np.testing.assert_allclose(A[:, 2], [0, 0, 1.0], atol=1e-15)
    assert abs(A[:, 0] @ A[:, 1] - np.cos(1.0)) < 1e-15  # oblique: not orthogonal


def test_oblique_decomposition_reconstructs_the_moment_printed_form_fails():
    A = joint_frame([1.0, 0.2, 0.1], [0.3, 1.0, -0.4])
    M = np.array([0.7, -1.2, 2.5])
    c = oblique_components(M, A)
    np.testing.assert_allclose(c[0] * A[:, 0] + c[1] * A[:, 1] + c[2] * A[:, 2], M, atol=1e-14)
    c_printed = oblique_components_printed(M, A)
    back = c_printed[0] * A[:, 0] + c_printed[1] * A[:, 1] + c_printed[2] * A[:, 2]
    assert np.abs(back - M).max() > 0.05  # (8-86) as printed: not M


def test_orthonormal_joint_frame_gives_pinocchios_spherical_joint_torque():
    """For a ball joint whose frame is the child body's (p1, p2, p3 = its x, y, z axes), the
    components (8-86) are the body-frame moment pin.rnea returns for the spherical joint."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "ball")
    model.appendBodyToJoint(
        jid, pin.Inertia(1.3, np.array([0.1, 0.05, -0.2]), random_inertia(RNG)), pin.SE3.Identity()
    )
    data = model.createData()
    q = pin.randomConfiguration(model, -np.ones(4), np.ones(4))
    v, a = RNG.normal(size=3), RNG.normal(size=3)
    tau = pin.rnea(model, data, q, v, a)
    R = data.oMi[jid].rotation
    M_world = R @ tau
    A = joint_frame(R[:, 0], R[:, 1])
    np.testing.assert_allclose(A, R, atol=1e-12)
    np.testing.assert_allclose(oblique_components(M_world, A), tau, atol=1e-12)
    np.testing.assert_allclose(
        oblique_components_printed(M_world, A), tau, atol=1e-12
    )  # orthonormal: same
    np.testing.assert_allclose(axis_projections(M_world, A), tau, atol=1e-12)


def test_printed_8_33_angular_momentum_fails():
    """(8-33) as printed (l. 6101): H_x = ω_x J_z − ω_y J_zy − ω_z J_zx, H_y = −ω_x J_yz + ω_y J_y
    − ω_z J_yx.  The corrected H = J ω (8-34) is r × (ω × r) summed over point masses (8-32)."""
    pts, ms = RNG.normal(size=(6, 3)), RNG.uniform(0.1, 1.0, 6)
    J = sum(m * (p @ p * np.eye(3) - np.outer(p, p)) for m, p in zip(ms, pts))
    w = RNG.normal(size=3)
    H_true = sum(m * np.cross(p, np.cross(w, p)) for m, p in zip(ms, pts))  # (8-32)
    np.testing.assert_allclose(angular_momentum(J, w), H_true, atol=1e-12)
    Jy, Jz = J[1, 1], J[2, 2]
    Jxy, Jyz, Jzx = -J[0, 1], -J[1, 2], -J[2, 0]
    Hx_printed = w[0] * Jz - w[1] * Jyz - w[2] * Jzx  # J_zy = J_yz
    Hy_printed = -w[0] * Jyz + w[1] * Jy - w[2] * Jxy  # J_yx = J_xy
    # each printed component is wrong on its own (J_z for J_x in H_x; J_yz and J_yx swapped in H_y)
    assert abs(Hx_printed - H_true[0]) > 1e-3 and abs(Hy_printed - H_true[1]) > 1e-3


def test_8_84_row_vectors_with_the_passive_matrices_are_the_rotated_axes():
    """(8-84): (l, m, n)(Φ Ψ Θ) of a link with X–Y–X angles e is R(e) (l, m, n)ᵀ, R = R_x(θ)
    R_y(ψ) R_x(φ) (scipy's intrinsic 'XYX' as the independent oracle)."""
    from scipy.spatial.transform import Rotation

    e1, e2 = RNG.uniform(-1, 1, 3), RNG.uniform(-1, 1, 3)
    l1, l2 = np.array([0.0, 0.6, 0.8]), np.array([1.0, 0.0, 0.0])
    A = joint_frame_from_links(l1, e1, l2, e2)
    R1, R2 = (Rotation.from_euler("XYX", e).as_matrix() for e in (e1, e2))
    np.testing.assert_allclose(A[:, 0], R1 @ l1, atol=1e-14)
    np.testing.assert_allclose(A[:, 1], R2 @ l2, atol=1e-14)
    c = np.cross(R1 @ l1, R2 @ l2)
    np.testing.assert_allclose(A[:, 2], c / np.linalg.norm(c), atol=1e-14)  # (8-85)
