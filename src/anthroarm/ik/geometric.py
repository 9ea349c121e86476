"""Closed-form IK of any 6R arm whose geometry allows it, by IK-Geo's solver classes.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, §IV (the 6-DOF solvers); the decompositions were read from
the reference implementation (github.com/rpiRobotics/ik-geo, ``matlab/+IK``); the code is our
own, batched over N poses, built on the subproblems of :mod:`anthroarm.ik.subproblems`.

The arm is read from ``robot.chain`` (:func:`anthroarm.ik.classify.classify`), never from its
name.  Conventions (IK-Geo): joint i turns about the unit axis ``h_i`` (base frame, q = 0);
``P[0]`` is the base → joint 1 offset, ``P[i]`` joint i → joint i+1, ``P[6]`` joint 6 → tool
(m); the tool orientation at q = 0 is removed first, ``R06 = R · R_tool(0)ᵀ``.  Joints may slide
along their own axes without changing the kinematics, which makes the offsets between
intersecting axes zero (the form each solver needs: :func:`ik_geo_P`).

========================================  =====================================  ==========
class (:mod:`.classify`)                  decomposition                          branches
========================================  =====================================  ==========
``spherical_two_parallel``                q1 SP4, q3 SP3, q2 SP1; wrist q5 SP4,  2 × 2 × 2
                                          q4, q6 SP1
``spherical_two_intersecting``            q3 SP3, (q1, q2) SP2; wrist as above   2 × 2 × 2
``three_parallel_two_intersecting``       q1 SP4, q5 SP4, q2 + q3 + q4 and q6    2 × 2 × 2
                                          SP1, q3 SP3, q2 SP1, q4 by difference
``spherical``                             (q1, q2, q3) SP5 (quartic); the wrist   4 × 2
``three_parallel``                        (q1, q5) SP6 (quartic); then as above   4 × 2
``two_parallel``                          1-D search over q1: (q4, q6) SP6,      ≤ 16
                                          θ23 SP1, error ‖span‖ − ‖p23‖; q2,
                                          q5 SP1
``two_intersecting``                      1-D search over q4: (q1, q2, q3) SP5,  ≤ 16
                                          error h5ᵀ R04ᵀ R06 h6 − h5ᵀ h6;
                                          q5, q6 SP1
``gen_six_dof``                           2-D search over (q1, q2): (q3, q4,     ≤ 16
                                          q5) SP5, error ‖R05 h6 − R06 h6‖;
                                          local minima polished by Newton, q6
                                          SP1
========================================  =====================================  ==========

The search classes (IK-Geo ``IK_2_parallel``, ``IK_2_intersecting``; compiled in
:mod:`.search`, whose docstring has the details) sample the searched joint on
:data:`SEARCH_GRID` values, follow each root of the inner subproblem from sample to sample,
refine every sign change of the error by regula falsi (Illinois) to ``|e| ≤``
:data:`SEARCH_TOL`, minimise the dips of ``|e|`` between samples (a pair of roots closer than a
sample interval), look again more finely where roots fold or jump, and polish the roots next
to a fold by Newton steps on the whole arm's pose; ~1–3 ms a pose.  A root that lives inside
one grid interval with no root of the inner subproblem at either end is not found (4 of 9 600
random reachable poses of 96 random arms).

``gen_six_dof`` (IK-Geo ``IK_gen_6_dof``) samples (q1, q2) on a :data:`SEARCH_GRID_2D` ²
grid; every (sample, SP5 root) whose error ``‖R05 h6 − R06 h6‖`` is below 0.3 and not above
any of its 8 neighbours' seeds Newton steps on the whole pose (kept where they converge to
:data:`SEARCH_TOL`).  A branch whose basin the grid misses is not found (no completeness
claim), and it costs tens of ms a pose; a 7-joint arm is not solved this way.

A class that holds for the reversed chain (a spherical *shoulder*: the prosthetic arm) is
solved on the reversed arm: T = e^{ξ1 q1} ⋯ e^{ξ6 q6} M gives T⁻¹ = e^{ξ'1 q6} ⋯ e^{ξ'6 q1} M⁻¹
with ξ'_k the twist of joint 7 − k seen from the tool at q = 0 and its axis negated
(``h'_k = −R_toolᵀ h_{7−k}`` through ``R_toolᵀ (o_{7−k} − p_tool)``), the same angles.

Every branch returned by :func:`solve` is a candidate: its ``exact`` flag is False where a
subproblem had only a least-squares answer (the pose is out of reach on that branch).  The
closed classes (:data:`CLOSED`) are compiled per pose (:mod:`anthroarm.jit`) from the
subproblem kernels, and :func:`solve_verified` / :func:`solve_nearest` add in the same compiled
call the 2π shift into the joint limits, the FK check by the chain's product of exponentials
(in joint-local frames, :func:`local_frames`) and the removal of duplicates (used by
:func:`anthroarm.ik.closed_form.analytic`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..chain_kernels import put_joint
from ..check_rows import CheckRow
from ..jit import kernel, local, local2, local_flags, view2
from ..threads import run_rows
from . import classify as C
from . import subproblems as sp
from .search import SEARCH_BRANCHES, SEARCH_GRID, SEARCH_GRID_2D, SEARCH_TOL, solve6, solve_search  # noqa: F401 - re-exported
from .subproblems import TOL, TOL_QUARTIC, sp1_cs, sp2_cs, sp3_cs, sp4_cs, sp5_one, sp6_one
from .vec3 import (
    add,
    angle_cs,
    atan2,
    cross,
    dot,
    mat,
    mm,
    mtm,
    mtv,
    mv,
    neg,
    norm,
    perpendicular,
    rot_cs,
    rotate_cs,
    rows6,
    rows7,
    sub,
    transpose,
    vec,
    wrap,
)

#: the classes solved here in closed form or by a 1-D search (the others: use aa.ik.solve)
SOLVED = (
    C.SPHERICAL_TWO_PARALLEL,
    C.SPHERICAL_TWO_INTERSECTING,
    C.THREE_PARALLEL_TWO_INTERSECTING,
    C.SPHERICAL,
    C.THREE_PARALLEL,
    C.TWO_PARALLEL,
    C.TWO_INTERSECTING,
    C.GEN_SIX_DOF,
)
#: the classes of :data:`SOLVED` solved by a search (1-D over one joint angle; 2-D for
#: ``gen_six_dof``)
SEARCHED = (C.TWO_PARALLEL, C.TWO_INTERSECTING, C.GEN_SIX_DOF)

#: per class: (the unknowns of each branching subproblem, its number of roots), outermost first
_LABELS = {
    C.SPHERICAL_TWO_PARALLEL: (("q1", 2), ("q3", 2), ("q5", 2)),
    C.SPHERICAL_TWO_INTERSECTING: (("q3", 2), ("q1q2", 2), ("q5", 2)),
    C.THREE_PARALLEL_TWO_INTERSECTING: (("q1", 2), ("q5", 2), ("q3", 2)),
    C.SPHERICAL: (("q1q2q3", 4), ("q5", 2)),
    C.THREE_PARALLEL: (("q1q5", 4), ("q3", 2)),
}


def n_branches(cls: str) -> int:
    """The number of branch slots of a class solver per pose: 8, or :data:`SEARCH_BRANCHES`
    for a search class."""
    return SEARCH_BRANCHES if cls in SEARCHED else 8


def branch_labels(cls: str) -> tuple[str, ...]:
    """The branch labels of a class: which root of each of its branching subproblems
    (``"q1=0,q3=1,q5=0"``: the first root for q1, the second for q3, …); for a search class
    which root of the search along the searched joint, in the order found
    (``"q1root=2"``; slots are filled from the first)."""
    if cls in SEARCHED:
        j = {C.TWO_PARALLEL: "q1", C.TWO_INTERSECTING: "q4", C.GEN_SIX_DOF: "q1q2"}[cls]
        return tuple(f"{j}root={k}" for k in range(SEARCH_BRANCHES))
    out = [""]
    for name, k in _LABELS[cls]:
        out = [f"{o},{name}={i}".lstrip(",") for o in out for i in range(k)]
    return tuple(out)


@dataclass(frozen=True)
class GeoPlan:
    """What a call needs besides the pose: the class, the (possibly reversed) kinematics in
    IK-Geo's form (``H`` (6, 3), ``P`` (7, 3), ``R_tool`` (3, 3)), the map from the solver's
    joints to ``robot.chain.independent``, the per-joint limits (rad; ±inf for continuous
    joints) and the classification (its tolerances and near calls)."""

    cls: str
    reversed: bool
    H: np.ndarray
    P: np.ndarray
    R_tool: np.ndarray
    order: np.ndarray  # independent joint k is solver joint order[k]
    lower: np.ndarray
    upper: np.ndarray
    classification: object  # the anthroarm.ik.classify.Classification
    chain: object
    tool: str
    labels: tuple
    #: a 7-joint arm: the last joint on the path is the family parameter (its index along the
    #: path, its axis and point at q = 0, and the tool pose M at q = 0, 4×4); else None
    param_joint: int | None = None
    param_axis: np.ndarray | None = None
    param_point: np.ndarray | None = None
    M: np.ndarray | None = None
    #: the FK check of the compiled path: every joint on the path (path order) as read from the
    #: chain (not snapped to the class): axes (n, 3) and points (n, 3) at q = 0, the tool pose
    #: at q = 0 (4×4), limits in path order (rad; ±inf continuous)
    fk_axes: np.ndarray | None = None
    fk_points: np.ndarray | None = None
    fk_M: np.ndarray | None = None
    lower_path: np.ndarray | None = None
    upper_path: np.ndarray | None = None
    #: the configuration q is the joint angles themselves (nq = n, and no continuous joint: no
    #: cos/sin pair)
    plain: bool = False

    @functools.cached_property
    def order_is_path(self) -> bool:
        """The independent joints are the path's joints in path order (no reordering)."""
        return bool((self.order == np.arange(len(self.order))).all())

    @functools.cached_property
    def packed(self) -> tuple:
        """The plan's constants as the compiled drivers take them (:func:`_unpack`): one float
        array (H, P, R_tool, the held joint's axis and point, the tool pose at q = 0, the
        chain's FK as :func:`local_frames`, limits in path order) and one int array (class index,
        reversed, joints on the path n, the path position of each independent joint, the
        chain's nq, then per independent joint its first entry in q and whether it is
        continuous: ``Chain._configuration_index``)."""
        pa = np.zeros(3) if self.param_axis is None else self.param_axis
        pp = np.zeros(3) if self.param_point is None else self.param_point
        frames = local_frames(self.fk_axes, self.fk_points, self.fk_M)
        cf = np.concatenate(
            [
                a.ravel()
                for a in (
                    self.H,
                    self.P,
                    self.R_tool,
                    pa,
                    pp,
                    self.fk_M,
                    frames,
                    self.lower_path,
                    self.upper_path,
                )
            ]
        ).astype(float)
        n, nq = len(self.fk_axes), self.chain.nq
        if nq > 2 * n:  # the compiled calls' scratch (local arrays) holds 2 entries a joint
            raise ValueError(f"{self.chain.name}: nq = {nq} > 2 × {n} joints on the path")
        ci = np.array(
            [
                CLOSED.index(self.cls) if self.cls in CLOSED else -1,
                int(self.reversed),
                n,
                *self.order,
                nq,
                *self.chain._configuration_index.ravel(),
            ],
            dtype=np.int64,
        )
        return cf, ci


