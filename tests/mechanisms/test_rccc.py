"""RCCC mechanism by dual-number matrices (book §5-6 四): recomputed elements, both branches,
rates vs a Pinocchio open chain and finite differences; the printed elements fail."""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from anthroarm.mechanisms.rccc import (
    RCCCGeometry,
    c_elements,
    d_elements,
    loop_matrices,
    pinocchio_chain,
    rccc_acceleration,
    rccc_position,
    rccc_velocity,
)
from anthroarm.spatial import dual as D
from anthroarm.spatial.dual import Dual

H = settings(max_examples=40, deadline=None)
twist = st.floats(0.2, np.pi - 0.2)
length = st.floats(-2.0, 2.0)
dual_link = st.tuples(twist, length).map(lambda t: Dual(*t))
dual_joint = st.tuples(st.floats(-np.pi, np.pi), length).map(lambda t: Dual(*t))

FIXTURE = RCCCGeometry(Dual(0.5, 1.0), Dual(1.0, 2.5), Dual(0.8, 1.5), Dual(1.2, 3.0), s1=0.7)


def wrap(a):
    return float(np.angle(np.exp(1j * a)))


def test_notes_fixture_both_branches():
    """ch5.md §3 synthetic fixture (computed by the note's author, not printed in the book)."""
    r = rccc_position(FIXTURE, 0.9)
    assert r.status == "ok" and len(r.solutions) == 2
    expected = [
        ((3.530899, 0.347775), (2.961129, -0.855839), (-0.980084, 0.276170)),
        ((1.981656, -2.178122), (1.683413, -2.552412), (0.980084, -0.276170)),
    ]
    for sol in r.solutions:
        match = [e for e in expected if abs(wrap(sol.theta4.real - e[0][0])) < 1e-5]
        assert len(match) == 1
        (t4, s4), (t2, s2), (t3, s3) = match[0]
        assert abs(wrap(sol.theta4.real - t4)) < 1e-5 and abs(sol.theta4.dual - s4) < 1e-5
        assert abs(wrap(sol.theta2.real - t2)) < 1e-5 and abs(sol.theta2.dual - s2) < 1e-5
        assert abs(wrap(sol.theta3.real - t3)) < 1e-5 and abs(sol.theta3.dual - s3) < 1e-5
        assert sol.closure_residual < 1e-13


# ----------------------------------------------------------------------------- elements
def printed_c(a12, a41, a34, t1, t4):
    """The c-elements as printed (l. 3569-3576), with cα43 read as cα41 (only the ones the
    book gets wrong; c11, c13, c21 are printed correctly)."""
    c12, s12, c41, s41, c34, s34 = (
        D.cos(a12),
        D.sin(a12),
        D.cos(a41),
        D.sin(a41),
        D.cos(a34),
        D.sin(a34),
    )
    ct1, st1, ct4, st4 = D.cos(t1), D.sin(t1), D.cos(t4), D.sin(t4)
    return {
        (0, 1): c34 * (ct1 * st4 + c41 * st1 * ct4) - s34 * (c41 * s12 + s41 * c12 * ct1),
        (1, 1): -c34 * (s12 * st1 * st4 - ct4 * (s41 * c12 + c41 * s12 * ct1))
        - s34 * (c41 * s12 + s41 * c12 * ct1),
        (1, 2): -s34 * (s12 * st1 * st4 + (s41 * s12 - c41 * c12 * ct1) * ct4)
        + c34 * (c41 * s12 + s41 * c12 * ct1),
        (2, 0): s12 * st1 * ct4 + st4 * (s41 * s12 - c41 * c12 * ct1),
        (2, 1): c34 * (s12 * st1 * st4 - (s41 * c12 + c41 * s12 * ct1))
        - s34 * (c41 * c12 - s41 * s12 * ct1),
        (2, 2): s34 * (s12 * st1 * st4 - ct4 * (s41 * c12 + c41 * s12 * ct1))
        - c34 * (c41 * c12 - s41 * s12 * ct1),
    }


def printed_d(a23, t2, t3):
    """The d-elements as printed that are wrong: d12 (with cα43 read as cα23), d13 ("cθ22" read
    as cθ2), d22, d32."""
    ca, sa, c2, s2, c3, s3 = D.cos(a23), D.sin(a23), D.cos(t2), D.sin(t2), D.cos(t3), D.sin(t3)
    return {
        (0, 1): -c2 * s3 + s2 * c3 * ca,
        (0, 2): sa * c2,
        (1, 1): -s2 * s3 - c2 * c3 * ca,
        (2, 1): sa * c2,
    }


