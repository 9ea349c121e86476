"""ContactNormalTask and SurfaceContactTask against mathematics and Pinocchio.

Oracles: the residuals from Pinocchio FK (data.oMf) and the geometry of the sphere/cylinder
written out here; the Jacobians against central finite differences of the residual on the
manifold (pin.integrate); the objects' normals and their derivatives against finite differences
of the signed distance."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.hand import Cylinder, Sphere
from anthroarm.ik import qp


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def _fd_jacobian(robot, task, q, h=1e-6):
    conf = qp.IKConfiguration(robot, q)
    J = np.empty((len(task.compute_error(conf)), robot.nv))
    for i in range(robot.nv):
        dv = np.zeros(robot.nv)
        dv[i] = h
        conf.update(pin.integrate(robot.model, q, dv))
        ep = task.compute_error(conf)
        conf.update(pin.integrate(robot.model, q, -dv))
        em = task.compute_error(conf)
        J[:, i] = (ep - em) / (2 * h)
    return J


def _fk(robot, q, frame):
    d = robot.model.createData()
    pin.framesForwardKinematics(robot.model, d, q)
    return d.oMf[robot.model.getFrameId(frame)]


def test_contact_normal_residual_and_jacobian(limb):
    rng = np.random.default_rng(0)
    axis = np.array([0.0, 1.0, 0.0])
    for _ in range(3):
        q = limb.random_q(rng=rng)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        task = qp.ContactNormalTask(limb, "index_tip", axis=axis, target=d)
        conf = qp.IKConfiguration(limb, q)
        a_w = _fk(limb, q, "index_tip").rotation @ axis  # Pinocchio FK
        e = task.compute_error(conf)
        np.testing.assert_allclose(e, a_w - d, atol=1e-12)
        theta = np.arccos(np.clip(a_w @ d, -1, 1))
        assert np.linalg.norm(e) == pytest.approx(2 * np.sin(theta / 2), abs=1e-12)
        assert task.angle(conf) == pytest.approx(theta, abs=1e-9)
        np.testing.assert_allclose(
            task.compute_jacobian(conf), _fd_jacobian(limb, task, q), atol=1e-6
        )


def test_contact_normal_qp_converges_to_a_reachable_direction(limb):
    """Target = the fingertip axis at another configuration: reachable, so QP steps drive the
    angle (from Pinocchio FK) to zero."""
    q0 = limb.random_q(rng=1, margin=0.1)
    q1 = limb.random_q(rng=2, margin=0.1)
    axis = np.array([0.0, 1.0, 0.0])
    d = _fk(limb, q1, "middle_tip").rotation @ axis
    task = qp.ContactNormalTask(limb, "middle_tip", axis=axis, target=d, lm_damping=1e-3)
    conf = qp.IKConfiguration(limb, q0)
    for _ in range(40):
        conf.integrate_inplace(qp.step(conf, None, [task], 1.0, limits=None, solver="daqp"), 1.0)
    a = _fk(limb, conf.q, "middle_tip").rotation @ axis
    assert np.degrees(np.arccos(np.clip(a @ d, -1, 1))) < 1e-4


@pytest.mark.parametrize(
    "obj", [Sphere([0.05, 0.1, -0.6], 0.04), Cylinder([0.02, 0.08, -0.7], [1.0, 0.2, 0.1], 0.03)]
)
def test_surface_contact_residual_and_jacobian(limb, obj):
    rng = np.random.default_rng(3)
    axis = np.array([0.0, 1.0, 0.0])
    task = qp.SurfaceContactTask(
        limb, "thumb_tip", obj, axis=axis, distance_cost=1.0, normal_cost=0.3
    )
    for _ in range(2):
        q = limb.random_q(rng=rng)
        conf = qp.IKConfiguration(limb, q)
        M = _fk(limb, q, "thumb_tip")
        p = M.translation
        if isinstance(obj, Sphere):  # geometry written out here
            w = p - np.array([0.05, 0.1, -0.6])
            dist, m = np.linalg.norm(w) - 0.04, w / np.linalg.norm(w)
        else:
            u = np.array([1.0, 0.2, 0.1]) / np.linalg.norm([1.0, 0.2, 0.1])
            w = p - np.array([0.02, 0.08, -0.7])
            w = w - (w @ u) * u
            dist, m = np.linalg.norm(w) - 0.03, w / np.linalg.norm(w)
        e = task.compute_error(conf)
        assert e[0] == pytest.approx(dist, abs=1e-12)
        np.testing.assert_allclose(e[1:], M.rotation @ axis + m, atol=1e-12)
        np.testing.assert_allclose(
            task.compute_jacobian(conf), _fd_jacobian(limb, task, q), atol=1e-6
        )


@pytest.mark.parametrize(
    "obj", [Sphere([0.1, -0.2, 0.3], 0.05), Cylinder([0.0, 0.1, 0.0], [0.3, -1.0, 0.5], 0.02)]
)
def test_object_normal_is_distance_gradient(obj):
    rng = np.random.default_rng(4)
    h = 1e-6
    for _ in range(5):
        p = obj.center + rng.normal(scale=0.1, size=3)
        g = np.array(
            [(obj.distance(p + h * e) - obj.distance(p - h * e)) / (2 * h) for e in np.eye(3)]
        )
        np.testing.assert_allclose(obj.normal(p), g, atol=1e-8)
        N = np.column_stack(
            [(obj.normal(p + h * e) - obj.normal(p - h * e)) / (2 * h) for e in np.eye(3)]
        )
        np.testing.assert_allclose(obj.normal_jacobian(p), N, atol=1e-5)
        c = obj.project(p)
        assert abs(obj.distance(c)) < 1e-12
    # surface points from surface coordinates lie on the surface, normal as the geometry says
    if isinstance(obj, Sphere):
        c = obj.point([1.0, 2.0, -2.0])
        np.testing.assert_allclose(c, obj.center + 0.05 * np.array([1, 2, -2]) / 3.0, atol=1e-15)
    else:
        c = obj.point(0.7, 0.01)
        assert obj.height(c) == pytest.approx(0.01)
        assert obj.distance(c) == pytest.approx(0.0, abs=1e-15)
        assert obj.normal(c) @ obj.axis == pytest.approx(0.0, abs=1e-15)


def test_task_bad_input(limb):
    with pytest.raises(ValueError, match="nonzero"):
        qp.ContactNormalTask(limb, "index_tip", axis=[0, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        qp.ContactNormalTask(limb, "index_tip", target=[np.nan, 0, 1])
    with pytest.raises(aa.errors.UnknownFrameError):
        qp.ContactNormalTask(limb, "no_such_tip")
    with pytest.raises(TypeError, match="distance"):
        qp.SurfaceContactTask(limb, "index_tip", object())
    with pytest.raises(aa.errors.GraspError):
        Sphere([0, 0, np.inf], 0.1)
    with pytest.raises(aa.errors.GraspError):
        Cylinder([0, 0, 0], [0, 0, 0], 0.1)
    with pytest.raises(aa.errors.GraspError):
        Sphere([0, 0, 0], -0.1)
