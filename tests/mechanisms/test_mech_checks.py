"""The mechanisms' rows of `anthroarm check` all pass and cover every mechanism, relative
motion and the RCCC loop."""

import numpy as np

from anthroarm import crosscheck
from anthroarm.mechanisms import checks


def test_mechanism_rows_pass_and_are_registered():
    assert "anthroarm.mechanisms.checks:rows" in crosscheck.PROVIDERS
    rows = checks.rows([], 3, np.random.default_rng(0))
    models = {r.model for r in rows}
    mechs = {"mech:fourbar", "mech:rssr", "mech:rrss", "mech:thumb", "mech:finger"}
    assert models == mechs | {"relative_motion", "rccc"}
    for m in mechs:
        oracles = {r.oracle for r in rows if r.model == m}
        assert {"pinocchio", "finite-diff", "math"} <= oracles, m
    assert {r.quantity for r in rows if r.model == "relative_motion"} == {
        "position 002 (4-6) vs pin FK (rel.)",
        "velocity 002 (4-11) vs frame velocity (rel.)",
        "acceleration 002 (4-17) vs classical acc (rel.)",
    }
    assert len([r for r in rows if r.model == "rccc"]) == 4
    bad = [(r.model, r.quantity, r.oracle, r.max_abs_err) for r in rows if not r.ok]
    assert not bad, bad
    assert all(r.samples >= 1 for r in rows)
    assert all(r.tol <= 1e-10 for r in rows if r.model != "rccc" or "finite" not in r.quantity)
