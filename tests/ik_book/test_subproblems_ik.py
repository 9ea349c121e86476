"""First class-generic closed form from the subproblems: spherical wrist + two parallel axes
(anthroarm.ik.geometric.drivers._solve_spherical_two_parallel), on sixr_arm, kinova (continuous joints)
and a user-built PUMA-like URDF.

Oracles: Pinocchio FK for every branch (inside the limits after a 2π wrap); PyPI ik-geo
(Rust) for the branch count and the solutions on the same poses."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from test_classify import puma_urdf  # same folder (pytest puts it on sys.path)

import anthroarm as aa
from anthroarm.ik import classify as C
from anthroarm.ik.geometric.drivers import _solve_spherical_two_parallel, _spherical_wrist_P


def _wrap_into_limits(q, lo, hi):
    """Shift each angle by a multiple of 2π into [lo, hi] if possible (else NaN)."""
    out = q.copy()
    for i in range(len(q)):
        for s in (0.0, 2 * np.pi, -2 * np.pi):
            if lo[i] - 1e-12 <= q[i] + s <= hi[i] + 1e-12:
                out[i] = q[i] + s
                break
        else:
            out[i] = np.nan
    return out


def _robots(tmp_path):
    return [aa.load("sixr_arm"), aa.load("kinova"), puma_urdf(tmp_path)]


def test_every_branch_fk_verified(tmp_path):
    rng = np.random.default_rng(11)
    for robot in _robots(tmp_path):
        c = C.classify(robot)
        assert c.name == C.SPHERICAL_TWO_PARALLEL
        ch = robot.chain
        lo = np.array([-np.pi if j.kind == "continuous" else j.lower for j in ch.joints])
        hi = np.array([np.pi if j.kind == "continuous" else j.upper for j in ch.joints])
        model, data = robot.model, robot.model.createData()
        fid = model.getFrameId(robot.tool)
        n_checked = 0
        for _ in range(40):
            theta = rng.uniform(np.maximum(lo, -np.pi) + 0.05, np.minimum(hi, np.pi) - 0.05)
            q = ch.configuration(theta)
            pin.framesForwardKinematics(model, data, q)
            T = data.oMf[fid].homogeneous.copy()
            sol, valid, exact = _solve_spherical_two_parallel(c.kinematics, T)
            assert valid.all() and exact.all()  # reachable generic pose: 8 exact branches
            dist = np.abs(np.angle(np.exp(1j * (sol - theta)))).max(1)
            assert dist.min() < 1e-7  # the sampled posture is one of them
            for k in range(8):
                qk = _wrap_into_limits(sol[k], lo, hi)
                if np.isnan(qk).any():
                    continue  # outside the limits: not a solution
                pin.framesForwardKinematics(model, data, ch.configuration(qk))
                M = data.oMf[fid]
                assert np.abs(M.homogeneous - T).max() < 1e-9, (robot.name, k)
                n_checked += 1
        assert n_checked >= 40


def test_unreachable_pose_is_least_squares_flagged():
    robot = aa.load("sixr_arm")
    c = C.classify(robot)
    T = np.eye(4)
    T[:3, 3] = [10.0, 0, 0]  # far out of reach
    sol, valid, exact = _solve_spherical_two_parallel(c.kinematics, T)
    assert valid.any() and not exact.any() and np.isfinite(sol[valid]).all()


def test_same_solutions_as_ik_geo():
    ik_geo = pytest.importorskip("ik_geo")
    robot = aa.load("sixr_arm")
    kin = C.classify(robot).kinematics
    P = _spherical_wrist_P(kin)
    geo = ik_geo.Robot.spherical_two_parallel(kin.H.tolist(), P.tolist())
    rng = np.random.default_rng(5)
    for _ in range(30):
        theta = robot.chain.random_q(None, rng)
        T = robot.fk(theta)
        R06 = T[:3, :3] @ kin.R_tool.T  # ik-geo's tool is identity at q = 0
        theirs = np.array([s for s, ls in geo.get_ik(R06.T.tolist(), T[:3, 3].tolist()) if not ls])
        ours, valid, exact = _solve_spherical_two_parallel(kin, T)
        ours = ours[exact]
        assert len(theirs) == len(ours) == 8
        d = np.abs(np.angle(np.exp(1j * (ours[:, None] - theirs[None])))).max(-1)
        assert d.min(1).max() < 1e-8 and d.min(0).max() < 1e-8
