"""Minimum distances between a robot's bodies and to obstacles, with witness points and normals.

For every checked pair (the active self pairs of :func:`~anthroarm.collision.model.model` and
every moving body against every obstacle) coal's GJK/EPA (``coal.distance``) gives the signed
distance d (negative: penetration depth), the witness points p_a, p_b and the unit normal n
from body a to body b (moving b along n increases d).  A broad phase runs first: every body has
a bounding sphere (centre c, radius r, from coal's local AABB), and a pair whose lower bound
|c_a − c_b| − r_a − r_b is at or beyond the ``cutoff`` is not given to coal; :func:`min_distance`
visits the pairs in order of that bound and stops when the bound exceeds the best distance
found (branch and bound), so thousands of obstacles cost one vectorised bound each.

An :class:`Environment` holds at most :data:`MAX_OBSTACLES` obstacles (more raise
:class:`~anthroarm.errors.CollisionError`: merge them into a mesh).  Units: m.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from ..errors import CollisionError
from .capsules import capsule_pairs, joint_poses
from .model import CollisionModel, model, support_mask
from .shapes import Obstacle

#: the most obstacles one Environment holds
MAX_OBSTACLES = 100_000

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class Environment:
    """Obstacles fixed in the world (a list of :class:`~anthroarm.collision.shapes.Obstacle`)."""

    def __init__(self, obstacles=()):
        obs = list(obstacles) if not isinstance(obstacles, Obstacle) else [obstacles]
        if len(obs) > MAX_OBSTACLES:
            raise CollisionError(
                f"{len(obs)} obstacles: at most {MAX_OBSTACLES} (merge many small obstacles "
                "into one mesh, or keep only those near the robot)"
            )
        bad = [i for i, o in enumerate(obs) if not isinstance(o, Obstacle)]
        if bad:
            raise CollisionError(
                f"obstacles must be made by anthroarm.collision.sphere/box/capsule/cylinder/mesh; "
                f"entry {bad[0]} is {type(obs[bad[0]]).__name__}"
            )
        self.obstacles = obs
        self.centers = np.array([o.center for o in obs]).reshape(-1, 3)
        self.radii = np.array([o.radius for o in obs], dtype=float)

    def __len__(self) -> int:
        return len(self.obstacles)

    def __repr__(self) -> str:
        return f"Environment({len(self)} obstacles)"


def environment(obstacles) -> Environment:
    """``obstacles`` as an :class:`Environment` (``None`` → empty; an Environment as is)."""
    if obstacles is None:
        return Environment(())
    if isinstance(obstacles, Environment):
        return obstacles
    return Environment(obstacles)


@dataclass
class Distances:
    """Distances of the pairs a query kept (K pairs).

    Attributes
    ----------
    distance : (K,) signed distance, m (< 0: penetration depth)
    point_a, point_b : (K, 3) witness points in the world, m
    normal : (K, 3) unit vector from a to b
    body_a, body_b : (K,) body indices; ``body_b`` of an obstacle pair is ``-1 - obstacle index``
    joint_a, joint_b : (K,) parent joints (0: the world, an obstacle)
    names : list of (name_a, name_b)
    """

    distance: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    normal: np.ndarray
    body_a: np.ndarray
    body_b: np.ndarray
    joint_a: np.ndarray
    joint_b: np.ndarray
    names: list

    def __len__(self) -> int:
        return len(self.distance)

    @property
    def min(self) -> float:
        """The smallest distance (``inf`` when no pair was kept)."""
        return float(self.distance.min()) if len(self.distance) else float("inf")

    @property
    def closest(self) -> tuple | None:
        """(name_a, name_b, distance) of the closest pair, ``None`` when empty."""
        if not len(self.distance):
            return None
        k = int(np.argmin(self.distance))
        return (*self.names[k], float(self.distance[k]))

    def colliding(self) -> list:
        """(name_a, name_b) of the pairs in collision (d ≤ 0)."""
        return [n for n, d in zip(self.names, self.distance) if d <= 0.0]


class _Query:
    """The scratch of one thread's queries: coal request/result, placements."""

    def __init__(self):
        self.req = coal.DistanceRequest()
        self.res = coal.DistanceResult()


def _query(cm: CollisionModel) -> _Query:
    q = getattr(cm._local, "query", None)
    if q is None:
        q = cm._local.query = _Query()
    return q


def placements(cm: CollisionModel, data) -> list:
    """World placements (``pin.SE3``) of every body, from ``data.oMi``."""
    oMi = data.oMi
    return [oMi[int(j)] * g.placement for j, g in zip(cm.joint, cm.geometry.geometryObjects)]


