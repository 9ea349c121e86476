"""prosthetic_hand: the book's linkages on one palm (Fig. 2-8 six-bar fingers, Fig. 2-9 thumb):
the exact closed-loop model (``mechanisms.linkage_hand``) and the catalog's plain mimic URDF
(``models.prosthetic_hand``, made from the table the closed-loop analysis writes).

Oracles: the mechanism solvers (``mechanisms.finger.finger``, ``mechanisms.thumb.thumb``: the
§6-5 closed forms) against Pinocchio FK of the closed-loop model solved at loop closure (Newton
on Pinocchio frame placements, checked by ``pin.RigidConstraintModel``); the mobility counts of
Eq. (2-1) / the planar Grübler count against the rank of Pinocchio's constraint Jacobian; the
plain mimic URDF through Pinocchio against the exact paths.
"""

import importlib

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.design import structure
from anthroarm.errors import ParameterError
from anthroarm.mechanisms.finger import FingerGeometry, finger
from anthroarm.mechanisms.thumb import thumb

# the module (anthroarm.models.prosthetic_hand is also the catalog builder's name in the package)
ph = importlib.import_module("anthroarm.models.prosthetic_hand")
lh = importlib.import_module("anthroarm.mechanisms.linkage_hand")

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


def test_plain_urdf_mimic_approximation_error_is_what_is_reported(hand, loop):
    robot = aa.load("prosthetic_hand")
    assert robot.nq == 5 and robot.has_mimic and robot.tool == "index_tip"
    fit = lh.mimic_fit()
    names = list(robot.model.names)[1:]
    drv = [n for n in names if n in loop.spec.inputs]
    assert drv == ["index_mcp", "little_mcp", "middle_mcp", "ring_mcp", "thumb_r1"]
    for k, d in enumerate(("index", "little", "middle", "ring", "thumb")):
        lo, hi = hand.driver_range(d)
        u = np.linspace(0.0, 1.0, fit.samples)
        u = lo + (hi - lo) * u if d == "thumb" else hi + (lo - hi) * u
        err = 0.0
        for v in u:
            q = np.zeros(5)
            q[k] = v
            exact, status = hand.tip_exact(d, v)
            assert status == "ok"
            err = max(err, np.linalg.norm(robot.fk(q, frame=f"{d}_tip")[:3, 3] - exact))
        # Pinocchio on the plain URDF vs the solver = the fit's report, which came from the tree
        assert err == pytest.approx(fit.tip_error[d], abs=1e-9)
        assert 1e-4 < err < 0.01  # a linear mimic is a few mm off the linkage's path
    # the mimic lines in the URDF are the fit's
    for n, (src, a, b, jerr) in fit.joints.items():
        if abs(a) < 1e-9:
            continue
        jid = robot.model.getJointId(n)
        assert robot.model.existJointName(n) and jid < robot.model.njoints
        assert jerr >= 0


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
        # the line's deviation on the fine grid stays within the reported error (+ its between-sample slack)
        assert np.max(np.abs(a * u + b - exact)) <= jerr * 1.05 + 1e-9


def test_scale_and_bad_parameters():
    big = lh.default_hand(1.2)
    base = lh.default_hand()
    assert big.fingers["index"].R == pytest.approx(tuple(1.2 * r for r in base.fingers["index"].R))
    np.testing.assert_allclose(big.thumb.rrss.b0, 1.2 * base.thumb.rrss.b0, atol=1e-15)
    for bad in (0.0, -1.0, float("nan"), 10.0, "big", True):
        with pytest.raises(ParameterError):
            ph.prosthetic_hand(scale=bad)
    for bad in (2, 10**9, 41.0, "41"):  # 10**9 exact solutions would run for hours
        with pytest.raises(ParameterError, match="samples"):
            lh.mimic_fit(samples=bad)


def test_committed_urdf_equals_generator_and_loads_everywhere(tmp_path, same_urdf_text):
    from pathlib import Path

    committed = Path(__file__).resolve().parents[2] / "urdf" / "prosthetic_hand.urdf"
    assert same_urdf_text(committed.read_text(), ph.urdf_text()), (
        "urdf/prosthetic_hand.urdf is stale: run ph.write_urdf()"
    )
    out = ph.write_urdf(tmp_path / "hand.urdf", scale=1.1)
    assert out.read_text() == ph.urdf_text(1.1)
    m = pin.buildModelFromXML(out.read_text(), mimic=True)
    assert m.nq == 5
    import yourdfpy

    u = yourdfpy.URDF.load(str(out))
    assert len(u.actuated_joint_names) == 5
    r = aa.load(str(out), tool="thumb_tip")  # any URDF consumer of the package
    assert r.nq == 5 and r.has_mimic


def test_crosscheck_rows_pass_on_the_plain_hand():
    from anthroarm import crosscheck

    rows = crosscheck.run(
        [aa.load("prosthetic_hand")],
        samples=6,
        providers=["anthroarm.kinematics.checks:rows", "anthroarm.dynamics.checks:model_rows"],
    )
    assert len(rows) >= 8
    bad = [(r.quantity, r.max_abs_err, r.note) for r in rows if not r.ok]
    assert not bad, bad


def test_the_catalog_table_is_the_closed_loop_analysis():
    """The committed table the catalog model is made of (``data/models/linkage_hand.json``)
    equals what the mechanism analysis computes now (regenerate it with
    ``anthroarm.mechanisms.linkage_hand.write_tree_table()``), and the scaling the catalog
    applies (lengths × s; angles, multipliers and offsets unchanged) is what the analysis of a
    scaled hand gives."""
    assert ph.tree_table() == lh.tree_table(), "stale table: run lh.write_tree_table()"
    table, s = ph.tree_table(), 0.8
    spec = lh.loop_spec(lh.default_hand(s))
    assert [j.name for j in spec.joints] == [j[0] for j in table["joints"]]
    for j, (_, parent, child, kind, T, axis) in zip(spec.joints, table["joints"]):
        assert (j.parent, j.child, j.type) == (parent, child, kind)
        T = np.reshape(T, (4, 4))
        np.testing.assert_allclose(j.origin[:3, :3], T[:3, :3], atol=1e-12)
        np.testing.assert_allclose(j.origin[:3, 3], s * T[:3, 3], atol=1e-12)
        np.testing.assert_allclose(j.axis, axis, atol=1e-15)
    for (n, p, T), (n1, p1, T1) in zip(spec.sites, table["sites"]):
        assert (n, p) == (n1, p1)
        np.testing.assert_allclose(T[:3, 3], s * np.reshape(T1, (4, 4))[:3, 3], atol=1e-12)
    fit = lh.mimic_fit(s)
    for name, (src, a, b, err) in table["fit"]["joints"].items():
        src1, a1, b1, err1 = fit.joints[name]
        assert src1 == src and a1 == pytest.approx(a, abs=1e-9) and b1 == pytest.approx(b, abs=1e-9)
    for d, e in table["fit"]["tip_error"].items():
        assert fit.tip_error[d] == pytest.approx(s * e, rel=1e-6)