def _common_point(H, pts):
    """Least-squares common point of lines (h_i, o_i)."""
    M = sum(np.eye(3) - np.outer(h, h) for h in H)
    b = sum((np.eye(3) - np.outer(h, h)) @ p for h, p in zip(H, pts))
    return np.linalg.lstsq(M, b, rcond=None)[0]


def ik_geo_P(cls: str, H: np.ndarray, points: np.ndarray, p_tool: np.ndarray) -> np.ndarray:
    """IK-Geo's offsets ``P`` (7, 3) of a 6R arm of class ``cls``: the joints whose axes meet
    slid along their axes to the common point (spherical wrist: p45 = p56 = 0; intersecting
    1–2: p12 = 0; intersecting 5–6: p56 = 0).  ``H`` (6, 3), ``points`` (6, 3) one point of
    each axis, ``p_tool`` (3,) the tool position at q = 0 (base frame, m)."""
    o = np.array(points, dtype=float)
    groups = {
        C.SPHERICAL_TWO_PARALLEL: [(3, 4, 5)],
        C.SPHERICAL: [(3, 4, 5)],
        C.SPHERICAL_TWO_INTERSECTING: [(0, 1), (3, 4, 5)],
        C.THREE_PARALLEL_TWO_INTERSECTING: [(4, 5)],
        C.THREE_PARALLEL: [],
        C.TWO_PARALLEL: [],
        C.TWO_INTERSECTING: [(4, 5)],
        C.GEN_SIX_DOF: [],
    }[cls]
    for g in groups:
        c = _common_point(H[list(g)], o[list(g)])
        for i in g:
            o[i] = c
    return np.diff(np.vstack([np.zeros(3), o, p_tool]), axis=0)


def _reversed(kin: C.Kinematics):
    """(H, points, R_tool, p_tool) of the arm read from the tool at q = 0 (module docstring)."""
    Rt, pt = kin.R_tool, kin.p_tool
    H = -(kin.H[::-1] @ Rt)  # rows: −R_toolᵀ h
    pts = (kin.points[::-1] - pt) @ Rt
    return H, pts, Rt.T, -Rt.T @ pt


def plan_for(robot) -> GeoPlan | None:
    """The :class:`GeoPlan` of ``robot`` for its tool (kept on the robot:
    :meth:`~anthroarm.robot.Robot.derived`), or None when its geometry has no closed form here
    (not 6R on the path to the tool, a mimic joint, joints off that path, or a class in
    :data:`anthroarm.ik.classify.CLASSES` other than :data:`SOLVED`)."""
    return robot.derived("ik.geometric.plan", _build)


def classification(robot):
    """The classification of ``robot`` at its tool (None where the chain cannot be read, e.g.
    a mimic joint on the path)."""
    try:
        return C.classify(robot)
    except Exception:  # noqa: BLE001 - UnsupportedModelError (mimic) and kin: no class
        return None


def _build(robot) -> GeoPlan | None:
    c = classification(robot)
    if c is None:
        return None
    ch = robot.chain
    kin = c.kinematics
    if sorted(kin.joints) != sorted(ch.independent):
        return None  # joints off the tool path: a solution is not a configuration
    param = None
    if (
        c.name == C.NOT_6R
        and kin.n == 7
        and all(k in ("revolute", "continuous") for k in kin.kinds)
    ):
        # a redundant 7R arm: hold the last joint as the family parameter; the first six joints
        # with the tool at q = 0 are a 6R arm (their relations do not depend on the last joint)
        param = 6
        c6 = C.classify_kinematics(
            C.Kinematics(
                kin.H[:6],
                kin.points[:6],
                kin.P[:6],
                kin.R_tool,
                kin.p_tool,
                kin.joints[:6],
                kin.kinds[:6],
                kin.names[:6],
            ),
            c.tol,
            c.angle_tol,
        )
        kin6, compatible = c6.kinematics, c6.compatible
    else:
        kin6, compatible = kin, c.compatible
    # a 7-joint arm: not by the 2-D search (seconds per pose for a grid of the held joint)
    pick = next(
        (
            (n, r)
            for n, r in compatible
            if n in SOLVED and not (param is not None and n == C.GEN_SIX_DOF)
        ),
        None,
    )
    if pick is None:
        return None
    cls, rev = pick
    if rev:
        H, pts, R_tool, p_tool = _reversed(kin6)
    else:
        H, pts, R_tool, p_tool = kin6.H, kin6.points, kin6.R_tool, kin6.p_tool
    path = kin.joints  # solve() turns a reversed solution back to this order
    P = ik_geo_P(cls, H, pts, p_tool)
    order = np.array([path.index(j) for j in ch.independent])
    lo = np.array(
        [
            -np.inf if ch.joints[j].kind == "continuous" else ch.joints[j].lower
            for j in ch.independent
        ]
    )
    hi = np.array(
        [
            np.inf if ch.joints[j].kind == "continuous" else ch.joints[j].upper
            for j in ch.independent
        ]
    )
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = kin.R_tool, kin.p_tool
    inv = np.argsort(order)  # path position -> independent joint
    extra = dict(
        fk_axes=np.ascontiguousarray(kin.H, dtype=float),
        fk_points=np.ascontiguousarray(kin.points, dtype=float),
        fk_M=M,
        lower_path=np.ascontiguousarray(lo[inv]),
        upper_path=np.ascontiguousarray(hi[inv]),
        plain=robot.nq == len(ch.independent)
        and all(ch.joints[j].kind != "continuous" for j in ch.independent),
    )
    if param is not None:
        extra.update(param_joint=param, param_axis=kin.H[param], param_point=kin.points[param], M=M)
    return GeoPlan(
        cls,
        rev,
        np.ascontiguousarray(H, dtype=float),
        np.ascontiguousarray(P, dtype=float),
        np.ascontiguousarray(R_tool, dtype=float),
        order,
        lo,
        hi,
        c,
        ch,
        robot.tool,
        branch_labels(cls),
        **extra,
    )


# ----------------------------------------------------------------------------- the closed classes
# One compiled kernel per class and pose (:mod:`anthroarm.jit`), built from the subproblem
# kernels of :mod:`.subproblems`; vectors are tuples (:mod:`.vec3`).  Each writes its 8
# branches into the rows of B (8, :data:`BRANCH_ROW`): the six angles (rad), their cosines
# (from column :data:`COS`) and sines (:data:`SIN`), whether the branch exists (:data:`EXISTS`,
# 1.0 / 0.0) and whether every subproblem on it was exact (:data:`EXACT`) — one array, so a
# call passes one reference, not five — in the order of the labels: the first branching
# subproblem outermost, the root index innermost.  A branch under a root that does not exist
# is left NaN / not existing.  An angle travels as its rotation, the pair a = (cos θ, sin θ):
# the subproblems give the rotation they find so (``sp*_cs``, :func:`.subproblems.unit_cs`),
# the rotations that follow and the FK check of :func:`_verified` evaluate no trigonometry,
# and the angles themselves are read at the end, in one vectorised loop (:func:`_angles`).
COS, SIN, EXISTS, EXACT, BRANCH_ROW = 6, 12, 18, 19, 20


@kernel
def _none(B, b0, b1):
    """Branches b0 … b1 − 1 do not exist (their root does not)."""
    for b in range(b0, b1):
        B[b, EXISTS] = 0.0