@H
@given(dual_link, dual_link, dual_link, dual_link, dual_joint, dual_joint, dual_joint, dual_joint)
def test_closed_form_elements_equal_the_dual_matrix_products(a12, a23, a34, a41, t1, t2, t3, t4):
    g = RCCCGeometry(a12, a23, a34, a41, s1=float(t1.dual))
    C, Dm = loop_matrices(g, t1, t2, t3, t4)
    Ce = c_elements(a12, a41, a34, t1, t4)
    De = d_elements(a23, t2, t3)
    assert np.allclose(C.real, Ce.real, atol=1e-12) and np.allclose(C.dual, Ce.dual, atol=1e-12)
    assert np.allclose(Dm.real, De.real, atol=1e-12) and np.allclose(Dm.dual, De.dual, atol=1e-12)


def test_printed_elements_fail():
    a12, a23, a34, a41 = Dual(0.5, 1.0), Dual(1.0, 2.5), Dual(0.8, 1.5), Dual(1.2, 3.0)
    t1, t2, t3, t4 = Dual(0.9, 0.7), Dual(0.4, -0.3), Dual(-1.1, 0.2), Dual(2.0, 0.5)
    Ce = c_elements(a12, a41, a34, t1, t4)
    for (i, j), v in printed_c(a12, a41, a34, t1, t4).items():
        assert not v.isclose(Ce[i, j], atol=1e-3), f"printed c{i + 1}{j + 1} unexpectedly right"
    De = d_elements(a23, t2, t3)
    for (i, j), v in printed_d(a23, t2, t3).items():
        assert not v.isclose(De[i, j], atol=1e-3), f"printed d{i + 1}{j + 1} unexpectedly right"
    # the printed input-output equation c33 = d33 does not close the loop of a real solution
    sol = rccc_position(FIXTURE, 0.9).solutions[0]
    pc33 = printed_c(FIXTURE.alpha12, FIXTURE.alpha41, FIXTURE.alpha34, sol.theta1, sol.theta4)[
        (2, 2)
    ]
    assert abs(pc33.real - np.cos(FIXTURE.alpha23.real)) > 1e-2


def test_book_theta3_rule_uses_c32_not_c21():
    """The print says θ3 follows from c31 = d31 and c21 = d21; d21 involves θ2 as well — the
    pair that isolates θ3 is (d31, d32) = sα23 (sθ3, cθ3)."""
    sol = rccc_position(FIXTURE, 0.9).solutions[1]
    De = d_elements(FIXTURE.alpha23, sol.theta2, sol.theta3)
    sa = D.sin(FIXTURE.alpha23)
    assert D.atan2(De[2, 0] / sa, De[2, 1] / sa).isclose(sol.theta3, atol=1e-12)
    assert not D.atan2(De[2, 0] / sa, De[1, 0] / sa).isclose(sol.theta3, atol=1e-3)


# ----------------------------------------------------------------------------- positions and rates
# vs Pinocchio
def _check_against_pinocchio(g, sol, w1, a1):
    model, fid = pinocchio_chain(g)
    data = model.createData()
    v = rccc_velocity(g, sol, w1)
    a = rccc_acceleration(g, sol, w1, a1, v)
    if v.status != "ok":
        return False
    pin.forwardKinematics(model, data, sol.q, v.rates, a.rates)
    pin.updateFramePlacements(model, data)
    LWA = pin.LOCAL_WORLD_ALIGNED
    scale = g.scale  # linear parts relative to the link size, angular parts absolute
    err6 = pin.log6(data.oMf[fid]).vector
    assert np.abs(err6[:3]).max() / scale < 1e-10 and np.abs(err6[3:]).max() < 1e-10
    vmag = max(1.0, np.abs(v.rates).max())  # near a dead point the rates grow without bound
    amag = max(1.0, np.abs(v.rates).max() ** 2, np.abs(a.rates).max())
    V = pin.getFrameVelocity(model, data, fid, LWA).vector
    A = pin.getFrameClassicalAcceleration(model, data, fid, LWA).vector
    assert np.abs(V[:3]).max() / scale < 1e-10 * vmag and np.abs(V[3:]).max() < 1e-10 * vmag
    assert np.abs(A[:3]).max() / scale < 1e-10 * amag and np.abs(A[3:]).max() < 1e-10 * amag
    return True


@H
@given(
    dual_link,
    dual_link,
    dual_link,
    dual_link,
    length,
    st.floats(-np.pi, np.pi),
    st.floats(-2, 2),
    st.floats(-2, 2),
)
def test_random_rccc_closes_and_rates_match_pinocchio(a12, a23, a34, a41, s1, th1, w1, acc1):
    g = RCCCGeometry(a12, a23, a34, a41, s1)
    r = rccc_position(g, th1)
    assert r.status in ("ok", "cannot assemble", "dead point", "degenerate")
    assume(r.ok)
    for sol in r.solutions:
        assert sol.closure_residual < 1e-10
        assert np.all(np.isfinite(sol.q))
        _check_against_pinocchio(g, sol, w1, acc1)


