"""Planar four-bar (book §5-2 complex vectors, §5-3 Cartesian vectors).

Oracles: loop closure, the Cartesian method (an independent formulation), finite differences,
and Pinocchio (tests/mechanisms/test_closed_loop.py).  The printed (5-17), (5-19), (5-20),
(5-22) are kept here in their printed form and shown to fail."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.mechanisms._util import fd_rates, wrap
from anthroarm.mechanisms.fourbar import (
    coupler_point,
    fourbar,
    fourbar_cartesian,
    fourbar_grashof,
    fourbar_input_range,
    fourbar_points,
    fourbar_position,
)

# synthetic fixture of ch5.md §3 (not from the book: it prints no numbers), r1, r2, r3, r4, th2,
# th2'
R = (4.0, 1.5, 3.5, 3.0)
TH2, W2 = 0.7, 2.0


def loop(s):
    z = (
        s.r2 * np.exp(1j * np.asarray(s.theta2))
        + s.r3 * np.exp(1j * np.asarray(s.theta3))
        - s.r1 * np.exp(1j * s.ground_angle)
        - s.r4 * np.exp(1j * np.asarray(s.theta4))
    )
    return np.abs(z)


def test_fixture_values_ch5_notes():
    s = fourbar(*R, TH2, omega2=W2)
    assert s.status == "ok" and s.assembled and not s.dead_point
    np.testing.assert_allclose(
        [s.d, s.theta_d, s.theta3, s.theta4],
        [3.011958458, -0.326605647, 0.620016666, 1.572194998],
        atol=1e-9,
    )
    np.testing.assert_allclose(
        [s.omega3, s.omega4, s.alpha3, s.alpha4],
        [-0.805653952, 0.098072882, 1.805248233, 3.369769814],
        atol=1e-9,
    )
    assert loop(s) < 1e-14


# ---------------------------------------------------------------- printed forms (errata)
def printed_5_17_theta4(s):
    # (5-17) as printed: theta4 = asin((r3 sin th3 - d sin th2) / r4)
    return np.arcsin((s.r3 * np.sin(s.theta3) - s.d * np.sin(s.theta2)) / s.r4)


def printed_5_19_omega3(s, w2):
    return w2 * s.r2 * np.sin(s.theta4 - s.theta3) / (s.r3 * np.sin(s.theta3 - s.theta4))


def printed_5_20_omega4(s, w2):
    return w2 * (-s.r2 * np.sin(s.theta3 + s.theta4)) / (s.r4 * np.sin(s.theta3 - s.theta4))


def printed_5_22_alpha4(s):
    # A, B with the corrected squared *velocities* (th2'' = 0); Cramer column printed as (A, -B)
    w2, w3, w4 = s.omega2, s.omega3, s.omega4
    A = (
        s.r2 * w2**2 * np.cos(s.theta2)
        + s.r3 * w3**2 * np.cos(s.theta3)
        - s.r4 * w4**2 * np.cos(s.theta4)
    )
    B = (
        s.r2 * w2**2 * np.sin(s.theta2)
        + s.r3 * w3**2 * np.sin(s.theta3)
        - s.r4 * w4**2 * np.sin(s.theta4)
    )
    return -(A * np.cos(s.theta3) - B * np.sin(s.theta3)) / (s.r4 * np.sin(s.theta3 - s.theta4))


def printed_5_21_AB_alpha3(s):
    # A, B as printed with squared *accelerations* (th2'' = 0 -> its term vanishes); th3'', th4''
    # from the truth
    a3, a4 = s.alpha3, s.alpha4
    A = s.r3 * a3**2 * np.cos(s.theta3) - s.r4 * a4**2 * np.cos(s.theta4)
    B = s.r3 * a3**2 * np.sin(s.theta3) - s.r4 * a4**2 * np.sin(s.theta4)
    return -(A * np.cos(s.theta4) + B * np.sin(s.theta4)) / (s.r3 * np.sin(s.theta3 - s.theta4))


def test_printed_5_17_fails():
    s = fourbar(*R, TH2, omega2=W2)
    assert abs(printed_5_17_theta4(s) - s.theta4) > 1e-3
    # the corrected theta4 closes the loop; the printed one does not
    bad = fourbar(*R, TH2)
    z = (
        s.r2 * np.exp(1j * TH2)
        + s.r3 * np.exp(1j * s.theta3)
        - s.r1
        - s.r4 * np.exp(1j * printed_5_17_theta4(s))
    )
    assert abs(z) > 1e-3 and loop(bad) < 1e-14


def test_printed_5_19_5_20_fail_against_finite_differences():
    s = fourbar(*R, TH2, omega2=W2)
    d1, _ = fd_rates(
        lambda t: np.array(
            [fourbar_position(*R, TH2 + W2 * t).theta3, fourbar_position(*R, TH2 + W2 * t).theta4]
        ),
        angular=True,
    )
    np.testing.assert_allclose([s.omega3, s.omega4], d1, atol=1e-10)
    assert abs(printed_5_19_omega3(s, W2) - d1[0]) > 1e-2  # = -r2 th2'/r3 = -0.857
    assert abs(printed_5_20_omega4(s, W2) - d1[1]) > 1e-1  # = 0.998


def test_printed_5_21_5_22_fail_against_finite_differences():
    s = fourbar(*R, TH2, omega2=W2)
    _, d2 = fd_rates(
        lambda t: np.array(
            [fourbar_position(*R, TH2 + W2 * t).theta3, fourbar_position(*R, TH2 + W2 * t).theta4]
        ),
        angular=True,
    )
    np.testing.assert_allclose([s.alpha3, s.alpha4], d2, atol=1e-9)
    assert abs(printed_5_22_alpha4(s) - d2[1]) > 1e-1  # = 0.918 instead of 3.370
    assert abs(printed_5_21_AB_alpha3(s) - d2[0]) > 1e-1


# ---------------------------------------------------------------- properties over random geometry
lengths = st.floats(0.2, 5.0)


@settings(max_examples=50, deadline=None)
@given(
    lengths,
    lengths,
    lengths,
    lengths,
    st.floats(-np.pi, np.pi),
    st.floats(-3, 3),
    st.floats(-3, 3),
    st.sampled_from([1, -1]),
    st.floats(-np.pi, np.pi),
)
def test_complex_equals_cartesian_and_closes(r1, r2, r3, r4, th2, w2, a2, br, g):
    s = fourbar(r1, r2, r3, r4, th2, w2, a2, branch=br)
    gv = r1 * np.array([np.cos(g), np.sin(g)])
    c = fourbar_cartesian(gv, r2, r3, r4, th2 + g, w2, a2, branch=br)
    # at a toggle the angles are only defined to ~sqrt(eps): the two forms may disagree on the flag
    # there
    assert s.status == c.status or abs(np.sin(s.theta3 - s.theta4)) < 1e-6
    for x in (s.theta3, s.theta4, s.omega3, s.alpha4, s.residual):
        assert np.isfinite(x)
    if s.status != "ok":
        return
    scale = r1 + r2 + r3 + r4
    assert loop(s) <= 1e-12 * scale and loop(c) <= 1e-12 * scale
    assert abs(wrap(c.theta3 - g - s.theta3)) < 1e-9 and abs(wrap(c.theta4 - g - s.theta4)) < 1e-9
    sn = abs(np.sin(s.theta3 - s.theta4))
    if sn > 1e-3:
        tol = 1e-9 / sn**3 * (1 + abs(w2) + abs(a2)) ** 2
        np.testing.assert_allclose(
            [c.omega3, c.omega4, c.alpha3, c.alpha4],
            [s.omega3, s.omega4, s.alpha3, s.alpha4],
            atol=tol,
        )


@settings(max_examples=40, deadline=None)
@given(
    lengths,
    lengths,
    lengths,
    lengths,
    st.floats(-np.pi, np.pi),
    st.floats(-2, 2),
    st.floats(-2, 2),
    st.sampled_from([1, -1]),
)
def test_rates_match_finite_differences(r1, r2, r3, r4, th2, w2, a2, br):
    s = fourbar(r1, r2, r3, r4, th2, w2, a2, branch=br)
    if s.status != "ok" or abs(np.sin(s.theta3 - s.theta4)) < 0.2:
        return
    rng = fourbar_input_range(r1, r2, r3, r4)
    h = 1e-3
    if not all(rng.contains(th2 + w2 * t + 0.5 * a2 * t * t) for t in (-4 * h, 4 * h)):
        return

    def f(t):
        p = fourbar_position(r1, r2, r3, r4, th2 + w2 * t + 0.5 * a2 * t * t, branch=br)
        return np.array([p.theta3, p.theta4])

    d1, d2 = fd_rates(f, h=h, angular=True)
    np.testing.assert_allclose([s.omega3, s.omega4], d1, atol=1e-6 * (1 + abs(d1).max()))
    np.testing.assert_allclose([s.alpha3, s.alpha4], d2, atol=1e-4 * (1 + abs(d2).max()))


def test_both_branches_are_mirror_images_about_the_diagonal():
    up, dn = fourbar_position(*R, TH2, 1), fourbar_position(*R, TH2, -1)
    assert abs(wrap(up.theta3 - up.theta_d) + wrap(dn.theta3 - dn.theta_d)) < 1e-12
    assert loop(up) < 1e-14 and loop(dn) < 1e-14
    assert abs(up.theta4 - dn.theta4) > 0.1


def test_cannot_assemble_and_dead_point_are_reported_without_nan():
    s = fourbar(1.0, 3.0, 1.0, 3.5, 0.0, omega2=1.0, alpha2=1.0)  # d = 2 < |r3 - r4| = 2.5
    assert s.status == "cannot_assemble" and not s.assembled and "cannot assemble" in s.reason
    assert s.omega3 == 0.0 and s.alpha4 == 0.0 and s.residual > 0.1
    # toggle: d = r3 + r4 exactly -> coupler and rocker collinear
    s = fourbar(2.0, 1.0, 1.5, 1.5, np.pi, omega2=1.0)
    assert s.assembled and s.dead_point and s.status == "dead_point" and "dead point" in s.reason
    assert np.isfinite([s.theta3, s.theta4, s.omega3, s.omega4]).all()
    # d = 0: crank tip on the rocker pivot
    s = fourbar(1.0, 1.0, 1.0, 2.0, 0.0)
    assert not s.assembled and np.isfinite(s.theta3)
    # vectorised status
    s = fourbar(1.0, 3.0, 1.0, 3.5, np.linspace(-np.pi, np.pi, 9), 1.0)
    assert s.status.shape == (9,) and (s.status == "cannot_assemble").sum() == 3  # |th2| < 0.896
    assert np.isfinite(s.omega3).all()


@pytest.mark.parametrize(
    "bad",
    [
        dict(r1=0.0),
        dict(r2=-1.0),
        dict(r3=np.nan),
        dict(theta2=np.inf),
        dict(theta2="x"),
        dict(branch=0),
    ],
)
def test_bad_input_raises_value_error(bad):
    kw = dict(r1=4.0, r2=1.5, r3=3.5, r4=3.0, theta2=0.3, branch=1)
    kw.update(bad)
    with pytest.raises(ValueError):
        fourbar_position(**kw)


def test_bad_ground_vector():
    with pytest.raises(ValueError, match="ground"):
        fourbar_cartesian([0.0, 0.0], 1, 1, 1, 0.0)
    with pytest.raises(ValueError, match="ground"):
        fourbar_cartesian([1.0, 0.0, 0.0], 1, 1, 1, 0.0)


def test_coupler_point_rates_match_finite_differences():
    p, gam = 2.0, 0.6
    s = fourbar(*R, TH2, W2, 0.4)
    cp = coupler_point(s, p, gam)

    def f(t):
        q = fourbar_position(*R, TH2 + W2 * t + 0.2 * t * t)
        return coupler_point(q, p, gam).position

    d1, d2 = fd_rates(f)
    np.testing.assert_allclose(cp.velocity, d1, atol=1e-10)
    np.testing.assert_allclose(cp.acceleration, d2, atol=1e-9)
    pts = fourbar_points(s)
    np.testing.assert_allclose(np.linalg.norm(cp.position - pts["A"]), p, atol=1e-14)


def test_input_range_and_grashof():
    assert fourbar_grashof(4, 1.5, 3.5, 3) == "crank-rocker"
    assert fourbar_input_range(4, 1.5, 3.5, 3).full_turn
    assert fourbar_grashof(1, 3, 3.2, 2) == "double-crank"
    assert fourbar_grashof(3, 3, 1, 3.5) == "double-rocker"
    assert fourbar_grashof(3, 2, 2.5, 4) == "triple-rocker"
    assert fourbar_grashof(2, 1, 2, 1) == "change-point"
    rng = fourbar_input_range(3, 2, 2.5, 4)
    assert not rng.full_turn
    th = np.linspace(-np.pi, np.pi, 721)
    s = fourbar_position(3, 2, 2.5, 4, th)
    np.testing.assert_array_equal(rng.contains(th), s.assembled)


def test_printed_section_5_3_theta2_for_theta_d_fails():
    # §5-3 (l. 2711, 2727) prints tg th2 = (r1y - r2y)/(r1x - r2x) and th3 = th2 +/- alpha; the
    # angle is th_d
    r1, r2, r3, r4, th2 = R[0], R[1], R[2], R[3], TH2
    c = fourbar_cartesian([r1, 0.0], r2, r3, r4, th2)
    dx, dy = r1 - r2 * np.cos(th2), -r2 * np.sin(th2)
    d = np.hypot(dx, dy)
    alpha = np.arccos((r3 * r3 + d * d - r4 * r4) / (2 * r3 * d))
    printed_th3 = th2 + alpha  # printed: th3 = th2 + alpha
    B = r2 * np.exp(1j * th2) + r3 * np.exp(1j * printed_th3)
    assert abs(abs(B - r1) - r4) > 1e-2  # the rocker length is not kept
    assert abs(abs(r2 * np.exp(1j * th2) + r3 * np.exp(1j * c.theta3) - r1) - r4) < 1e-14
