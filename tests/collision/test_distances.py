"""Distances of anthroarm.collision against direct coal calls on the same shapes and poses."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm.collision import distance as D
from anthroarm.collision.capsules import capsule_pairs


@pytest.fixture(scope="module")
def limb():
    return aa.load("human_upper_limb")


@pytest.fixture(scope="module")
def panda():
    return aa.load("panda")


def obstacles():
    return [
        C.box((0.6, 1.0, 0.04), xyz=(0.55, 0.0, 0.1), name="table"),
        C.sphere(0.05, xyz=(0.3, 0.3, 0.4), name="ball"),
        C.capsule(0.03, 0.2, xyz=(0.2, -0.3, 0.3), name="bar"),
        C.cylinder(0.04, 0.15, xyz=(-0.3, 0.2, -0.3), name="can"),
    ]


def coal_pair(cm, env, data, a, b):
    g = cm.geometry.geometryObjects
    Ta = data.oMi[int(g[a].parentJoint)] * g[a].placement
    if b >= 0:
        gb, Tb = g[b].geometry, data.oMi[int(g[b].parentJoint)] * g[b].placement
    else:
        gb, Tb = env.obstacles[-1 - b].geometry, env.obstacles[-1 - b].pose
    res = coal.DistanceResult()
    return coal.distance(g[a].geometry, Ta, gb, Tb, coal.DistanceRequest(), res), res


@pytest.mark.parametrize("name", ["limb", "panda"])
@pytest.mark.parametrize("direct", [True, False])
def test_distances_equal_coal(name, direct, request, monkeypatch):
    robot = request.getfixturevalue(name)
    monkeypatch.setattr(D, "DIRECT_PAIRS", 10**9 if direct else -1)  # both code paths
    cm = C.model(robot)
    env = C.environment(obstacles())
    data = robot.model.createData()
    n = 0
    for q in robot.random_q(4, rng=1):
        res = C.distances(robot, q, env)
        pin.forwardKinematics(robot.model, data, q)
        assert len(res) == len(cm.pairs) + (cm.joint > 0).sum() * len(env)  # cutoff inf: all
        for k in range(len(res)):
            d, r = coal_pair(cm, env, data, int(res.body_a[k]), int(res.body_b[k]))
            # equal within coal's GJK convergence (1e-5 m; Pinocchio warm-starts GJK per pair;
            # capsule-capsule and sphere pairs agree to 1e-15, curved-flat pairs to ~1e-6)
            assert res.distance[k] == pytest.approx(d, abs=1e-5), (res.names[k], d)
            # witness points: |p_b - p_a| = d when apart, the normal a unit vector along it
            gap = res.point_b[k] - res.point_a[k]
            if d > 1e-6:
                assert np.linalg.norm(gap) == pytest.approx(res.distance[k], abs=1e-9)
                assert np.allclose(res.normal[k], gap / np.linalg.norm(gap), atol=1e-6)
            n += 1
        assert C.min_distance(robot, q, env) == pytest.approx(res.distance.min(), abs=1e-5)
        assert C.in_collision(robot, q, env) == bool(res.distance.min() <= 0)
    assert n > 100


def test_capsule_fast_path_equals_coal():
    rng = np.random.default_rng(0)
    K = 300
    A1, B1, A2, B2 = (rng.normal(size=(K, 3)) * 0.2 for _ in range(4))
    A2[:20] = A1[:20] + np.array([0.0, 0.0, 0.03])  # parallel axes 3 cm apart
    B2[:20] = B1[:20] + np.array([0.0, 0.0, 0.03])
    A2[20:25], B2[20:25] = A1[20:25], B1[20:25]  # the same axis: they meet
    r1, r2 = rng.uniform(0.005, 0.05, K), rng.uniform(0.005, 0.05, K)
    d, pa, pb, n, meet = capsule_pairs(A1, B1, r1, A2, B2, r2)
    for k in range(K):
        shapes = []
        for A, B, r in ((A1[k], B1[k], r1[k]), (A2[k], B2[k], r2[k])):
            L = np.linalg.norm(B - A)
            z = (B - A) / L
            x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
            x /= np.linalg.norm(x)
            shapes.append(
                (coal.Capsule(r, L), pin.SE3(np.column_stack([x, np.cross(z, x), z]), (A + B) / 2))
            )
        res = coal.DistanceResult()
        ref = coal.distance(
            shapes[0][0], shapes[0][1], shapes[1][0], shapes[1][1], coal.DistanceRequest(), res
        )
        if meet[k]:  # axes that meet: left to coal (no normal here); deep inside each other
            assert ref < -min(r1[k], r2[k])
            continue
        assert d[k] == pytest.approx(ref, abs=1e-7)
        if ref > 1e-6:
            assert np.allclose(pa[k], res.getNearestPoint1(), atol=1e-6)


@pytest.mark.parametrize("name", ["human_upper_limb", "prosthetic_hand"])
def test_jacobian_matches_finite_differences(name):
    """∂d/∂q against central differences of coal's distances; the prosthetic hand has mimic
    joints (the per-joint LOCAL_WORLD_ALIGNED path of :func:`jacobians`)."""
    limb = aa.load(name)
    cm = C.model(limb)
    q = limb.random_q(rng=4, margin=0.05)
    data = limb.model.createData()
    pin.computeJointJacobians(limb.model, data, q)
    pin.updateFramePlacements(limb.model, data)
    res = D.compute(limb, None, None, data=data)
    J = C.jacobians(limb.model, data, res, cm.support)
    keep = np.flatnonzero(res.distance > 0.003)[:15]
    keys = [res.names[k] for k in keep]
    eps = 1e-7
    fd = np.zeros((len(keep), limb.nv))
    for i in range(limb.nv):
        dq = np.zeros(limb.nv)
        dq[i] = eps
        plus = C.distances(limb, pin.integrate(limb.model, q, dq))
        minus = C.distances(limb, pin.integrate(limb.model, q, -dq))
        for m, key in enumerate(keys):
            fd[m, i] = plus.distance[plus.names.index(key)] - minus.distance[minus.names.index(key)]
    fd /= 2 * eps
    assert len(keep) >= 5
    assert np.allclose(J[keep], fd, atol=1e-6)


def test_batched_queries(limb):
    Q = limb.random_q(5, rng=3)
    md = C.min_distance(limb, Q)
    assert md.shape == (5,)
    assert np.allclose(md, [C.min_distance(limb, q) for q in Q])
    assert list(C.in_collision(limb, Q)) == [C.in_collision(limb, q) for q in Q]


def test_broad_phase_many_obstacles(panda):
    # 2000 small spheres far away and one near: the answer is the near one, by coal
    rng = np.random.default_rng(0)
    far = [C.sphere(0.01, xyz=5 + rng.uniform(0, 1, 3), name=f"s{i}") for i in range(2000)]
    near = C.sphere(0.05, xyz=(0.3, 0.0, 0.5), name="near")
    env = C.environment([*far, near])
    q = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    res = D.compute(panda, q, env, self_collision=False, best_only=True)
    ref = C.distances(panda, q, C.environment([near]))
    ref_env = ref.distance[[b < 0 for b in ref.body_b]]
    assert res.min == pytest.approx(ref_env.min(), abs=1e-9)
    assert res.closest[1] == "near"
