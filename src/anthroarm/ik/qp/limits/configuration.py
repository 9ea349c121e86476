"""ConfigurationLimit: joint position limits as a box on the step (pink's formulation).

    gain · (q_min ⊖ q) ≤ Δq ≤ gain · (q_max ⊖ q)

with ⊖ the joint-space difference (m or rad), on the joints that have a range
(:func:`~anthroarm.ik.qp.configuration.ranged_joints` of ``robot.chain``): a continuous joint,
whose q is (cos θ, sin θ), is unbounded, and a mimic joint follows its source's limits.  A gain < 1
lets a joint approach its limit geometrically instead of hitting it in one step (pink's default
0.5).  This is the book's joint range constraint g_i(Q) ≥ 0 (Ch. 7 §7-6, (7-84)) linearised per step
as hard inequalities instead of the exterior penalty (7-85).  Joints with an infinite limit are
unbounded.  A joint that starts outside its range gets gain 1 on the violated side (back inside in
one step if the velocity limit allows; pink's QP is infeasible there, pink#206).  On an OpenSim
model with a coupling (``robot.coupling``) the box is on its coordinates, with their ranges
(``robot.lower``/``upper``): the QP's variables are the coordinates.
"""

from __future__ import annotations

import math

import numpy as np

from ..configuration import ranged_joints
from .base import Limit


class ConfigurationLimit(Limit):
    priority = 1

    def __init__(self, robot, gain: float = 0.5, lower=None, upper=None):
        if not 0.0 < gain <= 1.0:
            raise ValueError(f"configuration limit gain must be in (0, 1], got {gain}")
        chain = robot.chain
        coupled = getattr(robot, "coupling", None) is not None
        src = robot if coupled else chain  # the coordinates' ranges, or the joints'
        names = list(robot.joint_names if coupled else chain.q_names)
        self.gain = float(gain)
        self.lower = np.array(src.lower if lower is None else lower, dtype=float)
        self.upper = np.array(src.upper if upper is None else upper, dtype=float)
        if self.lower.shape != (robot.nq,) or self.upper.shape != (robot.nq,):
            raise ValueError(f"lower/upper must have shape ({robot.nq},) (q entries {names})")
        if np.isnan(self.lower).any() or np.isnan(self.upper).any():
            raise ValueError("lower/upper limits contain NaN (use inf for a side without a limit)")
        if np.any(self.lower > self.upper):
            raise ValueError(
                "lower limit above upper limit for joints "
                f"{[n for n, a, b in zip(names, self.lower, self.upper) if a > b]}"
            )
        # map every velocity index of a joint with a range to its configuration index; the
        # others (continuous joints) have no position limit here
        qidx = np.arange(robot.nv) if coupled else np.full(robot.nv, -1)
        for j in () if coupled else ranged_joints(chain):
            qidx[j.idx_v] = j.idx_q
        ok = qidx >= 0
        self._qidx = np.where(ok, qidx, 0)
        self._fin_lo = ok & np.isfinite(self.lower[self._qidx])
        self._fin_hi = ok & np.isfinite(self.upper[self._qidx])
        self._lo = np.where(self._fin_lo, self.lower[self._qidx], -np.inf)
        self._hi = np.where(self._fin_hi, self.upper[self._qidx], np.inf)
        self._identity = bool(np.all(self._qidx == np.arange(robot.nv))) and robot.nq == robot.nv
        self._L2 = np.stack([self._lo, -self._hi])  # [q_min; −q_max] for _box_into
        self._sign2 = np.array([[1.0], [-1.0]])
        self._scaled_for = None  # gain of the cached gain·_L2, gain·_sign2

    def box(self, conf, dt):
        q = conf.q if self._identity else conf.q[self._qidx]
        # inf - q stays inf: unbounded joints give an unbounded side
        lo = self.gain * (self._lo - q)
        hi = self.gain * (self._hi - q)
        if (
            np.maximum.reduce(lo) > 0.0 or np.minimum.reduce(hi) < 0.0
        ):  # a joint is outside its range
            above = q > self._hi
            below = q < self._lo
            # outside the range: ask for the whole way back (gain 1), landing a hair inside so
            # that rounding in q + Δq cannot leave it outside; velocity limits cap the speed
            with np.errstate(invalid="ignore"):  # inf − inf on unbounded joints, masked out
                hi = np.where(above, (self._hi - q) - 1e-12 * (1.0 + np.abs(self._hi)), hi)
                lo = np.where(below, (self._lo - q) + 1e-12 * (1.0 + np.abs(self._lo)), lo)
        return lo, hi

    def _box_into(self, conf, dt, out, tmp):
        # [lo; −hi] = gain · ([q_min; −q_max] − [q; −q]): the same floating-point operations as
        # box() (negation is exact); the start-outside branch is left to combine()
        q = conf.q if self._identity else conf.q[self._qidx]
        g = self.gain
        if g != self._scaled_for:
            # a power-of-two gain (pink's 0.5) scales exactly: g·(a − b) = g·a − g·b bit for bit,
            # so the product with the constant part is cached and one operation is saved
            self._pow2 = math.frexp(g)[0] == 0.5
            self._gL2 = g * self._L2
            self._gs2 = g * self._sign2
            self._scaled_for = g
        if self._pow2:
            np.multiply(self._gs2, q, out=tmp)
            np.subtract(self._gL2, tmp, out=out)
        else:
            np.multiply(self._sign2, q, out=tmp)
            np.subtract(self._L2, tmp, out=out)
            np.multiply(out, g, out=out)
        return out

    def __repr__(self) -> str:
        return f"ConfigurationLimit(gain={self.gain})"
