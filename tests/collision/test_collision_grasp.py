"""Collision-free grasps: the object is a collision body; the oracle is coal itself (direct
``coal.distance`` calls on the bodies placed by Pinocchio's forward kinematics)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm import hand as H
from anthroarm.errors import GraspError
from anthroarm.hand.collision_grasp import CONTACT_MARGIN, PENETRATION_TOL, CollisionGrasp
from anthroarm.hand.problems import collision_free_grasps, open_hand
from anthroarm.ik.qp.limits import CollisionLimit
from anthroarm.ik.qp.tasks.posture import comfortable_posture

PINCH = ("index_tip", "thumb_tip")


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


@pytest.fixture(scope="module")
def pinch(limb):
    return H.Hand(limb, tips=PINCH)


def coal_distances(robot, q, obj):
    """(body name -> distance to the object, [self-pair distances]) by direct coal calls."""
    cm = C.model(robot)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    gobj = cm.geometry.geometryObjects
    M = [data.oMi[int(g.parentJoint)] * g.placement for g in gobj]
    o = obj.obstacle()
    to_obj = {}
    for g, Mg in zip(gobj, M):
        if g.parentJoint == 0:
            continue
        to_obj[g.name] = coal.distance(
            g.geometry, Mg, o.geometry, o.pose, coal.DistanceRequest(), coal.DistanceResult()
        )
    self_d = [
        coal.distance(
            gobj[a].geometry,
            M[a],
            gobj[b].geometry,
            M[b],
            coal.DistanceRequest(),
            coal.DistanceResult(),
        )  # fmt: skip
        for a, b in cm.pairs.tolist()
    ]
    return to_obj, np.array(self_d)


@pytest.mark.parametrize("kind,seed", [("sphere", 3), ("cylinder", 9), ("cylinder", 10)])
def test_collision_free_grasp_touches_within_margin_and_never_penetrates(limb, pinch, kind, seed):
    (pb,) = collision_free_grasps(limb, 1, kind=kind, rng=seed, hand=pinch, max_draws=200)
    q0 = open_hand(limb, pinch, comfortable_posture(limb))
    r = H.solve_grasp(limb, pb.obj, pb.contacts, hand=pinch, q0=q0, collision_free=True)
    assert r.success and r.status == "success", r.info
    to_obj, self_d = coal_distances(limb, r.q, pb.obj)
    # nothing into the object, no finger into a finger or the palm (coal, every active pair)
    assert min(to_obj.values()) >= -PENETRATION_TOL
    assert self_d.min() >= -PENETRATION_TOL
    # each fingertip capsule (the distal phalanx) touches the object within the margin
    for tip in ("index_distal_0", "thumb_distal_0"):
        assert -PENETRATION_TOL <= to_obj[tip] <= CONTACT_MARGIN
    assert r.info["penetration"] == pytest.approx(max(0.0, -min(to_obj.values())), abs=1e-6)
    assert limb.within_limits(r.q)
    # the same problem without collisions puts the fingertip *frames* on the surface: their
    # capsules go into the object by about their radius
    r0 = H.solve_grasp(limb, pb.obj, pb.contacts, hand=pinch, q0=q0)
    assert r0.success
    assert min(coal_distances(limb, r0.q, pb.obj)[0].values()) < -0.005


def test_unreachable_object_is_a_status(limb, pinch):
    far = H.Sphere((2.0, 0.0, 0.0), 0.02)  # 2 m from the shoulder: out of the arm's reach
    r = H.solve_grasp(limb, far, hand=pinch, collision_free=True, restarts=0, max_iterations=30)
    assert not r.success
    assert r.status == "no_collision_free_grasp"
    assert "without collisions" in r.info["reason"]
    assert np.isfinite(r.q).all()


def test_object_too_big_is_a_status_or_an_error(limb, pinch):
    cg = CollisionGrasp(limb, pinch, H.Sphere((0.3, 0.0, 0.0), 0.01))
    grow = float(cg.radii.max()) + cg.gap
    # fits the span, but not once grown by the fingertip capsules: no collision-free grasp
    r_obj = 0.5 * pinch.span - 0.5 * grow
    r = H.solve_grasp(limb, H.Sphere((0.3, 0.0, 0.0), r_obj), hand=pinch, collision_free=True)
    assert r.status == "no_collision_free_grasp" and not r.success
    assert "span" in r.info["reason"]
    with pytest.raises(GraspError, match="span"):  # larger than the span: bad input
        H.solve_grasp(limb, H.Sphere((0.3, 0.0, 0.0), pinch.span), hand=pinch, collision_free=True)


def test_contact_bodies_aim_at_the_safety_distance(limb, pinch):
    """The damper row of a contact body against the object is ξ dt (d − d_s)/(d_i − d_s)
    (Faverjon & Tournassoud 1987) without the margin; other bodies keep d_s + margin."""
    q0 = open_hand(limb, pinch, comfortable_posture(limb))
    M = limb.fk(q0, frame="palm")
    obj = H.Sphere(M[:3, 3] + 0.05 * M[:3, 1], 0.02)
    cg = CollisionGrasp(limb, pinch, obj)
    lim = cg.limit
    conf = aa.ik.qp.IKConfiguration(limb, q0)
    G, h = lim.inequalities(conf, 1.0)
    d = lim.last
    for k in range(len(d)):
        contact = d.body_b[k] < 0 and d.body_a[k] in cg.tip_bodies
        ds = lim.d_safe + (0.0 if contact else lim.margin)
        expect = max(lim.xi * (d.distance[k] - ds) / (lim.d_detect - ds), -lim.xi)
        assert h[k] == pytest.approx(expect, abs=1e-12)
    with pytest.raises(aa.errors.CollisionError, match="contact_bodies"):
        CollisionLimit(limb, [obj.obstacle()], contact_bodies=[10_000])


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