def _pair(qy, ga, Ta, gb, Tb):
    res = qy.res
    res.clear()
    d = coal.distance(ga, Ta, gb, Tb, qy.req, res)
    pa = np.array(res.getNearestPoint1())
    pb = np.array(res.getNearestPoint2())
    diff = pb - pa
    L = float(np.sqrt(diff @ diff))
    if d > 1e-9 and L > 1e-12:
        n = diff / L
    else:
        n = np.array(res.normal)
        nn = float(np.sqrt(n @ n))
        n = n / nn if np.isfinite(nn) and nn > 1e-12 else np.zeros(3)
    return d, pa, pb, n


#: above this many pairs (self + body × obstacle) the numpy broad phase and per-pair coal
#: calls run instead of Pinocchio's ``computeDistances`` over every pair
DIRECT_PAIRS = 20_000


class Scene:
    """The robot's bodies and an environment's obstacles in one ``pin.GeometryModel`` whose
    collision pairs are the active self pairs and every moving body × every obstacle, so that
    Pinocchio's ``computeDistances`` (C++, coal) runs them all in one call."""

    def __init__(self, cm: CollisionModel, env: Environment):
        gm = cm.geometry.copy()
        gm.removeAllCollisionPairs()
        base = cm.n
        for o in env.obstacles:
            gm.addGeometryObject(pin.GeometryObject(o.name, 0, 0, o.pose, o.geometry))
        a = [int(i) for i in cm.pairs[:, 0]]
        b = [int(j) for j in cm.pairs[:, 1]]
        self.n_self = len(a)
        moving = np.flatnonzero(cm.joint > 0)
        for k in range(len(env)):
            a.extend(int(i) for i in moving)
            b.extend([-1 - k] * len(moving))
        for i, j in zip(a, b):
            gm.addCollisionPair(pin.CollisionPair(i, j if j >= 0 else base - 1 - j))
        self.geometry = gm
        self.a = np.array(a, dtype=int)
        self.b = np.array(b, dtype=int)
        self.pairs_version = cm.pairs
        self._local = threading.local()

    def data(self) -> pin.GeometryData:
        gd = getattr(self._local, "gd", None)
        if gd is None:
            gd = self._local.gd = pin.GeometryData(self.geometry)
        return gd


def scene(cm: CollisionModel, env: Environment) -> Scene:
    """The :class:`Scene` of ``cm`` with ``env`` (kept on ``cm`` for the last few
    environments; made again when the active pairs change)."""
    scenes = cm.__dict__.setdefault("_scenes", {})
    hit = scenes.get(id(env))
    if hit is not None and hit[0] is env and hit[1].pairs_version is cm.pairs:
        return hit[1]
    sc = Scene(cm, env)
    if len(scenes) >= 4:
        scenes.pop(next(iter(scenes)))
    scenes[id(env)] = (env, sc)
    return sc


def _direct(robot, cm, env, data, cutoff, self_collision, best_only):
    """Distances by Pinocchio's ``computeDistances`` over the :class:`Scene`'s pairs."""
    sc = scene(cm, env)
    gd = sc.data()
    pin.updateGeometryPlacements(robot.model, data, sc.geometry, gd)
    pin.computeDistances(sc.geometry, gd)
    results = gd.distanceResults
    d = np.fromiter((x.min_distance for x in results), float, len(sc.a))
    if not self_collision:
        d[: sc.n_self] = np.inf
    if best_only:
        sel = [int(np.argmin(d))] if len(d) and d.min() < cutoff else []
    else:
        sel = np.flatnonzero(d < cutoff).tolist()
    K = len(sel)
    pa, pb, nrm = np.empty((K, 3)), np.empty((K, 3)), np.empty((K, 3))
    for i, k in enumerate(sel):
        x = results[k]
        pa[i] = x.getNearestPoint1()
        pb[i] = x.getNearestPoint2()
        diff = pb[i] - pa[i]
        L = float(np.sqrt(diff @ diff))
        if d[k] > 1e-9 and L > 1e-12:
            nrm[i] = diff / L
        else:
            n = np.array(x.normal)
            nn = float(np.sqrt(n @ n))
            nrm[i] = n / nn if np.isfinite(nn) and nn > 1e-12 else 0.0
    sel = np.array(sel, dtype=int)
    A, B = sc.a[sel], sc.b[sel]
    names = [
        (cm.names[i], cm.names[j] if j >= 0 else env.obstacles[-1 - j].name) for i, j in zip(A, B)
    ]
    return Distances(
        d[sel],
        pa,
        pb,
        nrm,
        A,
        B,
        cm.joint[A],
        np.where(B >= 0, cm.joint[np.maximum(B, 0)], 0),
        names,
    )


