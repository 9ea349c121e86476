"""Cross-check rows of the collision layer (``anthroarm check``), on any robot.

* **distances = coal**: at random configurations, every checked pair's signed distance from
  :func:`anthroarm.collision.distances` against a direct ``coal.distance`` call on the same
  shapes at the same placements (the placements from Pinocchio's ``updateGeometryPlacements``;
  tolerance 1e-5 m: GJK on flat-sided shapes is warm-started per pair by Pinocchio);
  the row reports the largest difference (m).
* **damper never violated**: random reachable targets followed by QP steps with the
  :class:`~anthroarm.ik.qp.limits.collision.CollisionLimit` from a collision-free start; the
  row reports how far the closest active pair went below d_s − 1e-4 m (0 when never).
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from ..check_rows import CheckRow
from ..errors import CollisionError, NoCollisionBodiesError
from ..ik.qp import FrameTask, IKConfiguration, PostureTask, default_limits
from ..ik.qp.limits.collision import CollisionLimit
from ..ik.qp.limits.collision_step import step
from .distance import distances, min_distance
from .model import model


def coal_distance(cm, data, gd, a: int, b: int) -> float:
    """Signed distance of bodies ``a``, ``b`` of ``cm`` by one direct ``coal.distance`` call
    (placements from ``pin.updateGeometryPlacements`` into ``gd``)."""
    g = cm.geometry.geometryObjects
    res = coal.DistanceResult()
    return float(
        coal.distance(
            g[a].geometry, gd.oMg[a], g[b].geometry, gd.oMg[b], coal.DistanceRequest(), res
        )
    )


def distance_row(robot, samples: int, rng) -> CheckRow:
    cm = model(robot)
    gd = pin.GeometryData(cm.geometry)
    data = robot.model.createData()
    worst, n = 0.0, 0
    for q in robot.random_q(samples, rng=rng):
        D = distances(robot, q)
        pin.updateGeometryPlacements(robot.model, data, cm.geometry, gd, q)
        for k in range(len(D)):
            d = coal_distance(cm, data, gd, int(D.body_a[k]), int(D.body_b[k]))
            worst = max(worst, abs(d - float(D.distance[k])))
            n += 1
    return CheckRow(
        robot.name, "collision distances = coal.distance", worst, 1e-5, n, oracle="coal",
        note=f"{len(cm.pairs)} active pairs ({cm.source}), m",
    )  # fmt: skip


def start_and_targets(robot, n: int, rng, d_clear: float, obstacles=None, tries: int = 200):
    """A collision-free start (the neutral configuration if it is, else a random one) and up
    to ``n`` tool poses of random configurations whose bodies are at least ``d_clear`` apart."""
    chain = robot.chain
    q0 = np.clip(
        robot.neutral(), np.where(np.isfinite(chain.lower), chain.lower, -1e9), chain.upper
    )
    rng = np.random.default_rng(rng)
    if min_distance(robot, q0, obstacles) <= d_clear:
        for q in robot.random_q(tries, rng=rng, margin=0.05):
            if min_distance(robot, q, obstacles) > d_clear:
                q0 = q
                break
        else:
            return None, []
    targets = []
    for q in robot.random_q(tries, rng=rng, margin=0.05):
        if len(targets) >= n:
            break
        if min_distance(robot, q, obstacles) > d_clear:
            targets.append(robot.fk(q))
    return q0, targets


#: the damper row's safety distances, tried in order: 2 mm, then 0.5 mm for a robot whose bodies
#: are never 3 mm apart (a hand's fingers side by side)
D_SAFE = (0.002, 0.0005)


def damper_row(robot, samples: int, rng, steps: int = 60, dt: float = 0.01) -> CheckRow:
    quantity = "collision damper: d >= d_s - 1e-4 along QP steps"
    rng = np.random.default_rng(rng)
    for d_safe in D_SAFE:
        lim = CollisionLimit(robot, d_safe=d_safe, d_detect=0.03)
        q0, targets = start_and_targets(robot, max(2, min(int(samples), 5)), rng, d_safe + 0.001)
        if q0 is not None:
            break
    if q0 is None or not len(model(robot).pairs):
        return CheckRow.unsupported(
            robot.name, quantity, "no collision-free start or no active pair"
        )
    conf = IKConfiguration(robot, q0)
    ee = FrameTask(robot, position_cost=1.0, orientation_cost=0.5, lm_damping=1e-3)
    post = PostureTask(robot, cost=1e-3, target=q0)
    limits = [*default_limits(robot), lim]
    worst, n = 0.0, 0
    for T in targets:
        ee.set_target(T)
        conf.update(q0)
        for _ in range(steps):
            v = step(conf, None, [ee, post], dt, limits=limits)
            conf.integrate_inplace(v, dt)
            worst = max(worst, lim.d_safe - 1e-4 - float(min_distance(robot, conf.q)))
            n += 1
    return CheckRow(
        robot.name, quantity, max(worst, 0.0), 0.0, n, oracle="coal",
        note=f"d_s = {lim.d_safe} m, d_i = {lim.d_detect} m, {len(targets)} targets",
    )  # fmt: skip


def rows(robot, samples, rng) -> list[CheckRow]:
    """Both rows on ``robot`` (none when it has no collision bodies or no pair of its bodies can
    collide; an unsupported row when its collision model cannot be built)."""
    try:
        model(robot)
    except NoCollisionBodiesError:  # nothing to check (a bare Cartesian gantry): no row, as
        return []  # a row that cannot fail would pass for a check
    except CollisionError as exc:
        return [CheckRow.unsupported(robot.name, "collision distances = coal.distance", str(exc))]
    if not len(model(robot).pairs):  # no pair of bodies can touch (a planar 2R arm): nothing
        return []  # to check, and a row that cannot fail would pass for a check
    n = max(2, min(int(samples), 10))
    return [distance_row(robot, n, rng), damper_row(robot, n, rng)]


__all__ = ["rows", "distance_row", "damper_row", "start_and_targets", "coal_distance"]