@kernel
def _put(B, b, a1, a2, a3, a4, a5, a6, v, e):
    """Branch b: its six rotations (pairs (cos θ, sin θ)) and its flags; the angles are read
    from them at the end (:func:`_angles`)."""
    row = (a1, a2, a3, a4, a5, a6)
    for j in range(6):
        B[b, COS + j], B[b, SIN + j] = row[j]
    B[b, EXISTS], B[b, EXACT] = 1.0 if v else 0.0, 1.0 if e else 0.0


@kernel
def _angles(B):
    """The six angles of every branch row of B read from their cosines and sines,
    θ = atan2(sin, cos) ∈ (−π, π] (:func:`.vec3.atan2`): one loop of 48 independent atan2 on
    contiguous scratch, which the compiler vectorises — the subproblems hand on rotations, and
    an angle is only read once its branch is complete."""
    C, S, A = local(48), local(48), local(48)
    for b in range(8):
        for j in range(6):
            C[6 * b + j], S[6 * b + j] = B[b, COS + j], B[b, SIN + j]
    for k in range(48):
        A[k] = atan2(S[k], C[k])
    for b in range(8):
        for j in range(6):
            B[b, j] = A[6 * b + j]


@kernel
def _wrist(h, R03, R06, B, b, a1, a2, a3, ex):
    """Spherical wrist from R36 = R03ᵀ R06 (:func:`_wrist_of`); branches b (first q5 root) and
    b + 1.  a1, a2, a3: the rotations (cos, sin) of q1, q2, q3."""
    u, w = _wrist_reads(h, mtm(R03, R06))
    _wrist_of(h, u, w, B, b, a1, a2, a3, ex)


@kernel
def _wrist_reads(h, R):
    """(R h6, R x), x = :func:`.vec3.perpendicular` of h6: the two columns of a rotation R that
    :func:`_wrist_of` reads of R36 (R = R36, or R06 before it is turned back, :func:`_back3`)."""
    return mv(R, h[5]), mv(R, perpendicular(h[5]))


@kernel
def _back3(h, a1, a2, a3, v):
    """R03ᵀ v = rot(h3, −q3) rot(h2, −q2) rot(h1, −q1) v of the rotations (cos, sin) a1, a2, a3."""
    return rotate_cs(
        h[2], a3[0], -a3[1], rotate_cs(h[1], a2[0], -a2[1], rotate_cs(h[0], a1[0], -a1[1], v))
    )


@kernel
def _wrist_of(h, u, w, B, b, a1, a2, a3, ex):
    """Spherical wrist from u = R36 h6 and w = R36 x (x = :func:`.vec3.perpendicular` of h6; the
    two columns of R36 = R03ᵀ R06 it reads): q5 by SP4 (h4ᵀ R36 h6 = h4ᵀ rot(h5, q5) h6), q4
    and q6 by SP1; branches b (first q5 root) and b + 1.  a1, a2, a3: the rotations (cos, sin)
    of q1, q2, q3."""
    h4, h5, h6 = h[3], h[4], h[5]
    x = perpendicular(h6)
    ca, sa, cb, sb, cnt, ea, eb, _ = sp4_cs(h4, h6, h5, dot(h4, u), TOL)
    for j in range(2):
        if j >= cnt:
            B[b + j, EXISTS] = 0.0
            continue
        c, s = (ca, sa) if j == 0 else (cb, sb)
        # q4 (0 where it is free: h4 ∥ rot(h5, q5) h6, the wrist singularity), then q6 from
        # rot(h6, q6) = rot(h5, −q5) rot(h4, −q4) R36 applied to x ⟂ h6 (never singular)
        c4, s4, e4, _ = sp1_cs(rotate_cs(h5, c, s, h6), u, h4, TOL)
        c6, s6, e6, _ = sp1_cs(x, rotate_cs(h5, c, -s, rotate_cs(h4, c4, -s4, w)), h6, TOL)
        _put(
            B,
            b + j,
            a1,
            a2,
            a3,
            (c4, s4),
            (c, s),
            (c6, s6),
            True,
            ex and (ea if j == 0 else eb) and e4 and e6,
        )


@kernel
def _spherical_two_parallel(h, P, R06, p, B):
    """q1 SP4, q3 SP3, q2 SP1, the wrist (spherical wrist, axes 2 ∥ 3)."""
    wrist = sub(sub(p, mv(R06, P[6])), P[0])  # p_16 (wrist centre − p01)
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(
        h[1], wrist, neg(h[0]), dot(h[1], add(add(P[1], P[2]), P[3])), TOL
    )
    u0, w0 = _wrist_reads(h, R06)
    for i1 in range(2):
        if i1 >= n1:
            _none(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        v = sub(rotate_cs(neg(h[0]), a1[0], a1[1], wrist), P[1])  # R01ᵀ p_16 − p12
        u1, w1 = rotate_cs(h[0], a1[0], -a1[1], u0), rotate_cs(h[0], a1[0], -a1[1], w0)
        c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(neg(P[3]), P[2], h[2], norm(v), TOL)
        for i3 in range(2):
            b = 4 * i1 + 2 * i3
            if i3 >= n3:
                _none(B, b, b + 2)
                continue
            a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
            c2, s2, e2, _ = sp1_cs(add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), v, h[1], TOL)
            ex = (e1a if i1 == 0 else e1b) and (e3a if i3 == 0 else e3b) and e2
            u = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, u1))  # R03ᵀ R06 h6
            w = rotate_cs(h[2], a3[0], -a3[1], rotate_cs(h[1], c2, -s2, w1))
            _wrist_of(h, u, w, B, b, a1, (c2, s2), a3, ex)


@kernel
def _spherical_two_intersecting(h, P, R06, p, B):
    """q3 SP3, (q1, q2) SP2, the wrist (spherical wrist, axes 1 × 2)."""
    p16 = sub(sub(p, mv(R06, P[6])), P[0])  # from the 1–2 intersection
    u0, w0 = _wrist_reads(h, R06)
    c3a, s3a, c3b, s3b, n3, e3a, e3b, _ = sp3_cs(P[3], neg(P[2]), h[2], norm(p16), TOL)
    for i3 in range(2):
        if i3 >= n3:
            _none(B, 4 * i3, 4 * i3 + 4)
            continue
        a3 = (c3a, s3a) if i3 == 0 else (c3b, s3b)
        c1a, s1a, c2a, s2a, c1b, s1b, c2b, s2b, n12, ea, eb, _ = sp2_cs(
            p16, add(P[2], rotate_cs(h[2], a3[0], a3[1], P[3])), neg(h[0]), h[1], TOL
        )
        for j in range(2):
            b = 4 * i3 + 2 * j
            if j >= n12:
                _none(B, b, b + 2)
                continue
            a1, a2 = ((c1a, s1a), (c2a, s2a)) if j == 0 else ((c1b, s1b), (c2b, s2b))
            _wrist_of(
                h,
                _back3(h, a1, a2, a3, u0),
                _back3(h, a1, a2, a3, w0),
                B,
                b,
                a1,
                a2,
                a3,
                (e3a if i3 == 0 else e3b) and (ea if j == 0 else eb),
            )


@kernel
def _three_parallel_tail(h, P, R06, p06, a1, a5, ex, B, b):
    """Axes 2 ∥ 3 ∥ 4 with q1 and q5 known (rotations (cos, sin) a1, a5; branches b, b + 1 by
    the SP3 of q3): θ14 = q2 + q3 + q4 and q6 by SP1, q3 by SP3 (the planar elbow), q2 by SP1,
    q4 by difference.  h3, h4 may be −h2: rot(h3, q3) = rot(h2, ±q3)."""
    s3n = 1.0 if dot(h[1], h[2]) >= 0.0 else -1.0
    s4n = 1.0 if dot(h[1], h[3]) >= 0.0 else -1.0
    R01 = rot_cs(h[0], a1[0], a1[1])
    c5, s5 = a5
    # q6 (0 where it is free: h6 ∥ h2, the wrist aligned with the parallel axes), then θ14 from
    # rot(h2, θ14) = R01ᵀ R06 rot(h6, −q6) rot(h5, −q5) applied to x ⟂ h2 (never singular)
    c6, s6, e6, _ = sp1_cs(
        rotate_cs(neg(h[4]), c5, s5, h[1]), mtv(R06, mv(R01, h[1])), neg(h[5]), TOL
    )
    x = perpendicular(h[1])
    c14, s14, e14, _ = sp1_cs(
        x, mtv(R01, mv(R06, rotate_cs(h[5], c6, -s6, rotate_cs(h[4], c5, -s5, x)))), h[1], TOL
    )
    d_in = sub(
        sub(mtv(R01, p06), P[1]),
        rotate_cs(h[1], c14, s14, add(P[4], rotate_cs(h[4], c5, s5, P[5]))),
    )
    ca, sa, cb, sb, n3, ea, eb, _ = sp3_cs(neg(P[3]), P[2], h[1], norm(d_in), TOL)
    for j in range(2):
        if j >= n3:
            B[b + j, EXISTS] = 0.0
            continue
        c3, s3 = (ca, sa) if j == 0 else (cb, sb)
        c2, s2, e2, _ = sp1_cs(add(P[2], rotate_cs(h[1], c3, s3, P[3])), d_in, h[1], TOL)
        # q4 = θ14 − q2 − q3: its rotation is e^{iθ14} e^{−i(q2 + q3)}
        c23, s23 = c2 * c3 - s2 * s3, s2 * c3 + c2 * s3
        c4, s4 = c14 * c23 + s14 * s23, s14 * c23 - c14 * s23
        _put(
            B,
            b + j,
            a1,
            (c2, s2),
            (c3, s3n * s3),
            (c4, s4n * s4),
            a5,
            (c6, s6),
            True,
            ex and e14 and e6 and (ea if j == 0 else eb) and e2,
        )