def compute(
    robot,
    q=None,
    obstacles=None,
    cutoff: float = np.inf,
    data=None,
    self_collision: bool = True,
    best_only: bool = False,
    cm: CollisionModel | None = None,
) -> Distances:
    """Distances of the pairs whose broad-phase bound is below ``cutoff`` (m).

    ``data``: a ``pin.Data`` whose ``oMi`` already holds the placements at ``q`` (then ``q``
    may be ``None``).  ``best_only``: stop at the closest pair (branch and bound)."""
    cm = model(robot) if cm is None else cm
    env = environment(obstacles)
    if data is None:
        q = robot.check_q(q)
        data = robot.data
        pin.forwardKinematics(robot.model, data, q)
    if len(cm.pairs) + int((cm.joint > 0).sum()) * len(env) <= DIRECT_PAIRS:
        return _direct(robot, cm, env, data, cutoff, self_collision, best_only)
    ujoints = np.unique(cm.joint)
    Rj, tj = joint_poses(data, ujoints)
    slot = np.searchsorted(ujoints, cm.joint)
    R, t = Rj[slot], tj[slot]  # (G, 3, 3), (G, 3): every body's joint pose
    c = np.einsum("gij,gj->gi", R, cm.centers) + t
    r = cm.radii
    out_d, out_pa, out_pb, out_n, out_a, out_b = [], [], [], [], [], []
    best = np.inf
    items = []  # (bound, a, b): b >= 0 a body, b < 0 an obstacle
    if self_collision and len(cm.pairs):
        a, b = cm.pairs[:, 0], cm.pairs[:, 1]
        caps = cm.is_capsule[a] & cm.is_capsule[b]
        if caps.any():
            ca, cb = a[caps], b[caps]
            E = np.einsum("gij,gkj->gki", R, cm.cap_ends) + t[:, None, :]  # (G, 2, 3) world
            d, pa, pb, n, meet = capsule_pairs(
                E[ca, 0], E[ca, 1], cm.cap_radius[ca], E[cb, 0], E[cb, 1], cm.cap_radius[cb]
            )
            ok = ~meet & (d < cutoff)
            if best_only and ok.any():
                k = np.flatnonzero(ok)[np.argmin(d[ok])]
                ok = np.zeros_like(ok)
                ok[k] = True
            if ok.any():
                out_d.extend(d[ok])
                out_pa.extend(pa[ok])
                out_pb.extend(pb[ok])
                out_n.extend(n[ok])
                out_a.extend(ca[ok])
                out_b.extend(cb[ok])
                best = float(np.min(d[ok]))
            caps[np.flatnonzero(caps)[meet]] = False  # axes that meet: coal decides
        a, b = a[~caps], b[~caps]
        lb = np.linalg.norm(c[a] - c[b], axis=1) - r[a] - r[b]
        keep = lb < cutoff
        items.append((lb[keep], a[keep], b[keep]))
    if len(env):
        moving = np.flatnonzero(cm.joint > 0)
        diff = c[moving][:, None, :] - env.centers[None, :, :]
        lb = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff)) - r[moving][:, None] - env.radii[None, :]
        ii, oo = np.nonzero(lb < cutoff)
        items.append((lb[ii, oo], moving[ii], -1 - oo))
    if items:
        lb = np.concatenate([x[0] for x in items])
        A = np.concatenate([x[1] for x in items]).astype(int)
        B = np.concatenate([x[2] for x in items]).astype(int)
    else:
        lb, A, B = np.zeros(0), np.zeros(0, int), np.zeros(0, int)
    order = np.argsort(lb, kind="stable") if best_only else np.arange(len(lb))
    qy = _query(cm)
    geoms = cm.geometry.geometryObjects
    oMi = data.oMi
    place = {}

    def pose(i):
        T = place.get(i)
        if T is None:
            T = place[i] = oMi[int(cm.joint[i])] * geoms[i].placement
        return T

    for k in order:
        if best_only and lb[k] >= best:
            break
        a, b = int(A[k]), int(B[k])
        if b >= 0:
            d, pa, pb, n = _pair(qy, geoms[a].geometry, pose(a), geoms[b].geometry, pose(b))
        else:
            o = env.obstacles[-1 - b]
            d, pa, pb, n = _pair(qy, geoms[a].geometry, pose(a), o.geometry, o.pose)
        if d >= cutoff:
            continue
        if d < best:
            best = d
        out_d.append(d)
        out_pa.append(pa)
        out_pb.append(pb)
        out_n.append(n)
        out_a.append(a)
        out_b.append(b)
    Bj = np.array(out_b, dtype=int)
    names = [
        (cm.names[a], cm.names[b] if b >= 0 else env.obstacles[-1 - b].name)
        for a, b in zip(out_a, out_b)
    ]
    return Distances(
        np.array(out_d, dtype=float),
        np.array(out_pa).reshape(-1, 3),
        np.array(out_pb).reshape(-1, 3),
        np.array(out_n).reshape(-1, 3),
        np.array(out_a, dtype=int),
        Bj,
        cm.joint[np.array(out_a, dtype=int)] if out_a else np.zeros(0, int),
        np.where(Bj >= 0, cm.joint[np.maximum(Bj, 0)], 0) if out_b else np.zeros(0, int),
        names,
    )


