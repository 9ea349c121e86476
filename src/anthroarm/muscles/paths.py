"""Musculotendon lengths l(q) and moment arms r(q) = −∂l/∂q of OpenSim muscle paths, batched
over states, with the exact derivative.

A path point p fixed at location s in a frame with world pose (R, o) is at x = o + R s; with
the frame's Jacobian J = (J_v; J_ω) in the independent coordinates (LOCAL_WORLD_ALIGNED,
:meth:`anthroarm.robot.Robot.jacobian`, which carries the coupling's G = dφ/dq of an imported
model) its derivative is

    ∂x/∂q = J_v − [R s]× J_ω + R ∂s/∂q,

where ∂s/∂q is zero for a fixed point and f'(c) ∂c/∂q for a ``MovingPathPoint`` whose
location is f(c) of a coordinate c (∂c/∂q through the model's coordinate couplers).  The
path length is the sum of the straight segments between the active points,
l = Σ |x_{i+1} − x_i|, so

    ∂l/∂q = Σ u_iᵀ (∂x_{i+1}/∂q − ∂x_i/∂q),     u_i = (x_{i+1} − x_i) / |x_{i+1} − x_i|,

and the moment arm about coordinate q_k is r_k = −∂l/∂q_k (Delp & Loan 1995, *A graphics-based
software system to develop and analyze models of musculoskeletal structures*, Comput Biol Med
25(1); An et al. 1984, *Determination of muscle orientations and moment arms*, J Biomech Eng
106: the tendon-excursion definition r = −dl/dθ).  Wrapped segments (a ``PathWrap``) are
replaced by the wrap's tangent-line–surface–tangent-line path (:mod:`anthroarm.muscles.wrap`),
differentiated there by the complex step through OpenSim's whole multi-pass evaluation: the
exact −∂l/∂q on a path over an ellipsoid (one wrap or several), OpenSim's moment arm (the
tangent points fixed in their wrap bodies, −∂l/∂q wherever the wrap path is a shortest one) on
paths over cylinders and spheres only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MuscleError, ParameterError
from . import wrap as wrapping
from .reader import MuscleSet, read_muscles

#: consecutive active path points closer than this (m) make a path "with coinciding points"
COINCIDE = 1e-12


def muscle_set(robot, muscles=None) -> MuscleSet:
    """``muscles`` as a :class:`~anthroarm.muscles.reader.MuscleSet`: as given, read from a
    file path, or (None) read once from the robot's own ``.osim`` file and kept with it."""
    if isinstance(muscles, MuscleSet):
        return muscles
    if muscles is not None:
        return read_muscles(muscles)
    osim = getattr(robot, "osim", None)
    if osim is None:
        raise ParameterError(f"{robot.name}: not an OpenSim model; pass muscles= (a .osim file)")
    return robot.derived("muscles.set", lambda _robot: read_muscles(osim.path))


def _coordinates(robot, q):
    """(values (N, nc), dc/dq (N, nc, nq), name -> index) of every coordinate of the model."""
    n, nq = q.shape
    coup = getattr(robot, "coupling", None)
    if coup is None:
        osim = getattr(robot, "osim", None)
        names = list(robot.joint_names)
        extra = [] if osim is None else [c for c in osim.coordinates if c.name not in names]
        c = np.concatenate([q, np.tile([e.default for e in extra], (n, 1))], axis=1)
        dc = np.zeros((n, nq + len(extra), nq))
        dc[:, np.arange(nq), np.arange(nq)] = 1.0
        return c, dc, {nm: i for i, nm in enumerate(names + [e.name for e in extra])}
    nc = len(coup.coordinates)
    c = coup.coordinate_values(q)
    dc = np.zeros((n, nc, nq))
    dc[:, coup.independent, np.arange(nq)] = 1.0
    for s in coup.dependent_steps:  # c[target] = scale * f(c[source]): the chain rule
        _, f1, _ = s.function.eval(c[:, s.source])
        dc[:, s.target] = (s.scale * f1)[:, None] * dc[:, s.source]
    return c, dc, {nm: i for i, nm in enumerate(coup.coordinates)}


