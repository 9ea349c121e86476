"""``anthroarm check``'s collision rows on the catalog robots that used to leave them
'unsupported' (and so failed the README's main command): a bare Cartesian gantry has nothing to
check, and the linkage hand — whose bodies touch at its default configuration — gets its pairs
filtered as MoveIt's setup assistant does ("default": in collision at the default
configuration; "always": in collision in >= 95 % of samples) and a damper row that passes."""

import coal
import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.collision import checks
from anthroarm.collision.model import model
from anthroarm.errors import NoCollisionBodiesError


def test_a_robot_without_collision_bodies_gets_no_rows():
    gantry = aa.load("cartesian_robot")
    with pytest.raises(NoCollisionBodiesError):
        model(gantry)
    assert checks.rows(gantry, 4, np.random.default_rng(0)) == []


@pytest.fixture(scope="module")
def hand():
    return aa.load("prosthetic_hand")


def test_pairs_in_collision_at_the_default_configuration_are_not_checked(hand):
    cm = model(hand)
    assert "default" in set(cm.disabled.values())
    q0 = np.clip(hand.neutral(), hand.chain.lower, hand.chain.upper)
    # coal directly on the active pairs, bodies placed by Pinocchio: none touches at q0
    gm = cm.geometry
    gd = pin.GeometryData(gm)
    pin.updateGeometryPlacements(hand.model, hand.model.createData(), gm, gd, q0)
    for i, j in cm.pairs:
        a, b = gm.geometryObjects[int(i)], gm.geometryObjects[int(j)]
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        d = coal.distance(
            a.geometry,
            coal.Transform3s(gd.oMg[int(i)].rotation, gd.oMg[int(i)].translation),
            b.geometry,
            coal.Transform3s(gd.oMg[int(j)].rotation, gd.oMg[int(j)].translation),
            req,
            res,
        )
        assert d > 0.0, (a.name, b.name, d)


def test_the_damper_row_runs_on_the_linkage_hand(hand):
    row = checks.damper_row(hand, 3, np.random.default_rng(0))
    assert row.ok and row.samples > 0 and row.max_abs_err == 0.0, row.note
