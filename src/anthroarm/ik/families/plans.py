"""The plans of the two families read from the chain (an SRS 7R arm, a planar 2R arm): the
geometry tests and the constants the compiled kernels take."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .. import classify as C
from ..fk import local_frames
from ..geometric.plan import _common_point
from ..qp.tasks.swivel import swivel_frames

SRS_ROUTES = ("sp2", "general")
#: branches per swivel angle (SRS) and per pose (planar)
SRS_BRANCHES, PLANAR_BRANCHES = 8, 2
#: tolerances of the geometry tests (m, and sine of an angle), as :func:`classify.classify`
GEOM_TOL, ANGLE_TOL = 1e-6, 1e-6


def srs_branch_labels(route: str) -> tuple[str, ...]:
    """The 8 labels of one swivel angle: q4 root (SP3) × shoulder root (SP2 of (q1, q2), or SP4
    of q2 on the general route) × wrist root (SP4 of q6)."""
    sh = "q1q2" if route == "sp2" else "q2"
    return tuple(f"q4={i},{sh}={j},q6={k}" for i in range(2) for j in range(2) for k in range(2))


PLANAR_LABELS = ("q2=0", "q2=1")


# ----------------------------------------------------------------------------- plans
@dataclass(frozen=True)
class SRSPlan:
    """A 7R shoulder–elbow–wrist arm in the form of the kernels (base frame, q = 0, m):
    axes ``H`` (7, 3), shoulder centre ``S``, elbow point ``E0`` (on axis 4), wrist centre
    ``W0``, tool pose ``R_tool``, ``p_tool``; ``route`` index into :data:`SRS_ROUTES`; the map
    from path order to ``robot.chain.independent`` (``order``), limits in path order
    (rad, ±inf continuous); the FK check's unsnapped axes/points; ``swivel_frames`` the
    (shoulder, elbow, wrist) frames whose positions define φ (None: E0 chosen on axis 4)."""

    H: np.ndarray
    S: np.ndarray
    E0: np.ndarray
    W0: np.ndarray
    R_tool: np.ndarray
    p_tool: np.ndarray
    route: int
    order: np.ndarray
    lower_path: np.ndarray
    upper_path: np.ndarray
    fk_axes: np.ndarray
    fk_points: np.ndarray
    fk_M: np.ndarray
    labels: tuple
    swivel_frames: tuple | None
    chain: object
    tool: str
    in_order: bool = False  # path order is robot.chain.independent order

    @functools.cached_property
    def fk_frames(self) -> np.ndarray:
        """The FK check's chain as :func:`anthroarm.ik.fk.local_frames` (8, 16)."""
        return local_frames(self.fk_axes, self.fk_points, self.fk_M)

    @functools.cached_property
    def packed(self) -> tuple:
        """The plan's constants as the compiled drivers take them (:func:`_srs_unpack`): one
        float array (H, S, E0, W0, R_tool, p_tool, :attr:`fk_frames`, limits in path order) and
        one int array (route, then ``order``)."""
        cf = np.concatenate(
            [
                np.asarray(a, dtype=float).ravel()
                for a in (
                    self.H,
                    self.S,
                    self.E0,
                    self.W0,
                    self.R_tool,
                    self.p_tool,
                    self.fk_frames,
                    self.lower_path,
                    self.upper_path,
                )
            ]
        )
        return cf, np.array([self.route, *self.order], dtype=np.int64)