class Kinematics:
    """Frame poses and Jacobians, and coordinates, for one batch of states (computed once,
    shared by every muscle)."""

    def __init__(self, robot, q):
        self.robot = robot
        self.q = q
        self.c, self.dc, self.index = _coordinates(robot, q)
        self.frames: dict = {}

    def frame(self, name):
        if name not in self.frames:
            try:
                T = self.robot.fk(self.q, name)
                J = self.robot.jacobian(self.q, name)
            except KeyError as exc:
                raise MuscleError(
                    f"{self.robot.name}: path frame {name!r} not in the model"
                ) from exc
            self.frames[name] = (T, J)
        return self.frames[name]

    def coordinate(self, name):
        if name not in self.index:
            raise MuscleError(f"{self.robot.name}: coordinate {name!r} of a path not in the model")
        k = self.index[name]
        return self.c[:, k], self.dc[:, k]

    def point(self, frame, s, ds=None):
        """World position (N, 3) and ∂x/∂q (N, 3, nq) of location s (3,) or (N, 3) in frame,
        with ∂s/∂q (N, 3, nq) when s moves."""
        T, J = self.frame(frame)
        R, o = T[:, :3, :3], T[:, :3, 3]
        rs = np.einsum("nij,...j->ni", R, s) if s.ndim == 1 else np.einsum("nij,nj->ni", R, s)
        x = o + rs
        dx = J[:, :3] - _cross_cols(rs, J[:, 3:])
        if ds is not None:
            dx = dx + np.einsum("nij,njk->nik", R, ds)
        return x, dx

    def points(self, frame, S):
        """World positions (N, P, 3) and ∂x/∂q (N, P, 3, nq) of P fixed locations S (P, 3)."""
        T, J = self.frame(frame)
        rs = np.einsum("nij,pj->npi", T[:, :3, :3], S)
        x = T[:, None, :3, 3] + rs
        dx = J[:, None, :3] - _cross_cols(rs, J[:, None, 3:])
        return x, dx


def _cross_cols(a, B):
    """a × each column of B: a (..., 3), B (..., 3, k) -> (..., 3, k)."""
    a0, a1, a2 = a[..., 0, None], a[..., 1, None], a[..., 2, None]
    b0, b1, b2 = B[..., 0, :], B[..., 1, :], B[..., 2, :]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-2)


def _path_point(kin: Kinematics, p):
    """(x (N,3), dx (N,3,nq), active (N,)) of a path point."""
    n = kin.q.shape[0]
    if p.kind == "moving":
        s = np.zeros((n, 3))
        ds = np.zeros((n, 3, kin.q.shape[1]))
        for k, (f, cn) in enumerate(zip(p.functions, p.coordinates)):
            if cn is None:
                s[:, k] = f.value(np.zeros(n))
                continue
            c, dc = kin.coordinate(cn)
            f0, f1, _ = f.eval(c)
            s[:, k] = f0
            ds[:, k] = f1[:, None] * dc
        x, dx = kin.point(p.frame, s, ds)
        return x, dx, np.ones(n, dtype=bool)
    x, dx = kin.point(p.frame, p.location)
    if p.kind == "conditional":
        c, _ = kin.coordinate(p.coordinate)
        return x, dx, (c >= p.range[0]) & (c <= p.range[1])
    return x, dx, np.ones(n, dtype=bool)


def _muscle_path(kin: Kinematics, muscle, wraps: dict, use_wrap: bool, X, DX, codes=None):
    """(l (N,), dl/dq (N, nq)) of one muscle whose points are X (N, K, 3), DX (N, K, 3, nq)
    (moving points filled in here); ``codes`` (N, wraps): each wrap's outcome."""
    n, nq = kin.q.shape
    act = np.ones((n, len(muscle.points)), dtype=bool)
    for k, p in enumerate(muscle.points):
        if p.kind == "fixed":
            continue
        X[:, k], DX[:, k], act[:, k] = _path_point(kin, p)
    length = np.zeros(n)
    grad = np.zeros((n, nq))
    objs = []
    if use_wrap:
        for pw in muscle.wraps:
            w = wraps[pw.wrap]
            T, J = kin.frame(w.frame)
            objs.append((pw, w, T, J))
    patterns, inverse = np.unique(act, axis=0, return_inverse=True)
    for k, pat in enumerate(patterns):
        rows = np.flatnonzero(inverse.reshape(-1) == k)
        idx = np.flatnonzero(pat)
        xs, dxs = X[rows][:, idx], DX[rows][:, idx]
        if objs:
            sub = [(pw, w, T[rows], J[rows]) for pw, w, T, J in objs]
            ck = None if codes is None else np.zeros((len(rows), len(objs)), dtype=int)
            lk, gk = wrapping.wrapped_length(xs, dxs, idx, sub, muscle, ck)
            if codes is not None:
                codes[rows] = ck
        else:
            lk, gk = straight_length(xs, dxs, muscle.name)
        length[rows], grad[rows] = lk, gk
    return length, grad


