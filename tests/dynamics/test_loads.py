"""External loads (Eq. (8-5)) and inverse dynamics with loads, against Pinocchio and mathematics.

Oracles:
* ``pin.rnea(model, data, q, v, a, fext)`` with ``fext[i]`` built here from Pinocchio's own frame
  placements (a wrench at a frame moved to its parent joint and expressed in that joint's axes);
* ``pin.rnea`` of a model whose holding body carries the object's inertia (a held object is a
  body rigidly attached to the hand; no fext at all);
* Eq. (8-5) itself: Q_j = F · ∂r/∂q_j (+ m · ω_j) with the derivatives by central differences of
  forward kinematics;
* statics: a point mass at the hand of a horizontal arm loads the shoulder with m g times the
  lever arm.
"""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.dynamics import loads as L
from anthroarm.errors import InertiaError, ParameterError, UnknownFrameError


@pytest.fixture(scope="module")
def person():
    return aa.load("human_arm7", height=1.75, mass=70.0, sex="male")


def _traj(robot, n, seed):
    rng = np.random.default_rng(seed)
    q = robot.random_q(n, rng=rng, margin=0.05)
    qd = rng.uniform(-2, 2, (n, robot.nv))
    qdd = rng.uniform(-5, 5, (n, robot.nv))
    return q, qd, qdd


def _fext_of_wrench(model, data, q, fid, f, m, reference):
    """Pinocchio fext list for a wrench (f, m) at frame fid's origin (world axes if LWA)."""
    pin.framesForwardKinematics(model, data, q)
    R = data.oMf[fid].rotation
    if reference == "LOCAL_WORLD_ALIGNED":
        f, m = R.T @ f, R.T @ m
    frame = model.frames[fid]
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    fext[frame.parentJoint] = frame.placement.act(pin.Force(np.asarray(f), np.asarray(m)))
    return fext


@pytest.mark.parametrize("reference", ["LOCAL_WORLD_ALIGNED", "LOCAL"])
@pytest.mark.parametrize("frame", [None, "forearm", "upper_arm"])
def test_wrench_equals_rnea_with_fext(person, reference, frame):
    robot = person
    q, qd, qdd = _traj(robot, 12, 1)
    rng = np.random.default_rng(2)
    F = rng.uniform(-20, 20, (12, 3))
    Mo = rng.uniform(-3, 3, (12, 3))
    w = L.Wrench(F, Mo, frame=frame, reference=reference)
    for engine in ("lagrange", "pinocchio"):
        res = L.inverse_dynamics(robot, q, qd, qdd, w, engine=engine)
        model, data = robot.model, pin.Data(robot.model)
        fid = robot.frame_id(frame)
        ref = np.array(
            [
                pin.rnea(
                    model,
                    data,
                    q[k],
                    qd[k],
                    qdd[k],
                    _fext_of_wrench(model, data, q[k], fid, F[k], Mo[k], reference),
                )
                for k in range(len(q))
            ]
        )
        np.testing.assert_allclose(res.tau, ref, atol=1e-9, rtol=1e-10)
        assert np.abs(res.q_ext).max() > 1.0  # the load did something
        np.testing.assert_allclose(res.power, res.tau * qd, rtol=0, atol=0)


def test_held_object_equals_body_with_added_inertia(person):
    robot = person
    q, qd, qdd = _traj(robot, 15, 3)
    cup = L.HeldObject(0.5, com=[0.02, -0.01, 0.05], inertia=np.diag([4e-4, 5e-4, 3e-4]) + 1e-5)
    res = L.inverse_dynamics(robot, q, qd, qdd, cup)
    # oracle: the same arm whose hand body carries the cup (Pinocchio, no fext)
    model = robot.model.copy()
    fr = model.frames[robot.tool_id]
    model.inertias[fr.parentJoint] = model.inertias[fr.parentJoint] + fr.placement.act(
        pin.Inertia(0.5, cup.com, cup.inertia)
    )
    data = model.createData()
    ref = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])
    np.testing.assert_allclose(res.tau, ref, atol=1e-9, rtol=1e-10)


