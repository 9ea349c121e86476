"""The IK-Geo classes solved in closed form (:data:`anthroarm.ik.classes.CLOSED`, a kernel a
class in :mod:`anthroarm.ik.classes`): 8 branches a pose, each the roots of the class's subproblems, in
one compiled call that also shifts every branch by 2π into the joint limits, checks it by the
chain's FK (max |FK(θ) − T| ≤ ``tol`` over the 3×4 entries) and drops duplicates
(:func:`anthroarm.ik.geometric.solve_verified`, :func:`~anthroarm.ik.geometric.pose_solutions`
for one pose, :func:`~anthroarm.ik.geometric.solve_nearest` for the seeds of ``aa.ik.solve``).
"""

from __future__ import annotations

import functools

import numpy as np

from .... import jit as _jit
from ... import geometric as _geo
from ..poses import detail_bad_pose
from .base import OneCall, by_mask
from .geo import GeoKind, SingularOf


class GeoClosed(GeoKind):
    """A 6R arm of a closed IK-Geo class (a 7-joint arm with its last joint held)."""

    name = "ik_geo_closed"
    classes = _geo.CLOSED
    checks_rotation = True
    cost_us = 3.0

    def one_call(self, plan, plain: bool) -> OneCall | None:
        cf, ci = plan.packed
        n = int(ci[2])
        w = n if plain else plan.chain.nq
        call = _jit.entry_point(
            _geo.pose_solutions, cf, ci, np.eye(4), 0.0, 1.0, 1.0, np.empty((8, w + 4))
        )
        return OneCall(
            cf,
            ci,
            by_mask(plan.labels, w, w),
            plan.param_joint is not None,
            call,
            SingularOf(plan, plain),
            False,
            False,
            (8, w + 4),
        )

    def branches(self, robot, gp, Ts, Tr, prm, shape, single, tol, tol_orthonormal):
        S = Tr.shape[0] // max(Ts.shape[0], 1)
        try:
            out = _geo.solve_verified(gp, Tr, prm, tol, tol_orthonormal)
        except _geo.BadPoseError as exc:
            detail_bad_pose(Ts, exc.index // S, single, tol_orthonormal)
            raise
        th, valid, cand, exact, inside, res, conf = (a.reshape(shape + a.shape[2:]) for a in out)
        return th, valid, cand, exact, inside, res, conf

    def nearest(self, plan):
        cf, ci = plan.packed
        return functools.partial(_geo.solve_nearest, cf, ci)