def straight_length(xs, dxs, name="path"):
    """Length (N,) and its gradient (N, nq) of the polyline through points xs (N, K, 3) with
    derivatives dxs (N, K, 3, nq)."""
    d = xs[:, 1:] - xs[:, :-1]
    seg = np.linalg.norm(d, axis=-1)
    if np.any(seg < COINCIDE):
        i = np.argwhere(seg < COINCIDE)[0]
        raise MuscleError(
            f"muscle {name!r}: path points {i[1]} and {i[1] + 1} coincide (state {i[0]}): the "
            "path's direction is undefined"
        )
    u = d / seg[..., None]
    ddx = dxs[:, 1:] - dxs[:, :-1]
    return seg.sum(axis=1), np.einsum("nsi,nsik->nk", u, ddx)


def _evaluate(robot, muscles, q, wrap: bool):
    ms = muscle_set(robot, muscles)
    q = robot.check_q(q)
    one = q.ndim == 1
    q2 = q.reshape(1, -1) if one else q
    L = np.zeros((q2.shape[0], len(ms)))
    D = np.zeros((q2.shape[0], len(ms), q2.shape[1]))
    plan = ms.__dict__.get("plan")  # kept with the muscle set it describes
    if plan is None:
        plan = ms.__dict__["plan"] = _Plan(ms)
    for a in range(0, q2.shape[0], CHUNK):
        b = min(a + CHUNK, q2.shape[0])
        L[a:b], D[a:b] = plan.run(Kinematics(robot, q2[a:b]), wrap)
    return (L[0], D[0]) if one else (L, D)


#: states evaluated at once (bounds the (N, points, 3, nq) arrays)
CHUNK = 256


class _Plan:
    """Where every path point of a muscle set sits in one stacked array, and which muscles are
    plain polylines of fixed points (evaluated all at once)."""

    def __init__(self, ms: MuscleSet):
        self.ms = ms
        self.start = np.cumsum([0] + [len(m.points) for m in ms.muscles])
        self.by_frame: dict = {}
        for i, m in enumerate(ms.muscles):
            for k, p in enumerate(m.points):
                if p.kind != "moving":
                    self.by_frame.setdefault(p.frame, []).append(self.start[i] + k)
        self.plain = [
            i for i, m in enumerate(ms.muscles) if all(p.kind == "fixed" for p in m.points)
        ]
        self.plain_wrapless = [i for i in self.plain if not ms.muscles[i].wraps]
        a, b, owner = [], [], []
        for i in self.plain:
            for k in range(len(ms.muscles[i].points) - 1):
                a.append(self.start[i] + k)
                b.append(self.start[i] + k + 1)
                owner.append(i)
        self.seg_a, self.seg_b = np.array(a, dtype=int), np.array(b, dtype=int)
        self.seg_owner = np.array(owner, dtype=int)

    def run(self, kin: Kinematics, wrap: bool):
        ms = self.ms
        n, nq = kin.q.shape
        P = int(self.start[-1])
        X = np.zeros((n, P, 3))
        DX = np.zeros((n, P, 3, nq))
        for frame, idx in self.by_frame.items():
            S = np.array([self._point(j).location for j in idx])
            X[:, idx], DX[:, idx] = kin.points(frame, S)
        L = np.zeros((n, len(ms)))
        D = np.zeros((n, len(ms), nq))
        done = set(self.plain if not wrap else self.plain_wrapless)
        if done:
            sel = np.isin(self.seg_owner, list(done))
            sa, sb, own = self.seg_a[sel], self.seg_b[sel], self.seg_owner[sel]
            d = X[:, sb] - X[:, sa]
            seg = np.linalg.norm(d, axis=-1)
            if np.any(seg < COINCIDE):
                s_, j = np.argwhere(seg < COINCIDE)[0]
                m = ms.muscles[own[j]]
                raise MuscleError(
                    f"muscle {m.name!r}: path points {sa[j] - self.start[own[j]]} and "
                    f"{sb[j] - self.start[own[j]]} coincide (state {s_}): the path's direction "
                    "is undefined"
                )
            g = np.einsum("nsi,nsik->nsk", d / seg[..., None], DX[:, sb] - DX[:, sa])
            for i in done:
                rows = own == i
                L[:, i] = seg[:, rows].sum(axis=1)
                D[:, i] = g[:, rows].sum(axis=1)
        for i, m in enumerate(ms.muscles):
            if i in done:
                continue
            sl = slice(self.start[i], self.start[i + 1])
            L[:, i], D[:, i] = _muscle_path(kin, m, ms.wrap_objects, wrap, X[:, sl], DX[:, sl])
        return L, D

    def _point(self, j):
        i = int(np.searchsorted(self.start, j, side="right") - 1)
        return self.ms.muscles[i].points[j - self.start[i]]


