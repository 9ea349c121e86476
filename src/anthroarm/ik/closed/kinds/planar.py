"""The planar 2R kind: two parallel hinges (the book's Fig. 7-14, ``planar2r``), solved for the
tool position p (m) — q2 by SP3 (‖p − o1‖ fixes the elbow angle, two roots) and then q1 by SP1
(the turn about h1 that brings the elbow's image of p onto it); 2 branches
(:func:`anthroarm.ik.families.planar_plan`, :func:`~anthroarm.ik.families.planar_verified`).

A target off the plane of motion, |h1 · (p − p_tool(0))| > ``tol``, is outside the workspace.
The rotation is compared only with ``position_only=False`` (then a 2-DOF constraint on a 3-D
rotation, checked by Pinocchio's FK).
"""

from __future__ import annotations

import numpy as np

from .... import jit as _jit
from ... import families as _fam
from ..finish import empty, finish, fk_residual
from ..poses import check_poses
from ..results import AnalyticIKResult
from .base import ClosedForm, ClosedFormKind, OneCall, by_mask

#: the family name of the planar 2R arm (``ClosedForm.family``)
PLANAR = "planar_2r"


class Planar2R(ClosedFormKind):
    """Two parallel hinges, solved for the position of the tool."""

    name = PLANAR
    position_only = True
    cost_us = 2.0

    def plan(self, robot):
        return _fam.planar_plan(robot)

    def form(self, plan) -> ClosedForm:
        return ClosedForm(PLANAR, 2, 2, position_only=True, cost_us=self.cost_us)

    def one_call(self, plan, plain: bool) -> OneCall | None:
        if not plain:
            return None
        cf, ci = plan.packed
        shape = (2, 4)
        call = _jit.entry_point(
            _fam.planar_pose_solutions, cf, ci, np.eye(4), 0.0, 1.0, 1.0, np.empty(shape)
        )
        return OneCall(cf, ci, by_mask(plan.labels, 2, 2), False, call, None, False, True, shape)

    def solve_one(self, robot, s, arr, swivel, position_only, tol, tol_orthonormal):
        """A 4×4 pose or a position (3,) in one call of
        :func:`~anthroarm.ik.families.planar_pose_solutions` (position only)."""
        if position_only is False or arr.shape not in ((4, 4), (3,)):
            return None
        if arr.shape == (3,):  # a position: the pose the planar kernel reads it from
            pose = np.eye(4)
            pose[:3, 3] = arr
        else:
            pose = arr
        cf, ci = s.plan.packed
        out = np.empty((2, 4))
        mask = _fam.planar_pose_solutions(
            cf, ci, pose, 0.0, float(tol), float(tol_orthonormal), out
        )
        if mask <= 0:
            return None  # none, a malformed target, a candidate to polish: the batch path
        labels = s.plan.labels
        k = [b for b in range(len(labels)) if mask >> b & 1]
        q = out[: len(k), :2]
        return AnalyticIKResult(
            solutions=q if s.plain else s.plan.chain.configuration(q),
            branches=[labels[b] for b in k],
            residuals=out[: len(k), 2],
            model=robot.name,
        )

    def solve_batch(
        self, robot, s, T, *, swivel, param, position_only, tol, tol_orthonormal, single_grid
    ):
        """Positions from ``T`` (N, 4, 4), (N, 3) or (3,); the rotation is compared only with
        ``position_only=False`` (Pinocchio's residuals, the solutions marked again)."""
        po = True if position_only is None else bool(position_only)
        Ts, _ = check_poses(T, position_only=po)
        N = Ts.shape[0]
        labels = list(s.plan.labels)
        if N == 0:
            return empty(robot, labels)
        th, cand, exact, inside, res, ok = _fam.planar_verified(
            s.plan, np.ascontiguousarray(Ts[:, :3, 3]), tol
        )
        if not po:
            Q = s.plan.chain.configuration(np.where(cand[..., None], th, 0.0))
            res = np.where(cand, fk_residual(robot, Q, Ts, False), np.inf)
            ok = None
        return finish(robot, s, Ts, th, cand, exact, inside, res, ok, labels, tol, po)

    def outside(self, plan, T, tol) -> str | None:
        off = abs(float(plan.h1 @ (T[:3, 3] - plan.p_tool)))
        if off > tol:
            return (
                f"outside the workspace: the target is {off:.3g} m off the plane of motion of the "
                "mechanism (normal to its parallel axes)"
            )
        return None
