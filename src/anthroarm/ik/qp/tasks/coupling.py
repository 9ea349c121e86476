"""JointCouplingTask: linear relations between joints (finger joints that move together,
URDF mimic joints).

    e(q) = Σ_j r_j q_j − b  (1,),   J = [r_j at the joint's velocity index]  (1 × nv)

``JointCouplingTask.mimic(robot, joint, mimicked, multiplier, offset)`` encodes the URDF
``<mimic>`` relation q_joint = multiplier · q_mimicked + offset between two joints that are
both degrees of freedom of the model (a coupling the URDF does not declare: joints with a
``<mimic>`` tag are modelled by Pinocchio as followers, ``robot.chain.joints[i].mimic``, and
need no task).  Pass them as ``constraints=`` to :func:`~anthroarm.ik.qp.step` to hold them
exactly.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .base import Task


def _joint_index(robot, name: str) -> int:
    """Velocity index of the 1-DOF joint ``name`` (from ``robot.chain``)."""
    chain = robot.chain
    names = [j.name for j in chain.joints]
    if name not in names:
        raise ValueError(f"{robot.name}: unknown joint {name!r}; joints: {', '.join(names)}")
    j = chain.joint(name)
    if j.nv != 1:
        raise ValueError(
            f"{robot.name}: joint {name!r} is a mimic joint (it has no velocity of its own: "
            f"Pinocchio moves it with {chain.joints[j.mimic.source].name!r}); couple that joint "
            "instead"
        )
    return j.idx_v


class JointCouplingTask(Task):
    """Σ ratios[j] q[joints[j]] = offset, as a soft task (cost) or a hard constraint."""

    def __init__(
        self,
        robot,
        joints,
        ratios,
        offset: float = 0.0,
        cost=1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
    ):
        super().__init__(cost=cost, gain=gain, lm_damping=lm_damping)
        joints = list(joints)
        ratios = np.asarray(ratios, dtype=float)
        if len(joints) != len(ratios) or len(joints) == 0:
            raise ValueError(
                f"need one ratio per joint, got {len(joints)} joints and {len(ratios)} ratios"
            )
        if not np.isfinite(ratios).all() or not np.isfinite(offset):
            raise ValueError("ratios and offset must be finite")
        self.joints = joints
        self.ratios = ratios
        self.offset = float(offset)
        self._row = np.zeros((1, robot.nv))
        for name, r in zip(joints, ratios):
            self._row[0, _joint_index(robot, name)] += r

    def __repr__(self) -> str:
        terms = " + ".join(f"{r:g}·{j}" for j, r in zip(self.joints, self.ratios))
        return f"JointCouplingTask({terms} = {self.offset:g}, cost={self.cost})"

    @classmethod
    def mimic(
        cls, robot, joint: str, mimicked: str, multiplier: float = 1.0, offset: float = 0.0, **kw
    ):
        """q_joint = multiplier · q_mimicked + offset (URDF ``<mimic>`` semantics)."""
        return cls(robot, [joint, mimicked], [1.0, -float(multiplier)], offset=offset, **kw)

    def compute_error(self, conf) -> np.ndarray:
        if conf.nq == conf.nv:
            qt = conf.q
        else:  # joint coordinates in the tangent space (1-DOF joints of a Lie-group model)
            qt = pin.difference(conf.model, pin.neutral(conf.model), conf.q)
        return np.array([self._row[0] @ qt - self.offset])

    def compute_jacobian(self, conf) -> np.ndarray:
        return self._row.copy()