def test_held_object_equals_rnea_with_fext(person):
    """The same held object as Pinocchio fext: −(I a_g + v ×* I v) of the object, a_g the frame's
    spatial acceleration minus gravity, computed with Pinocchio's spatial algebra."""
    robot = person
    q, qd, qdd = _traj(robot, 8, 4)
    cup = L.HeldObject.cylinder(0.4, 0.04, 0.1, com=[0.0, 0.03, 0.04])
    res = L.inverse_dynamics(robot, q, qd, qdd, cup, engine="pinocchio")
    model, data = robot.model, pin.Data(robot.model)
    fid = robot.tool_id
    fr = model.frames[fid]
    Iobj = pin.Inertia(cup.mass, cup.com, cup.inertia)
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k], qd[k], qdd[k])
        pin.updateFramePlacements(model, data)
        v = pin.getFrameVelocity(model, data, fid, pin.LOCAL)
        a = pin.getFrameAcceleration(model, data, fid, pin.LOCAL)
        g = data.oMf[fid].rotation.T @ model.gravity.linear
        ag = pin.Motion(a.linear - g, a.angular)
        f_obj = Iobj * ag + v.cross(Iobj * v)
        fext = [pin.Force.Zero() for _ in range(model.njoints)]
        fext[fr.parentJoint] = fr.placement.act(-f_obj)
        ref = pin.rnea(model, data, q[k], qd[k], qdd[k], fext)
        np.testing.assert_allclose(res.tau[k], ref, atol=1e-9, rtol=1e-10)


def test_generalized_forces_are_eq_8_5_by_finite_differences(person):
    """Q_j = F·∂r/∂q_j + m·ω_j with ∂r/∂q_j and ω_j = vee(∂R/∂q_j Rᵀ) by central differences."""
    robot = person
    q = robot.random_q(1, rng=5, margin=0.1)[0]
    F, Mo = np.array([3.0, -4.0, 12.0]), np.array([0.3, 0.2, -0.5])
    Q = L.generalized_forces(robot, q, L.Wrench(F, Mo))
    h = 1e-6
    ref = np.zeros(robot.nv)
    for j in range(robot.nv):
        e = np.zeros(robot.nq)
        e[j] = h
        Tp, Tm = robot.fk(q + e), robot.fk(q - e)
        dr = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ robot.fk(q)[:3, :3].T
        ref[j] = F @ dr + Mo @ np.array([W[2, 1], W[0, 2], W[1, 0]])
    np.testing.assert_allclose(Q, ref, atol=1e-7)


def test_static_point_mass_on_a_horizontal_arm(person):
    """Arm raised forward to horizontal (shoulder flexion 90°): the load of m at the hand adds
    m g d to the shoulder flexion torque, d the horizontal distance from the shoulder axis."""
    robot = person
    q = robot.neutral()
    q[robot.joint_names.index("shoulder_flexion")] = np.pi / 2
    assert robot.within_limits(q)
    z = np.zeros(robot.nv)
    m = 0.5
    res = L.inverse_dynamics(robot, q, z, z, L.HeldObject(m))
    T_sh = robot.fk(q, "shoulder_flexion")
    axis = T_sh[:3, :3] @ robot.chain.joint("shoulder_flexion").axis
    r = robot.fk(q)[:3, 3] - T_sh[:3, 3]
    g = robot.chain.gravity
    lever = np.cross(r, m * g) @ axis  # moment of the weight about the shoulder axis
    assert abs(lever) > 0.5 * m * 9.81 * 0.5  # the hand is ~0.6 m out
    j = robot.joint_names.index("shoulder_flexion")
    # the joint must supply the opposite of the weight's moment
    np.testing.assert_allclose(res.tau[j] - res.tau_free[j], -lever, rtol=1e-12, atol=1e-12)


def test_tree_and_prismatic_robot():
    """A tree (two branches) with a prismatic joint: a wrench on one branch loads only its path."""
    model = pin.Model()
    rng = np.random.default_rng(7)

    def body():
        return pin.Inertia(
            rng.uniform(0.5, 1.5), rng.uniform(-0.1, 0.1, 3), np.diag(rng.uniform(0.01, 0.02, 3))
        )

    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0, 0, 0.1])), "j1")
    model.appendBodyToJoint(j1, body(), pin.SE3.Identity())
    j2 = model.addJoint(j1, pin.JointModelPX(), pin.SE3(np.eye(3), np.array([0.2, 0, 0])), "j2")
    model.appendBodyToJoint(j2, body(), pin.SE3.Identity())
    j3 = model.addJoint(j1, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0, 0.2, 0])), "j3")
    model.appendBodyToJoint(j3, body(), pin.SE3.Identity())
    for name, j, p in (("tipA", j2, [0.1, 0, 0]), ("tipB", j3, [0, 0.15, 0.05])):
        model.addFrame(
            pin.Frame(name, j, 0, pin.SE3(np.eye(3), np.array(p, float)), pin.FrameType.OP_FRAME)
        )
    model.lowerPositionLimit[:] = -1
    model.upperPositionLimit[:] = 1
    robot = aa.load(model, tool="tipA")
    q, qd, qdd = _traj(robot, 6, 8)
    w = L.Wrench([1.0, 2.0, -3.0], [0.1, 0.0, 0.2], frame="tipB")
    res = L.inverse_dynamics(robot, q, qd, qdd, w)
    data = model.createData()
    fid = robot.frame_id("tipB")
    ref = np.array(
        [
            pin.rnea(
                model,
                data,
                q[k],
                qd[k],
                qdd[k],
                _fext_of_wrench(model, data, q[k], fid, w.force, w.moment, w.reference),
            )
            for k in range(len(q))
        ]
    )
    np.testing.assert_allclose(res.tau, ref, atol=1e-10)
    assert np.all(res.q_ext[:, robot.joint_names.index("j2")] == 0.0)  # other branch
    assert np.abs(res.q_ext[:, robot.joint_names.index("j3")]).max() > 0.01


