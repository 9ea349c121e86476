"""Batched forward kinematics and Jacobians of any serial chain.

:class:`SerialChain` holds, for each joint, its placement in its parent (a constant rotation
R0 and offset p0) and its axis (revolute or prismatic), plus the tool placement; it evaluates
the product of exponentials

    T_0,tool(q) = M_1 exp(a_1 q_1) M_2 exp(a_2 q_2) … M_n exp(a_n q_n) M_tool

for a whole batch of configurations at once.  Build it from a Pinocchio model
(:meth:`SerialChain.of`, used for robots without a book formula: panda, ur5, …) or straight
from the book's H-D table (:meth:`SerialChain.from_dh`: joint j sits at the static part
S_{j−1} of row j−1 of Eq. (6-12), axis z — the chain product (6-14) itself).

The kernel works on a structure of arrays: every matrix entry is one length-N vector (or a
Python float while it is still constant), so each arithmetic step is one contiguous numpy
operation, and products with the constant placements skip their zero and ±1 entries.  The
Jacobian is the geometric one, LOCAL_WORLD_ALIGNED, rows (v; ω).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import UnsupportedModelError

_EPS = 1e-15


def _axis_and_kind(jm) -> tuple[str, np.ndarray]:
    name = jm.shortname()
    table = {
        "JointModelRX": ("R", (1, 0, 0)), "JointModelRY": ("R", (0, 1, 0)), "JointModelRZ": ("R", (0, 0, 1)),
        "JointModelPX": ("P", (1, 0, 0)), "JointModelPY": ("P", (0, 1, 0)), "JointModelPZ": ("P", (0, 0, 1)),
    }
    if name in table:
        k, a = table[name]
        return k, np.array(a, float)
    if name == "JointModelRevoluteUnaligned":
        return "R", np.array(jm.extract().axis, float)
    if name == "JointModelPrismaticUnaligned":
        return "P", np.array(jm.extract().axis, float)
    raise UnsupportedModelError(f"joint type {name} is not a 1-DOF revolute/prismatic joint")


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
    E = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
         [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
         [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]
    return [[R[i][0] * E[0][j] + R[i][1] * E[1][j] + R[i][2] * E[2][j] for j in range(3)] for i in range(3)]


def _full(x, N):
    return np.full(N, x) if isinstance(x, float) else x


class SerialChain:
    """A serial chain: constant joint placements (R0, p0), joint axes and kinds, tool placement."""

    def __init__(self, R0s, p0s, axes, kinds, tool_R, tool_p, q_index=None, v_index=None, nq=None, nv=None):
        self.R0 = [_clean(R) for R in R0s]
        self.p0 = [np.array(p, float) for p in p0s]
        self.axes = [np.array(a, float) / np.linalg.norm(a) for a in axes]
        self.kinds = list(kinds)
        self.tool_R = _clean(tool_R)
        self.tool_p = np.array(tool_p, float)
        n = len(self.kinds)
        self.q_index = list(q_index) if q_index is not None else list(range(n))
        self.v_index = list(v_index) if v_index is not None else list(range(n))
        self.nq = nq if nq is not None else n
        self.nv = nv if nv is not None else n
        self._axis_index = []
        for a in self.axes:
            k = int(np.argmax(np.abs(a)))
            self._axis_index.append(k if abs(a[k] - 1.0) < _EPS else None)

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_model(cls, model: pin.Model, frame_id: int) -> "SerialChain":
        f = model.frames[frame_id]
        chain = []
        jid = f.parentJoint
        while jid > 0:
            chain.append(jid)
            jid = model.parents[jid]
        chain.reverse()
        R0s, p0s, axes, kinds, qi, vi = [], [], [], [], [], []
        for jid in chain:
            jm = model.joints[jid]
            if jm.nq != 1 or jm.nv != 1:
                raise UnsupportedModelError(f"joint {model.names[jid]} has nq={jm.nq}; only 1-DOF joints are supported")
            k, a = _axis_and_kind(jm)
            M = model.jointPlacements[jid]
            R0s.append(M.rotation)
            p0s.append(M.translation)
            axes.append(a)
            kinds.append(k)
            qi.append(jm.idx_q)
            vi.append(jm.idx_v)
        return cls(R0s, p0s, axes, kinds, f.placement.rotation, f.placement.translation, qi, vi, model.nq, model.nv)

    @classmethod
    def of(cls, robot, frame=None) -> "SerialChain":
        """The chain from the base of ``robot`` to ``frame`` (default: the tool)."""
        return cls.from_model(robot.model, robot.frame_id(frame))

    @classmethod
    def from_dh(cls, rows, tool=None) -> "SerialChain":
        """The book's H-D chain, Eq. (6-12)–(6-14): A_j(q) = Rz(q) S_j (R) or Tz(q) S_j (P),
        where S_j is the static part of row j; joint j sits at S_{j−1} with axis z."""
        from ..models.spec import dh_static

        S = [np.eye(4)] + [dh_static(r) for r in rows]
        T_tool = S[-1] @ (np.eye(4) if tool is None else np.asarray(tool, float))
        return cls([s[:3, :3] for s in S[:-1]], [s[:3, 3] for s in S[:-1]], [(0, 0, 1.0)] * len(rows),
                   ["R" if r.kind == "R" else "P" for r in rows], T_tool[:3, :3], T_tool[:3, 3])

    @classmethod
    def from_spec(cls, spec) -> "SerialChain":
        """Chain of a catalog :class:`~anthroarm.models.spec.ChainSpec` (joint origins and axes
        as tabulated; for the §6-3 arm this is Eq. (6-31)–(6-33))."""
        return cls([j.origin[:3, :3] for j in spec.joints], [j.origin[:3, 3] for j in spec.joints],
                   [j.axis for j in spec.joints], ["R" if j.type == "revolute" else "P" for j in spec.joints],
                   spec.tool_origin[:3, :3], spec.tool_origin[:3, 3])

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
        for R0, p0, a, kind, iq, ax in zip(self.R0, self.p0, self.axes, self.kinds, self.q_index, self._axis_index):
            dp = _vec_const(R, p0)
            p = [_axpy(p[i], 1.0, dp[i]) for i in range(3)]
            R = _mat_const(R, R0)
            qj = qT[iq]
            w = _vec_const(R, a)  # joint axis in world
            if keep_joints:
                joints.append((kind, w, p))
            if kind == "R":
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

    def fk_jacobian(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Tool pose and its LOCAL_WORLD_ALIGNED Jacobian (6 × nv, rows (v; ω)) in one pass."""
        q2, single = self._batch(q)
        N = q2.shape[0]
        R, p, joints = self._walk(q2, keep_joints=True)
        J = np.zeros((N, 6, self.nv))
        for (kind, w, pj), col in zip(joints, self.v_index):
            if kind == "R":
                d = [p[i] - pj[i] for i in range(3)]
                J[:, 0, col] = _full(w[1] * d[2] - w[2] * d[1], N)
                J[:, 1, col] = _full(w[2] * d[0] - w[0] * d[2], N)
                J[:, 2, col] = _full(w[0] * d[1] - w[1] * d[0], N)
                for i in range(3):
                    J[:, 3 + i, col] = w[i]
            else:
                for i in range(3):
                    J[:, i, col] = w[i]
        T = self._pose(R, p, N)
        return (T[0], J[0]) if single else (T, J)

    def jacobian(self, q) -> np.ndarray:
        return self.fk_jacobian(q)[1]
