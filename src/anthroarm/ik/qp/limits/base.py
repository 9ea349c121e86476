"""Limit: a box on the joint displacement Δq of one QP step, with a priority.

Every limit of this package is a box  lo(q, dt) ≤ Δq ≤ hi(q, dt)  (nv,), ±inf where a joint is
unbounded.  :func:`combine` intersects the boxes in priority order (lower number first).  When
a lower-priority box does not meet the current one, the current box is reduced to its point
closest to it, so the combined box is never empty and the QP is always feasible:

* velocity (priority 0) is a hard actuator bound;
* configuration (1): if q starts outside its range the step moves back toward the range at
  the largest speed the velocity limit allows (pink#206 raises an infeasible QP instead);
* acceleration (2): yields when braking in time is impossible.
"""

from __future__ import annotations

import numpy as np


class Limit:
    """Base class.  ``box(conf, dt) -> (lo, hi)``; ``after_step(v, dt)`` lets stateful limits
    (acceleration) record the velocity that was applied."""

    priority: float = 1.5

    def box(self, conf, dt: float) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - interface
        raise NotImplementedError

    def after_step(self, v: np.ndarray, dt: float) -> None:
        pass

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def _priority(limit) -> float:
    return limit.priority


def combine(limits, conf, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Intersect the limits' boxes in priority order (see the module docstring)."""
    ordered = sorted(limits, key=_priority) if len(limits) > 1 else limits
    if not ordered:
        return np.full(conf.nv, -np.inf), np.full(conf.nv, np.inf)
    lo, hi = ordered[0].box(conf, dt)
    for lim in ordered[1:]:
        l, h = lim.box(conf, dt)
        nl = np.maximum(lo, l)
        nh = np.minimum(hi, h)
        if np.maximum.reduce(nl - nh) > 0.0:
            # nearest point of the current box to [l, h]: lo if [l, h] lies below, hi if above
            empty = nl > nh
            pt = np.where(h < lo, lo, hi)
            nl = np.where(empty, pt, nl)
            nh = np.where(empty, pt, nh)
        lo, hi = nl, nh
    return lo, hi
