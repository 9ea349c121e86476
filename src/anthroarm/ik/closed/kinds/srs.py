"""The SRS kind: a redundant shoulder (3R, axes meeting) – elbow (R) – wrist (3R, axes meeting)
arm (§6-3, ``human_arm7``), parametrised by the elbow swivel angle φ (rad; the definition of
:func:`anthroarm.ik.qp.tasks.swivel.swivel_angle`).  Per φ: the wrist centre W from T, the
elbow angle q4 by SP3 (‖W − S‖), the elbow E on the circle about S–W at angle φ, the shoulder
(q1, q2) by SP2 (or SP4) and q3 by SP1, the wrist by SP4/SP1; 8 branches per swivel angle
(:func:`anthroarm.ik.families.srs_plan`, :func:`~anthroarm.ik.families.srs_verified`).

``swivel=``: a scalar, a grid, or :data:`..poses.DEFAULT_SWIVEL`.  The compiled calls check the
rotation part of T; a family of solutions is not rescued along self-motions on the limits.
"""

from __future__ import annotations

import functools

import numpy as np

from .... import jit as _jit
from ... import families as _fam
from ... import geometric as _geo
from ..finish import empty, finish, grid_labels
from ..poses import check_poses, detail_bad_pose, swivel_array
from ..results import AnalyticIKResult
from .base import ClosedForm, ClosedFormKind, OneCall, by_mask

#: the family name of the SRS 7R arm (``ClosedForm.family``)
SRS = "srs_7r"


class SRS7R(ClosedFormKind):
    """A 7R shoulder–elbow–wrist arm, solved per elbow swivel angle."""

    name = SRS
    swivel = True
    checks_rotation = True
    rescues = False
    cost_us = 4.0

    def plan(self, robot):
        return _fam.srs_plan(robot)

    def form(self, plan) -> ClosedForm:
        return ClosedForm(SRS, 7, 8, swivel=True, cost_us=self.cost_us)

    def one_call(self, plan, plain: bool) -> OneCall | None:
        if not plain:
            return None
        cf, ci = plan.packed
        shape = (8, 12)
        call = _jit.entry_point(
            _fam.srs_pose_solutions, cf, ci, np.eye(4), 0.0, 1.0, 1.0, np.empty(shape)
        )
        return OneCall(
            cf, ci, by_mask(plan.labels, 7, 9, 11), False, call, None, True, False, shape
        )

    def solve_one(self, robot, s, arr, swivel, position_only, tol, tol_orthonormal):
        """One pose (4×4) at ``swivel`` (a scalar or a 1-D grid; default
        :data:`..poses.DEFAULT_SWIVEL`) in one call of :func:`.families.srs_solutions`."""
        if position_only or arr.shape != (4, 4):
            return None
        try:
            grid = swivel_array(swivel, 1, grid_1d=True)[0]
            got = _fam.srs_solutions(s.plan, arr, grid, tol, tol_orthonormal)
        except ValueError:
            return None
        if got is None:
            return None
        q, res, rows, angles = got
        labels = (
            s.plan.labels if len(grid) == 1 else grid_labels(s.plan.labels, len(grid), "swivel")
        )
        return AnalyticIKResult(
            q if s.plain else s.plan.chain.configuration(q),
            [labels[r] for r in rows],
            None,
            angles,
            res,
            None,
            robot.name,
        )

    def solve_batch(
        self, robot, s, T, *, swivel, param, position_only, tol, tol_orthonormal, single_grid
    ):
        Ts, single = check_poses(T, tol_orthonormal=tol_orthonormal, rigid=False)
        N = Ts.shape[0]
        grid = swivel_array(swivel, N, grid_1d=single or single_grid)
        labels = grid_labels(s.plan.labels, grid.shape[1], "swivel")
        if N == 0:
            return empty(robot, labels, swivel=True)
        try:
            th, cand, exact, inside, res, ok = _fam.srs_verified(
                s.plan, Ts, grid, tol, tol_orthonormal
            )
        except _geo.BadPoseError as exc:
            detail_bad_pose(Ts, exc.index, single, tol_orthonormal)
            raise
        sw = np.repeat(grid, len(s.plan.labels), axis=1)
        return finish(robot, s, Ts, th, cand, exact, inside, res, ok, labels, tol, False, swivel=sw)

    def nearest_swivel(self, plan):
        return functools.partial(_fam.srs_nearest, plan)
