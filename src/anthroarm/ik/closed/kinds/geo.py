"""What the IK-Geo kinds share (:class:`GeoKind`): a 6R arm of one of the classes of
:mod:`anthroarm.ik.geometric` (Elias & Wen, "IK-Geo", arXiv 2211.05737, §IV), or a 7-joint arm
whose first six are one with its last joint held at ``param=`` (rad; default a grid of
:data:`PARAM_GRID` values over its range).  Each kind takes the classes it solves
(:attr:`GeoKind.classes`) of the one plan :func:`anthroarm.ik.geometric.plan_for` makes.

A solution of an IK-Geo arm is singular where its normalised Jacobian volume
|det J| / Π‖J_k‖ (:func:`anthroarm.ik.geometric.jacobian_volumes`) is at most
:data:`anthroarm.ik.geometric.SINGULAR_TOL` (:class:`SingularOf`, computed on first use).
"""

from __future__ import annotations

import functools

import numpy as np

from ... import geometric as _geo
from ..finish import empty, finish, grid_labels
from ..poses import check_poses, swivel_array
from ..results import singular_text
from .base import ClosedForm, ClosedFormKind

#: values of the held joint of a 7-joint arm when ``param`` is not given
PARAM_GRID = 12


class SingularOf:
    """:attr:`AnalyticIKResult.singular` of one pose's solutions (K, n or nq) of an IK-Geo arm,
    made on first use: the smallest normalised Jacobian volume of the K solutions
    (:func:`.geometric.jacobian_volumes`) in words (:func:`..results.singular_text`)."""

    __slots__ = ("plan", "plain")

    def __init__(self, plan, plain: bool):
        self.plan, self.plain = plan, plain

    def __call__(self, solutions: np.ndarray) -> str | None:
        plan, K = self.plan, len(solutions)
        th = (
            solutions
            if self.plain
            else plan.chain.angles(solutions)[:, list(plan.chain.independent)]
        )
        return singular_text(
            float(_geo.jacobian_volumes(plan, th[None], np.ones((1, K), bool)).min())
        )


def singular_rows(plan, TH, valid, rows) -> list:
    """``AnalyticBatchResult.singular`` of the poses ``rows`` of a batch (joint angles
    ``TH`` (N, B, n), ``valid`` (N, B))."""
    vol = _geo.jacobian_volumes(plan, TH[rows], valid[rows]).min(1)
    return [singular_text(float(v)) for v in vol]


class GeoKind(ClosedFormKind):
    """An IK-Geo class solved by :mod:`anthroarm.ik.geometric`: the plan, the held 7th joint,
    the batch bookkeeping; a subclass names its :attr:`classes` and makes the candidates of N
    poses (:meth:`branches`)."""

    #: the classes of :data:`anthroarm.ik.geometric.SOLVED` this kind solves
    classes: tuple = ()

    def plan(self, robot):
        gp = _geo.plan_for(robot)
        return gp if gp is not None and gp.cls in self.classes else None

    def form(self, plan) -> ClosedForm:
        return ClosedForm(
            plan.cls,
            len(plan.fk_axes),
            _geo.n_branches(plan.cls),
            param=plan.param_joint is not None,
            cost_us=self.cost_us,
        )

    def held_joint(self, plan) -> int | None:
        return None if plan.param_joint is None else plan.order.tolist().index(plan.param_joint)

    def branches(self, robot, gp, Ts, Tr, prm, shape, single, tol, tol_orthonormal):
        """The candidates of the poses ``Tr`` (N·S, 4, 4: ``Ts`` (N, 4, 4) repeated per held-joint
        value ``prm`` (N·S,) or None), reshaped to ``shape`` (N, B): (θ, valid or None, cand,
        exact, inside, residuals, configurations or None)."""
        raise NotImplementedError

    def solve_batch(
        self, robot, s, T, *, swivel, param, position_only, tol, tol_orthonormal, single_grid
    ):
        Ts, single = check_poses(T, tol_orthonormal=tol_orthonormal, rigid=not self.checks_rotation)
        N = Ts.shape[0]
        gp = s.plan
        if gp.param_joint is not None:
            if param is None:  # a grid over the held joint's range
                k = gp.order.tolist().index(gp.param_joint)
                lo, hi = (max(gp.lower[k], -np.pi), min(gp.upper[k], np.pi))
                param = (np.linspace(lo, hi, PARAM_GRID + 1)[:-1] + 0.5 * (hi - lo) / PARAM_GRID)[
                    None
                ]
            try:
                pv = swivel_array(param, N, grid_1d=single or single_grid)
            except ValueError as exc:
                raise ValueError(str(exc).replace("swivel", "param")) from None
        else:
            pv = np.zeros((N, 1))
        S = pv.shape[1]
        labels = grid_labels(gp.labels, S, "param")
        if N == 0:
            return empty(robot, labels)
        Tr = Ts if S == 1 else np.repeat(Ts, S, axis=0)
        prm = pv.reshape(-1) if gp.param_joint is not None else None
        th, valid, cand, exact, inside, res, conf = self.branches(
            robot, gp, Ts, Tr, prm, (N, len(labels)), single, tol, tol_orthonormal
        )
        return finish(
            robot,
            s,
            Ts,
            th,
            cand,
            exact,
            inside,
            res,
            valid,
            labels,
            tol,
            False,
            conf=conf,
            singular=functools.partial(singular_rows, gp),
        )

    def tolerance_note(self, plan) -> str:
        c = plan.classification
        if max(c.worst_accepted) > 0:
            return (
                f", or the arm is {plan.cls} only within the classification tolerance (axes up to "
                f"{c.worst_accepted[0]:.3g} m / sine {c.worst_accepted[1]:.3g} from the exact relation)"
            )
        return ""
