"""Per-robot constants of the fast closed-form IK paths, computed once per robot and cached.

An :class:`ArmPlan` holds what every call of :func:`~anthroarm.ik.closed_form.analytic` needs
besides the pose: the closed form from the registry (:mod:`anthroarm.models.closed_forms`:
family, branch tree) and the lengths it reads (``robot.spec.params``, m), the joint limits
(``robot.lower`` / ``robot.upper``, rad) as Python floats and arrays, and the generated
verification FK of ``robot.chain`` (:class:`~anthroarm.ik.fk_codegen.FKStages`, split where the
branch tree fans out).  :func:`plan_for` returns the cached plan, rebuilt if the robot's chain,
tool or limits changed.
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


@dataclass
class ArmPlan:
    name: str              # the model (catalog) name, a label
    family: str            # the closed-form family (models.closed_forms)
    form: object           # its models.closed_forms.ClosedForm
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
    chain: object
    tool: str
    c_kernel: object = None  # compiled kernel (analytic_c.CKernel), False if unavailable, None untried


#: Robot -> ArmPlan (weak keys; a plan holds the chain and arrays, never the Robot)
_PLANS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def cached_plan(robot) -> ArmPlan | None:
    """The cached plan of ``robot`` if it is still valid (same chain, tool and limits), else None."""
    plan = _PLANS.get(robot)
    if plan is not None and plan.chain is robot.chain and plan.tool == robot.tool \
            and plan.lower_arr is robot.lower and plan.upper_arr is robot.upper:
        return plan
    return None


def plan_for(robot, form=None) -> ArmPlan:
    """The cached :class:`ArmPlan` of ``robot`` (an arm with a closed form; ``form`` its
    registry entry, looked up if not given)."""
    plan = cached_plan(robot)
    if plan is not None:
        return plan
    if form is None:
        from ..models.closed_forms import lookup

        form = lookup(robot.spec)
    lo, hi = robot.lower, robot.upper
    lo_f = tuple(float(x) if math.isfinite(x) else -math.pi for x in lo)
    plan = ArmPlan(
        name=robot.spec.name, family=form.family, form=form,
        params={k: robot.spec.params[k] for k in form.params}, nq=robot.nq,
        lower=tuple(float(x) for x in lo), upper=tuple(float(x) for x in hi),
        lower_arr=lo, upper_arr=hi,
        lo_f=lo_f,
        fast_lo=tuple(float(x) if math.isfinite(x) else -math.pi for x in lo),
        # below lo_f + 2π − tol the wrap index is 0; a 1e-6 rad margin keeps the rounding of the
        # boundary case on the exact formula (_wrap)
        fast_hi=tuple(min(float(h), f + TWO_PI - 1e-6) for h, f in zip(hi, lo_f)),
        fk=FKStages(robot.chain, form.splits, frame=robot.tool),
        fk_pos=FKStages(robot.chain, form.splits, position_only=True, frame=robot.tool),
        chain=robot.chain, tool=robot.tool)
    _PLANS[robot] = plan
    return plan
