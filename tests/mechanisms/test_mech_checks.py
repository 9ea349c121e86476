"""The mechanisms' rows of `anthroarm check` all pass at 1e-10 and cover every mechanism."""

import numpy as np

from anthroarm import crosscheck
from anthroarm.mechanisms import checks


def test_mechanism_rows_pass_and_are_registered():
    assert "anthroarm.mechanisms.checks:rows" in crosscheck.PROVIDERS
    rows = checks.rows([], 3, np.random.default_rng(0))
    models = {r.model for r in rows}
    assert models == {"mech:fourbar", "mech:rssr", "mech:rrss", "mech:thumb", "mech:finger"}
    for m in models:
        oracles = {r.oracle for r in rows if r.model == m}
        assert {"pinocchio", "finite-diff", "math"} <= oracles, m
    bad = [(r.model, r.quantity, r.oracle, r.max_abs_err) for r in rows if not r.ok]
    assert not bad, bad
    assert all(r.tol <= 1e-10 for r in rows)
