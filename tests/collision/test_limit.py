"""The collision limits in the QP: never violated along random trajectories, pushes apart from
a start in collision, refuses bad parameters."""

from __future__ import annotations

import numpy as np
import pytest

import anthroarm as aa
from anthroarm import collision as C
from anthroarm.collision.checks import start_and_targets
from anthroarm.errors import CollisionError
from anthroarm.ik import qp
from anthroarm.ik.qp.limits import CollisionBarrier, CollisionLimit
from anthroarm.ik.qp.limits.collision_step import step

DT = 0.01


@pytest.fixture(scope="module")
def panda():
    return aa.load("panda")


def obstacles():
    return [
        C.box((0.6, 1.0, 0.04), xyz=(0.55, 0.0, 0.1), name="table"),
        C.box((0.1, 0.1, 0.1), xyz=(0.45, 0.2, 0.35), name="box"),
    ]


READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


def follow(robot, q0, targets, limits, steps, d_check, env=None):
    conf = qp.IKConfiguration(robot, q0)
    ee = qp.FrameTask(robot, position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)
    post = qp.PostureTask(robot, cost=1e-3, target=q0)
    worst, statuses = np.inf, set()
    for T in targets:
        conf.update(q0)
        ee.set_target(T)
        for _ in range(steps):
            res = step(conf, None, [ee, post], DT, limits=limits, full=True)
            statuses.add(res.status)
            conf.integrate_inplace(res.v, DT)
            worst = min(worst, float(C.min_distance(robot, conf.q, env)))
    return worst, statuses, conf


@pytest.mark.parametrize("kind", ["damper", "barrier"])
def test_never_violated_panda_with_obstacles(panda, kind):
    env = C.environment(obstacles())
    d_min = 0.02
    _, targets = start_and_targets(panda, 4, rng=5, d_clear=d_min + 0.001, obstacles=env)
    lim = (
        CollisionLimit(panda, env, d_safe=d_min, d_detect=0.05)
        if kind == "damper"
        else CollisionBarrier(panda, env, d_min=d_min, gain=20.0)
    )
    assert C.min_distance(panda, READY, env) > d_min
    worst, statuses, _ = follow(
        panda, READY, targets, [*qp.default_limits(panda), lim], 60, d_min, env
    )
    assert worst >= d_min - 1e-4
    assert statuses <= {"optimal"}


def test_never_violated_limb_self_collision():
    limb = aa.load("human_upper_limb")
    lim = CollisionLimit(limb, d_safe=0.002, d_detect=0.03)
    q0, targets = start_and_targets(limb, 3, rng=2, d_clear=0.003)
    worst, _, _ = follow(limb, q0, targets, [*qp.default_limits(limb), lim], 50, 0.002)
    assert worst >= 0.002 - 1e-4


def test_without_the_limit_the_same_targets_collide(panda):
    """The test above can fail: the same motion without the limit goes below d_min."""
    env = C.environment(obstacles())
    _, targets = start_and_targets(panda, 4, rng=5, d_clear=0.021, obstacles=env)
    worst, _, _ = follow(panda, READY, targets, qp.default_limits(panda), 60, 0.02, env)
    assert worst < 0.02 - 1e-4


def test_start_in_collision_pushes_apart(panda):
    # a ball 1.4 cm into link 6: the step must separate, not freeze
    T = panda.fk(READY)
    ball = C.sphere(0.04, xyz=T[:3, 3] + np.array([-0.1, -0.08, 0.08]), name="ball")
    env = C.environment([ball])
    d0 = C.min_distance(panda, READY, env)
    assert d0 < 0
    lim = CollisionLimit(panda, env, d_safe=0.01, d_detect=0.05)
    conf = qp.IKConfiguration(panda, READY)
    post = qp.PostureTask(panda, cost=1e-3, target=READY)
    res = step(conf, None, [post], DT, limits=[*qp.default_limits(panda), lim], full=True)
    assert res.status == "start_in_collision" and res.min_distance == pytest.approx(d0, abs=1e-6)
    for _ in range(100):
        res = step(conf, None, [post], DT, limits=[*qp.default_limits(panda), lim], full=True)
        conf.integrate_inplace(res.v, DT)
    assert C.min_distance(panda, conf.q, env) > 0.01 - 1e-4  # out, and at d_s


def test_bad_parameters(panda):
    with pytest.raises(CollisionError, match="below the detection distance"):
        CollisionLimit(panda, d_safe=0.05, d_detect=0.05)
    with pytest.raises(CollisionError, match="safety distance"):
        CollisionLimit(panda, d_safe=float("nan"))
    with pytest.raises(CollisionError, match="xi"):
        CollisionLimit(panda, xi=0.0)
    with pytest.raises(CollisionError, match="gain"):
        CollisionBarrier(panda, gain=-1)
    lim = CollisionLimit(panda)
    with pytest.raises(CollisionError, match="not a box"):
        qp.step(panda, READY, [qp.PostureTask(panda, cost=1.0, target=READY)], DT, limits=[lim])
