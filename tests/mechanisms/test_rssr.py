"""RSSR closed form (002 §4-2 (4-18)-(4-31)) and the §5-2 polar form.

Oracles: the derived reference D1 of ch9-and-002.md (two independent computations there),
closure |a - b| = |a1 - b1|, finite differences, Pinocchio closed loop; printed (4-27)/(4-30)
shown wrong."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from anthroarm.mechanisms._util import fd_derivative, skew, wrap
from anthroarm.mechanisms.closed_loop import ClosedLoop
from anthroarm.mechanisms.pin_models import rssr_spec
from anthroarm.mechanisms.rssr import (
    RSSRGeometry,
    rssr,
    rssr_branch_through,
    rssr_crank_test,
    rssr_polar,
    rssr_position,
)

D1 = RSSRGeometry(
    a0=[0, 0, 0], ua=[0, 0, 1], a1=[1, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 3]
)


@pytest.mark.parametrize(
    "alpha,E,F,G,disc,b1,b2",
    [
        (0, -2, -4, 2, 16, 126.869898, 0.0),
        (30, -2, -4.267949, 1.598076, 19.661543, 135.072455, -5.288891),
        (60, -2, -5, 0.5, 28.75, 152.871138, -16.473957),
        (90, -2, -6, -1, 39, 170.662487, -27.532385),
        (180, -2, -8, -4, 52, -165.019103, -43.053384),
    ],
)
def test_derived_reference_D1(alpha, E, F, G, disc, b1, b2):
    s, t = rssr_position(D1, np.deg2rad(alpha), 1), rssr_position(D1, np.deg2rad(alpha), -1)
    np.testing.assert_allclose([s.E, s.F, s.G, s.discriminant], [E, F, G, disc], atol=1e-6)
    assert abs(np.rad2deg(s.beta) - b1) < 1e-6 and abs(np.rad2deg(t.beta) - b2) < 1e-6
    assert s.residual < 1e-14 and t.residual < 1e-14


def test_D1_rates_and_crank_test():
    s = rssr(D1, np.deg2rad(30), 1.0, 0.5, branch=-1)
    np.testing.assert_allclose(s.a, [0.8660254, 0.5, 0], atol=1e-7)
    np.testing.assert_allclose(s.b, [2.81564496, 0, 2.99148518], atol=1e-8)
    assert abs(s.betadot - -0.31749662) < 1e-8 and abs(s.betaddot - -0.52974244) < 1e-8
    ct = rssr_crank_test(D1)
    assert ct.is_crank and ct.kind == "crank" and abs(ct.min_discriminant - 16) < 1e-9
    assert rssr_branch_through(D1) == -1


# ------------------------------------------------------------ printed forms (errata, 002 text)
def test_printed_4_27_and_4_30_fail():
    s = rssr(D1, np.deg2rad(50), 1.3, 0.4, branch=-1)
    ab = s.a - s.b
    rel = s.adot - s.bdot
    # (4-27) as printed: (a' - b')^T (a - b) + |a' - b'|^2 = 0 -- its first term is 0 by (4-23)
    assert abs(rel @ ab) < 1e-14 and abs(rel @ ab + rel @ rel) > 1e-2
    P = skew(D1.ub)
    rb = s.b - D1.b0
    den = ab @ P @ rb
    # (4-30) as printed, the stray -beta' [P_ub](b - b0) read inside the (a - b)^T bracket
    printed = (ab @ (s.addot - s.betadot**2 * P @ P @ rb - s.betadot * P @ rb) + rel @ rel) / den
    truth = fd_derivative(
        lambda t: rssr(D1, np.deg2rad(50) + 1.3 * t + 0.2 * t * t, 1.3 + 0.4 * t, 0.4, -1).betadot
    )
    assert abs(s.betaddot - truth) < 1e-10 and abs(printed - truth) > 1e-2


# ------------------------------------------------------------ properties over random geometry
def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


vec = st.lists(st.floats(-1, 1), min_size=3, max_size=3)


@settings(max_examples=40, deadline=None)
@given(
    vec,
    vec,
    vec,
    vec,
    vec,
    vec,
    st.floats(-np.pi, np.pi),
    st.floats(0.3, 2),
    st.floats(-1, 1),
    st.sampled_from([1, -1]),
)
def test_closure_and_rates_by_finite_differences(a0, ua, a1, b0, ub, b1, al, w, acc, br):
    if np.linalg.norm(ua) < 0.3 or np.linalg.norm(ub) < 0.3:
        return
    try:
        g = RSSRGeometry(
            np.array(a0) * 0.2,
            unit(ua),
            np.array(a1) * 0.3 + [1, 0, 0],
            np.array(b0) * 0.3 + [3, 0, 1],
            unit(ub),
            np.array(b1) * 0.3 + [3, 0, 3],
        )
    except ValueError:
        return
    s = rssr(g, al, w, acc, br)
    assert np.isfinite([s.beta, s.betadot, s.betaddot]).all() and np.isfinite(s.b).all()
    if s.status != "ok":
        assert s.betadot == 0.0
        return
    L = g.length_scale
    assert s.residual < 1e-12 * L
    if s.discriminant < 1e-2 * L**4:
        return

    def traj(t):
        return rssr(g, al + w * t + 0.5 * acc * t * t, w + acc * t, acc, br)

    d1 = fd_derivative(lambda t: traj(t).beta, angular=True)
    d2 = fd_derivative(lambda t: traj(t).betadot)
    sc1, sc2 = max(1, abs(s.betadot)), max(1, abs(s.betaddot))
    assert abs(d1 - s.betadot) < 1e-8 * sc1 and abs(d2 - s.betaddot) < 1e-7 * sc2
    np.testing.assert_allclose(fd_derivative(lambda t: traj(t).b), s.bdot, atol=1e-8 * L * sc1)
    np.testing.assert_allclose(fd_derivative(lambda t: traj(t).bdot), s.bddot, atol=1e-7 * L * sc2)


def test_against_pinocchio_closed_loop_by_continuation():
    g = RSSRGeometry(
        a0=[0.05, -0.02, 0.0],
        ua=unit([0.1, 0.2, 1]),
        a1=[1.0, 0.1, 0.0],
        b0=[3, 0.1, 1],
        ub=unit([0.0, 1, 0.2]),
        b1=[3.1, 0, 3],
    )
    assert rssr_crank_test(g).is_crank
    br = rssr_branch_through(g)
    loop = ClosedLoop(rssr_spec(g))
    path = np.linspace(0, 2 * np.pi, 64)
    Q, ok = loop.track(path[:, None])
    assert ok.all()
    ib = loop.joint_q_index("rocker")
    s = rssr_position(g, path, br)
    assert np.max(np.abs(wrap(Q[:, ib] - s.beta))) < 1e-10
    st_ = loop.solve([path[20]], [1.1], [0.3], q0=Q[20])
    c = rssr(g, path[20], 1.1, 0.3, br)
    assert st_.ok and abs(st_.v[ib] - c.betadot) < 1e-12 and abs(st_.a[ib] - c.betaddot) < 1e-12
    assert loop.residual_pin(st_.q) < 1e-12
    np.testing.assert_allclose(
        loop.frame_acceleration(st_.q, st_.v, st_.a, "b_rocker"), c.bddot, atol=1e-12
    )


def test_cannot_assemble_rocker_and_bad_input():
    g = RSSRGeometry(
        a0=[0, 0, 0], ua=[0, 0, 1], a1=[2, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 2]
    )
    ct = rssr_crank_test(g)
    assert not ct.is_crank and ct.kind == "rocker" and ct.intervals
    al = np.linspace(-np.pi, np.pi, 73)
    s = rssr_position(g, al)
    bad = ~np.asarray(s.assembled)
    assert bad.any() and (np.asarray(s.status)[bad] == "cannot_assemble").all()
    assert np.isfinite(s.beta).all() and "cannot assemble" in s.reason
    one = rssr(g, float(al[bad][0]), 1.0, 1.0)
    assert one.status == "cannot_assemble" and "(4-31)" in one.reason and one.betadot == 0.0
    for kw in (dict(ua=[0, 0, 0]), dict(ua=[0, 0, 2]), dict(b1=[np.nan, 0, 0]), dict(a1=[0, 0, 1])):
        args = dict(
            a0=[0, 0, 0], ua=[0, 0, 1], a1=[1, 0, 0], b0=[3, 0, 1], ub=[0, 1, 0], b1=[3, 0, 3]
        )
        args.update(kw)
        with pytest.raises(ValueError):
            RSSRGeometry(**args)
    with pytest.raises(ValueError, match="branch"):
        rssr_position(D1, 0.1, branch=0)


def test_chapter5_polar_form_matches_the_002_form():
    r2, r3, r4, C, th2, phi2 = 1.0, 4.0, 2.0, np.array([3.0, 1.0, 0.5]), 0.4, 1.1
    for br, ref in ((1, 2.221524889), (-1, 0.877485105)):  # ch5.md §3 synthetic fixture
        phi4, ok = rssr_polar(r2, r3, r4, C, th2, phi2, br)
        assert ok and abs(phi4 - ref) < 1e-8
        A = r2 * np.array([np.sin(phi2) * np.cos(th2), np.sin(phi2) * np.sin(th2), np.cos(phi2)])
        B = C + r4 * np.array([np.sin(phi4), 0, np.cos(phi4)])
        assert abs(np.linalg.norm(B - A) - r3) < 1e-12
    # the same mechanism in the 002 form, referenced at the polar solution: moving the crank by
    # delta moves the rocker by the difference of the polar outputs
    phi4, _ = rssr_polar(r2, r3, r4, C, th2, phi2, 1)
    a1 = r2 * np.array([np.sin(phi2) * np.cos(th2), np.sin(phi2) * np.sin(th2), np.cos(phi2)])
    b1 = C + r4 * np.array([np.sin(phi4), 0, np.cos(phi4)])
    g = RSSRGeometry(
        a0=[0, 0, 0], ua=[-np.sin(th2), np.cos(th2), 0], a1=a1, b0=C, ub=[0, 1, 0], b1=b1
    )
    br = rssr_branch_through(g)
    for delta in (0.1, 0.3, -0.2):
        new, _ = rssr_polar(r2, r3, r4, C, th2, phi2 + delta, 1)
        assert abs(wrap(rssr_position(g, delta, br).beta - (new - phi4))) < 1e-10
