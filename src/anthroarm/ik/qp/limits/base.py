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
    _box_finite = False  # set by _box_into when the box it returned is finite everywhere

    def box(self, conf, dt: float) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - interface
        raise NotImplementedError

    def after_step(self, v: np.ndarray, dt: float) -> None:
        pass

    def _box_into(self, conf, dt: float, out: np.ndarray, tmp: np.ndarray):
        """The box as [lo; −hi] (2, nv): written into ``out`` (scratch ``tmp``, both (2, nv)) and
        ``out`` returned, or a cached read-only array returned; ``None`` when this limit has no
        such form (then :func:`combine_into` falls back to :func:`combine`).  Must give the same
        numbers as :meth:`box` whenever the box contains Δq = 0."""
        return None

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


BIG = 1e20  # finite stand-in for an infinite bound (the QP backends read ±1e20 as "no bound")


def combine_into(limits, conf, dt: float, ws) -> None:
    """:func:`combine` written into the step workspace: ``ws.B`` (2 nv,) = [lo; −hi] and
    ``ws.hi`` (nv,) = hi, both clipped to ±:data:`BIG` (``ws.lo``, ``ws.mhi`` are the views
    ``ws.B[:nv]``, ``ws.B[nv:]``; ``ws.Bm`` is ``ws.B`` as (2, nv)).

    Fast path: every limit writes its box in place (:meth:`Limit._box_into`) and the boxes are
    intersected with ``np.maximum``.  When the intersection contains Δq = 0 it equals what
    :func:`combine` returns, number for number: no intermediate box was empty (the priority
    rule never applied) and every box contains 0 (a configuration limit's start-outside branch
    did not apply).  Otherwise, or when a limit has no in-place form, :func:`combine` runs."""
    B, Bm = ws.B, ws.Bm
    first = True
    finite = False
    for lim in limits:
        if first:
            box = lim._box_into(conf, dt, Bm, ws.tmp2)
            if box is None:
                break
            if box is not Bm:
                np.copyto(Bm, box)
            first = False
        else:
            box = lim._box_into(conf, dt, ws.box2, ws.tmp2)
            if box is None:
                break
            np.maximum(Bm, box, out=Bm)
        finite = finite or lim._box_finite
    else:
        if not first:
            if not finite:  # a finite box in the intersection bounds B below already
                np.maximum(B, -BIG, out=B)
            if B[B.argmax()] <= 0.0:  # 0 inside the box (False for NaN: argmax finds it)
                np.negative(ws.mhi, out=ws.hi)
                return
    lo, hi = combine(limits, conf, dt)
    np.clip(lo, -BIG, BIG, out=ws.lo)
    np.clip(hi, -BIG, BIG, out=ws.hi)
    np.negative(ws.hi, out=ws.mhi)