@kernel
def _three_parallel_two_intersecting(h, P, R06, p, B):
    """2 ∥ 3 ∥ 4 and 5 × 6 (p56 = 0): q1 by SP4 (h2ᵀ R01ᵀ p16 = h2ᵀ (p12 + … + p45)), q5 by SP4
    (h2ᵀ R01ᵀ R06 h6 = h2ᵀ R45 h6), then :func:`_three_parallel_tail`."""
    p06 = sub(sub(p, mv(R06, P[6])), P[0])
    d1 = dot(h[1], add(add(add(P[1], P[2]), P[3]), P[4]))
    c1a, s1a, c1b, s1b, n1, e1a, e1b, _ = sp4_cs(h[1], p06, neg(h[0]), d1, TOL)
    R06h6 = mv(R06, h[5])
    for i1 in range(2):
        if i1 >= n1:
            _none(B, 4 * i1, 4 * i1 + 4)
            continue
        a1 = (c1a, s1a) if i1 == 0 else (c1b, s1b)
        c5a, s5a, c5b, s5b, n5, e5a, e5b, _ = sp4_cs(
            h[1], h[5], h[4], dot(h[1], rotate_cs(neg(h[0]), a1[0], a1[1], R06h6)), TOL
        )
        for i5 in range(2):
            b = 4 * i1 + 2 * i5
            if i5 >= n5:
                _none(B, b, b + 2)
                continue
            _three_parallel_tail(
                h,
                P,
                R06,
                p06,
                a1,
                (c5a, s5a) if i5 == 0 else (c5b, s5b),
                (e1a if i1 == 0 else e1b) and (e5a if i5 == 0 else e5b),
                B,
                b,
            )


@kernel
def _three_parallel(h, P, R06, p, B):
    """2 ∥ 3 ∥ 4 alone: (q1, q5) by SP6 (the two height equations along h2, of the position
    and of h6; a quartic, up to 4), then :func:`_three_parallel_tail`."""
    p06 = sub(sub(p, mv(R06, P[6])), P[0])
    t = local2(4, 2)
    cnt, _ = sp6_one(
        (h[1], h[1], h[1], h[1]),
        (neg(h[0]), h[4], neg(h[0]), h[4]),
        (p06, neg(P[5]), mv(R06, h[5]), neg(h[5])),
        dot(h[1], add(add(add(P[1], P[2]), P[3]), P[4])),
        0.0,
        TOL_QUARTIC,
        t,
    )
    for j in range(4):
        if j >= cnt:
            _none(B, 2 * j, 2 * j + 2)
            continue
        _three_parallel_tail(h, P, R06, p06, angle_cs(t[j, 0]), angle_cs(t[j, 1]), True, B, 2 * j)


@kernel
def _spherical(h, P, R06, p, B):
    """Spherical wrist only: (q1, q2, q3) by SP5 (−p12 + R01ᵀ p16 = R12 (p23 + R23 p34), a
    quartic, up to 4), then the wrist."""
    p16 = sub(sub(p, mv(R06, P[6])), P[0])
    u0, w0 = _wrist_reads(h, R06)
    t = local2(4, 3)
    cnt, _ = sp5_one(neg(P[1]), p16, P[2], P[3], neg(h[0]), h[1], h[2], TOL_QUARTIC, t)
    for j in range(4):
        if j >= cnt:
            _none(B, 2 * j, 2 * j + 2)
            continue
        a1, a2, a3 = angle_cs(t[j, 0]), angle_cs(t[j, 1]), angle_cs(t[j, 2])
        _wrist_of(
            h, _back3(h, a1, a2, a3, u0), _back3(h, a1, a2, a3, w0), B, 2 * j, a1, a2, a3, True
        )


#: the compiled class solvers, by their index in :data:`CLOSED`
CLOSED = (
    C.SPHERICAL_TWO_PARALLEL,
    C.SPHERICAL_TWO_INTERSECTING,
    C.THREE_PARALLEL_TWO_INTERSECTING,
    C.SPHERICAL,
    C.THREE_PARALLEL,
)


@kernel
def _solve_closed(cls, h, P, R06, p, B):
    """The 8 branches of one pose of class ``cls`` (index in :data:`CLOSED`) into B: the
    class solver writes their rotations and flags, :func:`_angles` reads the angles; a branch
    that does not exist is NaN."""
    for b in range(8):
        B[b, EXISTS], B[b, EXACT] = 0.0, 0.0
    if cls == 0:
        _spherical_two_parallel(h, P, R06, p, B)
    elif cls == 1:
        _spherical_two_intersecting(h, P, R06, p, B)
    elif cls == 2:
        _three_parallel_two_intersecting(h, P, R06, p, B)
    elif cls == 3:
        _spherical(h, P, R06, p, B)
    else:
        _three_parallel(h, P, R06, p, B)
    _angles(B)
    for b in range(8):
        if B[b, EXISTS] == 0.0:
            for j in range(6):
                B[b, j] = math.nan
            B[b, EXACT] = 0.0


@kernel
def _closed_loop(cls, H, P, R06, p, Q, V, E):
    h, PP = rows6(H), rows7(P)
    B = np.empty((8, BRANCH_ROW))
    for i in range(len(p)):
        _solve_closed(cls, h, PP, mat(R06[i]), vec(p[i]), B)
        for b in range(8):
            for j in range(6):
                Q[i, b, j] = B[b, j]
            V[i, b], E[i, b] = B[b, EXISTS] != 0.0, B[b, EXACT] != 0.0


# ----------------------------------------------------------------------------- one call: pose → verified branches
@kernel
def into_limit(x, lo, hi):
    """The angle x (rad) shifted by a multiple of 2π into [lo, hi] (a continuous joint, ±inf:
    into (−π, π]): of the values x + 2πk inside the limits, the one nearest 0 (a UR joint of
    ±2π keeps 0.4, not 0.4 − 2π); a value within 1e-9 rad outside a limit is put onto it.
    Returns (the angle, whether it is inside); an angle that is not keeps the smallest shifted
    value ≥ the lower limit (the caller may move it along a self-motion,
    :func:`anthroarm.ik.closed_form.analytic`)."""
    lo_j, hi_j = lo - 1e-9, hi + 1e-9
    w = wrap(x)
    best = w if lo_j <= w <= hi_j else math.nan
    k = 1
    while best != best and (w + 2.0 * math.pi * k <= hi_j or w - 2.0 * math.pi * k >= lo_j):
        up, down = w + 2.0 * math.pi * k, w - 2.0 * math.pi * k
        if lo_j <= up <= hi_j:
            best = up
        if lo_j <= down <= hi_j and not (abs(best) <= abs(down)):
            best = down
        k += 1
    if best == best:
        return min(max(best, lo), hi), True
    lo_f = lo if math.isfinite(lo) else -math.pi
    return x - 2.0 * math.pi * math.floor((x - lo_f + 1e-9) / (2.0 * math.pi)), False


@kernel
def into_limit_cs(x, c, s, lo, hi, exists):
    """:func:`into_limit` of an angle x carried with its cosine and sine (c, s): (the angle, its
    cosine, its sine, whether it is inside) — (c, s) kept where the angle returned is x moved
    by whole turns (the same rotation), cos and sin of the angle returned where it was put
    onto a limit (it is then the limit) and the branch ``exists``."""
    if -math.pi < x <= math.pi and lo <= x <= hi:  # the usual case: already the angle returned
        return x, c, s, True
    q, ok = into_limit(x, lo, hi)
    if exists and q != x and (q == lo or q == hi):
        c, s = math.cos(q), math.sin(q)
    return q, c, s, ok


@kernel
def into_limit_rows(Q, QC, QS, V, E, n, lo, hi, IN, CHK):
    """:func:`into_limit_cs` of the candidate branches of one pose in place: rows Q (B, n) (rad)
    with their cosines QC and sines QS, flags V (a candidate) and E (exact); writes IN (every
    joint inside) and CHK (its FK residual is wanted: a candidate inside the limits, or a
    least-squares one, :func:`_fk_residuals`)."""
    for b in range(len(V)):
        inside = True
        for j in range(n):
            Q[b, j], QC[b, j], QS[b, j], ok = into_limit_cs(
                Q[b, j], QC[b, j], QS[b, j], lo[j], hi[j], V[b]
            )
            inside = inside and ok
        IN[b] = inside
        CHK[b] = V[b] and (inside or not E[b])


@kernel
def into_limits(q, n, lo, hi):
    """:func:`into_limit` of the angles q[:n] (rad) in place, limits lo, hi (n,); returns
    whether every joint is inside."""
    inside = True
    for j in range(n):
        q[j], ok = into_limit(q[j], lo[j], hi[j])
        inside = inside and ok
    return inside


@kernel
def _into_limits_rows(Q, lo, hi, inside):
    for i in range(Q.shape[0]):
        inside[i] = into_limits(Q[i], Q.shape[1], lo, hi)


