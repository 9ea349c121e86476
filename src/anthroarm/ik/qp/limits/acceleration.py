"""AccelerationLimit: |Δq/dt − v_prev| ≤ a_max · dt, i.e.

    dt (v_prev − a_max dt) ≤ Δq ≤ dt (v_prev + a_max dt)     (rad/s², m/s²)

``v_prev`` is the velocity applied at the previous step; :func:`~anthroarm.ik.qp.step` records
it through ``after_step`` (call :meth:`reset` to start from rest).  The book's velocity-level
control (Ch. 7 §7-7) has no acceleration bound; this is the smooth-start counterpart of its
feedback-compensation predictor (7-52)–(7-53)."""

from __future__ import annotations

import numpy as np

from .base import Limit


class AccelerationLimit(Limit):
    priority = 2

    def __init__(self, robot, a_max):
        a = np.array(np.broadcast_to(np.asarray(a_max, dtype=float), (robot.nv,)))
        if np.isnan(a).any() or np.any(a <= 0):
            raise ValueError(f"a_max must be positive, got {a_max}")
        self.a_max = a
        self.v_prev = np.zeros(robot.nv)

    def reset(self, v=None) -> None:
        self.v_prev = np.zeros_like(self.a_max) if v is None else np.array(v, dtype=float)

    def box(self, conf, dt):
        return dt * (self.v_prev - self.a_max * dt), dt * (self.v_prev + self.a_max * dt)

    def after_step(self, v, dt) -> None:
        self.v_prev = np.array(v, dtype=float)

    def __repr__(self) -> str:
        return f"AccelerationLimit(a_max={np.round(self.a_max, 3).tolist()})"
