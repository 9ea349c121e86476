"""Thumb of §6-5 (Fig. 6-17, the Chapter 4 geometry): the RRSS + planar four-bar against the
Chapter 3 curve f2, Pinocchio's closed loop and finite differences, the global transform
(6-114)-(6-116), bad input."""

import numpy as np
import pytest

from anthroarm.mechanisms._util import fd_derivative, wrap
from anthroarm.mechanisms.closed_loop import ClosedLoop
from anthroarm.mechanisms.rrss import rrss_point
from anthroarm.mechanisms.thumb import ThumbGeometry, thumb, thumb_f2, thumb_spec

TG = ThumbGeometry.book()


def test_thumb_rrss_follows_f2_with_the_chapter4_optimum():
    th = np.deg2rad(np.linspace(0, 30, 31))
    th2 = np.array([thumb(TG, t).theta2 for t in th])
    err = np.abs(np.rad2deg(th2) - thumb_f2(np.rad2deg(th)))
    assert err.max() < 0.6  # the printed minimax error e = 0.01 is not reproduced
    assert abs(thumb(TG, 0.0).theta2) < 1e-12 and abs(thumb(TG, 0.0).theta3) < 1e-12


def test_thumb_printed_u0_sense_cannot_assemble():
    # with theta1 about +z (the printed u0 read literally) the RRSS cannot even reach 10 deg
    from anthroarm.mechanisms.rrss import RRSSGeometry, rrss_branch_through, rrss_position

    g = TG.rrss
    plus = RRSSGeometry(a0=g.a0, u0=[0, 0, 1], a1=g.a1, u1=g.u1, b0=g.b0, b1=g.b1)
    assert (
        rrss_position(plus, np.deg2rad(10), rrss_branch_through(plus)).status == "cannot_assemble"
    )


def test_thumb_upper_fourbar_literal_reading():
    # ch3-4.md E9 naive reading: PF = 0.791 mm, FC = 59.645 mm, angle PFC = 13.4 deg (< 35 deg
    # asked)
    assert abs(TG.R4 * 1e3 - 0.791) < 1e-3 and abs(TG.R5 * 1e3 - 59.645) < 1e-3
    assert abs(np.rad2deg(TG.transmission_angle0) - 13.4) < 0.05
    s = thumb(TG, 0.0)
    np.testing.assert_allclose(s.S, TG.to_world(TG.S0), atol=1e-15)
    np.testing.assert_allclose(s.P, TG.to_world(TG.P0), atol=1e-15)


@pytest.mark.parametrize("th1", [0.15, 0.3, 0.5])
def test_thumb_against_pinocchio_and_finite_differences(th1):
    w, a = 0.8, 0.3
    s = thumb(TG, th1, w, a)
    assert s.status == "ok" and s.residual < 1e-15
    loop = ClosedLoop(thumb_spec(TG))
    Q, ok = loop.track(np.linspace(0, th1, 9)[:, None])
    st_ = loop.solve([th1], [w], [a], q0=Q[-1])
    assert ok.all() and st_.ok
    L = TG.length_scale
    i2, i3 = loop.joint_q_index("r2"), loop.joint_q_index("r3")
    # the 0.79 mm coupler makes theta3 ~1e3 times more sensitive than theta2
    assert abs(wrap(st_.q[i2] - s.theta2)) < 1e-12 and abs(wrap(st_.q[i3] - s.theta3)) < 1e-10
    sc = max(1.0, np.abs(s.Sddot).max() / L, abs(s.theta3ddot))
    np.testing.assert_allclose(loop.frame_position(st_.q, "S"), s.S, atol=1e-14 * L)
    np.testing.assert_allclose(loop.frame_velocity(st_.q, st_.v, "S"), s.Sdot, atol=1e-12 * L * sc)
    np.testing.assert_allclose(
        loop.frame_acceleration(st_.q, st_.v, st_.a, "S"), s.Sddot, atol=1e-11 * L * sc
    )
    assert abs(st_.a[i3] - s.theta3ddot) < 1e-11 * sc

    def traj(t):
        return thumb(TG, th1 + w * t + 0.5 * a * t * t, w + a * t, a)

    np.testing.assert_allclose(fd_derivative(lambda t: traj(t).S), s.Sdot, atol=1e-10 * L * sc)
    np.testing.assert_allclose(fd_derivative(lambda t: traj(t).Sdot), s.Sddot, atol=1e-10 * L * sc)
    np.testing.assert_allclose(fd_derivative(lambda t: traj(t).P), s.Pdot, atol=1e-10 * L * sc)
    # the IP joint is also a point of R2 of the RRSS (6-100)-(6-113)
    P = rrss_point(TG.rrss, s.rrss, TG.to_world(TG.P0))
    np.testing.assert_allclose(P.position, s.P, atol=1e-15)
    np.testing.assert_allclose(P.velocity, s.Pdot, atol=1e-14)
    np.testing.assert_allclose(P.acceleration, s.Pddot, atol=1e-13)


def test_thumb_bad_input():
    with pytest.raises(ValueError, match="theta1"):
        thumb(TG, np.inf)
    with pytest.raises(ValueError, match="ex"):
        ThumbGeometry(
            rrss=TG.rrss, ex=[1, 0, 0], P0=TG.P0, F0=TG.F0, C=TG.C, R3=TG.R3, beta=TG.beta
        )
    s = thumb(TG, np.deg2rad(-10))  # below the reference pose the thumb cannot close
    assert (
        s.status == "cannot_assemble" and "cannot assemble" in s.reason and np.isfinite(s.S).all()
    )
