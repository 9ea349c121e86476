"""``anthroarm ik``: the run (the parser: :mod:`.ik`)."""

from __future__ import annotations

import json
import math

import numpy as np
import pinocchio as pin

from .. import ik
from ..urdf_io import MAX_LENGTH
from .common import UserError
from .runtime import check_radians, joint_values, model_from_args, parse_q, progress


class IKOutcome:
    """What ``anthroarm ik`` reports, whichever solver produced it."""

    def __init__(self, q, success, status, pos_err, rot_err, iterations, method, solutions=()):
        self.q, self.success, self.status = q, bool(success), str(status)
        self.pos_err, self.rot_err = pos_err, rot_err
        self.iterations, self.method = int(iterations), method
        self.solutions = list(solutions)

    def to_dict(self, conv, joint_names) -> dict:
        as_list = lambda x: [float(v) for v in conv(x)]  # noqa: E731
        return {
            "success": self.success,
            "status": self.status,
            "method": self.method,
            "q": dict(zip(joint_names, as_list(self.q))) if self.q is not None else None,
            "pos_err_m": self.pos_err,
            "rot_err_rad": self.rot_err,
            "iterations": self.iterations,
            "closed_form_solutions": [as_list(q) for q in self.solutions],
        }


def pose_error(robot, q, T, frame):
    F = robot.fk(q, frame)
    return float(np.linalg.norm(F[:3, 3] - T[:3, 3])), float(
        np.linalg.norm(pin.log3(F[:3, :3].T @ T[:3, :3]))
    )


def solve_pose(robot, T, q0=None, frame=None) -> IKOutcome:
    """IK for the CLI: ``aa.ik.solve``, plus every closed-form branch inside the limits
    (``aa.ik.analytic``) for an arm that has one at the frame (default the tool).  Errors are
    recomputed here from ``robot.fk`` whatever the solver says."""
    sols = []
    if ik.has_analytic(robot, frame):
        sols = list(np.reshape(ik.analytic(robot, T, frame=frame).solutions, (-1, robot.nq)))
    r = ik.solve(robot, T, q0=q0, frame=frame)
    pe, re = pose_error(robot, r.q, T, frame)
    return IKOutcome(r.q, r.success, r.status, pe, re, r.iterations, "aa.ik.solve", sols)


def run(a) -> int:
    robot = model_from_args(a)
    if not all(math.isfinite(x) for x in [*a.xyz, *a.rpy]):
        raise UserError("--xyz and --rpy must be finite numbers")
    if max(map(abs, a.xyz)) > MAX_LENGTH:
        raise UserError(
            f"--xyz {' '.join(map(str, a.xyz))} is beyond the physical bound of {MAX_LENGTH:g} m"
        )
    if not a.deg:
        check_radians(a.rpy, [True] * 3, "--rpy")
    rpy = np.deg2rad(a.rpy) if a.deg else np.asarray(a.rpy, float)
    T = np.eye(4)
    T[:3, :3] = pin.rpy.rpyToMatrix(*rpy)
    T[:3, 3] = a.xyz
    if a.frame is not None:
        robot.frame_id(a.frame)  # UnknownFrameError (one line, lists the frames)
    q0 = parse_q(robot, a.q0, a.deg, "--q0") if a.q0 is not None else None
    bar = progress(1, "ik", not a.json)
    try:
        res = solve_pose(robot, T, q0=q0, frame=a.frame)
    finally:
        bar.close()
    if a.deg:
        conv = lambda x: np.rad2deg(joint_values(robot, x))  # noqa: E731
    else:
        conv = lambda x: joint_values(robot, x)  # noqa: E731
    if a.json:
        out = {
            "model": robot.name,
            "frame": a.frame or robot.tool,
            "xyz": list(a.xyz),
            "rpy": list(a.rpy),
            "units": "deg" if a.deg else "rad",
            **res.to_dict(conv, robot.joint_names),
        }
        print(json.dumps(out, indent=1))
        return 0 if res.success else 1
    unit = "deg" if a.deg else "rad"
    print(
        f"{robot.name}: {'solved' if res.success else 'NOT solved'} ({res.status}) by {res.method}"
    )
    if res.q is not None:
        for n, v in zip(robot.joint_names, conv(res.q)):
            print(f"  {n:<22} {v: .6f} {unit}")
        print(f"  position error {res.pos_err:.3e} m, orientation error {res.rot_err:.3e} rad")
    if len(res.solutions) > 1:
        print(f"  {len(res.solutions)} closed-form branches inside the limits (--json lists them)")
    return 0 if res.success else 1
