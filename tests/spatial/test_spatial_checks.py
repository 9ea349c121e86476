"""The spatial cross-check provider runs and every row passes."""

import numpy as np

from anthroarm import crosscheck
from anthroarm.spatial.checks import rows


def test_provider_rows_pass():
    out = rows(["human_arm7", "prosthetic_arm"], 8, np.random.default_rng(1))
    assert {r.model for r in out} >= {"spatial", "relative_motion", "rccc", "human_arm7", "prosthetic_arm"}
    bad = [r for r in out if not r.ok]
    assert not bad, bad
    assert "anthroarm.spatial.checks:rows" in crosscheck.PROVIDERS
