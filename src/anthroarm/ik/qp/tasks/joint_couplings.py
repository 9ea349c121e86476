"""JointCouplingsTask: several linear joint relations as one task (the DIP–PIP couplings of four
fingers, a linkage's joint ratios).

Stacks K :class:`~anthroarm.ik.qp.tasks.coupling.JointCouplingTask` rows r_k (1 × nv) and
offsets b_k::

    e(q) = A θ(q) − b  (K,),   J = A  (K × nv),   A = [r_1; …; r_K]

with θ the joint coordinates in the tangent space (q itself when nq = nv).  The objective is
the sum of the K tasks' objectives (same weights, same gain, LM terms adding up).  J is
constant, so H = AᵀW²A is computed once (per cost and gain) and a step only adds
c = α AᵀW² e: the relations cost one matrix addition per step instead of K outer products.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .base import Task
from .coupling import JointCouplingTask


class JointCouplingsTask(Task):
    """The relations of ``couplings`` (a sequence of
    :class:`~anthroarm.ik.qp.tasks.coupling.JointCouplingTask`), one cost per relation taken
    from each (a scalar cost each), one gain and LM damping for all."""

    def __init__(self, robot, couplings, gain: float = 1.0, lm_damping: float = 0.0):
        couplings = list(couplings)
        if not couplings or not all(isinstance(c, JointCouplingTask) for c in couplings):
            raise ValueError("JointCouplingsTask takes a non-empty sequence of JointCouplingTask")
        cost = np.array([float(np.asarray(c.cost).reshape(-1)[0]) for c in couplings])
        super().__init__(cost=cost, gain=gain, lm_damping=lm_damping)
        self.couplings = couplings
        self.A = np.vstack([c._row for c in couplings])
        self.b = np.array([c.offset for c in couplings])
        self._key = None

    def __repr__(self) -> str:
        return f"JointCouplingsTask({len(self.couplings)} relations, gain={self.gain})"

    def _theta(self, conf) -> np.ndarray:
        if conf.nq == conf.nv:
            return conf.q
        return pin.difference(conf.model, pin.neutral(conf.model), conf.q)

    def compute_error(self, conf) -> np.ndarray:
        return self.A @ self._theta(conf) - self.b

    def compute_jacobian(self, conf) -> np.ndarray:
        return self.A.copy()

    def _accumulate(self, conf, ws, first):
        if type(self) is not JointCouplingsTask:
            return Task._accumulate(self, conf, ws, first)
        if self._key is None or self._key[0] is not self.cost or self._key[1] != self.gain:
            W2 = self.cost**2
            self._H = self.A.T @ (W2[:, None] * self.A)
            self._AtW2a = self.A.T * (W2 * self.gain)  # α AᵀW², (nv, K)
            self._key = (self.cost, self.gain)
        e = self.A @ self._theta(conf) - self.b
        if first:
            np.copyto(ws.H, self._H)
            self._AtW2a.dot(e, out=ws.c)
        else:
            np.add(ws.H, self._H, out=ws.H)
            ws.c += self._AtW2a.dot(e)
        if self.lm_damping:
            We = (self.cost * self.gain) * e
            return self.lm_damping * float(We @ We)
        return 0.0
