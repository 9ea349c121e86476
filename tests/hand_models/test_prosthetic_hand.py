"""models.prosthetic_hand: the catalog's plain mimic URDF of the book's linkage hand (Fig. 2-8
six-bar fingers, Fig. 2-9 thumb), made from the table the closed-loop analysis
(``mechanisms.linkage_hand``, tested in ``tests/mechanisms/test_linkage_hand.py``) writes.

Oracles: the exact closed-loop model and the mechanism solvers against the plain URDF through
Pinocchio; the committed table and URDF against their generators; the cross-check rows.
"""

import importlib

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.errors import ParameterError

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
