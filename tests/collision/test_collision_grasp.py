"""Collision-free grasps: the object is a collision body, the report is coal's."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm import hand as H
from anthroarm.errors import GraspError
from anthroarm.hand.problems import open_hand


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


def test_collision_free_grasp_reports_and_never_penetrates(limb):
    hand = H.Hand(limb)
    q0 = open_hand(limb, hand)
    # a cylinder across the palm, in front of it (palm axes from the model's FK), clear of it
    M = limb.fk(q0, frame="palm")
    obj = H.Cylinder(M[:3, 3] + 0.06 * M[:3, 1], M[:3, 0], 0.02, length=0.12)
    env = C.environment([obj.obstacle()])
    assert C.min_distance(limb, q0, env) > 0.0
    r = H.solve_grasp(
        limb, obj, hand=hand, q0=q0, collision_free=True, restarts=0, max_iterations=60
    )
    assert r.status in {"success", "no_collision_free_grasp", "stalled", "max_iterations"}
    d = C.distances(limb, r.q, env)
    on_obj = np.array([b < 0 for b in d.body_b])
    # the report is the distance to the object by coal, and nothing went into it
    assert r.info["penetration"] == pytest.approx(max(0.0, -d.distance[on_obj].min()), abs=1e-5)
    assert r.info["penetration"] <= 1e-4
    assert len(r.info["tip_gaps"]) == len(hand.fingers)
    assert r.success == (r.status == "success") and (not r.success or r.info["collision_free"])


def test_collision_free_refuses_couplings(limb):
    obj = H.Sphere((0.0, 0.1, -0.6), 0.03)
    with pytest.raises(GraspError, match="collision_free"):
        H.solve_grasp(limb, obj, collision_free=True, step_fn=lambda *a: None)
    with pytest.raises(GraspError, match="contact_margin"):
        H.solve_grasp(limb, obj, collision_free=True, contact_margin=0.0)


def test_object_obstacles_match_the_objects():
    s = H.Sphere((0.1, 0.2, 0.3), 0.04)
    c = H.Cylinder((0.0, 0.0, 0.5), (0.0, 1.0, 0.0), 0.03, length=0.2)
    p = np.array([0.3, 0.05, 0.6])  # beside both (within the cylinder's length)
    probe = C.sphere(1e-9, xyz=p)
    for obj in (s, c):
        env = C.environment([obj.obstacle()])
        # distance of a point to the coal body = the object's own distance function
        o = env.obstacles[0]
        res = coal.DistanceResult()
        d = coal.distance(
            o.geometry, o.pose, probe.geometry, pin.SE3(np.eye(3), p), coal.DistanceRequest(), res
        )
        assert d == pytest.approx(obj.distance(p), abs=1e-6)
