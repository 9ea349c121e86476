"""DampingTask: penalise the joint displacement itself, e = 0, J = I.

Adds ``cost² ‖Δq‖²`` to the objective: the Tikhonov regulariser of damped least squares
(Ch. 7 §7-6: the λ → ∞ limit is the steepest-descent direction Jᵀe of the book's A9)."""

from __future__ import annotations

import numpy as np

from .base import Task


class DampingTask(Task):
    def __init__(self, cost=1e-3):
        super().__init__(cost=cost, gain=0.0, lm_damping=0.0)

    def compute_error(self, conf) -> np.ndarray:
        return np.zeros(conf.nv)

    def compute_jacobian(self, conf) -> np.ndarray:
        return np.eye(conf.nv)

    def compute_qp_objective(self, conf):  # the returned H is a fresh array (may be modified)
        w = self.cost
        return np.diag(
            np.broadcast_to(np.asarray(w, float) ** 2, (conf.nv,)).astype(float)
        ), np.zeros(conf.nv)

    def _accumulate(self, conf, ws, first):
        # H += diag(w²), c unchanged
        if type(self) is not DampingTask:
            return Task._accumulate(self, conf, ws, first)
        if first:
            ws.H.fill(0.0)
            ws.c.fill(0.0)
        w = self.cost
        if isinstance(w, float):
            return w * w
        np.add(ws.Hd, w * w, out=ws.Hd)
        return 0.0
