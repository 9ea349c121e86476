"""PostureTask: pull the joints toward a reference posture, and the comfortable human posture.

    e(q) = q ⊖ q_ref  (pin.difference),   J = I   (nv × nv)

so the error of a continuous joint ((cos θ, sin θ) in q) is the shortest angle to its reference,
in (−π, π].

Used with a small cost it resolves redundancy (the book's redundancy handling by a penalty on
the configuration, Ch. 7 §7-6 (7-84)–(7-86), becomes a QP regulariser).

:func:`comfortable_posture` gives the relaxed reference posture a model carries
(``robot.spec.comfort``: for the human arm the centres of RULA's lowest-load bands, see
:data:`anthroarm.models.human.HUMAN_ARM7_COMFORT`), clipped into the joint limits.  Other
robots get the middle of their joint ranges (θ = 0 for a joint without a finite range, a
continuous joint included); an OpenSim model with a coupling (``robot.coupling``) the middle of
its coordinates' ranges, and its posture error is the plain difference of coordinates.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .base import Task


def has_comfortable_posture(robot) -> bool:
    """True when the robot's model carries a comfortable posture for every joint
    (``robot.spec.comfort``, e.g. the §6-3 human arm; see :mod:`anthroarm.models.human`)."""
    comfort = getattr(robot.spec, "comfort", None)
    return bool(comfort) and all(
        robot.chain.joints[i].name in comfort for i in robot.chain.independent
    )


def comfortable_posture(robot) -> np.ndarray:
    """Reference posture (nq,) of ``robot`` from ``robot.chain``: the model's comfortable
    posture where it has one (:func:`has_comfortable_posture`), else the middle of each joint's
    range (θ = 0, clipped into the range, where it is not finite: a continuous joint gets
    (cos 0, sin 0)); always within the limits.  In the coordinates (``robot.lower``/``upper``)
    for a model with ``robot.coupling``."""
    if getattr(robot, "coupling", None) is not None:
        lo, hi = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
        finite = np.isfinite(lo) & np.isfinite(hi)
        mid = 0.5 * (np.where(finite, lo, 0.0) + np.where(finite, hi, 0.0))
        return np.clip(mid, lo, hi)
    chain = robot.chain
    joints = [chain.joints[i] for i in chain.independent]
    lo = np.array([j.lower for j in joints])
    hi = np.array([j.upper for j in joints])
    if has_comfortable_posture(robot):
        theta = np.array([robot.spec.comfort[j.name] for j in joints])
    else:
        finite = np.isfinite(lo) & np.isfinite(hi)
        theta = np.where(finite, 0.5 * (np.where(finite, lo, 0.0) + np.where(finite, hi, 0.0)), 0.0)
    return chain.configuration(np.clip(theta, lo, hi))


class PostureTask(Task):
    """Posture task; ``target`` defaults to :func:`comfortable_posture`."""

    def __init__(self, robot, cost=1e-3, gain: float = 1.0, lm_damping: float = 0.0, target=None):
        super().__init__(cost=cost, gain=gain, lm_damping=lm_damping)
        self.model = robot.model
        self.robot = robot
        self._coupled = getattr(robot, "coupling", None) is not None  # q: coordinates
        self._H = np.diag(
            np.broadcast_to(np.asarray(self.cost, float) ** 2, (robot.nv,)).astype(float)
        )
        self._H.setflags(write=False)
        self._s_for = (None, None, None)  # (cost, gain, α w² per joint) of _accumulate
        self.set_target(comfortable_posture(robot) if target is None else target)

    def set_target(self, q_ref) -> None:
        self.target = self.robot.check_q(q_ref, name="posture target").copy()
        if self.target.ndim != 1:
            raise ValueError(f"posture target must have shape ({self.robot.nq},)")

    def set_target_from_configuration(self, conf) -> None:
        self.target = conf.q.copy()

    def _difference(self, conf) -> np.ndarray:
        """q ⊖ q_ref: ``pin.difference``, or the coordinates' difference with a coupling."""
        if self._coupled:
            return conf.q - self.target
        return pin.difference(self.model, self.target, conf.q)

    def compute_error(self, conf) -> np.ndarray:
        return self._difference(conf)

    def compute_jacobian(self, conf) -> np.ndarray:
        return np.eye(conf.nv)

    def compute_qp_objective(self, conf):
        # J = I: H = (w² + μ) I, c = α w² e  (same as Task._objective, without the matrix products)
        # the returned H may be a cached array: callers must not modify it in place
        w = self.cost
        We = (w * self.gain) * self._difference(conf)
        if self.lm_damping:
            H = np.diag(np.broadcast_to(w * w, (conf.nv,)).astype(float))
            H.flat[:: conf.nv + 1] += self.lm_damping * float(We @ We)
        else:
            H = self._H
        return H, w * We

    def _accumulate(self, conf, ws, first):
        # J = I: c += α w² e, diag(H) += w² + μ (returned when the cost is a scalar)
        if type(self) is not PostureTask:
            return Task._accumulate(self, conf, ws, first)
        w = self.cost
        d = self._difference(conf)
        key = self._s_for
        if key[0] is not w or key[1] != self.gain:
            # α w² as an (nv,) array: an array-array product is cheaper than one with a scalar
            s = np.empty(conf.nv)
            s[:] = w * w * self.gain
            self._s_for = (w, self.gain, s)
        s = self._s_for[2]
        if first:
            ws.H.fill(0.0)
            np.multiply(d, s, out=ws.c)
        else:
            np.add(ws.c, np.multiply(d, s, out=d), out=ws.c)
        mu = 0.0
        if self.lm_damping:
            We = (w * self.gain) * self._difference(conf)
            mu = self.lm_damping * float(We @ We)
        if isinstance(w, float):
            return w * w + mu
        np.add(ws.Hd, w * w, out=ws.Hd)
        return mu