def wrap_into_limits(Q, lo, hi):
    """:func:`into_limits` of every row of Q (..., n) rad (a copy; NaN rows stay NaN): (Q
    shifted, inside (...,))."""
    Q = np.array(Q, dtype=float)
    shape = Q.shape
    Q2 = np.ascontiguousarray(Q.reshape(-1, shape[-1]))
    inside = np.empty(len(Q2), dtype=bool)
    _into_limits_rows(
        Q2, np.ascontiguousarray(lo, dtype=float), np.ascontiguousarray(hi, dtype=float), inside
    )
    return Q2.reshape(shape), inside.reshape(shape[:-1])


@kernel
def _pose_status(T, tol_orthonormal):
    """0: a valid pose; 1: not finite; 2: last row not [0, 0, 0, 1]; 3: not a rotation."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return 1
    if (
        abs(T[3, 0]) > 1e-12
        or abs(T[3, 1]) > 1e-12
        or abs(T[3, 2]) > 1e-12
        or abs(T[3, 3] - 1.0) > 1e-12
    ):
        return 2
    R = mat(T)
    RtR = mtm(R, R)
    for i in range(3):
        for j in range(3):
            if abs(RtR[i][j] - (1.0 if i == j else 0.0)) > tol_orthonormal:
                return 3
    if dot(transpose(R)[0], cross(transpose(R)[1], transpose(R)[2])) < 0.0:
        return 3
    return 0


# ----------------------------------------------------------------------------- the chain's FK (local frames)
def local_frames(axes, points, M) -> np.ndarray:
    """The forward kinematics of a chain of revolute joints as constant rigid transforms:
    F(q) = A_0 Rz(q1) A_1 Rz(q2) ⋯ Rz(qn) A_n, returned as A (n + 1, 12) (each row: the
    rotation row by row, then the translation; base frame, m).

    ``axes`` (n, 3) unit joint axes through ``points`` (n, 3) at q = 0, ``M`` (4×4) the tool
    pose at q = 0 (base frame, m).  Joint i gets a frame F_i whose z axis is its axis, at its
    point; then e^{ξi qi} = F_i Rz(qi) F_i⁻¹, and the product of exponentials
    e^{ξ1 q1} ⋯ e^{ξn qn} M (Lynch & Park, *Modern Robotics*, 2017, §4.1.1) becomes the product
    above with A_0 = F_1, A_i = F_i⁻¹ F_{i+1}, A_n = F_n⁻¹ M.  A joint's rotation then turns
    two columns of the partial product (:func:`_joint_step`): about three quarters of the
    arithmetic of a product of exponentials, and the tool pose comes out without a last
    multiplication by M."""
    axes, points, M = (np.asarray(a, dtype=float) for a in (axes, points, M))
    frames = []
    for k, o in zip(axes, points):
        x = np.array(perpendicular(tuple(k)))
        frames.append((np.column_stack([x, np.cross(k, x), k]), o))
    A = np.empty((len(frames) + 1, 12))
    chain = [(np.eye(3), np.zeros(3))] + frames + [(M[:3, :3], M[:3, 3])]
    for i in range(len(frames) + 1):
        (Ra, pa), (Rb, pb) = chain[i], chain[i + 1]
        A[i, :9], A[i, 9:] = (Ra.T @ Rb).ravel(), Ra.T @ (pb - pa)
    return A


@kernel
def _frame(A, i):
    """Row i of A (:func:`local_frames`) as (R, t)."""
    return (
        ((A[i, 0], A[i, 1], A[i, 2]), (A[i, 3], A[i, 4], A[i, 5]), (A[i, 6], A[i, 7], A[i, 8])),
        (A[i, 9], A[i, 10], A[i, 11]),
    )


@kernel
def _joint_step(R, t, A, i, c, s):
    """(R, t) · Rz(q) · A_i, a partial product of :func:`local_frames` taken one joint further,
    from c = cos q and s = sin q: the first two columns of R turned by q, then A_i."""
    Rq = (
        (R[0][0] * c + R[0][1] * s, R[0][1] * c - R[0][0] * s, R[0][2]),
        (R[1][0] * c + R[1][1] * s, R[1][1] * c - R[1][0] * s, R[1][2]),
        (R[2][0] * c + R[2][1] * s, R[2][1] * c - R[2][0] * s, R[2][2]),
    )
    B, a = _frame(A, i)
    return mm(Rq, B), add(mv(Rq, a), t)


@kernel
def _pose_error(R, t, T):
    """max |F − T| over the 3×4 entries of the pose F = (R, t)."""
    err = 0.0
    for i in range(3):
        err = max(err, abs(t[i] - T[i, 3]))
        for j in range(3):
            err = max(err, abs(R[i][j] - T[i, j]))
    return err


@kernel
def _chain_fk(A, q, n):
    """The tool pose (R, t) = F(q) of the chain (:func:`local_frames`; q (n,) rad, path order)."""
    R, t = _frame(A, 0)
    for i in range(n):
        R, t = _joint_step(R, t, A, i + 1, math.cos(q[i]), math.sin(q[i]))
    return R, t


@kernel
def _target_errors(A, q, n, T):
    """(‖p* − p‖ m, ‖log₃(Rᵀ R*)‖ rad) of the tool pose (R, p) = F(q) (:func:`_chain_fk`)
    against T = (R*, p*) — the position and rotation errors :func:`anthroarm.ik.solve` reports
    (the angle of W = Rᵀ R* as atan2(‖vee(W − Wᵀ)‖ / 2, (tr W − 1) / 2), accurate near 0 and π)."""
    R, x = _chain_fk(A, q, n)
    W = mtm(R, mat(T))
    v = (W[2][1] - W[1][2], W[0][2] - W[2][0], W[1][0] - W[0][1])
    return (
        norm((T[0, 3] - x[0], T[1, 3] - x[1], T[2, 3] - x[2])),
        math.atan2(0.5 * norm(v), 0.5 * (W[0][0] + W[1][1] + W[2][2] - 1.0)),
    )


@kernel
def _chain_jacobian(A, q, n, J):
    """The 6×6 Jacobian J of the first six joints at ``q`` (path order, rad; a 7th held), at the
    tool point x, base frame: column i is (w × (x − o); w) with the joint's axis w, the z axis
    of the partial product (R, t) of :func:`local_frames` before the joint's rotation, through
    its point o = t.  Returns the tool pose (R, t) = F(q)."""
    R, t = _frame(A, 0)
    for i in range(n):
        if i < 6:
            J[3, i], J[4, i], J[5, i] = R[0][2], R[1][2], R[2][2]
            J[0, i], J[1, i], J[2, i] = t
        R, t = _joint_step(R, t, A, i + 1, math.cos(q[i]), math.sin(q[i]))
    for i in range(6):
        c = cross((J[3, i], J[4, i], J[5, i]), sub(t, (J[0, i], J[1, i], J[2, i])))
        J[0, i], J[1, i], J[2, i] = c
    return R, t


@kernel
def _polish_chain(A, q, n, T, lo, hi, tol, J, F):
    """Newton steps on the pose equations F(q) = T of the chain's first six joints (a 7th held),
    in place on ``q`` (n,) rad, for a candidate of an arm that is of its class only within the
    classification tolerance (its class solution is off by up to that much, ~1e-7 m).

    The Jacobian :func:`_chain_jacobian`, the error (x* − x;
    ½ vee(R* Rᵀ − R R*ᵀ)) (the same step as :func:`anthroarm.ik.search.polish`).  At most
    :data:`POLISH_STEPS` steps, fewer once the residual is ≤ 1e-3 ``tol``; a step on a singular
    Jacobian (|det| ≤ 1e-12) ends it.  A joint within 1e-9 rad outside a limit is put onto it.
    Returns the FK residual (:func:`_pose_error`) of the angles it leaves in ``q``, inf if a
    joint left its limits by more than 1e-9 rad.  ``J`` (6, 6), ``F`` (6,)
    scratch."""
    res = math.inf
    for it in range(POLISH_STEPS + 1):
        R, x = _chain_jacobian(A, q, n, J)
        res = _pose_error(R, x, T)
        if res <= 1e-3 * tol or it == POLISH_STEPS:
            break
        W = mm(mat(T), transpose(R))
        F[0], F[1], F[2] = T[0, 3] - x[0], T[1, 3] - x[1], T[2, 3] - x[2]
        F[3] = 0.5 * (W[2][1] - W[1][2])
        F[4] = 0.5 * (W[0][2] - W[2][0])
        F[5] = 0.5 * (W[1][0] - W[0][1])
        if abs(solve6(J, F)) <= 1e-12:
            break
        for i in range(6):
            q[i] += F[i]
    moved = False
    for j in range(n):
        if q[j] < lo[j] - 1e-9 or q[j] > hi[j] + 1e-9:
            return math.inf
        x = min(max(q[j], lo[j]), hi[j])
        moved = moved or x != q[j]
        q[j] = x
    if moved:  # put onto a limit: the residual of the angles returned
        R, x = _chain_fk(A, q, n)
        res = _pose_error(R, x, T)
    return res


@kernel
def _fk_residuals(A, Q, QC, QS, V, n, T, RES, S):
    """The FK residual max |F(θ) − T| over the 3×4 pose entries (:func:`_chain_fk`,
    :func:`_pose_error`) of every candidate branch b (``V[b]``) of Q (B, n) into RES (B,)
    (inf where there is none), each joint's rotation from QC, QS (B, n), the cosine and sine
    of its angle (the rotation the class solver found, whose angle Q is, whole turns added
    or not; cos and sin of Q where :func:`into_limit_cs` put it onto a limit or the polish
    moved it), the partial products shared along the branch tree:
    branches come root index innermost, so a branch repeats the leading angles of the one
    before it, and the partial products up to the first joint whose angle differs are kept
    (scratch S (n + 1, 12): rotation rows and translation after each joint) — the same
    arithmetic as one product per branch, about a third fewer joint factors for 8 branches."""
    for k in range(12):
        S[0, k] = A[0, k]
    prev = -1
    for b in range(len(V)):
        if not V[b]:
            RES[b] = math.inf
            continue
        j0 = 0
        if prev >= 0:
            while j0 < n and Q[b, j0] == Q[prev, j0]:
                j0 += 1
        prev = b
        for i in range(j0, n):
            R, t = _frame(S, i)
            R, t = _joint_step(R, t, A, i + 1, QC[b, i], QS[b, i])
            S[i + 1, 0], S[i + 1, 1], S[i + 1, 2] = R[0]
            S[i + 1, 3], S[i + 1, 4], S[i + 1, 5] = R[1]
            S[i + 1, 6], S[i + 1, 7], S[i + 1, 8] = R[2]
            S[i + 1, 9], S[i + 1, 10], S[i + 1, 11] = t
        R, t = _frame(S, n)
        RES[b] = _pose_error(R, t, T)


@kernel(inline=True)
def _unpack(cf, ci):
    """The plan's constants from :attr:`GeoPlan.packed`: (class index, reversed, n, H, P,
    R_tool, the held joint's axis and point, the tool pose at q = 0, the FK frames A (n + 1, 12),
    lo, hi (n,), order (n,): the path position of each independent joint, index (n, 2): its
    first entry in q and whether it is continuous) — views of ``cf``, ``ci``, compiled into each
    caller (:func:`anthroarm.jit.kernel`)."""
    n = ci[2]
    o = 70 + 12 * (n + 1)
    return (
        ci[0],
        ci[1] == 1,
        n,
        view2(cf, 6, 3),
        view2(cf[18:], 7, 3),
        view2(cf[39:], 3, 3),
        (cf[48], cf[49], cf[50]),
        (cf[51], cf[52], cf[53]),
        view2(cf[54:], 4, 4),
        view2(cf[70:], n + 1, 12),
        cf[o : o + n],
        cf[o + n : o + 2 * n],
        ci[3 : 3 + n],
        view2(ci[4 + n :], n, 2),
    )


@kernel(counted=False)
def _verified(cf, ci, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF):
    """Every branch of poses T (N, 4, 4) (:func:`_verify_pose` of each, ``param`` (N,) the held
    7th joint): writes Q (N, 8, n), V, E, IN, RES, OK (N, 8) and, unless its last axis is
    empty, CONF (N, 8, nq).  Returns the index of the first malformed pose (−1 if none).
    ``cf``, ``ci``: :attr:`GeoPlan.packed`.  Compiled without reference counts
    (:func:`anthroarm.jit.kernel`): its scratch is local (n ≤ 7 joints)."""
    plan = _pose_plan(cf, ci)
    n = plan[2]
    B6 = local2(8, BRANCH_ROW)
    q = local(7)
    QC, QS = view2(local(56), 8, n), view2(local(56), 8, n)
    S = view2(local(96), n + 1, 12)
    J, F = local2(6, 6), local(6)
    CHK = local_flags(8)
    for i in range(len(T)):
        if not _verify_pose(
            plan,
            T[i],
            param[i],
            tol,
            tol_orthonormal,
            Q[i],
            V[i],
            E[i],
            IN[i],
            RES[i],
            OK[i],
            CONF[i],
            (B6, q, QC, QS, S, J, F, CHK),
        ):
            return i
    return -1


@kernel(inline=True)
def _pose_plan(cf, ci):
    """The constants :func:`_verify_pose` takes, from :attr:`GeoPlan.packed` (:func:`_unpack`,
    its vectors and matrices as tuples, :mod:`.vec3`; the tool pose at q = 0 as (MR, Mp)):
    (class index, reversed, n, h, P, R_tool, MR, Mp, the held joint's axis and point, A, lo,
    hi, order, index).  Compiled into each caller."""
    cls, rev, n, H, P, R_tool, p_axis, p_point, M, A, lo, hi, order, index = _unpack(cf, ci)
    return (
        cls,
        rev,
        n,
        rows6(H),
        rows7(P),
        mat(R_tool),
        mat(M[:3, :3]),
        vec(M[:3, 3]),
        p_axis,
        p_point,
        A,
        lo,
        hi,
        order,
        index,
    )


@kernel(inline=True)
def _verify_pose(plan, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF, scratch):
    """Every branch of one pose T (4, 4) in path order, wrapped into the limits and FK-checked:
    writes Q (8, n) rad, V (candidate exists), E (exact), IN (inside the limits), RES (FK
    residual; inf where there is no candidate, and for an exact candidate outside the limits,
    which is never returned and so not checked), OK (a solution: candidate, inside, residual
    ≤ tol, and not within 1e-9 rad of an earlier solution of its pose); a candidate inside the
    limits with tol < residual ≤ :data:`POLISH_MAX` is polished (:func:`_polish_chain`) and
    kept polished where that brings it within tol.  ``CONF`` (8, nq), unless its last axis is
    empty: the chain's configuration q of each solution (:func:`_configurations`).  ``param``
    the held 7th joint (rad).  Returns False for a malformed pose (:func:`_pose_status`).
    ``plan``: :func:`_pose_plan`; ``scratch``: B6 (8, :data:`BRANCH_ROW`), q (7,), QC, QS
    (8, n), S (n + 1, 12), J (6, 6), F (6,), CHK (8,).  Compiled into each caller
    (:func:`_verified`, :func:`_verified_one`)."""
    cls, rev, n, h, PP, Rt, MR, Mp, p_axis, p_point, A, lo, hi, order, index = plan
    B6, q, QC, QS, S, J, F, CHK = scratch
    if _pose_status(T, tol_orthonormal) != 0:
        return False
    R, p = mat(T), (T[0, 3], T[1, 3], T[2, 3])
    t7, a7 = 0.0, (1.0, 0.0)
    if n == 7:
        t7 = wrap(param)
        a7 = angle_cs(t7)
        # T · M⁻¹ e^{−ξ7 v} M: the pose the first six joints reach (docstring of :func:`solve`)
        Rv = rot_cs(p_axis, a7[0], -a7[1])
        X = mtm(MR, mm(Rv, MR))
        x = mtv(MR, sub(add(mv(Rv, Mp), sub(p_point, mv(Rv, p_point))), Mp))
        p = add(mv(R, x), p)
        R = mm(R, X)
    if rev:
        p = neg(mtv(R, p))
        R = transpose(R)
    _solve_closed(cls, h, PP, mm(R, transpose(Rt)), p, B6)
    for b in range(8):
        V[b], E[b] = B6[b, EXISTS] != 0.0, B6[b, EXACT] != 0.0
        for j in range(n):
            jj = 5 - j if rev else j  # a reversed chain's joints come last first
            x = (B6[b, jj], B6[b, COS + jj], B6[b, SIN + jj]) if j < 6 else (t7, a7[0], a7[1])
            Q[b, j], QC[b, j], QS[b, j] = x
    into_limit_rows(Q, QC, QS, V, E, n, lo, hi, IN, CHK)
    _fk_residuals(A, Q, QC, QS, CHK, n, T, RES, S)
    for b in range(8):
        if V[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
            for j in range(n):
                q[j] = Q[b, j]
            r = _polish_chain(A, q, n, T, lo, hi, tol, J, F)
            if r <= tol:
                for j in range(n):
                    Q[b, j], QC[b, j], QS[b, j] = q[j], math.cos(q[j]), math.sin(q[j])
                RES[b] = r
    _mark_solutions(Q, V, IN, RES, tol, 8, OK)
    if CONF.shape[1] > 0:
        _configurations(order, index, n, Q, QC, QS, OK, CONF)
    return True


@kernel
def _configurations(order, index, n, Q, QC, QS, OK, CONF):
    """The chain's configuration q (:func:`anthroarm.chain_kernels.put_joint`) of each solution
    b (``OK[b]``) of θ Q (8, n) (path order) with its cosines QC and sines QS into CONF (8, nq)
    (NaN rows elsewhere); ``order``, ``index``: :func:`_unpack`'s."""
    for b in range(8):
        if not OK[b]:
            for j in range(CONF.shape[1]):
                CONF[b, j] = math.nan
            continue
        for k in range(n):
            j = order[k]
            put_joint(CONF[b], index[k, 0], index[k, 1] != 0, Q[b, j], QC[b, j], QS[b, j])


