"""VelocityLimit: |Δq| ≤ v_max · dt (rad/s or m/s), from the URDF ``velocity`` attribute by
default.  A non-finite or non-positive entry means "no limit" for that joint (URDFs often
leave it 0 when unknown)."""

from __future__ import annotations

import numpy as np

from .base import Limit


class VelocityLimit(Limit):
    priority = 0

    def __init__(self, robot, v_max=None):
        v = np.array(robot.model.velocityLimit if v_max is None else np.broadcast_to(v_max, (robot.nv,)), dtype=float)
        if v.shape != (robot.nv,):
            raise ValueError(f"v_max must have shape ({robot.nv},), got {v.shape}")
        if np.isnan(v).any():
            raise ValueError("v_max contains NaN")
        self.v_max = np.where(np.isfinite(v) & (v > 0), v, np.inf)

    def box(self, conf, dt):
        d = self.v_max * dt
        return -d, d.copy()

    def _box_into(self, conf, dt, out, tmp):
        np.multiply(self.v_max, -dt, out=out)      # both rows: lo = −v dt and −hi = −v dt
        return True

    def __repr__(self) -> str:
        return f"VelocityLimit(v_max={np.round(self.v_max, 3).tolist()})"
