"""Closed-form inverse kinematics of the book's arms, every branch (Ch. 7 §7-2).

:func:`analytic` (exported as ``aa.ik.analytic``) returns *every* joint solution of one hand pose
that lies inside the joint limits, each labelled by its branch and each verified by forward
kinematics before it is returned; :func:`analytic_batch` does the same for ``N`` poses at once
(vectorised numpy over poses × branches).

Families of closed forms (which arm has which: the registry
:mod:`anthroarm.models.closed_forms`; :func:`has_analytic` asks it for a robot):

``spherical_wrist_6r`` (the 6R arm of Fig. 6-3, ``sixr_arm``)
    The book's procedure (7-1)–(7-15) with the corrections of the ch7 notes §0.4 (L uses θ3;
    N = −cos θ5, Eq. (7-12); step 6 / (7-13)–(7-14) solve θ6), written with atan2 and rotation
    matrices: wrist centre D = p − P·a, θ1 from (7-2) (two: θ1, θ1 + π), θ2/θ3 from the planar
    triangle B–C–D (7-4)/(7-6) (two), θ4 from z4 ⊥ z5 (7-8) (two: wrist flip), θ5 from
    N = −cos θ5 and θ6 from (7-14).  8 branches (Fig. 7-1).
``prosthetic_6r`` (Fig. 7-2, Table 7.1, ``prosthetic_arm``)
    The book's order (7-17)–(7-31): wrist W = C − L3·n, elbow E on the sphere |E| = L1, the
    sphere |E − W| = L2 and the plane (E − C)·m = 0 (7-17), θ1/θ2 from E (7-18)/(7-19), θ4 from
    the triangle O–E–W (7-24), θ3 from (7-26), θ5/θ6 from x6 = l (7-28)–(7-31).  The elbow is
    solved *robustly* as the intersection of the line of the two planes with the sphere, which
    works where the book's Cramer determinant Δ of (7-20)/(7-21) is zero (Table 7.2 row 1);
    :func:`prosthetic_book_procedure` is the book's Cramer-rule version.  Branches: the two
    elbow roots of (7-22) × shoulder (θ1, θ2) / (θ1 + π, −θ2) × elbow flexion sign.
``planar_2r`` (Fig. 7-14, ``planar2r``)
    Position-only by default (the mechanism has 2 DOF): the two elbow branches ±θ2.
``srs_7r`` (§6-3, ``human_arm7``)
    Redundant (7 DOF): the elbow swivel angle φ (rotation of the elbow about the shoulder–wrist
    axis) is the parameter of the one-parameter family.  ``swivel=`` a scalar or an array of
    angles (rad); default: a grid of 36 angles over [−π, π).  Per swivel angle: elbow sign ×
    shoulder Euler branch × wrist Euler branch = 8 candidates.  See :func:`anthroarm.ik.qp.tasks.swivel.swivel_angle`.

Frames and units: ``T`` is the 4×4 pose (SE(3), metres) of the robot's tool frame
(``robot.tool``) in the base frame; joint values in radians.  Lengths are read from
``robot.spec.params`` (the keys the registry names), limits from ``robot.lower`` /
``robot.upper``.  A robot without a registered closed form raises
:class:`~anthroarm.errors.UnsupportedModelError` pointing to ``aa.ik.solve``.

Implementations (same formulas, branches, limit wrap, FK check, duplicate filter and reasons):
the general vectorised path in this module (the reference of the tests); for plainly valid
float64 input the fast paths — batches: structure-of-arrays numpy kernels
(:mod:`.analytic_soa`); single poses: the compiled kernel (:mod:`.analytic_c`, built with the
system C compiler on first use and cached) or, without a compiler, scalar ``math`` kernels
(:mod:`.analytic_scalar`).  The fast paths verify every candidate with a chain product generated
from ``robot.chain`` (:mod:`.fk_codegen`), the same model Pinocchio holds; the general path with
Pinocchio's FK (few candidates) or ``robot.chain.serial`` (many).  Per-robot
constants are cached (:mod:`.analytic_plan`).  At exactly singular poses (measure zero) the paths
may differ by a pair of nearly coincident roots or by the representative of a singular family.
"""

from __future__ import annotations

import functools
import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..errors import UnsupportedModelError
from ..models import closed_forms as _registry
from . import analytic_c as _c
from . import analytic_scalar as ks
from . import analytic_soa as _soa
from . import geometric as _geo
from .analytic_plan import cached_plan, plan_for
from .fk_codegen import FKStages
from .qp.tasks.swivel import swivel_basis

TWO_PI = 2.0 * np.pi
HALF_PI = 0.5 * np.pi
#: the closed-form families (models.closed_forms names the arms of each)
SIXR, PROSTHETIC, PLANAR, SRS = "spherical_wrist_6r", "prosthetic_6r", "planar_2r", "srs_7r"
#: default swivel grid of a redundant (srs_7r) arm (rad)
DEFAULT_SWIVEL = np.linspace(-np.pi, np.pi, 36, endpoint=False)

# failure codes of a candidate (per pose and branch); 0 = a candidate solution exists
OK, OUTSIDE, ELBOW, DEGENERATE, OUT_OF_PLANE = 0, 1, 2, 3, 4
_REASONS = {
    OUTSIDE: "outside the workspace: the wrist centre is out of reach of the arm "
             "(cos of the elbow angle outside [-1, 1])",
    ELBOW: "no elbow position: the elbow circle (|E| = L1, |E - W| = L2) does not meet the "
           "plane (E - C)·m = 0 of Eq. (7-17) (the hand orientation is not reachable here)",
    DEGENERATE: "degenerate pose: the wrist centre lies along the hand y axis, the two elbow "
                "planes of Eq. (7-17) are parallel (elbow determinant zero)",
    OUT_OF_PLANE: "outside the workspace: the target is not in the plane x = 0 of the mechanism",
}