def test_rates_match_finite_differences():
    g, th1, w1 = FIXTURE, 0.9, 1.3
    h = 1e-5
    for b in (0, 1):
        sol = rccc_position(g, th1).solutions[b]
        v = rccc_velocity(g, sol, w1)
        a = rccc_acceleration(g, sol, w1, 0.0, v)
        qp = rccc_position(g, th1 + w1 * h).solutions[b].q
        qm = rccc_position(g, th1 - w1 * h).solutions[b].q
        assert np.allclose((qp - qm) / (2 * h), v.rates, atol=1e-7)
        dq = np.angle(np.exp(1j * (qp - 2 * sol.q + qm)))
        dq[[2, 4, 6]] = (qp - 2 * sol.q + qm)[[2, 4, 6]]
        assert np.allclose(dq[1:] / h**2, a.rates[1:], atol=1e-3)
        assert v["theta1"] == w1 and v["s4"] == v.rates[2]


# ----------------------------------------------------------------------------- bad geometry
def test_cannot_assemble_is_a_status():
    g = RCCCGeometry(Dual(0.2, 1.0), Dual(2.9, 0.5), Dual(0.2, 1.0), Dual(0.3, 0.5), 0.0)
    r = rccc_position(g, 0.0)
    assert r.status == "cannot assemble" and r.solutions == [] and "no real θ4" in r.message


def test_degenerate_and_dead_point_statuses():
    g = RCCCGeometry(
        Dual(0.5, 1.0), Dual(1.0, 2.5), Dual(0.0, 1.5), Dual(1.2, 3.0), 0.7
    )  # sin α34 = 0
    assert rccc_position(g, 0.9).status == "degenerate"
    g2 = RCCCGeometry(
        Dual(0.5, 1.0), Dual(0.0, 2.5), Dual(0.8, 1.5), Dual(1.2, 3.0), 0.7
    )  # sin α23 = 0
    assert rccc_position(g2, 0.9).status in ("degenerate", "cannot assemble")
    # a rocker input: assembly fails for part of the turn; bisect to the dead point
    rocker = RCCCGeometry(Dual(0.6, 1.0), Dual(0.5, 2.5), Dual(0.8, 1.5), Dual(1.2, 3.0), 0.7)
    ths = np.linspace(-np.pi, np.pi, 181)
    ok = np.array([rccc_position(rocker, t).ok for t in ths])
    assert ok.any() and not ok.all()
    statuses = {rccc_position(rocker, t).status for t in ths}
    assert statuses <= {"ok", "cannot assemble"}
    k = int(np.nonzero(ok[1:] != ok[:-1])[0][0])
    lo, hi = ths[k], ths[k + 1]  # ok[k] differs from ok[k+1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if rccc_position(rocker, mid).ok == ok[k]:
            lo = mid
        else:
            hi = mid
    r = rccc_position(rocker, 0.5 * (lo + hi), tol=1e-6)
    assert r.status == "dead point" and "dead point" in r.message and r.solutions == []
    # just inside the assembly range the two branches meet
    inside = lo if ok[k] else hi
    near = rccc_position(rocker, inside)
    if near.ok:
        t4 = [s_.theta4.real for s_ in near.solutions]
        assert abs(wrap(t4[0] - t4[1])) < 1e-3


def test_rccc_bad_input():
    with pytest.raises(ValueError, match="alpha12"):
        RCCCGeometry("x", Dual(1.0, 0), Dual(1.0, 0), Dual(1.0, 0))
    with pytest.raises(ValueError, match="finite"):
        RCCCGeometry(Dual(1.0, 0), Dual(1.0, 0), Dual(1.0, 0), Dual(1.0, 0), np.nan)
    with pytest.raises(ValueError, match="theta1"):
        rccc_position(FIXTURE, np.nan)
    with pytest.raises(ValueError, match="theta1 must be a scalar"):
        rccc_position(FIXTURE, np.array([0.1, 0.2]))
    sol = rccc_position(FIXTURE, 0.9).solutions[0]
    with pytest.raises(ValueError, match="theta1_dot"):
        rccc_velocity(FIXTURE, sol, np.nan)
    with pytest.raises(ValueError, match="theta1_ddot"):
        rccc_acceleration(FIXTURE, sol, 1.0, np.inf)
    assert RCCCGeometry((0.5, 1.0), (1.0, 2.5), (0.8, 1.5), (1.2, 3.0), 0.7).alpha12.isclose(
        Dual(0.5, 1.0)
    )
