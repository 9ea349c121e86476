"""Cross-check rows of the numerical IK (``anthroarm check``).

* ``aa.ik.solve`` round trip: random configurations inside the limits → Pinocchio FK → solve →
  Pinocchio FK of the answer; the row reports the largest position / rotation error, and an
  answer outside the joint limits (or a failure) counts as an infinite error.
* ``qp.step`` against the closed form of its QP when no limit is active: with the box far away
  the QP optimum is the damped least-squares step Δq = −(Σ JᵀW²J + μI + λI)⁻¹ Σ α JᵀW²e
  (Eq. of ``tasks/base.py``), computed here with ``numpy.linalg.solve``; the row reports the
  largest difference of the OSQP answer (the default, sparse iterative backend).

Both rows run on every model they are given (any robot :func:`anthroarm.load` takes; the
catalog when ``models`` is None).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ... import models as catalog
from ...check_rows import CheckRow
from ...robot import load
from ..solve import solve
from .configuration import IKConfiguration
from .limits import Limit
from .step import step
from .tasks import FrameTask, PostureTask


def rows(models, samples, rng) -> list[CheckRow]:
    out = []
    n = max(3, min(int(samples), 20))
    for name in catalog.names() if models is None else models:
        robot = load(name)
        Q = robot.random_q(n, rng)
        worst = 0.0
        d = robot.model.createData()
        for q in Q:
            T = robot.fk(q)
            res = solve(robot, T, max_time=0.05)
            if not (res.success and robot.within_limits(res.q)):
                worst = float("inf")
                break
            pin.framesForwardKinematics(robot.model, d, res.q)
            M = d.oMf[robot.tool_id]
            worst = max(
                worst,
                float(np.linalg.norm(M.translation - T[:3, 3])),
                float(np.linalg.norm(pin.log3(M.rotation.T @ T[:3, :3]))),
            )
        out.append(
            CheckRow(
                name,
                "aa.ik.solve: FK(solve(T)) = T within limits",
                worst,
                1e-6,
                n,
                oracle="pinocchio FK",
                note="pos (m) / rot (rad), worst of both",
            )
        )
        # QP step vs its closed form (limits far away: box of ±10 rad)
        werr = 0.0
        big = Limit()
        big.box = lambda conf, dt: (np.full(robot.nv, -10.0), np.full(robot.nv, 10.0))
        for q, q2 in zip(Q[:3], Q[1:4]):
            conf = IKConfiguration(robot, q)
            ee = FrameTask(
                robot,
                position_cost=[1.0, 0.5, 2.0],
                orientation_cost=0.3,
                lm_damping=1e-2,
                target=robot.fk(pin.interpolate(robot.model, q, q2, 0.05)),
            )
            post = PostureTask(robot, cost=0.1, target=q2)
            dq = step(conf, None, [ee, post], 1.0, limits=[big], solver="osqp", damping=1e-6)
            H = 1e-6 * np.eye(robot.nv)
            c = np.zeros(robot.nv)
            for t in (ee, post):
                J, e = t.compute_jacobian(conf), t.compute_error(conf)
                w = np.broadcast_to(t.cost, e.shape)
                mu = t.lm_damping * float((w * e) @ (w * e))
                H += J.T @ (w[:, None] ** 2 * J) + mu * np.eye(robot.nv)
                c += t.gain * J.T @ (w**2 * e)
            werr = max(werr, float(np.abs(dq - np.linalg.solve(H, -c)).max()))
        out.append(
            CheckRow(
                name,
                "qp.step (OSQP) = damped least squares, inactive limits",
                werr,
                1e-8,
                3,
                oracle="numpy closed form",
                note="frame + posture task",
            )
        )
    return out
