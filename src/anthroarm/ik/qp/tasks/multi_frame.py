"""MultiFrameTask: several frames to target poses at once (five fingertips and the palm).

The residual stacks one :class:`~anthroarm.ik.qp.tasks.frame.FrameTask` residual per frame
(body twist in the frame, rows (v; ω), m and rad)::

    e = [e_1; …; e_K],   e_k = log₆(T_k⁻¹ T_k*),   J_k = −Jlog₆(T_k*⁻¹ T_k) · ᵇJ_k

with the costs W = diag(W_1, …, W_K).  Its QP objective ½‖W(JΔq + αe)‖² + ½μ‖Δq‖² with
μ = λ_LM ‖W α e‖² is exactly the sum of the K FrameTasks' objectives with the same λ_LM (the
LM terms add up: Σ_k λ‖W_k α e_k‖² = λ‖Wαe‖²).  Why a task of its own: the step adds
H = (WJ)ᵀ(WJ) in one matrix product over the stacked 6K × nv Jacobian instead of K products
and K additions, which is what a 27-DOF hand-and-arm step with six frames spends its time on.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..configuration import LOCAL
from ..targets import as_se3
from .base import Task


class MultiFrameTask(Task):
    """Pose tasks on ``frames`` (names or ids), one objective.

    Parameters
    ----------
    robot : anthroarm.Robot
    frames : sequence of str or int
    position_cost, orientation_cost : float or array
        Per frame the same weights as :class:`~anthroarm.ik.qp.tasks.frame.FrameTask`
        ([cost]/m, [cost]/rad); a scalar, a 3-vector, or one value (or 3-vector) per frame
        (shape (K,) or (K, 3); with K = 3 a (3,) array is read as one 3-vector for every frame).
    gain, lm_damping
        As for every task.
    targets : sequence of 4×4 or pin.SE3, optional
    """

    def __init__(
        self,
        robot,
        frames,
        position_cost=1.0,
        orientation_cost=1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
        targets=None,
    ):
        frames = list(frames)
        if not frames:
            raise ValueError("MultiFrameTask needs at least one frame")
        K = len(frames)

        def per_frame(c, what):
            c = np.asarray(c, dtype=float)
            if c.ndim == 1 and c.shape == (K,) and K != 3:
                c = c[:, None]
            try:
                return np.broadcast_to(c, (K, 3))
            except ValueError:
                raise ValueError(
                    f"MultiFrameTask {what} must be a scalar, a 3-vector or one per frame "
                    f"((K,) or (K, 3) with K = {K}), got shape {c.shape}"
                ) from None

        pc, oc = (
            per_frame(position_cost, "position_cost"),
            per_frame(orientation_cost, "orientation_cost"),
        )
        super().__init__(
            cost=np.concatenate([pc, oc], axis=1).ravel(), gain=gain, lm_damping=lm_damping
        )
        self.frame_ids = [robot.frame_id(f) for f in frames]
        self.frames = [robot.chain.frame(i).name for i in self.frame_ids]
        self._target_names = [f"MultiFrameTask target of {f!r}" for f in self.frames]
        self._nv = robot.nv
        self.targets: list = [None] * K
        self._w_cost = None
        self._w_gain = None
        n = 6 * K
        WJ = np.empty((n, self._nv))
        self._buf = (WJ, WJ.T, np.empty(n), np.empty((self._nv, self._nv)), np.empty(self._nv))
        if targets is not None:
            self.set_targets(targets)

    def __repr__(self) -> str:
        return f"MultiFrameTask({self.frames}, gain={self.gain}, lm_damping={self.lm_damping})"

    def set_target(self, k, T) -> None:
        """Target pose of frame ``k`` (an index into ``frames`` or a frame name)."""
        if isinstance(k, str):
            if k not in self.frames:
                raise ValueError(f"MultiFrameTask: {k!r} is not one of its frames {self.frames}")
            k = self.frames.index(k)
        self.targets[k] = as_se3(T, self._target_names[k])

    def set_targets(self, Ts) -> None:
        """All targets, in the order of ``frames`` (each as in :meth:`set_target`)."""
        Ts = list(Ts)
        if len(Ts) != len(self.frames):
            raise ValueError(f"MultiFrameTask: {len(Ts)} targets for {len(self.frames)} frames")
        self.targets = [as_se3(T, name) for T, name in zip(Ts, self._target_names)]

    def set_targets_from_configuration(self, conf) -> None:
        self.targets = [pin.SE3(conf.frame_placement(f)) for f in self.frame_ids]

    def _require_targets(self):
        for k, T in enumerate(self.targets):
            if T is None:
                raise ValueError(
                    f"MultiFrameTask: no target for frame {self.frames[k]!r} (call set_target)"
                )
        return self.targets

    def compute_error(self, conf) -> np.ndarray:
        Ts = self._require_targets()
        return np.concatenate(
            [pin.log6(conf.frame_placement(f).actInv(T)).vector for f, T in zip(self.frame_ids, Ts)]
        )

    def compute_jacobian(self, conf) -> np.ndarray:
        Ts = self._require_targets()
        return np.vstack(
            [
                -pin.Jlog6(T.actInv(conf.frame_placement(f))) @ conf.frame_jacobian(f, LOCAL)
                for f, T in zip(self.frame_ids, Ts)
            ]
        )

    def _accumulate(self, conf, ws, first):
        # the objective in place: stacked W Jlog6 ᵇJ in one buffer, one product for H and one for c
        if type(self) is not MultiFrameTask or conf.G is not None:  # J G with a coupling
            return Task._accumulate(self, conf, ws, first)
        Ts = self._require_targets()
        if self._w_cost is not self.cost or self._w_gain != self.gain:
            self._wcol = self.cost[:, None].copy()
            self._nwg = -self.cost * self.gain
            self._w_cost, self._w_gain = self.cost, self.gain
        model, data = conf.model, conf.data
        WJ, WJt, e, Ht, ct = self._buf
        for k, (fid, T_t) in enumerate(zip(self.frame_ids, Ts)):
            X = pin.updateFramePlacement(model, data, fid).actInv(T_t)  # T_b⁻¹ T_t
            pin.Jlog6(X.inverse()).dot(
                pin.getFrameJacobian(model, data, fid, LOCAL), out=WJ[6 * k : 6 * k + 6]
            )
            e[6 * k : 6 * k + 6] = pin.log6(X).vector
        np.multiply(WJ, self._wcol, out=WJ)
        nWe = np.multiply(e, self._nwg, out=e)  # −αW e
        return self._add_weighted_least_squares(ws, first, WJ, WJt, nWe, Ht, ct)
