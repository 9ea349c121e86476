"""Result types of the one-shot IK solver :func:`anthroarm.ik.solve`.

``IKResult`` is one answer; ``IKBatchResult`` is the answer for a batch of targets (arrays over
the batch, indexable into ``IKResult``).  Errors are SI: ``pos_err`` in metres (distance between
the frame origin and the target position, world frame) and ``rot_err`` in radians (angle of the
rotation ``R(q)ᵀ R_target``).  For a position-only target ``rot_err`` is ``nan``-free 0.0 and not
checked; for an orientation-only target ``pos_err`` is 0.0 and not checked (``mode`` says which).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Status strings of :class:`IKResult`.
STATUSES = {
    "success": "the target is reached within tol_pos / tol_rot and every joint is within its limits",
    "out_of_reach": "the target lies farther from the base than the arm can reach; q is the closest pose found",
    "not_converged": "no configuration within the limits reached the tolerance before max_time / max_restarts; "
    "q is the closest pose found",
}


@dataclass
class IKResult:
    """One IK answer.

    Attributes
    ----------
    q : ndarray (nq,)
        Joint configuration, always within the joint limits (also when ``success`` is False:
        then it is the closest pose found).
    success : bool
        True when ``pos_err <= tol_pos`` and ``rot_err <= tol_rot`` (for the checked parts).
    status : str
        One of :data:`STATUSES` (``"success"``, ``"out_of_reach"``, ``"not_converged"``).
    pos_err : float
        Position error, m (world frame).
    rot_err : float
        Orientation error, rad.
    iterations : int
        Gauss–Newton iterations summed over all restarts.
    restarts : int
        Number of seeds tried after the first (0: the first seed converged).
    message : str
        Human-readable explanation (why it failed, which seed won).
    mode : str
        ``"pose"``, ``"position"`` or ``"orientation"``.
    seed : str
        Which seed produced ``q``: ``"q0"`` (the caller's), ``"analytic"`` (a closed-form
        solution), ``"table"`` (the solver's table of the arm's own poses, nearest first) or
        ``"restart"`` (uniform random inside the limits).
    """

    q: np.ndarray
    success: bool
    status: str
    pos_err: float
    rot_err: float
    iterations: int
    restarts: int = 0
    message: str = ""
    mode: str = "pose"
    seed: str = "q0"

    def __bool__(self) -> bool:  # ``if aa.ik.solve(...):`` reads naturally
        return bool(self.success)

    def as_dict(self) -> dict:
        """JSON-friendly dict (lists instead of arrays)."""
        return {
            "q": [float(x) for x in self.q],
            "success": bool(self.success),
            "status": self.status,
            "pos_err": float(self.pos_err),
            "rot_err": float(self.rot_err),
            "iterations": int(self.iterations),
            "restarts": int(self.restarts),
            "message": self.message,
            "mode": self.mode,
            "seed": self.seed,
        }


@dataclass
class IKBatchResult:
    """Answers for a batch of N targets (arrays over the batch).

    ``result[i]`` is the :class:`IKResult` of target ``i``; ``len(result) == N``."""

    q: np.ndarray  # (N, nq)
    success: np.ndarray  # (N,) bool
    status: list  # N strings
    pos_err: np.ndarray  # (N,)
    rot_err: np.ndarray  # (N,)
    iterations: np.ndarray  # (N,) int
    restarts: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    messages: list = field(default_factory=list)
    mode: str = "pose"

    @classmethod
    def collect(cls, results, nq: int, mode: str) -> "IKBatchResult":
        """The batch of the one-target answers ``results`` (IKResults, q of length ``nq``)."""
        return cls(
            q=np.array([r.q for r in results]).reshape(len(results), nq),
            success=np.array([r.success for r in results], dtype=bool),
            status=[r.status for r in results],
            pos_err=np.array([r.pos_err for r in results]),
            rot_err=np.array([r.rot_err for r in results]),
            iterations=np.array([r.iterations for r in results], dtype=int),
            restarts=np.array([r.restarts for r in results], dtype=int),
            messages=[r.message for r in results],
            mode=mode,
        )

    def __len__(self) -> int:
        return len(self.q)

    def __getitem__(self, i) -> IKResult:
        return IKResult(
            self.q[i].copy(),
            bool(self.success[i]),
            self.status[i],
            float(self.pos_err[i]),
            float(self.rot_err[i]),
            int(self.iterations[i]),
            int(self.restarts[i]) if len(self.restarts) else 0,
            self.messages[i] if self.messages else "",
            self.mode,
        )

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def success_rate(self) -> float:
        return float(np.mean(self.success)) if len(self.success) else 0.0
