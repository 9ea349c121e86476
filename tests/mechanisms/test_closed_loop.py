"""Generic Pinocchio closed-loop helper: URDF spanning tree + closures, least-norm Newton,
velocities and classical accelerations; cross-checked on the four-bar and by finite differences."""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.errors import AnthroarmError
from anthroarm.mechanisms._util import fd_derivative, wrap
from anthroarm.mechanisms.closed_loop import ClosedLoop, Closure, LoopSpec, TreeJoint, origin
from anthroarm.mechanisms.fourbar import fourbar, fourbar_input_range
from anthroarm.mechanisms.pin_models import fourbar_spec


@settings(max_examples=30, deadline=None)
@given(
    st.floats(0.3, 3),
    st.floats(0.3, 3),
    st.floats(0.3, 3),
    st.floats(0.3, 3),
    st.floats(-np.pi, np.pi),
    st.floats(-2, 2),
    st.floats(-2, 2),
    st.sampled_from([1, -1]),
)
def test_fourbar_closed_form_equals_pinocchio(r1, r2, r3, r4, th2, w2, a2, br):
    s = fourbar(r1, r2, r3, r4, th2, w2, a2, br)
    if s.status != "ok" or abs(np.sin(s.theta3 - s.theta4)) < 0.05:
        return
    loop = ClosedLoop(fourbar_spec(r1, r2, r3, r4))
    st_ = loop.solve([th2], [w2], [a2], q0=[th2, s.theta3 - th2 + 0.02, s.theta4 - 0.02])
    assert st_.ok
    assert (
        abs(wrap(st_.q[0] + st_.q[1] - s.theta3)) < 1e-10 and abs(wrap(st_.q[2] - s.theta4)) < 1e-10
    )
    sc = max(1.0, abs(s.omega3), abs(s.omega4), abs(s.alpha3), abs(s.alpha4))
    np.testing.assert_allclose(
        [st_.v[0] + st_.v[1], st_.v[2]], [s.omega3, s.omega4], atol=1e-10 * sc
    )
    np.testing.assert_allclose(
        [st_.a[0] + st_.a[1], st_.a[2]], [s.alpha3, s.alpha4], atol=1e-10 * sc
    )
    assert loop.residual_pin(st_.q) < 1e-12 * (r1 + r2 + r3 + r4)


def test_urdf_spanning_tree_and_pin_constraint_residual():
    loop = ClosedLoop(fourbar_spec(4.0, 1.5, 3.5, 3.0))
    assert "<robot" in loop.urdf and loop.urdf.count("<joint") == 3 + 2  # 3 joints + 2 sites
    m = pin.buildModelFromXML(loop.urdf)
    assert m.nq == 3 and list(m.names)[1:] == ["crank", "coupler", "rocker"]
    q = np.array([0.3, 0.5, 1.2])  # not closed
    r = loop.residual(q)
    pa, pb = loop.frame_position(q, "B_coupler"), loop.frame_position(q, "B_rocker")
    np.testing.assert_allclose(r, (pa - pb)[:2], atol=1e-15)
    assert abs(loop.residual_pin(q) - np.linalg.norm((pa - pb)[:2])) < 1e-14


def test_velocity_and_acceleration_equal_finite_differences_of_the_solved_loop():
    r = (4.0, 1.5, 3.5, 3.0)
    loop = ClosedLoop(fourbar_spec(*r))
    s = fourbar(*r, 0.7)
    q0 = np.array([0.7, s.theta3 - 0.7, s.theta4])
    w, a = 1.3, -0.4

    def q_of(t):
        return loop.solve_position([0.7 + w * t + 0.5 * a * t * t], q0)[0]

    st_ = loop.solve([0.7], [w], [a], q0=q0)
    v_fd = fd_derivative(q_of)
    np.testing.assert_allclose(st_.v, v_fd, atol=1e-10)

    def v_of(t):
        qt = q_of(t)
        return loop.solve_velocity(qt, [w + a * t])[0]

    np.testing.assert_allclose(st_.a, fd_derivative(v_of), atol=1e-10)


def test_pose_closure_and_ball_joint():
    # a triangle closed by a weld: ground -R- l1 -R- l2 (tip), ground -R- l3 (tip); pose closure at
    # the tips
    L = 1.0
    spec = LoopSpec(
        name="weld",
        joints=(
            TreeJoint("j1", "ground", "l1"),
            TreeJoint("j2", "l1", "l2", origin=origin((L, 0, 0))),
            TreeJoint("j3", "ground", "l3", origin=origin((2 * L, 0, 0))),
        ),
        closures=(Closure("tipA", "tipB", kind="pose"),),
        inputs=("j1",),
        sites=(("tipA", "l2", origin((L, 0, 0))), ("tipB", "l3", origin((0.0, 0, 0)))),
        length_scale=3.0,
    )
    loop = ClosedLoop(spec)
    # at j1 = 0: l2 tip at (2L, 0) = pivot of l3; orientation equality needs q1 + q2 = q3
    st_ = loop.solve([0.0], [0.0], [0.0], q0=[0.0, 0.1, 0.2])
    assert (
        st_.ok and abs(st_.q[0] + st_.q[1] - st_.q[2]) < 1e-12 and loop.residual_pin(st_.q) < 1e-12
    )
    # a ball joint is three revolute joints in the URDF
    spec2 = LoopSpec(
        name="ball",
        joints=(TreeJoint("b", "ground", "link", "ball"),),
        closures=(),
        inputs=("b_x",),
    )
    assert ClosedLoop(spec2).model.nq == 3


def test_bad_specs_and_unreachable_inputs():
    with pytest.raises(ValueError, match="input joint"):
        ClosedLoop(
            LoopSpec(
                name="x", joints=(TreeJoint("a", "ground", "l"),), closures=(), inputs=("nope",)
            )
        )
    with pytest.raises(ValueError, match="unknown type"):
        LoopSpec(
            name="x", joints=(TreeJoint("a", "ground", "l", "screw"),), closures=(), inputs=("a",)
        ).urdf()
    with pytest.raises(ValueError, match="unknown frame"):
        ClosedLoop(
            LoopSpec(
                name="x",
                joints=(TreeJoint("a", "ground", "l"),),
                closures=(Closure("l", "zz"),),
                inputs=("a",),
            )
        )
    with pytest.raises(AnthroarmError):
        ClosedLoop(
            LoopSpec(
                name="x",
                joints=(TreeJoint("a", "ground", "l"), TreeJoint("b", "l", "ground")),
                closures=(),
                inputs=("a",),
            )
        )
    loop = ClosedLoop(fourbar_spec(1.0, 3.0, 1.0, 3.5))
    assert not fourbar_input_range(1.0, 3.0, 1.0, 3.5).contains(0.0)
    st_ = loop.solve([0.0], [1.0], [0.0], q0=[0.0, 0.3, 0.3])
    assert st_.status == "not_converged" and np.isfinite(st_.q).all() and not st_.ok
    with pytest.raises(ValueError, match="inputs"):
        loop.solve({"bogus": 1.0})
    with pytest.raises(ValueError):
        loop.solve([np.nan])


def test_dead_point_is_reported_as_singular():
    # toggle: d = r3 + r4 at theta2 = pi -> coupler and rocker collinear
    loop = ClosedLoop(fourbar_spec(2.0, 1.0, 1.5, 1.5))
    st_ = loop.solve([np.pi], [1.0], [0.0], q0=[np.pi, -np.pi, np.pi])
    assert st_.status == "singular" and "dead point" in st_.reason
