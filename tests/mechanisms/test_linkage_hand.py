"""mechanisms.linkage_hand: the book's linkages on one palm (Fig. 2-8 six-bar fingers, Fig. 2-9
thumb) as one exact closed-loop model, and the mimic fit of its spanning tree.

Oracles: the mechanism solvers (``mechanisms.finger.finger``, ``mechanisms.thumb.thumb``: the
§6-5 closed forms) against Pinocchio FK of the closed-loop model solved at loop closure (Newton
on Pinocchio frame placements, checked by ``pin.RigidConstraintModel``); the mobility counts of
Eq. (2-1) / the planar Grübler count against the rank of Pinocchio's constraint Jacobian; the
fitted lines against fresh exact closures.
"""

import numpy as np
import pytest

from anthroarm.design import structure
from anthroarm.errors import ParameterError
from anthroarm.mechanisms import linkage_hand as lh
from anthroarm.mechanisms.finger import FingerGeometry, finger
from anthroarm.mechanisms.thumb import thumb

FINGERS = ("index", "middle", "ring", "little")
DIGITS = ("thumb",) + FINGERS


@pytest.fixture(scope="module")
def hand():
    return lh.default_hand()


@pytest.fixture(scope="module")
def loop(hand):
    return lh.closed_loop(hand)


def _driver_grid(hand, n=7):
    """n driver vectors (5 digits, in the loop's input order) sweeping every range together."""
    lo = np.array([hand.driver_range(d)[0] for d in ("index", "little", "middle", "ring", "thumb")])
    hi = np.array([hand.driver_range(d)[1] for d in ("index", "little", "middle", "ring", "thumb")])
    t = np.linspace(0.0, 1.0, n)[:, None]
    return np.where(lo < 0, hi + (lo - hi) * t, lo + (hi - lo) * t)


def test_inputs_and_driver_ranges(hand, loop):
    assert loop.spec.inputs == ("index_mcp", "little_mcp", "middle_mcp", "ring_mcp", "thumb_r1")
    g = hand.fingers["index"]
    assert hand.driver_range("index") == pytest.approx((g.phi_range[1] - g.phi_range[0], 0.0))
    assert hand.driver_range("thumb") == pytest.approx((0.0, np.deg2rad(30)))


def test_fingertip_paths_equal_the_mechanism_solvers(hand, loop):
    """Pinocchio FK of the closed loop solved at closure = the §6-5 solvers, to 1e-9 m."""
    path = _driver_grid(hand, 9)
    Q, ok = loop.track(path, q0=np.zeros(loop.model.nq))
    assert ok.all()
    worst = worst_gap = worst_dist = 0.0
    for x, q in zip(path, Q):
        assert loop.residual_pin(q) < 1e-12
        for k, d in enumerate(("index", "little", "middle", "ring", "thumb")):
            p = loop.frame_position(q, f"{d}_tip")
            T = hand.mounts[d]
            if d == "thumb":
                s = thumb(hand.thumb, x[k])
                exact = T[:3, :3] @ s.S + T[:3, 3]
                pivot = T[:3, :3] @ hand.thumb.rrss.a0 + T[:3, 3]
                dist = np.linalg.norm(s.S - hand.thumb.rrss.a0)
            else:
                g = hand.fingers[d]
                s = finger(g, g.phi_range[0] + x[k])
                exact = T[:3, :3] @ np.r_[s.tip, 0.0] + T[:3, 3]
                pivot = T[:3, :3] @ np.r_[g.P1, 0.0] + T[:3, 3]
                dist = np.linalg.norm(s.tip - g.P1)
            assert s.status == "ok"
            worst = max(worst, np.linalg.norm(p - exact))
            # mount-free: the tip's distance from the mechanism's fixed pivot
            worst_dist = max(worst_dist, abs(np.linalg.norm(p - pivot) - dist))
        worst_gap = max(worst_gap, float(np.max(np.abs(loop.residual(q)))))
    assert worst < 1e-9 and worst_dist < 1e-9 and worst_gap < 1e-12