@dataclass(frozen=True)
class PlanarPlan:
    """A planar 2R arm (two parallel axes): ``h1``, ``h2`` (h2 snapped to ±h1), points ``o1``,
    ``o2`` on the axes, tool point ``p_tool`` at q = 0 (base frame, m); ``order``, limits and
    the FK check's unsnapped axes/points as :class:`SRSPlan`."""

    h1: np.ndarray
    h2: np.ndarray
    o1: np.ndarray
    o2: np.ndarray
    p_tool: np.ndarray
    order: np.ndarray
    lower_path: np.ndarray
    upper_path: np.ndarray
    fk_axes: np.ndarray
    fk_points: np.ndarray
    labels: tuple
    chain: object
    tool: str
    in_order: bool = False

    @functools.cached_property
    def fk_frames(self) -> np.ndarray:
        """The FK check's chain as :func:`anthroarm.ik.fk.local_frames` (3, 16): its unsnapped
        axes and points, the tool point p_tool (the tool's rotation is not compared)."""
        M = np.eye(4)
        M[:3, 3] = self.p_tool
        return local_frames(self.fk_axes, self.fk_points, M)

    @functools.cached_property
    def packed(self) -> tuple:
        """The plan's constants as the compiled drivers take them (:func:`_planar_unpack`): one
        float array (h1, h2, o1, o2, p_tool, :attr:`fk_frames`, limits in path order) and one
        int array (``order``)."""
        cf = np.concatenate(
            [
                np.asarray(a, dtype=float).ravel()
                for a in (
                    self.h1,
                    self.h2,
                    self.o1,
                    self.o2,
                    self.p_tool,
                    self.fk_frames,
                    self.lower_path,
                    self.upper_path,
                )
            ]
        )
        return cf, np.array(self.order, dtype=np.int64)


def srs_plan(robot) -> SRSPlan | None:
    """The :class:`SRSPlan` of ``robot`` at its tool, or None (:func:`srs_reason` says why).
    Kept on the robot (:meth:`~anthroarm.robot.Robot.derived`), rebuilt when ``robot.chain`` or
    ``robot.tool`` change."""
    return robot.derived("ik.families.srs", _build_srs)[0]


def srs_reason(robot) -> str | None:
    """Why ``robot`` has no SRS plan (None when it has one)."""
    return robot.derived("ik.families.srs", _build_srs)[1]


def planar_plan(robot) -> PlanarPlan | None:
    """The cached :class:`PlanarPlan` of ``robot`` at its tool, or None
    (:func:`planar_reason`)."""
    return robot.derived("ik.families.planar", _build_planar)[0]


def planar_reason(robot) -> str | None:
    """Why ``robot`` has no planar-2R plan (None when it has one)."""
    return robot.derived("ik.families.planar", _build_planar)[1]


def _kinematics(robot, n):
    """(kinematics, limits lo/hi in path order, order) of the revolute path to the tool, or
    (None, reason)."""
    try:
        kin = C.classify(robot).kinematics
    except Exception as exc:  # noqa: BLE001 - mimic joints, no path: no closed form
        return None, f"the chain cannot be read: {exc}"
    ch = robot.chain
    if kin.n != n:
        return None, f"{kin.n} joints on the path to the tool, not {n}"
    if not all(k in ("revolute", "continuous") for k in kin.kinds):
        return None, "not every joint on the path is revolute"
    if sorted(kin.joints) != sorted(ch.independent):
        return None, "joints off the tool path (a solution would not be a configuration)"
    path = list(kin.joints)
    order = np.array([path.index(j) for j in ch.independent])
    lo = np.array(
        [-np.inf if ch.joints[j].kind == "continuous" else ch.joints[j].lower for j in path]
    )
    hi = np.array(
        [np.inf if ch.joints[j].kind == "continuous" else ch.joints[j].upper for j in path]
    )
    return (
        kin,
        np.ascontiguousarray(lo, dtype=float),
        np.ascontiguousarray(hi, dtype=float),
        order,
    ), None


def _line_distance(h, o, x):
    """Distance of the point x from the line through o along the unit h (m)."""
    d = x - o
    return float(np.linalg.norm(d - (d @ h) * h))


def _meet(H, pts):
    """(common point, worst distance of a line from it, min sine between two of the axes)."""
    c = _common_point(H, pts)
    dist = max(_line_distance(h, o, c) for h, o in zip(H, pts))
    sines = [np.linalg.norm(np.cross(H[i], H[j])) for i in range(3) for j in range(i + 1, 3)]
    return c, dist, min(sines)


