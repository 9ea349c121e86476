"""The plan of a 6R (or 7R, last joint held) arm for its IK-Geo class solver: which class
(:mod:`anthroarm.ik.classify`), the kinematics in IK-Geo's form (reversed where the class holds
for the reversed chain), the joint order and limits, and the plan's constants packed for the
compiled calls (:attr:`GeoPlan.packed`, read back by :func:`_unpack`)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ...jit import kernel, part, part2
from .. import classify as C
from ..classes import CLOSED, ORDER, SEARCH_2D, get
from ..classes import SEARCHED as _SEARCHED
from ..fk import WIDTH, local_frames
from ..search.constants import SEARCH_BRANCHES
from ..search.polish import geo_frames

#: the classes solved here, in closed form or by a search (the order they are tried)
SOLVED = ORDER
#: the classes of :data:`SOLVED` solved by a search (1-D over one joint angle; 2-D for
#: ``gen_six_dof``)
SEARCHED = _SEARCHED


def n_branches(cls: str) -> int:
    """The number of branch slots of a class solver per pose: 8, or :data:`SEARCH_BRANCHES`
    for a search class."""
    return 8 if get(cls).closed else SEARCH_BRANCHES


def branch_labels(cls: str) -> tuple[str, ...]:
    """The branch labels of a class (:meth:`anthroarm.ik.classes.base.GeoClass.branch_labels`):
    which root of each of its branching subproblems (``"q1=0,q3=1,q5=0"``: the first root for
    q1, the second for q3, …); for a search class which root of the search along the searched
    joint, in the order found (``"q1root=2"``; slots are filled from the first)."""
    return get(cls).branch_labels(SEARCH_BRANCHES)


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
    def search_frames(self) -> np.ndarray:
        """The arm in IK-Geo's form (``H``, ``P``) as the frames of the searches' Newton polish
        (:func:`anthroarm.ik.search.geo_frames`)."""
        return geo_frames(self.H, self.P)

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
    groups = get(cls).meets
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
    (not 6R on the path to the tool, a mimic joint, joints off that path, or a 7-joint arm whose
    first six joints are of no class but ``gen_six_dof``, whose 2-D search is not run per held
    value)."""
    return robot.derived("ik.geometric.plan", _build)


def classification(robot):
    """The classification of ``robot`` at its tool (None where the chain cannot be read, e.g.
    a mimic joint on the path)."""
    try:
        return C.classify(robot)
    except Exception:  # noqa: BLE001 - UnsupportedModelError (mimic) and kin: no class
        return None


# long: one straight sequence (classify, hold a 7th joint, reverse, limits, FK constants)
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
        ((n, r) for n, r in compatible if not (param is not None and get(n).solution == SEARCH_2D)),
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


@kernel(inline=True)
def _unpack(cf, ci):
    """The plan's constants from :attr:`GeoPlan.packed`: (class index, reversed, n, H, P,
    R_tool, the held joint's axis and point, the tool pose at q = 0, the FK frames A
    (n + 1, :data:`~anthroarm.ik.fk.WIDTH`),
    lo, hi (n,), order (n,): the path position of each independent joint, index (n, 2): its
    first entry in q and whether it is continuous) — views of ``cf``, ``ci``, compiled into each
    caller (:func:`anthroarm.jit.kernel`)."""
    n = ci[2]
    o = 70 + WIDTH * (n + 1)
    return (
        ci[0],
        ci[1] == 1,
        n,
        part2(cf, 0, 6, 3),
        part2(cf, 18, 7, 3),
        part2(cf, 39, 3, 3),
        (cf[48], cf[49], cf[50]),
        (cf[51], cf[52], cf[53]),
        part2(cf, 54, 4, 4),
        part2(cf, 70, n + 1, WIDTH),
        part(cf, o, n),
        part(cf, o + n, n),
        part(ci, 3, n),
        part2(ci, 4 + n, n, 2),
    )