def lengths(robot, muscles=None, q=None, *, wrap: bool = True) -> np.ndarray:
    """Musculotendon (path) lengths, m: ``q`` ``(nq,)`` → ``(M,)``, ``(N, nq)`` → ``(N, M)``,
    muscles in the set's order (``muscles``: a :class:`~anthroarm.muscles.reader.MuscleSet`, a
    ``.osim`` path, or None for the robot's own model).  ``wrap=False`` ignores the wrap
    objects (straight segments between the active path points).  See the module docstring."""
    return _evaluate(robot, muscles, q, wrap)[0]


def moment_arms(robot, muscles=None, q=None, *, wrap: bool = True) -> np.ndarray:
    """Moment arms r = −∂l/∂q, m (or m/m for a translational coordinate): ``(M, nq)`` or
    ``(N, M, nq)``, in the independent coordinates ``robot.joint_names``, the exact derivative
    of :func:`lengths` (chain rule through the frames' Jacobians and the coupling; no finite
    differences)."""
    return -_evaluate(robot, muscles, q, wrap)[1]


def lengths_and_moment_arms(robot, muscles=None, q=None, *, wrap: bool = True):
    """(:func:`lengths`, :func:`moment_arms`) from one evaluation."""
    L, D = _evaluate(robot, muscles, q, wrap)
    return L, -D


def wrap_status(robot, muscles=None, q=None) -> dict:
    """Each wrap's outcome, per muscle with wraps: ``{name: codes}``, codes ``(W,)`` for
    ``q`` ``(nq,)`` or ``(N, W)`` for ``(N, nq)``, in the order of the muscle's PathWrapSet:
    1 the path wraps over the object, 0 it does not, -1 it does not because a segment tried
    had an end point inside the object (OpenSim's ``insideRadius``: the path then passes
    straight through, as here; the length stays finite and equals OpenSim's).  A bad-input
    report for "a wrap object the path starts inside" (issue 34)."""
    ms = muscle_set(robot, muscles)
    q = robot.check_q(q)
    one = q.ndim == 1
    q2 = q.reshape(1, -1) if one else q
    kin = Kinematics(robot, q2)
    n, nq = q2.shape
    out = {}
    for m in ms.muscles:
        if not m.wraps:
            continue
        X = np.zeros((n, len(m.points), 3))
        DX = np.zeros((n, len(m.points), 3, nq))
        for k, p in enumerate(m.points):
            if p.kind != "moving":
                X[:, k], DX[:, k] = kin.point(p.frame, p.location)
        codes = np.zeros((n, len(m.wraps)), dtype=int)
        _muscle_path(kin, m, ms.wrap_objects, True, X, DX, codes)
        out[m.name] = codes[0] if one else codes
    return out


