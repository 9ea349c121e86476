"""CollisionBarrier: a control-barrier form of collision avoidance, as pink's
``SelfCollisionBarrier`` writes it, for comparison with the velocity damper
(:class:`~anthroarm.ik.qp.limits.collision.CollisionLimit`)::

    h(q) = d(q) − d_min ,     ∂h/∂q · q̇ ≥ −γ h(q)     for the ``n_pairs`` closest pairs

i.e. the row −(∂d/∂q) Δq ≤ γ dt (d − d_min) on the step Δq = q̇ dt (Ames et al. 2019, *Control
barrier functions: theory and applications*; pink's ``Barrier.compute_qp_inequalities``:
G = −J/dt, h = γ h(q)).  Unlike the damper every pair is constrained whatever its distance
(no detection distance), so the rate allowed far away is γ d instead of ξ.  pink adds a
"safe displacement" cost (zero for this barrier) that only regularises the step; it is left
out.  Units: m, 1/s.
"""

from __future__ import annotations

import math

import numpy as np

from ....collision import distance as coll
from ....errors import CollisionError
from .collision import CollisionLimit


class CollisionBarrier(CollisionLimit):
    """Barrier collision avoidance (see the module docstring).

    Parameters
    ----------
    robot, obstacles, self_collision : as :class:`CollisionLimit`
    d_min : float
        The distance the barrier keeps (m; pink's default 0.02).
    gain : float
        γ (1/s) of the class-K function γ h (pink's default 1).
    n_pairs : int or None
        Constrain the ``n_pairs`` closest pairs only (pink's ``n_collision_pairs``); None: all.
    """

    def __init__(
        self, robot, obstacles=None, d_min=0.02, gain=1.0, n_pairs=None, self_collision=True
    ):
        super().__init__(robot, obstacles, d_safe=d_min, d_detect=float(d_min) + 1.0,
                         xi=1.0, self_collision=self_collision, margin=0.0)  # fmt: skip
        g = float(gain)
        if not (math.isfinite(g) and g > 0):
            raise CollisionError(f"barrier gain must be a finite number > 0 (1/s), got {gain!r}")
        if n_pairs is not None and int(n_pairs) < 1:
            raise CollisionError(f"n_pairs must be >= 1 or None, got {n_pairs!r}")
        self.d_min = self.d_safe
        self.gain = g
        self.n_pairs = None if n_pairs is None else int(n_pairs)

    def distances(self, conf):
        dist = coll.compute(
            self.robot, None, self.env, cutoff=np.inf, data=conf.data,
            self_collision=self.self_collision, cm=self.model,
        )  # fmt: skip
        if self.n_pairs is not None and len(dist) > self.n_pairs:
            keep = np.argpartition(dist.distance, self.n_pairs - 1)[: self.n_pairs]
            dist = coll.Distances(
                *(getattr(dist, f)[keep] for f in (
                    "distance", "point_a", "point_b", "normal", "body_a", "body_b", "joint_a", "joint_b"
                )),
                [dist.names[k] for k in keep],
            )  # fmt: skip
        return dist

    def inequalities(self, conf, dt: float):
        dist = self.last = self.distances(conf)
        if not len(dist):
            return np.zeros((0, conf.nv)), np.zeros(0)
        J = coll.jacobians(self.robot.model, conf.data, dist, self.model.support)
        return -J, self.gain * dt * (dist.distance - self.d_min)

    def __repr__(self) -> str:
        return f"CollisionBarrier(d_min={self.d_min}, gain={self.gain}, n_pairs={self.n_pairs})"


__all__ = ["CollisionBarrier"]
