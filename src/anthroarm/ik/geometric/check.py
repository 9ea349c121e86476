"""``anthroarm check`` rows of the geometric IK: FK(IK(T)) = T by Pinocchio on every branch, and
the number of branches against IK-Geo's (PyPI ``ik-geo``, optional)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...check_rows import CheckRow
from .drivers import class_pose, solve
from .plan import plan_for


# ----------------------------------------------------------------------------- anthroarm check
def check_rows(robot, samples: int, rng) -> list:
    """``anthroarm check`` rows of an arm whose geometry has a class solver here (none for the
    others): every exact branch of random reachable poses FK-checked by Pinocchio (max entry
    of the 3×4 pose), and the number of exact branches per pose against IK-Geo's (PyPI
    ``ik-geo``, same H and P; the row is left out when it is not installed)."""
    plan = plan_for(robot)
    if plan is None:
        return []
    n = max(3, min(int(samples), 30))
    model, data, fid = robot.model, robot.model.createData(), robot.tool_id
    Q = robot.random_q(n, rng)
    T = np.empty((n, 4, 4))
    for i, q in enumerate(Q):
        pin.framesForwardKinematics(model, data, q)
        T[i] = data.oMf[fid].homogeneous
    k7 = None if plan.param_joint is None else plan.order.tolist().index(plan.param_joint)
    param = None if k7 is None else plan.chain.angles(Q)[:, k7]  # the sampled last joint
    th, valid, exact = solve(plan, T, param)
    worst, nb = 0.0, int(exact.sum())
    for i, k in zip(*np.nonzero(exact)):
        pin.framesForwardKinematics(model, data, plan.chain.configuration(th[i, k]))
        worst = max(worst, float(np.abs(data.oMf[fid].homogeneous[:3] - T[i, :3]).max()))
    if not exact.any(1).all():
        worst = float("inf")  # a pose made by FK must have a branch
    tag = f"{plan.cls}{' (reversed chain)' if plan.reversed else ''}"
    # an arm of its class only within the classification tolerance (rounded URDF angles): the raw
    # class solution is off by about that much (aa.ik.analytic polishes it before its FK check)
    off = max(plan.classification.worst_accepted)
    tol = max(1e-9, 10.0 * off)
    note = f"{tag}; {nb} branches" + (
        f"; axes {off:.2g} off the class: raw class solutions" if off else ""
    )
    rows = [
        CheckRow(
            robot.name,
            "closed form by geometry: FK(IK(T)) = T, all branches",
            worst,
            tol,
            n,
            "pinocchio FK",
            note,
        )
    ]
    try:
        import ik_geo
    except ImportError:
        return rows
    make = getattr(getattr(ik_geo, "Robot", None), plan.cls, None)
    if make is None:  # a folder named ik_geo on sys.path, or a class IK-Geo does not name
        return rows
    geo = make(plan.H.tolist(), plan.P.tolist())
    diff = 0
    R06, p06 = class_pose(plan, T, param)
    for i in range(n):
        theirs = sum(1 for _, ls in geo.get_ik(R06[i].T.tolist(), p06[i].tolist()) if not ls)
        diff = max(diff, abs(theirs - int(exact[i].sum())))
    rows.append(
        CheckRow(
            robot.name,
            "closed form by geometry: branches = IK-Geo's",
            float(diff),
            0.0,
            n,
            "ik-geo (Rust)",
            f"{tag}; max |ours - ik-geo| exact solutions per pose",
        )
    )
    return rows
