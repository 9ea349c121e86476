"""VelocityLimit: |Δq| ≤ v_max · dt (rad/s or m/s), one bound per velocity (nv: a continuous
joint has one), from ``robot.chain.velocity_limit`` (the URDF ``velocity`` attribute) by
default.  A non-finite or non-positive entry means "no limit" for that joint (URDFs often
leave it 0 when unknown); on an OpenSim model with a coupling, one per coordinate
(``robot.velocity_limit``: none unless given).  ``v_max`` is read-only: assign a new array to
change it (the step's box is cached per ``v_max`` array and dt)."""

from __future__ import annotations

import numpy as np

from .base import BIG, Limit


class VelocityLimit(Limit):
    priority = 0

    def __init__(self, robot, v_max=None):
        if v_max is not None:
            v = np.array(np.broadcast_to(v_max, (robot.nv,)), dtype=float)
        elif getattr(robot, "coupling", None) is not None:  # one per coordinate
            v = np.array(robot.velocity_limit, dtype=float)
        else:
            v = np.array(robot.chain.velocity_limit, dtype=float)
        if v.shape != (robot.nv,):
            raise ValueError(f"v_max must have shape ({robot.nv},), got {v.shape}")
        if np.isnan(v).any():
            raise ValueError("v_max contains NaN")
        if v_max is not None and np.any(v < 0):
            raise ValueError(
                "v_max must be >= 0 (0 or inf: no limit on that joint), got "
                f"{np.asarray(v_max).tolist()}"
            )
        self.v_max = np.where(np.isfinite(v) & (v > 0), v, np.inf)
        self.v_max.setflags(write=False)  # replace it (lim.v_max = ...) rather than edit it
        self._cached = (None, None, None)  # (v_max, dt, [−v dt; −v dt]) of the last _box_into

    def box(self, conf, dt):
        d = self.v_max * dt
        return -d, d.copy()

    def _box_into(self, conf, dt, out, tmp):
        # both rows: lo = −v dt and −hi = −v dt; constant while v_max and dt are
        vm, dt0, box = self._cached
        if vm is not self.v_max or dt0 != dt:
            box = np.multiply(self.v_max, -dt, out=np.empty_like(out))
            box.setflags(write=False)
            self._cached = (self.v_max, dt, box)
            self._box_finite = bool((np.abs(box) <= BIG).all())
        return box

    def __repr__(self) -> str:
        return f"VelocityLimit(v_max={np.round(self.v_max, 3).tolist()})"
