"""Closed-form inverse kinematics of every arm whose geometry allows it, every branch.

:func:`analytic` (exported as ``aa.ik.analytic``) returns *every* joint solution of one tool
pose that lies inside the joint limits, each labelled by its branch and each verified by forward
kinematics before it is returned; :func:`analytic_batch` does the same for ``N`` poses at once.

Which closed form an arm has is read from ``robot.chain`` (never from its name), in this order:

``planar_2r`` (:mod:`.families`)
    two parallel hinges (the book's Fig. 7-14, ``planar2r``): position only, q2 by SP3 and q1 by
    SP1; 2 branches.
``srs_7r`` (:mod:`.families`)
    a redundant shoulder (3R, axes meeting) – elbow (R) – wrist (3R, axes meeting) arm (§6-3,
    ``human_arm7``), parametrised by the elbow swivel angle φ (rad; the definition of
    :func:`anthroarm.ik.qp.tasks.swivel.swivel_angle`): ``swivel=`` a scalar, an array, or
    default :data:`DEFAULT_SWIVEL`; 8 branches per swivel angle.
an IK-Geo class (:mod:`.geometric`)
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
Pinocchio holds, in joint-local frames: :func:`.geometric.local_frames`; ``tol`` on every
entry of the 3×4 pose, or the position for ``planar_2r``), duplicates dropped.  Candidates
inside the limits that are near a solution (FK residual ≤ :data:`POLISH_MAX`: an arm of its
class only within the classification tolerance, with rounded URDF numbers; a least-squares
root where a subproblem's two roots meet, at a singular pose) are polished by Newton steps on
the chain inside that call (a held 7th joint stays where it was asked to be), and the exact
ones by bounded least squares where that leaves any; a pose whose only
candidates lie on or just beyond a limit, or on a singular family whose representative is
outside the limits, is rescued along its self-motions (:func:`_rescue`).

A tree (a humanoid, two arms on a torso, an arm with a hand or a gripper): the closed form is
that of the joints on the path from the base to the tool (:class:`_Arm`, the robot reduced to
them); every other joint keeps its value in ``q_rest`` (default the comfortable posture,
:func:`anthroarm.ik.qp.tasks.posture.comfortable_posture`) — it does not move the tool.

Frames and units: ``T`` is the 4×4 pose (SE(3), metres) of the robot's tool frame
(``robot.tool``) in the base frame; joint values in radians.  A robot without a closed form
raises :class:`~anthroarm.errors.UnsupportedModelError` naming its class and pointing to
``aa.ik.solve``.  Thread-safe: per-robot plans are immutable and cached by weak reference;
Pinocchio is called with the calling thread's ``robot.data``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from .. import jit as _jit
from ..errors import UnsupportedModelError
from ..models import closed_forms as _models
from . import families as _fam
from . import geometric as _geo
from .vec3 import WRAP_MAX

TWO_PI = 2.0 * np.pi
_F64 = np.dtype(np.float64)
_INF = math.inf
#: default swivel grid of a redundant (srs_7r) arm (rad)
DEFAULT_SWIVEL = np.linspace(-np.pi, np.pi, 36, endpoint=False)
#: values of the held joint of a 7-joint arm when ``param`` is not given
PARAM_GRID = 12
#: FK residual (m / unitless) up to which a candidate is polished (an arm of its class only
#: within the classification tolerance; a singular pose)
POLISH_MAX = _geo.POLISH_MAX
PLANAR, SRS = "planar_2r", "srs_7r"


# ---------------------------------------------------------------------------- results
@dataclass
class AnalyticIKResult:
    """Every closed-form solution of one pose.

    ``solutions`` (K, nq) rad, each inside the joint limits and verified by FK;
    ``branches`` K labels; ``reason`` is None when K > 0, else why there is none;
    ``swivel`` (K,) the swivel angle of each solution (human_arm7 only, else None);
    ``residuals`` (K,) the FK check: max |FK(q) − T| over the 3×4 pose entries (m / unitless);
    :attr:`singular` says whether the solutions lie at a singular configuration."""

    solutions: np.ndarray
    branches: list
    reason: str | None = None
    swivel: np.ndarray | None = None
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: the text of :attr:`singular`, or a function of :attr:`solutions` that makes it on first use
    #: (or of the solutions it was made for: a batch row's, the arm's of a tree)
    _singular: object = field(default=None, repr=False, compare=False)
    model: str = ""

    @property
    def singular(self) -> str | None:
        """None, or what makes the pose singular: a solution whose 6×6 Jacobian has a normalised
        volume |det J| / Π‖J_k‖ ≤ :data:`.geometric.SINGULAR_TOL` (aligned wrist axes, a stretched
        elbow, the wrist centre on the first axis) — there solutions coincide in pairs or form a
        one-parameter family, of which one member is returned per branch.  Computed on first
        use (arms solved by their geometry; None for the swivel and planar families)."""
        if callable(self._singular):
            self._singular = self._singular(self.solutions)
        return self._singular

    def __getstate__(self):
        """Pickled with :attr:`singular` evaluated (its lazy maker is a closure)."""
        state = self.__dict__.copy()
        state["_singular"] = self.singular
        return state

    @property
    def success(self) -> bool:
        return len(self.branches) > 0

    def __len__(self) -> int:
        return len(self.branches)

    def as_dict(self) -> dict:
        return {
            "model": self.model,
            "solutions": self.solutions.tolist(),
            "branches": list(self.branches),
            "reason": self.reason,
            "swivel": None if self.swivel is None else self.swivel.tolist(),
            "residuals": self.residuals.tolist(),
            "singular": self.singular,
        }


@dataclass
class AnalyticBatchResult:
    """Closed-form solutions of N poses, on B fixed branches.

    ``solutions`` (N, B, nq): entry [i, b] is a verified solution inside the limits where
    ``valid[i, b]``; elsewhere it is NaN (there is no solution on that branch — read ``valid``).
    ``branches`` the B labels, ``reasons`` N entries (None where some branch is valid),
    ``swivel`` (N, B) for human_arm7, :attr:`singular` N entries.  ``result[i]`` gives pose i
    as an AnalyticIKResult.  ``solutions``, ``valid`` and ``residuals`` are read-only: a record
    of what the call found, which :attr:`singular` reads when it is first asked for (copy
    them to edit; ``result[i]`` holds copies)."""

    solutions: np.ndarray
    valid: np.ndarray
    branches: list
    reasons: list
    swivel: np.ndarray | None = None
    residuals: np.ndarray | None = None
    #: a function of the pose indices (a list) giving their :attr:`AnalyticIKResult.singular`
    #: texts, called on first use; None: never singular (the swivel and planar families)
    _singular_of: object = field(default=None, repr=False, compare=False)
    model: str = ""

    def __post_init__(self):
        for a in (self.solutions, self.valid, self.residuals):  # what `singular` reads later
            if a is not None:
                a.flags.writeable = False

    @functools.cached_property
    def singular(self) -> list:
        """:attr:`AnalyticIKResult.singular` of every pose (N entries), computed on first use."""
        n = len(self)
        return [None] * n if self._singular_of is None else self._singular_of(list(range(n)))

    def __getstate__(self):
        """Pickled with :attr:`singular` evaluated (its lazy maker is a closure)."""
        self.singular  # noqa: B018 - evaluated into __dict__
        state = self.__dict__.copy()
        state["_singular_of"] = None
        return state

    def __len__(self) -> int:
        return self.solutions.shape[0]

    def __getitem__(self, i: int) -> AnalyticIKResult:
        v = self.valid[i]
        if self._singular_of is None or "singular" in self.__dict__:
            sing = self.singular[i]
        else:
            sing = functools.partial(_pose_singular, self._singular_of, int(i))
        return AnalyticIKResult(
            solutions=self.solutions[i][v].copy(),
            branches=[b for b, ok in zip(self.branches, v) if ok],
            reason=self.reasons[i],
            swivel=None if self.swivel is None else self.swivel[i][v].copy(),
            residuals=np.zeros(int(v.sum()))
            if self.residuals is None
            else self.residuals[i][v].copy(),
            _singular=sing,
            model=self.model,
        )

    @property
    def n_solutions(self) -> np.ndarray:
        return self.valid.sum(axis=1)


def _singular_from(make, solutions, _held) -> str | None:
    """:attr:`AnalyticIKResult.singular` by ``make`` (a :class:`_SingularOf`) from the
    ``solutions`` it was made for, not those the result holds (``_held``: a tree's result holds
    the robot's configurations, its arm's maker reads the arm's θ)."""
    return make(solutions)


def _pose_singular(singular_of, i: int, _solutions) -> str | None:
    """:attr:`AnalyticIKResult.singular` of pose ``i`` of a batch, from the batch's maker
    ``singular_of`` (its solutions are those the batch holds)."""
    return singular_of([i])[0]


# ---------------------------------------------------------------------------- which closed form
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


def _cost(cls: str) -> float:
    if cls == _geo.C.GEN_SIX_DOF:
        return 3e5  # the 2-D search
    return 2e3 if cls in _geo.SEARCHED else 3.0


@dataclass(frozen=True)
class _Arm:
    """The arm of a tree: ``robot`` reduced to the joints on the path from its base to its tool
    (:func:`anthroarm.robot.reduce_model`, every other joint locked), which the closed form
    solves, and where the arm's configuration sits in the robot's: ``q_idx`` (nq_arm,) the
    robot's q index of each arm q entry, ``th_idx`` (n_arm,) the robot's θ index
    (``chain.independent`` order) of each arm θ entry; ``q_rest`` (nq,) and ``th_rest`` (n,)
    the comfortable posture, the default of the joints off the path."""

    robot: object
    q_idx: np.ndarray
    th_idx: np.ndarray
    q_rest: np.ndarray
    th_rest: np.ndarray

    def configurations(self, Qa, q_rest=None, valid=None) -> np.ndarray:
        """The robot's configurations (..., nq) of the arm's ``Qa`` (..., nq_arm): the joints off
        the path at ``q_rest`` (default :attr:`q_rest`); rows where ``valid`` (...) is False are
        NaN, as the arm's are."""
        rest = self.q_rest if q_rest is None else q_rest
        Q = np.empty(Qa.shape[:-1] + rest.shape)
        Q[...] = rest
        Q[..., self.q_idx] = Qa
        if valid is not None:
            Q[~valid] = np.nan
        return Q


def _arm_of(robot):
    """The :class:`_Arm` of ``robot`` where some of its joints are off the path to its tool (a
    mimic joint off the path that follows one on it stays in the arm, following it); None where
    every joint is on it; a text saying why where the arm cannot be cut out of the tree (a
    mimic joint on the path following one off it, a model the reduction does not take)."""
    from ..robot import Robot, reduce_model
    from .qp.tasks.posture import comfortable_posture

    ch = robot.chain
    path = ch.path(robot.tool_id)
    if all(j in path for j in ch.independent):
        return None
    if not path:
        return "no joint moves the frame"
    keep = set(path) | {j.index for j in ch.joints if j.is_mimic and j.mimic.source in path}
    try:
        model, _ = reduce_model(
            robot.model, robot.name, active=[ch.joints[j].name for j in sorted(keep)]
        )
        arm = Robot(model, name=robot.name, tool=robot.tool)
    except Exception as exc:  # noqa: BLE001 - UnsupportedModelError (a mimic pair cut), a model without frames
        return f"the arm on the path to the tool could not be cut out of the tree: {exc}"
    full = robot.model
    starts = [full.joints[full.getJointId(model.names[j])].idx_q for j in range(1, model.njoints)]
    q_idx = np.concatenate(
        [np.arange(i, i + model.joints[j].nq) for j, i in enumerate(starts, 1)]
    ).astype(int)
    pos = {ch.joints[j].name: k for k, j in enumerate(ch.independent)}
    th_idx = np.array([pos[arm.chain.joints[j].name] for j in arm.chain.independent], dtype=int)
    q_rest = comfortable_posture(robot)
    th_rest = ch.angles(q_rest)[list(ch.independent)]
    for a in (q_idx, th_idx, q_rest, th_rest):
        a.setflags(write=False)
    return _Arm(arm, q_idx, th_idx, q_rest, th_rest)


@dataclass(frozen=True)
class _Solver:
    kind: str  # "geo", "srs", "planar"
    plan: object
    form: ClosedForm
    plain: bool  # q is the joint angles themselves (no continuous joint)
    arm: _Arm | None = None  # a tree: the closed form is the arm's (its own _Solver)

    @functools.cached_property
    def one_call(self) -> _OneCall | None:
        """How :func:`analytic` answers one pose in one compiled call (:class:`_OneCall`): a
        closed class; an SRS arm at one swivel angle or a planar 2R arm (position only) whose q
        is θ; None for the others."""
        if self.kind in ("srs", "planar") and self.plain:
            cf, ci = self.plan.packed
            srs = self.kind == "srs"
            shape = (8, 12) if srs else (2, 4)
            kernel = _fam.srs_pose_solutions if srs else _fam.planar_pose_solutions
            call = _jit.entry_point(kernel, cf, ci, np.eye(4), 0.0, 1.0, 1.0, np.empty(shape))
            rows = _by_mask(self.plan.labels, 7, 9, 11) if srs else _by_mask(self.plan.labels, 2, 2)
            return _OneCall(cf, ci, rows, False, call, None, self.kind, shape)
        if self.kind != "geo" or self.plan.cls not in _geo.CLOSED:
            return None
        cf, ci = self.plan.packed
        n = int(ci[2])
        w = n if self.plain else self.plan.chain.nq
        call = _jit.entry_point(
            _geo.pose_solutions, cf, ci, np.eye(4), 0.0, 1.0, 1.0, np.empty((8, w + 4))
        )
        return _OneCall(
            cf,
            ci,
            _by_mask(self.plan.labels, w, w),
            self.plan.param_joint is not None,
            call,
            _SingularOf(self.plan, self.plain),
            self.kind,
            (8, w + 4),
        )


def _by_mask(labels, width: int, residual: int, swivel: int | None = None) -> tuple:
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


class _OneCall(NamedTuple):
    """One pose in one compiled call (:func:`analytic`): ``call(cf, ci, T, angle, tol,
    tol_orthonormal, out)`` writes the solutions into the rows of ``out`` and returns the bit
    mask of their branches (≤ 0: the general path answers) — :func:`.geometric.pose_solutions`
    (``angle`` the held 7th joint, 0.0 for none; a row: θ (n), or q (nq) where q is not θ, then
    the FK residual), :func:`.families.srs_pose_solutions` (``angle`` the swivel angle; a
    row: θ (7), the FK residual in column 9, the swivel angle in column 11) or
    :func:`.families.planar_pose_solutions` (position only; a row: θ (2), the residual)."""

    cf: np.ndarray  # the plan's packed constants
    ci: np.ndarray
    by_mask: tuple  # :func:`_by_mask` of the plan's labels and ``out``'s columns
    holds_param: bool  # a 7th joint is held (``param=``)
    call: object  # the kernel compiled for these types (:func:`anthroarm.jit.entry_point`:
    #                                      the caller checks T)
    singular: (
        _SingularOf | None
    )  # the results' lazy :attr:`AnalyticIKResult.singular` (None: never)
    kind: str  # of the :class:`_Solver`: "geo", "srs" (``angle`` is the swivel
    #                                      angle), "planar" (position only)
    shape: tuple  # of ``out``


class _SingularOf:
    """:attr:`AnalyticIKResult.singular` of one pose's solutions (K, n or nq) of a closed class,
    made on first use: the smallest normalised Jacobian volume of the K solutions
    (:func:`.geometric.jacobian_volumes`) in words (:func:`_singular_text`)."""

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
        return _singular_text(
            float(_geo.jacobian_volumes(plan, th[None], np.ones((1, K), bool)).min())
        )


_PENDING = object()


class _Entry:
    """What :func:`analytic` keeps on a robot (:meth:`~anthroarm.robot.Robot.derived`): its
    :class:`_Solver` at its tool or None, and the solver's :attr:`_Solver.one_call` where
    :func:`analytic` may answer one pose by it (no tree; made on the first such pose,
    :data:`_PENDING` until then), else None."""

    __slots__ = ("solver", "one")

    def __init__(self, robot):
        self.solver = _new_solver(robot)
        self.one = None if self.solver is None or self.solver.arm is not None else _PENDING


def _solver(robot):
    """The :class:`_Solver` of ``robot`` at its tool (kept on the robot), or None."""
    return robot.derived("ik.closed_form", _Entry).solver


def _one_call_of(entry: _Entry) -> _OneCall | None:
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
    out = None
    pl = _fam.planar_plan(robot)
    if pl is not None:
        out = _Solver(
            "planar", pl, ClosedForm(PLANAR, 2, 2, position_only=True, cost_us=2.0), plain
        )
    if out is None:
        sp = _fam.srs_plan(robot)
        if sp is not None:
            out = _Solver("srs", sp, ClosedForm(SRS, 7, 8, swivel=True, cost_us=4.0), plain)
    if out is None:
        gp = _geo.plan_for(robot)
        if gp is not None:
            out = _Solver(
                "geo",
                gp,
                ClosedForm(
                    gp.cls,
                    len(gp.fk_axes),
                    _geo.n_branches(gp.cls),
                    param=gp.param_joint is not None,
                    cost_us=_cost(gp.cls),
                ),
                plain,
            )
    return out


def _no_others(robot) -> dict:
    return {}


def _retooled(robot, frame):
    """``robot`` itself where ``frame`` (a name or a Pinocchio frame id; None: the tool) is its
    tool, else the same model with ``frame`` as its tool (another tip of a tree: the other
    foot, the other hand; the same spec, so the same comfortable posture), made once per
    (robot, frame) and kept with the robot; None where that frame's name is also an earlier
    frame's (a tool is named, so it would be the other one).  Unknown frames raise
    :class:`~anthroarm.errors.UnknownFrameError`."""
    if frame is None:
        return robot
    f = robot.chain.frame(frame)
    if f.index == robot.tool_id:
        return robot
    from ..robot import Robot

    others = robot.derived("ik.closed_form.retooled", _no_others)  # frame id -> Robot or None
    if f.index not in others:
        other = Robot(
            robot.model,
            name=robot.name,
            tool=f.name,
            info=robot.info,
            spec=robot.spec,
            locked=robot.locked,
        )
        others[f.index] = other if other.tool_id == f.index else None
    return others[f.index]


def _unnamed(robot, frame) -> str:
    f = robot.chain.frame(frame)
    return (
        f"{robot.name}: frame {f.index} shares its name {f.name!r} with frame {robot.chain.frame(f.name).index}; "
        "the closed form solves for a frame known by its name: use aa.ik.solve(robot, T, frame=...)"
    )


def _frame_robot(robot, frame):
    """:func:`_retooled`, or :class:`~anthroarm.errors.UnsupportedModelError` where ``frame`` has
    no closed form of its own (its name is an earlier frame's)."""
    other = _retooled(robot, frame)
    if other is None:
        raise UnsupportedModelError(_unnamed(robot, frame))
    return other


def _at(robot, frame):
    """The solver for ``frame`` (default the tool), or None."""
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
    if s is None or s.kind != "geo" or s.plan.param_joint is None:
        return None
    k = s.plan.order.tolist().index(s.plan.param_joint)
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


def _q_rest(robot, arm, q_rest) -> np.ndarray | None:
    """The configuration (nq,) whose joints off the tool's path a tree's solutions keep:
    ``q_rest`` checked (``robot.check_q``), else the arm's default (its comfortable posture)."""
    if q_rest is None:
        return None if arm is None else arm.q_rest
    q = robot.check_q(q_rest, name="q_rest")
    if q.ndim != 1:
        raise ValueError(
            f"{robot.name}: q_rest is one configuration, shape ({robot.nq},), got shape {q.shape}"
        )
    if arm is not None:
        off = np.setdiff1d(np.arange(robot.nq), arm.q_idx)
        bad = off[(q[off] < robot.lower[off]) | (q[off] > robot.upper[off])]
        if len(bad):
            names = robot.chain.q_names
            raise ValueError(
                f"{robot.name}: q_rest puts {', '.join(names[i] for i in bad)} outside the joint limits "
                "(the solutions keep its joints off the tool's path, and every solution is inside them)"
            )
    return q


def _on_robot(arm: _Arm, res, q_rest):
    """A result of the arm of a tree as the robot's: every solution a configuration of the
    robot, the joints off the path at ``q_rest``."""
    if isinstance(res, AnalyticBatchResult):
        return replace(res, solutions=arm.configurations(res.solutions, q_rest, res.valid))
    sing = (
        functools.partial(_singular_from, res._singular, res.solutions)
        if callable(res._singular)
        else res._singular
    )
    return replace(res, solutions=arm.configurations(res.solutions, q_rest), _singular=sing)


def require_form(robot, frame=None) -> ClosedForm:
    """:func:`closed_form_info` of ``robot``, or :class:`~anthroarm.errors.UnsupportedModelError`
    saying why it has no closed form (and pointing to ``aa.ik.solve``)."""
    s = _at(robot, frame)
    if s is None:
        r = _retooled(robot, frame)
        raise UnsupportedModelError(_unnamed(robot, frame) if r is None else _why_not(r))
    return s.form


# ---------------------------------------------------------------------------- input checks
def _check_poses(
    T, name="T", tol_orthonormal=1e-6, position_only=False, rigid=True
) -> tuple[np.ndarray, bool]:
    """Return (N, 4, 4) and whether the input was a single pose.  ValueError on bad input:
    the shape, a value that is not finite, and (``rigid``) the last row and the rotation part
    (``rigid=False``: the caller's compiled solver checks those, :class:`.geometric.BadPoseError`)."""
    arr = np.asarray(T, dtype=float)
    single = arr.ndim == 2
    if position_only and arr.ndim in (1, 2) and arr.shape[-1] == 3 and arr.shape != (3, 3):
        single = arr.ndim == 1
        P = arr.reshape(-1, 3)
        arr = np.tile(np.eye(4), (P.shape[0], 1, 1))
        arr[:, :3, 3] = P
    elif arr.ndim == 2 and arr.shape == (4, 4):
        arr = arr[None]
    elif not (arr.ndim == 3 and arr.shape[1:] == (4, 4)):
        raise ValueError(
            f"{name} must be a 4x4 homogeneous pose or a batch (N, 4, 4), got shape {arr.shape}"
        )
    if arr.shape[0] == 0:
        return arr, single  # an empty batch: an empty result
    if not np.isfinite(arr).all():
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(
            f"{name}{list(idx) if not single else list(idx[1:])} is {arr[idx]} (not finite)"
        )
    if not rigid:
        return arr, single
    if np.abs(arr[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max() > 1e-12:
        raise ValueError(f"{name}: the last row of a homogeneous pose must be [0, 0, 0, 1]")
    R = arr[:, :3, :3]
    err = np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    det = (
        np.linalg.det(R)
        if len(R) < 64
        else np.einsum("ni,ni->n", R[:, :, 0], np.cross(R[:, :, 1], R[:, :, 2]))
    )
    bad = (err > tol_orthonormal) | (det < 0)
    if not position_only and bad.any():
        i = int(np.argmax(bad))
        where = "" if single else f"[{i}]"
        raise ValueError(
            f"{name}{where}: the rotation part is not a rotation matrix (max |R^T R - I| = {err[i]:.3g}, "
            f"det = {det[i]:.6g}); orthonormalise it first (e.g. nearest rotation by SVD)"
        )
    return arr, single


def _detail_bad_pose(Ts, i, single, tol_orthonormal):
    """Raise :func:`_check_poses`'s detailed ValueError for pose ``i`` of ``Ts``, named as the
    caller indexed it — the pose a compiled call found malformed (its
    :class:`.geometric.BadPoseError` says only which)."""
    _check_poses(Ts[i], name="T" if single else f"T[{i}]", tol_orthonormal=tol_orthonormal)


# ---------------------------------------------------------------------------- helpers


def _fk_residual(robot, Qw, Ts, position_only):
    """max |FK(q) − T| (3×4 entries, or position) of candidates Qw (N, B, nq) against Ts (N, 4, 4),
    +inf for a non-finite candidate.  Few candidates: Pinocchio's FK (one C++ call each, the
    calling thread's ``robot.data``); many: the batched chain FK (``robot.chain.serial``)."""
    import pinocchio as pin

    N, B = Qw.shape[:2]
    finite = np.isfinite(Qw).all(-1)
    if N * B > 64:
        Tf = robot.chain.serial(robot.tool).fk(
            np.where(finite[..., None], Qw, 0.0).reshape(N * B, -1)
        )
        Tf = Tf.reshape(N, B, 4, 4)
        d = np.abs(Tf[..., :3, 3] - Ts[:, None, :3, 3]).max(-1)
        if not position_only:
            d = np.maximum(d, np.abs(Tf[..., :3, :3] - Ts[:, None, :3, :3]).max(axis=(-1, -2)))
        return np.where(finite, d, np.inf)
    model, data, fid = robot.model, robot.data, robot.tool_id
    res = np.empty((N, B))
    for i in range(N):
        Ti = Ts[i]
        for b in range(B):
            if not finite[i, b]:
                res[i, b] = np.inf
                continue
            pin.framesForwardKinematics(model, data, Qw[i, b])
            M = data.oMf[fid]
            e = np.abs(M.translation - Ti[:3, 3]).max()
            if not position_only:
                e = max(e, np.abs(M.rotation - Ti[:3, :3]).max())
            res[i, b] = e
    return res


def _swivel_array(swivel, N, grid_1d=False):
    """(N, S) swivel angles.  Batch rule: scalar -> every pose; 1-D -> one angle per pose
    (length N), unless ``grid_1d`` (single-pose call: a 1-D array is a grid); 2-D (N, S) or
    (1, S) -> a grid per pose; None -> :data:`DEFAULT_SWIVEL` for every pose."""
    if swivel is None:
        return np.broadcast_to(DEFAULT_SWIVEL[None, :], (N, DEFAULT_SWIVEL.size)).copy()
    if type(swivel) is float and abs(swivel) < WRAP_MAX:  # the usual one angle: no numpy checks
        sw = np.empty((N, 1))
        sw.fill(swivel)
        return sw
    sw = np.asarray(swivel, dtype=float)
    if not (np.abs(sw) < WRAP_MAX).all():
        raise ValueError(
            f"swivel must be finite angles (rad) of magnitude below {WRAP_MAX:g}, got {swivel!r}"
        )
    if sw.ndim == 0:
        return np.full((N, 1), float(sw))
    if sw.ndim == 1 and grid_1d:
        sw = sw[None, :]
    elif sw.ndim == 1:
        if sw.shape[0] != N:
            raise ValueError(
                f"swivel: a 1-D array gives one angle per pose and must have length N = {N}, "
                f"got {sw.shape[0]} (pass shape (1, S) for a grid shared by all poses)"
            )
        return sw[:, None].copy()
    if sw.ndim == 2 and sw.shape[0] in (1, N) and sw.shape[1] >= 1:
        return np.broadcast_to(sw, (N, sw.shape[1])).copy()
    raise ValueError(
        f"swivel must be a scalar, shape (N,), (1, S) or (N, S) with N = {N}, got {sw.shape}"
    )


# ---------------------------------------------------------------------------- batches
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
    if s.kind != "srs" and swivel is not None:
        raise ValueError(
            f"{robot.name}: swivel= applies to a redundant SRS arm's family of solutions; this arm "
            f"({s.form.family}) has finitely many solutions"
            + ("; its held last joint is param=" if s.form.param else "")
        )
    if s.kind != "geo" or not s.form.param:
        if param is not None:
            raise ValueError(
                f"{robot.name}: param= is the value of the held last joint of a 7-joint arm solved "
                f"by its geometry; this arm ({s.form.family}) has none"
                + ("; use swivel=" if s.kind == "srs" else "")
            )
    if s.kind == "planar":
        return _planar_batch(robot, s, T, position_only, tol)
    if position_only:
        raise ValueError(
            f"{robot.name}: a {s.form.family} arm is solved for the full pose (position and "
            "rotation); for a position alone use aa.ik.solve(robot, p, position_only=True)"
        )
    closed = s.kind == "geo" and s.plan.cls in _geo.CLOSED
    # a closed class and the SRS family check the rotations in their compiled call
    Ts, single = _check_poses(
        T, tol_orthonormal=tol_orthonormal, rigid=not (closed or s.kind == "srs")
    )
    N = Ts.shape[0]
    if s.kind == "srs":
        grid = _swivel_array(swivel, N, grid_1d=single or _single_grid)
        labels = _grid_labels(s.plan.labels, grid.shape[1], "swivel")
        if N == 0:
            return _empty(robot, labels, swivel=True)
        try:
            th, cand, exact, inside, res, ok = _fam.srs_verified(
                s.plan, Ts, grid, tol, tol_orthonormal
            )
        except _geo.BadPoseError as exc:
            _detail_bad_pose(Ts, exc.index, single, tol_orthonormal)
            raise
        sw = np.repeat(grid, len(s.plan.labels), axis=1)
        return _finish(
            robot, s, Ts, th, cand, exact, inside, res, ok, labels, tol, False, swivel=sw
        )
    gp = s.plan
    if gp.param_joint is not None:
        if param is None:  # a grid over the held joint's range
            k = gp.order.tolist().index(gp.param_joint)
            lo, hi = (max(gp.lower[k], -np.pi), min(gp.upper[k], np.pi))
            param = (np.linspace(lo, hi, PARAM_GRID + 1)[:-1] + 0.5 * (hi - lo) / PARAM_GRID)[None]
        try:
            pv = _swivel_array(param, N, grid_1d=single or _single_grid)
        except ValueError as exc:
            raise ValueError(str(exc).replace("swivel", "param")) from None
    else:
        pv = np.zeros((N, 1))
    S = pv.shape[1]
    labels = _grid_labels(gp.labels, S, "param")
    if N == 0:
        return _empty(robot, labels)
    B = len(labels)
    Tr = Ts if S == 1 else np.repeat(Ts, S, axis=0)
    prm = pv.reshape(-1) if gp.param_joint is not None else None
    if closed:
        try:
            out = _geo.solve_verified(gp, Tr, prm, tol, tol_orthonormal)
        except _geo.BadPoseError as exc:
            _detail_bad_pose(Ts, exc.index // S, single, tol_orthonormal)
            raise
        th, valid, cand, exact, inside, res, conf = (a.reshape((N, B) + a.shape[2:]) for a in out)
    else:
        th, cand, exact = (a.reshape((N, B) + a.shape[2:]) for a in _geo.solve(gp, Tr, prm))
        th, inside = _geo.wrap_into_limits(th, gp.lower, gp.upper)
        cand = cand & np.isfinite(th).all(-1)
        Q = gp.chain.configuration(np.where(cand[..., None], th, 0.0))
        res = np.where(cand, _fk_residual(robot, Q, Ts, False), np.inf)
        valid = conf = None
    return _finish(robot, s, Ts, th, cand, exact, inside, res, valid, labels, tol, False, conf=conf)


def _grid_labels(labels, S, what):
    return list(labels) if S == 1 else [f"{b},{what}#{k}" for k in range(S) for b in labels]


def _empty(robot, labels, swivel=False):
    B = len(labels)
    return AnalyticBatchResult(
        np.zeros((0, B, robot.nq)),
        np.zeros((0, B), bool),
        labels,
        [],
        swivel=np.zeros((0, B)) if swivel else None,
        residuals=np.zeros((0, B)),
        model=robot.name,
    )


def _planar_batch(robot, s, T, position_only, tol):
    """``planar_2r``: positions from ``T`` (N, 4, 4), (N, 3) or (3,); the rotation is compared
    only with ``position_only=False`` (it is then a 2-DOF constraint on a 3-D rotation)."""
    po = True if position_only is None else bool(position_only)
    Ts, _ = _check_poses(T, position_only=po)
    N = Ts.shape[0]
    labels = list(s.plan.labels)
    if N == 0:
        return _empty(robot, labels)
    th, cand, exact, inside, res, ok = _fam.planar_verified(
        s.plan, np.ascontiguousarray(Ts[:, :3, 3]), tol
    )
    if not po:  # the rotation too: Pinocchio's residuals, solutions marked again
        Q = s.plan.chain.configuration(np.where(cand[..., None], th, 0.0))
        res = np.where(cand, _fk_residual(robot, Q, Ts, False), np.inf)
        ok = None
    return _finish(robot, s, Ts, th, cand, exact, inside, res, ok, labels, tol, po)


def _finish(
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
    position_only,
    swivel=None,
    conf=None,
):
    """From the compiled solver's branches to the result: configurations (``conf``, where the
    compiled call made them), polish of near-exact candidates, duplicates, the rescue of poses
    whose candidates lie on a limit, reasons."""
    N, B = cand.shape
    ch = robot.chain
    Q = (
        th if s.plain else conf if conf is not None else ch.configuration(th)
    )  # NaN below where no solution
    res = np.array(res, dtype=float)
    # near-exact candidates inside the limits, exact or not: a subproblem's least-squares root
    # at a singular pose (flagged inexact) is within √ε of a solution, which the polish finds
    near = cand & inside & (res > tol) & (res <= POLISH_MAX)
    polished = bool(near.any()) and s.plain
    if polished:
        Q = np.array(Q)
        for i, b in zip(*np.nonzero(near)):
            Q[i, b], res[i, b] = _refine(
                robot, Q[i, b], Ts[i], robot.lower, robot.upper, position_only
            )
    if valid is None or polished:
        valid = _geo.mark_solutions(Q if polished else th, cand, inside, res, tol, s.form.branches)
    else:
        valid = np.array(valid)
    none = ~valid.any(1)  # poses without a solution
    if s.kind != "srs" and s.plain and none.any():
        todo = np.flatnonzero(none & (cand & (exact | (res <= POLISH_MAX)) & ~inside).any(1))
        if todo.size:
            Q = np.array(Q)
            for i in todo:
                for b, q, r in _rescue(
                    robot,
                    Q[i],
                    cand[i] & (exact[i] | (res[i] <= POLISH_MAX)) & ~inside[i],
                    Ts[i],
                    tol,
                    position_only,
                ):
                    Q[i, b], valid[i, b], res[i, b], inside[i, b] = q, True, r, True
    reasons = [None] * N
    for i in np.flatnonzero(~valid.any(1)) if none.any() else ():
        reasons[i] = _reason(
            robot, s, Ts[i], cand[i], exact[i], inside[i], res[i], tol, position_only
        )
    singular_of = None
    if s.kind == "geo":
        TH = Q if polished else th  # polished: a plain arm, Q = θ
        plan = s.plan

        def singular_of(rows):
            vol = _geo.jacobian_volumes(plan, TH[rows], valid[rows]).min(1)
            return [_singular_text(float(v)) for v in vol]

    # Q and res are this call's own arrays (the compiled call's, or copies): NaN in place where
    # no solution (a new 8·n·N array would cost more than the rest of this function)
    _geo.blank_unsolved(Q, res, valid)
    return AnalyticBatchResult(
        solutions=Q,
        valid=valid,
        branches=labels,
        reasons=reasons,
        swivel=None if swivel is None else np.where(valid, swivel, np.nan),
        residuals=res,
        _singular_of=singular_of,
        model=robot.name,
    )


#: an FK residual (m / unitless) up to which a pose without a solution is reported as a near miss
#: (rounding of the pose, not the workspace) by :func:`_reason`
NEAR_MISS = 1e-6


def _reason(robot, s, T, cand, exact, inside, res, tol, position_only) -> str:
    """Why pose ``T`` has no solution, from its branches' flags."""
    fam = s.form.family
    if s.kind == "planar":
        off = abs(float(s.plan.h1 @ (T[:3, 3] - s.plan.p_tool)))
        if off > tol:
            return (
                f"outside the workspace: the target is {off:.3g} m off the plane of motion of the "
                "mechanism (normal to its parallel axes)"
            )
    if not (cand & exact).any():
        best = float(np.min(res)) if np.isfinite(res).any() else float("inf")
        if best <= NEAR_MISS:
            return (
                f"not reached to tol = {tol:g}: the best candidate leaves an FK residual of {best:.3g} "
                "(the pose is not a rigid transform to that precision — a single-precision pose, a rotation "
                "orthonormal only to ~1e-8 — or lies that close to the workspace boundary); pass a larger tol "
                "to accept it"
            )
        return (
            f"outside the workspace: no branch of the {fam} closed form reaches this pose (its "
            f"subproblems have least-squares answers only; best FK residual {best:.3g})"
        )
    if not (cand & exact & inside).any():
        ch = (
            robot.chain
        )  # limits of the joints solved for (θ, not q: a continuous joint is cos, sin in q)
        joints = [ch.joints[j] for j in ch.independent]
        return (
            f"all {int((cand & exact).sum())} closed-form solutions violate the joint limits ("
            + ", ".join(
                f"{j.name} continuous"
                if j.kind == "continuous"
                else f"{j.name} [{j.lower:.4g}, {j.upper:.4g}]"
                for j in joints
            )
            + ")"
        )
    worst = float(np.min(np.where(cand & exact & inside, res, np.inf)))
    text = (
        f"no candidate passed the FK check (best residual {worst:.3g} > tol {tol:g}); the pose is at a "
        "singularity or not reachable with this orientation"
    )
    if s.kind == "geo":
        c = s.plan.classification
        if max(c.worst_accepted) > 0:
            text += (
                f", or the arm is {fam} only within the classification tolerance (axes up to "
                f"{c.worst_accepted[0]:.3g} m / sine {c.worst_accepted[1]:.3g} from the exact relation)"
            )
    return text


def _rescue(robot, Q, which, T, tol, position_only):
    """Solutions of one pose (4×4) whose closed-form candidates ``Q[which]`` lie on or just
    beyond a limit.  Each is moved along its exact self-motions (:func:`_slide_into_limits`: a
    straight elbow, the shoulder or the wrist at a singularity, where the closed form returns
    one representative of a one-parameter family) and, if it is then within
    :data:`LIMIT_SLACK` of the limits, clipped onto them and polished (the candidates at such
    poses carry ≈ √ε errors).  Kept if it passes the FK check ``tol``.  Returns
    ``[(branch, q, residual)]``."""
    lo, hi = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
    rows = slice(0, 3) if position_only else slice(None)
    out = []
    for b in np.flatnonzero(which):
        J = np.asarray(robot.jacobian(Q[b]))
        revolute = np.abs(J[3:]).max(0) > 0.0  # a prismatic joint turns nothing
        q = _slide_into_limits(_turns_into_limits(Q[b], revolute, lo, hi), J[rows], lo, hi)
        if q is None:
            continue
        q, res = _refine(robot, np.clip(q, lo, hi), T, lo, hi, position_only, polish=False)
        if res > 1e-6:  # not a near-solution: skip the polish
            continue
        q, res = _refine(robot, q, T, lo, hi, position_only)
        if res <= tol and all(np.abs(q - k[1]).max() >= 1e-9 for k in out):
            out.append((int(b), q, res))
    return out


# ---------------------------------------------------------------------------- one pose
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
        cf, ci, by_mask, holds_param, call, singular, kind, shape = one
        srs = kind == "srs"
        if srs:
            angle = (
                swivel
                if param is None and type(swivel) is float and -WRAP_MAX < swivel < WRAP_MAX
                else None
            )
        elif (
            swivel is None
            and (param is None) != holds_param
            and (position_only is None or kind != "planar")
        ):
            angle = 0.0 if param is None else _held_angle(param)
        else:
            angle = None
        if angle is not None:
            out = np.empty(shape)
            mask, tried = call(cf, ci, arr, angle, tol, tol_orthonormal, out), True
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
    if (
        not tried
        and s is not None
        and s.kind != "geo"
        and param is None
        and arr.dtype == np.float64
        and (arr.shape == (4, 4) or (s.kind == "planar" and arr.shape == (3,)))
    ):
        fast = _family_single(robot, s, arr, swivel, position_only, tol, tol_orthonormal)
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
    if s is None or s.kind != "geo" or s.plan.cls not in _geo.CLOSED:
        return None
    cf, ci = s.plan.packed
    inner = functools.partial(_geo.solve_nearest, cf, ci)
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
    if s is None or s.kind != "srs":
        return None
    inner = functools.partial(_fam.srs_nearest, s.plan)
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


def _srs_single(robot, s, arr, swivel, tol, tol_orthonormal):
    """One pose ``arr`` (4×4, C order) of an SRS arm at ``swivel`` (a scalar or a 1-D grid;
    default :data:`DEFAULT_SWIVEL`) in one compiled call (:func:`.families.srs_solutions`), when
    it has a solution and nothing to polish — the same solutions, labels and order as
    :func:`analytic_batch`; else None (a malformed pose or swivel, no solution: the batch path
    says what happened)."""
    try:
        grid = _swivel_array(swivel, 1, grid_1d=True)[0]
        got = _fam.srs_solutions(s.plan, arr, grid, tol, tol_orthonormal)
    except ValueError:
        return None
    if got is None:
        return None
    q, res, rows, angles = got
    labels = s.plan.labels if len(grid) == 1 else _grid_labels(s.plan.labels, len(grid), "swivel")
    return AnalyticIKResult(
        q if s.plain else s.plan.chain.configuration(q),
        [labels[r] for r in rows],
        None,
        angles,
        res,
        None,
        robot.name,
    )


def _family_single(robot, s, arr, swivel, position_only, tol, tol_orthonormal):
    """One pose of an SRS arm (:func:`_srs_single`) or a planar 2R arm (position only: a 4×4
    pose or a position (3,); :func:`.families.planar_pose_solutions`) in one compiled call, when
    it has a solution and nothing to polish — the same solutions, labels and order as
    :func:`analytic_batch`, without its batch bookkeeping; else None (the batch path answers,
    with the reasons and the polish)."""
    if s.kind == "srs":
        return None if position_only else _srs_single(robot, s, arr, swivel, tol, tol_orthonormal)
    if position_only is False:
        return None
    if arr.shape == (3,):  # a position: the pose the planar kernel reads it from
        pose = np.eye(4)
        pose[:3, 3] = arr
    else:
        pose = arr
    cf, ci = s.plan.packed
    out = np.empty((2, 4))
    mask = _fam.planar_pose_solutions(cf, ci, pose, 0.0, float(tol), float(tol_orthonormal), out)
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


def _held_angle(param) -> float | None:
    """A held joint's value ``param`` as a float angle, or None where it is not one (the batch
    path says what is wrong)."""
    try:
        prm = float(param)
    except (TypeError, ValueError):
        return None
    return prm if abs(prm) < WRAP_MAX else None


def _singular_text(volume: float) -> str | None:
    """None, or what a normalised Jacobian volume ≤ :data:`.geometric.SINGULAR_TOL` of a
    solution (:func:`.geometric.jacobian_volumes`) means, in words."""
    if volume > _geo.SINGULAR_TOL:
        return None
    return (
        f"a singular configuration (normalised |det J| = {volume:.2g}: aligned wrist axes, a stretched "
        "elbow or the wrist centre on the first axis): solutions coincide in pairs or form a one-parameter "
        "family, one member is returned per branch"
    )


# ---------------------------------------------------------------------------- the book's procedure
def prosthetic_book_procedure(
    T,
    L1: float = 0.340,
    L2: float = 0.260,
    L3: float = 0.130,
    *,
    det_tol: float = 1e-9,
    printed_m2: bool = False,
):
    """The book's prosthetic-arm IK exactly as printed (corrected), Eqs. (7-17)–(7-31), Fig. 7-3.

    Elbow by Cramer's rule (7-20)/(7-21) (coefficient A with m3, not the printed m2) and the
    quadratic (7-22); θ1 = atan2(yE, xE) (7-18), θ2 = acos(−zE/L1) (7-19), θ4 (7-24),
    θ3 = asin(...) (7-27), θ6 = asin r3 (7-30), θ5 = atan2(r2, r1) (7-31, r2 with −cθ2cθ3).
    Units: whatever ``T`` and the lengths use (the book: mm).  Returns (solutions, reason):
    ``solutions`` a list of two 6-vectors (rad; the two elbow roots, not limit-filtered) or
    empty with ``reason`` ("elbow determinant Δ = 0", "outside workspace", "s2·s4 = 0").
    ``printed_m2=True`` uses the printed numerator "m2/2 (L1² + L3² + L0² − L2²)" of A (a
    misprint, kept to show that it fails; docs/errata.md)."""
    T = np.asarray(T, float)
    l1_, l2_, l3_ = T[:3, 0]
    m1, m2, m3 = T[:3, 1]
    n1, n2, n3 = T[:3, 2]
    x, y, z = T[:3, 3]
    L0s = x * x + y * y + z * z
    K0 = 0.5 * (L1**2 + L3**2 + L0s - L2**2)
    nC = n1 * x + n2 * y + n3 * z
    mC = m1 * x + m2 * y + m3 * z
    Delta = m3 * x - m1 * z + L3 * (m1 * n3 - m3 * n1)
    scale = max(1.0, abs(x) + abs(y) + abs(z))
    if abs(Delta) <= det_tol * scale:
        return [], (
            f"elbow determinant Δ = m3·x − m1·z + L3(m1·n3 − m3·n1) = {Delta:.3g} ≈ 0: "
            "Cramer's rule (7-20)/(7-21) cannot solve the elbow (use the robust solver)"
        )
    A = ((m2 if printed_m2 else m3) * K0 - L3 * m3 * nC - mC * (z - L3 * n3)) / Delta
    B = (m2 * z - m3 * y + L3 * (m3 * n2 - m2 * n3)) / Delta
    Cc = (mC * (x - L3 * n1) + L3 * m1 * nC - m1 * K0) / Delta
    D = (m1 * y - m2 * x + L3 * (m2 * n1 - m1 * n2)) / Delta
    E = B * B + D * D + 1
    F = 2 * (A * B + Cc * D)
    G = A * A + Cc * Cc - L1**2
    disc = F * F - 4 * E * G
    if disc < 0:
        return [], "no elbow position: F² − 4EG < 0 in (7-22)"
    xW, yW, zW = x - L3 * n1, y - L3 * n2, z - L3 * n3
    c4 = (xW**2 + yW**2 + zW**2 - (L1**2 + L2**2)) / (2 * L1 * L2)
    if abs(c4) > 1:
        return [], "outside workspace: |cos θ4| > 1 in (7-24)"
    th4 = np.arccos(c4)
    sols = []
    for sgn in (1.0, -1.0):
        yE = (-F + sgn * np.sqrt(disc)) / (2 * E)
        xE, zE = A + B * yE, Cc + D * yE
        th1 = np.arctan2(yE, xE)
        th2 = np.arccos(np.clip(-zE / L1, -1, 1))
        c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
        s4 = np.sin(th4)
        if abs(s2 * s4) < 1e-12:
            return [], "singular: s2·s4 = 0 in (7-27) (arm vertical or straight)"
        th3 = np.arcsin(np.clip((zW + L2 * c2 * c4 + L1 * c2) / (L2 * s2 * s4), -1, 1))
        c3, s3 = np.cos(th3), np.sin(th3)
        P1 = l1_ * c1 + l2_ * s1
        Q1 = l1_ * s1 - l2_ * c1
        r1 = P1 * (s2 * s4 - c2 * s3 * c4) - l3_ * (s2 * s3 * c4 + c2 * s4) + c3 * c4 * Q1
        r2 = -c2 * c3 * P1 - l3_ * s2 * c3 - s3 * Q1
        r3 = P1 * (c2 * s3 * s4 + s2 * c4) + l3_ * (s2 * s3 * s4 - c2 * c4) - c3 * s4 * Q1
        th6 = np.arcsin(np.clip(r3, -1, 1))
        th5 = np.arctan2(r2, r1)
        sols.append(np.array([th1, th2, th3, th4, th5, th6]))
    return sols, None


def _book_result(robot, T, prm, tol):
    sols, reason = prosthetic_book_procedure(T, prm["L1"], prm["L2"], prm["L3"])
    if not sols:
        return AnalyticIKResult(np.zeros((0, robot.nq)), [], reason, model=robot.name)
    Q = np.array(sols)
    Qw, inside = _geo.wrap_into_limits(Q, robot.lower, robot.upper)
    res = _fk_residual(robot, Qw[None], T[None], False)[0]
    ok = inside & (res <= tol)
    labels = ["elbow_root=+", "elbow_root=-"]
    if not ok.any():
        why = (
            "the book's asin-based θ3/θ6 (7-27)/(7-30) give no FK-consistent solution inside the limits "
            f"(residuals {', '.join(f'{r:.3g}' for r in res)}); use method='robust'"
        )
        return AnalyticIKResult(
            np.zeros((0, robot.nq)), [], why, residuals=np.zeros(0), model=robot.name
        )
    return AnalyticIKResult(
        Qw[ok], [lb for lb, k in zip(labels, ok) if k], None, residuals=res[ok], model=robot.name
    )


# ---------------------------------------------------------------------------- poses on the limits
#: how far (rad) a closed-form candidate may lie outside a joint limit and still be kept, clipped
#: onto the limit and polished (see :func:`_rescue_pose`).  The closed forms lose precision at
#: double roots and singular configurations — an arccos near ±1, a square root of a discriminant
#: near 0 — where a joint is determined by the pose only to ≈ √ε ≈ 1.5e-8 rad; a configuration with
#: a joint exactly on its limit then yields a candidate up to a few 1e-8 rad beyond it.  1e-6 rad
#: covers that with margin; every kept candidate still passes the FK check (``tol``).
LIMIT_SLACK = 1e-6


def _c_order(T) -> np.ndarray:
    """``T`` as an array in C order (the compiled calls take C order): a list as floats, an
    array as it is (its dtype checked later), a strided view copied."""
    arr = T if isinstance(T, np.ndarray) else np.asarray(T, dtype=float)
    return arr if arr.flags.c_contiguous else np.ascontiguousarray(arr)


def _check_tol(name, value):
    """``tol`` / ``tol_orthonormal``: a finite positive number, else ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name} must be a positive number, got {type(value).__name__} {value!r}")
    if not (math.isfinite(float(value)) and float(value) > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


def _turns_into_limits(q, revolute, lo, hi):
    """``q`` with each revolute joint turned by the multiple of 2π that brings it nearest its
    limits (a copy).  A joint on a limit comes out of the closed form as often at the limit
    ± 2π, which the exact wrap of the compiled call puts an ulp outside (−π/2 as 3π/2 − 2π)."""
    q = np.array(q, dtype=float)
    for i in np.flatnonzero(revolute):
        k = np.arange(-2, 3)
        x = q[i] + TWO_PI * k
        out = np.maximum(lo[i] - x, x - hi[i]).clip(0.0)
        q[i] = x[int(np.argmin(out))]
    return q


def _slide_into_limits(q, J, lo, hi):
    """Move ``q`` along its exact self-motions into the limits, or return None.

    Two revolute joints i, j whose axes are the same line at ``q`` (columns J[:, i] = s·J[:, j]
    of the tool Jacobian, s = ±1: the shoulder at θ2 = 0/π, a straight elbow, a wrist at
    sin θ5 = 0) leave the tool pose unchanged under q_i += t, q_j −= s·t for every t (the links
    between them turn about the common axis, which that turn maps onto itself).  The smallest |t|
    (with 2π shifts of either joint) that brings both inside their limits is chosen."""
    q = q.copy()
    nq = q.size
    scale = max(float(np.abs(J).max()), 1e-300)

    def outside(v):
        return float(np.maximum(lo - v, v - hi).clip(0.0).max())

    for _ in range(2):  # at most two families (shoulder and elbow) at once
        if outside(q) <= LIMIT_SLACK:
            return q
        moved = False
        for i in range(nq):
            for j in range(i + 1, nq):
                bad_ij = max(lo[i] - q[i], q[i] - hi[i], lo[j] - q[j], q[j] - hi[j]) > LIMIT_SLACK
                if not bad_ij:
                    continue
                for s in (1.0, -1.0):
                    if np.abs(J[:, i] - s * J[:, j]).max() > 1e-6 * scale:
                        continue
                    best = None
                    for ki in (-1, 0, 1):
                        for kj in (-1, 0, 1):
                            a, b = lo[i] + TWO_PI * ki - q[i], hi[i] + TWO_PI * ki - q[i]
                            c, d = q[j] - hi[j] - TWO_PI * kj, q[j] - lo[j] - TWO_PI * kj
                            if s < 0:
                                c, d = -d, -c
                            a, b = max(a, c), min(b, d)
                            if a <= b:
                                t = min(max(0.0, a), b)
                                if best is None or abs(t) < abs(best[0]):
                                    best = (t, ki, kj)
                    if best is not None:
                        t, ki, kj = best
                        q[i] += t - TWO_PI * ki
                        q[j] -= s * t + TWO_PI * kj
                        moved = True
                        break
        if not moved:
            break
    return q if outside(q) <= LIMIT_SLACK else None


def _refine(robot, q, T, lo, hi, position_only, polish=True):
    """(q, max |FK(q) − T| over the 3×4 entries or the position) after polishing ``q`` inside
    the limits by bounded least squares on the FK error (scipy's trust-region reflective
    method, which copes with the rank-deficient Jacobian at the singular poses where the closed
    forms lose precision).  FK: Pinocchio, ``robot.data`` of the calling thread."""
    import pinocchio as pin

    model, data, fid = robot.model, robot.data, robot.tool_id
    Rt, pt = T[:3, :3], T[:3, 3]

    def err(x):
        pin.framesForwardKinematics(model, data, x)
        M = data.oMf[fid]
        e = M.translation - pt
        return e if position_only else np.concatenate([e, (M.rotation - Rt).ravel()])

    if polish and bool((hi > lo).all()):
        from scipy.optimize import least_squares

        sol = least_squares(
            err, q, bounds=(lo, hi), method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=60
        )
        if np.isfinite(sol.x).all():
            q = np.clip(sol.x, lo, hi)
        # the reflective method creeps towards a solution that lies on a bound (each step halves
        # the distance) and its finite-difference Jacobian stops it near 1e-9: finish with
        # Newton steps on Pinocchio's Jacobian, joints that would cross a limit held on it
        qn = _newton_on_limits(model, data, fid, q, T, lo, hi, position_only)
        if float(np.abs(err(qn)).max()) < float(np.abs(err(q)).max()):
            q = qn
    return q, float(np.abs(err(q)).max())


def _newton_on_limits(model, data, fid, q, T, lo, hi, position_only, iters: int = 40):
    """Gauss–Newton steps δq = −J⁺ e on the pose error e = (p − p*, log₃(R R*ᵀ)) (world frame;
    J: Pinocchio's frame Jacobian, LOCAL_WORLD_ALIGNED, rows of the position only where
    ``position_only``), with an active set: a joint whose step would leave [lo, hi] is put on
    that limit and held there for the following steps.  Quadratic convergence where the
    solution lies on a limit, which the bounded least squares above only approaches; linear (the
    error halves a step) at a singular configuration on a limit, hence up to ``iters`` steps."""
    import pinocchio as pin

    x = np.clip(np.array(q, dtype=float), lo, hi)
    free = np.ones(x.size, dtype=bool)
    rows = slice(0, 3) if position_only else slice(0, 6)
    Rt, pt = T[:3, :3], T[:3, 3]
    for _ in range(iters):
        J = pin.computeFrameJacobian(model, data, x, fid, pin.LOCAL_WORLD_ALIGNED)[rows]
        M = pin.updateFramePlacement(model, data, fid)  # after the Jacobian computed the joints
        e = np.concatenate([M.translation - pt, pin.log3(M.rotation @ Rt.T)])[rows]
        if float(np.abs(e).max()) < 1e-15 or not free.any():
            break
        while True:
            dq = np.zeros(x.size)
            dq[free] = -np.linalg.lstsq(J[:, free], e, rcond=1e-10)[0]
            xn = x + dq
            out = free & ((xn < lo) | (xn > hi))
            if not out.any():
                break
            x[out] = np.clip(xn[out], lo[out], hi[out])  # onto the limit it would cross
            free &= ~out
            if not free.any():
                break
        if not np.isfinite(xn).all():
            break
        x = np.clip(xn, lo, hi)
    return x
