"""RRSS: closed form (6-93)-(6-113, subscripts reconstructed), 002 §4-3 Newton in rotation-vector
form, Pinocchio, finite differences, derived reference D2; printed forms shown failing."""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.mechanisms._util import W, Wdot, fd_derivative, rot, skew, wrap
from anthroarm.mechanisms.closed_loop import ClosedLoop
from anthroarm.mechanisms.pin_models import rrss_spec
from anthroarm.mechanisms.rrss import (
    RRSSGeometry,
    rrss,
    rrss_branch_through,
    rrss_constraints,
    rrss_newton,
    rrss_point,
    rrss_position,
    rrss_track,
)

D2 = RRSSGeometry(
    a0=[0, 0, 0],
    u0=[0, 0, 1],
    a1=[1, 0, 0],
    u1=np.array([0, 1, 1]) / np.sqrt(2),
    b0=[1, 1, 5],
    b1=[2, 0.5, -0.5],
)


@pytest.mark.parametrize(
    "deg,psi,b",
    [
        (30, 6.977804, (1.360143, 1.457545, -0.582199)),
        (60, 0.695635, (0.555255, 1.978826, -0.508548)),
        (90, -12.626846, (-0.333333, 2.130388, -0.333333)),
        (180, -60.503792, (-2.107823, 0.369274, 0.369274)),
        (270, -70.528779, (-0.5, -2, 0.5)),
    ],
)
def test_derived_reference_D2_closed_form_and_newton(deg, psi, b):
    br = rrss_branch_through(D2)
    s = rrss_position(D2, np.deg2rad(deg), br)
    assert abs(np.rad2deg(s.theta2) - psi) < 1e-6
    np.testing.assert_allclose(s.b, b, atol=1e-6)
    n = rrss_newton(D2, np.deg2rad(deg), steps=max(2, deg // 15))
    assert n.status == "ok" and abs(wrap(n.theta2 - s.theta2)) < 1e-12
    np.testing.assert_allclose(n.b, s.b, atol=1e-13)


def test_D2_velocity():
    s = rrss(D2, np.deg2rad(30), 1.0, 0.0, rrss_branch_through(D2))
    np.testing.assert_allclose(s.omega2, [0.010524, -0.018227, 0.978953], atol=1e-6)
    np.testing.assert_allclose(s.bdot, [-1.426779, 1.355870, 0.019083], atol=1e-6)
    assert abs(s.theta2dot - -0.029765) < 1e-6


# ------------------------------------------------------------ 002 §4-3: (u, phi) is singular at phi
# = 0
def printed_residual_u_phi(geom, x, theta1):
    """(4-42)-(4-47) in the 002 text's unknowns x = (p, u, phi) (u free 3-vector, (4-47) |u| =
    1)."""
    p, u, phi = x[:3], x[3:6], x[6]
    R = np.cos(phi) * np.eye(3) + np.sin(phi) * skew(u) + (1 - np.cos(phi)) * np.outer(u, u)
    rv = pin.log3(R) if abs(u @ u - 1) < 1e-6 else phi * u
    xr = np.r_[p, rv]
    return np.r_[rrss_constraints(geom, xr, theta1), u @ u - 1]


def test_printed_u_phi_unknowns_are_singular_at_zero_rotation_rotation_vector_is_not():
    x_ref = np.r_[D2.a1, 0.0, 0.0, 1.0, 0.0]  # reference pose: phi = 0, any unit u
    h = 1e-7
    J = np.column_stack(
        [
            (
                printed_residual_u_phi(D2, x_ref + h * e, 0.0)
                - printed_residual_u_phi(D2, x_ref - h * e, 0.0)
            )
            / (2 * h)
            for e in np.eye(7)
        ]
    )
    J_free = np.delete(J, 0, axis=1)  # 002: fix one unknown (here p_x), solve for six
    assert np.linalg.matrix_rank(J_free, tol=1e-6) < 6
    # the rotation-vector form used by rrss_newton: full rank 6 at rho = 0
    x0 = np.r_[D2.a1, 0.0, 0.0, 0.0]
    Jr = np.column_stack(
        [
            (rrss_constraints(D2, x0 + h * e, 0.0) - rrss_constraints(D2, x0 - h * e, 0.0))
            / (2 * h)
            for e in np.eye(6)
        ]
    )
    assert np.linalg.matrix_rank(Jr, tol=1e-6) == 6


def test_printed_4_43_zero_rhs_needs_a_common_normal():
    # the Chapter 4 thumb: a1 - a0 is not perpendicular to u1, so the printed (4-43)
    # u_a^T (a - a0) = 0 is violated already at the reference pose; our form keeps the reference
    # value
    u1 = np.array([np.sqrt(3) / 2, np.sqrt(3) / 4, -0.25])
    g = RRSSGeometry(
        a0=[0, 0, 0],
        u0=[0, 0, -1],
        a1=[0, 0.03, 0],
        u1=u1,
        b0=[-0.002229, -0.004316, -0.048326],
        b1=[0.015913, 0.015462, -0.04015],
    )
    assert abs(u1 @ (g.a1 - g.a0)) > 1e-2
    assert np.max(np.abs(rrss_constraints(g, np.r_[g.a1, 0, 0, 0], 0.0))) < 1e-15


# ------------------------------------------------------------ printed (6-94)-(6-112) subscripts
def test_printed_6_94_6_96_and_6_98_with_u1_do_not_close():
    th1 = 0.6
    br = rrss_branch_through(D2)
    s = rrss_position(D2, th1, br)
    R1 = rot(th1, D2.u0)
    a = R1 @ (D2.a1 - D2.a0) + D2.a0
    bp_printed = rot(s.theta2, D2.u0) @ (D2.b1 - D2.a0) + D2.a0  # (6-94) printed R(theta2, u0)
    ua_printed = rot(th1, D2.u1) @ D2.u1  # (6-95) printed R(theta1, u1) u_a1
    b_printed = (
        rot(th1, D2.u1) @ (R1 @ (D2.b1 - D2.a0) + D2.a0 - a) + a
    )  # (6-96) printed R(theta1, u1)
    L = D2.bar_length
    assert abs(np.linalg.norm(b_printed - D2.b0) - L) > 1e-2
    assert np.linalg.norm(bp_printed - (R1 @ (D2.b1 - D2.a0) + D2.a0)) > 1e-2
    assert np.linalg.norm(ua_printed - R1 @ D2.u1) > 1e-2
    # (6-98) printed with the initial axis u1 instead of u_a: its root does not close the loop
    bp = R1 @ (D2.b1 - D2.a0) + D2.a0
    c, e, u = a - D2.b0, bp - a, D2.u1
    E, F = c @ (e - u * (u @ e)), c @ np.cross(u, e)
    G = (c @ u) * (u @ e) + 0.5 * (e @ e + c @ c - L * L)
    th2 = 2 * np.arctan2(-F + br * np.sqrt(max(E * E + F * F - G * G, 0)), G - E)
    b_with_u1_root = rot(th2, R1 @ D2.u1) @ e + a
    assert abs(np.linalg.norm(b_with_u1_root - D2.b0) - L) > 1e-3
    assert s.residual < 1e-14


def test_printed_6_105_6_106_6_111_6_112_fail_against_finite_differences():
    th1, w1, al1 = 0.5, 0.7, 0.3
    br = rrss_branch_through(D2)
    s = rrss(D2, th1, w1, al1, br)

    def traj(t):
        return rrss(D2, th1 + w1 * t + 0.5 * al1 * t * t, w1 + al1 * t, al1, br)

    w2 = fd_derivative(lambda t: traj(t).theta2, angular=True)
    al2 = fd_derivative(lambda t: traj(t).theta2dot)
    adot = fd_derivative(lambda t: traj(t).a)
    addot = fd_derivative(lambda t: traj(t).adot)
    assert abs(s.theta2dot - w2) < 1e-11 and abs(s.theta2ddot - al2) < 1e-10
    np.testing.assert_allclose(s.adot, adot, atol=1e-12)
    np.testing.assert_allclose(s.addot, addot, atol=1e-11)
    b, a, b0, a0, u0, u1 = s.b, s.a, D2.b0, D2.a0, D2.u0, D2.u1
    # (6-105) printed: numerator = denominator -> theta2' = -theta1'
    P1 = skew(u1)
    printed_w2 = -w1 * ((b - b0) @ P1 @ (b - a)) / ((b - b0) @ P1 @ (b - a))
    assert abs(printed_w2 - w2) > 0.1
    # (6-106)/(6-112) printed with (a1 - a0) (and u1 in (6-106))
    assert np.linalg.norm(W(w1, u1) @ (D2.a1 - a0) - adot) > 1e-2
    assert np.linalg.norm(Wdot(w1, al1, u0) @ (D2.a1 - a0) - addot) > 1e-2
    # (6-110)/(6-111) printed: b_r'' with (theta1', theta1'', u0), Coriolis W(theta1) W(theta1),
    # P_u0, |b'|^2 outside
    Pu0 = skew(u0)
    bpp = Wdot(w1, al1, u0) @ (b - a0)
    br_pr = Wdot(w1, al1, u0) @ (b - a)
    printed_al2 = -(
        ((b - b0) @ (bpp + w2**2 * Pu0 @ Pu0 @ (b - a) + br_pr)) / ((b - b0) @ Pu0 @ (b - a))
        + s.bdot @ s.bdot
    )
    assert abs(printed_al2 - al2) > 0.1


def test_printed_6_89_skew_pattern_does_not_give_6_88():
    u = np.array([0.48, -0.6, 0.64])
    th = 0.9
    P_printed = np.array([[0, -u[0], u[1]], [u[0], 0, -u[2]], [-u[1], u[2], 0]])
    R_printed = -P_printed @ P_printed * np.cos(th) + P_printed * np.sin(th) + np.outer(u, u)
    R88 = pin.exp3(th * u)  # (6-88) = Rodrigues
    assert np.abs(R_printed - R88).max() > 1e-2
    np.testing.assert_allclose(rot(th, u), R88, atol=1e-15)
    np.testing.assert_allclose(-skew(u) @ skew(u), np.eye(3) - np.outer(u, u), atol=1e-15)


# ------------------------------------------------------------ random geometry
vec = st.lists(st.floats(-1, 1), min_size=3, max_size=3)


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


@settings(max_examples=25, deadline=None)
@given(vec, vec, vec, vec, st.floats(-1.0, 1.0), st.floats(0.3, 1.5), st.floats(-1, 1))
def test_newton_equals_closed_form_and_finite_differences(du0, du1, db0, db1, th, w, acc):
    u0 = unit(np.array([0, 0, 1.0]) + 0.3 * np.array(du0))
    u1 = unit(np.array([0, 1.0, 1.0]) + 0.4 * np.array(du1))
    g = RRSSGeometry(
        a0=[0, 0, 0],
        u0=u0,
        a1=[1, 0, 0],
        u1=u1,
        b0=np.array([1, 1, 5.0]) + 0.4 * np.array(db0),
        b1=np.array([2, 0.5, -0.5]) + 0.3 * np.array(db1),
    )
    br = rrss_branch_through(g)
    path = np.linspace(0, th, 17)
    cf = rrss_position(g, path, br)
    if not np.all(np.asarray(cf.status) == "ok"):
        return
    s = rrss(g, th, w, acc, br)
    den = abs(np.dot(s.b - g.b0, np.cross(s.u_a, s.b - s.a))) / (
        g.bar_length * np.linalg.norm(s.b - s.a)
    )
    if den < 0.1:
        return
    n = rrss_newton(g, th, w, acc, steps=8)
    assert n.status == "ok"
    assert abs(wrap(n.theta2 - s.theta2)) < 1e-11
    sc = max(1.0, abs(s.theta2dot), abs(s.theta2ddot))
    assert (
        abs(n.theta2dot - s.theta2dot) < 1e-10 * sc
        and abs(n.theta2ddot - s.theta2ddot) < 1e-10 * sc
    )
    np.testing.assert_allclose(n.bddot, s.bddot, atol=1e-10 * sc * g.length_scale)

    def traj(t):
        return rrss(g, th + w * t + 0.5 * acc * t * t, w + acc * t, acc, br)

    np.testing.assert_allclose(
        fd_derivative(lambda t: traj(t).b), s.bdot, atol=1e-8 * sc * g.length_scale
    )
    np.testing.assert_allclose(
        fd_derivative(lambda t: traj(t).bdot), s.bddot, atol=1e-7 * sc * g.length_scale
    )
    P = rrss_point(g, s, [1.5, 0.2, 0.3])
    Pt = lambda t: rrss_point(g, traj(t), [1.5, 0.2, 0.3])
    np.testing.assert_allclose(
        fd_derivative(lambda t: Pt(t).position), P.velocity, atol=1e-8 * sc * g.length_scale
    )
    np.testing.assert_allclose(
        fd_derivative(lambda t: Pt(t).velocity), P.acceleration, atol=1e-7 * sc * g.length_scale
    )


def test_against_pinocchio_closed_loop():
    loop = ClosedLoop(rrss_spec(D2))
    path = np.linspace(0, 2 * np.pi, 73)
    Q, ok = loop.track(path[:, None])
    assert ok.all()
    br = rrss_branch_through(D2)
    s = rrss_position(D2, path, br)
    i2 = loop.joint_q_index("r2")
    assert np.max(np.abs(wrap(Q[:, i2] - s.theta2))) < 1e-10
    k = 30
    st_ = loop.solve([path[k]], [0.9], [-0.4], q0=Q[k])
    c = rrss(D2, path[k], 0.9, -0.4, br)
    assert st_.ok and abs(st_.v[i2] - c.theta2dot) < 1e-12 and abs(st_.a[i2] - c.theta2ddot) < 1e-12
    np.testing.assert_allclose(loop.frame_velocity(st_.q, st_.v, "b_R2"), c.bdot, atol=1e-12)
    np.testing.assert_allclose(
        loop.frame_acceleration(st_.q, st_.v, st_.a, "b_R2"), c.bddot, atol=1e-12
    )


def test_track_reports_a_lost_branch_and_bad_input():
    # a rocker: the input cannot turn a full circle; the march must stop with a status, not NaN
    g = RRSSGeometry(
        a0=[0, 0, 0],
        u0=[0, 0, 1],
        a1=[1, 0, 0],
        u1=unit([0, 1, 1]),
        b0=[2, 0.5, 0.5],
        b1=[2, 0.5, -0.5],
    )
    cf = rrss_position(g, np.linspace(0, 2 * np.pi, 73), rrss_branch_through(g))
    assert (np.asarray(cf.status) == "cannot_assemble").any()
    states = rrss_track(g, np.linspace(0, 2 * np.pi, 37))
    stat = [s.status for s in states]
    assert "branch_lost" in stat and stat[0] == "ok"
    assert all(np.isfinite(s.b).all() and np.isfinite(s.theta2) for s in states)
    lost = next(s for s in states if s.status == "branch_lost")
    assert "branch lost" in lost.reason
    one = rrss(
        g,
        float(np.linspace(0, 2 * np.pi, 73)[np.argmax(np.asarray(cf.status) == "cannot_assemble")]),
        1.0,
    )
    assert one.status == "cannot_assemble" and one.theta2dot == 0.0 and np.isfinite(one.theta2)
    with pytest.raises(ValueError, match="u1"):
        RRSSGeometry(
            a0=[0, 0, 0], u0=[0, 0, 1], a1=[1, 0, 0], u1=[0, 0, 0], b0=[1, 1, 5], b1=[2, 0, 0]
        )
    with pytest.raises(ValueError, match="u0"):
        RRSSGeometry(
            a0=[0, 0, 0], u0=[0, 0, 1.5], a1=[1, 0, 0], u1=[0, 1, 0], b0=[1, 1, 5], b1=[2, 0, 0]
        )
    with pytest.raises(ValueError, match="theta1"):
        rrss(D2, np.nan)


def test_printed_4_48_plus_p_for_p_dot_fails():
    # 002 l. 314-318: a' = [W](a - p) + (p) is printed with p for p'; with the reference point p = a
    # the printed form returns the position of a as its velocity
    th1, w1 = 0.4, 0.9
    s = rrss_newton(D2, th1, w1, 0.0)
    truth = fd_derivative(lambda t: rrss_position(D2, th1 + w1 * t, rrss_branch_through(D2)).a)
    np.testing.assert_allclose(s.adot, truth, atol=1e-12)
    printed = np.cross(s.omega2, s.a - s.a) + s.a
    assert np.linalg.norm(printed - truth) > 0.1
