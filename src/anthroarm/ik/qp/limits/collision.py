"""CollisionLimit: the velocity damper of Faverjon & Tournassoud (1987) on every pair of bodies
closer than the detection distance d_i, self and environment::

    ḋ ≥ −ξ (d − d_s) / (d_i − d_s)        for every pair with d < d_i

with d the signed distance of the pair (m; negative inside), d_s the safety distance, ξ the
approach speed allowed at d_i (m/s) and ḋ = n · (J_b(p_b) − J_a(p_a)) q̇ from the witness points
p_a, p_b and the unit normal n from a to b (:func:`anthroarm.collision.jacobians`; an obstacle's
Jacobian is zero).  On the step Δq = q̇ dt this is the row

    −(∂d/∂q) Δq ≤ ξ dt (d − d_s) / (d_i − d_s)

an inequality, not a box: the QP of :func:`anthroarm.ik.qp.limits.collision_step.step` takes
it (``qp.step`` takes boxes only and refuses this limit).  A pair that starts closer than d_s
(or in collision) gets a positive lower bound on ḋ, at most ξ: the step pushes it apart
instead of freezing; ``status`` says so.  Distances come from coal (:mod:`anthroarm.collision`); the
damper is mink's ``CollisionAvoidanceLimit`` in velocity form (mink: d_s = 0.005 m,
d_i = 0.01 m) and the book's obstacle constraint g(Q) ≥ 0 (Ch. 7 §7-6) linearised per step.

Bad input: d_s ≥ d_i, a negative or non-finite distance or ξ ≤ 0 raise
:class:`~anthroarm.errors.CollisionError`.
"""

from __future__ import annotations

import math

import numpy as np

from ....collision import distance as coll
from ....collision.model import model as collision_model
from ....errors import CollisionError
from .base import Limit


def check_distances(d_safe, d_detect) -> tuple[float, float]:
    """(d_s, d_i) as floats with 0 ≤ d_s < d_i < inf; :class:`CollisionError` otherwise."""
    try:
        ds, di = float(d_safe), float(d_detect)
    except (TypeError, ValueError):
        raise CollisionError(
            f"distances must be numbers (m), got {d_safe!r}, {d_detect!r}"
        ) from None
    if not (math.isfinite(ds) and math.isfinite(di)) or ds < 0.0:
        raise CollisionError(f"safety distance must be a finite number >= 0 (m), got {d_safe!r}")
    if not ds < di:
        raise CollisionError(
            f"safety distance d_s = {ds} m must be below the detection distance d_i = {di} m"
        )
    return ds, di


class CollisionLimit(Limit):
    """Velocity-damper collision avoidance (see the module docstring).

    Parameters
    ----------
    robot : Robot
    obstacles : sequence of :class:`~anthroarm.collision.Obstacle` or an Environment, optional
    d_safe : float
        Safety distance d_s (m), the distance no pair goes below.
    d_detect : float
        Detection distance d_i (m): pairs farther away are not constrained.
    xi : float
        Approach speed ξ allowed at d_i (m/s).
    self_collision : bool
        Constrain the robot's own active pairs (:func:`anthroarm.collision.model`).
    margin : float
        The damper aims at d_s + margin (m): one witness point per pair linearises d, and
        when the closest features switch between steps (a flat face of a hull turning
        towards a table, a vertex taking over) the distance can dip below the linear
        prediction; 1 mm keeps such dips above d_s in the tests and benchmarks.
    contact_bodies : sequence of int
        Bodies (indices into :func:`anthroarm.collision.model`'s bodies) that may touch the
        obstacles: their rows against an obstacle aim at d_s itself (no ``margin``).  A
        grasp's fingertip capsules: they must reach the object, every other body keeps the
        margin (:mod:`anthroarm.hand.collision_grasp`).
    """

    priority = 3

    def __init__(
        self,
        robot,
        obstacles=None,
        d_safe: float = 0.005,
        d_detect: float = 0.05,
        xi: float = 0.5,
        self_collision: bool = True,
        margin: float = 0.001,
        contact_bodies=(),
    ):
        self.d_safe, self.d_detect = check_distances(d_safe, d_detect)
        margin = float(margin)
        if not (math.isfinite(margin) and 0.0 <= margin < self.d_detect - self.d_safe):
            raise CollisionError(
                f"margin must be >= 0 and below d_i - d_s = {self.d_detect - self.d_safe} m, got {margin}"
            )
        self.margin = margin
        xi = float(xi)
        if not (math.isfinite(xi) and xi > 0):
            raise CollisionError(f"xi (approach speed, m/s) must be a finite number > 0, got {xi}")
        self.xi = xi
        self.robot = robot
        self.model = collision_model(robot)
        self.env = coll.environment(obstacles)
        self.self_collision = bool(self_collision)
        cb = np.asarray(list(contact_bodies), dtype=int).reshape(-1)
        if len(cb) and (cb.min() < 0 or cb.max() >= self.model.n):
            raise CollisionError(
                f"contact_bodies must be body indices in 0..{self.model.n - 1}, got {cb.tolist()}"
            )
        self.contact = np.zeros(self.model.n, dtype=bool)
        self.contact[cb] = True
        self.last = None  # the Distances of the last step

    def box(self, conf, dt):
        raise CollisionError(
            "CollisionLimit is an inequality on Δq, not a box: pass it in the limits of "
            "anthroarm.ik.qp.limits.collision_step.step (qp.step takes boxes only)"
        )

    def distances(self, conf):
        """The pairs closer than d_i at ``conf`` (its ``data`` holds the kinematics)."""
        return coll.compute(
            self.robot,
            None,
            self.env,
            cutoff=self.d_detect,
            data=conf.data,
            self_collision=self.self_collision,
            cm=self.model,
        )

    def min_distance_at(self, q) -> float:
        """The smallest distance (m) of the pairs this limit constrains at configuration ``q``
        (coal; ``inf`` when none)."""
        return coll.compute(
            self.robot, q, self.env, cutoff=self.d_detect, self_collision=self.self_collision,
            best_only=True, cm=self.model,
        ).min  # fmt: skip

    def inequalities(self, conf, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(G, h) with G Δq ≤ h, one row per pair closer than d_i."""
        dist = self.last = self.distances(conf)
        if not len(dist):
            return np.zeros((0, conf.nv)), np.zeros(0)
        J = coll.jacobians(self.robot.model, conf.data, dist, self.model.support)
        ds = self.d_safe + self.margin
        if self.contact.any():  # contact bodies against obstacles: no margin
            ds = np.where(self.contact[dist.body_a] & (dist.body_b < 0), self.d_safe, ds)
        h = self.xi * dt * (dist.distance - ds) / (self.d_detect - ds)
        # a pair inside d_s separates at most at ξ (deep penetrations ask no more than that)
        return -J, np.maximum(h, -self.xi * dt)

    def __repr__(self) -> str:
        return (
            f"CollisionLimit(d_safe={self.d_safe}, d_detect={self.d_detect}, xi={self.xi}, "
            f"obstacles={len(self.env)}, self_collision={self.self_collision})"
        )


__all__ = ["CollisionLimit", "check_distances"]
