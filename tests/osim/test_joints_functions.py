"""Every joint type and function type the import reads, against OpenSim (issue 32 item 1).

* OpenSim's functions (``opensim.SimmSpline``, ``PolynomialFunction``, ``PiecewiseLinearFunction``,
  ``MultiplierFunction``, ``LinearFunction``): values and derivatives equal to
  :mod:`anthroarm.osim.functions`, inside, outside and at the knots.
* A model written for the test (``synthetic_models.py``: Pin, Slider, Universal, Gimbal,
  Planar, Weld and Custom joints, rotated offset frames, products of inertia, a spline coupler
  with a scale factor, a locked coordinate, markers) read by OpenSim and by the import: poses,
  markers, M, g and τ equal.
* Two places where OpenSim's dynamics do not follow its own kinematics (Simbody's
  ``MobilizedBody::FunctionBased``, ``MobilizedBodyImpl.h``), where the import is checked
  against the derivative of OpenSim's own poses / mass matrix instead:
  ``buildH`` leaves a constant rotation axis at 0 when it builds W (its value is only computed
  for axes with coordinates), and ``buildHdot`` builds Ẇ from the whole angular velocity when
  one coordinate drives several rotations (Rajagopal's walker knee).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

opensim = pytest.importorskip("opensim")

from synthetic_models import model_text  # noqa: E402

import anthroarm as aa  # noqa: E402
from anthroarm.osim import functions as fn  # noqa: E402
from anthroarm.osim.checks import OpenSimModel  # noqa: E402


def _osim_eval(f, x):
    v = opensim.Vector(1, float(x))
    # lists (SWIG's sequence typemap), not opensim.StdVectorInt: see anthroarm.osim.checks.OpenSimModel
    d1 = f.calcDerivative([0], v)
    d2 = f.calcDerivative([0, 0], v)
    return f.calcValue(v), d1, d2


def _points(xs, rng):
    inside = rng.uniform(xs[0], xs[-1], 40)
    return np.r_[inside, xs, xs[0] - 0.3, xs[-1] + 0.7, xs[0] + 1e-14]


@pytest.mark.parametrize("n", [2, 3, 4, 5, 9, 13])
def test_simm_spline_equals_opensim(n):
    rng = np.random.default_rng(n)
    xs = np.sort(rng.uniform(-2, 2, n)) + np.arange(n) * 1e-3
    ys = rng.normal(size=n)
    ref = opensim.SimmSpline()
    for x, y in zip(xs, ys):
        ref.addPoint(float(x), float(y))
    mine = fn.SimmSpline(xs, ys)
    for x in _points(xs, rng):
        f, f1, f2 = (float(a[0]) for a in mine.eval(np.array([x])))
        r = _osim_eval(ref, x)
        assert abs(f - r[0]) <= 1e-14 * max(1, abs(r[0])), (n, x)
        assert abs(f1 - r[1]) <= 1e-12 * max(1, abs(r[1])), (n, x)
        # at an interior knot the second derivative jumps; OpenSim's binary search may pick
        # either side, the import the left one: compare away from knots only
        if np.min(np.abs(xs[1:-1] - x), initial=1.0) > 1e-12:
            assert abs(f2 - r[2]) <= 1e-10 * max(1, abs(r[2])), (n, x)


def _multiplier(inner, scale):
    """An OpenSim MultiplierFunction owning a copy of ``inner`` (given Python's object, both
    would free it: a crash at exit)."""
    m = opensim.MultiplierFunction()
    c = inner.clone()
    c.thisown = False  # the MultiplierFunction owns and frees it
    m.setFunction(c)
    m.setScale(scale)
    return m


def test_other_functions_equal_opensim():
    rng = np.random.default_rng(1)
    xs = np.array([-1.0, -0.2, 0.4, 1.5])
    ys = np.array([0.3, -0.1, 0.8, 0.2])
    pl = opensim.PiecewiseLinearFunction()
    for x, y in zip(xs, ys):
        pl.addPoint(float(x), float(y))
    spline = opensim.SimmSpline()
    for x, y in zip(xs, ys):
        spline.addPoint(float(x), float(y))
    cases = [
        (opensim.LinearFunction(-0.5, 0.1), fn.Linear(-0.5, 0.1), 2),
        (
            opensim.PolynomialFunction(opensim.Vector([0.01, -0.02, 0.03, 0.05])),
            fn.Polynomial((0.01, -0.02, 0.03, 0.05)),
            2,
        ),
        (_multiplier(spline, 1.3), fn.Multiplier(1.3, fn.SimmSpline(xs, ys)), 1),
        (pl, fn.PiecewiseLinear(xs, ys), 1),
        (opensim.Constant(0.7), fn.Constant(0.7), 2),
    ]
    for ref, mine, order in cases:
        for x in rng.uniform(-2, 2, 30):
            got = [float(a[0]) for a in mine.eval(np.array([x]))]
            want = _osim_eval(ref, x)
            assert np.allclose(got[: order + 1], want[: order + 1], rtol=1e-13, atol=1e-14), (
                mine.kind,
                x,
                got,
                want,
            )


def _write(tmp_path, name, **kw):
    p = tmp_path / f"{name}.osim"
    p.write_text(model_text(**kw))
    return p


def test_every_joint_type_agrees_with_opensim(tmp_path):
    path = _write(tmp_path, "synthetic")
    robot = aa.load(path)
    # names: each coordinate a joint, the coupled and the locked one not in q
    assert robot.joint_names[:6] == [
        "free_rz",
        "free_rx",
        "free_ry",
        "free_tx",
        "free_ty",
        "free_tz",
    ]
    assert "pat_rz" not in robot.joint_names and "held_rz" not in robot.joint_names
    assert {"u_rx", "u_ry", "g_rx", "g_ry", "g_rz", "p_rz", "p_tx", "p_ty", "flex", "twist"} <= set(
        robot.joint_names
    )
    assert {f"b{i}" for i in range(10)} | {f"m{i}" for i in range(10)} <= set(robot.frame_names)
    oracle = OpenSimModel(path, robot.joint_names)
    rng = np.random.default_rng(0)
    err = dict(pose=0.0, marker=0.0, M=0.0, g=0.0, tau=0.0)
    for _ in range(60):
        q = robot.random_q(None, rng)
        qd, qdd = rng.normal(size=robot.nq), rng.normal(size=robot.nq)
        C, _ = oracle.set_state(q)
        for b, H in oracle.poses().items():
            err["pose"] = max(err["pose"], np.abs(robot.fk(q, b) - H).max())
        for mk, p in oracle.markers().items():
            err["marker"] = max(err["marker"], np.abs(robot.fk(q, mk)[:3, 3] - p).max())
        Mo = oracle.mass_matrix(C)
        go = oracle.inverse_dynamics(C, np.zeros(oracle.nu))
        err["M"] = max(err["M"], np.abs(robot.mass_matrix(q) - Mo).max() / np.abs(Mo).max())
        err["g"] = max(err["g"], np.abs(robot.gravity(q) - go).max() / np.abs(go).max())
        C, udot = oracle.set_state(q, qd, qdd)
        to = oracle.inverse_dynamics(C, udot)
        err["tau"] = max(
            err["tau"], np.abs(robot.inverse_dynamics(q, qd, qdd) - to).max() / np.abs(to).max()
        )
    assert err["pose"] < 1e-9 and err["marker"] < 1e-9, err
    assert max(err["M"], err["g"], err["tau"]) < 1e-9, err


def test_locked_coordinate_held_at_its_default(tmp_path):
    robot = aa.load(_write(tmp_path, "synthetic"))
    held = robot.model.names.tolist().index("held_rz")
    qf = robot.full_q(robot.random_q(None, 3))
    assert qf[robot.model.idx_qs[held]] == 0.4  # <default_value> of the locked coordinate
    assert "locked" in " ".join(r.why for r in robot.report.kept if r.component.endswith("held_rz"))


def test_simbody_H_ignores_a_constant_rotation_before_a_moving_one(tmp_path):
    """``buildH`` computes s_i only for axes with coordinates, so a constant rotation (0.3 rad)
    before the moving 'twist' axis counts as 0 in W: OpenSim's body velocity disagrees with the
    derivative of its own poses, the import's agrees."""
    path = _write(tmp_path, "constfirst", const_first=True)
    robot = aa.load(path)
    oracle = OpenSimModel(path, robot.joint_names)
    q = robot.random_q(None, 0)
    k = robot.joint_names.index("twist")
    e = np.zeros(robot.nq)
    e[k] = 1.0
    h = 1e-6

    def R(qq):
        oracle.set_state(qq)
        return oracle.poses()["b7"][:3, :3]

    W = (R(q + h * e) - R(q - h * e)) / (2 * h) @ R(q).T
    w_fd = np.array([W[2, 1], W[0, 2], W[1, 0]])
    w_ours = robot.jacobian(q, "b7")[3:, k]
    oracle.set_state(q, e)
    V = oracle.model.getBodySet().get("b7").getVelocityInGround(oracle.state)
    w_osim = np.array([V.get(0).get(i) for i in range(3)])
    assert np.abs(w_ours - w_fd).max() < 1e-8
    assert np.abs(w_osim - w_fd).max() > 1e-2  # OpenSim's own inconsistency (Simbody buildH)


