"""Cross-check provider for the book's spatial mathematics (Ch. 5, 002 §4-1), the RCCC
mechanism, relative motion and §6-6 error propagation.

Rows (all errors are max-abs over random samples; positions relative to the link size):

* ``spatial``: E^{wθ} (5-105) vs ``pin.exp3``; screw matrix (4-6) vs ``pin.exp6``; dual
  matrix (5-145) vs ``SE3.actInv`` on a Plücker line; (5-130) vs the classical acceleration of
  a revolute–prismatic chain; Euler z–x–z (5-80) and hand angles (6-47) round trips;
* ``relative_motion``: q, q̇ (4-11), q̈ (4-17) vs a Pinocchio chain;
* ``rccc``: loop closure (log6), velocity and classical acceleration of the cut frame of the
  Pinocchio open chain, joint rates vs finite differences;
* each catalog arm: J_L (6-118) vs finite differences over perturbed joint placements;
  ``human_arm7``: the book's (6-119) vs the same finite differences.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

LWA = pin.LOCAL_WORLD_ALIGNED


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _spatial_rows(n, rng, CheckRow):
    from . import dual as D
    from .euler import euler_zxz, euler_zxz_inverse
    from .hand_angles import hand_angles, hand_matrix
    from .rotation_tensor import rotated_vector_motion, rotation_tensor
    from .screw import screw_matrix, screw_twist

    W = _unit(rng, n)
    th = rng.uniform(-np.pi, np.pi, n)
    e_exp3 = max(np.abs(rotation_tensor(w, t) - pin.exp3(t * w)).max() for w, t in zip(W, th))
    e_exp6 = 0.0
    e_line = 0.0
    e_acc = 0.0
    e_euler = 0.0
    e_hand = 0.0
    for w, t in zip(W, th):
        p, s = rng.normal(size=3), rng.normal()
        tw = screw_twist(t, s, w, p)
        e_exp6 = max(e_exp6, np.abs(screw_matrix(t, s, w, p) - pin.exp6(pin.Motion(tw[:3], tw[3:])).homogeneous).max())
        M = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        L = D.Line.from_point_direction(rng.normal(size=3), rng.normal(size=3))
        L2 = D.transform_line(D.dual_matrix_from_se3(M.rotation, M.translation), L)
        m = M.actInv(L.as_motion())
        e_line = max(e_line, np.abs(np.r_[L2.moment - m.linear, L2.u - m.angular]).max())
        # (5-130) vs a revolute-prismatic chain
        R, Rd, Rdd = rng.normal(size=(3, 3))
        thd, thdd = rng.normal(size=2)
        mot = rotated_vector_motion(w, t, thd, thdd, R, Rd, Rdd)
        model = pin.Model()
        j = model.addJoint(0, pin.JointModelRevoluteUnaligned(w), pin.SE3.Identity(), "r")
        for name, jm in (("x", pin.JointModelPX()), ("y", pin.JointModelPY()), ("z", pin.JointModelPZ())):
            j = model.addJoint(j, jm, pin.SE3.Identity(), name)
        data = model.createData()
        pin.forwardKinematics(model, data, np.r_[t, R], np.r_[thd, Rd], np.r_[thdd, Rdd])
        acc = pin.getClassicalAcceleration(model, data, j, LWA).linear
        e_acc = max(e_acc, np.abs(mot.acceleration - acc).max() / max(1.0, np.abs(acc).max()))
        a = rng.uniform(-np.pi, np.pi, 3)
        a[1] = rng.uniform(0.05, np.pi - 0.05)
        C = euler_zxz(*a)
        ref = pin.exp3(np.array([0, 0, a[0]])) @ pin.exp3(np.array([a[1], 0, 0])) @ pin.exp3(np.array([0, 0, a[2]]))
        e_euler = max(e_euler, np.abs(C - ref).max(), np.abs(euler_zxz(*euler_zxz_inverse(C).angles) - C).max())
        b = rng.uniform(-1.5, 1.5)
        H = hand_matrix(a[0], b, a[2])
        e_hand = max(e_hand, np.abs(hand_angles(H).angles - np.array([a[0], b, a[2]])).max())
    return [
        CheckRow("spatial", "E^{wθ} (5-105) vs exp3", float(e_exp3), 1e-12, n),
        CheckRow("spatial", "screw matrix 002 (4-6) vs exp6", float(e_exp6), 1e-12, n),
        CheckRow("spatial", "dual matrix (5-145) on a line vs SE3.actInv", float(e_line), 1e-11, n),
        CheckRow("spatial", "rotated vector acc (5-130) vs classical acc", float(e_acc), 1e-11, n),
        CheckRow("spatial", "Euler z-x-z (5-80) vs exp3, inverse", float(e_euler), 1e-10, n, "pinocchio+round trip"),
        CheckRow("spatial", "hand angles (6-44)/(6-47) round trip", float(e_hand), 1e-10, n, "round trip"),
    ]


def _relative_rows(n, rng, CheckRow):
    from ..mechanisms.relative_motion import (RelativeMotionGeometry, pinocchio_model, relative_acceleration,
                                              relative_position, relative_velocity)

    e = np.zeros(3)
    for _ in range(n):
        u0, u1 = _unit(rng, 2)
        g = RelativeMotionGeometry(u0, rng.normal(size=3), u1, rng.normal(size=3), rng.normal(size=3))
        x = rng.normal(size=9)
        th, thd, thdd, ph, phd, phdd, s, sd, sdd = x
        model, fid = pinocchio_model(g)
        data = model.createData()
        pin.forwardKinematics(model, data, np.array([th, s, ph]), np.array([thd, sd, phd]), np.array([thdd, sdd, phdd]))
        pin.updateFramePlacements(model, data)
        scale = max(1.0, np.abs(np.r_[g.p0, g.p1, g.q1]).max())
        e[0] = max(e[0], np.abs(relative_position(g, th, ph, s).q - data.oMf[fid].translation).max() / scale)
        e[1] = max(e[1], np.abs(relative_velocity(g, th, thd, ph, phd, s, sd).total
                                - pin.getFrameVelocity(model, data, fid, LWA).linear).max() / scale)
        e[2] = max(e[2], np.abs(relative_acceleration(g, th, thd, thdd, ph, phd, phdd, s, sd, sdd).total
                                - pin.getFrameClassicalAcceleration(model, data, fid, LWA).linear).max() / scale)
    return [
        CheckRow("relative_motion", "position 002 (4-6) vs pin FK (rel.)", float(e[0]), 1e-10, n),
        CheckRow("relative_motion", "velocity 002 (4-11) vs frame velocity (rel.)", float(e[1]), 1e-10, n),
        CheckRow("relative_motion", "acceleration 002 (4-17) vs classical acc (rel.)", float(e[2]), 1e-10, n),
    ]


def _rccc_rows(n, rng, CheckRow):
    from ..mechanisms.rccc import RCCCGeometry, pinocchio_chain, rccc_acceleration, rccc_position, rccc_velocity
    from .dual import Dual

    e = np.zeros(4)
    count = checked = fd_checked = 0  # assembled geometries, branches with rates, FD comparisons
    tries = 0
    while (count < n or not fd_checked) and tries < 20 * n + 20:
        tries += 1
        tw = rng.uniform(0.2, np.pi - 0.2, 4)
        ln = rng.uniform(-2, 2, 5)
        g = RCCCGeometry(*(Dual(a, b) for a, b in zip(tw, ln[:4])), s1=ln[4])
        th1, w1, a1 = rng.uniform(-np.pi, np.pi), rng.normal(), rng.normal()
        r = rccc_position(g, th1)
        if not r.ok:
            continue
        model, fid = pinocchio_chain(g)
        data = model.createData()
        for sol in r.solutions:
            v = rccc_velocity(g, sol, w1)
            a = rccc_acceleration(g, sol, w1, a1, v)
            if v.status != "ok":
                continue
            checked += 1
            pin.forwardKinematics(model, data, sol.q, v.rates, a.rates)
            pin.updateFramePlacements(model, data)
            err6 = pin.log6(data.oMf[fid]).vector
            vmag = max(1.0, np.abs(v.rates).max())  # rates grow without bound near a dead point
            amag = max(1.0, np.abs(v.rates).max() ** 2, np.abs(a.rates).max())
            V = pin.getFrameVelocity(model, data, fid, LWA).vector
            A = pin.getFrameClassicalAcceleration(model, data, fid, LWA).vector
            e[0] = max(e[0], np.abs(err6[:3]).max() / g.scale, np.abs(err6[3:]).max())
            e[1] = max(e[1], np.abs(V[:3]).max() / (g.scale * vmag), np.abs(V[3:]).max() / vmag)
            e[2] = max(e[2], np.abs(A[:3]).max() / (g.scale * amag), np.abs(A[3:]).max() / amag)
            h = 1e-6
            rp, rm = rccc_position(g, th1 + h), rccc_position(g, th1 - h)
            v1 = rccc_velocity(g, sol, 1.0).rates
            if rp.ok and rm.ok and np.abs(v1).max() < 100.0:  # away from dead points (FD is meaningless there)
                dq = (rp.solutions[sol.branch].q - rm.solutions[sol.branch].q) / (2 * h)
                e[3] = max(e[3], np.abs(dq - v1).max() / max(1.0, np.abs(v1).max()))
                fd_checked += 1
        count += 1
    # a row that compared nothing must not pass: NaN fails the check
    e[:3] = e[:3] if checked else np.nan
    e[3] = e[3] if fd_checked else np.nan
    note = f"{checked} branches of {count} assembled geometries"
    return [
        CheckRow("rccc", "loop closure (5-152) log6 (rel.)", float(e[0]), 1e-10, checked, note=note),
        CheckRow("rccc", "cut-frame velocity = 0 (rel.)", float(e[1]), 1e-10, checked, note=note),
        CheckRow("rccc", "cut-frame classical acc = 0 (rel.)", float(e[2]), 1e-10, checked, note=note),
        CheckRow("rccc", "joint rates vs finite differences (rel.)", float(e[3]), 1e-6, fd_checked, "finite differences"),
    ]


def _error_rows(models, n, rng, CheckRow):
    from ..kinematics.error_propagation import human_arm7_length_jacobian, length_jacobian, length_jacobian_fd
    from ..robot import load

    out = []
    for name in models:
        r = load(name)
        Q = r.random_q(n, rng)
        err = max(np.abs(length_jacobian(r, q, mode="components") - length_jacobian_fd(r, q, mode="components")).max() for q in Q)
        out.append(CheckRow(name, "J_L (6-118) vs FD of perturbed placements", float(err), 1e-10, n))
        if name == "human_arm7":
            e119 = max(np.abs(human_arm7_length_jacobian(q) - length_jacobian_fd(r, q)[:3]).max() for q in Q)
            out.append(CheckRow(name, "(6-119) vs FD of perturbed placements", float(e119), 1e-10, n))
    return out


def rows(models, samples, rng) -> list:
    """Provider for :mod:`anthroarm.crosscheck` (``samples`` capped to keep it ~ seconds)."""
    from ..crosscheck import CheckRow

    n = max(1, min(int(samples), 50))
    out = _spatial_rows(n, rng, CheckRow)
    out += _relative_rows(n, rng, CheckRow)
    out += _rccc_rows(max(1, n // 2), rng, CheckRow)
    out += _error_rows(models, max(1, min(n, 5)), rng, CheckRow)
    return out