@dataclass(frozen=True, eq=False)
class MusclePath:
    """One muscle's path on one state, as drawn (:func:`path_points`).

    ``points`` (K, 3): the path in order, in the model's ground frame (the robot's base frame),
    m; ``labels`` (K,): each point's PathPoint name, or the wrap object's name for its tangent
    points and the points of its surface arc; ``surface`` (K,) bool: True for the points strictly
    inside a wrap's surface arc (the others are OpenSim's ``GeometryPath.getCurrentPath``: the
    active path points and each wrap's two ``PathWrapPoint``\\ s)."""

    name: str
    points: np.ndarray
    labels: tuple
    surface: np.ndarray

    @property
    def current(self) -> np.ndarray:
        """(k, 3) the points of OpenSim's ``getCurrentPath`` (without the arcs' inner points)."""
        return self.points[~self.surface]

    @property
    def length(self) -> float:
        """The polyline's length Σ |x_{i+1} − x_i|, m: the muscle's :func:`lengths` (and
        OpenSim's ``getLength``) to within the arcs' ``tolerance`` (an ellipsoid's arc is its
        polyline) on a path over one wrap at most.  Over two or more, OpenSim's tangent points
        (its ``getLocationInGround``, which the length adds up) are where a wrap point was
        first placed in the state and the arcs are the last pass's: the polyline joins them by
        short straight pieces and differs from the length (by up to 5.4 mm on arm26's TRIlong
        over 20 random states)."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())


def path_points(
    robot, muscles=None, q=None, *, wrap: bool = True, tolerance: float = wrapping.ARC_TOLERANCE
):
    """The muscles' paths as points, what a viewer draws: ``q`` ``(nq,)`` → ``{name:``
    :class:`MusclePath` ``}`` in the set's order, ``(N, nq)`` → a list of N such dicts.

    Each path: the active path points (a ``ConditionalPathPoint`` inside its coordinate's
    range, a ``MovingPathPoint`` at f(c)), and on a wrapped segment the wrap's two tangent
    points with its surface arc between them (:func:`anthroarm.muscles.wrap.current_path`,
    the evaluation :func:`lengths` makes): a cylinder's helix and a sphere's great circle
    sampled so that the polyline is shorter than the arc by at most ``tolerance`` m each
    (:func:`anthroarm.muscles.wrap.surface_points`), an ellipsoid's OpenSim polyline (1 mm
    chords).  Frame: the model's ground (the robot's base frame); units: m.  ``muscles`` and
    ``wrap`` as in :func:`lengths`; ``tolerance`` > 0."""
    ms = muscle_set(robot, muscles)
    if isinstance(tolerance, bool) or not (
        isinstance(tolerance, (int, float)) and np.isfinite(tolerance) and tolerance > 0
    ):
        raise ParameterError(f"tolerance must be a positive number of metres, got {tolerance!r}")
    q = robot.check_q(q)
    one = q.ndim == 1
    q2 = q.reshape(1, -1) if one else q
    out = [{} for _ in range(q2.shape[0])]
    for a in range(0, q2.shape[0], CHUNK):
        kin = Kinematics(robot, q2[a : a + CHUNK])
        for m in ms.muscles:
            for s, path in enumerate(_paths(kin, m, ms.wrap_objects, wrap, tolerance)):
                out[a + s][m.name] = path
    return out[0] if one else out


def _paths(kin: Kinematics, muscle, wraps: dict, use_wrap: bool, tolerance: float) -> list:
    """The :class:`MusclePath` of one muscle on every state of ``kin``."""
    xs = [_path_point(kin, p) for p in muscle.points]
    X = np.stack([x for x, _, _ in xs], axis=1)  # (N, K, 3)
    act = np.stack([a for _, _, a in xs], axis=1)
    objs = []
    if use_wrap and muscle.wraps:
        objs = [(pw, wraps[pw.wrap], kin.frame(wraps[pw.wrap].frame)[0]) for pw in muscle.wraps]
    out = []
    for s in range(X.shape[0]):
        idx = np.flatnonzero(act[s])
        if not objs:
            trace = [("point", k, X[s, k]) for k in idx]
        else:
            sub = [(pw, w, T[s]) for pw, w, T in objs]
            trace = wrapping.current_path(X[s, idx], idx, sub, muscle, tolerance)
        pts, labels, surf = [], [], []
        for kind, k, x in trace:
            x = np.atleast_2d(x)
            pts.append(x)
            name = muscle.points[k].name if kind == "point" else objs[k][1].name
            labels += [name] * len(x)
            surf += [kind == "surface"] * len(x)
        out.append(MusclePath(muscle.name, np.concatenate(pts), tuple(labels), np.array(surf)))
    return out