# ---------------------------------------------------------------------------- results
@dataclass
class AnalyticIKResult:
    """Every closed-form solution of one pose.

    ``solutions`` (K, nq) rad, each inside the joint limits and verified by FK;
    ``branches`` K labels; ``reason`` is None when K > 0, else why there is none;
    ``swivel`` (K,) the swivel angle of each solution (human_arm7 only, else None);
    ``residuals`` (K,) the FK check: max |FK(q) − T| over the 3×4 pose entries (m / unitless);
    ``singular`` names a singular configuration family if the pose is singular (a
    representative member was returned), else None."""

    solutions: np.ndarray
    branches: list
    reason: str | None = None
    swivel: np.ndarray | None = None
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    singular: str | None = None
    model: str = ""

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
    ``swivel`` (N, B) for human_arm7.  ``result[i]`` gives pose i as an AnalyticIKResult."""

    solutions: np.ndarray
    valid: np.ndarray
    branches: list
    reasons: list
    swivel: np.ndarray | None = None
    residuals: np.ndarray | None = None
    singular: list | None = None
    model: str = ""

    def __len__(self) -> int:
        return self.solutions.shape[0]

    def __getitem__(self, i: int) -> AnalyticIKResult:
        v = self.valid[i]
        return AnalyticIKResult(
            solutions=self.solutions[i][v].copy(),
            branches=[b for b, ok in zip(self.branches, v) if ok],
            reason=self.reasons[i],
            swivel=None if self.swivel is None else self.swivel[i][v].copy(),
            residuals=np.zeros(int(v.sum())) if self.residuals is None else self.residuals[i][v].copy(),
            singular=None if self.singular is None else self.singular[i],
            model=self.model,
        )

    @property
    def n_solutions(self) -> np.ndarray:
        return self.valid.sum(axis=1)


# ---------------------------------------------------------------------------- model checks
def _form(robot, frame=None):
    """The registry entry of ``robot`` if its closed form solves for ``frame`` (default: the
    tool), else None: a catalog arm with a registered closed form, all its joints present (none
    locked away), the tool frame its formulas end at, and ``frame`` that tool."""
    spec = getattr(robot, "spec", None)
    form = _registry.lookup(spec)
    if form is None or robot.nq != form.nq or robot.tool != spec.tool_name \
            or len(robot.chain.path(robot.tool)) != form.nq:
        return None
    if frame is not None and robot.chain.frame(frame).name != robot.tool:
        return None
    return form


#: the registry-like entry of an arm solved by its geometry (:mod:`.geometric`), per class;
#: ``cost_us`` is the single-pose time with the FK check (order of magnitude,
#: benchmarks/results/ik_analytic.md: a closed class ~10 µs in one compiled call; a 1-D search
#: class, :data:`.geometric.SEARCHED`, ~30 ms; the 2-D search of gen_six_dof ~0.3 s)
_GEO_COST = {c: 300000.0 if c == _geo.C.GEN_SIX_DOF else 30000.0 if c in _geo.SEARCHED else 10.0
             for c in _geo.SOLVED}
_GEO_FORMS = {c: _registry.ClosedForm(c, (), 6, (), _geo.n_branches(c), cost_us=_GEO_COST[c]) for c in _geo.SOLVED}
#: a 7-joint arm with its last joint held (the family parameter): per value of the grid
_GEO_FORMS7 = {c: _registry.ClosedForm(c, (), 7, (), _geo.n_branches(c), cost_us=_GEO_COST[c]) for c in _geo.SOLVED}
#: values of the held joint of a 7-joint arm when ``param`` is not given
PARAM_GRID = 12
#: FK residual (m / unitless) up to which a class solution is polished (arm of its class only
#: within the classification tolerance)
POLISH_MAX = 1e-4


def _geo_plan(robot, frame=None):
    """The :class:`.geometric.GeoPlan` of a robot without a registered closed form whose
    geometry has one (IK-Geo class of ``robot.chain``), for ``frame`` = its tool; else None."""
    if frame is not None and robot.chain.frame(frame).name != robot.tool:
        return None
    if _form(robot) is not None:
        return None
    return _geo.plan_for(robot)


def _form_any(robot, frame=None):
    form = _form(robot, frame)
    if form is None:
        gp = _geo_plan(robot, frame)
        if gp is not None:
            return (_GEO_FORMS if gp.param_joint is None else _GEO_FORMS7)[gp.cls]
    return form


def has_analytic(robot, frame=None) -> bool:
    """True if :func:`analytic` has a closed form for ``robot`` at ``frame`` (a name or a
    Pinocchio frame id; default the tool).  Which arms have one is the registry
    :mod:`anthroarm.models.closed_forms`, then the arm's geometry (a 6R class of
    :mod:`.geometric`); an unknown frame raises :class:`~anthroarm.errors.UnknownFrameError`."""
    return _form_any(robot, frame) is not None


def closed_form_info(robot, frame=None):
    """The registry entry (:class:`anthroarm.models.closed_forms.ClosedForm`: family, branches,
    swivel, position_only, cost_us) of ``robot`` at ``frame``, or None without a closed form.
    An arm solved by its geometry gets an entry whose ``family`` is its IK-Geo class."""
    return _form_any(robot, frame)


def analytic_cost(robot, frame=None) -> float:
    """Cost hint of one :func:`analytic` call at ``frame`` in µs per pose (the compiled
    kernel's benchmark time; a redundant arm's per swivel angle), ``inf`` without a closed form."""
    form = _form_any(robot, frame)
    return float("inf") if form is None else form.cost_us


def _plan(robot):
    """The plan of a robot with a closed form for its tool, else None (no exception)."""
    plan = cached_plan(robot)
    if plan is None:
        form = _form(robot)
        if form is not None:
            plan = plan_for(robot, form)
    return plan


def _require(robot):
    plan = _plan(robot)
    if plan is None:
        spec = getattr(robot, "spec", None)
        form = _registry.lookup(spec)
        if form is not None and robot.tool != spec.tool_name:
            raise UnsupportedModelError(
                f"{robot.name}: the closed form solves for the tool frame {spec.tool_name!r}, "
                f"not {robot.tool!r}")
        if form is not None:
            raise UnsupportedModelError(
                f"{robot.name}: the closed form solves all {form.nq} joints of {spec.name}; this robot has "
                f"{robot.nq} (joints locked or left out): use aa.ik.solve(robot, T)")
        c = _geo.classification(robot)
        why = ("its chain could not be read" if c is None else
               f"its kinematic class is {c.name}" + (f" ({c.reason})" if c.reason else ""))
        raise UnsupportedModelError(
            f"{robot.name}: no closed-form IK is registered for this robot (closed forms exist for "
            f"{', '.join(_registry.names())}; anthroarm.models.closed_forms) and no closed form for "
            f"this geometry: {why}, solved in closed form are 6R arms of the classes "
            f"{', '.join(_geo.SOLVED)}; use aa.ik.solve(robot, T) for a numerical solution")
    return plan


def require_form(robot, frame=None):
    """:func:`closed_form_info` of ``robot``, or :class:`~anthroarm.errors.UnsupportedModelError`
    saying why it has no closed form (and pointing to ``aa.ik.solve``)."""
    form = _form_any(robot, frame)
    if form is None:
        _require(robot)
    return form


# ---------------------------------------------------------------------------- input checks
def _check_poses(T, name="T", tol_orthonormal=1e-6, position_only=False) -> tuple[np.ndarray, bool]:
    """Return (N, 4, 4) and whether the input was a single pose.  ValueError on bad input."""
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
        raise ValueError(f"{name} must be a 4x4 homogeneous pose or a batch (N, 4, 4), got shape {arr.shape}")
    if arr.shape[0] == 0:
        return arr, single                   # an empty batch: an empty result
    if not np.isfinite(arr).all():
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(f"{name}{list(idx) if not single else list(idx[1:])} is {arr[idx]} (not finite)")
    if np.abs(arr[:, 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max() > 1e-12:
        raise ValueError(f"{name}: the last row of a homogeneous pose must be [0, 0, 0, 1]")
    R = arr[:, :3, :3]
    err = np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(R) if len(R) < 64 else np.einsum("ni,ni->n", R[:, :, 0], np.cross(R[:, :, 1], R[:, :, 2]))
    bad = (err > tol_orthonormal) | (det < 0)
    if not position_only and bad.any():
        i = int(np.argmax(bad))
        where = "" if single else f"[{i}]"
        raise ValueError(
            f"{name}{where}: the rotation part is not a rotation matrix (max |R^T R - I| = {err[i]:.3g}, "
            f"det = {det[i]:.6g}); orthonormalise it first (e.g. nearest rotation by SVD)")
    return arr, single


# ---------------------------------------------------------------------------- helpers
def _wrap_into_limits(Q, lo, hi, tol=1e-9):
    """Shift revolute angles by multiples of 2π into [lo, hi] where possible; returns (Q, inside).
    Values within ``tol`` outside a limit are clipped onto it."""
    lo_f = np.where(np.isfinite(lo), lo, -np.pi)
    k = np.floor((Q - lo_f + tol) / TWO_PI)
    Qw = Q - k * TWO_PI
    inside = (Qw >= lo - tol) & (Qw <= hi + tol)
    Qw = np.clip(Qw, lo, hi)
    return Qw, inside.all(axis=-1)


# ---------------------------------------------------------------------------- FK used for verification
_DEDUP_DIR = np.random.default_rng(12345).uniform(0.5, 1.5, 16)


def _fk_residual(robot, Qw, Ts, position_only):
    """max |FK(q) − T| (3×4 entries, or position) of candidates Qw (N, B, nq) against Ts (N, 4, 4),
    +inf for a non-finite candidate.  Few candidates: Pinocchio's FK (one C++ call each, the
    calling thread's ``robot.data``); many: the batched chain FK (``robot.chain.serial``)."""
    import pinocchio as pin

    N, B = Qw.shape[:2]
    finite = np.isfinite(Qw).all(-1)
    if N * B > 64:
        Tf = robot.chain.serial(robot.tool).fk(np.where(finite[..., None], Qw, 0.0).reshape(N * B, -1))
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


# ---------------------------------------------------------------------------- 6R arm (Fig. 6-3)
SIXR_BRANCHES = [f"shoulder={s},elbow={e},wrist={w}"
                 for s in ("front", "back") for e in ("up", "down") for w in ("noflip", "flip")]


