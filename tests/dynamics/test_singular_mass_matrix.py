"""Forward dynamics at a singular mass matrix (issue 12, item 8).

The model: a yaw joint (z) carrying a massless yoke, a pitch joint (y) carrying a point mass m
at distance l (no rotational inertia).  Mathematics: M(q) = diag(m l² cos² q₂, m l²), singular
where the mass lies on the yaw axis (q₂ = ±π/2).  The URDF is valid and M(0) is positive
definite, so the model loads; forward dynamics at q₂ = π/2 must be a typed error, not a
LinAlgError nor the ~1e31 rad/s² that plain Cholesky (and Pinocchio's ``aba``) return.
"""

import math

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.dynamics import lagrange
from anthroarm.dynamics.simulate import simulate
from anthroarm.errors import InertiaError, SingularMassMatrixError

M_KG, L_M = 2.0, 0.5
URDF = f"""<?xml version="1.0"?>
<robot name="pointmass2r">
  <link name="base"/>
  <link name="yoke"><inertial><origin xyz="0 0 0"/><mass value="0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="{L_M} 0 0"/><mass value="{M_KG}"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="yoke"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
  <joint name="pitch" type="revolute"><parent link="yoke"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    p = tmp_path_factory.mktemp("singular") / "pointmass2r.urdf"
    p.write_text(URDF)
    return aa.load(str(p))


@pytest.fixture(scope="module")
def dyn(arm):
    return lagrange.load(arm, use_cache=False)


def test_mass_matrix_is_the_closed_form_and_pinocchios(arm, dyn):
    for q2 in (0.0, 0.7, math.pi / 2):
        q = np.array([0.3, q2])
        expect = np.diag([M_KG * (L_M * math.cos(q2)) ** 2, M_KG * L_M**2])
        assert np.allclose(dyn.mass_matrix(q), expect, atol=1e-15)
        assert np.allclose(pin.crba(arm.model, arm.model.createData(), q), expect, atol=1e-15)


@pytest.mark.parametrize("q2", [math.pi / 2, -math.pi / 2, math.pi / 2 - 1e-7])
def test_forward_at_singular_M_is_a_typed_error(dyn, q2):
    q = np.array([0.2, q2])
    with pytest.raises(SingularMassMatrixError, match="singular at q") as ei:
        dyn.forward(q, np.zeros(2), np.array([0.1, 0.0]))
    err = ei.value
    assert isinstance(err, InertiaError) and isinstance(err, ValueError)
    assert err.joint == "yaw" and "'yaw'" in str(err)
    assert np.array_equal(err.q, q)
    assert err.cond > 1e12  # mathematics: cond = 1 / cos² q₂ here


def test_forward_batch_names_the_singular_item(dyn):
    Q = np.array([[0.0, 0.5], [0.0, math.pi / 2], [0.0, 1.0]])
    with pytest.raises(SingularMassMatrixError, match="batch item 1"):
        dyn.forward(Q, np.zeros(2), np.array([0.1, 0.0]))


def test_pinocchio_aba_does_not_flag_it(arm, dyn):
    """The comparison the docstring states: Pinocchio's aba returns a huge acceleration."""
    q, v, tau = np.array([0.0, math.pi / 2]), np.zeros(2), np.array([0.1, 0.0])
    a = pin.aba(arm.model, arm.model.createData(), q, v, tau)
    assert abs(a[0]) > 1e20
    # away from the singularity both agree (Pinocchio as the oracle)
    for q2 in (0.0, 0.4, 1.2):
        q = np.array([0.1, q2])
        assert np.allclose(
            dyn.forward(q, np.array([0.3, -0.2]), tau),
            pin.aba(arm.model, arm.model.createData(), q, np.array([0.3, -0.2]), tau),
            rtol=1e-10,
        )


def test_well_conditioned_models_are_unaffected():
    for name in ("planar2r", "prosthetic_arm", "human_arm7"):
        r = aa.load(name)
        d = lagrange.load(r)
        for seed in range(5):
            q = r.random_q(rng=seed)
            tau = d.tau(q, np.zeros(r.nv), np.ones(r.nv))
            assert np.allclose(d.forward(q, np.zeros(r.nv), tau), np.ones(r.nv), atol=1e-7)


def test_simulation_stops_with_status_singular(arm, dyn):
    res = simulate(dyn, np.array([0.0, math.pi / 2]), np.zeros(2), 0.01, dt=1e-3)
    assert res.status.startswith("singular:") and "'yaw'" in res.status
    assert res.q.shape == (1, 2) and np.all(np.isfinite(res.q))
    ok = simulate(dyn, np.array([0.0, 0.3]), np.zeros(2), 0.01, dt=1e-3)
    assert ok.status == "ok"


def test_forward_overflowing_torque_is_a_value_error(dyn):
    with pytest.raises(ValueError, match="within"):
        dyn.forward(np.array([0.0, 0.3]), np.zeros(2), np.array([1e308, -1e308]))
    with pytest.raises(ValueError, match="within"):
        dyn.coriolis(np.array([0.0, 0.3]), np.array([1e200, 0.0]))