def test_walker_knee_velocity_terms_are_exact(tmp_path):
    """One coordinate drives three rotations: the import's velocity terms c(q, q̇) equal those
    of OpenSim's own mass matrix, c = Ṁq̇ − ½ ∂(q̇ᵀMq̇)/∂q by central differences of
    ``calcM``; OpenSim's inverse dynamics (``buildHdot``) does not."""
    path = _write(tmp_path, "walker", walker=True)
    robot = aa.load(path)
    oracle = OpenSimModel(path, robot.joint_names)
    rng = np.random.default_rng(5)
    q = robot.random_q(None, rng, margin=0.1)
    qd = np.zeros(robot.nq)
    qd[robot.joint_names.index("flex")] = 2.0
    z = np.zeros(robot.nq)

    def M(qq):
        C, _ = oracle.set_state(qq)
        return oracle.mass_matrix(C)

    h = 1e-5
    Mdot = (M(q + h * qd) - M(q - h * qd)) / (2 * h)
    grad = [(qd @ M(q + h * e) @ qd - qd @ M(q - h * e) @ qd) / (2 * h) for e in np.eye(robot.nq)]
    c_fd = Mdot @ qd - 0.5 * np.array(grad)
    c_ours = robot.bias(q, qd) - robot.gravity(q)
    C, udot = oracle.set_state(q, qd, z)
    c_osim = oracle.inverse_dynamics(C, udot)
    C, udot = oracle.set_state(q, z, z)
    c_osim = c_osim - oracle.inverse_dynamics(C, udot)
    assert np.abs(c_ours - c_fd).max() < 1e-6 * max(1, np.abs(c_fd).max())
    assert np.abs(c_osim - c_fd).max() > 1e-4 * np.abs(c_fd).max()  # Simbody's buildHdot


def test_opensim_3_model_read_through_opensims_updater():
    """A 3.x model (opensim-core's ``OpenSim/Tools/Test/double_pendulum33.osim``, Apache-2.0,
    document version 30000) is brought to 4.x by OpenSim's updater and agrees with OpenSim
    reading the original file."""
    path = Path(__file__).parent / "data" / "double_pendulum33.osim"
    robot = aa.load(path)
    assert robot.joint_names == ["q1", "q2"]
    assert "updater" in robot.report.rows[-1].why
    oracle = OpenSimModel(path, robot.joint_names)
    for q in robot.random_q(20, 0):
        C, _ = oracle.set_state(q)
        for b, H in oracle.poses().items():
            assert np.abs(robot.fk(q, b) - H).max() < 1e-12
        Mo = oracle.mass_matrix(C)
        assert np.abs(robot.mass_matrix(q) - Mo).max() < 1e-12 * max(1, np.abs(Mo).max())
