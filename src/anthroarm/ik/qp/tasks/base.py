"""Task: a residual e(q) that differential IK drives to zero, and its QP objective.

Formalism (as in pink, Caron's note on task-based IK): the task asks for the displacement Δq
to satisfy the first-order dynamics J(q) Δq = −α e(q) (gain α ∈ [0, 1]).  Its contribution to
the QP objective is

    ½ ‖W (J Δq + α e)‖² + ½ μ ‖Δq‖²,   μ = λ_LM ‖W α e‖²   (Levenberg–Marquardt damping,
                                                           Sugihara 2011),

i.e. ``H = (WJ)ᵀ(WJ) + μ I`` and ``c = α (WJ)ᵀ W e`` with W = diag(cost).  For the book this is
the damped form of the Newton step of the feedback-compensation method: with α = 1, μ → 0 and
a square J, Δq = −J⁻¹ e (Ch. 7 §7-5, notes §6.2).
"""

from __future__ import annotations

import numpy as np


class Task:
    """Base class.  Subclasses implement ``compute_error`` and ``compute_jacobian``.

    Parameters
    ----------
    cost : float or array (m,)
        Weight W = diag(cost) of the task coordinates (units: [cost] per unit of error).
    gain : float
        α ∈ [0, 1]; 1 is dead-beat, smaller values low-pass the task.
    lm_damping : float
        Unitless Levenberg–Marquardt scale λ_LM (damps the step when the error is large,
        which keeps steps bounded near singularities and for unreachable targets).
    """

    def __init__(self, cost=1.0, gain: float = 1.0, lm_damping: float = 0.0):
        if not 0.0 <= float(gain) <= 1.0:
            raise ValueError(f"task gain must be in [0, 1], got {gain}")
        if not 0.0 <= float(lm_damping) < np.inf:  # also rejects NaN
            raise ValueError(f"lm_damping must be finite and >= 0, got {lm_damping}")
        c = np.asarray(cost, dtype=float)
        if not np.all(np.isfinite(c)) or np.any(c < 0):
            raise ValueError(f"task cost must be finite and >= 0, got {cost}")
        self.cost = c if c.ndim else float(c)
        self.gain = float(gain)
        self.lm_damping = float(lm_damping)

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(cost={self.cost}, gain={self.gain}, "
            f"lm_damping={self.lm_damping})"
        )

    # -- to implement ----------------------------------------------------------------------
    def compute_error(self, conf) -> np.ndarray:
        """Residual e(q) (m,)."""
        raise NotImplementedError

    def compute_jacobian(self, conf) -> np.ndarray:
        """∂e/∂q in the tangent space, (m, nv)."""
        raise NotImplementedError

    # -- QP objective ----------------------------------------------------------------------
    def compute_qp_objective(self, conf) -> tuple[np.ndarray, np.ndarray]:
        """(H, c) of ``½ Δqᵀ H Δq + cᵀ Δq`` for this task (see the module docstring)."""
        J = self.compute_jacobian(conf)
        e = self.compute_error(conf)
        return self._objective(J, e, conf.nv)

    def _accumulate(self, conf, ws, first: bool) -> float:
        """Add this task's objective into the step's buffers ``ws.H`` (nv, nv) and ``ws.c``
        (nv,) in place (overwrite them when ``first``; ``ws.Hd`` is the writable diagonal of
        ``ws.H``) and return a scalar that the caller adds to diag(H) once for all tasks.  Used
        by :func:`~anthroarm.ik.qp.step`; the sum is the same as adding
        up :meth:`compute_qp_objective` (tests/ik_qp check it task by task).  This general version
        calls :meth:`compute_qp_objective`; tasks with a cheaper in-place form override it (and fall
        back here for subclasses, which may override the objective)."""
        Ht, ct = self.compute_qp_objective(conf)
        if first:
            np.copyto(ws.H, Ht)
            np.copyto(ws.c, ct)
        else:
            np.add(ws.H, Ht, out=ws.H)
            np.add(ws.c, ct, out=ws.c)
        return 0.0

    def _add_weighted_least_squares(self, ws, first: bool, WJ, WJt, nWe, Ht, ct) -> float:
        """The in-place tail of :meth:`_accumulate` for a weighted least-squares task: ``WJ``
        (m, nv) = W J with its transpose view ``WJt``, ``nWe`` (m,) = −αW e; add H = (WJ)ᵀ WJ and
        c = (WJ)ᵀ (−αW e) into ``ws.H``/``ws.c`` (overwrite when ``first``; ``Ht``/``ct`` are
        scratch of the same shapes) and return the LM diagonal scalar λ‖αW e‖²."""
        # ndarray.dot with out=: the BLAS product without np.dot's dispatch cost
        if first:
            WJt.dot(WJ, out=ws.H)
            WJt.dot(nWe, out=ws.c)
        else:
            np.add(ws.H, WJt.dot(WJ, out=Ht), out=ws.H)
            np.add(ws.c, WJt.dot(nWe, out=ct), out=ws.c)
        if self.lm_damping:
            return self.lm_damping * float(nWe.dot(nWe))
        return 0.0

    def _objective(self, J, e, nv):
        w = self.cost
        if isinstance(w, float):
            WJ = w * J
            We = (w * self.gain) * e
        else:
            WJ = w[:, None] * J
            We = (w * self.gain) * e
        H = WJ.T @ WJ
        if self.lm_damping:
            H.flat[:: nv + 1] += self.lm_damping * float(We @ We)
        c = WJ.T @ We
        return H, c


class FrameAxesTask(Task):
    """Common set-up of the 3-coordinate tasks on one frame (:class:`PositionTask`,
    :class:`OrientationTask`): the frame (default: the robot's tool; an unknown name raises
    ``UnknownFrameError`` listing the frames), a cost that is a scalar or a 3-vector, and an
    optional target passed to the subclass's ``set_target``."""

    def __init__(
        self, robot, frame=None, cost=1.0, gain: float = 1.0, lm_damping: float = 0.0, target=None
    ):
        super().__init__(
            cost=np.broadcast_to(np.asarray(cost, dtype=float), (3,)).copy(),
            gain=gain,
            lm_damping=lm_damping,
        )
        self.frame_id = robot.frame_id(frame)
        self.frame = robot.chain.frame(self.frame_id).name
        self.target = None
        if target is not None:
            self.set_target(target)

    def set_target(self, target) -> None:
        raise NotImplementedError

    def _require_target(self):
        if self.target is None:
            raise ValueError(
                f"{type(self).__name__}({self.frame!r}): no target set (call set_target)"
            )
        return self.target