def _sixr(Rt, pt, s0, h2, s3, P):
    """Candidates (N, 8, 6) of the 6R arm, Eqs. (7-1)–(7-15) corrected (ch7 notes A2)."""
    N = Rt.shape[0]
    a = Rt[:, :, 2]
    d = pt - P * a - np.array([0.0, 0.0, s0])           # wrist centre D relative to B (step 0)
    rxy = np.hypot(d[:, 0], d[:, 1])
    shoulder_sing = rxy < 1e-12
    th1a = np.where(shoulder_sing, 0.0, np.arctan2(d[:, 1], d[:, 0]))   # (7-2)
    th1 = np.stack([th1a, th1a + np.pi], 1)                             # (N, 2)
    c1, s1 = np.cos(th1), np.sin(th1)
    X = d[:, None, 0] * c1 + d[:, None, 1] * s1                         # B of (7-3) = d·x1
    Y = np.broadcast_to(d[:, None, 2], X.shape)                        # A of (7-3)
    k = ((X**2 + Y**2) - h2**2 - s3**2) / (2 * h2 * s3)                # sin θ3, (7-6)
    code = np.where(np.abs(k) > 1 + 1e-12, OUTSIDE, OK)
    k = np.clip(k, -1.0, 1.0)
    as_k = np.arcsin(k)
    th3 = np.stack([as_k, np.pi - as_k], 2)                            # (N, 2, 2) elbow up/down
    c3 = np.cos(th3)
    # planar triangle B-C-D: θ2 = atan2(Y, X) - atan2(-s3 cos θ3, h2 + s3 sin θ3)   (7-4)
    th2 = np.arctan2(Y, X)[:, :, None] - np.arctan2(-s3 * c3, h2 + s3 * k[:, :, None])
    th23 = th2 + th3
    c23, s23 = np.cos(th23), np.sin(th23)
    # R3 = R01 R12 R23 with R01 = Rz(θ1) Rx(90°), R12 R23 = Rz(θ2+θ3) Rx(90°)
    C1, S1 = c1[:, :, None], s1[:, :, None]
    R3 = np.empty((N, 2, 2, 3, 3))
    R3[..., 0, 0] = C1 * c23
    R3[..., 0, 1] = S1
    R3[..., 0, 2] = C1 * s23
    R3[..., 1, 0] = S1 * c23
    R3[..., 1, 1] = -C1
    R3[..., 1, 2] = S1 * s23
    R3[..., 2, 0] = s23
    R3[..., 2, 1] = 0.0
    R3[..., 2, 2] = -c23
    M = np.swapaxes(R3, -1, -2) @ Rt[:, None, None]                    # C_{30} · hand rotation
    # third column of M = (c4 s5, s4 s5, -c5): (L, M, N) of (7-8) with N = -cos θ5 (7-12 corrected)
    L_, M_, N_ = M[..., 0, 2], M[..., 1, 2], M[..., 2, 2]
    wrist_sing = np.hypot(L_, M_) < 1e-12
    th4a = np.where(wrist_sing, 0.0, np.arctan2(M_, L_))               # (7-8)
    th4 = np.stack([th4a, th4a + np.pi], -1)                           # (N, 2, 2, 2) wrist flip
    c4, s4 = np.cos(th4), np.sin(th4)
    th5 = np.arctan2(c4 * L_[..., None] + s4 * M_[..., None], -N_[..., None])   # (7-12) corrected
    c5, s5 = np.cos(th5), np.sin(th5)
    # θ6 from (R34 R45)^T M = Rz(θ6)   (7-13)/(7-14), step 6 (solves θ6, not θ5)
    # R34 R45 = Rz(θ4) Rx(90) Rz(θ5) Rx(90): columns 0 and 1 give cos/sin of θ6
    # G = Rz4 Rx90 Rz5 Rx90; G[:,0] = (c4 c5, s4 c5, s5), G[:,1] = (s4, -c4, 0)
    Mx = M[..., :, 0][..., None, :]                                     # (N,2,2,1,3)
    g0 = np.stack([c4 * c5, s4 * c5, s5], -1)
    g1 = np.stack([s4, -c4, np.zeros_like(c4)], -1)
    cos6 = (g0 * Mx).sum(-1)
    sin6 = (g1 * Mx).sum(-1)
    th6 = np.arctan2(sin6, cos6)
    Q = np.stack([
        np.broadcast_to(th1[:, :, None, None], th4.shape),
        np.broadcast_to(th2[..., None], th4.shape),
        np.broadcast_to(th3[..., None], th4.shape),
        th4, th5, th6], -1).reshape(N, 8, 6)
    code = np.broadcast_to(code[:, :, None, None], th4.shape).reshape(N, 8)
    sing = np.full(N, None, dtype=object)
    ws = wrist_sing.reshape(N, 4).any(1)
    sing[ws] = "wrist singularity (sin θ5 = 0: only θ4 + θ6 is determined; θ4 = 0 returned)"
    sing[shoulder_sing] = "shoulder singularity (wrist centre on the z0 axis: θ1 is free; θ1 = 0 returned)"
    return Q, code, sing


# ---------------------------------------------------------------------------- prosthetic arm (Fig. 7-2)
PROSTHETIC_BRANCHES = [f"elbow_root={r},shoulder={s},flexion={f}"
                       for r in ("+", "-") for s in ("normal", "flipped") for f in ("positive", "negative")]


def _prosthetic(Rt, C, L1, L2, L3):
    """Candidates (N, 8, 6) of the prosthetic arm, Eqs. (7-17)–(7-31) with the robust elbow."""
    N = Rt.shape[0]
    m, n = Rt[:, :, 1], Rt[:, :, 2]
    W = C - L3 * n                                                       # step 1
    W2 = np.einsum("ni,ni->n", W, W)
    c4 = (W2 - L1**2 - L2**2) / (2 * L1 * L2)                           # (7-24)
    code = np.where(np.abs(c4) > 1 + 1e-12, OUTSIDE, OK)
    th4p = np.arccos(np.clip(c4, -1.0, 1.0))
    # elbow E: |E| = L1, E·W = h, E·m = g (the two planes of (7-17)); line E0 + t d
    h = 0.5 * (L1**2 + W2 - L2**2)
    g = np.einsum("ni,ni->n", W, m)                                    # = C·m since n ⊥ m
    dvec = np.cross(W, m)
    dd = np.einsum("ni,ni->n", dvec, dvec)                              # = |W|²|m|² − (W·m)²
    degen = dd < 1e-14 * np.maximum(W2, 1e-30)
    code = np.where((code == OK) & degen, DEGENERATE, code)
    dd_s = np.where(degen, 1.0, dd)
    alpha = (h - g * g) / dd_s           # |m| = 1: [[W2, g],[g, 1]] [α, β] = [h, g]
    beta = (W2 * g - g * h) / dd_s
    E0 = alpha[:, None] * W + beta[:, None] * m
    disc = (L1**2 - np.einsum("ni,ni->n", E0, E0)) / dd_s                # t² of (7-22)
    code = np.where((code == OK) & (disc < -1e-12), ELBOW, code)
    t = np.sqrt(np.clip(disc, 0.0, None))
    E = E0[:, None, :] + np.stack([t, -t], 1)[:, :, None] * dvec[:, None, :]   # (N, 2, 3) roots
    z2 = E / L1
    th2a = np.arccos(np.clip(-z2[..., 2], -1.0, 1.0))                  # (7-19)
    sh_sing = np.hypot(z2[..., 0], z2[..., 1]) < 1e-12
    th1a = np.where(sh_sing, -HALF_PI, np.arctan2(z2[..., 1], z2[..., 0]))   # (7-18) with atan2
    th1 = np.stack([th1a, th1a + np.pi], 2)                             # shoulder normal / flipped
    th2 = np.stack([th2a, -th2a], 2)                                    # (N, 2, 2)
    c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
    # R2 = Rz(θ1) Rx90 Rz(θ2) Rx90
    z, o = np.zeros_like(c1), np.ones_like(c1)
    R01 = np.stack([np.stack([c1, z, s1], -1), np.stack([s1, z, -c1], -1), np.stack([z, o, z], -1)], -2)
    R12 = np.stack([np.stack([c2, z, s2], -1), np.stack([s2, z, -c2], -1), np.stack([z, o, z], -1)], -2)
    R2 = R01 @ R12
    v = np.einsum("nrsji,nrj->nrsi", R2, (W[:, None, :] - E) / L2)      # = (s4 s3, -s4 c3, c4), (7-26)
    th4 = np.stack([th4p, -th4p], 1)                                    # flexion sign (N, 2)
    s4 = np.sin(th4)
    sg = np.where(s4 >= 0, 1.0, -1.0)[:, None, None, :]                 # (N,1,1,2)
    el_sing = np.abs(np.sin(th4p)) < 1e-12
    th3 = np.where(el_sing[:, None, None, None], 0.0,
                   np.arctan2(sg * v[..., 0:1], -sg * v[..., 1:2]))     # (N, 2, 2, 2)
    c3, s3 = np.cos(th3 + HALF_PI), np.sin(th3 + HALF_PI)               # hidden +90° of A23
    c4b = np.broadcast_to(np.cos(th4)[:, None, None, :], th3.shape)
    s4b = np.broadcast_to(s4[:, None, None, :], th3.shape)
    z3, o3 = np.zeros_like(c3), np.ones_like(c3)
    R23 = np.stack([np.stack([c3, z3, s3], -1), np.stack([s3, z3, -c3], -1), np.stack([z3, o3, z3], -1)], -2)
    R34 = np.stack([np.stack([c4b, z3, -s4b], -1), np.stack([s4b, z3, c4b], -1), np.stack([z3, -o3, z3], -1)], -2)
    R4 = R2[..., None, :, :] @ R23 @ R34
    M = np.swapaxes(R4, -1, -2) @ Rt[:, None, None, None]               # Rz5 Rx90 Rz6 Rx-90, (7-28)
    th5 = np.arctan2(-M[..., 0, 1], M[..., 1, 1])                       # y column (-s5, c5, 0)
    c5, s5 = np.cos(th5), np.sin(th5)
    th6 = np.arctan2(M[..., 2, 0], c5 * M[..., 0, 0] + s5 * M[..., 1, 0])   # (7-30)/(7-31): x col (c5c6, s5c6, s6)
    sh = th3.shape
    Q = np.stack([np.broadcast_to(th1[..., None], sh), np.broadcast_to(th2[..., None], sh), th3,
                  np.broadcast_to(th4[:, None, None, :], sh), th5, th6], -1).reshape(N, 8, 6)
    code = np.broadcast_to(code[:, None], (N, 8))
    sing = np.full(N, None, dtype=object)
    sing[el_sing] = "elbow singularity (straight arm, sin θ4 = 0: θ3 + θ5 only determined; θ3 = 0 returned)"
    sing[sh_sing.any(1)] = "shoulder singularity (elbow on the vertical axis: θ1 is free; θ1 = -90° returned)"
    return Q, code, sing


