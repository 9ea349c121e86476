"""Closed-form inverse kinematics of every arm whose geometry allows it, every branch.

:func:`analytic` (exported as ``aa.ik.analytic``) returns *every* joint solution of one tool
pose that lies inside the joint limits, each labelled by its branch and each verified by forward
kinematics before it is returned; :func:`analytic_batch` does the same for ``N`` poses at once.

Which closed form an arm has is read from ``robot.chain`` (never from its name) by the kinds
of :data:`.closed.kinds.KINDS` (one interface, :class:`.closed.kinds.ClosedFormKind`; one
registry), in this order:

``planar_2r`` (:mod:`.families`; :mod:`.closed.kinds.planar`)
    two parallel hinges (the book's Fig. 7-14, ``planar2r``): position only, q2 by SP3 and q1 by
    SP1; 2 branches.
``srs_7r`` (:mod:`.families`; :mod:`.closed.kinds.srs`)
    a redundant shoulder (3R, axes meeting) – elbow (R) – wrist (3R, axes meeting) arm (§6-3,
    ``human_arm7``), parametrised by the elbow swivel angle φ (rad; the definition of
    :func:`anthroarm.ik.qp.tasks.swivel.swivel_angle`): ``swivel=`` a scalar, an array, or
    default :data:`DEFAULT_SWIVEL`; 8 branches per swivel angle.
an IK-Geo class (:mod:`.geometric`; :mod:`.closed.kinds.geo_closed`, :mod:`.closed.kinds.geo_search`)
    a 6R arm (``sixr_arm``, ``prosthetic_arm``, ``care_robot``, UR, PUMA-like, ``talos_arm``,
    your own URDF …) of one of the classes :data:`.geometric.SOLVED`, solved by the subproblems
    of :mod:`.subproblems` (8 branches for a closed class, up to 16 for a search class); a
    7-joint arm with its last joint held at ``param=`` (rad; default a grid of
    :data:`PARAM_GRID` values over its range) when the first six form such a class (panda,
    xarm7).

The book's own procedure for the prosthetic arm ((7-17)–(7-31) with Cramer's rule, Table 7.2)
stays available as ``method="book"`` (:func:`prosthetic_book_procedure`); the production path
is the general one above, and Table 7.2 reproduces through it.

Every solver runs as one compiled call (:mod:`anthroarm.jit`) per batch: the class solver's
branches, each shifted by 2π into the joint limits and checked by the chain's forward
kinematics (product of exponentials of the joints as read from ``robot.chain``, the model
Pinocchio holds, in joint-local frames: :func:`.fk.local_frames`; ``tol`` on every
entry of the 3×4 pose, or the position for ``planar_2r``), duplicates dropped.  Candidates
inside the limits that are near a solution (FK residual ≤ :data:`POLISH_MAX`: an arm of its
class only within the classification tolerance, with rounded URDF numbers; a least-squares
root where a subproblem's two roots meet, at a singular pose) are polished by Newton steps on
the chain inside that call (a held 7th joint stays where it was asked to be), and the exact
ones by bounded least squares where that leaves any; a pose whose only
candidates lie on or just beyond a limit, or on a singular family whose representative is
outside the limits, is rescued along its self-motions (:func:`.closed.limits.rescue`).

A tree (a humanoid, two arms on a torso, an arm with a hand or a gripper): the closed form is
that of the joints on the path from the base to the tool (:class:`.closed.trees.Arm`, the robot reduced to
them); every other joint keeps its value in ``q_rest`` (default the comfortable posture,
:func:`anthroarm.ik.qp.tasks.posture.comfortable_posture`) — it does not move the tool.

Frames and units: ``T`` is the 4×4 pose (SE(3), metres) of the robot's tool frame
(``robot.tool``) in the base frame; joint values in radians.  A robot without a closed form
raises :class:`~anthroarm.errors.UnsupportedModelError` naming its class and pointing to
``aa.ik.solve``.  Thread-safe: per-robot plans are immutable and cached by weak reference;
Pinocchio is called with the calling thread's ``robot.data``.

This module holds the public entry points and the solver kept on a robot; the rest lives in
:mod:`anthroarm.ik.closed` (results, input checks, the kinds, the bookkeeping of a batch, the
rescue on the limits, trees, the book's procedure), re-exported here under its former names.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import UnsupportedModelError
from ..models import closed_forms as _models
from . import families as _fam
from . import geometric as _geo
from .closed.book import book_result as _book_result
from .closed.book import prosthetic_book_procedure
from .closed.finish import NEAR_MISS, POLISH_MAX
from .closed.finish import fk_residual as _fk_residual
from .closed.kinds import KINDS, PLANAR, SRS, ClosedForm, ClosedFormKind, OneCall
from .closed.kinds.geo import PARAM_GRID
from .closed.limits import LIMIT_SLACK, TWO_PI
from .closed.limits import refine as _refine
from .closed.limits import rescue as _rescue
from .closed.poses import DEFAULT_SWIVEL
from .closed.poses import c_order as _c_order
from .closed.poses import check_poses as _check_poses
from .closed.poses import check_tol as _check_tol
from .closed.poses import held_angle as _held_angle
from .closed.results import AnalyticBatchResult, AnalyticIKResult
from .closed.trees import Arm as _Arm
from .closed.trees import arm_of as _arm_of
from .closed.trees import frame_robot as _frame_robot
from .closed.trees import on_robot as _on_robot
from .closed.trees import q_rest_of as _q_rest
from .closed.trees import retooled as _retooled
from .closed.trees import unnamed as _unnamed
from .vec3 import WRAP_MAX

__all__ = [
    "DEFAULT_SWIVEL",
    "KINDS",
    "LIMIT_SLACK",
    "NEAR_MISS",
    "PARAM_GRID",
    "PLANAR",
    "POLISH_MAX",
    "SRS",
    "TWO_PI",
    "AnalyticBatchResult",
    "AnalyticIKResult",
    "ClosedForm",
    "ClosedFormKind",
    "analytic",
    "analytic_batch",
    "analytic_cost",
    "closed_form_info",
    "has_analytic",
    "held_joint",
    "nearest_solver",
    "nearest_swivel_solver",
    "prosthetic_book_procedure",
    "require_form",
]

_F64 = np.dtype(np.float64)
_INF = math.inf
# kept importable under their former names (used by callers of this module's internals)
_ = (_check_poses, _fk_residual, _refine, _rescue)


# ---------------------------------------------------------------------------- the solver
@dataclass(frozen=True)
class _Solver:
    """The closed form of a robot at its tool: its ``kind`` (one of :data:`KINDS`), the kind's
    ``plan`` of the robot, the :class:`ClosedForm` it offers, whether q is θ (``plain``: no
    continuous joint), and for a tree its arm (the closed form is the arm's)."""

    kind: ClosedFormKind
    plan: object
    form: ClosedForm
    plain: bool  # q is the joint angles themselves (no continuous joint)
    arm: _Arm | None = None  # a tree: the closed form is the arm's (its own _Solver)

    @functools.cached_property
    def one_call(self):
        """How :func:`analytic` answers one pose in one compiled call
        (:class:`.closed.kinds.OneCall`; the kind's :meth:`~ClosedFormKind.one_call`), or None."""
        return self.kind.one_call(self.plan, self.plain)


_PENDING = object()


class _Entry:
    """What :func:`analytic` keeps on a robot (:meth:`~anthroarm.robot.Robot.derived`): its
    :class:`_Solver` at its tool or None, and the solver's :attr:`_Solver.one_call` where
    :func:`analytic` may answer one pose by it (no tree; made on the first such pose,
    :data:`_PENDING` until then), else None."""

    __slots__ = ("solver", "one")

    def __init__(self, robot):
        if getattr(robot, "coupling", None) is not None:
            raise UnsupportedModelError(
                f"{robot.name}: no closed form for an OpenSim model whose joints are nonlinear "
                "functions of its coordinates (robot.coupling); use aa.ik.solve(robot, T), which "
                "solves in the coordinates"
            )
        self.solver = _new_solver(robot)
        self.one = None if self.solver is None or self.solver.arm is not None else _PENDING


def _solver(robot):
    """The :class:`_Solver` of ``robot`` at its tool (kept on the robot), or None."""
    return robot.derived("ik.closed_form", _Entry).solver


def _one_call_of(entry: _Entry) -> OneCall | None:
    """The :attr:`_Solver.one_call` of an entry still :data:`_PENDING`, made (the one-pose
    kernel compiled or loaded) and kept in the entry."""
    entry.one = entry.solver.one_call
    return entry.one


def _new_solver(robot):
    """The :class:`_Solver` of ``robot`` at its tool, made (:func:`_solver` keeps it), or None."""
    ch = robot.chain
    arm = _arm_of(robot)
    if arm is not None:
        inner = _solver(arm.robot) if isinstance(arm, _Arm) else None
        return None if inner is None else _Solver(inner.kind, inner.plan, inner.form, False, arm)
    plain = robot.nq == len(ch.independent) and all(
        ch.joints[j].kind != "continuous" for j in ch.independent
    )
    for kind in KINDS:  # the first kind whose plan reads the chain
        plan = kind.plan(robot)
        if plan is not None:
            return _Solver(kind, plan, kind.form(plan), plain)
    return None


def _at(robot, frame):
    """The solver for ``frame`` (default the tool), or None (always for an OpenSim model with
    nonlinear couplings, ``robot.coupling``: its coordinates are not Pinocchio's joints)."""
    if getattr(robot, "coupling", None) is not None:
        robot.frame_id(frame)  # UnknownFrameError for a name the model lacks
        return None
    r = _retooled(robot, frame)
    return None if r is None else _solver(r)


def has_analytic(robot, frame=None) -> bool:
    """True if :func:`analytic` has a closed form for ``robot`` at ``frame`` (a name or a
    Pinocchio frame id; default the tool): its geometry is one of the families of the module
    docstring.  An unknown frame raises :class:`~anthroarm.errors.UnknownFrameError`."""
    return _at(robot, frame) is not None


def closed_form_info(robot, frame=None) -> ClosedForm | None:
    """The :class:`ClosedForm` of ``robot`` at ``frame``, or None without a closed form."""
    s = _at(robot, frame)
    return None if s is None else s.form


def held_joint(robot, frame=None) -> int | None:
    """Index (in ``robot.chain.independent`` order, the order of θ) of the joint a 7-joint arm
    holds as the parameter of its family (``param=`` of :func:`analytic`), or None."""
    s = _at(robot, frame)
    k = None if s is None else s.kind.held_joint(s.plan)
    if k is None:
        return None
    return k if s.arm is None else int(s.arm.th_idx[k])


def analytic_cost(robot, frame=None) -> float:
    """Cost hint of one :func:`analytic` call at ``frame`` in µs per pose (per swivel angle of a
    redundant arm), ``inf`` without a closed form."""
    s = _at(robot, frame)
    return float("inf") if s is None else s.form.cost_us


def _why_not(robot) -> str:
    on_path = len(robot.chain.path(robot.tool_id))
    if not on_path:
        return (
            f"{robot.name}: no joint moves the frame {robot.tool!r}: there is nothing to solve for"
        )
    arm = _arm_of(robot)
    sub = arm.robot if isinstance(arm, _Arm) else robot
    c = _geo.classification(sub)
    why = (
        "its chain could not be read"
        if c is None
        else f"its kinematic class is {c.name}" + (f" ({c.reason})" if c.reason else "")
    )
    if isinstance(arm, str):
        why += f"; {arm}"
    srs = _fam.srs_reason(sub)
    return (
        f"{robot.name}: no closed form for this geometry at the tool {robot.tool!r}: {why}"
        + (f"; not an SRS arm: {srs}" if srs and on_path == 7 else "")
        + (
            "; lock joints on the path (aa.load(..., locked=[...])) to leave 6 or 7"
            if on_path > 7
            else ""
        )
        + f". Closed forms exist for 6R arms of the classes {', '.join(_geo.SOLVED)} (and 7-joint arms whose "
        "first six are one, with the last joint held), SRS 7R arms by swivel angle, and planar 2R arms; "
        "use aa.ik.solve(robot, T) for a numerical solution"
    )


def _require(robot) -> _Solver:
    s = _solver(robot)
    if s is None:
        raise UnsupportedModelError(_why_not(robot))
    return s


def require_form(robot, frame=None) -> ClosedForm:
    """:func:`closed_form_info` of ``robot``, or :class:`~anthroarm.errors.UnsupportedModelError`
    saying why it has no closed form (and pointing to ``aa.ik.solve``)."""
    s = _at(robot, frame)
    if s is None:
        r = _retooled(robot, frame)
        raise UnsupportedModelError(_unnamed(robot, frame) if r is None else _why_not(r))
    return s.form


# ---------------------------------------------------------------------------- batches
# long: the public docstring (every argument); the body checks them in turn and its calls
# pass their keywords a line each
def analytic_batch(
    robot,
    T,
    *,
    swivel=None,
    position_only: bool | None = None,
    tol: float = 1e-9,
    tol_orthonormal: float = 1e-6,
    param=None,
    q_rest=None,
    frame=None,
    _single_grid: bool = False,
) -> AnalyticBatchResult:
    """Closed-form IK of N poses ``T`` (N, 4, 4) on every branch (see the module docstring).

    Candidates are wrapped into the joint limits (multiples of 2π), rejected if outside, and
    verified by FK: kept only if every entry of the 3×4 pose differs from ``T`` by ≤ ``tol``
    (m for the position; the rotation entries are unitless); ``position_only`` (the default of
    ``planar_2r`` only) compares the position alone.  An SRS arm: ``swivel`` a scalar (all
    poses), shape (N,) (one angle per pose), (1, S) (a grid shared by all poses) or (N, S);
    default :data:`DEFAULT_SWIVEL` for every pose.  A 7-joint arm solved with its last joint
    held: ``param`` with the same rules (default :data:`PARAM_GRID` values over its range).  A
    tree: the joints off the path to the tool take their values in ``q_rest`` (nq,) (default
    the comfortable posture); ``frame`` solves for another frame (:func:`analytic`).

    Raises ``ValueError`` for a malformed ``T`` (shape, NaN, non-orthonormal rotation) or a
    ``swivel``/``param`` the arm does not take, and
    :class:`~anthroarm.errors.UnsupportedModelError` for a robot without a closed form."""
    _check_tol("tol", tol)
    _check_tol("tol_orthonormal", tol_orthonormal)
    other = _frame_robot(robot, frame)
    if other is not robot:
        return analytic_batch(
            other,
            T,
            swivel=swivel,
            position_only=position_only,
            tol=tol,
            tol_orthonormal=tol_orthonormal,
            param=param,
            q_rest=q_rest,
            _single_grid=_single_grid,
        )
    s = _require(robot)
    if s.arm is not None:
        rest = _q_rest(robot, s.arm, q_rest)
        return _on_robot(
            s.arm,
            analytic_batch(
                s.arm.robot,
                T,
                swivel=swivel,
                position_only=position_only,
                tol=tol,
                tol_orthonormal=tol_orthonormal,
                param=param,
                _single_grid=_single_grid,
            ),
            rest,
        )
    if q_rest is not None:
        _q_rest(robot, None, q_rest)
    if swivel is not None and not s.kind.swivel:
        raise ValueError(
            f"{robot.name}: swivel= applies to a redundant SRS arm's family of solutions; this arm "
            f"({s.form.family}) has finitely many solutions"
            + ("; its held last joint is param=" if s.form.param else "")
        )
    if param is not None and not s.form.param:
        raise ValueError(
            f"{robot.name}: param= is the value of the held last joint of a 7-joint arm solved "
            f"by its geometry; this arm ({s.form.family}) has none"
            + ("; use swivel=" if s.kind.swivel else "")
        )
    if position_only and not s.kind.position_only:
        raise ValueError(
            f"{robot.name}: a {s.form.family} arm is solved for the full pose (position and "
            "rotation); for a position alone use aa.ik.solve(robot, p, position_only=True)"
        )
    return s.kind.solve_batch(
        robot,
        s,
        T,
        swivel=swivel,
        param=param,
        position_only=position_only,
        tol=tol,
        tol_orthonormal=tol_orthonormal,
        single_grid=_single_grid,
    )


# ---------------------------------------------------------------------------- one pose
# long: the public docstring, and the one-pose fast path written inline (a ~3 µs call where
# each helper call costs 0.1–0.3 µs, measured), then the general path
def analytic(
    robot,
    T,
    *,
    swivel=None,
    position_only: bool | None = None,
    tol: float = 1e-9,
    tol_orthonormal: float = 1e-6,
    method: str = "robust",
    param=None,
    q_rest=None,
    frame=None,
):
    """Every closed-form IK solution of ``robot`` at pose ``T`` inside the joint limits.

    ``T``: 4×4 pose of ``robot.tool`` (m) — or a batch (N, 4, 4), which returns an
    :class:`AnalyticBatchResult` (same as :func:`analytic_batch`).  A planar 2R arm also takes a
    position (3,).  ``swivel`` (SRS arm, rad) a scalar or a 1-D grid; ``param`` (7-joint arm
    with its last joint held, rad) likewise.  ``method="book"`` (the prosthetic arm of
    Fig. 7-2 only) runs the book's Cramer-rule procedure :func:`prosthetic_book_procedure`,
    whose elbow determinant Δ may vanish.  A tree (joints off the path to the tool): those
    joints take their values in ``q_rest`` (nq,) (default the comfortable posture); ``frame``
    (a name or a Pinocchio frame id; default the tool) solves for another frame instead (the
    other foot of a humanoid: ``T`` is then that frame's pose).

    Returns :class:`AnalyticIKResult`: ``solutions`` (K, nq), ``branches``, ``reason`` (None,
    or why there is none: outside the workspace, joint limits, a singular pose), ``swivel``
    (SRS arm), ``residuals`` (FK check).  One pose of a closed class (a 7-joint arm at one
    ``param``) is one compiled call (≈ 3 µs from Python, limits and FK check included), as is
    one pose of an SRS arm at one swivel angle (≈ 3.5 µs) or of a planar 2R arm (≈ 2 µs); see the
    module docstring."""
    hit = robot.derived("ik.closed_form", _Entry)
    if type(T) is np.ndarray:
        arr, usual = T, T.shape == (4, 4) and T.dtype is _F64
    else:
        arr = _c_order(T)
        usual = type(arr) is np.ndarray and arr.shape == (4, 4) and arr.dtype is _F64
    if (
        usual
        and frame is None
        and q_rest is None
        and not position_only
        and method == "robust"
        and type(tol) is float
        and type(tol_orthonormal) is float
        and 0.0 < tol < _INF
        and 0.0 < tol_orthonormal < _INF
    ):
        flags = arr.flags  # what the compiled calls take without a copy
        usual = flags.c_contiguous and flags.aligned
    else:
        usual = False
    one, tried = hit.one, False
    if usual and one is _PENDING:
        one = _one_call_of(hit)
    if usual and one is not None:
        # one pose of a closed class (no tree, no other frame), of an SRS arm at one swivel
        # angle or of a planar 2R arm (position only): one compiled call, when it has a
        # solution and nothing to polish; else the general path below says what happened
        cf, ci, by_mask, holds_param, call, singular, by_swivel, by_position, shape = one
        if by_swivel:
            angle = (
                swivel
                if param is None and type(swivel) is float and -WRAP_MAX < swivel < WRAP_MAX
                else None
            )
        elif (
            swivel is None
            and (param is None) != holds_param
            and (position_only is None or not by_position)
        ):
            angle = 0.0 if param is None else _held_angle(param)
        else:
            angle = None
        if angle is not None:
            out = np.empty(shape)
            mask, tried = call.fn(cf, ci, arr, angle, tol, tol_orthonormal, out), True
            if mask > 0:
                branches, rows, res, sw = by_mask[mask]
                # positional: (solutions, branches, reason, swivel, residuals, _singular, model) — the
                # path of every single pose, where keywords cost a third of the result's construction
                return AnalyticIKResult(
                    out[rows],
                    branches[:],
                    None,
                    None if sw is None else out[sw],
                    out[res],
                    singular,
                    robot.name,
                )
    return _general(
        robot,
        hit,
        T,
        arr,
        tried,
        swivel,
        position_only,
        tol,
        tol_orthonormal,
        method,
        param,
        q_rest,
        frame,
    )


def _general(
    robot,
    hit,
    T,
    arr,
    tried,
    swivel,
    position_only,
    tol,
    tol_orthonormal,
    method,
    param,
    q_rest,
    frame,
):
    """:func:`analytic` where its one compiled call did not answer (``tried``: it was called):
    the checks, another frame, the book's procedure, a tree, a kind's one-pose call
    (:meth:`ClosedFormKind.solve_one`), else the batch path (reasons, polish, rescue)."""
    arr = _c_order(arr)
    _check_tol("tol", tol)
    _check_tol("tol_orthonormal", tol_orthonormal)
    if frame is not None:
        other = _frame_robot(robot, frame)
        if other is not robot:
            return analytic(
                other,
                T,
                swivel=swivel,
                position_only=position_only,
                tol=tol,
                tol_orthonormal=tol_orthonormal,
                method=method,
                param=param,
                q_rest=q_rest,
            )
    if method != "robust":
        return _by_book(robot, arr, method, tol, tol_orthonormal)
    s = hit.solver
    if s is not None and s.arm is not None:
        rest = _q_rest(robot, s.arm, q_rest)
        return _on_robot(
            s.arm,
            analytic(
                s.arm.robot,
                T,
                swivel=swivel,
                position_only=position_only,
                tol=tol,
                tol_orthonormal=tol_orthonormal,
                param=param,
            ),
            rest,
        )
    if q_rest is not None:
        _q_rest(robot, None, q_rest)
    if not tried and s is not None and param is None and arr.dtype == np.float64:
        fast = s.kind.solve_one(robot, s, arr, swivel, position_only, tol, tol_orthonormal)
        if fast is not None:
            return fast
    if arr.ndim == 3:
        return analytic_batch(
            robot,
            arr,
            swivel=swivel,
            position_only=position_only,
            tol=tol,
            tol_orthonormal=tol_orthonormal,
            param=param,
        )
    return analytic_batch(
        robot,
        arr,
        swivel=swivel,
        position_only=position_only,
        tol=tol,
        tol_orthonormal=tol_orthonormal,
        param=param,
        _single_grid=True,
    )[0]


def _by_book(robot, arr, method, tol, tol_orthonormal):
    """``method="book"``: the book's procedure (:func:`prosthetic_book_procedure`) on its arm."""
    if method != "book":
        raise ValueError(f"method must be 'robust' or 'book', got {method!r}")
    spec = getattr(robot, "spec", None)
    if (
        spec is None
        or spec.name not in _models.BOOK_PROCEDURES
        or robot.nq != 6
        or robot.tool != spec.tool_name
    ):
        raise ValueError(
            "method='book' (Cramer's rule, Eqs. (7-20)-(7-22)) is the book's procedure for the "
            f"prosthetic arm of Fig. 7-2 (catalog {', '.join(_models.BOOK_PROCEDURES)}; all 6 "
            "joints, its tool) only"
        )
    Ts, single = _check_poses(arr, tol_orthonormal=tol_orthonormal)
    if not single:
        raise ValueError("method='book' takes one pose")
    return _book_result(robot, Ts[0], spec.params, tol)


def nearest_solver(robot, frame=None):
    """The seeds of :func:`anthroarm.ik.solve` on an arm of a closed class at ``frame`` (default
    the tool): a function ``f(T, ref, param)`` of one pose ``T`` (4×4 C-order float array,
    base frame, m), a reference θ ``ref`` (n,) (rad) and the held 7th joint ``param`` (rad; 0.0
    for a 6-joint arm) that returns the joint angles θ (K, n) (``robot.chain.independent``
    order, rad) of the solutions :func:`analytic` returns, the one nearest ``ref`` first, with
    that one's position and rotation errors (m, rad) — or None where :func:`analytic` itself
    must answer (no solution, a malformed pose, a candidate to polish).  None for other arms.
    One compiled call (:func:`.geometric.solve_nearest`); the function holds the plan's
    packed constants, not the robot."""
    s = _at(robot, frame)
    inner = None if s is None else s.kind.nearest(s.plan)
    if inner is None:
        return None
    return (
        inner
        if s.arm is None
        else functools.partial(_nearest_on_arm, inner, s.arm.th_idx, s.arm.th_rest)
    )


def nearest_swivel_solver(robot, frame=None):
    """:func:`nearest_solver` of an SRS arm at ``frame`` (default the tool): ``f(T, ref, swivel,
    first)`` of one pose, a reference θ ``ref`` (n,) and swivel angles ``swivel`` (S,) (rad,
    finite) that returns the solutions at those angles — only at the first that has any where
    ``first`` (any solution will do) — nearest ``ref`` first, with that one's errors, or None
    (:func:`.families.srs_nearest`).  None for other arms."""
    s = _at(robot, frame)
    inner = None if s is None else s.kind.nearest_swivel(s.plan)
    if inner is None:
        return None
    return (
        inner
        if s.arm is None
        else functools.partial(_nearest_on_arm, inner, s.arm.th_idx, s.arm.th_rest)
    )


def _nearest_on_arm(inner, th_idx, th_rest, T, ref, *args):
    """:func:`nearest_solver` of a tree from its arm's (``inner``): the arm's θ put into the
    robot's, the joints off the path at ``ref`` (default ``th_rest``)."""
    base = th_rest if len(ref) == 0 else ref
    out = inner(T, base[th_idx], *args)
    if out is None:
        return None
    S = np.repeat(base[None], len(out[0]), axis=0)
    S[:, th_idx] = out[0]
    return S, out[1], out[2]
