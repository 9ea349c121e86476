"""The spatial cross-check provider runs, every row passes, and it holds only the spatial
mathematics (relative motion and RCCC rows live with the mechanisms, error propagation with
the kinematics)."""

import numpy as np

from anthroarm import crosscheck
from anthroarm.spatial.checks import rows


def test_provider_rows_pass():
    out = rows(["human_arm7", "prosthetic_arm"], 8, np.random.default_rng(1))
    assert {r.model for r in out} == {"spatial"}
    assert len(out) == 6
    bad = [r for r in out if not r.ok]
    assert not bad, bad
    assert "anthroarm.spatial.checks:rows" in crosscheck.PROVIDERS