# ---------------------------------------------------------------------------- planar 2R (Fig. 7-14)
PLANAR_BRANCHES = ["elbow=positive", "elbow=negative"]


def _planar(Rt, p, l1, l2):
    N = p.shape[0]
    y, z = p[:, 1], p[:, 2]
    c2 = (y * y + z * z - l1**2 - l2**2) / (2 * l1 * l2)
    code = np.where(np.abs(c2) > 1 + 1e-12, OUTSIDE, OK)
    code = np.where(np.abs(p[:, 0]) > 1e-9 * max(l1 + l2, 1.0), OUT_OF_PLANE, code)
    t2 = np.arccos(np.clip(c2, -1, 1))
    th2 = np.stack([t2, -t2], 1)
    th1 = np.arctan2(z, y)[:, None] - np.arctan2(l2 * np.sin(th2), l1 + l2 * np.cos(th2))
    Q = np.stack([th1, th2], -1)
    return Q, np.broadcast_to(code[:, None], (N, 2)), np.full(N, None, dtype=object)


# ---------------------------------------------------------------------------- human arm 7 (§6-3)
HUMAN_BRANCHES = [f"elbow={e},shoulder={s},wrist={w}"
                  for e in ("flexed", "hyperextended") for s in ("a", "b") for w in ("a", "b")]


def _human(Rt, H, l1, l2, l3, swivel):
    """Candidates (N, S·8, 7) of human_arm7 for swivel angles ``swivel`` (N, S)."""
    N, S = swivel.shape
    W = H + l3 * Rt[:, :, 2]                                           # wrist: H = W + R (0,0,-l3)
    Wn = np.linalg.norm(W, axis=1)
    c4 = (Wn**2 - l1**2 - l2**2) / (2 * l1 * l2)
    code = np.where((np.abs(c4) > 1 + 1e-12) | (Wn < 1e-12), OUTSIDE, OK)
    q4p = np.arccos(np.clip(c4, -1, 1))
    nvec = W / np.where(Wn > 1e-12, Wn, 1.0)[:, None]
    u, v = swivel_basis(nvec)
    cc = np.where(Wn > 1e-12, (l1**2 - l2**2 + Wn**2) / (2 * np.where(Wn > 1e-12, Wn, 1.0)), 0.0)
    dvec = np.cos(swivel)[..., None] * u[:, None] + np.sin(swivel)[..., None] * v[:, None]   # (N,S,3)
    r = np.sqrt(np.clip(l1**2 - cc**2, 0, None))
    E = cc[:, None, None] * nvec[:, None] + r[:, None, None] * dvec                        # elbow
    ex0 = np.cross(dvec, np.broadcast_to(nvec[:, None], dvec.shape))                        # d × n
    q4 = np.stack([q4p, -q4p], 1)                                     # (N, 2)
    sg = np.array([1.0, -1.0])
    ez = -E / l1                                                       # (N,S,3)
    ex = sg[None, None, :, None] * ex0[:, :, None, :]                  # (N,S,2,3)
    ezb = np.broadcast_to(ez[:, :, None, :], ex.shape)
    ey = np.cross(ezb, ex)
    Rsh = np.stack([ex, ey, ezb], -1)                                  # columns
    # XYZ Euler R = Rx(q1) Ry(q2) Rz(q3), two branches (cos q2 > 0 / < 0)
    sb = np.array([1.0, -1.0])[None, None, None, :]
    R02, R12, R22 = Rsh[..., 0, 2][..., None], Rsh[..., 1, 2][..., None], Rsh[..., 2, 2][..., None]
    R00, R01 = Rsh[..., 0, 0][..., None], Rsh[..., 0, 1][..., None]
    cq2 = sb * np.hypot(R00, R01)
    q2 = np.arctan2(np.broadcast_to(R02, cq2.shape), cq2)
    sh_sing = (np.abs(cq2) < 1e-12)
    q1 = np.where(sh_sing, 0.0, np.arctan2(-sb * R12, sb * R22))
    # gimbal lock (q2 = ±90°): q1 = 0 and R = Ry(q2) Rz(q3), so q3 = atan2(R10, R11)
    q3 = np.where(sh_sing, np.arctan2(Rsh[..., 1, 0][..., None], Rsh[..., 1, 1][..., None]),
                  np.arctan2(-sb * R01, sb * R00))                     # (N,S,2,2)
    # wrist: X = (Rsh Rx(q4))^T R = Rz(q5) Ry(q6) Rx(q7)
    c4_, s4_ = np.cos(q4), np.sin(q4)                                  # (N,2)
    z, o = np.zeros_like(c4_), np.ones_like(c4_)
    Rx4 = np.stack([np.stack([o, z, z], -1), np.stack([z, c4_, -s4_], -1), np.stack([z, s4_, c4_], -1)], -2)
    RW = Rsh @ Rx4[:, None]                                            # (N,S,2,3,3)
    X = np.swapaxes(RW, -1, -2) @ Rt[:, None, None]
    X = X[:, :, :, None]                                               # (N,S,2,1,3,3)
    wb = np.array([1.0, -1.0])
    c6 = wb * np.hypot(X[..., 2, 1], X[..., 2, 2])                       # (N,S,2,2) over wrist branch
    q6 = np.arctan2(-X[..., 2, 0], c6)
    q5 = np.arctan2(wb * X[..., 1, 0], wb * X[..., 0, 0])
    q7 = np.arctan2(wb * X[..., 2, 1], wb * X[..., 2, 2])
    # assemble (N, S, elbow 2, shoulder 2, wrist 2, 7)
    shp = (N, S, 2, 2, 2)
    Q = np.stack([
        np.broadcast_to(q1[..., None], shp), np.broadcast_to(q2[..., None], shp),
        np.broadcast_to(q3[..., None], shp),
        np.broadcast_to(q4[:, None, :, None, None], shp),
        np.broadcast_to(q5[:, :, :, None, :], shp), np.broadcast_to(q6[:, :, :, None, :], shp),
        np.broadcast_to(q7[:, :, :, None, :], shp)], -1).reshape(N, S * 8, 7)
    sw = np.broadcast_to(swivel[:, :, None], (N, S, 8)).reshape(N, S * 8)
    sing = np.full(N, None, dtype=object)
    sing[np.abs(np.sin(q4p)) < 1e-12] = "straight elbow: the swivel angle then turns the elbow axis about the arm"
    return Q, np.broadcast_to(code[:, None], (N, S * 8)), sing, sw


# ---------------------------------------------------------------------------- public API
def _candidates(family, prm, Rt, pt, swivel):
    if family == SIXR:
        Q, code, sing = _sixr(Rt, pt, prm["s0"], prm["h2"], prm["s3"], prm["P"])
        return Q, code, sing, None, SIXR_BRANCHES
    if family == PROSTHETIC:
        Q, code, sing = _prosthetic(Rt, pt, prm["L1"], prm["L2"], prm["L3"])
        return Q, code, sing, None, PROSTHETIC_BRANCHES
    if family == PLANAR:
        Q, code, sing = _planar(Rt, pt, prm["l1"], prm["l2"])
        return Q, code, sing, None, PLANAR_BRANCHES
    if family == SRS:
        Q, code, sing, sw = _human(Rt, pt, prm["l1"], prm["l2"], prm["l3"], swivel)
        S = swivel.shape[1]
        labels = [f"{b},swivel#{k}" for k in range(S) for b in HUMAN_BRANCHES] if S > 1 else list(HUMAN_BRANCHES)
        return Q, code, sing, sw, labels
    raise AssertionError(family)


def _swivel_array(swivel, N, grid_1d=False):
    """(N, S) swivel angles.  Batch rule: scalar -> every pose; 1-D -> one angle per pose
    (length N), unless ``grid_1d`` (single-pose call: a 1-D array is a grid); 2-D (N, S) or
    (1, S) -> a grid per pose; None -> :data:`DEFAULT_SWIVEL` for every pose."""
    if swivel is None:
        return np.broadcast_to(DEFAULT_SWIVEL[None, :], (N, DEFAULT_SWIVEL.size)).copy()
    sw = np.asarray(swivel, dtype=float)
    if not np.isfinite(sw).all():
        raise ValueError(f"swivel must be finite angles (rad), got {swivel!r}")
    if sw.ndim == 0:
        return np.full((N, 1), float(sw))
    if sw.ndim == 1 and grid_1d:
        sw = sw[None, :]
    elif sw.ndim == 1:
        if sw.shape[0] != N:
            raise ValueError(f"swivel: a 1-D array gives one angle per pose and must have length N = {N}, "
                             f"got {sw.shape[0]} (pass shape (1, S) for a grid shared by all poses)")
        return sw[:, None].copy()
    if sw.ndim == 2 and sw.shape[0] in (1, N) and sw.shape[1] >= 1:
        return np.broadcast_to(sw, (N, sw.shape[1])).copy()
    raise ValueError(f"swivel must be a scalar, shape (N,), (1, S) or (N, S) with N = {N}, got {sw.shape}")


