"""Closed-form IK at configurations with joints exactly on a limit or a straight elbow (issue 12
item 7): both paths (one pose, a batch) return the configuration the pose came from.

Oracle: Pinocchio's FK (the pose of q) and its Jacobian (whether q is singular).  Where J(q) is
well conditioned the pose determines q: a returned solution must equal q within 1e-9 rad (mod 2π
for joints with a full turn of range).  At a singular q (the shoulder at θ2 = 0/π, a straight
elbow, the wrist at sin θ5 = 0) the pose fixes only a one-parameter family: at least one solution,
every one inside the limits and FK-exact (Pinocchio) within 1e-9."""

import numpy as np
import pinocchio as pin
import pytest

import anthroarm as aa
from anthroarm.ik import closed_form as cf

#: the catalog arms with a closed form of finitely many solutions (not a swivel family)
ARMS = [
    n
    for n in aa.models.names()
    if (f := cf.closed_form_info(aa.load(n))) is not None and not f.swivel
]
PATHS = ["single", "batch"]


def _configs(robot, seed=7):
    lo, hi = robot.lower, robot.upper
    rng = np.random.default_rng(seed)
    out = []
    for j in range(robot.model.nq):
        for bound in (lo, hi):
            q = rng.uniform(lo + 0.2 * (hi - lo), hi - 0.2 * (hi - lo))
            q[j] = bound[j]
            out.append(q)
    for _ in range(6):  # several joints on limits at once
        q = rng.uniform(lo, hi)
        pick = rng.random(q.size) < 0.5
        q[pick] = np.where(rng.random(q.size) < 0.5, lo, hi)[pick]
        out.append(q)
    if robot.name == "prosthetic_arm":  # straight elbow (θ4 = 0, its lower limit)
        for _ in range(4):
            q = rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))
            q[3] = 0.0
            out.append(q)
    return out


def _solutions(robot, T, path, q):
    """The solutions of pose T; a 7-joint arm solved with its last joint held: at the value of
    the configuration q the pose came from (the last joint on the path to the tool)."""
    kw = {}
    if cf.closed_form_info(robot).param:
        kw["param"] = q[robot.chain.independent.index(robot.chain.path(robot.tool)[-1])]
    if path == "batch":
        b = aa.ik.analytic_batch(robot, T[None], **kw)
        return b.solutions[0][b.valid[0]]
    return aa.ik.analytic(robot, T, **kw).solutions


def _pose(robot, q):
    pin.framesForwardKinematics(robot.model, robot.data, q)
    return robot.data.oMf[robot.tool_id].homogeneous.copy()


@pytest.mark.parametrize("name", ARMS)
def test_limits_and_straight_elbow_found_by_every_path(name):
    robot = aa.load(name)
    lo, hi = robot.lower, robot.upper
    po = cf.closed_form_info(robot).position_only
    full = (hi - lo) >= 2 * np.pi - 1e-12
    misses = []
    for q in _configs(robot):
        T = _pose(robot, q)
        J = pin.computeFrameJacobian(
            robot.model, robot.data, q, robot.tool_id, pin.LOCAL_WORLD_ALIGNED
        )
        J = J[:3] if po else J
        regular = np.linalg.svd(J, compute_uv=False)[-1] > 1e-6
        for path in PATHS:
            S = _solutions(robot, T, path, q)
            if len(S) == 0:
                misses.append((path, q.round(6).tolist(), "no solution"))
                continue
            assert np.all(S >= lo) and np.all(S <= hi)
            for s in S:
                Ts = _pose(robot, s)
                err = np.abs(Ts[:3, 3] - T[:3, 3]).max() if po else np.abs(Ts[:3] - T[:3]).max()
                assert err <= 1e-9, (path, s, err)
            if regular:
                d = S - q
                d = np.where(full, (d + np.pi) % (2 * np.pi) - np.pi, d)
                if np.abs(d).max(-1).min() > 1e-9:
                    misses.append((path, q.round(6).tolist(), float(np.abs(d).max(-1).min())))
    assert not misses, misses
