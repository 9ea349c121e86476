"""Per-robot constants of the fast closed-form IK paths, computed once per robot and cached.

An :class:`ArmPlan` holds what every call of :func:`~anthroarm.ik.closed_form.analytic` needs
besides the pose: the model name and lengths (``robot.spec.params``, m), the joint limits
(``robot.lower`` / ``robot.upper``, rad) as Python floats and arrays, the branch labels, the
generated verification FK (:class:`~anthroarm.ik.fk_codegen.FKStages`, split where the branch
tree of the model fans out) and the robot's tool frame.  :func:`plan_for` returns the cached
plan, rebuilt if the robot's spec, tool or limits changed.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from .fk_codegen import FKStages

TWO_PI = 2.0 * math.pi
#: tolerance of the limit wrap (rad), the same as ``closed_form._wrap_into_limits``
WRAP_TOL = 1e-9

#: where the branch tree of each model fans out (first joint of each FK stage after the first):
#: sixr_arm θ1 (shoulder) | θ2, θ3 (elbow) | θ4–θ6 (wrist flip);
#: prosthetic_arm θ1, θ2 (elbow root × shoulder) | θ3–θ6 (flexion sign);
#: human_arm7 q1–q4 (elbow × shoulder Euler branch) | q5–q7 (wrist Euler branch);
#: planar2r one stage (the two elbow branches differ in both joints).
SPLITS = {"sixr_arm": (1, 3), "prosthetic_arm": (2,), "human_arm7": (4,), "planar2r": ()}


@dataclass
class ArmPlan:
    name: str
    params: dict
    nq: int
    lower: tuple
    upper: tuple
    lower_arr: np.ndarray
    upper_arr: np.ndarray
    lo_f: tuple            # lower limit, or −π where it is infinite (origin of the 2π wrap)
    fast_lo: tuple         # [fast_lo, fast_hi] ⊂ limits: values there need no wrap (k = 0, no clip)
    fast_hi: tuple
    fk: FKStages           # full pose residual
    fk_pos: FKStages       # position-only residual
    spec: object
    tool: str
    model_name: str
    c_kernel: object = None  # compiled kernel (analytic_c.CKernel), False if unavailable, None untried


_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def plan_for(robot, name: str, params: dict) -> ArmPlan:
    """The cached :class:`ArmPlan` of ``robot`` (a supported book model, already checked)."""
    plan = _PLANS.get(robot)
    if plan is not None and plan.spec is robot.spec and plan.tool == robot.tool and plan.model_name == robot.name \
            and plan.lower_arr is robot.lower and plan.upper_arr is robot.upper:
        return plan
    lo, hi = robot.lower, robot.upper
    lo_f = tuple(float(x) if math.isfinite(x) else -math.pi for x in lo)
    plan = ArmPlan(
        name=name, params=dict(params), nq=robot.nq,
        lower=tuple(float(x) for x in lo), upper=tuple(float(x) for x in hi),
        lower_arr=lo, upper_arr=hi,
        lo_f=lo_f,
        fast_lo=tuple(float(x) if math.isfinite(x) else -math.pi for x in lo),
        # below lo_f + 2π − tol the wrap index is 0; a 1e-6 rad margin keeps the rounding of the
        # boundary case on the exact formula (_wrap)
        fast_hi=tuple(min(float(h), f + TWO_PI - 1e-6) for h, f in zip(hi, lo_f)),
        fk=FKStages(robot.spec, SPLITS[name]), fk_pos=FKStages(robot.spec, SPLITS[name], position_only=True),
        spec=robot.spec, tool=robot.tool, model_name=robot.name)
    _PLANS[robot] = plan
    return plan