def analytic_batch(robot, T, *, swivel=None, position_only: bool | None = None,
                   tol: float = 1e-9, tol_orthonormal: float = 1e-6, param=None,
                   _single_grid: bool = False, _impl: str = "auto") -> AnalyticBatchResult:
    """Closed-form IK of N poses ``T`` (N, 4, 4) on every branch (see module docstring).

    Candidates are wrapped into the joint limits (multiples of 2π), rejected if outside, and
    verified by FK: kept only if every entry of the 3×4 pose differs from ``T`` by ≤ ``tol``
    (m for the position; the rotation entries are unitless).  ``position_only`` (default True
    for planar2r only) compares the position alone.  human_arm7: ``swivel`` a scalar (all
    poses), shape (N,) (one angle per pose), (1, S) (a grid shared by all poses) or (N, S);
    default :data:`DEFAULT_SWIVEL` for every pose.

    Raises ``ValueError`` for a malformed ``T`` (shape, NaN, non-orthonormal rotation) and
    :class:`~anthroarm.errors.UnsupportedModelError` for a robot without a closed form.

    Plainly valid (N, 4, 4) float64 arrays go through the structure-of-arrays numpy kernels of
    :mod:`.analytic_soa` (same formulas, branches and checks; FK verification by the chain
    product generated from the spec, :mod:`.fk_codegen`); anything else through the general
    path below.  ``_impl`` (private, for tests and benchmarks): "auto" (= "python" for
    batches), "python", "c" (the compiled kernel of :mod:`.analytic_c` on the whole batch) or
    "general"."""
    _check_tol("tol", tol)
    _check_tol("tol_orthonormal", tol_orthonormal)
    if _plan(robot) is None:
        gp = _geo.plan_for(robot)
        if gp is not None:
            return _geometric_batch(robot, gp, T, swivel, position_only, tol, tol_orthonormal, param)
    _no_param(robot, param)
    plan = _require(robot)
    family, prm = plan.family, plan.params
    if position_only is None:
        position_only = plan.form.position_only
    fast = _fast_candidates(robot, plan, T, swivel, position_only, tol, tol_orthonormal, _single_grid, _impl)
    if fast is not None:
        Qw, valid, code, inside, res, sing, swv, labels = fast
        N, B = valid.shape
    else:
        Ts, _ = _check_poses(T, tol_orthonormal=tol_orthonormal, position_only=position_only)
        N = Ts.shape[0]
        Rt, pt = Ts[:, :3, :3], Ts[:, :3, 3]
        sw = _swivel_array(swivel, N, grid_1d=_single_grid) if family == SRS else None
        Q, code, sing, swv, labels = _candidates(family, prm, Rt, pt, sw)
        B = Q.shape[1]
        Qw, inside = _wrap_into_limits(Q, robot.lower, robot.upper)
        res = _fk_residual(robot, Qw, Ts, position_only)                  # FK check (N, B)
        valid = (code == OK) & inside & (res <= tol)
        valid &= np.isfinite(res)
    # poses without a solution whose candidates lie on (or, by rounding, just beyond) a limit, or
    # whose singular family has members inside the limits: _rescue_pose
    if family != SRS and N:
        c_ = np.asarray(code)
        todo = np.flatnonzero(~valid.any(1) & ((c_ == OK) | (c_ == ELBOW)).any(1))
        if todo.size:
            Tall, _ = _check_poses(T, tol_orthonormal=tol_orthonormal, position_only=position_only)
            Qw, valid, res = np.array(Qw), np.array(valid), np.array(res, dtype=float)
            inside = np.array(inside)
            for i in todo:
                for b, q, r in _rescue_pose(robot, plan, Tall[i], tol, position_only):
                    Qw[i, b], valid[i, b], res[i, b], inside[i, b] = q, True, r, True
    # remove duplicate solutions (singular poses give coincident branches)
    if B > 1:
        # cheap pre-filter: a random projection of each solution; only rows with two nearly equal
        # projections are compared in full
        key = np.where(valid, Qw @ _DEDUP_DIR[:Qw.shape[-1]], 1e6 * np.arange(1, B + 1))
        ks = np.sort(key, axis=1)
        rows = np.flatnonzero((np.diff(ks, axis=1) < 1e-8).any(1))
        for i in rows:
            for b in range(1, B):
                if valid[i, b]:
                    diff = np.abs(Qw[i, :b] - Qw[i, b]).max(-1)
                    if ((diff < 1e-9) & valid[i, :b]).any():
                        valid[i, b] = False
    sol = np.where(valid[..., None], Qw, np.nan)
    reasons = [None] * N
    fails = np.flatnonzero(~valid.any(1))
    sing = list(sing)
    for i in fails:
        reasons[i] = _reason_for(code[i], inside[i], res[i], tol, robot)
        if not (code[i] == OK).any():
            sing[i] = None      # outside the workspace: no configuration, nothing singular about it
    return AnalyticBatchResult(solutions=sol, valid=valid, branches=labels, reasons=reasons,
                               swivel=None if swv is None else np.where(valid, swv, np.nan),
                               residuals=np.where(valid, res, np.nan), singular=sing, model=robot.name)


_GEO_FK: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _geo_fk_residual(robot, gp, th, Q, Ts):
    """max |FK − T| over the 3×4 pose entries of candidates θ (N, B, n) (independent-joint
    order; Q the configurations): Pinocchio for a few, else the chain product generated from
    ``robot.chain`` (:class:`.fk_codegen.FKStages`, cached per robot)."""
    N, B = th.shape[:2]
    hit = _GEO_FK.get(robot)
    if N * B > 64 and (hit is None or hit[0] is not robot.chain or hit[1] != robot.tool):
        try:
            fk = FKStages(robot.chain, (), frame=robot.tool)
        except NotImplementedError:              # e.g. continuous joints: Pinocchio / chain FK
            fk = None
        hit = (robot.chain, robot.tool, fk)
        _GEO_FK[robot] = hit
    if N * B <= 64 or hit[2] is None:
        return _fk_residual(robot, Q, Ts, False)
    path = np.argsort(gp.order)                     # path position p holds independent joint path[p]
    ang = [np.ascontiguousarray(np.nan_to_num(th[..., k]).T) for k in path]      # (B, N) each
    rows = tuple(Ts[:, i, j] for i in range(3) for j in range(4))
    return np.broadcast_to(hit[2].numpy[0](*ang, rows), (B, N)).T


def _no_param(robot, param):
    if param is not None:
        raise ValueError(f"{robot.name}: param= is for a 7-joint arm solved by its geometry (its last joint "
                         "held); use swivel= for a registered redundant arm")