def test_single_sample_shapes(person):
    q = person.neutral()
    z = np.zeros(person.nv)
    res = L.inverse_dynamics(person, q, z, z, [L.HeldObject(0.2), L.Wrench([0, 0, -1.0])])
    assert res.tau.shape == (person.nv,)
    Q = L.generalized_forces(person, q, L.HeldObject(0.2))
    assert Q.shape == (person.nv,)
    np.testing.assert_allclose(
        Q, L.generalized_forces(person, q, L.Wrench([0, 0, -0.2 * 9.81])), atol=1e-12
    )


@pytest.mark.parametrize(
    "kw, exc",
    [
        (dict(mass=-0.1), InertiaError),
        (dict(mass=float("nan")), InertiaError),
        (dict(mass=0.5, inertia=np.diag([1.0, 1.0, 3.0])), InertiaError),  # triangle inequality
        (dict(mass=0.5, inertia=-np.eye(3)), InertiaError),
        (dict(mass=0.5, com=[0, 0]), InertiaError),
    ],
)
def test_bad_held_objects(kw, exc):
    with pytest.raises(exc):
        L.HeldObject(**kw)


@pytest.mark.parametrize(
    "args", [("1 kg", 0.04, 0.1), (0.5, "wide", 0.1), (0.5, 0.04, -0.1), (np.nan, 0.04, 0.1)]
)
def test_bad_cylinders(args):
    with pytest.raises(InertiaError, match="held object"):
        L.HeldObject.cylinder(*args)


def test_bad_wrenches_and_trajectories(person):
    with pytest.raises(ParameterError, match="finite"):
        L.Wrench([0, np.inf, 0])
    with pytest.raises(ParameterError, match="numbers"):
        L.Wrench(["a", "b", "c"])
    with pytest.raises(ParameterError, match="beyond"):
        L.Wrench([0, 0, 1e300])
    with pytest.raises(ParameterError, match="reference"):
        L.Wrench([0, 0, 1.0], reference="WORLD_UPSIDE_DOWN")
    q, qd, qdd = _traj(person, 4, 0)
    with pytest.raises(ParameterError, match="qd"):
        L.inverse_dynamics(person, q, qd[:3], qdd)
    with pytest.raises(ParameterError, match="qd"):
        L.inverse_dynamics(person, q, [["x"] * person.nv] * 4, qdd)
    bad = qdd.copy()
    bad[1, 2] = np.nan
    with pytest.raises(ParameterError, match="shoulder_rotation"):
        L.inverse_dynamics(person, q, qd, bad)
    with pytest.raises(ParameterError, match="rows"):
        L.inverse_dynamics(person, q, qd, qdd, L.Wrench(np.ones((3, 3))))
    with pytest.raises(UnknownFrameError):
        L.inverse_dynamics(person, q, qd, qdd, L.Wrench([0, 0, 1.0], frame="no_such_frame"))
    with pytest.raises(ParameterError, match="Wrench or a HeldObject"):
        L.inverse_dynamics(person, q, qd, qdd, [object()])
    with pytest.raises(ParameterError, match="engine"):
        L.inverse_dynamics(person, q, qd, qdd, engine="newton")


def test_lagrange_with_the_load_term_equals_lagrange_of_the_arm_carrying_the_object(person):
    """The Lagrange path: τ from the generated Lagrange code minus Jᵀw (Eq. (8-5)) equals the
    generated Lagrange code of a second arm whose hand body carries the object (its T and V
    include the object), i.e. the external wrench enters the Lagrange equations (8-8) as Q."""
    from anthroarm.dynamics import lagrange

    cup = L.HeldObject(0.7, com=[0.01, 0.02, 0.06], inertia=np.diag([6e-4, 6e-4, 4e-4]))
    model = person.model.copy()
    fr = model.frames[person.tool_id]
    model.inertias[fr.parentJoint] = model.inertias[fr.parentJoint] + fr.placement.act(
        pin.Inertia(cup.mass, cup.com, cup.inertia)
    )
    heavy = aa.load(model, tool=person.tool)
    q, qd, qdd = _traj(person, 10, 9)
    res = L.inverse_dynamics(person, q, qd, qdd, cup, engine="lagrange")
    np.testing.assert_allclose(res.tau, lagrange.load(heavy).tau(q, qd, qdd), atol=1e-9, rtol=1e-10)
