"""FrameTask: drive a frame to a target pose (position and orientation costs separate).

Residual (body twist in the frame, rows (v; ω), m and rad), as in pink:

    e(q) = log₆(T_b⁻¹ T_t),   J(q) = −Jlog₆(T_t⁻¹ T_b) · ᵇJ(q)

with T_b the world pose of the frame, T_t the target and ᵇJ the LOCAL frame Jacobian (the
hand-frame Jacobian of the book, Eq. (7-94)).  ``position_cost`` weights the three linear
rows ([cost]/m), ``orientation_cost`` the three angular rows ([cost]/rad); either may be a
3-vector (anisotropic costs; 0 frees an axis).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..configuration import LOCAL
from ..targets import as_se3
from .base import Task


class FrameTask(Task):
    """Pose task on ``frame`` (name or id; default the robot's tool)."""

    def __init__(
        self,
        robot,
        frame=None,
        position_cost=1.0,
        orientation_cost=1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
        target=None,
    ):
        pc = np.broadcast_to(np.asarray(position_cost, dtype=float), (3,))
        oc = np.broadcast_to(np.asarray(orientation_cost, dtype=float), (3,))
        super().__init__(cost=np.concatenate([pc, oc]), gain=gain, lm_damping=lm_damping)
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.chain.frame(self.frame_id).name
        self._nv = robot.nv
        self._w_cost = None  # the cost array and gain the cached weights belong to
        self._w_gain = None
        self._weights()
        self.target: pin.SE3 | None = None
        if target is not None:
            self.set_target(target)

    def __repr__(self) -> str:
        return (
            f"FrameTask({self.frame!r}, cost={self.cost.tolist()}, gain={self.gain}, "
            f"lm_damping={self.lm_damping})"
        )

    @property
    def position_cost(self) -> np.ndarray:
        return self.cost[:3]

    @property
    def orientation_cost(self) -> np.ndarray:
        return self.cost[3:]

    def set_target(self, T) -> None:
        """Target world pose: 4×4 rigid transform or ``pin.SE3`` (``ValueError`` otherwise)."""
        self.target = as_se3(T, "FrameTask target")

    def set_target_from_configuration(self, conf) -> None:
        """Target = the frame's current pose in ``conf``."""
        self.target = pin.SE3(conf.frame_placement(self.frame_id))

    def _require_target(self):
        if self.target is None:
            raise ValueError(f"FrameTask({self.frame!r}): no target set (call set_target)")
        return self.target

    def compute_error(self, conf) -> np.ndarray:
        T_t = self._require_target()
        return pin.log6(conf.frame_placement(self.frame_id).actInv(T_t)).vector

    def compute_jacobian(self, conf) -> np.ndarray:
        T_t = self._require_target()
        T_tb = T_t.actInv(conf.frame_placement(self.frame_id))
        return -pin.Jlog6(T_tb) @ conf.frame_jacobian(self.frame_id, LOCAL)

    def _weights(self):
        """Cached W (as a column), αW, −αW and, when the six costs are equal, the scalar w
        (re-derived when ``cost`` or ``gain`` was reassigned)."""
        if self._w_cost is not self.cost or self._w_gain != self.gain:
            w = self.cost
            self._wcol = w[:, None].copy()
            self._wg = w * self.gain
            uniform = bool(np.all(w == w[0]))
            self._w1 = float(w[0]) if uniform else None  # scalar weight, or None
            self._nwg1 = -float(w[0]) * self.gain if uniform else None
            self._nwg = -self._wg
            WJ = np.empty((6, self._nv))
            self._buf = (WJ, WJ.T, np.empty((self._nv, self._nv)), np.empty(self._nv))
            self._w_cost, self._w_gain = self.cost, self.gain

    def compute_qp_objective(self, conf):
        # Task._objective written out for speed, with Jl = Jlog6 · ᵇJ = −J:
        # H = (W Jl)ᵀ(W Jl) + μ I,  c = α JᵀW²e = −(W Jl)ᵀ(α W e)
        T_t = self.target
        if T_t is None:
            self._require_target()
        self._weights()
        X = conf.frame_placement(self.frame_id).actInv(T_t)  # T_b⁻¹ T_t
        e = pin.log6(X).vector
        WJ = self._wcol * (pin.Jlog6(X.inverse()) @ conf.frame_jacobian(self.frame_id, LOCAL))
        We = self._wg * e
        H = WJ.T @ WJ
        if self.lm_damping:
            H.flat[:: conf.nv + 1] += self.lm_damping * float(We @ We)
        return H, -(WJ.T @ We)

    def _accumulate(self, conf, ws, first):
        # compute_qp_objective in place: the same operations on preallocated buffers, the LM
        # term returned as the diagonal scalar.  A subclass may override the objective, and a
        # model with a coupling needs the Jacobian J G: they take the general path.
        if type(self) is not FrameTask or conf.G is not None:
            return Task._accumulate(self, conf, ws, first)
        T_t = self.target
        if T_t is None:
            self._require_target()
        if self._w_cost is not self.cost or self._w_gain != self.gain:
            self._weights()
        model, data, fid = conf.model, conf.data, self.frame_id
        # kinematics are current (IKConfiguration.update / integrate_inplace computed them)
        X = pin.updateFramePlacement(model, data, fid).actInv(T_t)  # T_b⁻¹ T_t
        WJ, WJt, Ht, ct = self._buf
        pin.Jlog6(X.inverse()).dot(pin.getFrameJacobian(model, data, fid, LOCAL), out=WJ)
        w = self._w1
        if w is None:
            np.multiply(WJ, self._wcol, out=WJ)
            e = pin.log6(X).vector
            nWe = np.multiply(e, self._nwg, out=e)
        else:
            if w != 1.0:
                np.multiply(WJ, w, out=WJ)
            if self._nwg1 == -1.0:
                nWe = (-pin.log6(X)).vector  # −αW e with αW = 1 (negation is exact)
            else:
                e = pin.log6(X).vector
                nWe = np.multiply(e, self._nwg1, out=e)  # −αW e
        return self._add_weighted_least_squares(ws, first, WJ, WJt, nWe, Ht, ct)
