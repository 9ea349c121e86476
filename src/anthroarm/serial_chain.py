"""Batched forward kinematics and Jacobians of any serial chain (model layer: ``robot.chain``
builds one per frame; :mod:`anthroarm.kinematics.batched` re-exports it).

:class:`SerialChain` holds, for each joint, its placement in its parent (a constant rotation
R0 and offset p0) and its axis (revolute or prismatic), plus the tool placement; it evaluates
the product of exponentials

    T_0,tool(q) = M_1 exp(a_1 q_1) M_2 exp(a_2 q_2) … M_n exp(a_n q_n) M_tool

for a whole batch of configurations at once.  Build it from a robot's
kinematic description (:meth:`SerialChain.from_chain`, i.e. ``robot.chain.serial(frame)``: any
robot, continuous and mimic joints included) or straight
from the book's H-D table (:meth:`SerialChain.from_dh`: joint j sits at the static part
S_{j−1} of row j−1 of Eq. (6-12), axis z — the chain product (6-14) itself).

The kernel works on a structure of arrays: every matrix entry is one length-N vector (or a
Python float while it is still constant), so each arithmetic step is one contiguous numpy
operation, and products with the constant placements skip their zero and ±1 entries.  The
Jacobian is the geometric one, LOCAL_WORLD_ALIGNED, rows (v; ω).
"""

from __future__ import annotations

import numpy as np

from .joint_kinds import CONTINUOUS, PRISMATIC

_EPS = 1e-15


def _clean(M: np.ndarray) -> np.ndarray:
    """Snap entries within 1e-15 of 0 or ±1 (e.g. cos 90° = 6e-17) so products skip them.
    This changes the matrix by less than one rounding error of the entries."""
    M = np.array(M, float)
    M[np.abs(M) < _EPS] = 0.0
    M[np.abs(M - 1) < _EPS] = 1.0
    M[np.abs(M + 1) < _EPS] = -1.0
    return M


# ---------------------------------------------------------------- structure-of-arrays algebra
# A "scalar" is a Python float (constant) or a length-N array.


def _axpy(acc, coef, x):
    """acc + coef * x, skipping zeros and unit coefficients."""
    if coef == 0.0:
        return acc
    if isinstance(x, float) and x == 0.0:
        return acc
    term = x if coef == 1.0 else (-x if coef == -1.0 else coef * x)
    return term if (isinstance(acc, float) and acc == 0.0) else acc + term


def _mat_const(R, M):
    """R @ M for a batch R (3×3 nested lists) and a constant 3×3 M."""
    return [[_sum3(R[i], M[:, j]) for j in range(3)] for i in range(3)]


def _sum3(row, col):
    acc = 0.0
    for k in range(3):
        acc = _axpy(acc, float(col[k]), row[k])
    return acc


def _vec_const(R, v):
    """R @ v for a constant vector v."""
    return [_sum3(R[i], v) for i in range(3)]


def _rotate_axis(R, axis_index, c, s):
    """R @ Rot(axis e_k, q) for an axis-aligned joint, given c = cos q, s = sin q."""
    i, j = {0: (1, 2), 1: (2, 0), 2: (0, 1)}[axis_index]
    out = [row[:] for row in R]
    for r in range(3):
        a, b = R[r][i], R[r][j]
        out[r][i] = a * c + b * s
        out[r][j] = b * c - a * s
    return out