#: a solution whose normalised Jacobian volume (:func:`_volume`) is at most this is at a
#: singular configuration of the arm
SINGULAR_TOL = 1e-6


@kernel
def _volume(A, q, n, J, F):
    """The normalised volume |det J| / Π‖J_k‖ ∈ [0, 1] (Hadamard's inequality) of the 6×6
    Jacobian of the first six joints at ``q`` (path order, rad), at the tool point, in the base
    frame (:func:`_chain_jacobian`): 0 at a singular configuration
    — a wrist with aligned axes, a stretched elbow, the wrist centre on the first axis — where
    solutions coincide in pairs or form a one-parameter family.  ``J`` (6, 6), ``F`` (6,)
    scratch."""
    _chain_jacobian(A, q, n, J)
    scale = 1.0
    for i in range(6):
        c, w = (J[0, i], J[1, i], J[2, i]), (J[3, i], J[4, i], J[5, i])
        scale *= math.sqrt(dot(c, c) + dot(w, w))
        F[i] = 0.0
    return abs(solve6(J, F)) / scale


@kernel
def _volume_loop(cf, ci, TH, OK, VOL):
    """:func:`_volume` of every solution (``OK``) of θ (N, B, n) in independent-joint order
    into VOL (N, B) (1 elsewhere)."""
    _, _, n, _, _, _, _, _, _, A, _, _, order, _ = _unpack(cf, ci)
    q, J, F = np.empty(n), np.empty((6, 6)), np.empty(6)
    for i in range(TH.shape[0]):
        for b in range(TH.shape[1]):
            VOL[i, b] = 1.0
            if OK[i, b]:
                for k in range(n):
                    q[order[k]] = TH[i, b, k]
                VOL[i, b] = _volume(A, q, n, J, F)