def distances(robot, q, obstacles=None, cutoff: float = np.inf) -> Distances:
    """Every checked pair closer than ``cutoff`` (m; all pairs by default) at configuration
    ``q`` (nq,): signed distances, witness points and normals (coal GJK/EPA; see the module
    docstring)."""
    return compute(robot, q, obstacles, cutoff=float(cutoff))


def _batched(robot, q, fn):
    q = np.asarray(q, dtype=float)
    if q.ndim == 2:
        return np.array([fn(robot, qi) for qi in q])
    return fn(robot, q)


def min_distance(robot, q, obstacles=None):
    """The smallest signed distance (m) between the robot's checked pairs and to the
    obstacles at ``q`` (nq,) or for each row of ``q`` (N, nq); ``inf`` when nothing is checked."""
    env = environment(obstacles)
    return _batched(robot, q, lambda r, qi: compute(r, qi, env, best_only=True).min)


def in_collision(robot, q, obstacles=None, margin: float = 0.0):
    """True where a checked pair is closer than ``margin`` (m; 0: touching or penetrating) at
    ``q`` (nq,) or each row of ``q`` (N, nq)."""
    env = environment(obstacles)
    m = float(margin)

    def one(r, qi):
        return bool(compute(r, qi, env, cutoff=max(m, 0.0) + 1e-12, best_only=True).min <= m)

    return _batched(robot, q, one)


def _cross(a, b):
    return np.stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ],
        axis=1,
    )


def jacobians(robot_model, data, dist: Distances, mask=None) -> np.ndarray:
    """∂d/∂q (K, nv) of every pair of ``dist``: ḋ = n · (ṗ_b − ṗ_a) (Faverjon & Tournassoud
    1987), with the velocity of a witness point p of joint j's body
    ṗ = J_v q̇ + ω × p from the WORLD joint Jacobian ``data.J`` of ``pin.computeJointJacobians``
    restricted to j's supporting joints (``mask``:
    :func:`~anthroarm.collision.model.support_mask`).  So n · ṗ = (n · J_v + (p × n) · J_ω) q̇ over those columns.  An
    obstacle's Jacobian is zero.  Models with mimic joints use ``pin.getJointJacobian`` per
    joint (LOCAL_WORLD_ALIGNED, J_v − [p − o]× J_ω), which handles their coupling."""
    K = len(dist)
    if not K:
        return np.zeros((0, robot_model.nv))
    n = dist.normal
    if not _has_mimic(robot_model):
        S = support_mask(robot_model) if mask is None else mask
        J0 = data.J
        nJv = n @ J0[:3]
        rows = S[dist.joint_b] * (nJv + _cross(dist.point_b, n) @ J0[3:])
        rows -= S[dist.joint_a] * (nJv + _cross(dist.point_a, n) @ J0[3:])
        return rows
    out = np.zeros((K, robot_model.nv))
    cache = {}
    for joints, points, sign in (
        (dist.joint_a, dist.point_a, -1.0),
        (dist.joint_b, dist.point_b, 1.0),
    ):
        joints = np.asarray(joints, dtype=int)
        moving = joints != 0  # a point of the universe (an obstacle) does not move
        if not moving.any():
            continue
        for j in np.unique(joints[moving]):
            if j not in cache:
                cache[j] = (
                    pin.getJointJacobian(robot_model, data, int(j), LWA),
                    data.oMi[int(j)].translation,
                )
        J = np.stack([cache[j][0] for j in joints[moving]])  # (k, 6, nv)
        r = points[moving] - np.stack([cache[j][1] for j in joints[moving]])
        nm = n[moving]
        out[moving] += sign * (
            np.einsum("ki,kiv->kv", nm, J[:, :3]) + np.einsum("ki,kiv->kv", _cross(r, nm), J[:, 3:])
        )
    return out


def _has_mimic(robot_model) -> bool:
    return len(getattr(robot_model, "mimicking_joints", ())) > 0


__all__ = [
    "Environment",
    "environment",
    "Distances",
    "compute",
    "distances",
    "min_distance",
    "in_collision",
    "jacobians",
    "placements",
    "MAX_OBSTACLES",
    "DIRECT_PAIRS",
    "Scene",
    "scene",
]