def _build_srs(robot):
    got, why = _kinematics(robot, 7)
    if got is None:
        return None, why
    kin, lo, hi, order = got
    H, O = np.asarray(kin.H, dtype=float), np.asarray(kin.points, dtype=float)
    S, dS, sS = _meet(H[:3], O[:3])
    W0, dW, sW = _meet(H[4:], O[4:])
    if dS > GEOM_TOL or sS <= ANGLE_TOL:
        return None, f"axes 1-3 do not meet in one point (no spherical shoulder; {dS:.3g} m)"
    if dW > GEOM_TOL or sW <= ANGLE_TOL:
        return None, f"axes 5-7 do not meet in one point (no spherical wrist; {dW:.3g} m)"
    frames, E0 = None, None
    try:
        frames = swivel_frames(robot)
    except Exception:  # noqa: BLE001 - no human-like layout: the elbow point is chosen below
        frames = None
    if frames is not None:
        q0 = robot.chain.configuration(np.zeros(len(robot.chain.independent)))
        Sf, Ef, Wf = (np.asarray(robot.fk(q0, f))[:3, 3] for f in frames)
        path = list(kin.joints)
        jE = robot.chain.frame(frames[1]).joint
        ok = (
            np.linalg.norm(Sf - S) <= GEOM_TOL
            and np.linalg.norm(Wf - W0) <= GEOM_TOL
            and _line_distance(H[3], O[3], Ef) <= GEOM_TOL
            and jE in path
            and path.index(jE) == 3
        )
        if not ok:
            return None, (
                "the swivel frames "
                + ", ".join(frames)
                + " are not at the shoulder centre, on the "
                "elbow axis and at the wrist centre: the swivel angle is not this decomposition's"
            )
        E0 = Ef
    if E0 is None:  # the point of axis 4 nearest the shoulder centre
        E0 = O[3] + ((S - O[3]) @ H[3]) * H[3]
    a, b = np.linalg.norm(E0 - S), np.linalg.norm(W0 - E0)
    if a <= GEOM_TOL or b <= GEOM_TOL:
        return None, "the elbow point coincides with the shoulder or wrist centre"
    if (
        min(
            np.linalg.norm(np.cross(H[3], (E0 - S) / a)),
            np.linalg.norm(np.cross(H[3], (W0 - E0) / b)),
        )
        <= ANGLE_TOL
    ):
        return (
            None,
            "the elbow axis lies along the upper arm or the forearm (the elbow does not bend)",
        )
    route = 0 if np.linalg.norm(np.cross(H[2], (E0 - S) / a)) <= ANGLE_TOL else 1
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = kin.R_tool, kin.p_tool
    f = lambda x: np.ascontiguousarray(x, dtype=float)  # noqa: E731
    plan = SRSPlan(
        f(H),
        f(S),
        f(E0),
        f(W0),
        f(kin.R_tool),
        f(kin.p_tool),
        route,
        order,
        lo,
        hi,
        f(H),
        f(O),
        M,
        srs_branch_labels(SRS_ROUTES[route]),
        frames,
        robot.chain,
        robot.tool,
        bool((order == np.arange(7)).all()),
    )
    return plan, None


def _build_planar(robot):
    got, why = _kinematics(robot, 2)
    if got is None:
        return None, why
    kin, lo, hi, order = got
    H, O = np.asarray(kin.H, dtype=float), np.asarray(kin.points, dtype=float)
    if np.linalg.norm(np.cross(H[0], H[1])) > ANGLE_TOL:
        return None, "the two axes are not parallel"
    h1 = H[0]
    h2 = np.sign(h1 @ H[1]) * h1
    pt = np.asarray(kin.p_tool, dtype=float)
    if _line_distance(h1, O[0], O[1]) <= GEOM_TOL:
        return None, "the two axes coincide"
    if _line_distance(h2, O[1], pt) <= GEOM_TOL:
        return None, "the tool point lies on the second axis"
    f = lambda x: np.ascontiguousarray(x, dtype=float)  # noqa: E731
    return PlanarPlan(
        f(h1),
        f(h2),
        f(O[0]),
        f(O[1]),
        f(pt),
        order,
        lo,
        hi,
        f(H),
        f(O),
        PLANAR_LABELS,
        robot.chain,
        robot.tool,
        bool((order == np.arange(2)).all()),
    ), None