def jacobian_volumes(plan: GeoPlan, TH, OK) -> np.ndarray:
    """The normalised Jacobian volume (:func:`_volume`) of each solution θ (N, B, n)
    (independent-joint order, rad) where ``OK`` (N, B); 1 elsewhere."""
    cf, ci = plan.packed
    VOL = np.empty(OK.shape)
    _volume_loop(cf, ci, np.ascontiguousarray(TH, dtype=float), np.ascontiguousarray(OK), VOL)
    return VOL


@kernel
def _mark_solutions(Q, V, IN, RES, tol, group, OK):
    """The solutions among the branches of one pose (Q (B, n), flags (B,)): a candidate inside
    the limits with FK residual ≤ ``tol``, not within 1e-9 rad of an earlier solution of its
    group (``group`` consecutive branches: one swivel angle or held-joint value) — coincident
    branches at singular poses.  Writes OK (B,)."""
    for b in range(len(V)):
        ok = V[b] and IN[b] and RES[b] <= tol
        a = b - b % group
        while ok and a < b:
            if OK[a]:
                ok = False  # a duplicate of a unless some joint differs
                for j in range(Q.shape[1]):
                    d = abs(
                        Q[b, j] - Q[a, j]
                    )  # differs by 1e-9 rad, and (below a turn: no wrap) as a rotation
                    if d >= 1e-9 and (d <= 2.0 * math.pi - 1e-9 or abs(wrap(d)) >= 1e-9):
                        ok = True
                        break
            a += 1
        OK[b] = ok


@kernel
def _mark_loop(Q, V, IN, RES, tol, group, OK):
    for i in range(len(V)):
        _mark_solutions(Q[i], V[i], IN[i], RES[i], tol, group, OK[i])


@kernel
def blank_unsolved(Q, RES, valid):
    """NaN in place in the rows of Q (N, B, n) and entries of RES (N, B) where not ``valid``
    (N, B): the batch result's "no solution on this branch" (a boolean-mask assignment costs
    several times this loop)."""
    for i in range(Q.shape[0]):
        for b in range(Q.shape[1]):
            if not valid[i, b]:
                RES[i, b] = math.nan
                for j in range(Q.shape[2]):
                    Q[i, b, j] = math.nan


def mark_solutions(Q, V, IN, RES, tol: float, group: int) -> np.ndarray:
    """The solutions (N, B) among candidate branches Q (N, B, n) rad with flags V (candidate),
    IN (inside the limits) and FK residuals RES (N, B): residual ≤ ``tol``, duplicates within
    1e-9 rad inside each ``group`` of consecutive branches dropped (compiled)."""
    OK = np.empty(V.shape, bool)
    _mark_loop(
        np.ascontiguousarray(Q, dtype=float),
        np.ascontiguousarray(V),
        np.ascontiguousarray(IN),
        np.ascontiguousarray(RES, dtype=float),
        float(tol),
        int(group),
        OK,
    )
    return OK


def solve_class(cls: str, H, P, R06, p):
    """Every branch of the class solver ``cls`` in IK-Geo's form (``H`` (6, 3), ``P`` (7, 3),
    ``R06`` (N, 3, 3) = R · R_tool(0)ᵀ, ``p`` (N, 3) the tool positions, base frame, m).
    Returns q (N, B, 6) rad in (−π, π] (NaN on a branch that does not exist), valid (N, B),
    exact (N, B) (False: least squares, out of reach; for a search class also a root whose
    error is above :data:`SEARCH_TOL`), B = :func:`n_branches` (8; 16 for a search class)."""
    n = len(p)
    H, P = np.ascontiguousarray(H, dtype=float), np.ascontiguousarray(P, dtype=float)
    R06, p = np.ascontiguousarray(R06, dtype=float), np.ascontiguousarray(p, dtype=float)
    if cls in CLOSED:
        q, valid, exact = np.empty((n, 8, 6)), np.empty((n, 8), bool), np.empty((n, 8), bool)
        _closed_loop(CLOSED.index(cls), H, P, R06, p, q, valid, exact)
        return q, valid, exact & valid
    return solve_search(cls, H, P, R06, p)


def class_pose(plan: GeoPlan, T, param=None):
    """The pose the class solver of ``plan`` solves for tool poses ``T`` (N, 4, 4): (R06
    (N, 3, 3), p (N, 3)) in IK-Geo's form — of the reversed chain (T⁻¹) for a reversed class,
    of the first six joints (T · M⁻¹ e^{−ξ7 v} M, ``param`` = v (N,)) for a 7-joint arm."""
    if plan.param_joint is not None:
        v = np.broadcast_to(np.asarray(param, dtype=float), (len(T),))
        Rv = sp.rot(np.broadcast_to(plan.param_axis, (len(T), 3)), -v)  # e^{−ξ7 v}
        E = np.broadcast_to(np.eye(4), (len(T), 4, 4)).copy()
        E[:, :3, :3] = Rv
        E[:, :3, 3] = plan.param_point - np.einsum("nij,j->ni", Rv, plan.param_point)
        T = T @ np.linalg.inv(plan.M) @ E @ plan.M
    R, p = T[:, :3, :3], T[:, :3, 3]
    if plan.reversed:
        R, p = np.swapaxes(R, 1, 2), -np.einsum("nji,nj->ni", R, p)
    return R @ plan.R_tool.T, p


def solve(plan: GeoPlan, T, param=None):
    """Every branch for poses ``T`` (N, 4, 4) of the tool (base frame, m; valid rotations):
    θ (N, B, n) in the order of ``robot.chain.independent`` (rad, (−π, π]), valid, exact
    (B = :func:`n_branches` of the class).

    A 7-joint arm (``plan.param_joint``): ``param`` (N,) the value of its last joint (rad) for
    each pose.  With the last joint's twist ξ7 and M the tool pose at q = 0,
    T = F6(q1…q6) e^{ξ7 v} M, so the first six joints solve the 6R arm (tool M) for the pose
    T · M⁻¹ e^{−ξ7 v} M."""
    T = np.asarray(T, dtype=float)
    R06, p = class_pose(plan, T, param)
    q, valid, exact = solve_class(plan.cls, plan.H, plan.P, R06, p)
    if plan.param_joint is not None:
        v = np.broadcast_to(np.asarray(param, dtype=float), (len(T),))
    if plan.reversed:
        q = q[..., ::-1]
    if plan.param_joint is not None:
        q = np.concatenate(
            [q, np.broadcast_to(np.angle(np.exp(1j * v))[:, None, None], q.shape[:2] + (1,))], -1
        )
    return q[..., plan.order], valid, exact


@kernel
def nearest_first(out, K, n, ref, width):
    """Swap the row of ``out[:K]`` whose first ``n`` entries (θ, rad) are nearest ``ref`` (n,)
    (Euclidean) into row 0, columns ``:width`` (the one-pose kernels' solutions first)."""
    best, kb = math.inf, 0
    for k in range(K):
        d = 0.0
        for j in range(n):
            d += (out[k, j] - ref[j]) ** 2
        if d < best:
            best, kb = d, k
    for j in range(width):
        out[0, j], out[kb, j] = out[kb, j], out[0, j]


@kernel(counted=False)
def _verified_one(cf, ci, T, param, tol, tol_orthonormal, ref, out):
    """One pose: the solutions (in the order of the branches) into the rows of ``out`` (8, w + 4):
    θ in independent-joint order (w = n joints) or the chain's configuration q (w = nq ≠ n: a
    continuous joint as (cos, sin), :func:`_configurations`), then the FK residual, the branch
    index; with a reference ``ref`` (n,) (θ, rad; an empty array: none; θ output only) the
    solution nearest it (Euclidean in θ) is swapped into the first row, and that row's last two
    columns hold its position and rotation errors (:func:`_target_errors`, m and rad).  Returns
    the set of branches that are solutions as a bit mask (bit b: branch b; their number K is
    its count of ones, > 0); −1: a malformed pose; −2: no solution, or a candidate to polish
    (the caller's general path answers: reasons, polishing).  One :func:`_verify_pose`, its
    scratch local."""
    plan = _pose_plan(cf, ci)
    n, w, A, order = plan[2], out.shape[1] - 4, plan[10], plan[13]
    Q, RES = view2(local(56), 8, n), local(8)
    V, E, IN, OK = local_flags(8), local_flags(8), local_flags(8), local_flags(8)
    CONF = view2(local(112), 8, w if w != n else 0)
    QC, QS = view2(local(56), 8, n), view2(local(56), 8, n)
    scratch = (
        local2(8, BRANCH_ROW),
        local(7),
        QC,
        QS,
        view2(local(96), n + 1, 12),
        local2(6, 6),
        local(6),
        local_flags(8),
    )
    if not _verify_pose(plan, T, param, tol, tol_orthonormal, Q, V, E, IN, RES, OK, CONF, scratch):
        return -1
    K, mask = 0, 0
    for b in range(8):
        if V[b] and E[b] and IN[b] and tol < RES[b] <= POLISH_MAX:
            return -2
        if OK[b]:
            if w != n:
                for k in range(w):
                    out[K, k] = CONF[b, k]
            else:
                for k in range(n):
                    out[K, k] = Q[b, order[k]]
            out[K, w], out[K, w + 1] = RES[b], b
            K += 1
            mask |= 1 << b
    if K == 0:
        return -2
    if len(ref) == n and w == n:
        nearest_first(out, K, n, ref, n + 2)
        out[0, n + 2], out[0, n + 3] = _target_errors(A, Q[int(out[0, n + 1])], n, T)
    return mask


