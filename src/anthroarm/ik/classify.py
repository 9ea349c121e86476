"""Kinematic classification of an arm from ``robot.chain``: which axes intersect, which are
parallel, and which IK-Geo solver class its inverse kinematics belongs to.

Source: A. J. Elias and J. T. Wen, "IK-Geo: Unified robot inverse kinematics using subproblem
decomposition", arXiv 2211.05737, Table I (the 6-DOF solver classes) and the reference
implementation's ``detect_intersecting_parallel_axes`` / ``rec_solver_6_DOF``
(github.com/rpiRobotics/ik-geo, ``matlab/automatic_IK``).

Everything is read at q = 0 in the **base frame**, in the product-of-exponentials form IK-Geo
uses: joint i turns about the unit axis ``h_i`` through the point ``points[i]`` (the joint's
origin; any point of the axis would do, joint origins may slide along their own axes), the
offsets are ``P[0]`` = base → joint 1, ``P[i]`` = joint i → joint i+1, ``P[n]`` = joint n →
tool (metres), and ``R_tool`` is the tool frame's orientation at q = 0.

Tests on pairs and triples of consecutive axes (IK-Geo's classes only use consecutive ones),
with the measured quantity kept so the user sees how close a call was:

* parallel (i, j): sin of the angle between the axes ``‖h_i × h_j‖ ≤ angle_tol`` (rad);
* intersecting (i, j): not parallel, and the distance between the two lines
  ``|(p_j − p_i) · (h_i × h_j)| / ‖h_i × h_j‖ ≤ tol`` (m);
* spherical (i, i+1, i+2): no two parallel, and the three lines pass through one point
  (the largest distance of a line from the least-squares common point ``≤ tol``);
* three parallel (i, i+1, i+2): both consecutive pairs parallel.

6R classes: IK-Geo's Table I, one module a class in :mod:`anthroarm.ik.classes` with its
condition on the axes (1-based joint numbers as in the paper; ``GeoClass.condition``, the rule
``GeoClass.holds``), tried in the order of :data:`anthroarm.ik.classes.ORDER` (the simplest
solution first: closed forms, quartics, 1-D searches, the 2-D search); the first match wins,
all matches are listed in ``compatible``.

The same tests on the reversed chain (tool to base: a spherical *shoulder* is a spherical wrist
of the reversed arm) are made too; the class of the reversed chain is used when it ranks
higher (``reversed = True``).  A chain that is not six revolute joints (a continuous joint is
revolute here) is :data:`NOT_6R`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..chain import CONTINUOUS, REVOLUTE
from ..errors import ParameterError, UnsupportedModelError
from .classes import CLOSED, ORDER, Relations, holding

#: the names of IK-Geo's classes (:mod:`anthroarm.ik.classes`, one module a class)
SPHERICAL_TWO_PARALLEL = "spherical_two_parallel"
SPHERICAL_TWO_INTERSECTING = "spherical_two_intersecting"
THREE_PARALLEL_TWO_INTERSECTING = "three_parallel_two_intersecting"
SPHERICAL = "spherical"
THREE_PARALLEL = "three_parallel"
TWO_PARALLEL = "two_parallel"
TWO_INTERSECTING = "two_intersecting"
GEN_SIX_DOF = "gen_six_dof"
NOT_6R = "not_6r"
#: the 6R classes, in the order they are tried (simplest solution first): the registry's
#: :data:`anthroarm.ik.classes.ORDER`
CLASSES = ORDER
#: classes with a closed form (no search)
CLOSED_FORM_CLASSES = CLOSED


@dataclass(frozen=True)
class Kinematics:
    """An arm's path from the base to a frame at q = 0, in the base frame (SI units).

    ``H`` (n, 3) unit joint axes; ``points`` (n, 3) the joint origins (a point on each axis);
    ``P`` (n + 1, 3) offsets base → joint 1, joint i → joint i+1, joint n → frame;
    ``R_tool`` (3, 3) and ``p_tool`` (3,) the frame's pose at q = 0; ``joints`` indices into
    ``robot.chain.joints``; ``kinds`` their kinds; ``names`` their names."""

    H: np.ndarray
    points: np.ndarray
    P: np.ndarray
    R_tool: np.ndarray
    p_tool: np.ndarray
    joints: tuple
    kinds: tuple
    names: tuple

    @property
    def n(self) -> int:
        return len(self.joints)


@dataclass(frozen=True)
class Classification:
    """The axis relations of an arm and its IK-Geo class.

    ``name``: the class (one of :data:`CLASSES`, or :data:`NOT_6R`); ``reversed``: the class
    holds for the reversed chain (tool → base); ``compatible``: every class whose condition
    holds, ``(name, reversed)`` pairs, best first; ``parallel`` / ``intersecting``: the
    consecutive pairs (0-based joint positions along the path) that are; ``spherical`` /
    ``three_parallel``: the first joint of each consecutive triple that is; ``sin_angle`` (n−1,)
    and ``distance`` (n−1,) the measured quantities of consecutive pairs (sin of the angle
    between axes; distance between the lines in m, NaN for parallel pairs); ``triple_distance``
    (n−2,) how far the three lines of a triple are from one common point (m, NaN when two are
    parallel); ``tol`` (m) and ``angle_tol`` (rad) the tolerances used; how close the calls
    were: ``worst_accepted`` = (largest distance in m, largest sine) of the relations that
    hold and ``nearest_rejected`` = (smallest distance, smallest sine) of those that do not
    (inf: none); ``reason``: why the arm is not 6R, else None."""

    name: str
    reversed: bool
    compatible: tuple
    parallel: tuple
    intersecting: tuple
    spherical: tuple
    three_parallel: tuple
    sin_angle: np.ndarray
    distance: np.ndarray
    triple_distance: np.ndarray
    tol: float
    angle_tol: float
    worst_accepted: tuple
    nearest_rejected: tuple
    kinematics: Kinematics = field(repr=False)
    reason: str | None = None

    @property
    def has_closed_form(self) -> bool:
        return self.name in CLOSED_FORM_CLASSES


def kinematics(robot, frame=None) -> Kinematics:
    """The axes and points of the joints from the base to ``frame`` (default: the tool) at
    q = 0 in the base frame (see the module docstring).  Raises
    :class:`~anthroarm.errors.UnsupportedModelError` for a path with a mimic joint."""
    chain = robot.chain
    fr = chain.frame(frame if frame is not None else chain.tool)
    path = chain.path(fr.name)
    world = {-1: (np.eye(3), np.zeros(3))}
    H, pts, kinds, names = [], [], [], []
    for j in path:
        jt = chain.joints[j]
        if jt.is_mimic:
            raise UnsupportedModelError(
                f"{chain.name}: joint {jt.name!r} mimics another joint; the subproblem "
                "decomposition needs independent joints: use aa.ik.solve"
            )
        Rp, pp = world[jt.parent]
        R = Rp @ jt.rotation
        p = Rp @ jt.translation + pp
        world[j] = (R, p)
        h = R @ jt.axis
        H.append(h / np.linalg.norm(h))
        pts.append(p)
        kinds.append(jt.kind)
        names.append(jt.name)
    Rj, pj = world[fr.joint]
    R_tool, p_tool = Rj @ fr.rotation, Rj @ fr.translation + pj
    pts = np.array(pts).reshape(-1, 3)
    P = np.diff(np.vstack([np.zeros(3), pts, p_tool]), axis=0)
    return Kinematics(
        np.array(H).reshape(-1, 3), pts, P, R_tool, p_tool, tuple(path), tuple(kinds), tuple(names)
    )


def _relations(H, pts, tol, angle_tol):
    n = len(H)
    sin = np.array([np.linalg.norm(np.cross(H[i], H[i + 1])) for i in range(n - 1)])
    par = sin <= angle_tol
    dist = np.full(n - 1, np.nan)
    for i in range(n - 1):
        if not par[i]:
            c = np.cross(H[i], H[i + 1])
            dist[i] = abs(np.dot(pts[i + 1] - pts[i], c)) / np.linalg.norm(c)
    inter = ~par & (np.nan_to_num(dist, nan=np.inf) <= tol)
    tri = np.full(max(n - 2, 0), np.nan)
    for i in range(n - 2):
        hs, ps = H[i : i + 3], pts[i : i + 3]
        if par[i] or par[i + 1]:  # (i, i+2 may be parallel: both lines through the centre)
            continue
        # least-squares common point x of the three lines: Σ (I − h hᵀ)(x − p) = 0
        M = sum(np.eye(3) - np.outer(h, h) for h in hs)
        b = sum((np.eye(3) - np.outer(h, h)) @ p for h, p in zip(hs, ps))
        x = np.linalg.lstsq(M, b, rcond=None)[0]
        tri[i] = max(np.linalg.norm(np.cross(h, x - p)) for h, p in zip(hs, ps))
    sph = np.nan_to_num(tri, nan=np.inf) <= tol
    three = par[:-1] & par[1:] if n >= 3 else np.zeros(0, bool)
    return sin, par, dist, inter, tri, sph, three


def _classes_6r(par, inter, sph, three):
    """IK-Geo's 6R classes whose condition holds (0-based indices), in :data:`CLASSES`
    order (each class's rule: ``GeoClass.holds``)."""
    return holding(Relations(par, inter, sph, three))


def classify(robot, frame=None, tol: float = 1e-6, angle_tol: float = 1e-6) -> Classification:
    """Classify the arm from the base to ``frame`` (default: the tool) at q = 0.

    ``tol``: distance tolerance (m) for intersecting axes and spherical triples; ``angle_tol``:
    tolerance on the sine of the angle between parallel axes (rad).  Reports every relation of
    consecutive axes, the measured values and the IK-Geo class (IK-Geo Table I; see the module
    docstring).  Joints of kind ``"continuous"`` count as revolute."""
    for name, v in (("tol", tol), ("angle_tol", angle_tol)):
        if (
            isinstance(v, bool)
            or not isinstance(v, (int, float, np.floating, np.integer))
            or not np.isfinite(v)
            or v <= 0
        ):
            raise ParameterError(f"classify: {name} must be a finite number > 0, got {v!r}")
    return classify_kinematics(kinematics(robot, frame), tol, angle_tol)


def classify_kinematics(
    kin: Kinematics, tol: float = 1e-6, angle_tol: float = 1e-6
) -> Classification:
    """:func:`classify` of given :class:`Kinematics` (e.g. the first six joints of a 7-joint
    arm whose last joint is held fixed)."""
    sin, par, dist, inter, tri, sph, three = _relations(kin.H, kin.points, tol, angle_tol)
    # the closest calls: the largest value accepted and the smallest rejected, per unit
    dl = np.concatenate([dist[~np.isnan(dist)], tri[~np.isnan(tri)]])
    acc_d, acc_a = dl[dl <= tol], sin[sin <= angle_tol]
    rej_d, rej_a = dl[dl > tol], sin[sin > angle_tol]
    worst = (float(acc_d.max()) if acc_d.size else 0.0, float(acc_a.max()) if acc_a.size else 0.0)
    nearest = (
        float(rej_d.min()) if rej_d.size else np.inf,
        float(rej_a.min()) if rej_a.size else np.inf,
    )

    def idx(mask):
        return tuple(int(i) for i in np.flatnonzero(mask))

    common = dict(
        parallel=tuple((i, i + 1) for i in idx(par)),
        intersecting=tuple((i, i + 1) for i in idx(inter)),
        spherical=idx(sph),
        three_parallel=idx(three),
        sin_angle=sin,
        distance=dist,
        triple_distance=tri,
        tol=float(tol),
        angle_tol=float(angle_tol),
        worst_accepted=worst,
        nearest_rejected=nearest,
        kinematics=kin,
    )
    revolute = all(k in (REVOLUTE, CONTINUOUS) for k in kin.kinds)
    if kin.n != 6 or not revolute:
        why = (
            f"{kin.n} joints from the base to the frame, not 6"
            if kin.n != 6
            else "not every joint is revolute: "
            + ", ".join(
                f"{nm} ({k})"
                for nm, k in zip(kin.names, kin.kinds)
                if k not in (REVOLUTE, CONTINUOUS)
            )
        )
        return Classification(NOT_6R, False, (), reason=why, **common)
    fwd = _classes_6r(par, inter, sph, three)
    # reversed chain: joint i ↔ joint 5 − i; pairs (i, i+1) ↔ (4 − i, 5 − i); triples i ↔ 3 − i
    rev = _classes_6r(par[::-1], inter[::-1], sph[::-1], three[::-1])
    ranked = sorted(
        [(CLASSES.index(c), False, c) for c in fwd] + [(CLASSES.index(c), True, c) for c in rev]
    )
    compatible = tuple((c, r) for _, r, c in ranked)
    name, is_rev = compatible[0]
    return Classification(name, is_rev, compatible, **common)


__all__ = [
    "Classification",
    "Kinematics",
    "classify",
    "classify_kinematics",
    "kinematics",
    "CLASSES",
    "CLOSED_FORM_CLASSES",
    "NOT_6R",
    "SPHERICAL_TWO_PARALLEL",
    "SPHERICAL_TWO_INTERSECTING",
    "THREE_PARALLEL_TWO_INTERSECTING",
    "SPHERICAL",
    "THREE_PARALLEL",
    "TWO_PARALLEL",
    "TWO_INTERSECTING",
    "GEN_SIX_DOF",
]
