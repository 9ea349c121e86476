"""The interface every kind of closed form implements (:class:`ClosedFormKind`), what it offers
for an arm (:class:`ClosedForm`), and its one-pose fast path (:class:`OneCall`).

A kind turns the arm read from ``robot.chain`` into a *plan* (:meth:`ClosedFormKind.plan`: the
constants its compiled calls take, None where the geometry is not of the kind), and solves
poses T (4×4, base frame, m) by that plan: every branch, each a candidate θ (rad) that the
shared bookkeeping (:func:`..finish.finish`) wraps into the joint limits, verifies by FK
(max |FK(θ) − T| ≤ ``tol`` over the 3×4 entries), polishes and labels.  What
:mod:`anthroarm.ik.closed_form` asks of a kind beyond that is read from its attributes
(:attr:`~ClosedFormKind.swivel`, :attr:`~ClosedFormKind.position_only`, ...), never from its
name; the kinds are listed once, in :data:`anthroarm.ik.closed.kinds.KINDS`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class ClosedForm:
    """What :func:`analytic` offers for an arm: ``family`` (an IK-Geo class of
    :mod:`.geometric`, ``"srs_7r"`` or ``"planar_2r"``), ``nq`` the joints it solves,
    ``branches`` candidates per pose (per swivel angle / held-joint value), ``position_only``
    compare the position only by default, ``swivel`` a redundant arm parametrised by the
    swivel angle, ``param`` a 7-joint arm with its last joint held, ``cost_us`` the single-pose
    time of ``aa.ik.analytic`` in µs (order of magnitude, benchmarks/results/ik_analytic.md; a
    hint for callers choosing between solvers)."""

    family: str
    nq: int
    branches: int
    position_only: bool = False
    swivel: bool = False
    param: bool = False
    cost_us: float = 10.0


class OneCall(NamedTuple):
    """One pose in one compiled call (:func:`anthroarm.ik.closed_form.analytic`): ``call(cf, ci,
    T, angle, tol, tol_orthonormal, out)`` writes the solutions into the rows of ``out`` and
    returns the bit mask of their branches (≤ 0: the general path answers).  ``angle`` is the
    swivel angle where ``swivel``, else the held 7th joint (0.0 for none); a kind that is
    ``position_only`` compares the position alone (its rows: θ, the residual)."""

    cf: np.ndarray  # the plan's packed constants
    ci: np.ndarray
    by_mask: tuple  # :func:`by_mask` of the plan's labels and ``out``'s columns
    holds_param: bool  # a 7th joint is held (``param=``)
    call: object  # :func:`anthroarm.jit.entry_point`: its ``fn`` is the kernel compiled for
    #               these types (its reference until the process runs compiled code; the caller
    #               checks T)
    singular: object  # the results' lazy :attr:`AnalyticIKResult.singular` (None: never)
    swivel: bool  # ``angle`` is the swivel angle of a redundant arm
    position_only: bool  # the position alone is compared
    shape: tuple  # of ``out``


def by_mask(labels, width: int, residual: int, swivel: int | None = None) -> tuple:
    """By the bit mask of a pose's branches that are solutions (bit b: branch b; how the
    one-pose kernels return them; 2 ** B entries for B labels): (their labels, and the keys into
    the kernel's ``out`` of their K rows: the solutions ``[:K, :width]``, the residuals
    ``[:K, residual]``, the swivel angles ``[:K, swivel]`` or None) — made once, not per call."""
    B, out = len(labels), []
    for mask in range(1 << B):
        lab = [labels[b] for b in range(B) if mask >> b & 1]
        rows = slice(0, len(lab))
        out.append(
            (
                lab,
                (rows, slice(0, width)),
                (rows, residual),
                None if swivel is None else (rows, swivel),
            )
        )
    return tuple(out)


class ClosedFormKind(ABC):
    """One kind of closed form (planar 2R, the SRS family, an IK-Geo class or search).

    Must implement :meth:`plan`, :meth:`form` and :meth:`solve_batch`; the rest have defaults
    (no one-pose fast path, no held joint, no nearest-seed solver, nothing to add to a reason).
    ``s`` below is the solver :mod:`anthroarm.ik.closed_form` keeps on a robot: ``s.plan`` (this
    kind's plan), ``s.form`` (:class:`ClosedForm`), ``s.plain`` (q is θ: no continuous joint),
    ``s.kind`` (this object)."""

    #: the registry's name of the kind (for messages and listings; never compared)
    name: str = ""
    #: a redundant arm solved per elbow swivel angle φ (rad): ``swivel=`` is accepted
    swivel: bool = False
    #: solved for a position (3,): the rotation is compared only when asked
    position_only: bool = False
    #: the compiled batch call checks the rotation part of T itself
    checks_rotation: bool = False
    #: candidates just beyond a limit are rescued along the self-motions (:func:`..limits.rescue`)
    rescues: bool = True
    #: single-pose time of ``aa.ik.analytic`` (µs, order of magnitude): a hint for callers
    cost_us: float = 10.0

    @abstractmethod
    def plan(self, robot):
        """The plan of ``robot`` at its tool (read from ``robot.chain``; kept on the robot by the
        module that makes it), or None where its geometry is not of this kind."""

    @abstractmethod
    def form(self, plan) -> ClosedForm:
        """The :class:`ClosedForm` of a plan (family, joints, branches, capabilities, cost)."""

    def labels(self, plan) -> tuple:
        """The branch labels of a plan, one per candidate of a pose."""
        return tuple(plan.labels)

    def held_joint(self, plan) -> int | None:
        """The θ index (in the arm's ``chain.independent`` order) of a joint held as the
        parameter of the family (``param=``), or None."""
        return None

    def one_call(self, plan, plain: bool) -> OneCall | None:
        """The one-pose fast path (:class:`OneCall`, its kernel compiled or loaded now), or None."""
        return None

    def solve_one(self, robot, s, arr, swivel, position_only, tol, tol_orthonormal):
        """One pose ``arr`` (4×4 C-order float64; a position (3,) where :attr:`~anthroarm.ik.closed.kinds.base.ClosedFormKind.position_only`) in
        one compiled call when it has a solution and nothing to polish — an
        :class:`~..results.AnalyticIKResult` with the same solutions, labels and order as
        :meth:`solve_batch` — else None (the batch path answers)."""
        return None

    @abstractmethod
    def solve_batch(
        self, robot, s, T, *, swivel, param, position_only, tol, tol_orthonormal, single_grid
    ):
        """Every branch of the poses ``T`` (an :class:`~..results.AnalyticBatchResult`), the
        arguments already checked against the kind's capabilities (``swivel`` only where
        :attr:`~anthroarm.ik.closed.kinds.base.ClosedFormKind.swivel`, ``param`` only where a joint is held, ``position_only`` only where
        :attr:`~anthroarm.ik.closed.kinds.base.ClosedFormKind.position_only`); ``single_grid``: a 1-D ``swivel``/``param`` is a grid."""

    def nearest(self, plan):
        """``f(T, ref, param)`` giving the solutions θ (K, n) nearest ``ref`` first with that
        one's errors, or None per pose (:func:`anthroarm.ik.closed_form.nearest_solver`); None
        where the kind has no such call."""
        return None

    def nearest_swivel(self, plan):
        """``f(T, ref, swivel, first)`` of a swivel family
        (:func:`anthroarm.ik.closed_form.nearest_swivel_solver`), or None."""
        return None

    def outside(self, plan, T, tol) -> str | None:
        """Why pose ``T`` (4×4) is outside the kind's workspace before any branch is read (a
        planar arm: off its plane), or None."""
        return None

    def tolerance_note(self, plan) -> str:
        """Text appended to a reason where no candidate passed the FK check ("" for none)."""
        return ""

    def __repr__(self) -> str:
        return f"<closed-form kind {self.name}>"