@kernel(counted=False)
def pose_solutions(cf, ci, T, param, tol, tol_orthonormal, out):
    """:func:`_verified_one` of one pose without a reference: the solutions into the rows of
    ``out`` (8, w + 4), the bit mask of their branches returned (≤ 0: the general path
    answers).  What :func:`anthroarm.ik.closed_form.analytic` calls for one pose of a closed
    class (:func:`anthroarm.jit.entry_point`)."""
    return _verified_one(cf, ci, T, param, tol, tol_orthonormal, local(1)[:0], out)


NO_REF = np.zeros(0)  # "no reference" of the one-pose kernels (an empty array)


class BadPoseError(ValueError):
    """A pose of a batch is not a rigid transform (not finite, last row, rotation part);
    ``index`` is the first such pose."""

    def __init__(self, index: int, message: str):
        super().__init__(message)
        self.index = index


#: FK residual up to which a candidate inside the limits is polished (:func:`_polish_chain` in
#: the compiled call): an arm that is of its class only within the classification tolerance, a
#: least-squares root where a subproblem's two roots meet (a singular pose); what that leaves,
#: :func:`anthroarm.ik.closed_form.analytic`
POLISH_MAX = 1e-4
#: Newton steps of :func:`_polish_chain` at most (quadratic convergence from ~1e-7: two suffice)
POLISH_STEPS = 4
_ZERO1 = np.zeros(1)


def solve_verified(plan: GeoPlan, T, param=None, tol: float = 1e-9, tol_orthonormal: float = 1e-6):
    """Every branch of a closed class (:data:`CLOSED`) for poses ``T`` (N, 4, 4), in one
    compiled call per batch: the class solver (:func:`solve`), each branch wrapped by 2π into
    the joint limits and checked by the chain's FK (product of exponentials of the joints as
    read from ``robot.chain``, the model Pinocchio holds; :func:`local_frames`).  ``param``
    (N,) the held joint of a 7-joint arm.  Returns θ (N, 8, n) (independent-joint order, rad),
    solution (N, 8), candidate (N, 8), exact (N, 8), inside (N, 8), FK residual (N, 8) (max
    entry of the 3×4 pose; inf where there is no candidate or an exact one outside the limits,
    :func:`_verified`) and the chain's configuration q (N, 8, nq) of each solution (θ itself
    where there is no continuous joint; NaN rows where there is no solution).  Raises
    ``ValueError`` naming the first malformed pose (not finite, last row, not a rotation) —
    ``anthroarm.ik.closed_form`` checks before it calls."""
    T = np.ascontiguousarray(T, dtype=float)
    N, n = len(T), len(plan.fk_axes)
    pv = (
        _ZERO1
        if param is None
        else np.ascontiguousarray(np.broadcast_to(np.asarray(param, float), (N,)))
    )
    if param is None and N > 1:
        pv = np.zeros(N)
    Q, V, E = np.empty((N, 8, n)), np.empty((N, 8), bool), np.empty((N, 8), bool)
    IN, RES, OK = np.empty((N, 8), bool), np.empty((N, 8)), np.empty((N, 8), bool)
    CONF = np.empty((N, 8, 0 if plan.plain else plan.chain.nq))
    cf, ci = plan.packed
    first_bad = []

    def rows(a, b):
        k = _verified(
            cf,
            ci,
            T[a:b],
            pv[a:b],
            tol,
            tol_orthonormal,
            Q[a:b],
            V[a:b],
            E[a:b],
            IN[a:b],
            RES[a:b],
            OK[a:b],
            CONF[a:b],
        )
        if k >= 0:
            first_bad.append(a + k)

    run_rows(rows, N)
    bad = min(first_bad) if first_bad else -1
    if bad >= 0:
        raise BadPoseError(
            bad,
            f"T[{bad}] is not a valid pose (finite, last row [0, 0, 0, 1], rotation part a "
            f"rotation to {tol_orthonormal:g})",
        )
    if not plan.order_is_path:
        Q = Q[..., plan.order]
    return Q, OK, V, E & V, IN, RES, (Q if plan.plain else CONF)


def solve_nearest(cf, ci, T, ref, param: float):
    """The solutions θ (K, n) (independent-joint order, rad) of one pose ``T`` (4, 4) of a
    closed class (``cf``, ``ci``: :attr:`GeoPlan.packed`; default tolerances; ``param`` the held
    7th joint) with the one nearest ``ref`` (n,) first, and that one's position and rotation
    errors (m, rad; :func:`_target_errors`; None, None without a reference: an empty ``ref``)
    — or None where the pose has no solution, is malformed or has a candidate to polish.  The
    seeds of :func:`anthroarm.ik.solve`, one compiled call."""
    n = ci[2]
    out = np.empty((8, n + 4))
    mask = _verified_one(cf, ci, T, param, 1e-9, 1e-6, ref, out)
    if mask <= 0:
        return None
    K = mask.bit_count()
    if len(ref) != n:
        return out[:K, :n], None, None
    return out[:K, :n], float(out[0, n + 2]), float(out[0, n + 3])


# ----------------------------------------------------------------------------- anthroarm check
def check_rows(robot, samples: int, rng) -> list:
    """``anthroarm check`` rows of an arm whose geometry has a class solver here (none for the
    others): every exact branch of random reachable poses FK-checked by Pinocchio (max entry
    of the 3×4 pose), and the number of exact branches per pose against IK-Geo's (PyPI
    ``ik-geo``, same H and P; the row is left out when it is not installed)."""
    import pinocchio as pin

    plan = plan_for(robot)
    if plan is None:
        return []
    n = max(3, min(int(samples), 30))
    model, data, fid = robot.model, robot.model.createData(), robot.tool_id
    Q = robot.random_q(n, rng)
    T = np.empty((n, 4, 4))
    for i, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        T[i] = data.oMf[fid].homogeneous
    k7 = None if plan.param_joint is None else plan.order.tolist().index(plan.param_joint)
    param = None if k7 is None else plan.chain.angles(Q)[:, k7]  # the sampled last joint
    th, valid, exact = solve(plan, T, param)
    worst, nb = 0.0, int(exact.sum())
    for i, k in zip(*np.nonzero(exact)):
        pin.framesForwardKinematics(model, data, plan.chain.configuration(th[i, k]))
        worst = max(worst, float(np.abs(data.oMf[fid].homogeneous[:3] - T[i, :3]).max()))
    if not exact.any(1).all():
        worst = float("inf")  # a pose made by FK must have a branch
    tag = f"{plan.cls}{' (reversed chain)' if plan.reversed else ''}"
    # an arm of its class only within the classification tolerance (rounded URDF angles): the raw
    # class solution is off by about that much (aa.ik.analytic polishes it before its FK check)
    off = max(plan.classification.worst_accepted)
    tol = max(1e-9, 10.0 * off)
    note = f"{tag}; {nb} branches" + (
        f"; axes {off:.2g} off the class: raw class solutions" if off else ""
    )
    rows = [
        CheckRow(
            robot.name,
            "closed form by geometry: FK(IK(T)) = T, all branches",
            worst,
            tol,
            n,
            "pinocchio FK",
            note,
        )
    ]
    try:
        import ik_geo
    except ImportError:
        return rows
    if not hasattr(ik_geo, "Robot"):  # a folder named ik_geo on sys.path, not IK-Geo
        return rows
    geo = getattr(ik_geo.Robot, plan.cls)(plan.H.tolist(), plan.P.tolist())
    diff = 0
    R06, p06 = class_pose(plan, T, param)
    for i in range(n):
        theirs = sum(1 for _, ls in geo.get_ik(R06[i].T.tolist(), p06[i].tolist()) if not ls)
        diff = max(diff, abs(theirs - int(exact[i].sum())))
    rows.append(
        CheckRow(
            robot.name,
            "closed form by geometry: branches = IK-Geo's",
            float(diff),
            0.0,
            n,
            "ik-geo (Rust)",
            f"{tag}; max |ours - ik-geo| exact solutions per pose",
        )
    )
    return rows


__all__ = [
    "CLOSED",
    "GeoPlan",
    "solve_nearest",
    "solve_verified",
    "SEARCHED",
    "SOLVED",
    "branch_labels",
    "n_branches",
    "check_rows",
    "class_pose",
    "ik_geo_P",
    "plan_for",
    "solve",
    "solve_class",
]
