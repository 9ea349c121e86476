"""Rigid-body and dyad subroutines, book §6-5 (6-66)-(6-87): finite differences, closure,
existence, and the printed (6-73) arctan and (6-86)/(6-87) single-dot labels shown wrong."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from anthroarm.mechanisms._util import fd_derivative, wrap
from anthroarm.mechanisms.dyads import dyad, rigid_body_point


def moving_point(c, v, a):
    """P(t) = c + v t + a t^2 / 2 and its rates at t."""
    c, v, a = (np.asarray(x, float) for x in (c, v, a))
    return lambda t: (c + v * t + 0.5 * a * t * t, v + a * t, a)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-2, 2), min_size=12, max_size=12),
    st.floats(0.3, 2),
    st.floats(0.3, 2),
    st.sampled_from([1, -1]),
)
@example(
    x=[0.0] * 6 + [1.703125, 1.296875, 0.0, 1.0, 0.0, 0.0], r1=1.84375, r2=0.3046875, br=1
)  # CI find
def test_dyad_rates_match_finite_differences(x, r1, r2, br):
    p1 = moving_point(x[0:2], x[2:4], x[4:6])
    p2 = moving_point(x[6:8], x[8:10], x[10:12])

    def at(t):
        a, b = p1(t), p2(t)
        return dyad(a[0], a[1], a[2], b[0], b[1], b[2], r1, r2, br)

    s = at(0.0)
    if s.status != "ok":
        assert np.isfinite(s.P3).all() and s.omega1 == 0.0
        return
    u, w = s.P3 - p1(0)[0], s.P3 - p2(0)[0]
    D = abs(u[0] * w[1] - u[1] * w[0]) / (r1 * r2)
    if D < 0.2:
        return
    assert (
        abs(np.linalg.norm(s.P3 - p1(0)[0]) - r1) < 1e-12
        and abs(np.linalg.norm(s.P3 - p2(0)[0]) - r2) < 1e-12
    )
    # a short stencil (h = 2e-4): at fast-turning dyads (alpha ~ 300 rad/s^2) the default
    # h = 1e-3 leaves a truncation error of ~4e-7 relative; h = 2e-4 brings it to ~1e-11
    h = 2e-4
    d1 = np.r_[
        fd_derivative(lambda t: at(t).P3, h=h),
        fd_derivative(lambda t: np.array([at(t).theta1, at(t).theta2]), h=h, angular=True),
    ]
    d2 = fd_derivative(lambda t: np.r_[at(t).P3dot, at(t).omega1, at(t).omega2], h=h)
    ref1 = np.r_[s.P3dot, s.omega1, s.omega2]
    ref2 = np.r_[s.P3ddot, s.alpha1, s.alpha2]
    np.testing.assert_allclose(d1, ref1, atol=1e-7 * (1 + np.abs(ref1).max()))
    np.testing.assert_allclose(d2, ref2, atol=1e-7 * (1 + np.abs(ref2).max()))
    # (6-78): P3' from the P2 side agrees
    k2 = p2(0)[1] + s.omega2 * np.array([-(s.P3 - p2(0)[0])[1], (s.P3 - p2(0)[0])[0]])
    np.testing.assert_allclose(k2, s.P3dot, atol=1e-12 * (1 + np.abs(k2).max()))


def test_rigid_body_point_66_69_by_finite_differences():
    P1 = moving_point([0.1, 0.2], [0.3, -0.1], [0.05, 0.2])

    def at(t):
        p = P1(t)
        return rigid_body_point(
            p[0], p[1], p[2], 0.7, 0.4 + 1.3 * t + 0.25 * t * t, 1.3 + 0.5 * t, 0.5, phi=0.6
        )

    s = at(0.0)
    np.testing.assert_allclose(np.linalg.norm(s.position - P1(0)[0]), 0.7, atol=1e-15)
    np.testing.assert_allclose(fd_derivative(lambda t: at(t).position), s.velocity, atol=1e-12)
    np.testing.assert_allclose(fd_derivative(lambda t: at(t).velocity), s.acceleration, atol=1e-12)


def test_dyad_existence_and_dead_point():
    z = np.zeros(2)
    s = dyad([0, 0], z, z, [3, 0], z, z, 1.0, 1.0)  # (6-71): d > r1 + r2
    assert s.status == "cannot_assemble" and "(6-71)" in s.reason and np.isfinite(s.P3).all()
    s = dyad([0, 0], z, z, [0.5, 0], z, z, 2.0, 1.0)  # (6-72): d < |r1 - r2|
    assert s.status == "cannot_assemble"
    s = dyad([0, 0], [0, 1], z, [2, 0], z, z, 1.0, 1.0)  # links collinear
    assert s.assembled and s.dead_point and s.omega1 == 0.0
    s = dyad([0, 0], z, z, [0, 0], z, z, 1.0, 1.0)  # coincident pivots, equal links
    assert np.isfinite(s.P3).all()
    with pytest.raises(ValueError, match="r1"):
        dyad([0, 0], z, z, [1, 0], z, z, -1.0, 1.0)
    with pytest.raises(ValueError, match="P2"):
        dyad([0, 0], z, z, [np.nan, 0], z, z, 1.0, 1.0)
    with pytest.raises(ValueError, match="branch"):
        dyad([0, 0], z, z, [1, 0], z, z, 1.0, 1.0, branch=2)
    v = dyad(
        np.zeros((5, 2)),
        np.zeros((5, 2)),
        np.zeros((5, 2)),
        np.c_[np.linspace(0.5, 3, 5), np.zeros(5)],
        np.zeros((5, 2)),
        np.zeros((5, 2)),
        1.0,
        1.2,
    )
    assert (
        v.P3.shape == (5, 2) and list(v.status) == ["ok"] * 3 + ["cannot_assemble"] * 2
    )  # d > 2.2


def test_printed_6_73_arctan_loses_the_quadrant():
    z = np.zeros(2)
    P1, P2 = np.array([1.0, 1.0]), np.array([-0.5, 0.2])  # P2 left of P1
    s = dyad(P1, z, z, P2, z, z, 1.0, 1.2)
    # (6-73)-(6-76) as printed: phi = arctan(dy/dx)
    d = np.linalg.norm(P2 - P1)
    phi = np.arctan((P2[1] - P1[1]) / (P2[0] - P1[0]))
    th1 = phi + np.arccos((1.0 + d * d - 1.44) / (2 * d))
    P3 = P1 + np.array([np.cos(th1), np.sin(th1)])
    assert abs(np.linalg.norm(P3 - P2) - 1.2) > 0.1  # printed: the dyad does not close
    assert abs(np.linalg.norm(s.P3 - P2) - 1.2) < 1e-14


def test_printed_6_86_6_87_are_accelerations_not_velocities():
    P1 = moving_point([0, 0], [0.2, 0.1], [0.3, -0.2])
    P2 = moving_point([1.5, 0.3], [-0.1, 0.4], [0.1, 0.5])

    def at(t):
        a, b = P1(t), P2(t)
        return dyad(a[0], a[1], a[2], b[0], b[1], b[2], 1.0, 1.1)

    s = at(0.0)
    a, b = s.P3 - P1(0)[0]
    c, d = s.P3 - P2(0)[0]
    D = b * c - a * d
    E = (P2(0)[2][0] - P1(0)[2][0]) + s.omega1**2 * a - s.omega2**2 * c
    F = (P2(0)[2][1] - P1(0)[2][1]) + s.omega1**2 * b - s.omega2**2 * d
    printed_thetadot1 = -(E * c + F * d) / D  # (6-86) labelled theta1-dot
    printed_thetadot2 = -(F * b + E * a) / D  # (6-87) labelled theta2-dot
    w = fd_derivative(lambda t: np.array([at(t).theta1, at(t).theta2]), angular=True)
    al = fd_derivative(lambda t: np.array([at(t).omega1, at(t).omega2]))
    assert abs(printed_thetadot1 - w[0]) > 1e-2 and abs(printed_thetadot2 - w[1]) > 1e-2
    np.testing.assert_allclose([printed_thetadot1, printed_thetadot2], al, atol=1e-10)
    assert abs(wrap(s.theta1 - np.arctan2(b, a))) < 1e-15