def _rotate_general(R, a, c, s):
    """R @ exp([a]× q) for a unit axis a (Rodrigues), batch c, s."""
    x, y, z = a
    C = 1.0 - c
    E = [
        [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
        [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
        [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ]
    return [
        [R[i][0] * E[0][j] + R[i][1] * E[1][j] + R[i][2] * E[2][j] for j in range(3)]
        for i in range(3)
    ]


def _position(qT, coord):
    """θ of one joint for the whole batch from q transposed (see :class:`SerialChain`)."""
    if coord[0] == "q":
        return qT[coord[1]]
    _, i, a, b, continuous = coord
    src = np.arctan2(qT[i + 1], qT[i]) if continuous else qT[i]
    return a * src + b if (a, b) != (1.0, 0.0) else src


class SerialChain:
    """A serial chain: constant joint placements (R0, p0), joint axes and kinds, tool placement.

    ``coords[j]`` says where joint j's position θ_j comes from: ``("q", i)`` θ = q[i];
    ``("cs", i)`` a continuous joint, (cos θ, sin θ) = (q[i], q[i+1]); ``("mimic", i, a, b,
    continuous)`` θ = a·θ_src + b with the source at q[i] (its (cos, sin) pair if
    ``continuous``).  ``v_index[j]`` is the column of J that joint j's rate adds to, with the
    factor ``v_scale[j]`` (the mimic multiplier, else 1)."""

    def __init__(
        self,
        R0s,
        p0s,
        axes,
        kinds,
        tool_R,
        tool_p,
        q_index=None,
        v_index=None,
        nq=None,
        nv=None,
        coords=None,
        v_scale=None,
    ):
        self.R0 = [_clean(R) for R in R0s]
        self.p0 = [np.array(p, float) for p in p0s]
        self.axes = [np.array(a, float) / np.linalg.norm(a) for a in axes]
        self.kinds = list(kinds)
        self.tool_R = _clean(tool_R)
        self.tool_p = np.array(tool_p, float)
        n = len(self.kinds)
        self.q_index = list(q_index) if q_index is not None else list(range(n))
        self.v_index = list(v_index) if v_index is not None else list(range(n))
        self.coords = list(coords) if coords is not None else [("q", i) for i in self.q_index]
        self.v_scale = [float(x) for x in v_scale] if v_scale is not None else [1.0] * n
        self.nq = nq if nq is not None else n
        self.nv = nv if nv is not None else n
        self._axis_index = []
        for a in self.axes:
            k = int(np.argmax(np.abs(a)))
            self._axis_index.append(k if abs(a[k] - 1.0) < _EPS else None)

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_chain(cls, chain, frame=None) -> "SerialChain":
        """The path of a :class:`~anthroarm.chain.Chain` from the base to ``frame`` (default:
        the tool), continuous and mimic joints included."""
        f = chain.frame(frame)
        R0s, p0s, axes, kinds, coords, vi, vs = [], [], [], [], [], [], []
        for i in chain.path(f.index):
            j = chain.joints[i]
            R0s.append(j.rotation)
            p0s.append(j.translation)
            axes.append(j.axis)
            kinds.append("P" if j.kind == PRISMATIC else "R")
            if j.is_mimic:
                src = chain.joints[j.mimic.source]
                coords.append(
                    ("mimic", src.idx_q, j.mimic.multiplier, j.mimic.offset, src.kind == CONTINUOUS)
                )
                vi.append(src.idx_v)
                vs.append(j.mimic.multiplier)
            else:
                coords.append(("cs", j.idx_q) if j.kind == CONTINUOUS else ("q", j.idx_q))
                vi.append(j.idx_v)
                vs.append(1.0)
        return cls(
            R0s,
            p0s,
            axes,
            kinds,
            f.rotation,
            f.translation,
            [c[1] for c in coords],
            vi,
            chain.nq,
            chain.nv,
            coords,
            vs,
        )

    @classmethod
    def of(cls, robot, frame=None) -> "SerialChain":
        """The chain from the base of ``robot`` to ``frame`` (default: the tool)."""
        return robot.chain.serial(frame)

    @classmethod
    def from_dh(cls, rows, tool=None) -> "SerialChain":
        """The book's H-D chain, Eq. (6-12)–(6-14): A_j(q) = Rz(q) S_j (R) or Tz(q) S_j (P),
        where S_j is the static part of row j (:meth:`~anthroarm.models.spec.DHRow.static`); joint j
        sits at S_{j−1} with axis z."""
        S = [np.eye(4)] + [r.static() for r in rows]
        T_tool = S[-1] @ (np.eye(4) if tool is None else np.asarray(tool, float))
        return cls(
            [s[:3, :3] for s in S[:-1]],
            [s[:3, 3] for s in S[:-1]],
            [(0, 0, 1.0)] * len(rows),
            ["R" if r.kind == "R" else "P" for r in rows],
            T_tool[:3, :3],
            T_tool[:3, 3],
        )

    @classmethod
    def from_spec(cls, spec) -> "SerialChain":
        """Chain of a catalog :class:`~anthroarm.models.spec.ChainSpec` (joint origins and axes
        as tabulated; for the §6-3 arm this is Eq. (6-31)–(6-33))."""
        return cls(
            [j.origin[:3, :3] for j in spec.joints],
            [j.origin[:3, 3] for j in spec.joints],
            [j.axis for j in spec.joints],
            ["R" if j.type == "revolute" else "P" for j in spec.joints],
            spec.tool_origin[:3, :3],
            spec.tool_origin[:3, 3],
        )

    # ------------------------------------------------------------ evaluation
    def _batch(self, q):
        q = np.asarray(q, float)
        single = q.ndim == 1
        q2 = q[None] if single else q
        if q2.ndim != 2 or q2.shape[1] != self.nq:
            raise ValueError(f"q must have shape ({self.nq},) or (N, {self.nq}), got {q.shape}")
        if not np.isfinite(q2).all():
            raise ValueError(f"q[{int(np.argwhere(~np.isfinite(q2))[0, 1])}] is not finite")
        return q2, single

    def _walk(self, q2, keep_joints: bool):
        qT = np.ascontiguousarray(q2.T)
        R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        p = [0.0, 0.0, 0.0]
        joints = []
        for R0, p0, a, kind, coord, ax in zip(
            self.R0, self.p0, self.axes, self.kinds, self.coords, self._axis_index
        ):
            dp = _vec_const(R, p0)
            p = [_axpy(p[i], 1.0, dp[i]) for i in range(3)]
            R = _mat_const(R, R0)
            w = _vec_const(R, a)  # joint axis in world
            if keep_joints:
                joints.append((kind, w, p))
            if coord[0] == "cs":
                c, s, qj = qT[coord[1]], qT[coord[1] + 1], None
            else:
                qj = _position(qT, coord)
            if kind == "R":
                if qj is not None:
                    c, s = np.cos(qj), np.sin(qj)
                R = _rotate_axis(R, ax, c, s) if ax is not None else _rotate_general(R, a, c, s)
            else:
                p = [_axpy(p[i], 1.0, w[i] * qj) for i in range(3)]
        dp = _vec_const(R, self.tool_p)
        p = [_axpy(p[i], 1.0, dp[i]) for i in range(3)]
        R = _mat_const(R, self.tool_R)
        return R, p, joints

    def _pose(self, R, p, N):
        T = np.zeros((N, 4, 4))
        for i in range(3):
            for j in range(3):
                T[:, i, j] = R[i][j]
            T[:, i, 3] = p[i]
        T[:, 3, 3] = 1.0
        return T

    def fk(self, q) -> np.ndarray:
        """Tool pose in the base frame, (4, 4) or (N, 4, 4)."""
        q2, single = self._batch(q)
        R, p, _ = self._walk(q2, keep_joints=False)
        T = self._pose(R, p, q2.shape[0])
        return T[0] if single else T

    def positions(self, q) -> np.ndarray:
        """Tool position only (m, base frame), (3,) or (N, 3): the translation of :meth:`fk`
        without assembling the rotations into 4×4 matrices."""
        q2, single = self._batch(q)
        _, p, _ = self._walk(q2, keep_joints=False)
        xyz = np.column_stack([np.broadcast_to(np.asarray(c, float), (q2.shape[0],)) for c in p])
        return xyz[0] if single else xyz

    def fk_jacobian(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Tool pose and its LOCAL_WORLD_ALIGNED Jacobian (6 × nv, rows (v; ω)) in one pass."""
        q2, single = self._batch(q)
        N = q2.shape[0]
        R, p, joints = self._walk(q2, keep_joints=True)
        J = np.zeros((N, 6, self.nv))
        for (kind, w, pj), col, k in zip(joints, self.v_index, self.v_scale):
            if kind == "R":
                d = [p[i] - pj[i] for i in range(3)]
                cols = (
                    w[1] * d[2] - w[2] * d[1],
                    w[2] * d[0] - w[0] * d[2],
                    w[0] * d[1] - w[1] * d[0],
                    w[0],
                    w[1],
                    w[2],
                )
            else:
                cols = (w[0], w[1], w[2], 0.0, 0.0, 0.0)
            for i, x in enumerate(cols):
                if k == 1.0:
                    J[:, i, col] += x  # += : a mimic joint adds to its source's column
                elif not (isinstance(x, float) and x == 0.0):
                    J[:, i, col] += k * x
        T = self._pose(R, p, N)
        return (T[0], J[0]) if single else (T, J)

    def jacobian(self, q) -> np.ndarray:
        return self.fk_jacobian(q)[1]