def test_middle_finger_follows_the_scaled_chapter3_curve(hand):
    """The middle finger is the index six-bar scaled by Buchholz's 0.544 / 0.485: its planar
    tip path is f(x) (Ch. 3, l. 1077) scaled by the same factor, within the index's fit error."""
    from anthroarm.mechanisms.finger import finger_f

    s = (0.266 + 0.170 + 0.108) / (0.245 + 0.143 + 0.097)
    g0, g = FingerGeometry.default(), hand.fingers["middle"]
    phi = np.linspace(*g.phi_range, 15)
    tip, tip0 = finger(g, phi).tip, finger(g0, phi).tip
    np.testing.assert_allclose(tip, s * tip0, atol=1e-15)
    x_mm = tip0[:, 0] * 1000
    inside = (x_mm >= 0) & (x_mm <= 40)
    assert np.max(np.abs(tip0[inside, 1] * 1000 - finger_f(x_mm[inside]))) < 1.0  # mm


def test_mobility_five_drivers(hand, loop):
    # each finger: planar six-bar, 5 moving links, 7 revolute pairs -> 1 (planar Grübler, §2-3)
    assert structure.planar_mobility(5, 7) == 1
    # thumb: RRSS (Eq. (2-1) minus the bar's spin) + the planar four-bar driven by R2 -> 1
    assert structure.rrss_mechanism().mobility() == 1 and structure.planar_mobility(3, 4) == 1
    # Pinocchio: nv - rank(constraint Jacobian) = 5 drivers + 1 local DOF (the S-S bar's spin)
    q = loop.track(_driver_grid(hand, 3)[1:2], q0=np.zeros(loop.model.nq))[0][0]
    J = loop._vel_jacobian(q)
    rank = np.linalg.matrix_rank(J, tol=1e-9)
    assert loop.model.nv - rank == 5 + 1
    # with the drivers held, nothing but the spin moves
    free = J[:, loop.free_idx]
    assert free.shape[1] - np.linalg.matrix_rank(free, tol=1e-9) == 1


def test_solve_returns_tips_and_statuses(hand, loop):
    st = lh.solve(loop, {"index_mcp": -0.1, "thumb_r1": 0.3}, hand)
    assert st.ok and st.residual < 1e-12
    g = hand.fingers["index"]
    T = hand.mounts["index"]
    np.testing.assert_allclose(
        st.tips["index"],
        T[:3, :3] @ np.r_[finger(g, g.phi_range[0] - 0.1).tip, 0] + T[:3, 3],
        atol=1e-9,
    )
    # drivers outside the range: a status, no NaN
    bad = lh.solve(loop, {"index_mcp": 0.3}, hand)
    assert bad.status == "out_of_range" and "index_mcp" in bad.reason and bad.tips == {}
    assert np.all(np.isfinite(bad.q))
    bad = lh.solve(loop, {"thumb_r1": -0.2}, hand)
    assert bad.status == "out_of_range"
    with pytest.raises(ParameterError):
        lh.solve(loop, {"index_knuckle": 0.1}, hand)
    with pytest.raises(ParameterError):
        lh.solve(loop, {"index_mcp": float("nan")}, hand)
    with pytest.raises(ParameterError):
        lh.solve(loop, [0.1, 0.2], hand)
    with pytest.raises(ParameterError):
        lh.solve(loop, ["a", "b", "c", "d", "e"], hand)
    with pytest.raises(ParameterError):
        lh.solve(loop, {"thumb_r1": "wide"}, hand)


def test_inconsistent_passive_joints_are_reported(hand, loop):
    st = lh.solve(loop, {"middle_mcp": -0.15}, hand)
    gap, status = lh.closure_status(loop, st.q)
    assert status == "ok" and gap < 1e-12
    q = st.q.copy()
    q[loop.joint_q_index("middle_pip")] += 0.05  # a PIP that contradicts its driver
    gap, status = lh.closure_status(loop, q)
    assert status == "inconsistent" and gap > 1e-4
    for bad in (q[:-1], "abc", np.full_like(q, np.nan)):
        with pytest.raises(ParameterError, match="joint values"):
            lh.closure_status(loop, bad)


def test_mimic_joint_lines_reproduce_the_closed_loop_at_the_ends(hand, loop):
    """At the start pose both models agree to the fit's offset; every fitted joint's reported
    error bounds its deviation from the exact closure on a fresh, finer driver grid."""
    fit = lh.mimic_fit()
    path = _driver_grid(hand, 23)
    Q, ok = loop.track(path, q0=np.zeros(loop.model.nq))
    assert ok.all()
    inputs = list(loop.spec.inputs)
    for n, (src, a, b, jerr) in fit.joints.items():
        u = path[:, inputs.index(src)]
        exact = Q[:, loop.joint_q_index(n)]
        # the line's deviation on the fine grid stays within the reported error (+ its
        # between-sample slack)
        assert np.max(np.abs(a * u + b - exact)) <= jerr * 1.05 + 1e-9