def _geometric_batch(robot, gp, T, swivel, position_only, tol, tol_orthonormal, param=None) -> AnalyticBatchResult:
    """:func:`analytic_batch` of an arm solved by its geometry (:mod:`.geometric`): the class
    solver's branches (8, or 16 slots for a search class; per value of ``param`` for a 7-joint arm: its last joint, rad; scalar,
    (N,), (1, S) or (N, S) as ``swivel``; default :data:`PARAM_GRID` values over its range),
    wrapped by 2π into the joint limits, each verified by FK (the 3×4 pose to ``tol``; candidates
    within :data:`POLISH_MAX` polished first), duplicates removed; a reason for every pose
    without a solution."""
    if swivel is not None:
        raise ValueError(f"{robot.name}: swivel= applies to a redundant arm's family of solutions; "
                         f"this arm is a 6R arm ({gp.cls}) with finitely many solutions")
    if position_only:
        raise ValueError(f"{robot.name}: a 6R arm is solved for the full pose (position and rotation); "
                         "for a position alone use aa.ik.solve(robot, p, position_only=True)")
    Ts, single = _check_poses(T, tol_orthonormal=tol_orthonormal)
    N, ch = Ts.shape[0], gp.chain
    if gp.param_joint is None and param is not None:
        raise ValueError(f"{robot.name}: param= is the value of the held joint of a 7-joint arm; this arm "
                         f"is a 6R arm ({gp.cls}) with finitely many solutions")
    if gp.param_joint is not None:
        if param is None:             # a grid over the held joint's range
            k = gp.order.tolist().index(gp.param_joint)
            lo, hi = (max(gp.lower[k], -np.pi), min(gp.upper[k], np.pi))
            param = (np.linspace(lo, hi, PARAM_GRID + 1)[:-1] + 0.5 * (hi - lo) / PARAM_GRID)[None]
        try:
            pv = _swivel_array(param, N, grid_1d=single)                 # (N, S), same rules as swivel
        except ValueError as exc:
            raise ValueError(str(exc).replace("swivel", "param")) from None
    else:
        pv = np.zeros((N, 1))
    S = pv.shape[1]
    labels = list(gp.labels) if S == 1 else [f"{b},param#{k}" for k in range(S) for b in gp.labels]
    B = len(gp.labels) * S
    if N == 0:
        return AnalyticBatchResult(np.zeros((0, B, robot.nq)), np.zeros((0, B), bool), labels, [],
                                   residuals=np.zeros((0, B)), singular=[], model=robot.name)
    Tr = np.repeat(Ts, S, axis=0)
    prm = pv.reshape(-1) if gp.param_joint is not None else None
    if gp.cls in _geo.CLOSED:              # one compiled call: branches, limits, FK check, duplicates
        thw, valid, cand, exact, inside, res = (a.reshape((N, B) + a.shape[2:]) for a in
                                                _geo.solve_verified(gp, Tr, prm, tol, tol_orthonormal))
        finite = cand
        Q = thw if gp.plain else ch.configuration(np.where(finite[..., None], thw, 0.0))
    else:
        th, cand, exact = _geo.solve(gp, Tr, prm)
        th, cand, exact = (a.reshape((N, B) + a.shape[2:]) for a in (th, cand, exact))
        thw, inside = _wrap_into_limits(th, gp.lower, gp.upper)
        finite = np.isfinite(thw).all(-1)
        Q = ch.configuration(np.where(finite[..., None], thw, 0.0))
        res = np.where(finite, _geo_fk_residual(robot, gp, thw, Q, Ts), np.inf)
        valid = None
    # an arm of its class only within the classification tolerance (e.g. rounded URDF angles):
    # polish its near-exact candidates on the FK error (joint layout = angles only)
    near = cand & exact & inside & finite & (res > tol) & (res <= POLISH_MAX)
    polished = near.any() and robot.nq == len(ch.independent)
    if polished:
        Q = np.array(Q)
        for i, b in zip(*np.nonzero(near)):
            Q[i, b], res[i, b] = _refine(robot, Q[i, b], Ts[i], robot.lower, robot.upper, False)
            thw[i, b] = Q[i, b]
    if valid is None or polished:
        valid = cand & inside & finite & (res <= tol)
        # coincident branches (singular poses): drop a branch equal to an earlier valid one
        earlier = np.tril(np.ones((B, B), bool), -1)                                     # [b, a]: a < b
        step = max(1, 2_000_000 // (B * B * thw.shape[-1]))              # bounded memory (param grids)
        for i in range(0, N, step):
            t, v = thw[i:i + step], valid[i:i + step]
            d = np.abs(np.angle(np.exp(1j * (t[:, :, None] - t[:, None, :])))).max(-1)  # (n, B, B)
            valid[i:i + step] &= ~((d < 1e-9) & earlier & v[:, None, :]).any(-1)
    reasons = [None] * N
    names = [ch.joints[j].name for j in ch.independent]
    c = gp.classification
    for i in np.flatnonzero(~valid.any(1)):
        ex = exact[i]
        if not ex.any():
            best = float(np.min(res[i])) if np.isfinite(res[i]).any() else float("inf")
            reasons[i] = (f"outside the workspace: no branch of the {gp.cls} closed form reaches this "
                          f"pose (its subproblems have least-squares answers only; best FK residual "
                          f"{best:.3g})")
        elif not (ex & inside[i]).any():
            reasons[i] = (f"all {int(ex.sum())} closed-form solutions violate the joint limits ("
                          + ", ".join(f"{n} [{lo:.4g}, {hi:.4g}]" for n, lo, hi in zip(names, gp.lower, gp.upper))
                          + ")")
        else:
            worst = float(np.min(np.where(ex & inside[i], res[i], np.inf)))
            reasons[i] = (f"no candidate passed the FK check (best residual {worst:.3g} > tol {tol:g}); the "
                          f"pose is singular, or the arm is {gp.cls} only within the classification "
                          f"tolerance (axes up to {c.worst_accepted[0]:.3g} m / sine {c.worst_accepted[1]:.3g} "
                          f"from the exact relation; tol {c.tol:g} m, angle_tol {c.angle_tol:g})")
    sol = np.where(valid[..., None], Q, np.nan)
    return AnalyticBatchResult(solutions=sol, valid=valid, branches=labels, reasons=reasons,
                               residuals=np.where(valid, res, np.nan), singular=[None] * N,
                               model=robot.name)


def _geometric_single(robot, gp, arr, param, tol, tol_orthonormal):
    """One pose of a closed class (:data:`.geometric.CLOSED`) in one compiled call, when it has
    a solution and nothing to polish; else None (:func:`_geometric_batch` answers, with the
    reasons)."""
    if arr.dtype != np.float64:
        return None
    try:
        one = _geo.solve_one(gp, arr, 0.0 if param is None else float(param), tol, tol_orthonormal)
    except (TypeError, ValueError):
        return None                     # a malformed param: the general path says what is wrong
    if one is None:
        return None
    q, res, idx = one
    labels = gp.labels
    return AnalyticIKResult(solutions=q if gp.plain else gp.chain.configuration(q),
                            branches=[labels[i] for i in idx], residuals=res, model=robot.name)


def _kernel(plan, impl, single=True):
    """The compiled kernel for ``impl`` "auto" (single poses: if available) or "c" (required),
    else None.  Batches in "auto" mode use the numpy kernels: numpy's vectorised tan/atan2 beat
    libm's scalar sincos/atan2, which dominate the C kernel (≈ 60 % of its time for the 6R arm's
    8 verified branches), so the C kernel pays only where the call overhead dominates."""
    if impl == "auto":
        return _c.kernel_for(plan) if single else None
    if impl == "c":
        k = _c.kernel_for(plan)
        if k is None:
            raise RuntimeError(f"compiled IK kernel requested but unavailable: {_c.status()}")
        return k
    if impl in ("python", "general"):
        return None
    raise ValueError(f"_impl must be 'auto', 'c', 'python' or 'general', got {impl!r}")


@functools.lru_cache(maxsize=64)
def _labels(family: str, S: int) -> tuple:
    if family == SRS and S > 1:
        return tuple(f"{b},swivel#{k}" for k in range(S) for b in HUMAN_BRANCHES)
    return tuple(_SCALAR_BRANCHES[family])


def _fast_candidates(robot, plan, T, swivel, position_only, tol, tol_orthonormal, single_grid, impl):
    """Candidates of :func:`analytic_batch` from the compiled kernel or from
    :func:`.analytic_soa.solve`, or None where the general path must answer (``impl`` "general",
    not a plain (N, 4, 4) float64 array, any invalid pose — the general path raises the error —,
    N = 0)."""
    if impl == "general":
        return None
    if type(T) is not np.ndarray or T.dtype != np.float64 or T.ndim != 3 or T.shape[1:] != (4, 4) \
            or T.shape[0] == 0 or not isinstance(tol, (float, int)) \
            or not isinstance(tol_orthonormal, (float, int)):
        return None
    N = T.shape[0]
    family = plan.family
    kern = _kernel(plan, impl, single=False)
    sw = _swivel_array(swivel, N, grid_1d=single_grid) if family == SRS else None
    if kern is not None:
        out = kern.batch(T, sw, tol, int(position_only), tol_orthonormal)
        if out is None:
            return None
        Qw, valid, inside, res, code, sing = out
        code = np.broadcast_to(code[:, None], valid.shape)
        sing = _SING_ARRAYS[family][sing]
    else:
        E = _soa.pose_rows(T)
        if not _soa.poses_ok(E, tol_orthonormal, position_only):
            return None
        Qw, valid, code, inside, res, sing, _ = _soa.solve(plan, E, tol, position_only, sw)
    labels = list(_labels(family, 1 if sw is None else sw.shape[1]))
    swv = np.repeat(sw, 8, axis=1) if sw is not None else None
    return Qw, valid, code, inside, res, sing, swv, labels


def _reason_for(code, inside, res, tol, robot) -> str:
    codes = set(int(c) for c in code)
    if OK not in codes:
        for c in (OUT_OF_PLANE, OUTSIDE, DEGENERATE, ELBOW):
            if c in codes:
                return _REASONS[c]
    ok = code == OK
    if not (ok & inside).any():
        return (f"all {int(ok.sum())} closed-form candidates violate the joint limits "
                f"({', '.join(f'{n} [{lo:.4g}, {hi:.4g}]' for n, lo, hi in zip(robot.joint_names, robot.lower, robot.upper))})")
    worst = float(np.nanmin(np.where(ok & inside, res, np.nan)))
    return (f"no candidate passed the FK check (best residual {worst:.3g} > tol {tol:g}); "
            "the pose is at a singularity or not reachable with this orientation")


def analytic(robot, T, *, swivel=None, position_only: bool | None = None, tol: float = 1e-9,
             tol_orthonormal: float = 1e-6, method: str = "robust", param=None, _impl: str = "auto"):
    """Every closed-form IK solution of ``robot`` at pose ``T`` inside the joint limits.

    ``T``: 4×4 pose of ``robot.tool`` (m) — or a batch (N, 4, 4), which returns an
    :class:`AnalyticBatchResult` (same as :func:`analytic_batch`).  For planar2r a position (3,)
    is accepted.  ``method="book"`` (prosthetic_arm only) runs the book's Cramer-rule procedure
    :func:`prosthetic_book_procedure`, whose elbow determinant Δ may vanish.

    Returns :class:`AnalyticIKResult`: ``solutions`` (K, nq), ``branches``, ``reason`` (None,
    or why there is none: outside the workspace, elbow determinant, wrist singularity, joint
    limits), ``swivel`` (human_arm7), ``residuals`` (FK check).  See the module docstring.

    One pose is solved by the compiled kernel (:mod:`.analytic_c`) when a C compiler is
    available — built once per robot parameterisation on first use (≈ 0.2 s, cached on disk;
    ``ANTHROARM_IK_C=0`` disables it) — else by the scalar kernels of :mod:`.analytic_scalar`."""
    if not (type(tol) is float and type(tol_orthonormal) is float        # the usual call: one test
            and 0.0 < tol < math.inf and 0.0 < tol_orthonormal < math.inf):
        _check_tol("tol", tol)
        _check_tol("tol_orthonormal", tol_orthonormal)
    arr = np.asarray(T, dtype=float) if not isinstance(T, np.ndarray) else T
    if method == "book":
        spec = getattr(robot, "spec", None)
        if spec is None or spec.name not in _registry.BOOK_PROCEDURES or robot.nq != 6 or robot.tool != spec.tool_name:
            raise ValueError("method='book' (Cramer's rule, Eqs. (7-20)-(7-22)) is the book's procedure for the "
                             "prosthetic arm of Fig. 7-2 (catalog 'prosthetic_arm', all 6 joints, its tool) only")
        Ts, single = _check_poses(arr, tol_orthonormal=tol_orthonormal)
        if not single:
            raise ValueError("method='book' takes one pose")
        return _book_result(robot, Ts[0], spec.params, tol)
    if method != "robust":
        raise ValueError(f"method must be 'robust' or 'book', got {method!r}")
    if _plan(robot) is None:
        gp = _geo.plan_for(robot)
        if gp is not None:
            if arr.shape == (4, 4) and gp.cls in _geo.CLOSED and swivel is None and not position_only \
                    and (param is None) == (gp.param_joint is None) and _impl != "general":
                fast = _geometric_single(robot, gp, arr, param, tol, tol_orthonormal)
                if fast is not None:
                    return fast
            res = _geometric_batch(robot, gp, arr, swivel, position_only, tol, tol_orthonormal, param)
            return res[0] if np.ndim(arr) == 2 else res
    _no_param(robot, param)
    if arr.ndim == 2 and _impl != "general":
        fast = _analytic_single_fast(robot, arr, swivel, position_only, tol, tol_orthonormal, _impl)
        if fast is not None and len(fast):       # solutions found: nothing to rescue
            return fast
        if fast is not None:
            plan = _plan(robot)
            po = plan.form.position_only if position_only is None else position_only
            return _rescued_single(robot, plan, arr, po, tol, fast)
    return _analytic_general(robot, arr, swivel=swivel, position_only=position_only, tol=tol,
                             tol_orthonormal=tol_orthonormal, _impl=_impl)


def _analytic_general(robot, arr, *, swivel=None, position_only=None, tol=1e-9, tol_orthonormal=1e-6,
                      _impl="auto"):
    """:func:`analytic` through :func:`analytic_batch` (one pose = a batch of one; ``_impl``
    "general": the general path, the reference of the fast paths' tests)."""
    arr = np.asarray(arr, dtype=float)
    if arr.ndim == 3:
        return analytic_batch(robot, arr, swivel=swivel, position_only=position_only, tol=tol,
                              tol_orthonormal=tol_orthonormal, _impl=_impl)
    batch = analytic_batch(robot, arr, swivel=swivel, position_only=position_only, tol=tol,
                           tol_orthonormal=tol_orthonormal, _single_grid=True, _impl=_impl)
    return batch[0]


# ---------------------------------------------------------------------------- single-pose fast path
_SCALAR_BRANCHES = {SIXR: SIXR_BRANCHES, PROSTHETIC: PROSTHETIC_BRANCHES, PLANAR: PLANAR_BRANCHES,
                    SRS: HUMAN_BRANCHES}
_SCALAR_KERNELS = {SIXR: ks.sixr, PROSTHETIC: ks.prosthetic, PLANAR: ks.planar}


def _analytic_single_fast(robot, arr, swivel, position_only, tol, tol_orthonormal, impl):
    """:func:`analytic` of one pose by the compiled kernel (:mod:`.analytic_c`) or the scalar
    kernels (:mod:`.analytic_scalar`); None where the vectorised path must answer (unsupported
    robot, anything unusual in the input — it raises the error —; the scalar kernels also leave
    swivel grids to it)."""
    if type(arr) is not np.ndarray or arr.dtype != np.float64 \
            or not isinstance(tol, (float, int)) or not isinstance(tol_orthonormal, (float, int)):
        return None
    plan = _plan(robot)
    if plan is None:
        return None
    family = plan.family
    if position_only is None:
        position_only = plan.form.position_only
    if arr.shape == (4, 4):
        kern = _kernel(plan, impl)
        if kern is not None:
            return _single_c(kern, robot, family, arr, swivel, position_only, tol, tol_orthonormal)
        rows = arr.tolist()
        r3 = rows[3]
        if not math.isfinite(sum(rows[0]) + sum(rows[1]) + sum(rows[2]) + sum(r3)):
            return None
        if abs(r3[0]) > 1e-12 or abs(r3[1]) > 1e-12 or abs(r3[2]) > 1e-12 or abs(r3[3] - 1.0) > 1e-12:
            return None
        if not position_only and not _rotation_ok(rows, tol_orthonormal):
            return None
    elif arr.shape == (3,) and position_only:
        x, y, z = arr.tolist()
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            return None
        rows = [[1.0, 0.0, 0.0, x], [0.0, 1.0, 0.0, y], [0.0, 0.0, 1.0, z]]
    else:
        return None
    if family == SRS:
        if swivel is None:
            return None                                   # a grid: the vectorised path
        if isinstance(swivel, (float, int)):
            sw = float(swivel)
        else:
            try:
                sw = float(swivel) if np.ndim(swivel) == 0 else None
            except (TypeError, ValueError):
                return None
        if sw is None or not math.isfinite(sw):
            return None
        cand = ks.human(rows, plan, tol, sw, position_only)
    else:
        cand = _SCALAR_KERNELS[family](rows, plan, tol, position_only)
    labels = _SCALAR_BRANCHES[family]
    B, nq = len(labels), plan.nq
    if cand.code != OK:
        return AnalyticIKResult(np.zeros((0, nq)), [], _REASONS[cand.code],
                                swivel=None if family != SRS else np.zeros(0),
                                residuals=np.zeros(0), singular=cand.singular, model=robot.name)
    sols = cand.sols
    if not sols:                                          # why: the general path's wording
        code = np.zeros(B, dtype=int)
        inside = np.zeros(B, dtype=bool)
        res = np.full(B, np.inf)
        for b, r in cand.tried:
            inside[b] = True
            res[b] = r
        return AnalyticIKResult(np.zeros((0, nq)), [], _reason_for(code, inside, res, tol, robot),
                                swivel=None if family != SRS else np.zeros(0),
                                residuals=np.zeros(0), singular=cand.singular, model=robot.name)
    if len(sols) > 1:
        sols = _dedup_scalar(sols)
    flat = []
    for s in sols:
        flat += s[1]
    return AnalyticIKResult(
        solutions=np.array(flat).reshape(len(sols), nq),
        branches=[labels[s[0]] for s in sols],
        reason=None,
        swivel=None if family != SRS else np.full(len(sols), sw),
        residuals=np.array([s[2] for s in sols]),
        singular=cand.singular, model=robot.name)


#: singular-configuration messages by the kernels' codes (0: none)
_SING_TEXT = {
    SIXR: (None, "wrist singularity (sin θ5 = 0: only θ4 + θ6 is determined; θ4 = 0 returned)",
                 "shoulder singularity (wrist centre on the z0 axis: θ1 is free; θ1 = 0 returned)"),
    PROSTHETIC: (None, "elbow singularity (straight arm, sin θ4 = 0: θ3 + θ5 only determined; θ3 = 0 returned)",
                       "shoulder singularity (elbow on the vertical axis: θ1 is free; θ1 = -90° returned)"),
    SRS: (None, "straight elbow: the swivel angle then turns the elbow axis about the arm"),
    PLANAR: (None,),
}
_SING_ARRAYS = {k: np.array(v, dtype=object) for k, v in _SING_TEXT.items()}


def _single_c(kern, robot, family, arr, swivel, position_only, tol, tol_orthonormal):
    """One pose through the compiled kernel (validation, candidates, FK check, duplicates in C)."""
    sw = None
    if family == SRS:
        if isinstance(swivel, (float, int)):
            sw = (float(swivel),)
            if not math.isfinite(sw[0]):
                return None
        else:
            sw = _swivel_array(swivel, 1, grid_1d=True)[0]           # ValueError as the general path
            if sw.size > _c.MAX_SINGLE_S:
                return None
    out = kern.single(arr, sw, tol, int(position_only), tol_orthonormal)
    if out is None:
        return None
    code, sing, bl, sols, res, (arrs, S) = out
    nq = kern.nq
    sing_text = _SING_TEXT[family][sing]
    if code != OK or not bl:
        if code != OK:
            reason = _REASONS[code]
        else:
            B = kern.nb * S
            reason = _reason_for(np.zeros(B, dtype=int), arrs["inside"][:B].astype(bool), arrs["res"][:B].copy(),
                                 tol, robot)
        return AnalyticIKResult(np.zeros((0, nq)), [], reason, swivel=None if sw is None else np.zeros(0),
                                residuals=np.zeros(0), singular=sing_text, model=robot.name)
    labels = _labels(family, S)
    return AnalyticIKResult(
        solutions=sols, branches=[labels[b] for b in bl], reason=None,
        swivel=None if sw is None else np.array([sw[b // 8] for b in bl], dtype=float),
        residuals=res, singular=sing_text, model=robot.name)


def _dedup_scalar(sols):
    """Drop solutions within 1e-9 rad (every joint) of an earlier one (coincident branches at
    singular poses), as the general path does.  Pre-filter: the sums of the joints of two
    duplicates differ by < nq·1e-9, so only sums closer than 1e-8 get the full test."""
    keys = sorted([sum(s[1]) for s in sols])
    k0 = keys[0]
    for k1 in keys[1:]:
        if k1 - k0 < 1e-8:
            break
        k0 = k1
    else:
        return sols
    keep = [sols[0]]
    for s in sols[1:]:
        q = s[1]
        if all(max(abs(a - b) for a, b in zip(q, k[1])) >= 1e-9 for k in keep):
            keep.append(s)
    return keep


def _rotation_ok(rows, tol_orthonormal) -> bool:
    """|RᵀR − I| ≤ tol and det R ≥ 0 (the test of :func:`_check_poses`) for nested lists."""
    (a, b, c, _), (d, e, f, _), (g, h, i, _) = rows[0], rows[1], rows[2]
    err = max(abs(a * a + d * d + g * g - 1.0), abs(b * b + e * e + h * h - 1.0), abs(c * c + f * f + i * i - 1.0),
              abs(a * b + d * e + g * h), abs(a * c + d * f + g * i), abs(b * c + e * f + h * i))
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return err <= tol_orthonormal and det >= 0.0


# ---------------------------------------------------------------------------- the book's procedure
def prosthetic_book_procedure(T, L1: float = 0.340, L2: float = 0.260, L3: float = 0.130,
                              *, det_tol: float = 1e-9, printed_m2: bool = False):
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
        return [], (f"elbow determinant Δ = m3·x − m1·z + L3(m1·n3 − m3·n1) = {Delta:.3g} ≈ 0: "
                    "Cramer's rule (7-20)/(7-21) cannot solve the elbow (use the robust solver)")
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
    Qw, inside = _wrap_into_limits(Q, robot.lower, robot.upper)
    res = _fk_residual(robot, Qw[None], T[None], False)[0]
    ok = inside & (res <= tol)
    labels = ["elbow_root=+", "elbow_root=-"]
    if not ok.any():
        why = ("the book's asin-based θ3/θ6 (7-27)/(7-30) give no FK-consistent solution inside the limits "
               f"(residuals {', '.join(f'{r:.3g}' for r in res)}); use method='robust'")
        return AnalyticIKResult(np.zeros((0, robot.nq)), [], why, residuals=np.zeros(0), model=robot.name)
    return AnalyticIKResult(Qw[ok], [lb for lb, k in zip(labels, ok) if k], None, residuals=res[ok],
                            model=robot.name)


# ---------------------------------------------------------------------------- poses on the limits
#: how far (rad) a closed-form candidate may lie outside a joint limit and still be kept, clipped
#: onto the limit and polished (see :func:`_rescue_pose`).  The closed forms lose precision at
#: double roots and singular configurations — an arccos near ±1, a square root of a discriminant
#: near 0 — where a joint is determined by the pose only to ≈ √ε ≈ 1.5e-8 rad; a configuration with
#: a joint exactly on its limit then yields a candidate up to a few 1e-8 rad beyond it.  1e-6 rad
#: covers that with margin; every kept candidate still passes the FK check (``tol``).
LIMIT_SLACK = 1e-6


def _check_tol(name, value):
    """``tol`` / ``tol_orthonormal``: a finite positive number, else ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name} must be a positive number, got {type(value).__name__} {value!r}")
    if not (math.isfinite(float(value)) and float(value) > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


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

    for _ in range(2):                         # at most two families (shoulder and elbow) at once
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

        sol = least_squares(err, q, bounds=(lo, hi), method="trf", xtol=1e-15, ftol=1e-15,
                            gtol=1e-15, max_nfev=60)
        if np.isfinite(sol.x).all():
            q = np.clip(sol.x, lo, hi)
    return q, float(np.abs(err(q)).max())


def _rescue_pose(robot, plan, T, tol, position_only):
    """Solutions of one pose (4×4) whose closed-form candidates lie on or just beyond a limit.

    Run where a pose got no solution.  Each candidate of the reference formulas
    (:func:`_candidates`) is shifted by 2π into the limits, moved along its exact self-motions
    (:func:`_slide_into_limits`: a straight elbow, the shoulder or the wrist at a singularity,
    where the formulas return one representative of a one-parameter family) and, if it is then
    within :data:`LIMIT_SLACK` of the limits, clipped onto them and polished by a few
    Gauss–Newton steps (the candidates at such poses carry ≈ √ε errors).  Kept if it passes the
    FK check ``tol``.  Returns ``[(branch, q, residual)]``; not for the redundant ``srs_7r``
    family (its limits are handled by the swivel angle)."""
    family = plan.family
    if family == SRS:
        return []
    Ts = T[None]
    Q, code, _s, _w, _l = _candidates(family, plan.params, Ts[:, :3, :3], Ts[:, :3, 3], None)
    Q = Q[0]
    # ELBOW: the discriminant of (7-22) is below its rounding threshold; at a double root (the
    # elbow circle tangent to the plane) the candidate with t = 0 is the solution — the FK decides
    ok = ((code[0] == OK) | (code[0] == ELBOW)) & np.isfinite(Q).all(-1)
    if not ok.any():
        return []
    lo, hi = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
    lo_f = np.where(np.isfinite(lo), lo, -np.pi)
    Qs = Q - np.floor((Q - lo_f + LIMIT_SLACK) / TWO_PI) * TWO_PI
    Js = np.asarray(robot.jacobian(np.where(ok[:, None], Qs, 0.0)))
    rows = slice(0, 3) if position_only else slice(None)
    out = []
    for b in np.flatnonzero(ok):
        q = _slide_into_limits(Qs[b], Js[b][rows], lo, hi)
        if q is None:
            continue
        q, res = _refine(robot, np.clip(q, lo, hi), T, lo, hi, position_only, polish=False)
        if res > 1e-6:                     # not a near-solution: skip the polish
            continue
        q, res = _refine(robot, q, T, lo, hi, position_only)
        if res <= tol and all(np.abs(q - k[1]).max() >= 1e-9 for k in out):
            out.append((int(b), q, res))
    return out


def _pose4(arr):
    """A 4×4 pose from a 4×4 array or (planar2r, position only) a position (3,)."""
    if arr.shape == (3,):
        T = np.eye(4)
        T[:3, 3] = arr
        return T
    return np.asarray(arr, dtype=float)


def _rescued_single(robot, plan, arr, position_only, tol, result):
    """``result`` of one pose, with :func:`_rescue_pose`'s solutions where it had none."""
    if len(result) or plan.family == SRS or result.reason in (_REASONS[OUTSIDE], _REASONS[DEGENERATE],
                                                               _REASONS[OUT_OF_PLANE]):
        return result
    found = _rescue_pose(robot, plan, _pose4(arr), tol, position_only)
    if not found:
        return result
    labels = _SCALAR_BRANCHES[plan.family]
    return AnalyticIKResult(solutions=np.array([f[1] for f in found]), branches=[labels[f[0]] for f in found],
                            reason=None, swivel=None, residuals=np.array([f[2] for f in found]),
                            singular=result.singular, model=robot.name)
